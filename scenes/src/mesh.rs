//! A small mesh renderer for the examples, tests and demo: procedural meshes and
//! `passes/lod_mesh.wgsl` drawn opaque, blended (unpopping, cross-fade) or screen-door dithered.
//! It is the reference for what an engine's own forward pass needs, not a scene graph.

use std::f32::consts::{PI, TAU};

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3, Vec4};

use lodkit::alpha_mask::AlphaMask;
use lodkit::gpu::checks::texture_extent;
use lodkit::gpu::counters::FragmentCounter;
use lodkit::gpu::resources::{
    DrawUniforms, begin_targets_pass, buffer_with_data, camera_draw_layouts, mesh_pipeline,
    r32float_texture, texture_2d, texture_entry, uniform_buffer,
};
use lodkit::gpu::unpopping::{lod_blend, lod_blend_constant, lod_depth_stencil};
use lodkit::gpu::{GpuContext, GpuError};
use lodkit::silhouette::{SilhouetteError, Surface};
use lodkit::unpopping::LodRenderState;

/// Depth format of [`RenderTarget`].
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Color format of [`RenderTarget`].
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// `dither_alpha` meaning "no screen door".
pub const DITHER_OFF: f32 = 2.0;

/// Triangle mesh: interleaved position and normal, 32-bit indices.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// `[px, py, pz, nx, ny, nz]` per vertex.
    pub vertices: Vec<[f32; 6]>,
    /// Counter-clockwise triangles.
    pub indices: Vec<u32>,
}

impl Mesh {
    /// A unit-radius UV sphere; few segments make a coarse LOD. Rings are clamped to 2..=2048
    /// and segments to 3..=4096 (at most 8.4 million vertices).
    pub fn sphere(rings: u32, segments: u32) -> Self {
        let (rings, segments) = (rings.clamp(2, 2048), segments.clamp(3, 4096));
        let mut m = Mesh::default();
        for r in 0..=rings {
            let theta = PI * r as f32 / rings as f32;
            for s in 0..=segments {
                let phi = TAU * s as f32 / segments as f32;
                let n = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                );
                m.vertices.push([n.x, n.y, n.z, n.x, n.y, n.z]);
            }
        }
        let row = segments + 1;
        for r in 0..rings {
            for s in 0..segments {
                let (a, b) = (r * row + s, (r + 1) * row + s);
                m.indices.extend([a, a + 1, b, b, a + 1, b + 1]);
            }
        }
        m
    }

    /// An axis-aligned cube from -1 to 1 with flat normals.
    pub fn cube() -> Self {
        let mut m = Mesh::default();
        for axis in 0..3 {
            for sign in [-1.0f32, 1.0] {
                let mut n = [0.0; 3];
                n[axis] = sign;
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let base = m.vertices.len() as u32;
                for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                    let mut p = [0.0; 3];
                    p[axis] = sign;
                    p[u] = a;
                    p[v] = b;
                    m.vertices.push([p[0], p[1], p[2], n[0], n[1], n[2]]);
                }
                if sign > 0.0 {
                    m.indices
                        .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
                } else {
                    m.indices
                        .extend([base, base + 2, base + 1, base, base + 3, base + 2]);
                }
            }
        }
        m
    }

    /// A card: the rectangle `min..max` in the z = 0 plane, facing +z (two triangles). With an
    /// alpha mask over the same rectangle
    /// ([`alpha_mask_rect`](lodkit::alpha_mask::alpha_mask_rect)) it is a billboard impostor.
    pub fn card(min: glam::Vec2, max: glam::Vec2) -> Self {
        let corners = [
            (min.x, min.y),
            (max.x, min.y),
            (max.x, max.y),
            (min.x, max.y),
        ];
        Mesh {
            vertices: corners
                .iter()
                .map(|&(x, y)| [x, y, 0.0, 0.0, 0.0, 1.0])
                .collect(),
            indices: vec![0, 1, 2, 0, 2, 3],
        }
    }

    /// Object-space bounding box (min, max) of the vertices; `None` for an empty mesh.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut points = self.vertices.iter().map(|v| Vec3::new(v[0], v[1], v[2]));
        let first = points.next()?;
        Some(points.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
    }

    /// Its surface for silhouettes ([`Surface`]: welded positions, edge twins); an error for a
    /// mesh that is not closed (a card) or has an index past its vertices.
    pub fn surface(&self) -> Result<Surface, SilhouetteError> {
        let points: Vec<[f32; 3]> = self.vertices.iter().map(|v| [v[0], v[1], v[2]]).collect();
        Surface::new(&points, Some(&self.indices))
    }

    /// Number of triangles.
    pub fn triangles(&self) -> usize {
        self.indices.len() / 3
    }

    /// Its streams as an impostor bake reads them (positions and normals apart).
    pub fn bake_streams(&self) -> BakeStreams {
        BakeStreams {
            positions: self.vertices.iter().map(|v| [v[0], v[1], v[2]]).collect(),
            normals: self.vertices.iter().map(|v| [v[3], v[4], v[5]]).collect(),
            indices: self.indices.clone(),
        }
    }

    /// Appends `other` transformed by `transform` (normals by its inverse transpose), to build
    /// one mesh out of several parts.
    pub fn append(&mut self, other: &Mesh, transform: Mat4) {
        let base = self.vertices.len() as u32;
        let normal_matrix = glam::Mat3::from_mat4(transform).inverse().transpose();
        self.vertices.extend(other.vertices.iter().map(|v| {
            let p = transform.transform_point3(Vec3::new(v[0], v[1], v[2]));
            let n = (normal_matrix * Vec3::new(v[3], v[4], v[5])).normalize_or_zero();
            [p.x, p.y, p.z, n.x, n.y, n.z]
        }));
        self.indices.extend(other.indices.iter().map(|i| i + base));
    }
}

