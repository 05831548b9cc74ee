//! Drawing meshes into LOD buffers with `passes/lod_buffer_mesh.wgsl`: the reference for an
//! engine's forward pass under frame-sequential LOD, used by the examples, tests and demo.

use glam::{Mat4, Vec3, Vec4};

use crate::mesh::{GpuMesh, PassDraw, UNFILTERABLE, draw_foreign, masked_view_group};
use lodkit::alpha_mask::AlphaMask;
use lodkit::combine::DepthConvention;
use lodkit::frame_sequential::FrameDraw;
use lodkit::gpu::checks::{check_color_format, same_color_format};
use lodkit::gpu::counters::FragmentCounter;
use lodkit::gpu::frame_sequential::{LOD_DEPTH_FORMAT, LodBuffers};
use lodkit::gpu::resources::{
    DrawUniforms, camera_draw_layouts, depth_write_state, mesh_pipeline, mesh_pipeline_entry,
    r32float_texture, texture_entry, uniform_buffer,
};
use lodkit::gpu::{GpuContext, GpuError};
use lodkit::lod_buffer::{ID_FORMAT, MOTION_FORMAT};
use lodkit::visibility::{VisibilitySpace, VisibilityTexture};

/// Rust mirror of `LodCamera` in `passes/lod_buffer_mesh.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LodCameraUniform {
    /// Projection x view.
    pub view_proj: [[f32; 4]; 4],
    /// The previous frame's projection x view.
    pub prev_view_proj: [[f32; 4]; 4],
    /// World-space direction toward the light.
    pub light_dir: [f32; 4],
    /// Framebuffer width and height in pixels; 1 for the pattern anchored to the screen, 0 for
    /// object space; padding.
    pub viewport: [f32; 4],
}

/// Rust mirror of `LodDraw` in `passes/lod_buffer_mesh.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LodDrawUniform {
    /// Object to world.
    pub model: [[f32; 4]; 4],
    /// Object to world in the previous frame.
    pub prev_model: [[f32; 4]; 4],
    /// Base color.
    pub color: [f32; 4],
    /// 0 for n-instances.
    pub instance_id: u32,
    /// Visibility threshold this frame.
    pub tau: f32,
    /// Visibility texture repeats per object-space unit.
    pub vis_scale: f32,
    /// Visibility threshold of the same LOD in the next frame.
    pub tau_next: f32,
    /// Sway: amplitude, phase, the previous frame's phase, padding.
    pub sway: [f32; 4],
    /// Alpha mask rect (`lodkit::alpha_mask`; x = 0: no alpha test).
    pub alpha_rect: [f32; 4],
}

/// The cameras of a LOD buffer frame. The previous frame's view-projection matters whenever the
/// camera or an object moves: the screen-anchored visibility pattern predicts from it where each
/// fragment is displayed next frame, and objects that move by themselves have their object
/// motion measured in its view. A `Mat4` converts to a view with no previous frame (a still
/// camera, the first frame, a cut); under a moving camera it leaves the older buffer's flags
/// looked up under the wrong pixels, and those pixels show both LODs' average.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LodView {
    /// Projection x view of this frame.
    pub view_proj: Mat4,
    /// Projection x view of the previous frame (the frame of the older LOD buffer).
    pub prev_view_proj: Mat4,
}

impl From<Mat4> for LodView {
    fn from(view_proj: Mat4) -> Self {
        Self {
            view_proj,
            prev_view_proj: view_proj,
        }
    }
}

/// One [`LodBufferRenderer::render`]: which buffer, from where, what, and whether its fragments
/// are counted.
#[derive(Clone, Copy, Debug)]
pub struct LodBufferFrame<'a> {
    /// The LOD buffer drawn into ([`LodBuffers`] holds two). Default: 0.
    pub index: usize,
    /// This frame's and the previous frame's projection x view (`Mat4::into()` for a frame with
    /// no previous one). Default: identity, no previous frame.
    pub view: LodView,
    /// The draws, in order. Default: none.
    pub items: &'a [LodDrawItem<'a>],
    /// The color buffer's clear color. Default: black.
    pub clear: wgpu::Color,
    /// Counts the pass's fragment-shader invocations. Default: none.
    pub counter: Option<&'a FragmentCounter>,
    /// The caller's own draws in the same pass, between the items (an impostor level drawn by
    /// `lodkit::gpu::impostor::ImpostorPass`, say). Default: none.
    pub foreign: &'a [PassDraw<'a>],
}

impl Default for LodBufferFrame<'_> {
    fn default() -> Self {
        Self {
            index: 0,
            view: Mat4::IDENTITY.into(),
            items: &[],
            clear: wgpu::Color::BLACK,
            counter: None,
            foreign: &[],
        }
    }
}

