//! wgpu glue for frame-sequential LOD: the LOD buffer pair (ping-pong) and the combine pass.
//!
//! Each frame the engine renders its scene into LOD buffer `scheduler.buffer_index()` (color at
//! location 0, the id word at location 1, the object motion at location 2, the buffer's own
//! depth attachment, see `lodkit::lod_buffer`), then calls [`CombinePass::encode`] (or
//! [`CombinePass::encode_regions`]) with the matrix from
//! [`new_to_old_matrix`](crate::reproject::new_to_old_matrix) to write the final image into its
//! own target.

use glam::Mat4;

use super::checks::{check_color_format, has_usage, target_extent, texture_matches};
use super::resources::{
    TextureSet, begin_color_pass, begin_load_pass, begin_targets_pass, fullscreen_pipeline_with,
    new_set, one_group_layout, resize_set, texture_2d, texture_entry, textures_and_uniform,
    uniform_buffer, uniform_entry,
};
use super::{GpuContext, GpuError};
use crate::combine::{ScreenRect, merge_rects};
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
            motion: match motion {
                true => Some(texture(MOTION_FORMAT, usage, "lod buffer object motion")?),
                false => None,
            },
        })
    }

    /// Allocates both buffers at `width` x `height` (a zero side is taken as 1) with color format
    /// `color_format`, a floating-point color format the device can render to, sample and copy,
    /// and the object motion target: 8 bytes per pixel per buffer with an RGBA8 color, 4 more for
    /// the motion, beyond the two depth attachments.
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
    /// color beyond its depth attachment, nothing else. The reference LOD pass writes no motion
    /// into them and the combine pass reads none (a t-instance that moves by itself is read
    /// where it is now).
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
}

/// Rust mirror of `CombineParams` in `passes/combine.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CombineParams {
    /// P_old V_old V_new^-1 P_new^-1, column-major.
    pub new_to_old: [[f32; 4]; 4],
}

/// The combine pass (`passes/combine.wgsl`) as a ready object: create once per target format,
/// call [`encode`](Self::encode) once per frame. Buffers with an object motion target are
/// combined with `combine_at_moved`; buffers without one
/// ([`LodBuffers::without_motion`]) with `combine_at` (`LODKIT_COMBINE_STILL`), which reads no
/// motion and whose 3x3 search the driver's compiler removes (the motion is a constant 0).
#[derive(Debug)]
pub struct CombinePass {
    pipeline: wgpu::RenderPipeline,
    /// The pipeline for buffers without object motion (`LODKIT_COMBINE_STILL`).
    still_pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    /// 1x1, zero: bound at the motion binding for buffers without a motion target.
    still: wgpu::Texture,
    target_format: wgpu::TextureFormat,
}

impl CombinePass {
    /// The `new_to_old` matrix for a frame with no usable older buffer (the first frame, after a
    /// resize or a camera cut): every pixel reprojects behind the older camera, so the newer
    /// buffer is shown as it is.
    pub const NO_HISTORY: Mat4 = Mat4::ZERO;

    /// Builds the pipeline for targets of `target_format` (a floating-point color format the
    /// device can render to); `reverse_z` selects the depth convention of the LOD buffers
    /// (`LODKIT_REVERSE_Z`).
    pub fn new(
        gpu: &GpuContext,
        target_format: wgpu::TextureFormat,
        reverse_z: bool,
    ) -> Result<Self, GpuError> {
        const CALL: &str = "CombinePass::new";
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        check_color_format(gpu, CALL, "target_format", target_format, usage)?;
        let reverse = reverse_z.then_some("LODKIT_REVERSE_Z");
        gpu.guarded(CALL, || {
            let size = std::mem::size_of::<CombineParams>();
            let mut entries = Self::buffer_layout_entries(0);
            entries.push(Self::motion_layout_entry(6));
            entries.push(uniform_entry(7, false));
            let (group, layout) = one_group_layout(gpu, &entries, "lodkit combine");
            let pipeline = |still: bool| {
                let defs: Vec<&str> = reverse
                    .into_iter()
                    .chain(still.then_some("LODKIT_COMBINE_STILL"))
                    .collect();
                let module = gpu.pass_module("combine", &defs)?;
                fullscreen_pipeline_with(
                    gpu,
                    &module,
                    target_format,
                    Some(&layout),
                    "lodkit combine",
                )
            };
            Ok(Self {
                pipeline: pipeline(false)?,
                still_pipeline: pipeline(true)?,
                layout: group,
                params: uniform_buffer(gpu, size, "combine params")?,
                still: texture_2d(
                    gpu,
                    (1, 1),
                    MOTION_FORMAT,
                    wgpu::TextureUsages::TEXTURE_BINDING,
                    "combine: no object motion",
                )?,
                target_format,
            })
        })
    }

    /// Bind group layout entries of the six LOD buffer textures the combine reads, from binding
    /// `first`: color, id and depth of the newer buffer, then of the older one. The depth
    /// attachments bind as unfilterable float textures (`texture_2d<f32>`), as
    /// `lodkit::combine::combine_at` reads them; a full-screen pass of the engine's that calls
    /// `combine_at` needs these (`combine_at_moved` also the motion, see
    /// [`motion_layout_entry`](Self::motion_layout_entry)).
    pub fn buffer_layout_entries(first: u32) -> Vec<wgpu::BindGroupLayoutEntry> {
        let float = wgpu::TextureSampleType::Float { filterable: false };
        let uint = wgpu::TextureSampleType::Uint;
        [float, uint, float, float, uint, float]
            .into_iter()
            .zip(first..)
            .map(|(t, binding)| texture_entry(binding, t))
            .collect()
    }

