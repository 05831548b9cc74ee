//! Reference scenes and renderers for lodkit's examples, tests and demo.
//!
//! An engine draws its own scene; these show what its passes give lodkit's:
//! - [`mesh`]: procedural meshes and a forward renderer, drawn opaque, blended (unpopping,
//!   cross-fade) or screen-door dithered;
//! - [`transition`]: one single-frame transition drawn with each technique;
//! - [`lod_buffer`]: the forward pass into frame-sequential LOD's LOD buffers (color, depth, ids,
//!   motion);
//! - [`gbuffer`]: the low-resolution (or full-resolution prepass) G-buffer pass of framebuffer
//!   LOD, and the edge scene its measures use;
//! - [`tree`]: a tree with alpha-masked leaf cards, what impostors are baked from.

#![warn(missing_docs)]

pub mod gbuffer;
pub mod lod_buffer;
pub mod mesh;
pub mod transition;
pub mod tree;
