//! The render-world side: extraction, the camera's main-pass viewport (its `Camera::viewport`,
//! sized by `MainPassResolutionOverride` where the render world has one), the upsample pipeline,
//! the low-resolution targets (allocated at the viewport's size once per size, drawn through a
//! viewport that shrinks with r, so changing r never reallocates), bind groups and the two
//! passes, both held inside the camera's main-pass viewport. The effect's own pipeline
//! and bind group come from its type's plugin (effect.rs).

use bevy::asset::load_embedded_asset;
use bevy::camera::MainPassResolutionOverride;
use bevy::core_pipeline::prepass::ViewPrepassTextures;
use bevy::core_pipeline::{Core3d, Core3dSystems, FullscreenShader};
use bevy::ecs::query::QueryItem;
use bevy::log::warn_once;
use bevy::prelude::*;
use bevy::render::diagnostic::RecordDiagnostics;
use bevy::render::extract_component::{ComponentUniforms, DynamicUniformIndex, ExtractComponent};
use bevy::render::globals::GlobalsBuffer;
use bevy::render::render_resource::binding_types::texture_2d;
use bevy::render::render_resource::*;
use bevy::render::renderer::{RenderContext, RenderDevice, ViewQuery};
use bevy::render::sync_component::SyncComponent;
use bevy::render::view::{ExtractedView, ViewTarget, ViewUniformOffset, ViewUniforms};
use bevy::render::{GpuResourceAppExt, Render, RenderApp, RenderSystems};
use lodkit::bilateral::gpu_sigma;

use super::effect::{EffectBinding, FRAMEBUFFER_LOD_EFFECT_BIND_GROUP_INDEX};
use super::layout::{FramebufferLodUniform, common_entries, effect_view_layout};
use super::settings::{
    ExtractedFramebufferLod, FramebufferLod, FramebufferLodComposite, FramebufferLodState,
    LOW_FORMAT,
};
use super::timer::{self, GpuFrameTimer};

/// View depth given to the sky: far beyond any scene, inside half-float range.
const SKY_DEPTH: f32 = 60_000.0;
/// Name of the effect pass in Bevy's render diagnostics: with `RenderDiagnosticsPlugin`,
/// `render/<name>/elapsed_gpu` and `render/<name>/fragment_shader_invocations` (where the device
/// has pipeline statistics).
pub const EFFECT_PASS: &str = "lodkit_framebuffer_lod_effect";
/// Name of the upsample pass in Bevy's render diagnostics (as [`EFFECT_PASS`]).
pub const UPSAMPLE_PASS: &str = "lodkit_framebuffer_lod_upsample";

impl SyncComponent<RenderApp> for FramebufferLod {
    type Target = (
        ExtractedFramebufferLod,
        FramebufferLodUniform,
        FramebufferLodTextures,
        FramebufferLodBindGroups,
        FramebufferLodPipelineIds,
        GpuFrameTimer,
    );
}

impl ExtractComponent<RenderApp> for FramebufferLod {
    type QueryData = (
        &'static FramebufferLod,
        &'static FramebufferLodState,
        &'static Camera,
        Option<&'static Msaa>,
    );
    type QueryFilter = With<Camera3d>;
    type Out = (ExtractedFramebufferLod, FramebufferLodUniform);

    fn extract_component(
        (settings, state, camera, msaa): QueryItem<'_, '_, Self::QueryData>,
    ) -> Option<Self::Out> {
        if !camera.is_active {
            return None;
        }
        if msaa.is_some_and(|m| *m != Msaa::Off) {
            warn_once!(
                "FramebufferLod needs Msaa::Off on its camera (the prepass is read per pixel); \
                 the effect is not drawn"
            );
            return None;
        }
        // The sizes are the render world's (prepare_viewports): a MainPassResolutionOverride
        // lives there.
        camera.physical_viewport_size()?;
        // The controller keeps the factor in [1, MAX_FACTOR] (clamp_factor), the one place r is
        // clamped.
        let factor = state.factor;
        // A shader is given no infinity: +inf (no range term) as the finite sigma that does the same.
        let sigmas = settings.upsample.sigmas();
        let (depth_sigma, normal_sigma) = (gpu_sigma(sigmas.depth), gpu_sigma(sigmas.normal));
        Some((
            ExtractedFramebufferLod {
                composite: settings.composite,
                factor,
                gpu_timed: state.gpu_timed,
                low_size: UVec2::ONE,
                origin: UVec2::ZERO,
                full_size: UVec2::ONE,
            },
            FramebufferLodUniform {
                low_size: Vec2::ONE,
                full_size: Vec2::ONE,
                origin: Vec2::ZERO,
                factor,
                depth_sigma,
                normal_sigma,
                sky_depth: SKY_DEPTH,
            },
        ))
    }
}

