//! Octahedral impostors in Bevy: [`ImpostorMaterial`] draws an atlas that lodkit baked
//! (`lodkit::gpu::impostor::bake_impostor`, or `lodkit lod --impostor`) as a Bevy material, and
//! [`ImpostorPlugin`] registers it.
//!
//! The entity carries the card mesh [`ImpostorMaterial::card_mesh`] (six vertices whose
//! positions span the bounding sphere's box, so Bevy culls it as the object, and whose uv is the
//! card's corner) and the material. Its vertex shader turns the card to face the camera,
//! through the sphere's centre, sized to the cone from the eye tangent to the sphere; its
//! fragment shader blends the three frames nearest the view ray with one parallax step each
//! (lodkit's `impostor_sample`, the module every lodkit host draws impostors with), drops what
//! the atlas does not cover, writes the depth of the surface the frames saw (so other objects
//! intersect the impostor as they would the mesh) and shades the baked base colour and normal
//! with Bevy's PBR lighting: the scene's lights, received shadows, fog and tonemapping, as a
//! `StandardMaterial` with the material's roughness and metallic. An entity with Bevy's
//! `VisibilityRange` fades in and out with Bevy's dither, so a mesh chain drawn with visibility
//! ranges can end in an impostor. With
//! [`FrameSequentialMaterialPlugin::<ImpostorMaterial>`](crate::frame_sequential::FrameSequentialMaterialPlugin)
//! it is the last level of a frame-sequential group (`LevelMaterial::custom`; the shader ends
//! with `lod_level_color`), blended with the screen-door dither: lodkit cannot repeat the alpha
//! test of a material of the app's own type in the combine.
//!
//! ```no_run
//! use bevy::prelude::*;
//! use lodkit::impostor::ImpostorAtlas;
//! use lodkit_bevy::impostor::{ImpostorMaterial, ImpostorPlugin};
//!
//! fn spawn(
//!     atlas: &ImpostorAtlas,
//!     commands: &mut Commands,
//!     meshes: &mut Assets<Mesh>,
//!     images: &mut Assets<Image>,
//!     materials: &mut Assets<ImpostorMaterial>,
//! ) -> Result<(), lodkit_bevy::impostor::ImpostorMaterialError> {
//!     let material = ImpostorMaterial::new(atlas, images)?;
//!     commands.spawn((
//!         Mesh3d(meshes.add(ImpostorMaterial::card_mesh(&atlas.layout))),
//!         MeshMaterial3d(materials.add(material)),
//!         Transform::from_xyz(0.0, 0.0, -10.0),
//!     ));
//!     Ok(())
//! }
//! # let _ = (ImpostorPlugin, spawn);
//! ```
//!
//! Limits: the instance's transform must be a rotation, a uniform scale and a translation (a
//! sheared or non-uniformly scaled impostor draws at the wrong depth); views are perspective;
//! the impostor casts no shadow and is not drawn in Bevy's prepasses (a camera with a depth
//! prepass still depth-tests it in the main pass; its depth is not in the prepass's texture).

use bevy::asset::{RenderAssetUsages, uuid_handle};
use bevy::image::{ImageAddressMode, ImageFilterMode, ImageSampler, ImageSamplerDescriptor};
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::prelude::*;
use bevy::reflect::TypePath;
use bevy::render::render_resource::{
    AsBindGroup, Extent3d, ShaderType, TextureDataOrder, TextureDimension, TextureFormat,
};
use bevy::shader::ShaderRef;
use lodkit::impostor::{ImpostorAtlas, ImpostorError, ImpostorImage, ImpostorLayout};

use crate::shaders::LodkitShadersPlugin;

/// The shader of [`ImpostorMaterial`] (`impostor.wesl`).
const IMPOSTOR_SHADER: Handle<Shader> = uuid_handle!("9a4e61c2-7b3f-4d85-b0e9-2c6f8a1d5e73");
/// Its prepass and shadow shader (`impostor_prepass.wesl`): draws nothing.
const IMPOSTOR_PREPASS_SHADER: Handle<Shader> =
    uuid_handle!("4c8d2e71-9f3a-4b56-a1e0-7d5b3c9f2a84");

/// Registers [`ImpostorMaterial`] (and lodkit's shader modules, where
/// [`LodkitShadersPlugin`] is not added yet). Adding it more than once is harmless (with the
/// `gltf` feature [`FrameSequentialLodPlugin`](crate::FrameSequentialLodPlugin) adds it, to draw
/// the impostor levels of glTF files).
pub struct ImpostorPlugin;

/// Marks an app [`ImpostorPlugin`] has built.
#[derive(Resource)]
struct ImpostorPluginBuilt;

impl Plugin for ImpostorPlugin {
    fn is_unique(&self) -> bool {
        false
    }

