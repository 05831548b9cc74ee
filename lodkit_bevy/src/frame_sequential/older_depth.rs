//! The older-level depth pass (render world): for each group in transition, the level this
//! frame does not draw is drawn again with this frame's camera and transform into a depth
//! texture of its own, with no fragment stage. The combine reads it to know which pixels that
//! level covers now and at what depth; last frame's picture, sampled at last frame's pixel
//! centers, only tells that to within a texel, and a silhouette resampled a texel off shows the
//! other level or the background every other frame.

use bevy::asset::load_embedded_asset;
use bevy::core_pipeline::core_3d::CORE_3D_DEPTH_FORMAT;
use bevy::mesh::{Mesh, MeshVertexBufferLayoutRef};
use bevy::prelude::*;
use bevy::render::mesh::allocator::MeshAllocator;
use bevy::render::mesh::{RenderMesh, RenderMeshBufferInfo};
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_phase::TrackedRenderPass;
use bevy::render::render_resource::binding_types::uniform_buffer;
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderDevice, RenderQueue};
use bevy::render::view::ExtractedView;

use super::view::FrameSequentialView;

/// Name of the pass in Bevy's render diagnostics (`render/<name>/...`).
pub const OLDER_DEPTH_PASS: &str = "lodkit_frame_sequential_older_depth";

/// One draw's uniform.
#[derive(ShaderType, Clone, Copy)]
struct OlderLevelUniform {
    clip_from_world: Mat4,
    world_from_local: Mat4,
}

/// The pass's bind group layout and shader.
#[derive(Resource)]
pub struct OlderDepthPipeline {
    layout: BindGroupLayoutDescriptor,
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
            shader: load_embedded_asset!(world, "older_depth.wesl"),
        }
    }
}

/// Pipelines differ by the mesh's topology and the material's culling.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct OlderDepthKey {
    topology: PrimitiveTopology,
    cull_mode: Option<Face>,
}

impl SpecializedMeshPipeline for OlderDepthPipeline {
    type Key = OlderDepthKey;

    fn specialize(
        &self,
        key: Self::Key,
        layout: &MeshVertexBufferLayoutRef,
    ) -> Result<RenderPipelineDescriptor, SpecializedMeshPipelineError> {
        let buffer = layout
            .0
            .get_layout(&[Mesh::ATTRIBUTE_POSITION.at_shader_location(0)])?;
        Ok(RenderPipelineDescriptor {
            label: Some(OLDER_DEPTH_PASS.into()),
            layout: vec![self.layout.clone()],
            vertex: VertexState {
                shader: self.shader.clone(),
                entry_point: Some("vertex".into()),
                buffers: vec![buffer],
                ..default()
            },
            fragment: None,
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

/// The camera's draws this frame: a pipeline, a mesh and a uniform offset each, and the
/// uniform buffer they read (kept from frame to frame, rewritten in place).
#[derive(Component, Default)]
pub struct OlderDepthDraws {
    uniforms: DynamicUniformBuffer<OlderLevelUniform>,
    bind_group: Option<BindGroup>,
    draws: Vec<(CachedRenderPipelineId, AssetId<Mesh>, u32)>,
    /// Whether every older level is drawn this frame (no pipeline still compiling, no mesh
    /// still uploading): only then does the combine read the pass (else it estimates).
    pub(super) ready: bool,
}

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
    mut views: Query<(
        Entity,
        &ExtractedView,
        &FrameSequentialView,
        Option<&mut OlderDepthDraws>,
    )>,
) {
    for (entity, view, frame, kept) in &mut views {
        if !frame.exact_coverage {
            if kept.is_some() {
                commands.entity(entity).remove::<OlderDepthDraws>();
            }
            continue;
        }
        let clip_from_world = view
            .clip_from_world
            .unwrap_or_else(|| view.clip_from_view * view.world_from_view.to_matrix().inverse());
        let mut fresh = OlderDepthDraws::default();
        let (draws_of_view, is_new) = match kept {
            Some(kept) => (kept.into_inner(), false),
            None => (&mut fresh, true),
        };
        let OlderDepthDraws {
            uniforms,
            bind_group,
            draws,
            ready: ready_of_view,
        } = draws_of_view;
        uniforms.clear();
        draws.clear();
        // Until every level can be drawn (a pipeline still compiling, a mesh not uploaded),
        // the combine places the older levels from last frame's picture instead.
        let mut ready = true;
        for level in &frame.older_levels {
            let Some(mesh) = meshes.get(level.mesh) else {
                ready = false;
                continue;
            };
            let key = OlderDepthKey {
                topology: mesh.primitive_topology(),
                cull_mode: level.cull_mode,
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
            draws.push((id, level.mesh, offset));
        }
        uniforms.write_buffer(&device, &queue);
        *bind_group = uniforms.binding().map(|binding| {
            device.create_bind_group(
                OLDER_DEPTH_PASS,
                &cache.get_bind_group_layout(&pipeline.layout),
                &BindGroupEntries::single(binding),
            )
        });
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
    for &(pipeline, mesh_id, offset) in &draws.draws {
        let (Some(pipeline), Some(mesh), Some(vertices)) = (
            cache.get_render_pipeline(pipeline),
            meshes.get(mesh_id),
            allocator.mesh_vertex_slice(&mesh_id),
        ) else {
            continue;
        };
        pass.set_render_pipeline(pipeline);
        pass.set_bind_group(0, bind_group, &[offset]);
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
