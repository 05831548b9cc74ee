//! [`ImpostorPass`]: instances of one baked impostor drawn into the engine's own render pass
//! (`passes/impostor.wgsl`).

use super::ImpostorTextures;
use super::instance::{INSTANCE_ATTRIBUTES, ImpostorInstance, ImpostorView, InstanceWords};
use crate::combine::DepthConvention;
use crate::gpu::frame_sequential::LOD_DEPTH_FORMAT;
use crate::gpu::resources::uniform_entry;
use crate::gpu::{GpuContext, GpuError};
use crate::lod_buffer::{ID_FORMAT, MOTION_FORMAT};
use crate::screen_door::DitherPattern;
use crate::unpopping::LodRenderState;

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
    /// passes serve every role, as two pipelines serve a mesh's. Other targets take only
    /// [`LodRenderState::OPAQUE`] ([`ImpostorPass::new`] refuses the rest by name).
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

/// A pipeline that draws impostors.
#[derive(Debug)]
pub struct ImpostorPass {
    pipeline: wgpu::RenderPipeline,
    group: wgpu::BindGroupLayout,
    descriptor: ImpostorPassDescriptor,
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

    /// The descriptor it was built with.
    pub fn descriptor(&self) -> &ImpostorPassDescriptor {
        &self.descriptor
    }

    /// The bind group layout of its group 0.
    pub(super) fn group(&self) -> &wgpu::BindGroupLayout {
        &self.group
    }

    /// Its pipeline.
    pub(super) fn pipeline(&self) -> &wgpu::RenderPipeline {
        &self.pipeline
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
