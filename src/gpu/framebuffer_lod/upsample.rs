//! [`UpsamplePass`]: full-resolution color from the low-resolution buffer L and a full-resolution
//! depth/normal prepass (`passes/upsample.wgsl`, eq. 1), built from a descriptor and recorded
//! with a per-recording description, any number of times per encoder.

use super::LowResBuffer;
use crate::gbuffer::GEOMETRY_FORMAT;
use crate::gpu::checks::{check_color_format, texture_matches};
use crate::gpu::resources::{
    BindGroupCache, RecordedUniform, begin_color_pass, fullscreen_pipeline, textures_and_uniform,
};
use crate::gpu::{GpuContext, GpuError};

/// Rust mirror of `UpsampleParams` in `passes/upsample.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct UpsampleParams {
    /// Size of L's viewport this frame.
    pub low_viewport: [f32; 2],
    /// Size of the full-resolution target.
    pub full_size: [f32; 2],
    /// Depth range sigma, a fraction of the pixel's view depth (`bilateral_relative_sigma`;
    /// `BILATERAL_SIGMA_OFF`: no depth term).
    pub sigma_z: f32,
    /// Normal range sigma (`BILATERAL_SIGMA_OFF`: no normal term).
    pub sigma_n: f32,
    /// Padding.
    pub pad: [f32; 2],
}

/// How L holds what the upsample reads.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LowResLayout {
    /// Color and geometry in two textures ([`LowResBuffer::new`]): 9 texel loads per pixel.
    #[default]
    ColorAndGeometry,
    /// `lodkit::gbuffer`'s packed texel ([`LowResBuffer::packed`]): 5 loads per pixel, HDR
    /// color kept as halves. Faster on a software rasterizer, slower on an NVIDIA H200
    /// (docs/framebuffer-lod.md says where each wins).
    Packed,
}

/// What the pass writes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum UpsampleComposite {
    /// The upsampled L.
    #[default]
    Upsampled,
    /// The upsampled L times a full-resolution albedo ([`UpsampleFrame::full_albedo`]): the
    /// composite of fine-grained resizing (the paper's sec. 4), where L holds only the
    /// expensive term (lighting).
    TimesAlbedo,
}

/// How to build an [`UpsamplePass`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UpsamplePassDescriptor {
    /// Format of the targets it draws into (a color format the device renders to).
    pub target_format: wgpu::TextureFormat,
    /// Layout of the L it reads.
    pub low_res: LowResLayout,
    /// What it writes.
    pub composite: UpsampleComposite,
}

impl Default for UpsamplePassDescriptor {
    /// `Rgba16Float` targets, L as color and geometry, the upsampled L.
    fn default() -> Self {
        Self {
            target_format: wgpu::TextureFormat::Rgba16Float,
            low_res: LowResLayout::default(),
            composite: UpsampleComposite::default(),
        }
    }
}

pub use crate::bilateral::RangeSigmas;

/// The parameters of one recording.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UpsampleSettings {
    /// The resize factor L was rendered at (>= 1; its viewport is L's full size / r).
    pub r: f32,
    /// The range filters.
    pub sigmas: RangeSigmas,
}

impl Default for UpsampleSettings {
    /// r = 2, the default sigmas.
    fn default() -> Self {
        Self {
            r: 2.0,
            sigmas: RangeSigmas::default(),
        }
    }
}

/// What one recording reads and writes.
#[derive(Clone, Copy, Debug)]
pub struct UpsampleFrame<'a> {
    /// L, rendered at `settings.r`, in the layout the pass was built for.
    pub low: &'a LowResBuffer,
    /// The full-resolution geometry (`GEOMETRY_FORMAT`, L's full size): the prepass's.
    pub full_geometry: &'a wgpu::Texture,
    /// The full-resolution albedo of [`UpsampleComposite::TimesAlbedo`] (L's full size; L's
    /// color format, or for a packed L the target's), `None` otherwise.
    pub full_albedo: Option<&'a wgpu::Texture>,
    /// The target: the pass's format, L's full size.
    pub target: &'a wgpu::TextureView,
    /// This recording's parameters.
    pub settings: UpsampleSettings,
}

/// The upsample pass (`passes/upsample.wgsl`): full-resolution color from L and a full-resolution
/// depth/normal prepass, eq. 1 (with [`RangeSigmas::OFF`], bilinear). Its parameters are written
/// into the encoder with each recording, so one encoder may hold any number of recordings, each
/// with its own parameters. A recording creates no bind group while the textures it binds are
/// those of one of the last four recordings (it keeps their bind groups, and with them the
/// textures).
#[derive(Debug)]
pub struct UpsamplePass {
    pipeline: wgpu::RenderPipeline,
    params: RecordedUniform,
    groups: BindGroupCache,
    desc: UpsamplePassDescriptor,
}

/// Bind groups an [`UpsamplePass`] keeps: a few targets or L buffers in turn.
const KEPT_GROUPS: usize = 4;