    fn build(&self, app: &mut App) {
        if app.world().contains_resource::<ImpostorPluginBuilt>()
            || app.is_plugin_added::<MaterialPlugin<ImpostorMaterial>>()
        {
            return;
        }
        app.insert_resource(ImpostorPluginBuilt);
        if !app.is_plugin_added::<LodkitShadersPlugin>() {
            app.add_plugins(LodkitShadersPlugin);
        }
        // The shader ends with lod_level_color (a level of a frame-sequential group).
        crate::shaders::register_level_libraries(app);
        app.world_mut()
            .resource_mut::<Assets<Shader>>()
            .insert(
                &IMPOSTOR_SHADER,
                Shader::from_wesl(
                    include_str!("impostor.wesl"),
                    "embedded://lodkit_bevy/impostor.wesl",
                ),
            )
            .expect("UUID handles never fail to insert");
        app.world_mut()
            .resource_mut::<Assets<Shader>>()
            .insert(
                &IMPOSTOR_PREPASS_SHADER,
                Shader::from_wesl(
                    include_str!("impostor_prepass.wesl"),
                    "embedded://lodkit_bevy/impostor_prepass.wesl",
                ),
            )
            .expect("UUID handles never fail to insert");
        app.add_plugins(MaterialPlugin::<ImpostorMaterial>::default());
    }
}

/// What the shader reads of an impostor besides its atlases (`impostor.wesl`'s
/// `ImpostorParams`).
#[derive(ShaderType, Clone, Copy, Debug, PartialEq)]
pub struct ImpostorParams {
    /// xyz: the bounding sphere's centre (object space); w: its radius.
    pub sphere: Vec4,
    /// x: frames per side, y: 1 for the hemisphere, z: texels per frame side; w unused.
    pub atlas: UVec4,
    /// x: perceptual roughness, y: metallic (as `StandardMaterial`'s); z, w unused.
    pub surface: Vec4,
}

/// An octahedral impostor's material: its layout, its two atlases with their mip chains, and
/// the surface Bevy's lighting shades it as. Build it with [`ImpostorMaterial::new`]; draw it on
/// [`ImpostorMaterial::card_mesh`].
#[derive(Asset, AsBindGroup, TypePath, Clone, Debug)]
pub struct ImpostorMaterial {
    /// The layout and the surface.
    #[uniform(0)]
    pub params: ImpostorParams,
    /// Base colour and coverage: `Rgba8UnormSrgb`, the whole mip chain, sampled linearly with
    /// mipmaps and clamped to the edge (the sampler both atlases are read with).
    #[texture(1)]
    #[sampler(3)]
    pub color: Handle<Image>,
    /// Object-space normal `* 0.5 + 0.5` and the stored depth: `Rgba16Float`, the whole mip
    /// chain.
    #[texture(2)]
    pub normal_depth: Handle<Image>,
}

/// An atlas [`ImpostorMaterial::new`] cannot draw.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ImpostorMaterialError {
    /// The layout is out of range.
    #[error("ImpostorMaterial::new: atlas.layout: {0}")]
    Layout(#[from] ImpostorError),
    /// A mip chain does not match the layout.
    #[error(
        "ImpostorMaterial::new: atlas.{atlas} has {found}, expected {expected} levels halving from \
         {size} x {size} texels"
    )]
    MipChain {
        /// `color` or `normal_depth`.
        atlas: &'static str,
        /// What it has.
        found: String,
        /// The levels the layout has (`ImpostorAtlas::mip_levels`).
        expected: u32,
        /// The atlas's side at level 0.
        size: u32,
    },
    /// An atlas image [`ImpostorMaterial::from_level0_images`] cannot read.
    #[error("ImpostorMaterial::from_level0_images: the {atlas} image {problem}")]
    Image {
        /// `color` or `normal_depth`.
        atlas: &'static str,
        /// What is wrong with it.
        problem: String,
    },
}