pub(super) fn build(render_app: &mut SubApp) {
    render_app.add_systems(
        Render,
        (
            prepare_pipelines.in_set(RenderSystems::Prepare),
            // Before the uniform is written and the targets are sized (both in
            // PrepareResources, a subset of Prepare that is not ordered after Prepare's own).
            prepare_viewports
                .in_set(RenderSystems::Prepare)
                .before(RenderSystems::PrepareResources),
            prepare_textures.in_set(RenderSystems::PrepareResources),
            prepare_bind_groups.in_set(RenderSystems::PrepareBindGroups),
        ),
    );
    render_app.add_systems(
        Core3d,
        framebuffer_lod_pass
            .after(Core3dSystems::MainPass)
            .before(Core3dSystems::EarlyPostProcess),
    );
    timer::build(render_app);
}

pub(super) fn finish(render_app: &mut SubApp) {
    render_app
        .init_gpu_resource::<FramebufferLodPipelines>()
        .init_gpu_resource::<SpecializedRenderPipelines<FramebufferLodPipelines>>();
}

/// The camera's main-pass viewport this frame, from its extracted view (`Camera::viewport`, or
/// the whole target) and a `MainPassResolutionOverride` (which keeps the viewport's corner and
/// sets its size, at most the viewport's): where the prepass and main pass drew, so where the
/// effect reads and the upsample writes. The low-resolution size follows: ceil(size / r).
fn prepare_viewports(
    mut views: Query<(
        &mut ExtractedFramebufferLod,
        &mut FramebufferLodUniform,
        &ExtractedView,
        Option<&MainPassResolutionOverride>,
    )>,
) {
    for (mut extracted, mut uniform, view, resolution_override) in &mut views {
        let viewport = view.viewport;
        let size = resolution_override
            .map_or(viewport.zw(), |o| o.0.min(viewport.zw()))
            .max(UVec2::ONE);
        // lodkit's one computation of L's size: ceil(size / r), at least 1.
        let (w, h) = lodkit::framebuffer_lod::low_res_size((size.x, size.y), uniform.factor);
        let low = UVec2::new(w, h);
        extracted.origin = viewport.xy();
        extracted.full_size = size;
        extracted.low_size = low;
        uniform.origin = viewport.xy().as_vec2();
        uniform.full_size = size.as_vec2();
        uniform.low_size = low.as_vec2();
    }
}

/// Bind group layouts and shader of the upsample pass, and the effect pass's group 0.
#[derive(Resource)]
pub struct FramebufferLodPipelines {
    effect_layout: BindGroupLayoutDescriptor,
    upsample_layout: BindGroupLayoutDescriptor,
    upsample_shader: Handle<Shader>,
    fullscreen: FullscreenShader,
}

impl FromWorld for FramebufferLodPipelines {
    fn from_world(world: &mut World) -> Self {
        let common = common_entries();
        let effect_layout = effect_view_layout();
        let low = texture_2d(TextureSampleType::Float { filterable: false });
        let upsample_layout = BindGroupLayoutDescriptor::new(
            "lodkit_framebuffer_lod_upsample",
            &BindGroupLayoutEntries::sequential(
                ShaderStages::FRAGMENT,
                (
                    common[0], common[1], common[2], common[3], common[4], low, low,
                ),
            ),
        );
        Self {
            effect_layout,
            upsample_layout,
            upsample_shader: load_embedded_asset!(world, "upsample.wesl"),
            fullscreen: world.resource::<FullscreenShader>().clone(),
        }
    }
}

/// The upsample pipeline: blended with this composite into a main texture of this format.
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct PipelineKey(FramebufferLodComposite, TextureFormat);

