//! What a device really can do for lodkit's shaders: wgpu's downlevel flags, corrected where
//! wgpu's GL backend claims more than the context's shading language has, and whether a pipeline
//! can bind more than one texture and one uniform buffer there.
//!
//! wgpu 30's GL backend (wgpu-hal `gles/adapter.rs`) claims compute shaders, indirect execution
//! and storage buffers when the driver lists `GL_ARB_compute_shader` and
//! `GL_ARB_shader_storage_buffer_object`, whatever the context's GLSL version. NVIDIA's EGL driver
//! lists them in the GL 3.3 context wgpu asks it for, and so does Mesa under
//! `MESA_GL_VERSION_OVERRIDE=3.3 MESA_GLSL_VERSION_OVERRIDE=330`. naga then writes
//! `#version 330 core`, which has neither (naga needs GLSL 4.30 or GLSL ES 3.10 for compute
//! shaders with storage arrays). The same claim costs more than compute:
//!
//! - wgpu-core builds compute pipelines for its indirect-call validation when it creates a device
//!   on such an adapter, and reports their failure as a lost device;
//! - wgpu then trusts each shader to carry its binding points (`layout(binding = N)`) and skips
//!   binding them by name after the link, but naga writes binding points only from GLSL 4.20 /
//!   GLSL ES 3.10 on: every texture of a pipeline reads texture unit 0 and every uniform block
//!   binding point 0, so any pipeline with two textures or two uniform buffers draws a wrong
//!   picture without an error.
//!
//! [`GpuCapabilities`] says what the device can do with that taken into account;
//! [`GpuContext::new_headless`](super::GpuContext::new_headless) leaves the indirect-call
//! validation out where compute cannot work, and
//! [`GpuContext::shader_module`](super::GpuContext::shader_module) refuses a module that needs
//! what the device lacks ([`GpuError::MissingCapability`]).

use std::collections::HashSet;
use std::fmt;

use super::GpuError;

/// The version of an OpenGL context, as wgpu's GL backend reports it in
/// `AdapterInfo::driver_info` (the `GL_VERSION` string).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct GlVersion {
    /// OpenGL ES (WebGL included) rather than desktop OpenGL.
    pub es: bool,
    /// Major version.
    pub major: u32,
    /// Minor version.
    pub minor: u32,
}

impl GlVersion {
    /// Reads a `GL_VERSION` string: `"3.3 (Core Profile) Mesa 22.3.6"`, `"4.6.0 NVIDIA 580.95"`,
    /// `"OpenGL ES 3.0 Mesa 22.3.6"`, `"WebGL 2.0 (OpenGL ES 3.0 Chromium)"` (WebGL 2 is
    /// GLES 3.0). `None` when the string starts otherwise.
    ///
    /// ```
    /// # use lodkit::gpu::GlVersion;
    /// let v = GlVersion::parse("3.3 (Core Profile) Mesa 22.3.6").unwrap();
    /// assert_eq!((v.es, v.major, v.minor, v.glsl()), (false, 3, 3, 330));
    /// assert_eq!(GlVersion::parse("OpenGL ES 3.1 Mesa").unwrap().glsl(), 310);
    /// assert_eq!(GlVersion::parse("WebGL 2.0 (OpenGL ES 3.0 Chromium)").unwrap().glsl(), 300);
    /// ```
    pub fn parse(version: &str) -> Option<Self> {
        let version = version.trim();
        if let Some(rest) = version.strip_prefix("WebGL ") {
            let (major, _) = major_minor(rest)?;
            // WebGL 1 is GLES 2.0, WebGL 2 is GLES 3.0.
            return Some(Self {
                es: true,
                major: major + 1,
                minor: 0,
            });
        }
        let (es, rest) = match version.strip_prefix("OpenGL ES ") {
            Some(rest) => (true, rest),
            None => (false, version),
        };
        let (major, minor) = major_minor(rest)?;
        Some(Self { es, major, minor })
    }

    /// The shading language version that goes with the context, as naga writes it in
    /// `#version`: 330 for GL 3.3, 450 for GL 4.5, 300 for GLES 3.0 (wgpu needs GL 3.3 or GLES
    /// 3.0 at least, where the numbers agree).
    pub fn glsl(self) -> u32 {
        self.major * 100 + self.minor * 10
    }

