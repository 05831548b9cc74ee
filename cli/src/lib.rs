//! The harness behind the `lodkit` command: the quality/cost demo that renders every technique
//! headless and writes the report, and the npm package of the WESL modules. The library a user depends on is `lodkit`; this package is
//! the command-line tool and its demo, and is not meant as a dependency.

#![warn(missing_docs)]

pub mod demo;
pub mod npm;
pub mod progress;