impl SpecializedRenderPipeline for FramebufferLodPipelines {
    type Key = PipelineKey;

    fn specialize(&self, key: Self::Key) -> RenderPipelineDescriptor {
        let PipelineKey(composite, format) = key;
        let keep_alpha = BlendComponent {
            src_factor: BlendFactor::Zero,
            dst_factor: BlendFactor::One,
            operation: BlendOperation::Add,
        };
        let color = match composite {
            FramebufferLodComposite::Over => BlendComponent {
                src_factor: BlendFactor::One,
                dst_factor: BlendFactor::OneMinusSrcAlpha,
                operation: BlendOperation::Add,
            },
            FramebufferLodComposite::Modulate => BlendComponent {
                src_factor: BlendFactor::Zero,
                dst_factor: BlendFactor::Src,
                operation: BlendOperation::Add,
            },
        };
        let target = ColorTargetState {
            format,
            blend: Some(BlendState {
                color,
                alpha: keep_alpha,
            }),
            write_mask: ColorWrites::ALL,
        };
        RenderPipelineDescriptor {
            label: Some("lodkit_framebuffer_lod_upsample".into()),
            layout: vec![self.upsample_layout.clone()],
            vertex: self.fullscreen.to_vertex_state(),
            fragment: Some(FragmentState {
                shader: self.upsample_shader.clone(),
                entry_point: Some("fragment".into()),
                targets: vec![Some(target)],
                ..default()
            }),
            ..default()
        }
    }
}

/// The camera's upsample pipeline (the effect's comes with its [`EffectBinding`]).
#[derive(Component)]
pub struct FramebufferLodPipelineIds {
    upsample: CachedRenderPipelineId,
}

fn prepare_pipelines(
    mut commands: Commands,
    cache: Res<PipelineCache>,
    mut specialized: ResMut<SpecializedRenderPipelines<FramebufferLodPipelines>>,
    pipelines: Res<FramebufferLodPipelines>,
    views: Query<(Entity, &ExtractedFramebufferLod, &ExtractedView)>,
) {
    for (entity, extracted, view) in &views {
        let upsample = specialized.specialize(
            &cache,
            &pipelines,
            PipelineKey(extracted.composite, view.target_format),
        );
        commands
            .entity(entity)
            .insert(FramebufferLodPipelineIds { upsample });
    }
}

/// The low-resolution color and geometry targets, at the camera's full size.
#[derive(Component)]
pub struct FramebufferLodTextures {
    size: UVec2,
    color: TextureView,
    geometry: TextureView,
}

