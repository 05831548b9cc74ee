//! A headless wgpu device: Vulkan first (a real GPU or lavapipe), OpenGL (llvmpipe) as fallback.

use std::borrow::Cow;

use crate::shaders::{
    ComposeDescriptor, Composed, Diagnostic, DiagnosticKind, ShaderDefValue, ShaderError,
    ShaderLibrary,
};

/// Why no GPU context could be made.
#[derive(Debug, thiserror::Error)]
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
}

/// Options for [`GpuContext::new_headless`].
#[derive(Clone, Debug, Default)]
pub struct GpuOptions {
    /// Backends to try, in order. Empty: `LODKIT_BACKEND` if set, else Vulkan then GL.
    pub backends: Vec<wgpu::Backends>,
    /// Optional features to enable when the adapter has them (others are silently left out).
    pub optional_features: wgpu::Features,
}

/// A headless device and queue with the adapter they came from.
#[derive(Debug)]
pub struct GpuContext {
    /// The wgpu instance.
    pub instance: wgpu::Instance,
    /// The adapter in use.
    pub adapter: wgpu::Adapter,
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
}

impl GpuContext {
    /// Creates a device without a window, blocking until it is ready.
    pub fn new_headless(options: &GpuOptions) -> Result<Self, GpuError> {
        let backends = if options.backends.is_empty() {
            match std::env::var("LODKIT_BACKEND") {
                Ok(name) => vec![parse_backend(&name)?],
                Err(_) => vec![wgpu::Backends::VULKAN, wgpu::Backends::GL],
            }
        } else {
            options.backends.clone()
        };
        for &backends in &backends {
            let mut desc = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
            desc.backends = backends;
            let instance = wgpu::Instance::new(desc);
            let request = wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                ..Default::default()
            };
            let Ok(adapter) = pollster::block_on(instance.request_adapter(&request)) else {
                continue;
            };
            let required_features = adapter.features() & options.optional_features;
            let device_desc = wgpu::DeviceDescriptor {
                label: Some("lodkit headless device"),
                required_features,
                required_limits: adapter.limits(),
                ..Default::default()
            };
            let (device, queue) = pollster::block_on(adapter.request_device(&device_desc))
                .map_err(|source| GpuError::RequestDevice {
                    adapter: adapter.get_info().name,
                    source,
                })?;
            return Ok(Self {
                instance,
                adapter,
                device,
                queue,
            });
        }
        let tried = backends
            .iter()
            .map(|b| format!("{b:?}"))
            .collect::<Vec<_>>()
            .join(", ");
        Err(GpuError::NoAdapter { tried })
    }

    /// One line about the adapter: name, backend, device type, driver.
    pub fn adapter_summary(&self) -> String {
        let info = self.adapter.get_info();
        format!(
            "{} ({:?}, {:?}, driver: {} {})",
            info.name, info.backend, info.device_type, info.driver, info.driver_info
        )
    }

    /// A shader module from a composed lodkit module (no re-parsing: naga IR goes straight in).
    pub fn shader_module(&self, label: &str, composed: &Composed) -> wgpu::ShaderModule {
        self.device
            .create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Naga(Cow::Owned(composed.module.clone())),
            })
    }

    /// The shader module of lodkit's pass `shader_lib/passes/<name>.wgsl`, composed with the
    /// boolean shader defs `defs` switched on.
    pub fn pass_module(
        &self,
        name: &str,
        defs: &[&str],
    ) -> Result<wgpu::ShaderModule, ShaderError> {
        let file_path = format!("shader_lib/passes/{name}.wgsl");
        let Some(source) = crate::shaders::find_pass_source(name) else {
            let d = Diagnostic::new(
                DiagnosticKind::UnknownImport,
                file_path,
                format!("lodkit has no pass `{name}`"),
            );
            return Err(ShaderError::Source(Box::new(d)));
        };
        let shader_defs = defs
            .iter()
            .map(|d| (d.to_string(), ShaderDefValue::Bool(true)))
            .collect();
        let composed = ShaderLibrary::new()?.compose(&ComposeDescriptor {
            source,
            file_path: &file_path,
            shader_defs,
            ..Default::default()
        })?;
        Ok(self.shader_module(name, &composed))
    }

    /// Blocks until the GPU has finished all submitted work.
    pub fn wait_idle(&self) {
        let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
    }
}

fn parse_backend(name: &str) -> Result<wgpu::Backends, GpuError> {
    match name.to_ascii_lowercase().as_str() {
        "vulkan" | "vk" => Ok(wgpu::Backends::VULKAN),
        "gl" | "gles" | "opengl" => Ok(wgpu::Backends::GL),
        "metal" => Ok(wgpu::Backends::METAL),
        "dx12" => Ok(wgpu::Backends::DX12),
        _ => Err(GpuError::UnknownBackend(name.to_owned())),
    }
}