    /// Whether naga's GLSL has compute shaders with storage arrays here: GLSL 4.30, GLSL ES 3.10.
    pub fn has_compute(self) -> bool {
        self.glsl() >= if self.es { 310 } else { 430 }
    }

    /// Whether naga writes binding points (`layout(binding = N)`) here: GLSL 4.20, GLSL ES 3.10.
    pub fn has_binding_points(self) -> bool {
        self.glsl() >= if self.es { 310 } else { 420 }
    }
}

impl fmt::Display for GlVersion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let es = if self.es { "ES " } else { "" };
        write!(f, "GL {es}{}.{}", self.major, self.minor)
    }
}

/// `"3.3..."` -> (3, 3): the leading `major.minor` of a version string.
fn major_minor(text: &str) -> Option<(u32, u32)> {
    let token = text.split_whitespace().next()?;
    let mut parts = token.split('.');
    let major = parts.next()?.parse().ok()?;
    let minor = parts
        .next()?
        .chars()
        .take_while(char::is_ascii_digit)
        .collect::<String>()
        .parse()
        .ok()?;
    Some((major, minor))
}

/// What a device really can do for lodkit's shaders (see the module docs for why this differs
/// from wgpu's own answer on some GL contexts). [`GpuContext::capabilities`] has the device's.
///
/// [`GpuContext::capabilities`]: super::GpuContext::capabilities
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GpuCapabilities {
    /// The adapter's downlevel flags, less `COMPUTE_SHADERS`, `INDIRECT_EXECUTION` and the
    /// storage flags (`VERTEX_STORAGE`, `FRAGMENT_STORAGE`, `FRAGMENT_WRITABLE_STORAGE`) on a GL
    /// context whose shading language cannot have them (below GLSL 4.30 / GLSL ES 3.10).
    pub downlevel: wgpu::DownlevelFlags,
    /// On wgpu's GL backend, the context's version.
    pub gl_version: Option<GlVersion>,
    /// Whether one pipeline may use more than one texture and more than one uniform buffer.
    /// False on a GL context below GLSL 4.20 / GLSL ES 3.10 where wgpu claims compute shaders:
    /// there it neither writes binding points nor assigns them by name, and every texture would
    /// read unit 0, every uniform block binding point 0.
    pub binding_layout: bool,
}

/// Storage flags wgpu's GL backend sets from the storage-buffer extension alone.
const STORAGE: wgpu::DownlevelFlags = wgpu::DownlevelFlags::VERTEX_STORAGE
    .union(wgpu::DownlevelFlags::FRAGMENT_STORAGE)
    .union(wgpu::DownlevelFlags::FRAGMENT_WRITABLE_STORAGE);

/// What to do where a pipeline would need more bindings than the context can route.
const BINDING_LAYOUT_FALLBACK: &str = "wgpu 30's GL backend writes no binding points below GLSL \
     4.20 and, on a driver that lists GL_ARB_compute_shader, does not bind by name either, so a \
     pipeline with two textures or two uniform buffers would read the wrong ones: use the \
     Vulkan backend, or a GL 4.2+ / GLES 3.1+ context";

/// What to do where a module needs compute shaders or storage buffers the device lacks.
const SHADER_FALLBACK: &str = "compute shaders and storage buffers need Vulkan, Metal, DX12, GL \
     4.3+ or GLES 3.1+ (naga writes GLSL 4.30 / GLSL ES 3.10 for them)";

impl GpuCapabilities {
    /// The capabilities of a device on an adapter with `info` whose downlevel flags are
    /// `claimed` (wgpu's `DownlevelCapabilities::flags`).
    pub fn new(info: &wgpu::AdapterInfo, claimed: wgpu::DownlevelFlags) -> Self {
        let gl_version = (info.backend == wgpu::Backend::Gl)
            .then(|| GlVersion::parse(&info.driver_info))
            .flatten();
        let mut downlevel = claimed;
        let mut binding_layout = true;
        if let Some(version) = gl_version {
            if !version.has_compute() {
                downlevel.remove(
                    wgpu::DownlevelFlags::COMPUTE_SHADERS
                        | wgpu::DownlevelFlags::INDIRECT_EXECUTION
                        | STORAGE,
                );
            }
            // wgpu-hal 30 skips binding by name exactly when it claims compute shaders.
            binding_layout = version.has_binding_points()
                || !claimed.contains(wgpu::DownlevelFlags::COMPUTE_SHADERS);
        }
        Self {
            downlevel,
            gl_version,
            binding_layout,
        }
    }