/// A [`Mesh`]'s positions, normals and indices, held for an impostor bake
/// ([`Mesh::bake_streams`]).
#[derive(Clone, Debug, Default)]
pub struct BakeStreams {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    indices: Vec<u32>,
}

impl BakeStreams {
    /// The part `lodkit::gpu::impostor::ImpostorBaker` bakes: the mesh in a white, opaque,
    /// single-sided material.
    pub fn part(&self) -> lodkit::gpu::impostor::ImpostorPart<'_> {
        lodkit::gpu::impostor::ImpostorPart {
            mesh: lodkit::gpu::impostor::ImpostorMesh {
                positions: &self.positions,
                indices: &self.indices,
                normals: Some(&self.normals),
                uvs: None,
            },
            material: Default::default(),
        }
    }
}

/// A mesh on the GPU.
#[derive(Debug)]
pub struct GpuMesh {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    count: u32,
}

impl GpuMesh {
    /// Uploads `mesh` (an empty mesh is allowed and draws nothing).
    pub fn new(gpu: &GpuContext, mesh: &Mesh) -> Result<Self, GpuError> {
        gpu.guarded("GpuMesh::new", || Self::upload(gpu, mesh))
    }

    fn upload(gpu: &GpuContext, mesh: &Mesh) -> Result<Self, GpuError> {
        let count = u32::try_from(mesh.indices.len()).map_err(|_| GpuError::TooLarge {
            call: "GpuMesh::new",
            parameter: "mesh.indices.len()",
            value: mesh.indices.len() as u64,
            limit: "u32 index count",
            max: u32::MAX.into(),
        })?;
        let vertices = bytemuck::cast_slice(&mesh.vertices);
        let indices = bytemuck::cast_slice(&mesh.indices);
        Ok(GpuMesh {
            vertices: buffer_with_data(gpu, vertices, wgpu::BufferUsages::VERTEX, "mesh vertices")?,
            indices: buffer_with_data(gpu, indices, wgpu::BufferUsages::INDEX, "mesh indices")?,
            count,
        })
    }

    /// Triangles drawn per draw call.
    pub fn triangles(&self) -> u32 {
        self.count / 3
    }

    /// Binds the buffers and draws one instance (vertex layout: position, normal).
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        if self.count == 0 {
            return;
        }
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..self.count, 0, 0..1);
    }
}

/// Vertex buffer layout and attributes of [`Mesh`] (position at location 0, normal at 1): the
/// layout [`mesh_pipeline`] builds pipelines with.
pub use lodkit::gpu::resources::{MESH_VERTEX_ATTRIBUTES, MESH_VERTEX_LAYOUT};

/// Rust mirror of `Camera` in `passes/lod_mesh.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CameraUniform {
    /// Projection x view.
    pub view_proj: [[f32; 4]; 4],
    /// World-space direction toward the light.
    pub light_dir: [f32; 4],
}