/// One draw into a LOD buffer.
#[derive(Clone, Copy, Debug)]
pub struct LodDrawItem<'a> {
    /// The mesh.
    pub mesh: &'a GpuMesh,
    /// Object to world.
    pub model: Mat4,
    /// Object to world in the previous frame (`model` for an object that did not move): with
    /// the sway phases, it gives the object motion the combine follows.
    pub prev_model: Mat4,
    /// Base color.
    pub color: Vec4,
    /// Instance id (0 = n-instance, always shown).
    pub id: u32,
    /// Visibility threshold this frame ([`visibility_shown`](lodkit::visibility::visibility_shown):
    /// 1 shows every fragment, 0 none, negative the inverted pattern).
    pub tau: f32,
    /// Visibility threshold of the same LOD in the next frame, when this buffer is the older one.
    pub tau_next: f32,
    /// Wind sway of the vertex stage: amplitude (object units at the top of a unit-high mesh,
    /// 0 = none) and phase (advance it over time). The visibility pattern stays on the object.
    pub sway: [f32; 2],
    /// The sway phase of the previous frame.
    pub prev_sway_phase: f32,
    /// Where the renderer's alpha mask lies in object space
    /// ([`alpha_mask_rect`](lodkit::alpha_mask::alpha_mask_rect)); `Vec4::ZERO`: no alpha test.
    pub alpha_rect: Vec4,
}

impl<'a> LodDrawItem<'a> {
    /// The draw the scheduler asks for: `mesh` is the mesh of LOD `draw.lod` (no sway; at the
    /// same place in the previous frame).
    pub fn from_draw(mesh: &'a GpuMesh, model: Mat4, color: Vec4, draw: &FrameDraw) -> Self {
        Self {
            mesh,
            model,
            prev_model: model,
            color,
            id: draw.id,
            tau: draw.tau,
            tau_next: draw.tau_next,
            sway: [0.0; 2],
            prev_sway_phase: 0.0,
            alpha_rect: Vec4::ZERO,
        }
    }

    /// Whether the draw can show a fragment: n-instances always; a t-instance when tau or
    /// tau_next is neither 0 nor NaN.
    pub fn shows_anything(&self) -> bool {
        let shows = |tau: f32| tau != 0.0 && !tau.is_nan();
        self.id == 0 || shows(self.tau) || shows(self.tau_next)
    }
}

/// Draws [`LodDrawItem`]s into one buffer of a [`LodBuffers`] pair, in standard or reversed Z.
#[derive(Debug)]
pub struct LodBufferRenderer {
    pipeline: wgpu::RenderPipeline,
    /// The same for LOD buffers without the object motion target.
    still_pipeline: wgpu::RenderPipeline,
    /// The older-level depth pass (`fs_level_depth`, depth only).
    level_depth_pipeline: wgpu::RenderPipeline,
    camera: wgpu::Buffer,
    camera_layout: wgpu::BindGroupLayout,
    vis_view: wgpu::TextureView,
    camera_group: wgpu::BindGroup,
    draws: DrawUniforms,
    draw_group: wgpu::BindGroup,
    vis_scale: f32,
    space: VisibilitySpace,
    color_format: wgpu::TextureFormat,
    depth: DepthConvention,
}

impl LodBufferRenderer {
    /// Most draws per [`render`](Self::render).
    pub const MAX_DRAWS: usize = 1024;

    /// Builds the pipeline for LOD buffers of color format `color_format`, with visibility
    /// texture `vis`: tiled over the screen, one texel per pixel (the default
    /// [`VisibilitySpace::Screen`]), or repeating `vis_scale` (finite, > 0) times per
    /// object-space unit once [`set_visibility_space`](Self::set_visibility_space) anchors it to
    /// the object; standard Z (depth test `Less`, cleared to 1).
    pub fn new(
        gpu: &GpuContext,
        color_format: wgpu::TextureFormat,
        vis: &VisibilityTexture,
        vis_scale: f32,
    ) -> Result<Self, GpuError> {
        Self::with_depth(gpu, color_format, vis, vis_scale, DepthConvention::Standard)
    }