fn prepare_textures(
    mut commands: Commands,
    device: Res<RenderDevice>,
    views: Query<(
        Entity,
        &ExtractedFramebufferLod,
        Option<&FramebufferLodTextures>,
    )>,
) {
    for (entity, extracted, textures) in &views {
        let size = extracted.full_size;
        if textures.is_some_and(|t| t.size == size) {
            continue;
        }
        let target = |label| {
            device
                .create_texture(&TextureDescriptor {
                    label: Some(label),
                    size: Extent3d {
                        width: size.x,
                        height: size.y,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: TextureDimension::D2,
                    format: LOW_FORMAT,
                    usage: TextureUsages::RENDER_ATTACHMENT | TextureUsages::TEXTURE_BINDING,
                    view_formats: &[],
                })
                .create_view(&TextureViewDescriptor::default())
        };
        commands.entity(entity).insert(FramebufferLodTextures {
            size,
            color: target("lodkit_framebuffer_lod_color"),
            geometry: target("lodkit_framebuffer_lod_geometry"),
        });
    }
}

/// The camera's bind groups for the two passes.
#[derive(Component)]
pub struct FramebufferLodBindGroups {
    effect: BindGroup,
    upsample: BindGroup,
}

#[allow(clippy::too_many_arguments)]
fn prepare_bind_groups(
    mut commands: Commands,
    device: Res<RenderDevice>,
    cache: Res<PipelineCache>,
    pipelines: Res<FramebufferLodPipelines>,
    view_uniforms: Res<ViewUniforms>,
    globals: Res<GlobalsBuffer>,
    settings: Res<ComponentUniforms<FramebufferLodUniform>>,
    views: Query<(Entity, &FramebufferLodTextures, &ViewPrepassTextures)>,
) {
    let (Some(view), Some(globals), Some(settings)) = (
        view_uniforms.uniforms.binding(),
        globals.buffer.binding(),
        settings.uniforms().binding(),
    ) else {
        return;
    };
    for (entity, textures, prepass) in &views {
        let (Some(depth), Some(normal)) = (prepass.depth_only_view(), prepass.normal_view()) else {
            continue;
        };
        let effect = device.create_bind_group(
            "lodkit_framebuffer_lod_effect",
            &cache.get_bind_group_layout(&pipelines.effect_layout),
            &BindGroupEntries::sequential((
                view.clone(),
                globals.clone(),
                depth,
                normal,
                settings.clone(),
            )),
        );
        let upsample = device.create_bind_group(
            "lodkit_framebuffer_lod_upsample",
            &cache.get_bind_group_layout(&pipelines.upsample_layout),
            &BindGroupEntries::sequential((
                view.clone(),
                globals.clone(),
                depth,
                normal,
                settings.clone(),
                &textures.color,
                &textures.geometry,
            )),
        );
        commands
            .entity(entity)
            .insert(FramebufferLodBindGroups { effect, upsample });
    }
}

/// What the pass reads from the view.
type PassView = (
    &'static ViewTarget,
    &'static ViewUniformOffset,
    &'static DynamicUniformIndex<FramebufferLodUniform>,
    &'static ExtractedFramebufferLod,
    &'static FramebufferLodTextures,
    &'static FramebufferLodBindGroups,
    &'static FramebufferLodPipelineIds,
    &'static EffectBinding,
);

/// The effect at 1/r into the low-resolution targets, then the upsample into the main texture.
fn framebuffer_lod_pass(
    view: ViewQuery<PassView>,
    cache: Res<PipelineCache>,
    mut ctx: RenderContext,
) {
    let (target, view_offset, settings_index, extracted, textures, bind_groups, ids, effect) =
        view.into_inner();
    let effect_bind_group = &effect.bind_group;
    let (Some(effect), Some(upsample)) = (
        cache.get_render_pipeline(effect.pipeline),
        cache.get_render_pipeline(ids.upsample),
    ) else {
        return;
    };
    let offsets = [view_offset.offset, settings_index.index()];
    let diagnostics = ctx.diagnostic_recorder();
    let diagnostics = diagnostics.as_deref();
    let keep = Operations {
        load: LoadOp::Load,
        store: StoreOp::Store,
    };
    let attachment = |view| {
        Some(RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: keep,
        })
    };
    {
        // Texels outside the viewport are never read, so the targets are not cleared.
        let mut pass = ctx.begin_tracked_render_pass(RenderPassDescriptor {
            label: Some(EFFECT_PASS),
            color_attachments: &[attachment(&textures.color), attachment(&textures.geometry)],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let span = diagnostics.pass_span(&mut pass, EFFECT_PASS);
        let low = extracted.low_size.as_vec2();
        pass.set_viewport(0.0, 0.0, low.x, low.y, 0.0, 1.0);
        pass.set_render_pipeline(effect);
        pass.set_bind_group(0, &bind_groups.effect, &offsets);
        pass.set_bind_group(
            FRAMEBUFFER_LOD_EFFECT_BIND_GROUP_INDEX,
            effect_bind_group,
            &[],
        );
        pass.draw(0..3, 0..1);
        span.end(&mut pass);
    }
    {
        let mut pass = ctx.begin_tracked_render_pass(RenderPassDescriptor {
            label: Some(UPSAMPLE_PASS),
            color_attachments: &[attachment(target.main_texture_view())],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let span = diagnostics.pass_span(&mut pass, UPSAMPLE_PASS);
        // Only the camera's main-pass viewport: the fullscreen triangle is clipped to it.
        let (origin, full) = (extracted.origin.as_vec2(), extracted.full_size.as_vec2());
        pass.set_viewport(origin.x, origin.y, full.x, full.y, 0.0, 1.0);
        pass.set_render_pipeline(upsample);
        pass.set_bind_group(0, &bind_groups.upsample, &offsets);
        pass.draw(0..3, 0..1);
        span.end(&mut pass);
    }
}
