//! The one error type of `lodkit::gpu` (the checks that make most of them before wgpu would see
//! a request are in `checks.rs`). docs/errors.md lists every error a host call can return and
//! what an engine does about it.

use crate::shaders::ShaderError;

/// Everything a call in `lodkit::gpu` can fail with.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GpuError {
    /// No adapter on any backend that was tried.
    #[error(
        "no GPU adapter found (tried: {tried}). On Debian/Ubuntu, `apt-get install \
         mesa-vulkan-drivers libvulkan1` gives a software Vulkan device (lavapipe)"
    )]
    NoAdapter {
        /// The backends that were tried, in order.
        tried: String,
    },
    /// `LODKIT_BACKEND` names no backend wgpu knows.
    #[error("LODKIT_BACKEND=`{0}` is not a backend (expected vulkan, gl, metal, dx12)")]
    UnknownBackend(String),
    /// The adapter refused to create a device.
    #[error("the adapter `{adapter}` could not create a device: {source}")]
    RequestDevice {
        /// Adapter name.
        adapter: String,
        /// wgpu's reason.
        #[source]
        source: wgpu::RequestDeviceError,
    },
    /// A size is larger than the device allows.
    #[error("{call}: {parameter} = {value} is larger than the device allows ({limit} = {max})")]
    TooLarge {
        /// The lodkit call, e.g. `LodBuffers::new`.
        call: &'static str,
        /// The parameter, e.g. `width`.
        parameter: &'static str,
        /// The value asked for.
        value: u64,
        /// The limit it was checked against, e.g. `max_texture_dimension_2d`.
        limit: &'static str,
        /// The device's value of that limit.
        max: u64,
    },
    /// A texture format the call cannot use on this device.
    #[error("{call}: {parameter} = {format:?} cannot be used: {reason}")]
    UnsupportedFormat {
        /// The lodkit call.
        call: &'static str,
        /// The parameter.
        parameter: &'static str,
        /// The format given.
        format: wgpu::TextureFormat,
        /// Why not.
        reason: String,
    },
    /// An input that does not match what the object was built for, or another input.
    #[error("{call}: {parameter} is {found}, but {expected}")]
    Mismatch {
        /// The lodkit call.
        call: &'static str,
        /// The parameter.
        parameter: &'static str,
        /// What was given.
        found: String,
        /// What was expected and why, e.g. `the pass was built for Rgba8Unorm`.
        expected: String,
    },
    /// A parameter outside its domain (not a size).
    #[error("{call}: {parameter} = {value} {rule}")]
    Invalid {
        /// The lodkit call.
        call: &'static str,
        /// The parameter.
        parameter: &'static str,
        /// The value given.
        value: String,
        /// The rule it breaks, e.g. `must be finite and positive`.
        rule: &'static str,
    },
    /// The device lacks a capability the call needs (a downlevel flag such as compute shaders
    /// or indirect execution).
    #[error("{call}: the device lacks {capability}; {fallback}")]
    MissingCapability {
        /// The lodkit call.
        call: &'static str,
        /// The missing capability, e.g. `INDIRECT_EXECUTION`.
        capability: &'static str,
        /// What to do instead.
        fallback: &'static str,
    },
    /// wgpu rejected work of this call (caught by an error scope).
    #[error("{call}: wgpu validation error: {description}")]
    Validation {
        /// The lodkit call.
        call: &'static str,
        /// wgpu's description.
        description: String,
    },
    /// The device ran out of memory during this call.
    #[error("{call}: out of GPU memory: {description}")]
    OutOfMemory {
        /// The lodkit call.
        call: &'static str,
        /// wgpu's description.
        description: String,
    },
    /// An internal error of wgpu or the driver during this call.
    #[error("{call}: internal GPU error: {description}")]
    Internal {
        /// The lodkit call.
        call: &'static str,
        /// wgpu's description.
        description: String,
    },
    /// wgpu reported errors outside any lodkit call (the engine's own work on the device, or a
    /// submission lodkit did not make); the context's handler recorded them and this is the
    /// first lodkit call since.
    #[error(
        "{call}: wgpu reported {count} error(s) outside lodkit's calls since the last one; the \
         first: {first}"
    )]
    Uncaptured {
        /// The lodkit call that found them.
        call: &'static str,
        /// How many were recorded.
        count: usize,
        /// The first one's description.
        first: String,
    },
    /// The device is lost (driver reset, `Device::destroy`, GPU removed). Every object made
    /// from the context is dead: recreate the [`GpuContext`](crate::gpu::GpuContext) and the
    /// lodkit objects.
    #[error(
        "{call}: the GPU device was lost ({reason}: {message}); create a new GpuContext and \
         rebuild the lodkit objects made from the old one"
    )]
    DeviceLost {
        /// The lodkit call that found it.
        call: &'static str,
        /// wgpu's reason (`Destroyed` or `Unknown`).
        reason: String,
        /// wgpu's message.
        message: String,
    },
    /// More draw items than one call of a renderer takes (its `MAX_DRAWS`; raised through
    /// `DrawUniforms::check_count`, by the `lodkit-scenes` reference renderers). Nothing was drawn:
    /// split the items over several calls (the later ones loading what the first drew), or
    /// merge meshes.
    #[error("{call}: {count} draw items, but one call draws at most {max} (MAX_DRAWS)")]
    TooManyDraws {
        /// The lodkit call.
        call: &'static str,
        /// The items given.
        count: usize,
        /// The most one call takes.
        max: usize,
    },
    /// wgpu's GL backend gave up waiting for its GL context lock (6 s): another thread held the
    /// context, outside lodkit's calls (they pass one at a time, see
    /// [`GpuContext::exclusive`](crate::gpu::GpuContext::exclusive)). Nothing is lost: the call
    /// did nothing and may be retried.
    #[error(
        "{call}: wgpu's GL backend waited more than 6 s for the GL context, which another \
         thread held; nothing was lost, retry, and run that thread's device work through \
         GpuContext::exclusive"
    )]
    ContextTimeout {
        /// The lodkit call.
        call: &'static str,
    },
    /// Copying data back to the CPU failed.
    #[error("{call}: reading back from the GPU failed: {reason}")]
    Readback {
        /// The lodkit call.
        call: &'static str,
        /// Why.
        reason: String,
    },
    /// A lodkit pass did not compose or validate.
    #[error(transparent)]
    Shader(#[from] ShaderError),
}

impl GpuError {
    /// Whether the device is lost: the caller must rebuild the context and its objects.
    pub fn is_device_lost(&self) -> bool {
        matches!(self, Self::DeviceLost { .. })
    }

    /// The error for a wgpu error caught while running `call`.
    pub(crate) fn from_wgpu(call: &'static str, error: wgpu::Error) -> Self {
        match error {
            wgpu::Error::OutOfMemory { source } => Self::OutOfMemory {
                call,
                description: source.to_string(),
            },
            wgpu::Error::Validation { description, .. } => Self::Validation { call, description },
            wgpu::Error::Internal { description, .. } => Self::Internal { call, description },
        }
    }
}
