//! [`ImpostorPass`]: instances of one baked impostor drawn into the engine's own render pass
//! (`passes/impostor.wgsl`).

use super::ImpostorTextures;
use crate::combine::DepthConvention;
use crate::frame_sequential::FrameDraw;
use crate::gpu::frame_sequential::LOD_DEPTH_FORMAT;
use crate::gpu::resources::{buffer_with_data, uniform_entry};
use crate::gpu::{GpuContext, GpuError};
use crate::lod_buffer::{ID_FORMAT, MOTION_FORMAT};
use crate::screen_door::DitherPattern;
use crate::unpopping::LodRenderState;
use crate::visibility::VisibilitySpace;

/// What an [`ImpostorPass`] draws into.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ImpostorTarget {
    /// One colour target of the descriptor's `color_format` and the depth target: a forward
    /// pass (`fs_main`), transitions by the screen door.
    #[default]
    Color,
    /// A LOD buffer of frame-sequential LOD
    /// ([`LodBuffers::begin_pass`](crate::gpu::frame_sequential::LodBuffers::begin_pass),
    /// `fs_lod_buffer`): colour (`color_format`: the buffers'), the id word with the
    /// display-time visibility flags (`lodkit::lod_buffer`), the object motion when `motion`
    /// (buffers from `LodBuffers::new`; `false` for `LodBuffers::without_motion`), the depth
    /// (`depth_format` must be [`LOD_DEPTH_FORMAT`]). Drawn with
    /// [`ImpostorPass::prepare_lod_buffer`].
    LodBuffer {
        /// Whether the buffers have the object motion target (location 2).
        motion: bool,
    },
    /// The older-level depth pass
    /// ([`LodBuffers::begin_level_depth_pass`](crate::gpu::frame_sequential::LodBuffers::begin_level_depth_pass),
    /// `fs_level_depth`): the impostor whole, depth only (`depth_format` must be
    /// [`LOD_DEPTH_FORMAT`]).
    LevelDepth,
}

/// How to build an [`ImpostorPass`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImpostorPassDescriptor {
    /// Format of the colour target it draws into.
    pub color_format: wgpu::TextureFormat,
    /// Format of the depth target (depth-tested and written).
    pub depth_format: wgpu::TextureFormat,
    /// The engine's depth convention: `Standard` tests `Less` (cleared to 1), `Reversed`
    /// (Bevy's, with an infinite reversed projection) `Greater` (cleared to 0). The depth the
    /// fragment writes comes from the view's projection either way.
    pub depth: DepthConvention,
    /// The screen-door pattern of transitions: the one the mesh levels it meets are drawn with
    /// (the two must match to be complementary).
    pub dither: DitherPattern,
    /// What the pass draws into (default: a colour target).
    pub target: ImpostorTarget,
    /// How a colour target's instances are drawn (`lodkit::unpopping`): opaque (default; the
    /// screen door of [`ImpostorInstance::alpha`] for dithered transitions) or blended with the
    /// blend constant, depth-tested without writes, for unpopping and cross-fades (set it with
    /// `lodkit::gpu::unpopping::lod_blend_constant` before [`draw`](ImpostorPass::draw)): two
    /// passes serve every role, as two pipelines serve a mesh's. Other targets draw opaque.
    pub state: LodRenderState,
}

impl Default for ImpostorPassDescriptor {
    /// `Rgba8UnormSrgb` colour, `Depth32Float` depth, standard depth, the 4x4 Bayer pattern, a
    /// colour target, opaque.
    fn default() -> Self {
        Self {
            color_format: wgpu::TextureFormat::Rgba8UnormSrgb,
            depth_format: wgpu::TextureFormat::Depth32Float,
            depth: DepthConvention::Standard,
            dither: DitherPattern::Bayer4x4,
            target: ImpostorTarget::Color,
            state: LodRenderState::OPAQUE,
        }
    }
}

/// The view impostors are drawn for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImpostorView {
    /// World to clip (wgpu's clip space: z in [0, 1]).
    pub view_proj: glam::Mat4,
    /// The camera's world position.
    pub eye: glam::Vec3,
    /// World-space direction toward the light (unit length).
    pub light: glam::Vec3,
    /// The ambient share of the lighting, in [0, 1].
    pub ambient: f32,
}

