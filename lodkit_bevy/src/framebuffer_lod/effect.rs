//! The effect a camera's framebuffer LOD renders at 1/r resolution: a user type with its own
//! bindings (`AsBindGroup`, as Bevy's materials) and its fragment shader.

use std::marker::PhantomData;

use bevy::asset::AssetId;
use bevy::core_pipeline::FullscreenShader;
use bevy::ecs::query::QueryItem;
use bevy::ecs::system::SystemParamItem;
use bevy::ecs::system::lifetimeless::SRes;
use bevy::log::error;
use bevy::prelude::*;
use bevy::render::extract_component::{ExtractComponent, ExtractComponentPlugin};
use bevy::render::material_bind_groups::FallbackBuffer;
use bevy::render::render_asset::{PrepareAssetError, RenderAsset, RenderAssetPlugin, RenderAssets};
use bevy::render::render_resource::*;
use bevy::render::renderer::RenderDevice;
use bevy::render::storage::GpuShaderBuffer;
use bevy::render::sync_component::SyncComponent;
use bevy::render::texture::GpuImage;
use bevy::render::{GpuResourceAppExt, Render, RenderApp, RenderSystems};
use bevy::shader::{ShaderDefVal, ShaderRef};

use super::FramebufferLodPlugin;
use super::layout::effect_view_layout;
use super::settings::LOW_FORMAT;

/// The bind group index of a [`FramebufferLodEffect`]'s own bindings. Group 0 holds what
/// `lodkit_bevy::framebuffer_lod` declares (view, globals, prepass, settings).
///
/// Effect shaders use it through the shader def `FRAMEBUFFER_LOD_EFFECT_BIND_GROUP`, as Bevy's
/// materials use `MATERIAL_BIND_GROUP`:
/// `@group(constants::FRAMEBUFFER_LOD_EFFECT_BIND_GROUP) @binding(0) var<uniform> fog: Fog;`.
pub const FRAMEBUFFER_LOD_EFFECT_BIND_GROUP_INDEX: usize = 1;

/// The expensive effect framebuffer LOD renders at 1/r resolution: an asset whose fields are
/// the effect's bindings, the way a Bevy `Material` is.
///
/// Derive `AsBindGroup` on your type (uniforms, textures, samplers, storage buffers of your
/// choosing), add [`FramebufferLodEffectPlugin::<YourEffect>`](FramebufferLodEffectPlugin) and
/// put a [`FramebufferLodEffectHandle`] on the camera. The bindings are bound at group
/// [`FRAMEBUFFER_LOD_EFFECT_BIND_GROUP_INDEX`] (`constants::FRAMEBUFFER_LOD_EFFECT_BIND_GROUP`
/// in WESL). Bindless (`#[bindless]`) effects are not supported: one bind group per effect
/// asset. Changing the asset (`Assets::get_mut`) rebuilds its bind group.
///
/// ```
/// use bevy::prelude::*;
/// use bevy::render::render_resource::AsBindGroup;
/// use bevy::shader::ShaderRef;
/// use lodkit_bevy::prelude::*;
///
/// #[derive(Asset, TypePath, AsBindGroup, Clone)]
/// struct Fog {
///     #[uniform(0)]
///     density: f32,
///     #[texture(1)]
///     #[sampler(2)]
///     noise: Handle<Image>,
/// }
///
/// impl FramebufferLodEffect for Fog {
///     fn fragment_shader() -> ShaderRef {
///         "shaders/fog.wesl".into()
///     }
/// }
/// ```
pub trait FramebufferLodEffect: AsBindGroup + Asset + Clone + Sized {
    /// The effect's WESL fragment shader (entry point `fragment`, run with Bevy's fullscreen
    /// vertex shader). It imports `lodkit_bevy::framebuffer_lod` and returns
    /// `effect_output(color, effect_sample(in.position))`. There is no default effect shader:
    /// `ShaderRef::Default` draws nothing and logs an error.
    fn fragment_shader() -> ShaderRef;
}

