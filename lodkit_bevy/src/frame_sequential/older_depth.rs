//! The older-level depth pass (render world): for each group in transition, the level this
//! frame does not draw is drawn again with this frame's camera and transform into a depth
//! texture of its own, with no fragment stage. The combine reads it to know which pixels that
//! level covers now and at what depth; last frame's picture, sampled at last frame's pixel
//! centers, only tells that to within a texel, and a silhouette resampled a texel off shows the
//! other level or the background every other frame. An alpha-mask level is drawn with its
//! material's alpha test ([`AlphaTest`]): what it covers is its leaves, not its cards.

use bevy::asset::load_embedded_asset;
use bevy::core_pipeline::core_3d::CORE_3D_DEPTH_FORMAT;
use bevy::math::Affine2;
use bevy::mesh::{Mesh, MeshAttributeCompressionFlags, MeshVertexBufferLayoutRef};
use bevy::prelude::*;
use bevy::render::camera::MipBias;
use bevy::render::mesh::allocator::MeshAllocator;
use bevy::render::mesh::{RenderMesh, RenderMeshBufferInfo};
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_phase::TrackedRenderPass;
use bevy::render::render_resource::binding_types::{sampler, texture_2d, uniform_buffer};
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderDevice, RenderQueue};
use bevy::render::texture::GpuImage;
use bevy::render::view::ExtractedView;

use super::view::{AlphaTest, FrameSequentialView};

/// Name of the pass in Bevy's render diagnostics (`render/<name>/...`).
pub const OLDER_DEPTH_PASS: &str = "lodkit_frame_sequential_older_depth";

/// One draw's uniform.
#[derive(ShaderType, Clone, Copy)]
struct OlderLevelUniform {
    clip_from_world: Mat4,
    world_from_local: Mat4,
}

/// A masked draw's uniform: `older_depth.wesl`'s `AlphaTest`.
#[derive(ShaderType, Clone, Copy)]
struct AlphaTestUniform {
    uv_axes: Vec4,
    uv_translation_alpha_cutoff: Vec4,
    mip_bias: Vec4,
}

impl AlphaTestUniform {
    fn new(test: &AlphaTest, mip_bias: f32) -> Self {
        let Affine2 {
            matrix2,
            translation,
        } = test.uv_transform;
        Self {
            uv_axes: matrix2
                .x_axis
                .extend(matrix2.y_axis.x)
                .extend(matrix2.y_axis.y),
            uv_translation_alpha_cutoff: translation.extend(test.base_alpha).extend(test.cutoff),
            mip_bias: Vec4::new(mip_bias, 0.0, 0.0, 0.0),
        }
    }
}

/// The pass's bind group layouts (the level's uniform; a masked level's texture, sampler and
/// alpha test) and shader.
#[derive(Resource)]
pub struct OlderDepthPipeline {
    layout: BindGroupLayoutDescriptor,
    mask_layout: BindGroupLayoutDescriptor,
    shader: Handle<Shader>,
}

impl FromWorld for OlderDepthPipeline {
    fn from_world(world: &mut World) -> Self {
        Self {
            layout: BindGroupLayoutDescriptor::new(
                OLDER_DEPTH_PASS,
                &BindGroupLayoutEntries::single(
                    ShaderStages::VERTEX,
                    uniform_buffer::<OlderLevelUniform>(true),
                ),
            ),
            mask_layout: BindGroupLayoutDescriptor::new(
                OLDER_DEPTH_PASS,
                &BindGroupLayoutEntries::sequential(
                    ShaderStages::FRAGMENT,
                    (
                        texture_2d(TextureSampleType::Float { filterable: true }),
                        sampler(SamplerBindingType::Filtering),
                        uniform_buffer::<AlphaTestUniform>(true),
                    ),
                ),
            ),
            shader: load_embedded_asset!(world, "older_depth.wesl"),
        }
    }
}

/// Pipelines differ by the mesh's topology, the material's culling and its alpha test.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct OlderDepthKey {
    topology: PrimitiveTopology,
    cull_mode: Option<Face>,
    /// The UV set a masked level's texture reads (None: not masked by a texture).
    masked: Option<UvSet>,
}

/// The UV set of a masked level.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum UvSet {
    Uv0,
    Uv1,
}

impl SpecializedMeshPipeline for OlderDepthPipeline {
    type Key = OlderDepthKey;

