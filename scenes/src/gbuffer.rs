//! Drawing meshes into a [`LowResBuffer`] with `passes/gbuffer_mesh.wgsl`: the reference for an
//! engine's low-resolution (or full-resolution prepass) pass under framebuffer LOD, used by the
//! examples, tests and demo.

use glam::{Mat4, Vec3, Vec4};

use crate::mesh::GpuMesh;
use lodkit::gbuffer::{GEOMETRY_FORMAT, PACKED_FORMAT};
use lodkit::gpu::checks::{check_low_res_format, same_color_format};
use lodkit::gpu::framebuffer_lod::{LOW_DEPTH_FORMAT, LowResBuffer};
use lodkit::gpu::resources::{
    DrawUniforms, camera_draw_layouts, depth_write_state, mesh_pipeline, uniform_buffer,
};
use lodkit::gpu::{GpuContext, GpuError};

/// Rust mirror of `GCamera` in `passes/gbuffer_mesh.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GCameraUniform {
    /// Projection x view.
    pub view_proj: [[f32; 4]; 4],
    /// World to view.
    pub view: [[f32; 4]; 4],
    /// xyz: world-space direction toward the light; w: synthetic shading work (sky directions
    /// summed per fragment, 0 = none).
    pub light_dir: [f32; 4],
}

/// Rust mirror of `GDraw` in `passes/gbuffer_mesh.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GDrawUniform {
    /// Object to world.
    pub model: [[f32; 4]; 4],
    /// Base color.
    pub color: [f32; 4],
}

/// One [`GBufferRenderer::render`]: at which resize factor, from where, what, and the clear.
#[derive(Clone, Copy, Debug)]
pub struct GBufferFrame<'a> {
    /// Resize factor r (the viewport is the target's size over r). Default: 1.
    pub r: f32,
    /// View matrix (the geometry's normals and depths are in view space). Default: identity.
    pub view: Mat4,
    /// Projection. Default: identity.
    pub proj: Mat4,
    /// The draws, in order. Default: none.
    pub items: &'a [GDrawItem<'a>],
    /// The color's clear color. Default: black.
    pub clear: wgpu::Color,
    /// The view depth the geometry is cleared to (the background's). Default: 1000.
    pub far_view_depth: f32,
}

impl Default for GBufferFrame<'_> {
    fn default() -> Self {
        Self {
            r: 1.0,
            view: Mat4::IDENTITY,
            proj: Mat4::IDENTITY,
            items: &[],
            clear: wgpu::Color::BLACK,
            far_view_depth: 1000.0,
        }
    }
}

/// One draw: mesh, transform, base color.
#[derive(Clone, Copy, Debug)]
pub struct GDrawItem<'a> {
    /// The mesh.
    pub mesh: &'a GpuMesh,
    /// Object to world.
    pub model: Mat4,
    /// Base color.
    pub color: Vec4,
}

/// What the color target of `passes/gbuffer_mesh.wgsl` holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ShadingTerm {
    /// Albedo x lighting.
    #[default]
    Full,
    /// Only the lighting (smooth; the part fine-grained resizing upsamples).
    Lighting,
    /// Only the striped albedo (detailed; rendered at full resolution).
    Albedo,
}

/// Draws [`GDrawItem`]s into a [`LowResBuffer`] at any resize factor.
#[derive(Debug)]
pub struct GBufferRenderer {
    pipeline: wgpu::RenderPipeline,
    camera: wgpu::Buffer,
    camera_group: wgpu::BindGroup,
    draws: DrawUniforms,
    draw_group: wgpu::BindGroup,
    shading_work: u32,
    color_format: wgpu::TextureFormat,
}

impl GBufferRenderer {
    /// Most draws per [`render`](Self::render).
    pub const MAX_DRAWS: usize = 256;