impl ImpostorMaterial {
    /// The material of `atlas` (checked: a layout lodkit can draw, each mip chain whole), its
    /// two atlases added to `images`; roughness 1 and metallic 0, as `lodkit lod --impostor`
    /// writes its impostor's material.
    pub fn new(
        atlas: &ImpostorAtlas,
        images: &mut Assets<Image>,
    ) -> Result<Self, ImpostorMaterialError> {
        let layout = atlas.layout;
        layout.validate()?;
        let levels = ImpostorAtlas::mip_levels(&layout);
        let size = layout.atlas_size();
        for (name, chain) in [
            ("color", &atlas.color),
            ("normal_depth", &atlas.normal_depth),
        ] {
            let whole = chain.len() == levels as usize
                && chain.iter().enumerate().all(|(k, image)| {
                    image.size == size >> k && image.texels.len() == (image.size as usize).pow(2)
                });
            if !whole {
                return Err(ImpostorMaterialError::MipChain {
                    atlas: name,
                    found: format!(
                        "{} levels of {:?} texels a side",
                        chain.len(),
                        chain.iter().map(|i| i.size).collect::<Vec<_>>()
                    ),
                    expected: levels,
                    size,
                });
            }
        }
        let color = atlas
            .color
            .iter()
            .flat_map(ImpostorImage::to_srgba8)
            .collect();
        let normal_depth = atlas
            .normal_depth
            .iter()
            .flat_map(|image| &image.texels)
            .flat_map(|t| t.map(|c| half::f16::from_f32(c).to_le_bytes()))
            .flatten()
            .collect();
        Ok(Self {
            params: Self::params(&layout),
            color: images.add(atlas_image(
                size,
                levels,
                color,
                TextureFormat::Rgba8UnormSrgb,
            )),
            normal_depth: images.add(atlas_image(
                size,
                levels,
                normal_depth,
                TextureFormat::Rgba16Float,
            )),
        })
    }

    /// The material of an impostor of `layout` whose atlases are Bevy images of level 0 (frames
    /// padded: what `lodkit lod --impostor` writes into a glTF file, read by Bevy's loader), the
    /// mip chains built as a bake builds them ([`ImpostorAtlas::from_level0`]) and added to
    /// `images` with the two atlases. `color`: RGBA8 or RGBA16 unorm holds sRGB-encoded colour
    /// (whether its format says `Rgba8UnormSrgb` or `Rgba8Unorm`: the values are what the PNG
    /// held), RGBA16 or RGBA32 float linear colour; `normal_depth`: any of the four, linear. An image of another format, not square, not the layout's size, or whose
    /// texels are not in main-world memory (`RenderAssetUsages` without `MAIN_WORLD`) is an
    /// error naming it.
    pub fn from_level0_images(
        layout: ImpostorLayout,
        color: &Image,
        normal_depth: &Image,
        images: &mut Assets<Image>,
    ) -> Result<Self, ImpostorMaterialError> {
        Self::new(&Self::atlas_of_images(layout, color, normal_depth)?, images)
    }

    /// The atlas [`from_level0_images`](Self::from_level0_images) draws: the two images read and
    /// their mip chains built.
    pub fn atlas_of_images(
        layout: ImpostorLayout,
        color: &Image,
        normal_depth: &Image,
    ) -> Result<ImpostorAtlas, ImpostorMaterialError> {
        layout.validate()?;
        let color = atlas_level0(color, "color", layout.atlas_size(), true)?;
        let normal_depth = atlas_level0(normal_depth, "normal_depth", layout.atlas_size(), false)?;
        Ok(ImpostorAtlas::from_level0(layout, color, normal_depth)?)
    }

    /// The uniform of `layout`, roughness 1 and metallic 0.
    pub fn params(layout: &ImpostorLayout) -> ImpostorParams {
        ImpostorParams {
            sphere: Vec3::from(layout.center).extend(layout.radius),
            atlas: UVec4::new(
                layout.frames,
                u32::from(layout.shape.is_hemi()),
                layout.frame_size,
                0,
            ),
            surface: Vec4::new(1.0, 0.0, 0.0, 0.0),
        }
    }

    /// The card every impostor of `layout` is drawn on: two triangles whose positions span the
    /// bounding sphere's box (Bevy's culling and its visibility ranges see the object) and whose
    /// `UV_0` is the card's corner (-1 or 1 each way; the shader places the card). Its normals
    /// (+z) are there for Bevy's pipelines that ask for them; the shader reads none.
    pub fn card_mesh(layout: &ImpostorLayout) -> Mesh {
        let corners = [
            [-1.0, -1.0],
            [1.0, -1.0],
            [1.0, 1.0],
            [-1.0, -1.0],
            [1.0, 1.0],
            [-1.0, 1.0],
        ];
        let center = Vec3::from(layout.center);
        let positions: Vec<[f32; 3]> = corners
            .iter()
            .enumerate()
            .map(|(k, &[x, y])| {
                // Alternate the box's depth so the six points span all of it.
                let z = if k % 2 == 0 { -1.0 } else { 1.0 };
                (center + Vec3::new(x, y, z) * layout.radius).to_array()
            })
            .collect();
        Mesh::new(
            PrimitiveTopology::TriangleList,
            RenderAssetUsages::RENDER_WORLD,
        )
        .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
        .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, vec![[0.0f32, 0.0, 1.0]; 6])
        .with_inserted_attribute(Mesh::ATTRIBUTE_UV_0, corners.to_vec())
        .with_inserted_indices(Indices::U16((0..6).collect()))
    }
}

