//! The render-world side: the older frame's copies (color with id words, depth; ping-pong per
//! view), the combine pipeline and its pass after Bevy's opaque pass.

use bevy::asset::load_embedded_asset;
use bevy::core_pipeline::core_3d::{
    CORE_3D_DEPTH_FORMAT, main_opaque_pass_3d, main_transparent_pass_3d,
};
use bevy::core_pipeline::prepass::ViewPrepassTextures;
use bevy::core_pipeline::{Core3d, FullscreenShader};
use bevy::ecs::query::QueryItem;
use bevy::log::warn_once;
use bevy::prelude::*;
use bevy::render::diagnostic::RecordDiagnostics;
use bevy::render::extract_component::ExtractComponent;
use bevy::render::mesh::RenderMesh;
use bevy::render::mesh::allocator::MeshAllocator;
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_resource::binding_types::{texture_2d, texture_depth_2d};
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderContext, RenderDevice, RenderQueue, ViewQuery};
use bevy::render::sync_component::SyncComponent;
use bevy::render::texture::{FallbackImage, GpuImage};
use bevy::render::view::{ExtractedView, ViewDepthStencilTexture, ViewTarget};
use bevy::render::{GpuResourceAppExt, Render, RenderApp, RenderSystems};

use super::data::combine_data;
use super::older_depth::{self, OLDER_DEPTH_PASS, OlderDepthDraws, OlderDepthPipeline};
use super::view::FrameSequentialView;

/// Name of the combine pass in Bevy's render diagnostics: with `RenderDiagnosticsPlugin`,
/// `render/<name>/elapsed_gpu` and `render/<name>/fragment_shader_invocations`.
pub const COMBINE_PASS: &str = "lodkit_frame_sequential_combine";

impl SyncComponent<RenderApp> for FrameSequentialView {
    type Target = (
        FrameSequentialView,
        FrameSequentialTextures,
        CombineBindGroup,
        CombinePipelineId,
        OlderDepthDraws,
    );
}

impl ExtractComponent<RenderApp> for FrameSequentialView {
    type QueryData = &'static FrameSequentialView;
    type QueryFilter = ();
    type Out = FrameSequentialView;

    fn extract_component(view: QueryItem<'_, '_, Self::QueryData>) -> Option<Self::Out> {
        Some(view.clone())
    }
}

pub(super) fn build(render_app: &mut SubApp) {
    render_app.add_systems(
        Render,
        (
            prepare_pipelines.in_set(RenderSystems::Prepare),
            prepare_textures.in_set(RenderSystems::PrepareResources),
            prepare_bind_groups.in_set(RenderSystems::PrepareBindGroups),
            older_depth::prepare_draws.in_set(RenderSystems::QueueMeshes),
        ),
    );
    render_app.add_systems(
        Core3d,
        combine_pass
            .after(main_opaque_pass_3d)
            .before(main_transparent_pass_3d),
    );
}

pub(super) fn finish(render_app: &mut SubApp) {
    render_app
        .init_gpu_resource::<CombinePipeline>()
        .init_gpu_resource::<SpecializedRenderPipelines<CombinePipeline>>()
        .init_gpu_resource::<OlderDepthPipeline>()
        .init_gpu_resource::<SpecializedMeshPipelines<OlderDepthPipeline>>();
}

/// The combine's bind group layout and shaders.
#[derive(Resource)]
pub struct CombinePipeline {
    layout: BindGroupLayoutDescriptor,
    shader: Handle<Shader>,
    fullscreen: FullscreenShader,
}

impl FromWorld for CombinePipeline {
    fn from_world(world: &mut World) -> Self {
        let color = texture_2d(TextureSampleType::Float { filterable: false });
        let words = texture_2d(TextureSampleType::Uint);
        let layout = BindGroupLayoutDescriptor::new(
            "lodkit_frame_sequential_combine",
            &BindGroupLayoutEntries::sequential(
                ShaderStages::FRAGMENT,
                (
                    // newer color and depth
                    color,
                    texture_depth_2d(),
                    // older color, id words and depth (Depth32Float read as unfilterable float)
                    color,
                    words,
                    color,
                    // motion vectors, the visibility pattern, the older-level depth pass
                    color,
                    color,
                    texture_depth_2d(),
                    // lodkit::combine_coverage::CombineData
                    words,
                ),
            ),
        );
        Self {
            layout,
            shader: load_embedded_asset!(world, "combine.wesl"),
            fullscreen: world.resource::<FullscreenShader>().clone(),
        }
    }
}

