//! [`CombinePass`]: the combine (`passes/combine.wgsl`) built from a [`CombinePassDescriptor`]
//! and recorded with a [`CombineFrame`].

use glam::Mat4;

use super::LodBuffers;
use super::combine_bindings::CombineBindings;
use crate::combine::{DepthConvention, ScreenRect, merge_rects};
use crate::combine_coverage::{COMBINE_ANCHORED, COMBINE_LEVEL_DEPTH, CombineData, combine_object};
use crate::gpu::checks::{check_color_format, has_usage, texture_matches};
use crate::gpu::resources::{
    RecordedUniform, begin_color_pass, begin_load_pass, fullscreen_pipeline_with, one_group_layout,
    texture_2d, texture_entry, uniform_entry,
};
use crate::gpu::{GpuContext, GpuError};
use crate::lod_buffer::MOTION_FORMAT;
use crate::silhouette::silhouette_texel;

/// Rust mirror of `CombineParams` in `passes/combine.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CombineParams {
    /// P_old V_old V_new^-1 P_new^-1, column-major.
    pub new_to_old: [[f32; 4]; 4],
}

/// How a [`CombinePass`] is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CombinePassDescriptor {
    /// Format of the targets it writes: a floating-point color format the device can render
    /// to (default `Rgba16Float`).
    pub target_format: wgpu::TextureFormat,
    /// Depth convention of the LOD buffers' depth (default [`DepthConvention::Standard`];
    /// `Reversed` is the shader def `LODKIT_REVERSE_Z`).
    pub depth: DepthConvention,
}

impl Default for CombinePassDescriptor {
    /// `Rgba16Float` targets, standard depth.
    fn default() -> Self {
        Self {
            target_format: wgpu::TextureFormat::Rgba16Float,
            depth: DepthConvention::Standard,
        }
    }
}

/// Where a recording combines.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CombineRegions<'a> {
    /// Every pixel of the target (default).
    #[default]
    Everywhere,
    /// Only inside these screen rectangles: the newer buffer's color is copied into the target
    /// first (which then needs `COPY_DST`) and the combine runs only inside the rectangles,
    /// those of the t-instances ([`screen_rect`](crate::combine::screen_rect)), clipped to the
    /// target and merged ([`merge_rects`]). With none the frame is the copy: no combine, no read
    /// of the older buffer. An engine that can show the newer buffer's color directly skips the
    /// copy as well (docs/frame-sequential.md).
    Only(&'a [ScreenRect]),
}

/// What a recording knows of where the older levels (those the older buffer holds) cover the
/// screen. There is no default: lodkit's route is [`Known`](Self::Known) with the older-level
/// depth pass ([`LodBuffers::level_depth`] and the data
/// [`CombineData::depth_pass`](crate::combine_coverage::CombineData::depth_pass) lays out), or,
/// without that pass, the data
/// [`CoverageLevels::data`](crate::combine_coverage::CoverageLevels::data) builds from the
/// levels' silhouettes; the estimate is a choice made knowingly, with the schedule it is made
/// for.
#[derive(Clone, Copy, Debug)]
pub enum CombineCoverage<'a> {
    /// Nothing: `lodkit::combine::combine_at_moved` (or `combine_at`) estimates it from last
    /// frame's picture. Where a level's edge moved by a fraction of a texel, the pixel shows the
    /// other level or the background every other frame. It is made for
    /// [`Schedule::Paper`](crate::frame_sequential::Schedule::Paper)
    /// ([`TransitionScheduler::with_schedule`](crate::frame_sequential::TransitionScheduler::with_schedule)):
    /// with the default complementary schedule the estimate shows the background through an
    /// object about twice as often.
    Estimated,
    /// `lodkit::combine_coverage::combine_pixel` with this frame's [`CombineData`]: each
    /// t-instance by its route (its older level's silhouette, the older-level depth pass, the
    /// estimate), as [`CombineData::depth_pass`](crate::combine_coverage::CombineData::depth_pass)
    /// lays them out for the older-level depth pass (the default route,
    /// docs/frame-sequential.md) or
    /// [`CoverageLevels::data`](crate::combine_coverage::CoverageLevels::data) from the older
    /// levels' silhouettes under this frame's camera.
    Known {
        /// The frame's data ([`CombineData::new`]) with its `new_to_old` equal to the
        /// recording's.
        data: &'a CombineData,
        /// The older-level depth pass (`LOD_DEPTH_FORMAT`, the buffers' size, cleared to the far
        /// depth), required when the data's `level_depth` is set.
        level_depth: Option<&'a wgpu::Texture>,
        /// The visibility pattern the LOD pass anchors to the screen (one texel per pixel, red
        /// channel, any float format; `LodBufferRenderer::visibility_view` in lodkit-scenes),
        /// required when the data displays an object's older level at an `older_tau`: the
        /// combine then takes that level's shown flag from the pattern at the pixel displayed,
        /// at this frame's threshold, instead of the flag its fragment predicted last frame, so
        /// the two levels stay exactly complementary however the pixel moved. `None`: the older
        /// buffer's flags stand.
        pattern: Option<&'a wgpu::TextureView>,
    },
}

