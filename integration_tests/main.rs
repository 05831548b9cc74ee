//! lodkit's integration tests: composition and export of the whole shader library, shader
//! functions on a GPU (lavapipe / llvmpipe in CI) held against their Rust twins, and the library
//! compiled by Tint in headless Chromium. The `lodkit` command and its demo are tested in
//! `cli/tests/`.

#[macro_use]
mod support;
mod alpha_tested;
mod bilateral_sigma;
mod combine_coverage;
mod combine_level_depth;
mod combine_ray;
mod composition;
mod cost;
mod cost_bounds;
mod coverage_levels;
mod display_time;
mod downlevel;
mod draw_limits;
mod fragment_probe;
mod frame_sequential;
mod frame_sequential_render;
mod framebuffer_lod;
mod gpu_select;
mod gpu_select_chunks;
mod gpu_select_path;
mod gpu_twins;
mod harness;
mod host_errors;
mod house;
mod impostor;
mod impostor_lod_buffer;
mod impostor_render;
mod impostor_sample;
mod impostor_states;
mod lod_chain;
mod object_motion;
mod older_threshold;
mod packed_gbuffer;
mod portability;
mod robustness;
mod screen_space;
mod selection;
mod single_frame;
mod webgpu_page;
mod wesl;
