//! wgpu glue for frame-sequential LOD: the LOD buffer pair (ping-pong) and the combine pass.
//!
//! Each frame the engine renders its scene into LOD buffer `scheduler.buffer_index()` (color at
//! location 0, the id word at location 1, the object motion at location 2, the buffer's own
//! depth attachment, see `lodkit::lod_buffer`), then records [`CombinePass::record`] with a
//! [`CombineFrame`] holding the matrix from
//! [`new_to_old_matrix`](crate::reproject::new_to_old_matrix) to write the final image into its
//! own target.

mod combine_bindings;
mod combine_pass;

pub use combine_pass::{
    CombineCoverage, CombineFrame, CombineParams, CombinePass, CombinePassDescriptor,
    CombineRegions,
};

use super::checks::target_extent;
use super::resources::{TextureSet, begin_targets_pass, new_set, resize_set, texture_2d};
use super::{GpuContext, GpuError};
use crate::lod_buffer::{ID_FORMAT, MOTION_FORMAT};

/// Depth format of each LOD buffer's depth attachment (the combine pass reads it).
pub const LOD_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Two LOD buffers, each a color target, an id target and the depth attachment it is rendered
/// with (read by the combine pass as the fragments' clip depth), and, unless built
/// [`without_motion`](Self::without_motion), one object motion target for the frame being
/// rendered (`MOTION_FORMAT`, location 2, see `lodkit::lod_buffer`).
#[derive(Debug)]
pub struct LodBuffers {
    color_format: wgpu::TextureFormat,
    size: (u32, u32),
    colors: [wgpu::Texture; 2],
    ids: [wgpu::Texture; 2],
    depths: [wgpu::Texture; 2],
    level_depth: wgpu::Texture,
    motion: Option<wgpu::Texture>,
}

impl TextureSet for LodBuffers {
    const USAGE: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
        .union(wgpu::TextureUsages::TEXTURE_BINDING)
        .union(wgpu::TextureUsages::COPY_SRC);

    fn allocate(
        gpu: &GpuContext,
        size: (u32, u32),
        color_format: wgpu::TextureFormat,
    ) -> Result<Self, GpuError> {
        Self::allocate_with(gpu, size, color_format, true)
    }

    fn allocate_like(&self, gpu: &GpuContext, size: (u32, u32)) -> Result<Self, GpuError> {
        Self::allocate_with(gpu, size, self.color_format, self.motion.is_some())
    }

    fn extent(&self) -> (u32, u32) {
        self.size
    }

    fn format(&self) -> wgpu::TextureFormat {
        self.color_format
    }

    fn textures(&self) -> Vec<&wgpu::Texture> {
        self.colors
            .iter()
            .chain(&self.ids)
            .chain(&self.depths)
            .chain([&self.level_depth])
            .chain(&self.motion)
            .collect()
    }
}

impl LodBuffers {
    /// Every texture at `size` (already checked), the motion target if `motion`.
    fn allocate_with(
        gpu: &GpuContext,
        size: (u32, u32),
        color_format: wgpu::TextureFormat,
        motion: bool,
    ) -> Result<Self, GpuError> {
        let texture = |format, usage, label| texture_2d(gpu, size, format, usage, label);
        let usage = Self::USAGE;
        Ok(Self {
            color_format,
            size,
            colors: [
                texture(color_format, usage, "lod buffer color 0")?,
                texture(color_format, usage, "lod buffer color 1")?,
            ],
            ids: [
                texture(ID_FORMAT, usage, "lod buffer id 0")?,
                texture(ID_FORMAT, usage, "lod buffer id 1")?,
            ],
            depths: [
                texture(LOD_DEPTH_FORMAT, usage, "lod buffer depth 0")?,
                texture(LOD_DEPTH_FORMAT, usage, "lod buffer depth 1")?,
            ],
            level_depth: texture(LOD_DEPTH_FORMAT, usage, "older-level depth pass")?,
            motion: match motion {
                true => Some(texture(MOTION_FORMAT, usage, "lod buffer object motion")?),
                false => None,
            },
        })
    }