    /// Builds the pipeline for color format `color_format`, writing `term` into the color target.
    /// With [`PACKED_FORMAT`] it draws into a packed L ([`LowResBuffer::packed`]): `term` and the
    /// geometry packed into one texel (`gbuffer_pack_texel`).
    pub fn new(
        gpu: &GpuContext,
        color_format: wgpu::TextureFormat,
        term: ShadingTerm,
    ) -> Result<Self, GpuError> {
        const CALL: &str = "GBufferRenderer::new";
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        check_low_res_format(gpu, CALL, "color_format", color_format, usage)?;
        gpu.guarded(CALL, || Self::build(gpu, color_format, term))
    }

    fn build(
        gpu: &GpuContext,
        color_format: wgpu::TextureFormat,
        term: ShadingTerm,
    ) -> Result<Self, GpuError> {
        let packed = color_format == PACKED_FORMAT;
        let defs: Vec<&str> = [
            match term {
                ShadingTerm::Full => None,
                ShadingTerm::Lighting => Some("GBUFFER_MESH_LIGHTING_ONLY"),
                ShadingTerm::Albedo => Some("GBUFFER_MESH_ALBEDO_ONLY"),
            },
            packed.then_some("GBUFFER_MESH_PACKED"),
        ]
        .into_iter()
        .flatten()
        .collect();
        let module = gpu.pass_module("gbuffer_mesh", &defs)?;
        let targets = match packed {
            true => vec![Some(color_format.into())],
            false => vec![Some(color_format.into()), Some(GEOMETRY_FORMAT.into())],
        };
        let device = &gpu.device;
        let (camera_layout, draw_layout, layout) = camera_draw_layouts(gpu, "gbuffer_mesh", &[])?;
        let pipeline = mesh_pipeline(
            gpu,
            &module,
            &layout,
            &targets,
            depth_write_state(LOW_DEPTH_FORMAT, wgpu::CompareFunction::Less),
            "gbuffer_mesh",
        )?;
        let camera = uniform_buffer(gpu, std::mem::size_of::<GCameraUniform>(), "gbuffer camera")?;
        let camera_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &camera_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: camera.as_entire_binding(),
            }],
        });
        let draws = DrawUniforms::new(
            gpu,
            std::mem::size_of::<GDrawUniform>(),
            Self::MAX_DRAWS,
            "gbuffer draws",
        )?;
        let draw_group = draws.bind_group(gpu, &draw_layout)?;
        Ok(Self {
            pipeline,
            camera,
            camera_group,
            draws,
            draw_group,
            shading_work: 0,
            color_format,
        })
    }

    /// Sets the synthetic shading work per fragment: `n` directions of a smooth sky term (0, the
    /// default: a constant ambient). It stands in for expensive low-frequency shading when
    /// measuring what framebuffer LOD saves.
    pub fn set_shading_work(&mut self, n: u32) {
        self.shading_work = n;
    }

    /// Renders `frame.items` (at most [`Self::MAX_DRAWS`]: more is [`GpuError::TooManyDraws`])
    /// into `target` at resize factor `frame.r` (the viewport shrinks with r; the textures do
    /// not change), cleared to `frame.clear` with geometry (`frame.far_view_depth`, +z).
    /// `target` must have the color format the renderer was built for.
    pub fn render(
        &self,
        gpu: &GpuContext,
        target: &LowResBuffer,
        frame: &GBufferFrame,
    ) -> Result<(), GpuError> {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        self.record(gpu, &mut encoder, target, frame)?;
        gpu.queue.submit([encoder.finish()]);
        Ok(())
    }

    /// [`render`](Self::render) recorded into `encoder` (its uniforms written to the queue, so
    /// every recording until the submission draws the last ones written).
    pub fn record(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        target: &LowResBuffer,
        frame: &GBufferFrame,
    ) -> Result<(), GpuError> {
        let GBufferFrame {
            r,
            view,
            proj,
            items,
            clear,
            far_view_depth,
        } = *frame;
        const CALL: &str = "GBufferRenderer::render";
        same_color_format(CALL, "target", target.color_format(), self.color_format)?;
        self.draws.check_count(CALL, items.len())?;
        gpu.recording(CALL, || {
            let camera = GCameraUniform {
                view_proj: (proj * view).to_cols_array_2d(),
                view: view.to_cols_array_2d(),
                light_dir: Vec3::new(0.5, 0.8, 0.4)
                    .extend(self.shading_work as f32)
                    .to_array(),
            };
            gpu.queue
                .write_buffer(&self.camera, 0, bytemuck::bytes_of(&camera));
            let uniforms: Vec<GDrawUniform> = items
                .iter()
                .map(|i| GDrawUniform {
                    model: i.model.to_cols_array_2d(),
                    color: i.color.to_array(),
                })
                .collect();
            self.draws.write(gpu, &uniforms)?;
            let mut pass = target.begin_pass(encoder, r, clear, far_view_depth);
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.camera_group, &[]);
            for (i, item) in items.iter().enumerate() {
                pass.set_bind_group(1, &self.draw_group, &[self.draws.offset(i)]);
                item.mesh.draw(&mut pass);
            }
            Ok(())
        })
    }
}