    /// The capabilities of a device created on `adapter`.
    pub fn of_adapter(adapter: &wgpu::Adapter) -> Self {
        Self::new(
            &adapter.get_info(),
            adapter.get_downlevel_capabilities().flags,
        )
    }

    /// Whether compute shaders work.
    pub fn compute_shaders(&self) -> bool {
        self.downlevel
            .contains(wgpu::DownlevelFlags::COMPUTE_SHADERS)
    }

    /// `Ok` when the device has every flag of `flags`; otherwise
    /// [`GpuError::MissingCapability`] naming the first one missing, with `fallback`.
    pub fn require(
        &self,
        call: &'static str,
        flags: wgpu::DownlevelFlags,
        fallback: &'static str,
    ) -> Result<(), GpuError> {
        match (flags - self.downlevel).iter_names().next() {
            Some((capability, _)) => Err(GpuError::MissingCapability {
                call,
                capability,
                fallback,
            }),
            None => Ok(()),
        }
    }

    /// `Ok` when a pipeline built from `module` runs correctly on this device: compute entry
    /// points need `COMPUTE_SHADERS`, storage buffers the stage's storage flag, and more than
    /// one texture, storage texture or uniform buffer used by the module's entry points
    /// together needs [`binding_layout`](Self::binding_layout). (A pipeline that takes its
    /// stages from two modules is checked one module at a time.)
    pub fn check_module(
        &self,
        call: &'static str,
        module: &naga::Module,
        info: &naga::valid::ModuleInfo,
    ) -> Result<(), GpuError> {
        use naga::{AddressSpace, ImageClass, ShaderStage, TypeInner};
        let mut needs = wgpu::DownlevelFlags::empty();
        let (mut textures, mut images, mut uniforms) =
            (HashSet::new(), HashSet::new(), HashSet::new());
        for (index, entry) in module.entry_points.iter().enumerate() {
            let used = info.get_entry_point(index);
            let storage = match entry.stage {
                ShaderStage::Compute => {
                    needs |= wgpu::DownlevelFlags::COMPUTE_SHADERS;
                    wgpu::DownlevelFlags::COMPUTE_SHADERS
                }
                ShaderStage::Vertex => wgpu::DownlevelFlags::VERTEX_STORAGE,
                _ => wgpu::DownlevelFlags::FRAGMENT_STORAGE,
            };
            for (handle, global) in module.global_variables.iter() {
                if used[handle].is_empty() {
                    continue;
                }
                match (global.space, &module.types[global.ty].inner) {
                    (AddressSpace::Uniform, _) => {
                        uniforms.insert(handle);
                    }
                    (AddressSpace::Storage { .. }, _) => needs |= storage,
                    (_, TypeInner::Image { class, .. }) => {
                        match class {
                            ImageClass::Storage { .. } => images.insert(handle),
                            _ => textures.insert(handle),
                        };
                    }
                    _ => {}
                }
            }
        }
        self.require(call, needs, SHADER_FALLBACK)?;
        if !self.binding_layout && [&textures, &images, &uniforms].iter().any(|s| s.len() > 1) {
            return Err(GpuError::MissingCapability {
                call,
                capability: "SHADER_BINDING_LAYOUT",
                fallback: BINDING_LAYOUT_FALLBACK,
            });
        }
        Ok(())
    }
}