    fn specialize(
        &self,
        key: Self::Key,
        layout: &MeshVertexBufferLayoutRef,
    ) -> Result<RenderPipelineDescriptor, SpecializedMeshPipelineError> {
        let position = Mesh::ATTRIBUTE_POSITION.at_shader_location(0);
        let (buffer, layouts, vertex, fragment) = match key.masked {
            None => (
                layout.0.get_layout(&[position])?,
                vec![self.layout.clone()],
                "vertex",
                None,
            ),
            Some(uv) => {
                let uv = match uv {
                    UvSet::Uv0 => Mesh::ATTRIBUTE_UV_0,
                    UvSet::Uv1 => Mesh::ATTRIBUTE_UV_1,
                };
                let fragment = FragmentState {
                    shader: self.shader.clone(),
                    entry_point: Some("fragment_masked".into()),
                    targets: Vec::new(),
                    ..default()
                };
                (
                    layout.0.get_layout(&[position, uv.at_shader_location(1)])?,
                    vec![self.layout.clone(), self.mask_layout.clone()],
                    "vertex_masked",
                    Some(fragment),
                )
            }
        };
        Ok(RenderPipelineDescriptor {
            label: Some(OLDER_DEPTH_PASS.into()),
            layout: layouts,
            vertex: VertexState {
                shader: self.shader.clone(),
                entry_point: Some(vertex.into()),
                buffers: vec![buffer],
                ..default()
            },
            fragment,
            primitive: PrimitiveState {
                topology: key.topology,
                cull_mode: key.cull_mode,
                ..default()
            },
            // Bevy's reversed Z: cleared to 0 (far), nearer is greater.
            depth_stencil: Some(DepthStencilState {
                format: CORE_3D_DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(CompareFunction::GreaterEqual),
                stencil: StencilState::default(),
                bias: DepthBiasState::default(),
            }),
            ..default()
        })
    }
}

/// One draw: its pipeline, mesh and uniform offset, and a masked level's bind group (an index
/// into [`OlderDepthDraws::mask_groups`]) and alpha-test offset.
type Draw = (
    CachedRenderPipelineId,
    AssetId<Mesh>,
    u32,
    Option<(usize, u32)>,
);

/// The camera's draws this frame and the uniform buffers they read (kept from frame to frame,
/// rewritten in place).
#[derive(Component, Default)]
pub struct OlderDepthDraws {
    uniforms: DynamicUniformBuffer<OlderLevelUniform>,
    alpha_tests: DynamicUniformBuffer<AlphaTestUniform>,
    bind_group: Option<BindGroup>,
    /// Per masked draw, its texture's bind group.
    mask_groups: Vec<BindGroup>,
    draws: Vec<Draw>,
    /// Whether every older level is drawn this frame (no pipeline still compiling, no mesh or
    /// texture still uploading): only then does the combine read the pass (else it estimates).
    pub(super) ready: bool,
}

/// How a level's alpha test is drawn, given its mesh's vertex layout.
enum Masking<'a> {
    /// Not masked, or masked by a constant alpha at or over the cutoff: depth only.
    None,
    /// Masked by a constant alpha under the cutoff: the level is not drawn at all (Bevy's main
    /// pass discards every fragment of it).
    Hidden,
    /// Masked by its texture, read at this UV set.
    Texture(&'a AlphaTest, UvSet),
}

impl<'a> Masking<'a> {
    fn of(test: Option<&'a AlphaTest>, layout: &MeshVertexBufferLayoutRef) -> Self {
        let Some(test) = test else {
            return Self::None;
        };
        let (uv, attribute) = if test.uv_b {
            (UvSet::Uv1, Mesh::ATTRIBUTE_UV_1)
        } else {
            (UvSet::Uv0, Mesh::ATTRIBUTE_UV_0)
        };
        // Bevy's main pass samples the texture only where the mesh has UVs.
        if test.texture.is_some() && layout.0.contains(attribute.id) {
            Self::Texture(test, uv)
        } else if test.base_alpha >= test.cutoff {
            Self::None
        } else {
            Self::Hidden
        }
    }
}

/// A camera's inputs to [`prepare_draws`].
type ViewDraws = (
    Entity,
    &'static ExtractedView,
    &'static FrameSequentialView,
    Option<&'static MipBias>,
    Option<&'static mut OlderDepthDraws>,
);