/// One recording of a [`CombinePass`]: what it reads, where it writes, its parameters.
#[derive(Clone, Copy, Debug)]
pub struct CombineFrame<'a> {
    /// The LOD buffer pair.
    pub buffers: &'a LodBuffers,
    /// The buffer rendered this frame (`TransitionScheduler::buffer_index`); the other holds
    /// the older frame.
    pub newer: usize,
    /// This frame's clip space to the older frame's
    /// ([`new_to_old_matrix`](crate::reproject::new_to_old_matrix)), or
    /// [`CombinePass::NO_HISTORY`].
    pub new_to_old: Mat4,
    /// The target: the pass's format and the buffers' size.
    pub target: &'a wgpu::TextureView,
    /// Where to combine (default everywhere).
    pub regions: CombineRegions<'a>,
    /// What is known of the older levels' coverage ([`CombineCoverage::Known`], lodkit's route,
    /// or the estimate chosen knowingly).
    pub coverage: CombineCoverage<'a>,
}

/// The combine pass (`passes/combine.wgsl`) as a ready object: build once per target format,
/// record once or more per frame. Buffers with an object motion target are combined with
/// `combine_at_moved`; buffers without one ([`LodBuffers::without_motion`]) with `combine_at`
/// (`LODKIT_COMBINE_STILL`), which reads no motion and whose 3x3 search the driver's compiler
/// removes (the motion is a constant 0). Each recording carries its own parameters
/// ([`RecordedUniform`]) and [`CombineData`], copied in the encoder: several recordings in one
/// encoder each read their own. A recording creates no texture or buffer once the pass has
/// seen a frame's data that tall, and no bind group while the textures it binds are those of
/// an earlier recording (it keeps the last six bind groups, and with them their textures).
#[derive(Debug)]
pub struct CombinePass {
    pipeline: wgpu::RenderPipeline,
    /// The pipeline for buffers without object motion (`LODKIT_COMBINE_STILL`).
    still_pipeline: wgpu::RenderPipeline,
    /// The pipeline for [`CombineCoverage::Known`] (`LODKIT_COMBINE_KNOWN`).
    known_pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    params: RecordedUniform,
    /// 1x1, zero: bound at the motion binding for buffers without a motion target.
    still: wgpu::Texture,
    /// 1x1: bound at the data and level depth bindings when they are not read.
    unused_data: wgpu::Texture,
    unused_depth: wgpu::Texture,
    /// A view of `still`: bound at the pattern binding when it is not read.
    still_view: wgpu::TextureView,
    /// The data texture and the bind groups, kept between recordings.
    bindings: CombineBindings,
    target_format: wgpu::TextureFormat,
}

impl CombinePass {
    /// The `new_to_old` matrix for a frame with no usable older buffer (the first frame, after a
    /// resize or a camera cut): every pixel reprojects behind the older camera, so the newer
    /// buffer is shown as it is.
    pub const NO_HISTORY: Mat4 = Mat4::ZERO;

