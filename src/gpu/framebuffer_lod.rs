//! wgpu glue for geometry-aware framebuffer LOD: the low-resolution buffer L, allocated once at
//! full size and rendered through a viewport that shrinks with r (changing r never reallocates),
//! and the upsample pass as a ready object.

use super::error::{check_color_format, check_format_usages, texture_extent, texture_matches};
use super::resources::{
    TextureSet, begin_color_pass, begin_targets_pass, fullscreen_pipeline, new_set, resize_set,
    texture_2d, textures_and_uniform, uniform_buffer,
};
use super::{GpuContext, GpuError};
use crate::gbuffer::{GEOMETRY_FORMAT, PACKED_FORMAT, gbuffer_pack_texel};

/// Depth format of the low-resolution pass.
pub const LOW_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The low-resolution buffer L: color, geometry (view depth, normal) and depth, all at full size;
/// frames render into the top-left `viewport(r)` of them. A packed L ([`LowResBuffer::packed`])
/// holds color and geometry in one [`PACKED_FORMAT`] texture (`lodkit::gbuffer`'s packed layout),
/// which the upsampler reads once per cell corner.
#[derive(Debug)]
pub struct LowResBuffer {
    full_size: (u32, u32),
    color_format: wgpu::TextureFormat,
    color: wgpu::Texture,
    geometry: Option<wgpu::Texture>,
    depth: wgpu::Texture,
}

impl TextureSet for LowResBuffer {
    const USAGE: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
        .union(wgpu::TextureUsages::TEXTURE_BINDING)
        .union(wgpu::TextureUsages::COPY_SRC);

    fn allocate(
        gpu: &GpuContext,
        size: (u32, u32),
        color_format: wgpu::TextureFormat,
    ) -> Result<Self, GpuError> {
        let usage = Self::USAGE;
        let depth_usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let packed = color_format == PACKED_FORMAT;
        let geometry = match packed {
            true => None,
            false => Some(texture_2d(
                gpu,
                size,
                GEOMETRY_FORMAT,
                usage,
                "low-res geometry",
            )?),
        };
        let label = if packed {
            "low-res packed"
        } else {
            "low-res color"
        };
        Ok(Self {
            full_size: size,
            color_format,
            color: texture_2d(gpu, size, color_format, usage, label)?,
            geometry,
            depth: texture_2d(gpu, size, LOW_DEPTH_FORMAT, depth_usage, "low-res depth")?,
        })
    }

    fn extent(&self) -> (u32, u32) {
        self.full_size
    }

    fn format(&self) -> wgpu::TextureFormat {
        self.color_format
    }

    fn textures(&self) -> Vec<&wgpu::Texture> {
        [Some(&self.color), self.geometry.as_ref(), Some(&self.depth)]
            .into_iter()
            .flatten()
            .collect()
    }
}

impl LowResBuffer {
    /// Allocates L for a `width` x `height` target (a zero side is taken as 1) with color format
    /// `color_format`, a floating-point color format the device can render to, sample and copy.
    pub fn new(
        gpu: &GpuContext,
        width: u32,
        height: u32,
        color_format: wgpu::TextureFormat,
    ) -> Result<Self, GpuError> {
        new_set(gpu, "LowResBuffer::new", (width, height), color_format)
    }

    /// Allocates a packed L for a `width` x `height` target (a zero side is taken as 1): one
    /// [`PACKED_FORMAT`] texture holding `lodkit::gbuffer`'s packed texel (color as half floats,
    /// HDR kept; view depth; the foreshortened normal), 16 bytes per pixel. Draw into it with a
    /// shader returning `gbuffer_pack_texel(...)` at location 0, and upsample it with
    /// [`UpsamplePass::packed`] or `bilateral_upsample_packed_at` in your own composite pass.
    pub fn packed(gpu: &GpuContext, width: u32, height: u32) -> Result<Self, GpuError> {
        const CALL: &str = "LowResBuffer::packed";
        let size = texture_extent(gpu, CALL, width, height)?;
        check_format_usages(gpu, CALL, "PACKED_FORMAT", PACKED_FORMAT, Self::USAGE)?;
        gpu.guarded(CALL, || Self::allocate(gpu, size, PACKED_FORMAT))
    }

    /// Whether L is packed ([`LowResBuffer::packed`]).
    pub fn is_packed(&self) -> bool {
        self.geometry.is_none()
    }