/// The effect of a camera with [`FramebufferLod`](super::FramebufferLod) (which it adds): a
/// handle to an `E` asset, as `MeshMaterial3d` is to a material. One effect per camera; the
/// camera draws nothing while the asset (or an image it binds) is loading.
#[derive(Component, Clone, Debug, Reflect)]
#[reflect(Component, Default, Clone)]
#[require(super::FramebufferLod)]
pub struct FramebufferLodEffectHandle<E: FramebufferLodEffect>(pub Handle<E>);

impl<E: FramebufferLodEffect> Default for FramebufferLodEffectHandle<E> {
    fn default() -> Self {
        Self(Handle::default())
    }
}

impl<E: FramebufferLodEffect> From<Handle<E>> for FramebufferLodEffectHandle<E> {
    fn from(handle: Handle<E>) -> Self {
        Self(handle)
    }
}

/// Framebuffer LOD with effects of type `E`: prepares every `E` asset's bind group and the
/// effect pipeline for its shader. Adds [`FramebufferLodPlugin`] if it is not added yet; add one
/// `FramebufferLodEffectPlugin` per effect type.
pub struct FramebufferLodEffectPlugin<E: FramebufferLodEffect>(PhantomData<fn() -> E>);

impl<E: FramebufferLodEffect> Default for FramebufferLodEffectPlugin<E> {
    fn default() -> Self {
        Self(PhantomData)
    }
}

impl<E: FramebufferLodEffect> Plugin for FramebufferLodEffectPlugin<E> {
    fn build(&self, app: &mut App) {
        if !app.is_plugin_added::<FramebufferLodPlugin>() {
            app.add_plugins(FramebufferLodPlugin);
        }
        app.init_asset::<E>()
            .register_type::<FramebufferLodEffectHandle<E>>()
            .add_plugins((
                ExtractComponentPlugin::<FramebufferLodEffectHandle<E>>::default(),
                RenderAssetPlugin::<PreparedEffect<E>, GpuImage>::default(),
            ));
        if let Some(render_app) = app.get_sub_app_mut(RenderApp) {
            render_app.add_systems(
                Render,
                prepare_effect_bindings::<E>.in_set(RenderSystems::PrepareBindGroups),
            );
        }
    }

    fn finish(&self, app: &mut App) {
        if let Some(render_app) = app.get_sub_app_mut(RenderApp) {
            render_app.init_gpu_resource::<EffectPipeline<E>>();
        }
    }
}

/// The render world's copy of a camera's [`FramebufferLodEffectHandle`].
#[derive(Component)]
pub struct ExtractedEffect<E: FramebufferLodEffect>(AssetId<E>);

/// What the passes need of the camera's effect this frame, whatever its type.
#[derive(Component)]
pub struct EffectBinding {
    pub(super) pipeline: CachedRenderPipelineId,
    pub(super) bind_group: BindGroup,
}

impl<E: FramebufferLodEffect> SyncComponent<RenderApp> for FramebufferLodEffectHandle<E> {
    type Target = (ExtractedEffect<E>, EffectBinding);
}

impl<E: FramebufferLodEffect> ExtractComponent<RenderApp> for FramebufferLodEffectHandle<E> {
    type QueryData = &'static FramebufferLodEffectHandle<E>;
    type QueryFilter = With<Camera3d>;
    type Out = ExtractedEffect<E>;

    fn extract_component(handle: QueryItem<'_, '_, Self::QueryData>) -> Option<Self::Out> {
        Some(ExtractedEffect(handle.0.id()))
    }
}

/// The effect pipeline of `E`: lodkit's group 0 and `E`'s layout, `E`'s fragment shader.
#[derive(Resource)]
struct EffectPipeline<E: FramebufferLodEffect> {
    layout: BindGroupLayoutDescriptor,
    pipeline: Option<CachedRenderPipelineId>,
    _marker: PhantomData<fn() -> E>,
}