/// What the frame-sequential passes ([`ImpostorTarget::LodBuffer`]) need beyond the view: the
/// previous frame's camera and the visibility pattern.
#[derive(Clone, Copy, Debug)]
pub struct ImpostorLodView<'a> {
    /// The previous frame's world to clip (this frame's when there is none): where a surface
    /// point was, for its object motion and for where the pattern is read next frame.
    pub prev_view_proj: glam::Mat4,
    /// The LOD buffers' size in pixels.
    pub size: (u32, u32),
    /// The visibility pattern (`R32Float`, read with `textureLoad`): the one the mesh levels are
    /// drawn with and the combine reads (`CombineCoverage::Known::pattern`).
    pub visibility: &'a wgpu::TextureView,
    /// Where the pattern is anchored: on the screen, one texel per pixel (lodkit's default), or
    /// on the surface point the frames saw.
    pub space: VisibilitySpace,
    /// Pattern repeats per object-space unit where it is anchored to the object (finite,
    /// positive; the mesh levels' value).
    pub vis_scale: f32,
}

/// One impostor instance: its object-to-world transform (a rotation, a uniform scale and a
/// translation; the card and the depth it writes assume no shear), its screen-door alpha and,
/// in a LOD buffer, its instance id and visibility thresholds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImpostorInstance {
    /// Object to world.
    pub model: glam::Mat4,
    /// The complementary screen-door pattern's alpha (`lodkit::screen_door`), in [-1, 1]: 1
    /// draws every pixel; in a transition from a mesh level at `-(1 - t)` the impostor takes
    /// `t` (or the other way round), and the two cover disjoint pixels whose union is the
    /// object's. Values outside are clamped, a NaN taken as 1. Not read in a LOD buffer.
    pub alpha: f32,
    /// LOD buffer: the previous frame's object to world (`model` for an object that did not
    /// move), for the object motion.
    pub prev_model: glam::Mat4,
    /// LOD buffer: the instance id (`FrameDraw::id`; 0: an n-instance, always shown).
    pub id: u32,
    /// LOD buffer: the visibility threshold this frame (`FrameDraw::tau`).
    pub tau: f32,
    /// LOD buffer: the threshold next frame (`FrameDraw::tau_next`).
    pub tau_next: f32,
    /// Linear RGB the baked base colour is multiplied with (1: as baked): one atlas for
    /// objects that differ only in colour.
    pub tint: glam::Vec3,
}

impl ImpostorInstance {
    /// An instance at `model` that did not move, drawn whole (alpha 1; in a LOD buffer an
    /// n-instance).
    pub fn new(model: glam::Mat4) -> Self {
        Self {
            model,
            alpha: 1.0,
            prev_model: model,
            id: 0,
            tau: 1.0,
            tau_next: 1.0,
            tint: glam::Vec3::ONE,
        }
    }

    /// An instance at `model` (at `prev_model` the frame before) drawn into a LOD buffer as the
    /// scheduler's `draw` says (`TransitionScheduler::draw`).
    pub fn from_draw(model: glam::Mat4, prev_model: glam::Mat4, draw: &FrameDraw) -> Self {
        Self {
            prev_model,
            id: draw.id,
            tau: draw.tau,
            tau_next: draw.tau_next,
            ..Self::new(model)
        }
    }
}

/// Rust mirror of `ImpostorView` in `passes/impostor.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct ViewUniform {
    view_proj: [f32; 16],
    eye: [f32; 4],
    light: [f32; 4],
    sphere: [f32; 4],
    atlas: [u32; 4],
    prev_view_proj: [f32; 16],
    viewport: [f32; 4],
}

/// Rust mirror of the instance attributes of `vs_main` in `passes/impostor.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct InstanceWords {
    model: [f32; 16],
    /// Screen-door alpha, tau, tau next, unused.
    door: [f32; 4],
    /// Instance id, unused x 3.
    id: [u32; 4],
    prev_model: [f32; 16],
    /// The tint, 1.
    tint: [f32; 4],
}