impl UpsamplePass {
    /// Builds the pipeline. Errors: a target format the device cannot render to.
    pub fn new(gpu: &GpuContext, desc: &UpsamplePassDescriptor) -> Result<Self, GpuError> {
        const CALL: &str = "UpsamplePass::new";
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        check_color_format(gpu, CALL, "target_format", desc.target_format, usage)?;
        gpu.guarded(CALL, || {
            let defs: Vec<&str> = [
                (desc.composite == UpsampleComposite::TimesAlbedo)
                    .then_some("LODKIT_UPSAMPLE_MODULATE"),
                (desc.low_res == LowResLayout::Packed).then_some("LODKIT_UPSAMPLE_PACKED"),
            ]
            .into_iter()
            .flatten()
            .collect();
            let module = gpu.pass_module("upsample", &defs)?;
            let size = std::mem::size_of::<UpsampleParams>();
            Ok(Self {
                pipeline: fullscreen_pipeline(gpu, &module, desc.target_format, "lodkit upsample")?,
                params: RecordedUniform::new(gpu, size, "upsample params")?,
                groups: BindGroupCache::new(KEPT_GROUPS),
                desc: *desc,
            })
        })
    }

    /// What the pass was built with.
    pub fn descriptor(&self) -> &UpsamplePassDescriptor {
        &self.desc
    }

    /// Records one upsampling into `encoder`. Errors ([`GpuError::Mismatch`]): an L of another
    /// layout than the pass was built for, an albedo given to a pass without
    /// [`UpsampleComposite::TimesAlbedo`] or missing from one with it, textures of another size
    /// or format than the fields say; ([`GpuError::Invalid`]) a sigma that is NaN or not
    /// positive.
    pub fn record(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        frame: &UpsampleFrame,
    ) -> Result<(), GpuError> {
        const CALL: &str = "UpsamplePass::record";
        let low = frame.low;
        let packed = self.desc.low_res == LowResLayout::Packed;
        if low.is_packed() != packed {
            let (built, wanted) = match packed {
                true => ("for a packed L", "LowResBuffer::packed"),
                false => ("for an unpacked L", "LowResBuffer::new"),
            };
            return Err(GpuError::Mismatch {
                call: CALL,
                parameter: "frame.low",
                found: format!("an L that does not match a pass built {built}"),
                expected: format!("an L from {wanted}"),
            });
        }
        let modulate = self.desc.composite == UpsampleComposite::TimesAlbedo;
        if frame.full_albedo.is_some() != modulate {
            let (found, expected) = match modulate {
                true => (
                    "no albedo",
                    "the full-resolution albedo the composite multiplies by",
                ),
                false => ("an albedo", "none: the pass was built without TimesAlbedo"),
            };
            return Err(GpuError::Mismatch {
                call: CALL,
                parameter: "frame.full_albedo",
                found: found.to_owned(),
                expected: expected.to_owned(),
            });
        }
        let mut textures = match packed {
            true => vec![low.color(), frame.full_geometry],
            false => vec![low.color(), low.geometry(), frame.full_geometry],
        };
        if let Some(albedo) = frame.full_albedo {
            let format = match packed {
                true => self.desc.target_format,
                false => low.color_format(),
            };
            let what = "L's full size, and L's color format (a packed L: the target's)";
            let size = low.full_size();
            texture_matches(CALL, "frame.full_albedo", albedo, size, format, what)?;
            textures.push(albedo);
        }
        let sigmas = frame.settings.sigmas;
        for (parameter, value) in [
            ("frame.settings.sigmas.depth", sigmas.depth),
            ("frame.settings.sigmas.normal", sigmas.normal),
        ] {
            if value.is_nan() || value <= 0.0 {
                return Err(GpuError::Invalid {
                    call: CALL,
                    parameter,
                    value: value.to_string(),
                    rule: "must be positive (+inf: no range term)",
                });
            }
        }
        let size = low.full_size();
        let what = "the full-resolution geometry of L";
        let geometry = frame.full_geometry;
        texture_matches(
            CALL,
            "frame.full_geometry",
            geometry,
            size,
            GEOMETRY_FORMAT,
            what,
        )?;
        let what = "the pass (built for its format, drawing L's full size)";
        let format = self.desc.target_format;
        texture_matches(
            CALL,
            "frame.target",
            frame.target.texture(),
            size,
            format,
            what,
        )?;
        gpu.recording(CALL, || {
            let (vw, vh) = low.viewport(frame.settings.r);
            let (w, h) = low.full_size();
            let params = UpsampleParams {
                low_viewport: [vw as f32, vh as f32],
                full_size: [w as f32, h as f32],
                // +inf (no range term) goes to the shader as a finite sigma that does the same.
                sigma_z: crate::bilateral::gpu_sigma(sigmas.depth),
                sigma_n: crate::bilateral::gpu_sigma(sigmas.normal),
                pad: [0.0; 2],
            };
            self.params.write(encoder, &params)?;
            let bind_group = self.groups.get_or_make(&textures, &[], || {
                let layout = self.pipeline.get_bind_group_layout(0);
                let uniform = Some(self.params.buffer());
                textures_and_uniform(gpu, &layout, &textures, uniform, "lodkit upsample")
            })?;
            let target = frame.target;
            let mut pass = begin_color_pass(encoder, target, wgpu::Color::BLACK, "lodkit upsample");
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.draw(0..3, 0..1);
            Ok(())
        })
    }
}
