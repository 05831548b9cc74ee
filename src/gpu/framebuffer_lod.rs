//! wgpu glue for geometry-aware framebuffer LOD: the low-resolution buffer L, allocated once at
//! full size and rendered through a viewport that shrinks with r (changing r never reallocates),
//! and the upsample pass as a ready object.

use super::checks::{check_format_usages, texture_extent};
use super::resources::{TextureSet, begin_targets_pass, new_set, resize_set, texture_2d};
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
    /// an [`UpsamplePass`] built with [`LowResLayout::Packed`] or `bilateral_upsample_packed_at`
    /// in your own composite pass.
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
        crate::framebuffer_lod::low_res_size(self.full_size, r)
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

mod upsample;
pub use upsample::{
    LowResLayout, RangeSigmas, UpsampleComposite, UpsampleFrame, UpsampleParams, UpsamplePass,
    UpsamplePassDescriptor, UpsampleSettings,
};
