//! The material a LOD group's levels are drawn with: Bevy's `StandardMaterial`, shaded by Bevy's
//! PBR functions, extended to write the fragment's LOD-buffer id word in alpha.

use bevy::asset::{RenderAssetUsages, uuid_handle};
use bevy::mesh::MeshVertexBufferLayoutRef;
use bevy::pbr::{
    ExtendedMaterial, MaterialExtension, MaterialExtensionKey, MaterialExtensionPipeline,
};
use bevy::prelude::*;
use bevy::reflect::TypePath;
use bevy::render::render_resource::{
    AsBindGroup, Extent3d, FragmentState, RenderPipelineDescriptor, SpecializedMeshPipelineError,
    TextureDimension, TextureFormat,
};
use bevy::shader::ShaderDefVal;
use bevy::shader::ShaderRef;
use lodkit::visibility::{VisibilityPattern, visibility_texture};

/// The main-pass shader of [`FrameSequentialExtension`].
pub(super) const LOD_MATERIAL_SHADER: Handle<Shader> =
    uuid_handle!("0b8f3e7a-5c1d-4e92-a6b4-7d2c9e1f3a58");
/// The prepass shader of [`FrameSequentialExtension`].
pub(super) const LOD_PREPASS_SHADER: Handle<Shader> =
    uuid_handle!("7c2e9a14-3b6d-4f58-8e01-d5a3c7b9f246");
/// The prepass shader [`FrameSequentialBindings`] puts in place of Bevy's default one.
pub(super) const LOD_DEFAULT_PREPASS_SHADER: Handle<Shader> =
    uuid_handle!("3e8b1f02-6a4c-4d97-b5e3-9c0f2a7d4b61");
/// The visibility texture every [`FrameSequentialExtension`] binds (64x64 void-and-cluster
/// blue noise from `lodkit::visibility::visibility_texture`).
pub const VISIBILITY_TEXTURE: Handle<Image> = uuid_handle!("5d7a2c41-8e36-4b0f-9c15-e2a4b6d8f013");
/// Size of [`VISIBILITY_TEXTURE`].
pub const VISIBILITY_TEXTURE_SIZE: u32 = 64;
/// Seed of [`VISIBILITY_TEXTURE`].
pub const VISIBILITY_TEXTURE_SEED: u64 = 1;

/// A LOD level's material: Bevy's [`StandardMaterial`] with [`FrameSequentialExtension`].
pub type FrameSequentialMaterial = ExtendedMaterial<StandardMaterial, FrameSequentialExtension>;

/// The extension that makes a [`StandardMaterial`] a level of a frame-sequential LOD group: the
/// shading is Bevy's, unchanged; the main pass also writes the fragment's LOD-buffer id word and
/// display-time flags (from lodkit's visibility pattern) in alpha, which the combine pass reads.
/// Where the group blends with the screen-door dither instead (a camera with MSAA), its prepass
/// (StandardMaterial's, with the dither's discard first) keeps the same pixels of each level as
/// the main pass, so a camera with MSAA and a prepass gets the dither too; on such a camera the
/// prepass of an opaque level gets a fragment stage (a depth-only prepass of Bevy's has none).
/// Shadow maps and prepasses without MSAA are Bevy's.
///
/// ```
/// use bevy::prelude::*;
/// use lodkit_bevy::frame_sequential::{FrameSequentialExtension, FrameSequentialMaterial};
///
/// let material = FrameSequentialMaterial {
///     base: StandardMaterial::from(Color::srgb(0.8, 0.5, 0.2)),
///     extension: FrameSequentialExtension::default(),
/// };
/// # let _ = material;
/// ```
#[derive(Asset, AsBindGroup, TypePath, Clone, Debug)]
pub struct FrameSequentialExtension {
    /// The visibility texture ([`VISIBILITY_TEXTURE`] unless you bring your own: single-channel,
    /// values strictly between 0 and 1).
    #[texture(100, sample_type = "float", filterable = false)]
    pub visibility: Handle<Image>,
    /// x: texture repeats per object-space unit where the pattern sticks to the object
    /// ([`VisibilitySpace::Object`](super::VisibilitySpace::Object)); y, z, w unused.
    #[uniform(101)]
    pub pattern_scale: Vec4,
}

impl Default for FrameSequentialExtension {
    fn default() -> Self {
        Self {
            visibility: VISIBILITY_TEXTURE,
            pattern_scale: Vec4::new(8.0, 0.0, 0.0, 0.0),
        }
    }
}

impl MaterialExtension for FrameSequentialExtension {
    fn fragment_shader() -> ShaderRef {
        LOD_MATERIAL_SHADER.into()
    }

    fn specialize(
        _: &MaterialExtensionPipeline,
        descriptor: &mut RenderPipelineDescriptor,
        _: &MeshVertexBufferLayoutRef,
        key: MaterialExtensionKey<Self>,
    ) -> Result<(), SpecializedMeshPipelineError> {
        define_level(descriptor);
        if key.mesh_key.msaa_samples() > 1 {
            dither_in_prepass(descriptor, STANDARD_PREPASS_SHADER_PATH, LOD_PREPASS_SHADER);
        }
        Ok(())
    }
}

/// The shader def Bevy's prepass pipelines (the camera's prepass and shadow maps) define.
const PREPASS_PIPELINE_SHADER_DEF: &str = "PREPASS_PIPELINE";