/// Rust mirror of `Draw` in `passes/lod_mesh.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct DrawUniform {
    /// Object to world.
    pub model: [[f32; 4]; 4],
    /// Base color (rgb) and output alpha.
    pub color: [f32; 4],
    /// Sway: amplitude (object units at the top of a unit-high mesh, 0 = none) and phase.
    pub sway: [f32; 2],
    /// Screen-door alpha, or [`DITHER_OFF`].
    pub dither_alpha: f32,
    /// Padding to the WGSL struct's size.
    pub pad: f32,
    /// Alpha mask rect (`lodkit::alpha_mask`; x = 0: no alpha test).
    pub alpha_rect: [f32; 4],
}

/// One [`MeshRenderer::render`]: what it draws, from where, and whether its fragments are
/// counted.
#[derive(Clone, Copy, Debug)]
pub struct MeshFrame<'a> {
    /// The target's clear color. Default: black.
    pub clear: wgpu::Color,
    /// Projection x view. Default: identity.
    pub view_proj: Mat4,
    /// Direction towards the light (world space). Default: +z.
    pub light_dir: Vec3,
    /// The draws, in order. Default: none.
    pub items: &'a [DrawItem<'a>],
    /// Counts the pass's fragment-shader invocations. Default: none.
    pub counter: Option<&'a FragmentCounter>,
    /// The caller's own draws in the same pass, between the items. Default: none.
    pub foreign: &'a [PassDraw<'a>],
}

impl Default for MeshFrame<'_> {
    fn default() -> Self {
        Self {
            clear: wgpu::Color::BLACK,
            view_proj: Mat4::IDENTITY,
            light_dir: Vec3::Z,
            items: &[],
            counter: None,
            foreign: &[],
        }
    }
}

/// A draw of the caller's own (an impostor, say) inside a renderer's pass, between its items:
/// it sets its own pipeline, bind groups and blend constant; the renderer sets its own again
/// after it. Counted by the frame's counter with the rest of the pass.
#[derive(Clone, Copy)]
pub struct PassDraw<'a> {
    /// Drawn before item `before` (`items.len()` or more: after the last).
    pub before: usize,
    /// Records the draw into the pass.
    pub draw: &'a dyn Fn(&mut wgpu::RenderPass<'_>),
}

impl std::fmt::Debug for PassDraw<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PassDraw")
            .field("before", &self.before)
            .finish_non_exhaustive()
    }
}

/// Records the draws of `foreign` that go before item `i` of `n` (all that are left at `n`);
/// whether there were any.
pub(crate) fn draw_foreign(
    pass: &mut wgpu::RenderPass<'_>,
    foreign: &[PassDraw<'_>],
    i: usize,
    n: usize,
) -> bool {
    let mut drew = false;
    for f in foreign
        .iter()
        .filter(|f| f.before == i || (i == n && f.before > n))
    {
        (f.draw)(pass);
        drew = true;
    }
    drew
}

/// One draw: a mesh, where, its color, and how it takes part in a transition.
#[derive(Clone, Copy, Debug)]
pub struct DrawItem<'a> {
    /// The mesh.
    pub mesh: &'a GpuMesh,
    /// Object to world.
    pub model: Mat4,
    /// Base color.
    pub color: Vec4,
    /// Opaque, or blended with depth test and no writes (unpopping, cross-fade).
    pub state: LodRenderState,
    /// Screen-door alpha (negative = inverted pattern), if dithered.
    pub dither_alpha: Option<f32>,
    /// Wind sway of the vertex stage: amplitude (object units at the top of a unit-high mesh,
    /// 0 = none) and phase (advance it over time).
    pub sway: [f32; 2],
    /// Where the renderer's alpha mask lies in object space
    /// ([`alpha_mask_rect`](lodkit::alpha_mask::alpha_mask_rect)); `Vec4::ZERO`: no alpha test.
    pub alpha_rect: Vec4,
}

/// A color and depth target of one size.
#[derive(Debug)]
pub struct RenderTarget {
    /// RGBA8 color, copyable.
    pub color: wgpu::Texture,
    /// Depth32Float.
    pub depth: wgpu::Texture,
}

