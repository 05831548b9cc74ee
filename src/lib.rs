//! # lodkit
//!
//! Composable WGSL/GLSL shader modules for smooth discrete level-of-detail transitions and
//! geometry-aware framebuffer LOD, validated and composed through naga / naga_oil, with the host
//! math and wgpu glue an engine needs to splice them into its own pipeline.
//!
//! - [`shaders`]: the embedded module library, composition of your shaders that
//!   `#import lodkit::...` (or `#include "lodkit/....glsl"`), validation and export.
//! - [`select`]: which LOD to draw (view-normalized distance, bias, hysteresis, max distance,
//!   distance- or time-driven transitions), per instance or over batches, configurable in RON.
//! - [`unpopping`], [`screen_door`]: single-frame transitions without popping (Giegl & Wimmer's
//!   unpopping render states; complementary screen-door dither).
//! - [`bilateral`], [`gbuffer`], [`normal_distance`]: geometry-aware framebuffer LOD (Yang et
//!   al. 2008): Rust twins of the upsampling and low-res buffer shaders.
//! - [`fullscreen`]: Rust twins of the shader functions of the same names.
//! - [`frame_sequential`] with [`visibility`], [`lod_buffer`], [`reproject`], [`combine`]:
//!   frame-sequential LOD interpolation (Scherzer & Wimmer 2008): the transition scheduler, the
//!   visibility textures, and Rust twins of the LOD-buffer, reprojection and combine shaders;
//!   [`silhouette`]: where the level not drawn this frame covers the screen, from its mesh's
//!   silhouette (no rasterization); [`combine_coverage`]: the combine that reads the older
//!   level where its silhouette (or a depth pass) says it covers the pixel.
//! - [`impostor`]: octahedral impostors, the last level of a chain: Rust twins of
//!   `lodkit::impostor`, the atlas layout, the CPU steps of a bake and the switch distance with
//!   a pixel bound (the bake itself: `gpu::impostor`, feature `wgpu`).
//! - [`noise`]: seeded blue-noise (void-and-cluster) and white-noise patterns.
//! - [`metrics`]: how a transition looks on read-back frames: pop, flicker (change over net
//!   change, direction reversals), PSNR, medians.
//! - [`gpu`] (feature `wgpu`): headless devices and ready-made passes.
//! - `lod_chain` (feature `lod_chain`): levels of detail generated from one mesh by
//!   meshoptimizer, each with an upper bound of its Hausdorff distance from the original, and
//!   switch distances for a pixel error.
//!
//! ## Features
//!
//! | feature | default | gives | pulls in |
//! |---|---|---|---|
//! | `compose` | yes | [`shaders::ShaderLibrary`], validation, export, [`shaders::add_to_composer`] | naga 30, naga_oil 0.23 |
//! | `wesl` | no | `SourceLanguage::Wesl`: link WESL that imports lodkit (wesl-rs), then validate | wesl 0.4.0 (no naga of its own; and `compose`) |
//! | `wgpu` | no | [`gpu`]: headless devices, buffers, ready-made passes | wgpu 30 (and `compose`) |
//! | `lod_chain` | no | `lod_chain`: LOD chains from one mesh, error bounds, switch distances for a pixel error | meshopt 0.7 (compiles meshoptimizer's C++: needs a C++ compiler), rstar; no naga |
//!
//! With `default-features = false` the crate is the embedded shader sources ([`shaders::modules`])
//! and the host math: no naga, naga_oil or wgpu in the tree, so an engine on another naga (Bevy
//! 0.19's naga 29) registers lodkit's sources with its own composer. The `lodkit` command and the
//! demo are the separate `lodkit-cli` package.
//!
//! Every pure shader function has a Rust twin with the same name; tests hold the GPU result
//! against it.

#![warn(missing_docs)]

pub mod alpha_mask;
pub mod bilateral;
pub mod combine;
pub mod combine_coverage;
pub mod frame_sequential;
pub mod framebuffer_lod;
pub mod fullscreen;
pub mod gbuffer;
pub mod impostor;
pub mod lod_buffer;
pub mod metrics;
pub mod noise;
pub mod normal_distance;
pub mod reproject;
pub mod screen_door;
pub mod select;
pub mod shaders;
pub mod silhouette;
pub mod unpopping;
pub mod visibility;

#[cfg(feature = "wgpu")]
pub mod gpu;

#[cfg(feature = "lod_chain")]
pub mod lod_chain;

/// The Rust snippets of `docs/engines.md`, compiled and run as doctests so the guide cannot
/// drift from the API.
#[cfg(doctest)]
#[doc = include_str!("../docs/engines.md")]
pub struct EnginesGuide;

/// The Rust snippets of `docs/errors.md` (errors and recovery in the wgpu glue), compiled as
/// doctests.
#[cfg(all(doctest, feature = "wgpu"))]
#[doc = include_str!("../docs/errors.md")]
pub struct ErrorsGuide;
