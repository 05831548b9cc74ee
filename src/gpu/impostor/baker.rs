//! [`ImpostorBaker`]: a mesh and its material on the GPU, drawn into every frame of an atlas
//! (`passes/impostor_bake.wgsl`), or from any camera as the reference an impostor is held to.

use glam::{Mat4, Vec3, Vec4};
use wgpu::util::DeviceExt;

use super::{ImpostorBakeDescriptor, ImpostorPart, check_input, impostor_bounds, vertices};
use crate::gpu::readback::read_texture;
use crate::gpu::resources::{
    DrawUniforms, depth_write_state, texture_2d, texture_entry, uniform_entry,
};
use crate::gpu::{GpuContext, GpuError};
use crate::impostor::{
    ImpostorAtlas, ImpostorImage, ImpostorLayout, dilate_frames, impostor_frame_basis,
    impostor_frame_dir,
};

/// Rust mirror of `BakeParams` in `passes/impostor_bake.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct BakeParams {
    clip_from_object: [f32; 16],
    dir: [f32; 4],
    sphere: [f32; 4],
    base_color: [f32; 4],
    material: [f32; 4],
}

/// One draw of a part: its parameters and the viewport it fills.
#[derive(Clone, Copy, Debug)]
struct Draw {
    part: usize,
    params: BakeParams,
    viewport: [f32; 4],
}

/// Colour and normal-depth targets of the bake (linear, exact enough for the CPU steps).
const BAKE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
const BAKE_DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// One part on the GPU: its buffers, texture and material words.
#[derive(Debug)]
struct GpuPart {
    texture_group: wgpu::BindGroup,
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    double_sided: bool,
    base_color: [f32; 4],
    material: [f32; 4],
}

/// A mesh's parts and their materials, ready to bake or to draw as a reference.
#[derive(Debug)]
pub struct ImpostorBaker {
    /// Back faces culled, and not (double-sided materials).
    pipelines: [wgpu::RenderPipeline; 2],
    params_layout: wgpu::BindGroupLayout,
    parts: Vec<GpuPart>,
    center: [f32; 3],
    radius: f32,
}