    /// Builds the pass as `descriptor` says ([`GpuError::UnsupportedFormat`] for a target
    /// format the pass cannot write).
    pub fn new(gpu: &GpuContext, descriptor: &CombinePassDescriptor) -> Result<Self, GpuError> {
        const CALL: &str = "CombinePass::new";
        let target_format = descriptor.target_format;
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        check_color_format(gpu, CALL, "target_format", target_format, usage)?;
        let reverse = (descriptor.depth == DepthConvention::Reversed).then_some("LODKIT_REVERSE_Z");
        gpu.guarded(CALL, || {
            let size = std::mem::size_of::<CombineParams>();
            let mut entries = Self::buffer_layout_entries(0);
            entries.push(Self::motion_layout_entry(6));
            entries.push(uniform_entry(7, false));
            entries.push(texture_entry(8, wgpu::TextureSampleType::Uint));
            entries.push(Self::motion_layout_entry(9));
            entries.push(Self::motion_layout_entry(10));
            let (group, layout) = one_group_layout(gpu, &entries, "lodkit combine");
            let pipeline = |def: Option<&'static str>| {
                let defs: Vec<&str> = reverse.into_iter().chain(def).collect();
                let module = gpu.pass_module("combine", &defs)?;
                fullscreen_pipeline_with(
                    gpu,
                    &module,
                    target_format,
                    Some(&layout),
                    "lodkit combine",
                )
            };
            let still = texture_2d(
                gpu,
                (1, 1),
                MOTION_FORMAT,
                wgpu::TextureUsages::TEXTURE_BINDING,
                "combine: no object motion",
            )?;
            Ok(Self {
                pipeline: pipeline(None)?,
                still_pipeline: pipeline(Some("LODKIT_COMBINE_STILL"))?,
                known_pipeline: pipeline(Some("LODKIT_COMBINE_KNOWN"))?,
                layout: group,
                params: RecordedUniform::new(gpu, size, "combine params")?,
                still_view: still.create_view(&Default::default()),
                still,
                unused_data: texture_2d(
                    gpu,
                    (1, 1),
                    wgpu::TextureFormat::Rgba32Uint,
                    wgpu::TextureUsages::TEXTURE_BINDING,
                    "combine: no data",
                )?,
                unused_depth: texture_2d(
                    gpu,
                    (1, 1),
                    super::LOD_DEPTH_FORMAT,
                    wgpu::TextureUsages::TEXTURE_BINDING,
                    "combine: no older-level depth pass",
                )?,
                bindings: CombineBindings::new(gpu),
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

    /// Records the combination of buffer `frame.newer` with the other one (reprojected through
    /// `frame.new_to_old`) into `frame.target`, everywhere or inside `frame.regions`. The
    /// target must have the format the pass was built for and the size of the buffers, and
    /// `COPY_DST` for [`CombineRegions::Only`] with a color format the buffers' copies into
    /// ([`GpuError::Mismatch`] otherwise). Returns the pixels combined.
    pub fn record(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        frame: &CombineFrame,
    ) -> Result<u64, GpuError> {
        const CALL: &str = "CombinePass::record";
        let (buffers, target) = (frame.buffers, frame.target);
        texture_matches(
            CALL,
            "target",
            target.texture(),
            buffers.size(),
            self.target_format,
            "the pass (built for its format, drawing the LOD buffers' size)",
        )?;
        self.check_coverage(frame)?;
        let (w, h) = buffers.size();
        let CombineRegions::Only(regions) = frame.regions else {
            self.draw(gpu, encoder, frame, None)?;
            return Ok(u64::from(w) * u64::from(h));
        };
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
        gpu.recording(CALL, || {
            encoder.copy_texture_to_texture(
                buffers.color(frame.newer).as_image_copy(),
                target.texture().as_image_copy(),
                target.texture().size(),
            );
            Ok(())
        })?;
        if !merged.is_empty() {
            self.draw(gpu, encoder, frame, Some(&merged))?;
        }
        Ok(merged.iter().map(ScreenRect::area).sum())
    }

    /// Refuses [`CombineCoverage::Known`] data this pass cannot honour: texels that do not fill
    /// its size, objects displayed at an `older_tau` with no pattern to display them by, a
    /// depth pass the data reads but the frame does not give, or one of another size.
    fn check_coverage(&self, frame: &CombineFrame) -> Result<(), GpuError> {
        const CALL: &str = "CombinePass::record";
        let CombineCoverage::Known {
            data,
            level_depth,
            pattern,
        } = frame.coverage
        else {
            return Ok(());
        };
        let texels = u64::from(data.width) * u64::from(data.height);
        if data.width == 0 || data.height == 0 || texels != data.texels.len() as u64 {
            return Err(GpuError::Mismatch {
                call: CALL,
                parameter: "coverage.data",
                found: format!("{} texels", data.texels.len()),
                expected: format!(
                    "{} x {} texels, non-empty, as CombineData::new lays them out",
                    data.width, data.height
                ),
            });
        }
        let records = combine_object(&data.texels, 0);
        let slots = silhouette_texel(&data.texels, 5).z;
        let anchored =
            (1..slots).find(|&k| combine_object(&data.texels, k).flags & COMBINE_ANCHORED != 0);
        if let (Some(k), None) = (anchored, pattern) {
            return Err(GpuError::Mismatch {
                call: CALL,
                parameter: "coverage.pattern",
                found: format!("None, with id {k} displayed at an older_tau"),
                expected: "the visibility pattern the LOD pass anchors to the screen (or no \
                           older_tau: the older buffer's display flags stand)"
                    .into(),
            });
        }
        let reads_depth = records.flags & COMBINE_LEVEL_DEPTH != 0;
        match (reads_depth, level_depth) {
            (true, None) => Err(GpuError::Mismatch {
                call: CALL,
                parameter: "coverage.level_depth",
                found: "None".into(),
                expected: "the older-level depth pass: the data's level_depth is set".into(),
            }),
            (_, Some(depth)) => texture_matches(
                CALL,
                "coverage.level_depth",
                depth,
                frame.buffers.size(),
                super::LOD_DEPTH_FORMAT,
                "the older-level depth pass (LOD_DEPTH_FORMAT, the LOD buffers' size)",
            ),
            (false, None) => Ok(()),
        }
    }

    /// Draws the combine over the whole target, or inside `rects` over what is there (the
    /// target already checked).
    fn draw(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        frame: &CombineFrame,
        rects: Option<&[ScreenRect]>,
    ) -> Result<(), GpuError> {
        let (buffers, newer) = (frame.buffers, frame.newer);
        gpu.recording("CombinePass::record", || {
            let params = CombineParams {
                new_to_old: frame.new_to_old.to_cols_array_2d(),
            };
            self.params.write(encoder, &params)?;
            let (known, pattern) = match frame.coverage {
                CombineCoverage::Known {
                    data,
                    level_depth,
                    pattern,
                } => (Some((data, level_depth)), pattern),
                CombineCoverage::Estimated => (None, None),
            };
            let data = known
                .map(|(data, _)| self.bindings.upload(gpu, encoder, data))
                .transpose()?;
            let level_depth = known.and_then(|(_, depth)| depth);
            let textures = [
                buffers.color(newer),
                buffers.id(newer),
                buffers.depth(newer),
                buffers.color(newer + 1),
                buffers.id(newer + 1),
                buffers.depth(newer + 1),
                buffers.motion().unwrap_or(&self.still),
                data.as_ref().unwrap_or(&self.unused_data),
                level_depth.unwrap_or(&self.unused_depth),
            ];
            // Not read where no older level is displayed at an older_tau: the 1x1 zero motion.
            let pattern = pattern.unwrap_or(&self.still_view);
            let bind_group =
                self.bindings
                    .group(gpu, &self.layout, self.params.buffer(), textures, pattern)?;
            let label = "lodkit combine";
            let mut pass = match rects {
                None => begin_color_pass(encoder, frame.target, wgpu::Color::BLACK, label),
                Some(_) => begin_load_pass(encoder, frame.target, label),
            };
            pass.set_pipeline(match (known, buffers.motion()) {
                (Some(_), _) => &self.known_pipeline,
                (None, Some(_)) => &self.pipeline,
                (None, None) => &self.still_pipeline,
            });
            pass.set_bind_group(0, &bind_group, &[]);
            match rects {
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