/// Whether `descriptor` is a prepass pipeline's (the camera's prepass or a shadow map's).
fn is_prepass(descriptor: &RenderPipelineDescriptor) -> bool {
    descriptor.vertex.shader_defs.iter().any(
        |def| matches!(def, ShaderDefVal::Bool(name, true) if name == PREPASS_PIPELINE_SHADER_DEF),
    )
}

/// Where Bevy 0.20.1 keeps its default prepass shader (the vertex and fragment stages of a
/// material with no prepass shader of its own).
const DEFAULT_PREPASS_SHADER_PATH: &str = "bevy_pbr/prepass/prepass.wesl";
/// Where Bevy 0.20.1 keeps `StandardMaterial`'s prepass fragment shader.
const STANDARD_PREPASS_SHADER_PATH: &str = "bevy_pbr/render/pbr_prepass.wesl";

/// On a camera prepass pipeline (not a shadow map's: those have one sample, and the callers
/// come here only for a multisampled one) that runs Bevy's default prepass vertex shader, puts
/// `ours` where Bevy's fragment shader at `bevys` would run, or where a depth-only prepass runs
/// no fragment stage: `ours` drops the pixels the screen-door dither drops, so the prepass keeps
/// the same pixels of each level as the main pass. A material with a prepass shader of its own
/// keeps it (its groups switch at once on a camera with MSAA and a prepass). Without MSAA no
/// prepass changes: the combine runs there, and no level pays for a fragment stage or a
/// material binding in its depth-only prepass or its shadows.
fn dither_in_prepass(descriptor: &mut RenderPipelineDescriptor, bevys: &str, ours: Handle<Shader>) {
    let at = |shader: &Handle<Shader>, path: &str| {
        shader.path().is_some_and(|p| p.path().ends_with(path))
    };
    if !is_prepass(descriptor) || !at(&descriptor.vertex.shader, DEFAULT_PREPASS_SHADER_PATH) {
        return;
    }
    match descriptor.fragment.as_mut() {
        None => {
            descriptor.fragment = Some(FragmentState {
                shader: ours,
                shader_defs: descriptor.vertex.shader_defs.clone(),
                ..default()
            });
        }
        Some(fragment) if at(&fragment.shader, bevys) => fragment.shader = ours,
        Some(_) => {}
    }
}

/// The shader def under which `lodkit_bevy::frame_sequential_level` declares its bindings and
/// `lod_level_color` does its work.
pub const LEVEL_SHADER_DEF: &str = "LODKIT_FRAME_SEQUENTIAL_LEVEL";

/// Defines [`LEVEL_SHADER_DEF`] in the fragment stage.
fn define_level(descriptor: &mut RenderPipelineDescriptor) {
    if let Some(fragment) = descriptor.fragment.as_mut() {
        fragment.shader_defs.push(LEVEL_SHADER_DEF.into());
    }
}

/// The extension that makes a material of the app's own a level of a frame-sequential LOD
/// group ([`FrameSequentialLevel<M>`](super::FrameSequentialLevel), derived by
/// [`FrameSequentialMaterialPlugin`](super::FrameSequentialMaterialPlugin)): the bindings that
/// `lodkit_bevy::frame_sequential_level::lod_level_color` reads (the same as
/// [`FrameSequentialExtension`]'s, at 100 and 101) and the shader def [`LEVEL_SHADER_DEF`] that
/// turns it on. The material's own shaders are used, unchanged; where the material has no
/// prepass shader of its own, on a camera with MSAA, its prepass drops the pixels the
/// screen-door dither drops (Bevy's default prepass with the dither's discard first).
#[derive(Asset, AsBindGroup, TypePath, Clone, Debug)]
pub struct FrameSequentialBindings {
    /// The visibility texture (as [`FrameSequentialExtension::visibility`]).
    #[texture(100, sample_type = "float", filterable = false)]
    pub visibility: Handle<Image>,
    /// As [`FrameSequentialExtension::pattern_scale`].
    #[uniform(101)]
    pub pattern_scale: Vec4,
}

impl Default for FrameSequentialBindings {
    fn default() -> Self {
        let FrameSequentialExtension {
            visibility,
            pattern_scale,
        } = FrameSequentialExtension::default();
        Self {
            visibility,
            pattern_scale,
        }
    }
}

impl MaterialExtension for FrameSequentialBindings {
    fn specialize(
        _: &MaterialExtensionPipeline,
        descriptor: &mut RenderPipelineDescriptor,
        _: &MeshVertexBufferLayoutRef,
        key: MaterialExtensionKey<Self>,
    ) -> Result<(), SpecializedMeshPipelineError> {
        define_level(descriptor);
        if key.mesh_key.msaa_samples() > 1 {
            dither_in_prepass(
                descriptor,
                DEFAULT_PREPASS_SHADER_PATH,
                LOD_DEFAULT_PREPASS_SHADER,
            );
        }
        Ok(())
    }
}

/// lodkit's blue-noise visibility texture as an R32Float image.
pub(super) fn visibility_image() -> Image {
    let texture = visibility_texture(
        VisibilityPattern::BlueNoise,
        VISIBILITY_TEXTURE_SIZE,
        VISIBILITY_TEXTURE_SEED,
    );
    let bytes = texture
        .texels
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    Image::new(
        Extent3d {
            width: texture.size,
            height: texture.size,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        bytes,
        TextureFormat::R32Float,
        RenderAssetUsages::RENDER_WORLD,
    )
}