    /// Allocates both buffers at `width` x `height` (a zero side is taken as 1) with color format
    /// `color_format`, a floating-point color format the device can render to, sample and copy,
    /// and the object motion target: 8 bytes per pixel per buffer with an RGBA8 color, 4 more for
    /// the motion, beyond the two depth attachments and the older-level depth pass's
    /// ([`level_depth`](Self::level_depth)).
    pub fn new(
        gpu: &GpuContext,
        width: u32,
        height: u32,
        color_format: wgpu::TextureFormat,
    ) -> Result<Self, GpuError> {
        new_set(gpu, "LodBuffers::new", (width, height), color_format)
    }

    /// [`new`](Self::new) without the object motion target, for scenes where nothing moves by
    /// itself (the camera's motion is the combine's reprojection) or engines that pass motion
    /// vectors of their own to `combine_at_moved`: 8 bytes per pixel per buffer with an RGBA8
    /// color beyond its depth attachment, and the older-level depth pass's target. The reference
    /// LOD pass writes no motion into them and the combine pass reads none (a t-instance that
    /// moves by itself is read where it is now).
    pub fn without_motion(
        gpu: &GpuContext,
        width: u32,
        height: u32,
        color_format: wgpu::TextureFormat,
    ) -> Result<Self, GpuError> {
        const CALL: &str = "LodBuffers::without_motion";
        let size = target_extent(gpu, CALL, (width, height), color_format, Self::USAGE)?;
        gpu.guarded(CALL, || Self::allocate_with(gpu, size, color_format, false))
    }

    /// Reallocates at a new size, with or without the motion target as before (a no-op at the
    /// same size; a zero side is taken as 1). The old textures are destroyed once the new ones
    /// exist; on an error the buffers are unchanged.
    pub fn resize(&mut self, gpu: &GpuContext, width: u32, height: u32) -> Result<(), GpuError> {
        resize_set(gpu, "LodBuffers::resize", self, (width, height))
    }

    /// Width and height.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// Format of the color textures.
    pub fn color_format(&self) -> wgpu::TextureFormat {
        self.color_format
    }

    /// Color texture of buffer `index` (0 or 1).
    pub fn color(&self, index: usize) -> &wgpu::Texture {
        &self.colors[index % 2]
    }

    /// Id texture (`ID_FORMAT`, the id words) of buffer `index`.
    pub fn id(&self, index: usize) -> &wgpu::Texture {
        &self.ids[index % 2]
    }

    /// Depth attachment of buffer `index` (`LOD_DEPTH_FORMAT`).
    pub fn depth(&self, index: usize) -> &wgpu::Texture {
        &self.depths[index % 2]
    }

    /// The older-level depth pass's target (`LOD_DEPTH_FORMAT`, the buffers' size): lodkit's
    /// default route to the older levels' coverage. Each frame of a transition, draw every
    /// t-instance's older level (`TransitionScheduler::older`) whole, with this frame's camera,
    /// transform and vertex animation and its alpha test, depth only, into
    /// [`begin_level_depth_pass`](Self::begin_level_depth_pass) (an engine's depth prepass
    /// pipeline does it), and pass it as `CombineCoverage::Known::level_depth` with
    /// [`CombineData::depth_pass`](crate::combine_coverage::CombineData::depth_pass).
    pub fn level_depth(&self) -> &wgpu::Texture {
        &self.level_depth
    }

    /// The object motion target (`MOTION_FORMAT`): written by the frame rendered last, read by
    /// its combine; `None` for buffers built [`without_motion`](Self::without_motion).
    pub fn motion(&self) -> Option<&wgpu::Texture> {
        self.motion.as_ref()
    }