impl RenderTarget {
    /// Allocates both textures at `width` x `height` (a zero side is taken as 1).
    pub fn new(gpu: &GpuContext, width: u32, height: u32) -> Result<Self, GpuError> {
        gpu.guarded("RenderTarget::new", || Self::allocate(gpu, width, height))
    }

    fn allocate(gpu: &GpuContext, width: u32, height: u32) -> Result<Self, GpuError> {
        let size = texture_extent(gpu, "RenderTarget::new", width, height)?;
        let color_usage = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::TEXTURE_BINDING;
        let depth_usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        Ok(Self {
            color: texture_2d(gpu, size, COLOR_FORMAT, color_usage, "scene color")?,
            depth: texture_2d(gpu, size, DEPTH_FORMAT, depth_usage, "scene depth")?,
        })
    }

    /// Width and height.
    pub fn size(&self) -> (u32, u32) {
        (self.color.width(), self.color.height())
    }
}

/// Draws [`DrawItem`]s with `passes/lod_mesh.wgsl`.
#[derive(Debug)]
pub struct MeshRenderer {
    opaque: wgpu::RenderPipeline,
    blended: wgpu::RenderPipeline,
    camera: wgpu::Buffer,
    camera_layout: wgpu::BindGroupLayout,
    camera_group: wgpu::BindGroup,
    draws: DrawUniforms,
    draw_group: wgpu::BindGroup,
}

impl MeshRenderer {
    /// Most draws one [`render`](Self::render) call takes.
    pub const MAX_DRAWS: usize = 256;

    /// Builds the pipelines (`blue_noise` selects the screen-door pattern).
    pub fn new(gpu: &GpuContext, blue_noise: bool) -> Result<Self, GpuError> {
        gpu.guarded("MeshRenderer::new", || Self::build(gpu, blue_noise))
    }

    fn build(gpu: &GpuContext, blue_noise: bool) -> Result<Self, GpuError> {
        let defs: &[&str] = if blue_noise {
            &["LODKIT_SCREEN_DOOR_BLUE_NOISE"]
        } else {
            &[]
        };
        let module = gpu.pass_module("lod_mesh", defs)?;
        let (camera_layout, draw_layout, layout) =
            camera_draw_layouts(gpu, "lod_mesh", &[texture_entry(1, UNFILTERABLE)])?;
        let pipeline = |state: LodRenderState| {
            let target = wgpu::ColorTargetState {
                format: COLOR_FORMAT,
                blend: lod_blend(&state),
                write_mask: wgpu::ColorWrites::ALL,
            };
            let depth = lod_depth_stencil(&state, DEPTH_FORMAT, wgpu::CompareFunction::Less);
            mesh_pipeline(gpu, &module, &layout, &[Some(target)], depth, "lod_mesh")
        };
        let opaque_state = LodRenderState::OPAQUE;
        let blended_state = LodRenderState {
            alpha: 0.5,
            depth_test: true,
            depth_write: false,
            blend: true,
        };
        let camera = uniform_buffer(gpu, std::mem::size_of::<CameraUniform>(), "camera")?;
        let camera_group =
            masked_view_group(gpu, &camera_layout, &camera, &[], &AlphaMask::opaque())?;
        let draws = DrawUniforms::new(
            gpu,
            std::mem::size_of::<DrawUniform>(),
            Self::MAX_DRAWS,
            "draws",
        )?;
        Ok(Self {
            opaque: pipeline(opaque_state)?,
            blended: pipeline(blended_state)?,
            camera_group,
            camera_layout,
            draw_group: draws.bind_group(gpu, &draw_layout)?,
            camera,
            draws,
        })
    }

    /// Binds `mask` as the alpha mask of every draw whose `alpha_rect` is set (one mask, or an
    /// atlas, per renderer; a 1x1 opaque one until then). [`GpuError::Mismatch`] when its texels
    /// do not fill `size` x `size` or `size` is 0.
    pub fn set_alpha_mask(&mut self, gpu: &GpuContext, mask: &AlphaMask) -> Result<(), GpuError> {
        self.camera_group = masked_view_group(gpu, &self.camera_layout, &self.camera, &[], mask)?;
        Ok(())
    }

