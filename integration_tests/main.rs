//! lodkit's integration tests: composition and export of the whole shader library, the CLI, and
//! shader functions on a GPU (lavapipe / llvmpipe in CI) held against their Rust twins, the
//! demo harness, and the library compiled by Tint in headless Chromium.

#[macro_use]
mod harness;
mod cli;
mod composition;
mod demo;
mod frame_sequential;
mod frame_sequential_render;
mod framebuffer_lod;
mod gpu_twins;
mod portability;
mod selection;
mod single_frame;