    /// Begins a render pass into buffer `index` that clears color to `clear`, the id and the
    /// object motion (location 2, when there is a target) to 0 and the depth attachment to
    /// `far_depth` (1 for standard Z, 0 for reversed).
    /// `occlusion_query_set` is passed on to the pass (see
    /// [`FragmentCounter`](super::counters::FragmentCounter)).
    pub fn begin_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        index: usize,
        clear: wgpu::Color,
        far_depth: f32,
        occlusion_query_set: Option<&wgpu::QuerySet>,
    ) -> wgpu::RenderPass<'e> {
        let color = self.colors[index % 2].create_view(&Default::default());
        let id = self.ids[index % 2].create_view(&Default::default());
        let depth = self.depths[index % 2].create_view(&Default::default());
        let motion = self
            .motion
            .as_ref()
            .map(|m| m.create_view(&Default::default()));
        let zero = wgpu::Color::TRANSPARENT;
        let mut targets = vec![(&color, clear), (&id, zero)];
        targets.extend(motion.as_ref().map(|m| (m, zero)));
        begin_targets_pass(
            encoder,
            &targets,
            &depth,
            far_depth,
            occlusion_query_set,
            "lod buffer",
        )
    }

    /// Begins the older-level depth pass: a depth-only render pass into
    /// [`level_depth`](Self::level_depth), cleared to `far_depth` (1 for standard Z, 0 for
    /// reversed), with no color target. Draw with the depth test of the LOD pass, the same
    /// vertex stage (its clip positions are what the combine compares with the LOD pass's
    /// coverage; where a driver may compute them otherwise in two pipelines, the position's
    /// `@invariant`, on the targets that take it: not GLSL ES 3.0 or MSL before 2.1) and no
    /// visibility pattern.
    pub fn begin_level_depth_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        far_depth: f32,
        occlusion_query_set: Option<&wgpu::QuerySet>,
    ) -> wgpu::RenderPass<'e> {
        let depth = self.level_depth.create_view(&Default::default());
        begin_targets_pass(
            encoder,
            &[],
            &depth,
            far_depth,
            occlusion_query_set,
            "older-level depth pass",
        )
    }
}

/// Reads buffer `index` of `buffers` back to the CPU, with the object motion target (which holds
/// the motion of the buffer rendered last; none for buffers without one). Its color format must
/// be RGBA8, unorm or sRGB ([`GpuError::UnsupportedFormat`] otherwise).
pub fn read_lod_image(
    gpu: &GpuContext,
    buffers: &LodBuffers,
    index: usize,
) -> Result<crate::combine::LodImage, GpuError> {
    use wgpu::TextureFormat::{Rgba8Unorm, Rgba8UnormSrgb};
    if !matches!(buffers.color_format(), Rgba8Unorm | Rgba8UnormSrgb) {
        return Err(GpuError::UnsupportedFormat {
            call: "read_lod_image",
            parameter: "buffers",
            format: buffers.color_format(),
            reason: "LodImage holds RGBA8 colors; read other formats with readback::read_texture"
                .into(),
        });
    }
    let (colors, ids, depths, motion) = gpu.guarded("read_lod_image", || {
        use super::readback::{read_depth32, read_texture, read_texture_rgba8};
        Ok((
            read_texture_rgba8(gpu, buffers.color(index))?,
            read_texture(gpu, buffers.id(index), 4)?,
            read_depth32(gpu, buffers.depth(index))?,
            match buffers.motion() {
                Some(m) => read_texture(gpu, m, 4)?,
                None => Vec::new(),
            },
        ))
    })?;
    let words = |bytes: Vec<u8>| -> Vec<u32> {
        bytes
            .chunks(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    };
    let ids = words(ids);
    let (width, height) = buffers.size();
    Ok(crate::combine::LodImage {
        width,
        height,
        colors: colors
            .chunks(4)
            .map(|c| glam::Vec4::new(c[0] as f32, c[1] as f32, c[2] as f32, c[3] as f32) / 255.0)
            .collect(),
        ids: ids
            .iter()
            .map(|w| crate::lod_buffer::lod_buffer_id(*w))
            .collect(),
        flags: ids
            .iter()
            .map(|w| crate::lod_buffer::lod_buffer_flags(*w))
            .collect(),
        depths,
        motion: motion
            .chunks(4)
            .map(|c| {
                let half = |lo: u8, hi: u8| half::f16::from_le_bytes([lo, hi]).to_f32();
                glam::Vec2::new(half(c[0], c[1]), half(c[2], c[3]))
            })
            .collect(),
    })
}