impl fmt::Display for GpuCapabilities {
    /// One line: the GL version where there is one, then what lodkit's passes may use.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(version) = self.gl_version {
            write!(f, "{version} (GLSL {}), ", version.glsl())?;
        }
        let yes = |b: bool| if b { "yes" } else { "no" };
        write!(
            f,
            "compute shaders: {}, storage buffers in fragment shaders: {}, several textures or \
             uniform buffers per pipeline: {}",
            yes(self.compute_shaders()),
            yes(self
                .downlevel
                .contains(wgpu::DownlevelFlags::FRAGMENT_STORAGE)),
            yes(self.binding_layout)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gl(driver_info: &str) -> wgpu::AdapterInfo {
        wgpu::AdapterInfo {
            driver_info: driver_info.into(),
            ..wgpu::AdapterInfo::new(wgpu::DeviceType::Cpu, wgpu::Backend::Gl)
        }
    }

    /// What wgpu 30's GL backend claims where the driver lists GL_ARB_compute_shader and
    /// GL_ARB_shader_storage_buffer_object (as NVIDIA's and Mesa's do at any context version).
    fn claimed() -> wgpu::DownlevelFlags {
        wgpu::DownlevelFlags::COMPUTE_SHADERS
            | wgpu::DownlevelFlags::INDIRECT_EXECUTION
            | STORAGE
            | wgpu::DownlevelFlags::DEPTH_TEXTURE_AND_BUFFER_COPIES
    }

    #[test]
    fn version_strings_of_the_drivers_seen() {
        let cases = [
            ("3.3 (Core Profile) Mesa 22.3.6", (false, 3, 3)),
            ("4.5 (Core Profile) Mesa 22.3.6", (false, 4, 5)),
            ("4.6.0 NVIDIA 580.159.04", (false, 4, 6)),
            ("3.3.0 NVIDIA 580.159.04", (false, 3, 3)),
            ("OpenGL ES 3.2 Mesa 22.3.6", (true, 3, 2)),
            ("OpenGL ES 3.0 (ANGLE 2.1)", (true, 3, 0)),
            ("WebGL 2.0 (OpenGL ES 3.0 Chromium)", (true, 3, 0)),
        ];
        for (text, (es, major, minor)) in cases {
            let want = GlVersion { es, major, minor };
            assert_eq!(GlVersion::parse(text), Some(want), "{text}");
        }
        for bad in ["", "Mesa", "OpenGL ES", "x.y"] {
            assert_eq!(GlVersion::parse(bad), None, "{bad}");
        }
    }

    #[test]
    fn gl_3_3_with_the_compute_extension_loses_compute_storage_and_bindings() {
        let caps = GpuCapabilities::new(&gl("3.3 (Core Profile) Mesa 22.3.6"), claimed());
        assert!(!caps.compute_shaders());
        assert_eq!(
            caps.downlevel,
            wgpu::DownlevelFlags::DEPTH_TEXTURE_AND_BUFFER_COPIES
        );
        assert!(!caps.binding_layout);
        let err = caps
            .require("x", wgpu::DownlevelFlags::COMPUTE_SHADERS, "f")
            .unwrap_err();
        assert!(err.to_string().contains("COMPUTE_SHADERS"), "{err}");
    }

    #[test]
    fn gl_3_3_without_the_compute_extension_binds_by_name() {
        let copies = wgpu::DownlevelFlags::DEPTH_TEXTURE_AND_BUFFER_COPIES;
        let caps = GpuCapabilities::new(&gl("3.3 (Core Profile) Mesa 22.3.6"), copies);
        assert!(caps.binding_layout);
        assert!(!caps.compute_shaders());
    }

    #[test]
    fn gl_4_2_has_binding_points_but_not_compute_and_4_3_has_both() {
        let caps = GpuCapabilities::new(&gl("4.2 (Core Profile) Mesa"), claimed());
        assert!(caps.binding_layout && !caps.compute_shaders());
        let caps = GpuCapabilities::new(&gl("4.3 (Core Profile) Mesa"), claimed());
        assert!(caps.binding_layout && caps.compute_shaders());
        assert_eq!(caps.downlevel, claimed());
        let caps = GpuCapabilities::new(&gl("OpenGL ES 3.1 Mesa"), claimed());
        assert!(caps.binding_layout && caps.compute_shaders());
    }

    #[test]
    fn other_backends_keep_what_wgpu_says() {
        let info = wgpu::AdapterInfo {
            driver_info: "3.3".into(),
            ..wgpu::AdapterInfo::new(wgpu::DeviceType::Cpu, wgpu::Backend::Vulkan)
        };
        let caps = GpuCapabilities::new(&info, claimed());
        assert_eq!(caps.downlevel, claimed());
        assert!(caps.binding_layout && caps.gl_version.is_none());
    }
}