/// The attributes of [`InstanceWords`].
const INSTANCE_ATTRIBUTES: [wgpu::VertexAttribute; 11] = wgpu::vertex_attr_array![
    0 => Float32x4, 1 => Float32x4, 2 => Float32x4, 3 => Float32x4, 4 => Float32x4,
    5 => Uint32x4, 6 => Float32x4, 7 => Float32x4, 8 => Float32x4, 9 => Float32x4,
    10 => Float32x4
];

/// A pipeline that draws impostors.
#[derive(Debug)]
pub struct ImpostorPass {
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroupLayout,
    descriptor: ImpostorPassDescriptor,
}

/// What one [`ImpostorPass::draw`] needs: the view's uniform, the atlas's bind group and the
/// instances.
#[derive(Debug)]
pub struct PreparedImpostors {
    bind_group: wgpu::BindGroup,
    instances: wgpu::Buffer,
    count: u32,
}

impl ImpostorPass {
    /// Builds the pipeline. [`GpuError::Invalid`] for a LOD-buffer or level-depth target whose
    /// `depth_format` is not [`LOD_DEPTH_FORMAT`]; an unusable colour format by name.
    pub fn new(gpu: &GpuContext, descriptor: &ImpostorPassDescriptor) -> Result<Self, GpuError> {
        const CALL: &str = "ImpostorPass::new";
        let target = descriptor.target;
        if target != ImpostorTarget::Color && descriptor.depth_format != LOD_DEPTH_FORMAT {
            return Err(GpuError::Invalid {
                call: CALL,
                parameter: "depth_format",
                value: format!("{:?} with target {target:?}", descriptor.depth_format),
                rule: "a LOD buffer's or the level-depth pass's depth is LOD_DEPTH_FORMAT",
            });
        }
        let state = descriptor.state;
        let opaque = !state.blend && state.depth_write && state.depth_test;
        if target != ImpostorTarget::Color && !opaque {
            return Err(GpuError::Invalid {
                call: CALL,
                parameter: "state",
                value: format!("{:?} with target {target:?}", descriptor.state),
                rule: "only a colour target draws blended or without depth writes; LOD buffers \
                       and depth passes are opaque",
            });
        }
        if target != ImpostorTarget::LevelDepth {
            crate::gpu::checks::check_color_format(
                gpu,
                CALL,
                "color_format",
                descriptor.color_format,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            )?;
        }
        let defs: &[&str] = match descriptor.dither {
            DitherPattern::Bayer4x4 => &[],
            DitherPattern::BlueNoise16x16 => &["LODKIT_SCREEN_DOOR_BLUE_NOISE"],
        };
        let module = gpu.pass_module("impostor", defs)?;
        let color = Some(wgpu::ColorTargetState {
            format: descriptor.color_format,
            blend: crate::gpu::unpopping::lod_blend(&descriptor.state),
            write_mask: wgpu::ColorWrites::ALL,
        });
        let (entry, targets) = match target {
            ImpostorTarget::Color => ("fs_main", vec![color]),
            ImpostorTarget::LodBuffer { motion } => {
                let mut targets = vec![color, Some(ID_FORMAT.into())];
                targets.extend(motion.then(|| Some(MOTION_FORMAT.into())));
                ("fs_lod_buffer", targets)
            }
            ImpostorTarget::LevelDepth => ("fs_level_depth", vec![]),
        };
        gpu.guarded(CALL, || {
            let device = &gpu.device;
            let texture = |binding, filterable| {
                crate::gpu::resources::texture_entry(
                    binding,
                    wgpu::TextureSampleType::Float { filterable },
                )
            };
            let mut entries = vec![
                uniform_entry(0, false),
                texture(1, true),
                texture(2, true),
                wgpu::BindGroupLayoutEntry {
                    binding: 3,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ];
            if matches!(target, ImpostorTarget::LodBuffer { .. }) {
                entries.push(texture(4, false));
            }
            let group = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("impostor"),
                entries: &entries,
            });
            let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("impostor"),
                bind_group_layouts: &[Some(&group)],
                immediate_size: 0,
            });
            let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("impostor"),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[Some(wgpu::VertexBufferLayout {
                        array_stride: std::mem::size_of::<InstanceWords>() as u64,
                        step_mode: wgpu::VertexStepMode::Instance,
                        attributes: &INSTANCE_ATTRIBUTES,
                    })],
                },
                primitive: Default::default(),
                depth_stencil: Some(crate::gpu::unpopping::lod_depth_stencil(
                    &descriptor.state,
                    descriptor.depth_format,
                    match descriptor.depth {
                        DepthConvention::Standard => wgpu::CompareFunction::Less,
                        DepthConvention::Reversed => wgpu::CompareFunction::Greater,
                    },
                )),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    targets: &targets,
                }),
                multiview_mask: None,
                cache: None,
            });
            Ok(Self {
                pipeline,
                group,
                descriptor: *descriptor,
            })
        })
    }

    /// The uniform, bind group and instance buffer for drawing `instances` of `textures` seen
    /// from `view`, for a colour or level-depth target ([`GpuError::Mismatch`] for a LOD-buffer
    /// one: [`prepare_lod_buffer`](Self::prepare_lod_buffer)).
    pub fn prepare(
        &self,
        gpu: &GpuContext,
        textures: &ImpostorTextures,
        view: &ImpostorView,
        instances: &[ImpostorInstance],
    ) -> Result<PreparedImpostors, GpuError> {
        self.prepare_with(
            gpu,
            "ImpostorPass::prepare",
            textures,
            view,
            None,
            instances,
        )
    }

    /// [`prepare`](Self::prepare) for a LOD-buffer target ([`GpuError::Mismatch`] for another),
    /// with the previous frame's camera and the visibility pattern of `lod`
    /// ([`GpuError::Invalid`] for a `vis_scale` that is not finite and positive where the
    /// pattern is anchored to the object).
    pub fn prepare_lod_buffer(
        &self,
        gpu: &GpuContext,
        textures: &ImpostorTextures,
        view: &ImpostorView,
        lod: &ImpostorLodView<'_>,
        instances: &[ImpostorInstance],
    ) -> Result<PreparedImpostors, GpuError> {
        const CALL: &str = "ImpostorPass::prepare_lod_buffer";
        let object = lod.space == VisibilitySpace::Object;
        if object && !(lod.vis_scale.is_finite() && lod.vis_scale > 0.0) {
            return Err(GpuError::Invalid {
                call: CALL,
                parameter: "lod.vis_scale",
                value: lod.vis_scale.to_string(),
                rule: "finite and positive where the pattern is anchored to the object",
            });
        }
        self.prepare_with(gpu, CALL, textures, view, Some(lod), instances)
    }

    fn prepare_with(
        &self,
        gpu: &GpuContext,
        call: &'static str,
        textures: &ImpostorTextures,
        view: &ImpostorView,
        lod: Option<&ImpostorLodView<'_>>,
        instances: &[ImpostorInstance],
    ) -> Result<PreparedImpostors, GpuError> {
        let lod_target = matches!(self.descriptor.target, ImpostorTarget::LodBuffer { .. });
        if lod_target != lod.is_some() {
            return Err(GpuError::Mismatch {
                call,
                parameter: "self",
                found: format!("a pass built for {:?}", self.descriptor.target),
                expected: match lod_target {
                    true => "ImpostorPass::prepare_lod_buffer for a LOD-buffer target".into(),
                    false => "ImpostorPass::prepare for a colour or level-depth target".into(),
                },
            });
        }
        let l = textures.layout;
        let (prev_view_proj, viewport) = match lod {
            Some(lod) => (
                lod.prev_view_proj,
                [
                    lod.size.0 as f32,
                    lod.size.1 as f32,
                    f32::from(u8::from(lod.space == VisibilitySpace::Screen)),
                    lod.vis_scale,
                ],
            ),
            None => (view.view_proj, [0.0; 4]),
        };
        let uniform = ViewUniform {
            view_proj: view.view_proj.to_cols_array(),
            eye: view.eye.extend(1.0).to_array(),
            light: view.light.extend(view.ambient.clamp(0.0, 1.0)).to_array(),
            sphere: [l.center[0], l.center[1], l.center[2], l.radius],
            atlas: [l.frames, u32::from(l.shape.is_hemi()), l.frame_size, 0],
            prev_view_proj: prev_view_proj.to_cols_array(),
            viewport,
        };
        let uniform = buffer_with_data(
            gpu,
            bytemuck::bytes_of(&uniform),
            wgpu::BufferUsages::UNIFORM,
            "impostor view",
        )?;
        let words: Vec<InstanceWords> = instances
            .iter()
            .map(|i| InstanceWords {
                model: i.model.to_cols_array(),
                door: [
                    match i.alpha.is_nan() {
                        true => 1.0,
                        false => i.alpha.clamp(-1.0, 1.0),
                    },
                    i.tau,
                    i.tau_next,
                    0.0,
                ],
                id: [i.id, 0, 0, 0],
                prev_model: i.prev_model.to_cols_array(),
                tint: i.tint.extend(1.0).to_array(),
            })
            .collect();
        let buffer = buffer_with_data(
            gpu,
            bytemuck::cast_slice(&words),
            wgpu::BufferUsages::VERTEX,
            "impostor instances",
        )?;
        gpu.guarded(call, || {
            let view = |t: &wgpu::Texture| t.create_view(&Default::default());
            let (color, normal_depth) = (view(&textures.color), view(&textures.normal_depth));
            let mut entries = vec![
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&color),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&normal_depth),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::Sampler(&textures.sampler),
                },
            ];
            entries.extend(lod.map(|lod| wgpu::BindGroupEntry {
                binding: 4,
                resource: wgpu::BindingResource::TextureView(lod.visibility),
            }));
            let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("impostor"),
                layout: &self.group,
                entries: &entries,
            });
            Ok(PreparedImpostors {
                bind_group,
                instances: buffer,
                count: instances.len() as u32,
            })
        })
    }

    /// Draws the prepared instances into `pass`: one with one colour target of the descriptor's
    /// format and its depth target, a LOD buffer's (`LodBuffers::begin_pass`) or the level-depth
    /// pass (`LodBuffers::begin_level_depth_pass`), as the descriptor's `target` says.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, prepared: &PreparedImpostors) {
        if prepared.count == 0 {
            return;
        }
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &prepared.bind_group, &[]);
        pass.set_vertex_buffer(0, prepared.instances.slice(..));
        pass.draw(0..6, 0..prepared.count);
    }

    /// `instances` drawn into a new `width x height` target of the descriptor's colour format
    /// (cleared to transparent) and depth format, read back: tightly packed rows of 4 bytes a
    /// pixel (an RGBA8 or BGRA8 colour format; others are [`GpuError::Mismatch`]; so is a pass
    /// for another target than a colour one). For tests, tools and previews; a renderer draws
    /// into its own pass with [`draw`](Self::draw).
    pub fn render(
        &self,
        gpu: &GpuContext,
        textures: &ImpostorTextures,
        view: &ImpostorView,
        instances: &[ImpostorInstance],
        (width, height): (u32, u32),
    ) -> Result<Vec<u8>, GpuError> {
        use crate::gpu::resources::{begin_targets_pass, texture_2d};
        if self.descriptor.target != ImpostorTarget::Color {
            return Err(GpuError::Mismatch {
                call: "ImpostorPass::render",
                parameter: "self",
                found: format!("a pass built for {:?}", self.descriptor.target),
                expected: "a pass built for ImpostorTarget::Color".into(),
            });
        }
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
        let size = (width, height);
        let color = texture_2d(gpu, size, self.descriptor.color_format, usage, "impostors")?;
        let depth = texture_2d(
            gpu,
            size,
            self.descriptor.depth_format,
            usage,
            "impostor depth",
        )?;
        let prepared = self.prepare(gpu, textures, view, instances)?;
        gpu.guarded("ImpostorPass::render", || {
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            {
                let color_view = color.create_view(&Default::default());
                let depth_view = depth.create_view(&Default::default());
                let far = match self.descriptor.depth {
                    DepthConvention::Standard => 1.0,
                    DepthConvention::Reversed => 0.0,
                };
                let mut pass = begin_targets_pass(
                    &mut encoder,
                    &[(&color_view, wgpu::Color::TRANSPARENT)],
                    &depth_view,
                    far,
                    None,
                    "impostors",
                );
                self.draw(&mut pass, &prepared);
            }
            gpu.queue.submit([encoder.finish()]);
            Ok(())
        })?;
        crate::gpu::readback::read_texture_rgba8(gpu, &color)
    }
}