impl ImpostorBaker {
    /// Checks every part (bad input is [`GpuError::Invalid`] naming the field and the part) and
    /// uploads them with the bake pipelines. The bounding sphere is the one around all parts.
    pub fn new(gpu: &GpuContext, parts: &[ImpostorPart]) -> Result<Self, GpuError> {
        const CALL: &str = "ImpostorBaker::new";
        if parts.is_empty() {
            return Err(GpuError::Invalid {
                call: CALL,
                parameter: "parts",
                value: "none".into(),
                rule: "must hold at least one mesh",
            });
        }
        for (k, part) in parts.iter().enumerate() {
            check_input(k, &part.mesh, &part.material)?;
        }
        let all: Vec<[f32; 3]> = parts
            .iter()
            .flat_map(|p| p.mesh.positions.iter().copied())
            .collect();
        let (center, radius) = impostor_bounds(&all);
        let module = gpu.pass_module("impostor_bake", &[])?;
        for part in parts {
            if let Some(t) = part.material.base_color_texture {
                crate::gpu::checks::texture_extent(gpu, CALL, t.width, t.height)?;
            }
        }
        gpu.guarded(CALL, || {
            let device = &gpu.device;
            let params_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some("impostor bake params"),
                entries: &[uniform_entry(0, true)],
            });
            let texture_layout =
                device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some("impostor bake texture"),
                    entries: &[
                        texture_entry(0, wgpu::TextureSampleType::Float { filterable: true }),
                        wgpu::BindGroupLayoutEntry {
                            binding: 1,
                            visibility: wgpu::ShaderStages::FRAGMENT,
                            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                            count: None,
                        },
                    ],
                });
            let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("impostor bake"),
                bind_group_layouts: &[Some(&params_layout), Some(&texture_layout)],
                immediate_size: 0,
            });
            let targets = [Some(BAKE_FORMAT.into()), Some(BAKE_FORMAT.into())];
            let pipeline = |cull_mode| {
                device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some("impostor bake"),
                    layout: Some(&pipeline_layout),
                    vertex: wgpu::VertexState {
                        module: &module,
                        entry_point: Some("vs_main"),
                        compilation_options: Default::default(),
                        buffers: &[Some(wgpu::VertexBufferLayout {
                            array_stride: 32,
                            step_mode: wgpu::VertexStepMode::Vertex,
                            attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2],
                        })],
                    },
                    primitive: wgpu::PrimitiveState {
                        cull_mode,
                        ..Default::default()
                    },
                    depth_stencil: Some(depth_write_state(BAKE_DEPTH, wgpu::CompareFunction::Less)),
                    multisample: Default::default(),
                    fragment: Some(wgpu::FragmentState {
                        module: &module,
                        entry_point: Some("fs_main"),
                        compilation_options: Default::default(),
                        targets: &targets,
                    }),
                    multiview_mask: None,
                    cache: None,
                })
            };
            let pipelines = [pipeline(Some(wgpu::Face::Back)), pipeline(None)];
            let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("impostor bake"),
                address_mode_u: wgpu::AddressMode::Repeat,
                address_mode_v: wgpu::AddressMode::Repeat,
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                ..Default::default()
            });
            let white = [255u8; 4];
            let gpu_parts = parts
                .iter()
                .map(|part| {
                    let material = &part.material;
                    let (tw, th, texels) = material
                        .base_color_texture
                        .map_or((1, 1, &white[..]), |t| (t.width, t.height, t.rgba8));
                    let base = device.create_texture_with_data(
                        &gpu.queue,
                        &wgpu::TextureDescriptor {
                            label: Some("impostor bake base colour"),
                            size: wgpu::Extent3d {
                                width: tw,
                                height: th,
                                depth_or_array_layers: 1,
                            },
                            mip_level_count: 1,
                            sample_count: 1,
                            dimension: wgpu::TextureDimension::D2,
                            format: wgpu::TextureFormat::Rgba8UnormSrgb,
                            usage: wgpu::TextureUsages::TEXTURE_BINDING,
                            view_formats: &[],
                        },
                        wgpu::util::TextureDataOrder::LayerMajor,
                        texels,
                    );
                    let texture_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                        label: Some("impostor bake texture"),
                        layout: &texture_layout,
                        entries: &[
                            wgpu::BindGroupEntry {
                                binding: 0,
                                resource: wgpu::BindingResource::TextureView(
                                    &base.create_view(&Default::default()),
                                ),
                            },
                            wgpu::BindGroupEntry {
                                binding: 1,
                                resource: wgpu::BindingResource::Sampler(&sampler),
                            },
                        ],
                    });
                    let buffer = |label, contents: &[u8], usage| {
                        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                            label: Some(label),
                            contents,
                            usage,
                        })
                    };
                    GpuPart {
                        texture_group,
                        vertices: buffer(
                            "impostor bake vertices",
                            bytemuck::cast_slice(&vertices(&part.mesh)),
                            wgpu::BufferUsages::VERTEX,
                        ),
                        indices: buffer(
                            "impostor bake indices",
                            bytemuck::cast_slice(part.mesh.indices),
                            wgpu::BufferUsages::INDEX,
                        ),
                        index_count: part.mesh.indices.len() as u32,
                        double_sided: material.double_sided,
                        base_color: material.base_color,
                        material: [
                            f32::from(u8::from(material.double_sided)),
                            material.alpha_cutoff.unwrap_or(0.0),
                            0.0,
                            0.0,
                        ],
                    }
                })
                .collect();
            Ok(Self {
                pipelines,
                params_layout,
                parts: gpu_parts,
                center,
                radius,
            })
        })
    }

    /// The bounding sphere it bakes around: centre and radius ([`impostor_bounds`]).
    pub fn bounds(&self) -> ([f32; 3], f32) {
        (self.center, self.radius)
    }

    /// Object space to the clip space of frame `frame`: the frame's square `[-1, 1]²` of
    /// normalized object space fills the viewport, the nearest point (height 1) at depth ~0.
    fn frame_matrix(&self, layout: &ImpostorLayout, frame: glam::UVec2) -> (Mat4, Vec3) {
        let dir = impostor_frame_dir(frame, layout.frames, layout.shape.is_hemi());
        let basis = impostor_frame_basis(dir);
        let to_frame = Mat4::from_cols(
            Vec4::new(basis.x_axis.x, basis.y_axis.x, -0.499 * dir.x, 0.0),
            Vec4::new(basis.x_axis.y, basis.y_axis.y, -0.499 * dir.y, 0.0),
            Vec4::new(basis.x_axis.z, basis.y_axis.z, -0.499 * dir.z, 0.0),
            Vec4::new(0.0, 0.0, 0.5, 1.0),
        );
        let normalize = Mat4::from_scale(Vec3::splat(1.0 / self.radius))
            * Mat4::from_translation(-Vec3::from(self.center));
        (to_frame * normalize, dir)
    }

    /// Part `part` drawn through `clip_from_object` into `viewport`.
    fn draw_of(&self, part: usize, clip_from_object: Mat4, dir: Vec3, viewport: [f32; 4]) -> Draw {
        let p = &self.parts[part];
        Draw {
            part,
            params: BakeParams {
                clip_from_object: clip_from_object.to_cols_array(),
                dir: dir.extend(0.0).to_array(),
                sphere: Vec3::from(self.center).extend(self.radius).to_array(),
                base_color: p.base_color,
                material: p.material,
            },
            viewport,
        }
    }

    /// Bakes the atlas `descriptor` describes: one render pass draws every frame into its
    /// viewport; the CPU then pads the frames ([`dilate_frames`]) and builds the mip chains
    /// ([`ImpostorAtlas::from_level0`]).
    pub fn bake(
        &self,
        gpu: &GpuContext,
        descriptor: &ImpostorBakeDescriptor,
    ) -> Result<ImpostorAtlas, GpuError> {
        const CALL: &str = "ImpostorBaker::bake";
        let layout = ImpostorLayout {
            frames: descriptor.frames,
            frame_size: descriptor.frame_size,
            shape: descriptor.shape,
            center: self.center,
            radius: self.radius,
        };
        layout.validate().map_err(|e| GpuError::Invalid {
            call: CALL,
            parameter: "descriptor",
            value: e.to_string(),
            rule: "must describe an atlas lodkit can bake",
        })?;
        let n = layout.frames;
        let mut draws = Vec::with_capacity((n * n) as usize * self.parts.len());
        for part in 0..self.parts.len() {
            for f in 0..n * n {
                let frame = glam::UVec2::new(f % n, f / n);
                let (m, dir) = self.frame_matrix(&layout, frame);
                let s = layout.frame_size as f32;
                let viewport = [frame.x as f32 * s, frame.y as f32 * s, s, s];
                draws.push(self.draw_of(part, m, dir, viewport));
            }
        }
        let size = layout.atlas_size();
        let (color, normal_depth) = self.draw(gpu, CALL, (size, size), &draws)?;
        let mut color = to_image(size, &color);
        let mut normal_depth = to_image(size, &normal_depth);
        dilate_frames(&mut color, &mut [&mut normal_depth], n, layout.frame_size);
        ImpostorAtlas::from_level0(layout, color, normal_depth).map_err(|e| GpuError::Invalid {
            call: CALL,
            parameter: "descriptor",
            value: e.to_string(),
            rule: "must describe an atlas lodkit can bake",
        })
    }

    /// The mesh drawn through `clip_from_object` (object space to wgpu clip space: z in
    /// [0, 1]) into a `width x height` image (row 0 at the top): linear base colour with alpha 1
    /// where the mesh covers the pixel (after its alpha test), 0 elsewhere. The reference an
    /// impostor drawn with the same camera is compared with.
    pub fn render(
        &self,
        gpu: &GpuContext,
        clip_from_object: Mat4,
        width: u32,
        height: u32,
    ) -> Result<Vec<[f32; 4]>, GpuError> {
        let instances: Vec<(usize, Mat4)> =
            (0..self.parts.len()).map(|k| (k, Mat4::IDENTITY)).collect();
        self.render_instances(gpu, clip_from_object, &instances, width, height)
    }

    /// Instances of single parts, `(part, object to world)`, drawn through `clip_from_world`
    /// into one `width x height` image as [`render`](Self::render) draws: a scene of objects
    /// (a forest), each at the level of detail its part holds. At most as many instances as
    /// the device's uniform buffer takes at once (a slot each).
    pub fn render_instances(
        &self,
        gpu: &GpuContext,
        clip_from_world: Mat4,
        instances: &[(usize, Mat4)],
        width: u32,
        height: u32,
    ) -> Result<Vec<[f32; 4]>, GpuError> {
        const CALL: &str = "ImpostorBaker::render_instances";
        if let Some((k, (part, _))) = instances
            .iter()
            .enumerate()
            .find(|(_, (part, _))| *part >= self.parts.len())
        {
            return Err(GpuError::Invalid {
                call: CALL,
                parameter: "instances",
                value: format!("part {part} at instance {k}"),
                rule: "must name one of the baker's parts",
            });
        }
        let viewport = [0.0, 0.0, width.max(1) as f32, height.max(1) as f32];
        let draws: Vec<Draw> = instances
            .iter()
            .map(|(part, model)| self.draw_of(*part, clip_from_world * *model, Vec3::Z, viewport))
            .collect();
        let (color, _) = self.draw(gpu, CALL, (width, height), &draws)?;
        Ok(to_image(width.max(1), &color).texels)
    }

    /// Makes each draw into its viewport of a `size` target pair; returns both targets'
    /// Rgba16Float bytes.
    fn draw(
        &self,
        gpu: &GpuContext,
        call: &'static str,
        (width, height): (u32, u32),
        draws: &[Draw],
    ) -> Result<(Vec<u8>, Vec<u8>), GpuError> {
        crate::gpu::checks::texture_extent(gpu, call, width, height)?;
        let params: Vec<BakeParams> = draws.iter().map(|d| d.params).collect();
        let uniforms =
            DrawUniforms::new(gpu, size_of::<BakeParams>(), params.len(), "impostor bake")?;
        uniforms.write(gpu, &params)?;
        let params_group = uniforms.bind_group(gpu, &self.params_layout)?;
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
        let size = (width, height);
        let color = texture_2d(gpu, size, BAKE_FORMAT, usage, "impostor bake colour")?;
        let normal_depth = texture_2d(gpu, size, BAKE_FORMAT, usage, "impostor normal-depth")?;
        let depth = texture_2d(gpu, size, BAKE_DEPTH, usage, "impostor bake depth")?;
        gpu.guarded(call, || {
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            {
                let view = |t: &wgpu::Texture| t.create_view(&Default::default());
                let views_out = [view(&color), view(&normal_depth)];
                let attachment = |view| {
                    Some(wgpu::RenderPassColorAttachment {
                        view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                            store: wgpu::StoreOp::Store,
                        },
                    })
                };
                let depth_view = view(&depth);
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("impostor bake"),
                    color_attachments: &[attachment(&views_out[0]), attachment(&views_out[1])],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: &depth_view,
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(1.0),
                            store: wgpu::StoreOp::Discard,
                        }),
                        stencil_ops: None,
                    }),
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                let mut bound = None;
                for (k, d) in draws.iter().enumerate() {
                    let part = &self.parts[d.part];
                    if bound != Some(d.part) {
                        pass.set_pipeline(&self.pipelines[usize::from(part.double_sided)]);
                        pass.set_bind_group(1, &part.texture_group, &[]);
                        pass.set_vertex_buffer(0, part.vertices.slice(..));
                        pass.set_index_buffer(part.indices.slice(..), wgpu::IndexFormat::Uint32);
                        bound = Some(d.part);
                    }
                    let [x, y, w, h] = d.viewport;
                    pass.set_viewport(x, y, w, h, 0.0, 1.0);
                    pass.set_bind_group(0, &params_group, &[uniforms.offset(k)]);
                    pass.draw_indexed(0..part.index_count, 0, 0..1);
                }
            }
            gpu.queue.submit([encoder.finish()]);
            Ok(())
        })?;
        Ok((
            read_texture(gpu, &color, 8)?,
            read_texture(gpu, &normal_depth, 8)?,
        ))
    }
}

/// Rgba16Float bytes as texels.
fn to_image(size: u32, bytes: &[u8]) -> ImpostorImage {
    let texels = bytes
        .chunks_exact(8)
        .map(|t| {
            let h = |i: usize| half::f16::from_le_bytes([t[i], t[i + 1]]).to_f32();
            [h(0), h(2), h(4), h(6)]
        })
        .collect();
    ImpostorImage { size, texels }
}
