//! [`ImpostorPass`]: instances of one baked impostor drawn into the engine's own render pass
//! (`passes/impostor.wgsl`).

use super::ImpostorTextures;
use crate::combine::DepthConvention;
use crate::gpu::resources::{buffer_with_data, uniform_entry};
use crate::gpu::{GpuContext, GpuError};
use crate::screen_door::DitherPattern;

/// How to build an [`ImpostorPass`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
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
}

impl Default for ImpostorPassDescriptor {
    /// `Rgba8UnormSrgb` colour, `Depth32Float` depth, standard depth, the 4x4 Bayer pattern.
    fn default() -> Self {
        Self {
            color_format: wgpu::TextureFormat::Rgba8UnormSrgb,
            depth_format: wgpu::TextureFormat::Depth32Float,
            depth: DepthConvention::Standard,
            dither: DitherPattern::Bayer4x4,
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

/// One impostor instance: its object-to-world transform (a rotation, a uniform scale and a
/// translation; the card and the depth it writes assume no shear) and its screen-door alpha.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImpostorInstance {
    /// Object to world.
    pub model: glam::Mat4,
    /// The complementary screen-door pattern's alpha (`lodkit::screen_door`), in [-1, 1]: 1
    /// draws every pixel; in a transition from a mesh level at `-(1 - t)` the impostor takes
    /// `t` (or the other way round), and the two cover disjoint pixels whose union is the
    /// object's. Values outside are clamped, a NaN taken as 1.
    pub alpha: f32,
}

impl ImpostorInstance {
    /// An instance at `model`, drawn whole (alpha 1).
    pub fn new(model: glam::Mat4) -> Self {
        Self { model, alpha: 1.0 }
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
}

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
    /// Builds the pipeline.
    pub fn new(gpu: &GpuContext, descriptor: &ImpostorPassDescriptor) -> Result<Self, GpuError> {
        const CALL: &str = "ImpostorPass::new";
        crate::gpu::checks::check_color_format(
            gpu,
            CALL,
            "color_format",
            descriptor.color_format,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )?;
        let defs: &[&str] = match descriptor.dither {
            DitherPattern::Bayer4x4 => &[],
            DitherPattern::BlueNoise16x16 => &["LODKIT_SCREEN_DOOR_BLUE_NOISE"],
        };
        let module = gpu.pass_module("impostor", defs)?;
        gpu.guarded(CALL, || {
            let device = &gpu.device;
            let texture = |binding| {
                crate::gpu::resources::texture_entry(
                    binding,
                    wgpu::TextureSampleType::Float { filterable: true },
                )
            };
            let group = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("impostor"),
                entries: &[
                    uniform_entry(0, false),
                    texture(1),
                    texture(2),
                    wgpu::BindGroupLayoutEntry {
                        binding: 3,
                        visibility: wgpu::ShaderStages::FRAGMENT,
                        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                        count: None,
                    },
                ],
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
                        array_stride: 80,
                        step_mode: wgpu::VertexStepMode::Instance,
                        attributes: &wgpu::vertex_attr_array![0 => Float32x4, 1 => Float32x4, 2 => Float32x4, 3 => Float32x4, 4 => Float32x4],
                    })],
                },
                primitive: Default::default(),
                depth_stencil: Some(crate::gpu::resources::depth_write_state(
                    descriptor.depth_format,
                    match descriptor.depth {
                        DepthConvention::Standard => wgpu::CompareFunction::Less,
                        DepthConvention::Reversed => wgpu::CompareFunction::Greater,
                    },
                )),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &[Some(descriptor.color_format.into())],
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
    /// from `view`.
    pub fn prepare(
        &self,
        gpu: &GpuContext,
        textures: &ImpostorTextures,
        view: &ImpostorView,
        instances: &[ImpostorInstance],
    ) -> Result<PreparedImpostors, GpuError> {
        const CALL: &str = "ImpostorPass::prepare";
        let l = textures.layout;
        let uniform = ViewUniform {
            view_proj: view.view_proj.to_cols_array(),
            eye: view.eye.extend(1.0).to_array(),
            light: view.light.extend(view.ambient.clamp(0.0, 1.0)).to_array(),
            sphere: [l.center[0], l.center[1], l.center[2], l.radius],
            atlas: [l.frames, u32::from(l.shape.is_hemi()), l.frame_size, 0],
        };
        let uniform = buffer_with_data(
            gpu,
            bytemuck::bytes_of(&uniform),
            wgpu::BufferUsages::UNIFORM,
            "impostor view",
        )?;
        let models: Vec<[f32; 20]> = instances
            .iter()
            .map(|i| {
                let mut words = [0.0; 20];
                words[..16].copy_from_slice(&i.model.to_cols_array());
                words[16] = if i.alpha.is_nan() {
                    1.0
                } else {
                    i.alpha.clamp(-1.0, 1.0)
                };
                words
            })
            .collect();
        let buffer = buffer_with_data(
            gpu,
            bytemuck::cast_slice(&models),
            wgpu::BufferUsages::VERTEX,
            "impostor instances",
        )?;
        gpu.guarded(CALL, || {
            let view = |t: &wgpu::Texture| t.create_view(&Default::default());
            let (color, normal_depth) = (view(&textures.color), view(&textures.normal_depth));
            let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("impostor"),
                layout: &self.group,
                entries: &[
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
                ],
            });
            Ok(PreparedImpostors {
                bind_group,
                instances: buffer,
                count: instances.len() as u32,
            })
        })
    }

    /// Draws the prepared instances into `pass` (a pass with one colour target of the
    /// descriptor's format and its depth target).
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
    /// pixel (an RGBA8 or BGRA8 colour format; others are [`GpuError::Mismatch`]). For tests,
    /// tools and previews; a renderer draws into its own pass with [`draw`](Self::draw).
    pub fn render(
        &self,
        gpu: &GpuContext,
        textures: &ImpostorTextures,
        view: &ImpostorView,
        instances: &[ImpostorInstance],
        (width, height): (u32, u32),
    ) -> Result<Vec<u8>, GpuError> {
        use crate::gpu::resources::{begin_targets_pass, texture_2d};
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