#[allow(
    clippy::too_many_arguments,
    reason = "one system's render-world inputs"
)]
pub(super) fn prepare_draws(
    mut commands: Commands,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    cache: Res<PipelineCache>,
    pipeline: Res<OlderDepthPipeline>,
    mut specialized: ResMut<SpecializedMeshPipelines<OlderDepthPipeline>>,
    meshes: Res<RenderAssets<RenderMesh>>,
    images: Res<RenderAssets<GpuImage>>,
    mut views: Query<ViewDraws>,
) {
    for (entity, view, frame, mip_bias, kept) in &mut views {
        if !frame.exact_coverage {
            if kept.is_some() {
                commands.entity(entity).remove::<OlderDepthDraws>();
            }
            continue;
        }
        let clip_from_world = view
            .clip_from_world
            .unwrap_or_else(|| view.clip_from_view * view.world_from_view.to_matrix().inverse());
        let mip_bias = mip_bias.map_or(0.0, |b| b.0);
        let mut fresh = OlderDepthDraws::default();
        let (draws_of_view, is_new) = match kept {
            Some(kept) => (kept.into_inner(), false),
            None => (&mut fresh, true),
        };
        let OlderDepthDraws {
            uniforms,
            alpha_tests,
            bind_group,
            mask_groups,
            draws,
            ready: ready_of_view,
        } = draws_of_view;
        uniforms.clear();
        alpha_tests.clear();
        draws.clear();
        // The textures of the masked draws, in the order of their alpha tests.
        let mut textures = Vec::new();
        // Until every level can be drawn (a pipeline still compiling, a mesh or texture not
        // uploaded), the combine places the older levels from last frame's picture instead.
        let mut ready = true;
        for level in &frame.older_levels {
            let Some(mesh) = meshes.get(level.mesh) else {
                ready = false;
                continue;
            };
            let compressed = mesh.layout.0.get_attribute_compression();
            if compressed.intersects(
                MeshAttributeCompressionFlags::COMPRESS_POSITION
                    | MeshAttributeCompressionFlags::COMPRESS_UV0
                    | MeshAttributeCompressionFlags::COMPRESS_UV1,
            ) {
                warn_once!(
                    "lodkit frame-sequential: a level's mesh has compressed positions or UVs, \
                     which the older-level depth pass does not read: its coverage is estimated"
                );
                ready = false;
                continue;
            }
            let masking = Masking::of(level.alpha_test.as_ref(), &mesh.layout);
            let masked = match &masking {
                Masking::Hidden => continue,
                Masking::None => None,
                Masking::Texture(test, uv) => {
                    let image = test.texture.as_ref().and_then(|t| images.get(t));
                    let Some(image) = image else {
                        ready = false;
                        continue;
                    };
                    textures.push(image);
                    let offset = alpha_tests.push(&AlphaTestUniform::new(test, mip_bias));
                    Some((*uv, textures.len() - 1, offset))
                }
            };
            let key = OlderDepthKey {
                topology: mesh.primitive_topology(),
                cull_mode: level.cull_mode,
                masked: masked.map(|(uv, ..)| uv),
            };
            let id = match specialized.specialize(&cache, &pipeline, key, &mesh.layout) {
                Ok(id) => id,
                Err(error) => {
                    warn_once!("lodkit frame-sequential: a level's mesh has no positions: {error}");
                    ready = false;
                    continue;
                }
            };
            ready &= cache.get_render_pipeline(id).is_some();
            let offset = uniforms.push(&OlderLevelUniform {
                clip_from_world,
                world_from_local: level.world_from_local,
            });
            draws.push((id, level.mesh, offset, masked.map(|(_, g, o)| (g, o))));
        }
        uniforms.write_buffer(&device, &queue);
        alpha_tests.write_buffer(&device, &queue);
        *bind_group = uniforms.binding().map(|binding| {
            device.create_bind_group(
                OLDER_DEPTH_PASS,
                &cache.get_bind_group_layout(&pipeline.layout),
                &BindGroupEntries::single(binding),
            )
        });
        mask_groups.clear();
        if let Some(binding) = alpha_tests.binding() {
            let layout = cache.get_bind_group_layout(&pipeline.mask_layout);
            mask_groups.extend(textures.iter().map(|image| {
                device.create_bind_group(
                    OLDER_DEPTH_PASS,
                    &layout,
                    &BindGroupEntries::sequential((
                        &image.texture_view,
                        &image.sampler,
                        binding.clone(),
                    )),
                )
            }));
        }
        *ready_of_view = ready;
        if is_new {
            commands.entity(entity).insert(fresh);
        }
    }
}

/// Draws the camera's older levels into `pass` (a depth-only pass).
pub(super) fn draw<'a>(
    pass: &mut TrackedRenderPass<'a>,
    draws: &'a OlderDepthDraws,
    cache: &'a PipelineCache,
    meshes: &'a RenderAssets<RenderMesh>,
    allocator: &'a MeshAllocator,
) {
    let Some(bind_group) = &draws.bind_group else {
        return;
    };
    for &(pipeline, mesh_id, offset, masked) in &draws.draws {
        let (Some(pipeline), Some(mesh), Some(vertices)) = (
            cache.get_render_pipeline(pipeline),
            meshes.get(mesh_id),
            allocator.mesh_vertex_slice(&mesh_id),
        ) else {
            continue;
        };
        pass.set_render_pipeline(pipeline);
        pass.set_bind_group(0, bind_group, &[offset]);
        if let Some((group, test)) = masked {
            let Some(group) = draws.mask_groups.get(group) else {
                continue;
            };
            pass.set_bind_group(1, group, &[test]);
        }
        pass.set_vertex_buffer(0, vertices.buffer.slice(..));
        match &mesh.buffer_info {
            RenderMeshBufferInfo::Indexed {
                index_format,
                count,
            } => {
                let Some(indices) = allocator.mesh_index_slice(&mesh_id) else {
                    continue;
                };
                pass.set_index_buffer(indices.buffer.slice(..), *index_format);
                pass.draw_indexed(
                    indices.range.start..indices.range.start + count,
                    vertices.range.start as i32,
                    0..1,
                );
            }
            RenderMeshBufferInfo::NonIndexed => pass.draw(vertices.range.clone(), 0..1),
        }
    }
}
