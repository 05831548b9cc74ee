//! wgpu glue (feature `wgpu`): headless devices, readback, and the passes and render states of
//! each technique.

mod context;
pub mod counters;
pub mod frame_sequential;
pub mod framebuffer_lod;
pub mod gbuffer_scene;
pub mod lod_buffer_scene;
pub mod readback;
pub mod resources;
pub mod scene;
pub mod transition_scene;
pub mod unpopping;

pub use context::{GpuContext, GpuError, GpuOptions};