    /// [`new`](Self::new) for the depth convention `depth`: reversed Z tests `Greater` and clears
    /// the depth buffer and the stored depth to 0 (pair it with a `CombinePass` whose
    /// `CombinePassDescriptor::depth` is `Reversed` and a reversed, possibly infinite-far,
    /// projection).
    pub fn with_depth(
        gpu: &GpuContext,
        color_format: wgpu::TextureFormat,
        vis: &VisibilityTexture,
        vis_scale: f32,
        depth: DepthConvention,
    ) -> Result<Self, GpuError> {
        const CALL: &str = "LodBufferRenderer::new";
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        check_color_format(gpu, CALL, "color_format", color_format, usage)?;
        if !(vis_scale.is_finite() && vis_scale > 0.0) {
            return Err(GpuError::Invalid {
                call: CALL,
                parameter: "vis_scale",
                value: vis_scale.to_string(),
                rule: "must be finite and positive",
            });
        }
        gpu.guarded(CALL, || {
            let vis_texture = r32float_texture(gpu, vis.size, &vis.texels, "visibility texture")?;
            let module = gpu.pass_module("lod_buffer_mesh", &[])?;
            let extra = [
                texture_entry(1, UNFILTERABLE),
                texture_entry(2, UNFILTERABLE),
            ];
            let (view_layout, draw_layout, layout) =
                camera_draw_layouts(gpu, "lod_buffer_mesh", &extra)?;
            let targets = [
                Some(color_format.into()),
                Some(ID_FORMAT.into()),
                Some(MOTION_FORMAT.into()),
            ];
            let depth_state = depth_write_state(LOD_DEPTH_FORMAT, depth_compare(depth));
            let pipeline = |targets: &[Option<wgpu::ColorTargetState>]| {
                mesh_pipeline(
                    gpu,
                    &module,
                    &layout,
                    targets,
                    depth_state.clone(),
                    "lod_buffer_mesh",
                )
            };
            let (with_motion, still) = (pipeline(&targets)?, pipeline(&targets[..2])?);
            let level_depth_pipeline = mesh_pipeline_entry(
                gpu,
                (&module, "fs_level_depth"),
                &layout,
                &[],
                depth_state.clone(),
                "older-level depth pass",
            )?;
            let size = std::mem::size_of::<LodCameraUniform>();
            let camera = uniform_buffer(gpu, size, "lod camera")?;
            let draws = DrawUniforms::new(
                gpu,
                std::mem::size_of::<LodDrawUniform>(),
                Self::MAX_DRAWS,
                "lod draws",
            )?;
            let vis_view = vis_texture.create_view(&Default::default());
            let opaque = AlphaMask::opaque();
            let camera_group =
                masked_view_group(gpu, &view_layout, &camera, &[&vis_view], &opaque)?;
            let draw_group = draws.bind_group(gpu, &draw_layout)?;
            Ok(Self {
                pipeline: with_motion,
                still_pipeline: still,
                level_depth_pipeline,
                camera,
                camera_layout: view_layout,
                vis_view,
                camera_group,
                draws,
                draw_group,
                vis_scale,
                space: VisibilitySpace::default(),
                color_format,
                depth,
            })
        })
    }

    /// Binds `mask` as the alpha mask of every draw whose `alpha_rect` is set (one mask, or an
    /// atlas, per renderer; a 1x1 opaque one until then). [`GpuError::Mismatch`] when its texels
    /// do not fill `size` x `size` or `size` is 0.
    pub fn set_alpha_mask(&mut self, gpu: &GpuContext, mask: &AlphaMask) -> Result<(), GpuError> {
        let views = [&self.vis_view];
        self.camera_group =
            masked_view_group(gpu, &self.camera_layout, &self.camera, &views, mask)?;
        Ok(())
    }

    /// The visibility texture the levels are drawn with (`R32Float`): where the pattern is
    /// anchored to the screen, what `CombineCoverage::Known::pattern` takes, so the combine shows
    /// an older level at this frame's threshold.
    pub fn visibility_view(&self) -> &wgpu::TextureView {
        &self.vis_view
    }

    /// Where the visibility pattern is anchored ([`VisibilitySpace::Screen`] unless set).
    pub fn visibility_space(&self) -> VisibilitySpace {
        self.space
    }

    /// Anchors the visibility pattern to the screen (one texel per pixel, looked up where each
    /// fragment is displayed; the default) or to the object (at `vis_scale` repeats per
    /// object-space unit, the paper's choice).
    pub fn set_visibility_space(&mut self, space: VisibilitySpace) {
        self.space = space;
    }

    /// Renders `frame.items` (at most [`Self::MAX_DRAWS`]: more is [`GpuError::TooManyDraws`]
    /// and draws nothing) into buffer `frame.index` of `buffers` seen by `frame.view`, cleared to
    /// `frame.clear`, counting the pass's fragments with `frame.counter` if given. Give the view
    /// the previous frame's view-projection whenever the camera or an object moves: the
    /// screen-anchored pattern predicts from it where each fragment is displayed next frame, and
    /// moving objects get their object motion from it. A view from a `Mat4` alone means no
    /// previous frame (a still camera, the first frame, a cut).
    /// Returns the triangles drawn and the count (0 without a counter). A t-instance item shown
    /// in neither this frame nor the next (tau and tau_next 0 or NaN: visibility texels lie
    /// strictly between 0 and 1) is not submitted. Every fragment of a t-instance is kept and
    /// flagged (see `passes/lod_buffer_mesh.wgsl`).
    pub fn render(
        &self,
        gpu: &GpuContext,
        buffers: &LodBuffers,
        frame: &LodBufferFrame,
    ) -> Result<(u64, u64), GpuError> {
        self.draw(gpu, buffers, frame, false)
    }