    /// Reallocates for a new target size (a no-op at the same size; a zero side is taken as 1).
    /// The old textures are destroyed once the new ones exist; on an error L is unchanged.
    pub fn resize(&mut self, gpu: &GpuContext, width: u32, height: u32) -> Result<(), GpuError> {
        resize_set(gpu, "LowResBuffer::resize", self, (width, height))
    }

    /// Size of the full-resolution target.
    pub fn full_size(&self) -> (u32, u32) {
        self.full_size
    }

    /// Format of the color texture.
    pub fn color_format(&self) -> wgpu::TextureFormat {
        self.color_format
    }

    /// The part of L used at resize factor `r` (clamped to >= 1): ceil(size / r).
    ///
    /// Changing r only changes this viewport; the textures stay.
    pub fn viewport(&self, r: f32) -> (u32, u32) {
        let r = if r.is_finite() { r.max(1.0) } else { 1.0 };
        let (w, h) = self.full_size;
        (
            ((w as f32 / r).ceil() as u32).clamp(1, w),
            ((h as f32 / r).ceil() as u32).clamp(1, h),
        )
    }

    /// Color texture (of a packed L: the packed texture).
    pub fn color(&self) -> &wgpu::Texture {
        &self.color
    }

    /// Geometry texture (view depth, normal); of a packed L, the packed texture, which holds the
    /// geometry too.
    pub fn geometry(&self) -> &wgpu::Texture {
        self.geometry.as_ref().unwrap_or(&self.color)
    }

    /// Begins the low-resolution pass at resize factor `r`: clears color to `clear`, geometry to
    /// (far_view_depth, 0, 0, 1) and depth to 1 (a packed L: its texel to the packing of
    /// these), and sets the viewport and scissor to [`viewport(r)`](Self::viewport).
    pub fn begin_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        r: f32,
        clear: wgpu::Color,
        far_view_depth: f32,
    ) -> wgpu::RenderPass<'e> {
        let color = self.color.create_view(&Default::default());
        let depth = self.depth.create_view(&Default::default());
        let geometry = self
            .geometry
            .as_ref()
            .map(|g| g.create_view(&Default::default()));
        let geometry_clear = wgpu::Color {
            r: f64::from(far_view_depth),
            g: 0.0,
            b: 0.0,
            a: 1.0,
        };
        let targets = match &geometry {
            Some(geometry) => vec![(&color, clear), (geometry, geometry_clear)],
            None => {
                let c = [clear.r, clear.g, clear.b, clear.a].map(|v| v as f32);
                let t = gbuffer_pack_texel(c.into(), far_view_depth, glam::Vec3::Z);
                let [r, g, b, a] = t.to_array().map(f64::from);
                vec![(&color, wgpu::Color { r, g, b, a })]
            }
        };
        let mut pass = begin_targets_pass(encoder, &targets, &depth, 1.0, None, "low-res pass");
        let (w, h) = self.viewport(r);
        pass.set_viewport(0.0, 0.0, w as f32, h as f32, 0.0, 1.0);
        pass.set_scissor_rect(0, 0, w, h);
        pass
    }
}

/// Rust mirror of `UpsampleParams` in `passes/upsample.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct UpsampleParams {
    /// Size of L's viewport this frame.
    pub low_viewport: [f32; 2],
    /// Size of the full-resolution target.
    pub full_size: [f32; 2],
    /// Depth range sigma (world units; +inf: no depth term).
    pub sigma_z: f32,
    /// Normal range sigma (+inf: no normal term).
    pub sigma_n: f32,
    /// Padding.
    pub pad: [f32; 2],
}

/// The upsample pass (`passes/upsample.wgsl`): full-res color from L and a full-res depth/normal
/// prepass. With both sigmas +inf it is a plain bilinear upsample. Built with
/// [`fine_grained`](Self::fine_grained), it also multiplies by a full-resolution albedo: the
/// composite of fine-grained resizing, in the same pass. Built with [`packed`](Self::packed) or
/// [`packed_fine_grained`](Self::packed_fine_grained), it reads a packed L
/// ([`LowResBuffer::packed`]): 4 low-resolution texel loads per pixel instead of 8.
#[derive(Debug)]
pub struct UpsamplePass {
    pipeline: wgpu::RenderPipeline,
    params: wgpu::Buffer,
    target_format: wgpu::TextureFormat,
    modulate: bool,
    packed: bool,
}

