//! wgpu glue (feature `wgpu`): headless devices, and the passes and buffers of each technique.

mod context;

pub use context::{GpuContext, GpuError, GpuOptions};