impl<E: FramebufferLodEffect> FromWorld for EffectPipeline<E> {
    fn from_world(world: &mut World) -> Self {
        let layout = E::bind_group_layout_descriptor(world.resource::<RenderDevice>());
        let shader = match E::fragment_shader() {
            ShaderRef::Handle(handle) => Some(handle),
            ShaderRef::Path(path) => Some(world.resource::<AssetServer>().load(path)),
            ShaderRef::Default => {
                error!(
                    "FramebufferLodEffect {}: fragment_shader() is ShaderRef::Default, and an \
                     effect has no default shader; cameras with it draw no effect",
                    E::type_path()
                );
                None
            }
        };
        let pipeline = shader.map(|shader| {
            let descriptor = RenderPipelineDescriptor {
                label: Some(
                    format!("lodkit_framebuffer_lod_effect<{}>", E::short_type_path()).into(),
                ),
                layout: vec![effect_view_layout(), layout.clone()],
                vertex: world.resource::<FullscreenShader>().to_vertex_state(),
                fragment: Some(FragmentState {
                    shader,
                    shader_defs: vec![ShaderDefVal::UInt(
                        "FRAMEBUFFER_LOD_EFFECT_BIND_GROUP".into(),
                        FRAMEBUFFER_LOD_EFFECT_BIND_GROUP_INDEX as u32,
                    )],
                    entry_point: Some("fragment".into()),
                    targets: vec![Some(LOW_FORMAT.into()), Some(LOW_FORMAT.into())],
                    ..default()
                }),
                ..default()
            };
            world
                .resource::<PipelineCache>()
                .queue_render_pipeline(descriptor)
        });
        Self {
            layout,
            pipeline,
            _marker: PhantomData,
        }
    }
}

/// An `E` asset's bind group.
struct PreparedEffect<E: FramebufferLodEffect> {
    bind_group: BindGroup,
    _marker: PhantomData<fn() -> E>,
}

impl<E: FramebufferLodEffect> RenderAsset for PreparedEffect<E> {
    type SourceAsset = E;
    type Param = (
        SRes<RenderDevice>,
        SRes<PipelineCache>,
        SRes<EffectPipeline<E>>,
        SRes<FallbackBuffer>,
        SRes<RenderAssets<GpuShaderBuffer>>,
        E::Param,
    );

    fn prepare_asset(
        effect: E,
        _id: AssetId<E>,
        (device, cache, pipeline, fallback, buffers, param): &mut SystemParamItem<Self::Param>,
        _previous: Option<&Self>,
    ) -> Result<Self, PrepareAssetError<E>> {
        match effect.as_bind_group(&pipeline.layout, device, cache, fallback, buffers, param) {
            Ok(prepared) => Ok(Self {
                bind_group: prepared.bind_group,
                _marker: PhantomData,
            }),
            Err(AsBindGroupError::RetryNextUpdate) => {
                Err(PrepareAssetError::RetryNextUpdate(effect))
            }
            Err(other) => Err(PrepareAssetError::AsBindGroupError(other)),
        }
    }
}

/// Gives every camera with an `E` effect its pipeline and bind group for the pass, or takes them
/// away while the effect is not ready.
fn prepare_effect_bindings<E: FramebufferLodEffect>(
    mut commands: Commands,
    pipeline: Option<Res<EffectPipeline<E>>>,
    prepared: Res<RenderAssets<PreparedEffect<E>>>,
    views: Query<(Entity, &ExtractedEffect<E>)>,
) {
    for (entity, effect) in &views {
        let ready = pipeline
            .as_ref()
            .and_then(|p| p.pipeline)
            .zip(prepared.get(effect.0));
        match ready {
            Some((pipeline, prepared)) => {
                commands.entity(entity).insert(EffectBinding {
                    pipeline,
                    bind_group: prepared.bind_group.clone(),
                });
            }
            None => {
                commands.entity(entity).remove::<EffectBinding>();
            }
        }
    }
}