impl UpsamplePass {
    /// Builds the pipeline for targets of `target_format` (a floating-point color format the
    /// device can render to).
    pub fn new(gpu: &GpuContext, target_format: wgpu::TextureFormat) -> Result<Self, GpuError> {
        Self::build(gpu, "UpsamplePass::new", target_format, false, false)
    }

    /// [`new`](Self::new) for a packed L ([`LowResBuffer::packed`]).
    pub fn packed(gpu: &GpuContext, target_format: wgpu::TextureFormat) -> Result<Self, GpuError> {
        Self::build(gpu, "UpsamplePass::packed", target_format, false, true)
    }

    /// [`fine_grained`](Self::fine_grained) for a packed L ([`LowResBuffer::packed`]): the
    /// composite of fine-grained resizing with the upsample folded in (4 low-resolution loads).
    pub fn packed_fine_grained(
        gpu: &GpuContext,
        target_format: wgpu::TextureFormat,
    ) -> Result<Self, GpuError> {
        const CALL: &str = "UpsamplePass::packed_fine_grained";
        Self::build(gpu, CALL, target_format, true, true)
    }

    /// [`new`](Self::new) for fine-grained resizing (the paper's sec. 4): L holds only the
    /// expensive term (lighting), and [`encode_fine_grained`](Self::encode_fine_grained)
    /// multiplies its upsampling by a full-resolution albedo in the same pass.
    pub fn fine_grained(
        gpu: &GpuContext,
        target_format: wgpu::TextureFormat,
    ) -> Result<Self, GpuError> {
        Self::build(
            gpu,
            "UpsamplePass::fine_grained",
            target_format,
            true,
            false,
        )
    }

    fn build(
        gpu: &GpuContext,
        call: &'static str,
        target_format: wgpu::TextureFormat,
        modulate: bool,
        packed: bool,
    ) -> Result<Self, GpuError> {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        check_color_format(gpu, call, "target_format", target_format, usage)?;
        gpu.guarded(call, || {
            let defs: Vec<&str> = [
                modulate.then_some("LODKIT_UPSAMPLE_MODULATE"),
                packed.then_some("LODKIT_UPSAMPLE_PACKED"),
            ]
            .into_iter()
            .flatten()
            .collect();
            let module = gpu.pass_module("upsample", &defs)?;
            let size = std::mem::size_of::<UpsampleParams>();
            Ok(Self {
                pipeline: fullscreen_pipeline(gpu, &module, target_format, "lodkit upsample")?,
                params: uniform_buffer(gpu, size, "upsample params")?,
                target_format,
                modulate,
                packed,
            })
        })
    }

    /// Records the upsampling of `low` (rendered at resize factor `r`) into `target`, with the
    /// full-resolution geometry `full_geometry` (gbuffer layout) and range sigmas (each > 0;
    /// +inf drops its term). `target` must have the format the pass was built for and, like
    /// `full_geometry` (in `GEOMETRY_FORMAT`), L's full size: [`GpuError::Mismatch`] otherwise.
    /// The parameters go through one uniform buffer: record one `encode` per submit. A pass
    /// built with [`fine_grained`](Self::fine_grained) takes
    /// [`encode_fine_grained`](Self::encode_fine_grained) instead ([`GpuError::Mismatch`]).
    #[allow(clippy::too_many_arguments)]
    pub fn encode(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        low: &LowResBuffer,
        r: f32,
        full_geometry: &wgpu::Texture,
        sigma_z: f32,
        sigma_n: f32,
        target: &wgpu::TextureView,
    ) -> Result<(), GpuError> {
        const CALL: &str = "UpsamplePass::encode";
        let sigmas = (sigma_z, sigma_n);
        let full = (full_geometry, None);
        self.record(gpu, CALL, encoder, low, r, full, sigmas, target)
    }