impl SpecializedRenderPipeline for CombinePipeline {
    type Key = TextureFormat;

    fn specialize(&self, format: Self::Key) -> RenderPipelineDescriptor {
        RenderPipelineDescriptor {
            label: Some(COMBINE_PASS.into()),
            layout: vec![self.layout.clone()],
            vertex: self.fullscreen.to_vertex_state(),
            fragment: Some(FragmentState {
                shader: self.shader.clone(),
                // Bevy's depth is reversed: 1 near, 0 far.
                shader_defs: vec!["LODKIT_REVERSE_Z".into()],
                entry_point: Some("fragment".into()),
                targets: vec![
                    Some(ColorTargetState {
                        format,
                        blend: None,
                        write_mask: ColorWrites::ALL,
                    }),
                    Some(ColorTargetState {
                        format: ID_FORMAT,
                        blend: None,
                        write_mask: ColorWrites::ALL,
                    }),
                ],
                ..default()
            }),
            ..default()
        }
    }
}

/// The camera's combine pipeline.
#[derive(Component)]
pub struct CombinePipelineId(CachedRenderPipelineId);

fn prepare_pipelines(
    mut commands: Commands,
    cache: Res<PipelineCache>,
    mut specialized: ResMut<SpecializedRenderPipelines<CombinePipeline>>,
    pipeline: Res<CombinePipeline>,
    views: Query<(Entity, &ViewTarget), With<FrameSequentialView>>,
) {
    for (entity, target) in &views {
        let id = specialized.specialize(&cache, &pipeline, target.main_texture_format());
        commands.entity(entity).insert(CombinePipelineId(id));
    }
}

/// The format of the id-word target the combine writes (the next frame's older ids).
const ID_FORMAT: TextureFormat = TextureFormat::R32Uint;

/// The two frames' copies (color with id words, depth) and id words, used in turn as newer and
/// older.
#[derive(Component)]
pub struct FrameSequentialTextures {
    size: UVec2,
    format: TextureFormat,
    color: [(Texture, TextureView); 2],
    depth: [(Texture, TextureView); 2],
    /// The id words the combine writes over its region (0 elsewhere).
    ids: [(Texture, TextureView); 2],
    /// The older-level depth pass's target: the camera's size with exact coverage, else one
    /// texel (bound, and read at every pixel, but ignored: the data says it is not read).
    older_level_depth: (Texture, TextureView),
    /// Whether the textures were made for exact coverage.
    exact_coverage: bool,
}