/// An edge-heavy test scene: boxes and spheres of different depths and orientations in front of
/// a far wall, with striped shading; the framebuffer-LOD quality tests and examples render it,
/// into an L of its color format or a packed L ([`LowResBuffer::packed`]).
#[derive(Debug)]
pub struct EdgeScene {
    renderers: [GBufferRenderer; 3],
    /// The renderers for a packed L, built on first use.
    packed: std::sync::OnceLock<[GBufferRenderer; 3]>,
    shading_work: u32,
    sphere: GpuMesh,
    cube: GpuMesh,
    aspect: f32,
}

impl EdgeScene {
    /// View depth of the background (cleared geometry).
    pub const FAR_VIEW_DEPTH: f32 = 40.0;

    /// Uploads the meshes and builds the renderer for targets of `color_format` (and, on first
    /// use, for packed ones) and `aspect` (width / height: finite and positive).
    pub fn new(
        gpu: &GpuContext,
        color_format: wgpu::TextureFormat,
        aspect: f32,
    ) -> Result<Self, GpuError> {
        const CALL: &str = "EdgeScene::new";
        if !(aspect.is_finite() && aspect > 0.0) {
            return Err(GpuError::Invalid {
                call: CALL,
                parameter: "aspect",
                value: aspect.to_string(),
                rule: "must be finite and positive",
            });
        }
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        check_low_res_format(gpu, CALL, "color_format", color_format, usage)?;
        gpu.guarded(CALL, || {
            Ok(Self {
                renderers: Self::renderers(gpu, color_format, 0)?,
                packed: std::sync::OnceLock::new(),
                shading_work: 0,
                sphere: GpuMesh::new(gpu, &crate::mesh::Mesh::sphere(24, 48))?,
                cube: GpuMesh::new(gpu, &crate::mesh::Mesh::cube())?,
                aspect,
            })
        })
    }

    fn renderers(
        gpu: &GpuContext,
        color_format: wgpu::TextureFormat,
        work: u32,
    ) -> Result<[GBufferRenderer; 3], GpuError> {
        let mut renderers = [
            GBufferRenderer::new(gpu, color_format, ShadingTerm::Full)?,
            GBufferRenderer::new(gpu, color_format, ShadingTerm::Lighting)?,
            GBufferRenderer::new(gpu, color_format, ShadingTerm::Albedo)?,
        ];
        for r in &mut renderers {
            r.set_shading_work(work);
        }
        Ok(renderers)
    }

    /// Sets the synthetic shading work of every term (see [`GBufferRenderer::set_shading_work`]).
    pub fn set_shading_work(&mut self, n: u32) {
        self.shading_work = n;
        let packed = self.packed.get_mut().into_iter().flatten();
        for r in self.renderers.iter_mut().chain(packed) {
            r.set_shading_work(n);
        }
    }