    /// Bind group layout entry of the object motion texture (`LodBuffers::motion`) at
    /// `binding`, read as an unfilterable float texture, for a pass of the engine's that calls
    /// `lodkit::combine::combine_at_moved`.
    pub fn motion_layout_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
        texture_entry(
            binding,
            wgpu::TextureSampleType::Float { filterable: false },
        )
    }

    /// Records the combination of buffer `newer` with the other one (reprojected through
    /// `new_to_old`) into `target`, which must have the format the pass was built for and the
    /// size of the buffers ([`GpuError::Mismatch`] otherwise). The parameters go through one
    /// uniform buffer written with `queue.write_buffer`: record one `encode` per submit (two in
    /// one encoder would both see the last matrix).
    pub fn encode(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        buffers: &LodBuffers,
        newer: usize,
        new_to_old: Mat4,
        target: &wgpu::TextureView,
    ) -> Result<(), GpuError> {
        self.check_target("CombinePass::encode", buffers, target)?;
        self.record(gpu, encoder, buffers, newer, new_to_old, target, None)
    }

    /// The target must have the pass's format and the buffers' size.
    fn check_target(
        &self,
        call: &'static str,
        buffers: &LodBuffers,
        target: &wgpu::TextureView,
    ) -> Result<(), GpuError> {
        texture_matches(
            call,
            "target",
            target.texture(),
            buffers.size(),
            self.target_format,
            "the pass (built for its format, drawing the LOD buffers' size)",
        )
    }

    /// The combine where it has work to do: copies buffer `newer`'s color into `target` (which
    /// needs `COPY_DST` besides what [`encode`](Self::encode) needs), then runs the combine only
    /// inside `regions`, the screen rectangles of the t-instances
    /// ([`screen_rect`](crate::combine::screen_rect), merged with
    /// [`merge_rects`]; overlapping rectangles are merged here
    /// too). With no region the frame is the copy: no combine, no read of the older buffer.
    /// Returns the pixels combined. An engine that can show the newer buffer's color directly
    /// skips the copy as well (see docs/frame-sequential.md).
    #[allow(clippy::too_many_arguments)]
    pub fn encode_regions(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        buffers: &LodBuffers,
        newer: usize,
        new_to_old: Mat4,
        target: &wgpu::TextureView,
        regions: &[ScreenRect],
    ) -> Result<u64, GpuError> {
        const CALL: &str = "CombinePass::encode_regions";
        let usage = target.texture().usage();
        let copy = wgpu::TextureUsages::COPY_DST;
        has_usage(CALL, "target", usage, usage.contains(copy), "COPY_DST")?;
        let (found, expected) = (buffers.color_format(), self.target_format);
        if found.remove_srgb_suffix() != expected.remove_srgb_suffix() {
            return Err(GpuError::Mismatch {
                call: CALL,
                parameter: "buffers",
                found: format!("{found:?} color"),
                expected: format!(
                    "{expected:?}, the target's format (the rest of the frame is a copy)"
                ),
            });
        }
        let (w, h) = buffers.size();
        let clipped: Vec<ScreenRect> = regions
            .iter()
            .filter_map(|r| {
                let (x1, y1) = (
                    r.x.saturating_add(r.width).min(w),
                    r.y.saturating_add(r.height).min(h),
                );
                (r.x < x1 && r.y < y1).then(|| ScreenRect {
                    x: r.x,
                    y: r.y,
                    width: x1 - r.x,
                    height: y1 - r.y,
                })
            })
            .collect();
        let merged = merge_rects(&clipped);
        self.check_target(CALL, buffers, target)?;
        gpu.guarded(CALL, || {
            encoder.copy_texture_to_texture(
                buffers.color(newer).as_image_copy(),
                target.texture().as_image_copy(),
                target.texture().size(),
            );
            Ok(())
        })?;
        if !merged.is_empty() {
            self.record(
                gpu,
                encoder,
                buffers,
                newer,
                new_to_old,
                target,
                Some(&merged),
            )?;
        }
        Ok(merged.iter().map(ScreenRect::area).sum())
    }

    /// Records the combine over the whole target, or inside `regions` over what is there (the
    /// target already checked).
    #[allow(clippy::too_many_arguments)]
    fn record(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        buffers: &LodBuffers,
        newer: usize,
        new_to_old: Mat4,
        target: &wgpu::TextureView,
        regions: Option<&[ScreenRect]>,
    ) -> Result<(), GpuError> {
        gpu.guarded("CombinePass::encode", || {
            let params = CombineParams {
                new_to_old: new_to_old.to_cols_array_2d(),
            };
            gpu.queue
                .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
            let textures = [
                buffers.color(newer),
                buffers.id(newer),
                buffers.depth(newer),
                buffers.color(newer + 1),
                buffers.id(newer + 1),
                buffers.depth(newer + 1),
                buffers.motion().unwrap_or(&self.still),
            ];
            let bind_group = textures_and_uniform(
                gpu,
                &self.layout,
                &textures,
                Some(&self.params),
                "lodkit combine",
            )?;
            let label = "lodkit combine";
            let mut pass = match regions {
                None => begin_color_pass(encoder, target, wgpu::Color::BLACK, label),
                Some(_) => begin_load_pass(encoder, target, label),
            };
            pass.set_pipeline(match buffers.motion() {
                Some(_) => &self.pipeline,
                None => &self.still_pipeline,
            });
            pass.set_bind_group(0, &bind_group, &[]);
            match regions {
                None => pass.draw(0..3, 0..1),
                Some(rects) => {
                    for r in rects {
                        pass.set_scissor_rect(r.x, r.y, r.width, r.height);
                        pass.draw(0..3, 0..1);
                    }
                }
            }
            Ok(())
        })
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