fn prepare_textures(
    mut commands: Commands,
    device: Res<RenderDevice>,
    views: Query<(
        Entity,
        &ViewTarget,
        &FrameSequentialView,
        Option<&FrameSequentialTextures>,
    )>,
) {
    for (entity, target, view, textures) in &views {
        let size = target.main_texture().size();
        let size = UVec2::new(size.width, size.height);
        let format = target.main_texture_format();
        let exact_coverage = view.exact_coverage;
        if textures.is_some_and(|t| {
            t.size == size && t.format == format && t.exact_coverage == exact_coverage
        }) {
            continue;
        }
        let make = |label, format, usage, size: UVec2| {
            let texture = device.create_texture(&TextureDescriptor {
                label: Some(label),
                size: Extent3d {
                    width: size.x,
                    height: size.y,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: TextureDimension::D2,
                format,
                usage: usage | TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            });
            let view = texture.create_view(&TextureViewDescriptor::default());
            (texture, view)
        };
        let color = || {
            make(
                "lodkit_frame_sequential_color",
                format,
                TextureUsages::COPY_DST,
                size,
            )
        };
        let depth = || {
            make(
                "lodkit_frame_sequential_depth",
                CORE_3D_DEPTH_FORMAT,
                TextureUsages::COPY_DST,
                size,
            )
        };
        let ids = || {
            make(
                "lodkit_frame_sequential_ids",
                ID_FORMAT,
                TextureUsages::RENDER_ATTACHMENT,
                size,
            )
        };
        commands.entity(entity).insert(FrameSequentialTextures {
            size,
            format,
            color: [color(), color()],
            depth: [depth(), depth()],
            ids: [ids(), ids()],
            older_level_depth: make(
                OLDER_DEPTH_PASS,
                CORE_3D_DEPTH_FORMAT,
                TextureUsages::RENDER_ATTACHMENT,
                if exact_coverage { size } else { UVec2::ONE },
            ),
            exact_coverage,
        });
    }
}

/// The combine's bind group this frame (newer: this frame's copies, older: last frame's).
#[derive(Component)]
pub struct CombineBindGroup(BindGroup);

/// What `prepare_bind_groups` reads of a camera.
type BindGroupView = (
    Entity,
    &'static FrameSequentialView,
    &'static FrameSequentialTextures,
    Option<&'static ViewPrepassTextures>,
    Option<&'static OlderDepthDraws>,
);

#[allow(
    clippy::too_many_arguments,
    reason = "one system's render-world inputs"
)]
fn prepare_bind_groups(
    mut commands: Commands,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    cache: Res<PipelineCache>,
    pipeline: Res<CombinePipeline>,
    fallback: Res<FallbackImage>,
    images: Res<RenderAssets<GpuImage>>,
    views: Query<BindGroupView>,
) {
    // A camera with no bind group this frame runs no combine: last frame's group would bind
    // the id target this frame writes.
    let Some(visibility) = images.get(&super::VISIBILITY_TEXTURE) else {
        for (entity, ..) in &views {
            commands.entity(entity).remove::<CombineBindGroup>();
        }
        return;
    };
    for (entity, view, textures, prepass, older) in &views {
        let motion = match prepass.and_then(ViewPrepassTextures::motion_vectors_view) {
            Some(motion) => motion,
            None if view.motion_vectors => {
                warn_once!("FrameSequentialLod: the motion-vector prepass has no texture yet");
                commands.entity(entity).remove::<CombineBindGroup>();
                continue;
            }
            // Not read (no COMBINE_OBJECT_MOTION): any texture of the layout's type.
            None => &fallback.d2.texture_view,
        };
        // The depth pass is read once every older level is drawn; until then the combine
        // estimates every level's coverage.
        let exact = view.exact_coverage && older.is_some_and(|o| o.ready);
        let data = match combine_data(view, exact, textures.size.y) {
            Ok(data) => data,
            Err(error) => {
                warn_once!("FrameSequentialLod: no combine this frame: {error}");
                commands.entity(entity).remove::<CombineBindGroup>();
                continue;
            }
        };
        let data_texture = device.create_texture_with_data(
            &queue,
            &TextureDescriptor {
                label: Some("lodkit_frame_sequential_combine_data"),
                size: Extent3d {
                    width: data.width,
                    height: data.height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: TextureDimension::D2,
                format: TextureFormat::Rgba32Uint,
                usage: TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            TextureDataOrder::LayerMajor,
            &data.bytes(),
        );
        let data_view = data_texture.create_view(&TextureViewDescriptor::default());
        let (newer, older) = (view.buffer, 1 - view.buffer);
        let bind_group = device.create_bind_group(
            "lodkit_frame_sequential_combine",
            &cache.get_bind_group_layout(&pipeline.layout),
            &BindGroupEntries::sequential((
                &textures.color[newer].1,
                &textures.depth[newer].1,
                &textures.color[older].1,
                &textures.ids[older].1,
                &textures.depth[older].1,
                motion,
                &visibility.texture_view,
                &textures.older_level_depth.1,
                &data_view,
            )),
        );
        commands.entity(entity).insert(CombineBindGroup(bind_group));
    }
}

type PassView = (
    &'static ExtractedView,
    &'static ViewTarget,
    &'static ViewDepthStencilTexture,
    &'static FrameSequentialView,
    &'static FrameSequentialTextures,
    Option<&'static CombineBindGroup>,
    Option<&'static CombinePipelineId>,
    Option<&'static OlderDepthDraws>,
);

/// Copies this frame's main color and depth where the frame is kept (the combine's newer input
/// and the next frame's older buffer), then combines within the rectangles. A frame not kept
/// has no rectangles: nothing is in transition, and nothing is copied.
fn combine_pass(
    view: ViewQuery<PassView>,
    cache: Res<PipelineCache>,
    meshes: Res<RenderAssets<RenderMesh>>,
    allocator: Res<MeshAllocator>,
    mut ctx: RenderContext,
) {
    let (_, target, depth, frame, textures, bind_group, pipeline_id, older) = view.into_inner();
    let newer = frame.buffer;
    let main = target.main_texture();
    let extent = main.size();
    if extent.width != textures.size.x || extent.height != textures.size.y {
        return;
    }
    if frame.keep {
        let encoder = ctx.command_encoder();
        encoder.copy_texture_to_texture(
            main.as_image_copy(),
            textures.color[newer].0.as_image_copy(),
            extent,
        );
        encoder.copy_texture_to_texture(
            depth.texture().as_image_copy(),
            textures.depth[newer].0.as_image_copy(),
            extent,
        );
    }
    let (Some(bind_group), Some(pipeline)) = (
        bind_group,
        pipeline_id.and_then(|id| cache.get_render_pipeline(id.0)),
    ) else {
        if frame.keep {
            // No combine yet (its pipeline still compiling): the next frame reads no id words
            // of an older frame than its colors.
            ctx.begin_tracked_render_pass(RenderPassDescriptor {
                label: Some(COMBINE_PASS),
                color_attachments: &[Some(id_attachment(textures, frame))],
                ..default()
            });
        }
        return;
    };
    let diagnostics = ctx.diagnostic_recorder();
    let diagnostics = diagnostics.as_deref();
    if let Some(older) = older {
        // Runs every frame, cleared to far when no group is in transition, so its diagnostics
        // count every frame and the combine never reads a stale frame's levels.
        let mut pass = ctx.begin_tracked_render_pass(RenderPassDescriptor {
            label: Some(OLDER_DEPTH_PASS),
            color_attachments: &[],
            depth_stencil_attachment: Some(RenderPassDepthStencilAttachment {
                view: &textures.older_level_depth.1,
                depth_ops: Some(Operations {
                    load: LoadOp::Clear(0.0),
                    store: StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let span = diagnostics.pass_span(&mut pass, OLDER_DEPTH_PASS);
        older_depth::draw(&mut pass, older, &cache, &meshes, &allocator);
        span.end(&mut pass);
    }
    let mut pass = ctx.begin_tracked_render_pass(RenderPassDescriptor {
        label: Some(COMBINE_PASS),
        color_attachments: &[
            Some(RenderPassColorAttachment {
                view: target.main_texture_view(),
                depth_slice: None,
                resolve_target: None,
                ops: Operations {
                    load: LoadOp::Load,
                    store: StoreOp::Store,
                },
            }),
            Some(id_attachment(textures, frame)),
        ],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    let span = diagnostics.pass_span(&mut pass, COMBINE_PASS);
    pass.set_render_pipeline(pipeline);
    pass.set_bind_group(0, &bind_group.0, &[]);
    // The pass runs even without rectangles, so its diagnostics count every frame.
    for rect in &frame.rects {
        let r = rect.intersect(URect::new(0, 0, extent.width, extent.height));
        if r.is_empty() {
            continue;
        }
        pass.set_scissor_rect(r.min.x, r.min.y, r.width(), r.height());
        pass.draw(0..3, 0..1);
    }
    span.end(&mut pass);
}

/// The combine's second target, this frame's id words (the next frame's older ids): cleared
/// where the frame is kept (the combine then writes them over its region), else kept.
fn id_attachment<'a>(
    textures: &'a FrameSequentialTextures,
    frame: &FrameSequentialView,
) -> RenderPassColorAttachment<'a> {
    RenderPassColorAttachment {
        view: &textures.ids[frame.buffer].1,
        depth_slice: None,
        resolve_target: None,
        ops: Operations {
            load: if frame.keep {
                LoadOp::Clear(LinearRgba::NONE.into())
            } else {
                LoadOp::Load
            },
            store: StoreOp::Store,
        },
    }
}