    /// Draws `frame.items` whole (no visibility pattern; their alpha test kept), depth only,
    /// into `buffers.level_depth()`: the older-level depth pass, lodkit's default route to the
    /// older levels' coverage. Give it each t-instance's older level (`TransitionScheduler::older`)
    /// with this frame's transform and sway. `frame.index` and `frame.clear` are not read.
    /// Returns the triangles drawn and the fragment count as [`render`](Self::render) does.
    pub fn render_level_depth(
        &self,
        gpu: &GpuContext,
        buffers: &LodBuffers,
        frame: &LodBufferFrame,
    ) -> Result<(u64, u64), GpuError> {
        self.draw(gpu, buffers, frame, true)
    }

    /// [`render`](Self::render), or with `level_depth` the older-level depth pass.
    fn draw(
        &self,
        gpu: &GpuContext,
        buffers: &LodBuffers,
        frame: &LodBufferFrame,
        level_depth: bool,
    ) -> Result<(u64, u64), GpuError> {
        let LodBufferFrame {
            index,
            view,
            items,
            clear,
            counter,
            foreign,
        } = *frame;
        let call = match level_depth {
            true => "LodBufferRenderer::render_level_depth",
            false => "LodBufferRenderer::render",
        };
        same_color_format(call, "buffers", buffers.color_format(), self.color_format)?;
        self.draws.check_count(call, items.len())?;
        gpu.recording(call, || {
            let camera = LodCameraUniform {
                view_proj: view.view_proj.to_cols_array_2d(),
                prev_view_proj: view.prev_view_proj.to_cols_array_2d(),
                light_dir: Vec3::new(0.4, 0.8, 0.6).extend(0.0).to_array(),
                viewport: [
                    buffers.size().0 as f32,
                    buffers.size().1 as f32,
                    f32::from(u8::from(self.space == VisibilitySpace::Screen)),
                    0.0,
                ],
            };
            gpu.queue
                .write_buffer(&self.camera, 0, bytemuck::bytes_of(&camera));
            let uniforms: Vec<LodDrawUniform> = items
                .iter()
                .map(|item| LodDrawUniform {
                    model: item.model.to_cols_array_2d(),
                    prev_model: item.prev_model.to_cols_array_2d(),
                    color: item.color.to_array(),
                    instance_id: item.id,
                    tau: item.tau,
                    vis_scale: self.vis_scale,
                    tau_next: item.tau_next,
                    sway: [item.sway[0], item.sway[1], item.prev_sway_phase, 0.0],
                    alpha_rect: item.alpha_rect.to_array(),
                })
                .collect();
            self.draws.write(gpu, &uniforms)?;
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            let mut triangles = 0u64;
            {
                let occlusion = counter.and_then(FragmentCounter::occlusion_query_set);
                let far = match self.depth {
                    DepthConvention::Standard => 1.0,
                    DepthConvention::Reversed => 0.0,
                };
                let mut pass = match level_depth {
                    true => buffers.begin_level_depth_pass(&mut encoder, far, occlusion),
                    false => buffers.begin_pass(&mut encoder, index, clear, far, occlusion),
                };
                if let Some(c) = counter {
                    c.begin(&mut pass);
                }
                let pipeline = match (level_depth, buffers.motion()) {
                    (true, _) => &self.level_depth_pipeline,
                    (false, Some(_)) => &self.pipeline,
                    (false, None) => &self.still_pipeline,
                };
                let mut bound = false;
                for (i, item) in items.iter().enumerate() {
                    bound &= !draw_foreign(&mut pass, foreign, i, items.len());
                    if !(level_depth || item.shows_anything()) {
                        continue;
                    }
                    if !bound {
                        pass.set_pipeline(pipeline);
                        pass.set_bind_group(0, &self.camera_group, &[]);
                        bound = true;
                    }
                    pass.set_bind_group(1, &self.draw_group, &[self.draws.offset(i)]);
                    item.mesh.draw(&mut pass);
                    triangles += u64::from(item.mesh.triangles());
                }
                draw_foreign(&mut pass, foreign, items.len(), items.len());
                if let Some(c) = counter {
                    c.end(&mut pass);
                }
            }
            match counter {
                Some(c) => Ok((triangles, c.read(gpu, encoder)?)),
                None => {
                    gpu.queue.submit([encoder.finish()]);
                    Ok((triangles, 0))
                }
            }
        })
    }
}

/// The depth test that keeps the nearer fragment under `depth`.
fn depth_compare(depth: DepthConvention) -> wgpu::CompareFunction {
    match depth {
        DepthConvention::Standard => wgpu::CompareFunction::Less,
        DepthConvention::Reversed => wgpu::CompareFunction::Greater,
    }
}
