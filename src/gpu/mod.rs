//! wgpu glue (feature `wgpu`): headless devices, readback, and the passes and render states of
//! each technique.
//!
//! Every call here that creates, records, submits or reads back returns [`GpuError`] instead of
//! panicking (the others are accessors that cannot fail): sizes and formats are checked
//! against the device's limits before wgpu sees them, the device work of each call runs inside
//! error scopes, and a lost device is reported by the next call (docs/errors.md).

mod capabilities;
pub mod checks;
mod context;
pub mod counters;
mod error;
pub mod frame_sequential;
pub mod framebuffer_lod;
pub mod impostor;
pub mod readback;
pub mod resources;
pub mod select;
pub mod unpopping;

pub use capabilities::{GlVersion, GpuCapabilities};
pub use context::{DeviceHandlers, GpuContext, GpuContextDescriptor, GpuOptions};
pub use error::GpuError;