/// Level 0 of atlas `atlas` from a Bevy image of `size` texels a side: RGBA floats, colour
/// linear (8- or 16-bit unorm colour decoded from sRGB where `srgb_bytes`).
fn atlas_level0(
    image: &Image,
    atlas: &'static str,
    size: u32,
    srgb_bytes: bool,
) -> Result<ImpostorImage, ImpostorMaterialError> {
    let bad = |problem: String| ImpostorMaterialError::Image { atlas, problem };
    let (width, height) = (image.width(), image.height());
    if (width, height) != (size, size) {
        return Err(bad(format!(
            "is {width} x {height} texels: the layout needs {size} x {size}"
        )));
    }
    let data = image.data.as_deref().ok_or_else(|| {
        bad("has no texels in main-world memory (its RenderAssetUsages lack MAIN_WORLD)".into())
    })?;
    let format = image.texture_descriptor.format;
    let texels = (size as usize).pow(2);
    let channel: fn(&[u8]) -> f32 = match format {
        TextureFormat::Rgba8UnormSrgb | TextureFormat::Rgba8Unorm => |b| f32::from(b[0]) / 255.0,
        TextureFormat::Rgba16Unorm => |b| f32::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0,
        TextureFormat::Rgba16Float => |b| half::f16::from_le_bytes([b[0], b[1]]).to_f32(),
        TextureFormat::Rgba32Float => |b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        other => {
            return Err(bad(format!(
                "has format {other:?}; read are RGBA8, RGBA16 unorm or float and RGBA32 float"
            )));
        }
    };
    let bytes = format.block_copy_size(None).unwrap_or(4) as usize / 4;
    if data.len() < texels * 4 * bytes {
        return Err(bad(format!(
            "holds {} bytes, fewer than {size} x {size} texels of {format:?}",
            data.len()
        )));
    }
    // PNG samples are sRGB at any depth; float images hold linear values.
    let decode = srgb_bytes
        && matches!(
            format,
            TextureFormat::Rgba8UnormSrgb | TextureFormat::Rgba8Unorm | TextureFormat::Rgba16Unorm
        );
    let texels = data[..texels * 4 * bytes]
        .chunks_exact(4 * bytes)
        .map(|texel| {
            let mut t = [0.0f32; 4];
            for (c, value) in t.iter_mut().enumerate() {
                let v = channel(&texel[c * bytes..]);
                *value = if decode && c < 3 {
                    srgb_to_linear(v)
                } else {
                    v
                };
            }
            t
        })
        .collect();
    Ok(ImpostorImage { size, texels })
}

/// The sRGB transfer function's inverse (IEC 61966-2-1).
fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.040_45 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// One atlas as a Bevy image: `levels` mip levels from `size` texels a side, `data` level
/// after level, sampled linearly with mipmaps, clamped to the edge.
fn atlas_image(size: u32, levels: u32, data: Vec<u8>, format: TextureFormat) -> Image {
    let mut image = Image::new_uninit(
        Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        format,
        RenderAssetUsages::RENDER_WORLD,
    );
    image.data = Some(data);
    image.data_order = TextureDataOrder::MipMajor;
    image.texture_descriptor.mip_level_count = levels;
    image.sampler = ImageSampler::Descriptor(ImageSamplerDescriptor {
        address_mode_u: ImageAddressMode::ClampToEdge,
        address_mode_v: ImageAddressMode::ClampToEdge,
        mag_filter: ImageFilterMode::Linear,
        min_filter: ImageFilterMode::Linear,
        mipmap_filter: ImageFilterMode::Linear,
        ..default()
    });
    image
}

impl Material for ImpostorMaterial {
    fn vertex_shader() -> ShaderRef {
        IMPOSTOR_SHADER.into()
    }

    fn fragment_shader() -> ShaderRef {
        IMPOSTOR_SHADER.into()
    }

    /// The shader discards what the atlas does not cover.
    fn alpha_mode(&self) -> AlphaMode {
        AlphaMode::Mask(0.5)
    }

    /// Bevy's prepass shaders know nothing of the card: not drawn there.
    fn enable_prepass() -> bool {
        false
    }

    /// Nor in shadow maps.
    fn enable_shadows() -> bool {
        false
    }

    /// Where it is drawn there all the same (a level of a frame-sequential group: the level
    /// material's extension decides), the card draws nothing.
    fn prepass_vertex_shader() -> ShaderRef {
        IMPOSTOR_PREPASS_SHADER.into()
    }

    /// As [`prepass_vertex_shader`](Self::prepass_vertex_shader).
    fn prepass_fragment_shader() -> ShaderRef {
        IMPOSTOR_PREPASS_SHADER.into()
    }
}

#[cfg(test)]
#[path = "impostor_tests.rs"]
mod tests;