    /// [`encode`](Self::encode) for a pass built with [`fine_grained`](Self::fine_grained):
    /// the upsampled L (the lighting) times `full_albedo`, a texture of L's full size and L's
    /// color format (the albedo pass that also wrote `full_geometry`; for a packed L, the
    /// target's format). [`GpuError::Mismatch`] on a pass built without fine-grained resizing,
    /// or for an albedo of another size or format.
    #[allow(clippy::too_many_arguments)]
    pub fn encode_fine_grained(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        low: &LowResBuffer,
        r: f32,
        full_geometry: &wgpu::Texture,
        full_albedo: &wgpu::Texture,
        sigma_z: f32,
        sigma_n: f32,
        target: &wgpu::TextureView,
    ) -> Result<(), GpuError> {
        const CALL: &str = "UpsamplePass::encode_fine_grained";
        let sigmas = (sigma_z, sigma_n);
        let full = (full_geometry, Some(full_albedo));
        self.record(gpu, CALL, encoder, low, r, full, sigmas, target)
    }

    /// Checks and records one upsampling of `low` with the full geometry and, when the pass
    /// modulates, the albedo.
    #[allow(clippy::too_many_arguments)]
    fn record(
        &self,
        gpu: &GpuContext,
        call: &'static str,
        encoder: &mut wgpu::CommandEncoder,
        low: &LowResBuffer,
        r: f32,
        (full_geometry, albedo): (&wgpu::Texture, Option<&wgpu::Texture>),
        (sigma_z, sigma_n): (f32, f32),
        target: &wgpu::TextureView,
    ) -> Result<(), GpuError> {
        // The encode call and L's layout must match how the pass was built.
        if low.is_packed() != self.packed {
            let (built, wanted) = match self.packed {
                true => ("for a packed L", "LowResBuffer::packed"),
                false => ("for an unpacked L", "LowResBuffer::new"),
            };
            return Err(GpuError::Mismatch {
                call,
                parameter: "low",
                found: format!("an L that does not match a pass built {built}"),
                expected: format!("an L from {wanted}"),
            });
        }
        if albedo.is_some() != self.modulate {
            let (built, wanted) = match self.modulate {
                true => ("for fine-grained resizing", "encode_fine_grained"),
                false => ("without fine-grained resizing", "encode"),
            };
            return Err(GpuError::Mismatch {
                call,
                parameter: "self",
                found: format!("a pass built {built}"),
                expected: format!("record it with UpsamplePass::{wanted}"),
            });
        }
        let mut textures = match low.is_packed() {
            true => vec![low.color(), full_geometry],
            false => vec![low.color(), low.geometry(), full_geometry],
        };
        if let Some(albedo) = albedo {
            let format = match low.is_packed() {
                true => self.target_format,
                false => low.color_format(),
            };
            let what = "L's full size, and L's color format (a packed L: the target's)";
            texture_matches(call, "full_albedo", albedo, low.full_size(), format, what)?;
            textures.push(albedo);
        }
        for (parameter, value) in [("sigma_z", sigma_z), ("sigma_n", sigma_n)] {
            if value.is_nan() || value <= 0.0 {
                return Err(GpuError::Invalid {
                    call,
                    parameter,
                    value: value.to_string(),
                    rule: "must be positive (+inf: no range term)",
                });
            }
        }
        let size = low.full_size();
        let what = "the full-resolution geometry of L";
        texture_matches(
            call,
            "full_geometry",
            full_geometry,
            size,
            GEOMETRY_FORMAT,
            what,
        )?;
        let what = "the pass (built for its format, drawing L's full size)";
        texture_matches(
            call,
            "target",
            target.texture(),
            size,
            self.target_format,
            what,
        )?;
        gpu.guarded(call, || {
            let (vw, vh) = low.viewport(r);
            let (w, h) = low.full_size();
            let params = UpsampleParams {
                low_viewport: [vw as f32, vh as f32],
                full_size: [w as f32, h as f32],
                // +inf (no range term) goes to the shader as a finite sigma that does the same.
                sigma_z: crate::bilateral::gpu_sigma(sigma_z),
                sigma_n: crate::bilateral::gpu_sigma(sigma_n),
                pad: [0.0; 2],
            };
            gpu.queue
                .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
            let layout = self.pipeline.get_bind_group_layout(0);
            let bind_group = textures_and_uniform(
                gpu,
                &layout,
                &textures,
                Some(&self.params),
                "lodkit upsample",
            )?;
            let mut pass = begin_color_pass(encoder, target, wgpu::Color::BLACK, "lodkit upsample");
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.draw(0..3, 0..1);
            Ok(())
        })
    }
}