    /// Clears `target` to `frame.clear` and draws `frame.items` in order (at most
    /// [`Self::MAX_DRAWS`]: more is [`GpuError::TooManyDraws`] and draws nothing), counting the
    /// pass's fragments with `frame.counter` if given. Returns the count (0 without a counter).
    ///
    /// The meshes and the counter must come from `gpu`'s device.
    pub fn render(
        &self,
        gpu: &GpuContext,
        target: &RenderTarget,
        frame: &MeshFrame,
    ) -> Result<u64, GpuError> {
        let MeshFrame {
            clear,
            view_proj,
            light_dir,
            items,
            counter,
            foreign,
        } = *frame;
        const CALL: &str = "MeshRenderer::render";
        self.draws.check_count(CALL, items.len())?;
        gpu.recording(CALL, || {
            let camera = CameraUniform {
                view_proj: view_proj.to_cols_array_2d(),
                light_dir: light_dir.extend(0.0).to_array(),
            };
            gpu.queue
                .write_buffer(&self.camera, 0, bytemuck::bytes_of(&camera));
            let uniforms: Vec<DrawUniform> = items
                .iter()
                .map(|item| DrawUniform {
                    model: item.model.to_cols_array_2d(),
                    color: item.color.to_array(),
                    sway: item.sway,
                    dither_alpha: item.dither_alpha.unwrap_or(DITHER_OFF),
                    pad: 0.0,
                    alpha_rect: item.alpha_rect.to_array(),
                })
                .collect();
            self.draws.write(gpu, &uniforms)?;
            let color_view = target.color.create_view(&Default::default());
            let depth_view = target.depth.create_view(&Default::default());
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            {
                let mut pass = begin_targets_pass(
                    &mut encoder,
                    &[(&color_view, clear)],
                    &depth_view,
                    1.0,
                    counter.and_then(FragmentCounter::occlusion_query_set),
                    "lod_mesh",
                );
                if let Some(c) = counter {
                    c.begin(&mut pass);
                }
                for (i, item) in items.iter().enumerate() {
                    draw_foreign(&mut pass, foreign, i, items.len());
                    pass.set_bind_group(0, &self.camera_group, &[]);
                    pass.set_pipeline(if item.state.blend {
                        &self.blended
                    } else {
                        &self.opaque
                    });
                    pass.set_blend_constant(lod_blend_constant(&item.state));
                    pass.set_bind_group(1, &self.draw_group, &[self.draws.offset(i)]);
                    item.mesh.draw(&mut pass);
                }
                draw_foreign(&mut pass, foreign, items.len(), items.len());
                if let Some(c) = counter {
                    c.end(&mut pass);
                }
            }
            match counter {
                Some(c) => c.read(gpu, encoder),
                None => {
                    gpu.queue.submit([encoder.finish()]);
                    Ok(0)
                }
            }
        })
    }
}

/// Texture binding type of the masks and patterns the mesh passes read with `textureLoad`.
pub(crate) const UNFILTERABLE: wgpu::TextureSampleType =
    wgpu::TextureSampleType::Float { filterable: false };

/// The per-view bind group of a mesh pass whose last texture is the alpha mask: `camera` at
/// binding 0, `views` from binding 1, then `mask` uploaded as an `R32Float` texture
/// ([`GpuError::Mismatch`] when its texels do not fill it).
pub(crate) fn masked_view_group(
    gpu: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    camera: &wgpu::Buffer,
    views: &[&wgpu::TextureView],
    mask: &AlphaMask,
) -> Result<wgpu::BindGroup, GpuError> {
    let texture = r32float_texture(gpu, mask.size, &mask.texels, "alpha mask")?;
    let mask_view = texture.create_view(&Default::default());
    let mut all = views.to_vec();
    all.push(&mask_view);
    gpu.guarded("alpha mask bind group", || {
        Ok(view_group(gpu, layout, camera, &all))
    })
}

/// The per-view bind group of a mesh pass: `camera` at binding 0, then `views` from binding 1.
fn view_group(
    gpu: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    camera: &wgpu::Buffer,
    views: &[&wgpu::TextureView],
) -> wgpu::BindGroup {
    let mut entries = vec![wgpu::BindGroupEntry {
        binding: 0,
        resource: camera.as_entire_binding(),
    }];
    entries.extend(
        views
            .iter()
            .zip(1..)
            .map(|(v, binding)| wgpu::BindGroupEntry {
                binding,
                resource: wgpu::BindingResource::TextureView(v),
            }),
    );
    gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout,
        entries: &entries,
    })
}
