//! Tests of the `lodkit` command and its demo: exit codes, diagnostics with file:line:col, JSON
//! output, and the demo's report on a GPU (lavapipe / llvmpipe in CI) checked in headless Chromium.

#[macro_use]
#[path = "../../integration_tests/support.rs"]
mod support;
mod action;
mod budget;
mod ci_formats;
mod cli;
mod combine_regions;
mod demo;
mod demo_chain;
mod demo_cli;
mod docs_figures;
mod engine_tree;
mod fast_path;
mod gpu_report;
mod impostor;
mod lod;
mod lod_compressed;
mod lod_folder;
mod lod_images;
mod lod_impostor;
mod lod_objects;
mod npm_package;
mod permutations;
mod pipes;
mod wesl_check;