    /// Renders the full shading into `target` at resize factor `r`.
    pub fn render(&self, gpu: &GpuContext, target: &LowResBuffer, r: f32) -> Result<(), GpuError> {
        self.render_term(gpu, target, r, ShadingTerm::Full)
    }

    /// Renders one shading term into `target` at resize factor `r`.
    pub fn render_term(
        &self,
        gpu: &GpuContext,
        target: &LowResBuffer,
        r: f32,
        term: ShadingTerm,
    ) -> Result<(), GpuError> {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        self.record_term(gpu, &mut encoder, target, r, term)?;
        gpu.queue.submit([encoder.finish()]);
        Ok(())
    }

    /// [`render_term`](Self::render_term) recorded into `encoder` (to time it with GPU
    /// timestamps, or to record it with other passes).
    pub fn record_term(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        target: &LowResBuffer,
        r: f32,
        term: ShadingTerm,
    ) -> Result<(), GpuError> {
        let view = glam::camera::rh::view::look_at_mat4(
            Vec3::new(0.5, 1.2, 6.0),
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::Y,
        );
        let proj = glam::camera::rh::proj::directx::perspective(0.9, self.aspect, 0.1, 100.0);
        let rot = |a: f32, b: f32| Mat4::from_rotation_y(a) * Mat4::from_rotation_x(b);
        let t = Mat4::from_translation;
        let s = |v: f32| Mat4::from_scale(Vec3::splat(v));
        let items = [
            GDrawItem {
                mesh: &self.cube,
                model: t(Vec3::new(0.0, 0.0, -12.0)) * Mat4::from_scale(Vec3::new(12.0, 8.0, 0.2)),
                color: Vec4::new(0.9, 0.85, 0.7, 1.0),
            },
            GDrawItem {
                mesh: &self.cube,
                model: t(Vec3::new(-1.6, 0.0, -1.0)) * rot(0.6, 0.3) * s(0.8),
                color: Vec4::new(0.9, 0.3, 0.2, 1.0),
            },
            GDrawItem {
                mesh: &self.sphere,
                model: t(Vec3::new(1.2, 0.3, 0.0)) * s(0.9),
                color: Vec4::new(0.2, 0.5, 0.9, 1.0),
            },
            GDrawItem {
                mesh: &self.cube,
                model: t(Vec3::new(0.3, -0.8, 1.5)) * rot(-0.8, 0.5) * s(0.5),
                color: Vec4::new(0.3, 0.8, 0.3, 1.0),
            },
            GDrawItem {
                mesh: &self.sphere,
                model: t(Vec3::new(-0.5, 1.0, -3.0)) * s(0.7),
                color: Vec4::new(0.8, 0.7, 0.2, 1.0),
            },
            GDrawItem {
                mesh: &self.cube,
                model: t(Vec3::new(2.2, -0.5, -4.0)) * rot(0.3, -0.4) * s(1.0),
                color: Vec4::new(0.6, 0.3, 0.8, 1.0),
            },
        ];
        let clear = wgpu::Color {
            r: 0.1,
            g: 0.12,
            b: 0.15,
            a: 1.0,
        };
        let renderers = match target.is_packed() {
            false => &self.renderers,
            true => match self.packed.get() {
                Some(packed) => packed,
                None => {
                    let built = Self::renderers(gpu, PACKED_FORMAT, self.shading_work)?;
                    self.packed.get_or_init(|| built)
                }
            },
        };
        let (renderer, clear) = match term {
            ShadingTerm::Full => (&renderers[0], clear),
            ShadingTerm::Lighting => (&renderers[1], wgpu::Color::WHITE),
            ShadingTerm::Albedo => (&renderers[2], clear),
        };
        let frame = GBufferFrame {
            r,
            view,
            proj,
            items: &items,
            clear,
            far_view_depth: Self::FAR_VIEW_DEPTH,
        };
        renderer.record(gpu, encoder, target, &frame)
    }
}
