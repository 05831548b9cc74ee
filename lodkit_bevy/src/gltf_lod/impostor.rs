//! A node's impostor level (`lodkit lod --impostor`): read from the card node's extras
//! ([`ImpostorGltfExtras`]) while the file loads, drawn with an [`ImpostorMaterial`] built once
//! per atlas and layout when the scene is spawned.

use bevy::gltf::gltf;
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use lodkit::impostor::{
    IMPOSTOR_GLTF_EXTRAS_KEY, ImpostorGltfExtras, ImpostorLayout, ImpostorShape,
};

use crate::impostor::ImpostorMaterial;

/// The impostor that ends a node's levels ([`GltfLod::impostor`](super::GltfLod::impostor)):
/// its layout and the two atlas images (level 0, as Bevy's loader read them).
#[derive(Reflect, Clone, Debug, Default, PartialEq)]
#[reflect(Default, Clone)]
pub struct GltfLodImpostor {
    /// Frames per side.
    pub frames: u32,
    /// Texels per side of one frame.
    pub frame_size: u32,
    /// The upper hemisphere of directions (else the whole sphere).
    pub hemi: bool,
    /// The bounding sphere's centre, in the finest mesh's space.
    pub center: Vec3,
    /// The bounding sphere's radius.
    pub radius: f32,
    /// The colour atlas.
    pub color: Handle<Image>,
    /// The normal and depth atlas.
    pub normal_depth: Handle<Image>,
}

impl GltfLodImpostor {
    /// The layout lodkit draws.
    pub fn layout(&self) -> ImpostorLayout {
        ImpostorLayout {
            frames: self.frames,
            frame_size: self.frame_size,
            shape: if self.hemi {
                ImpostorShape::Hemi
            } else {
                ImpostorShape::Full
            },
            center: self.center.to_array(),
            radius: self.radius,
        }
    }
}

/// Per node of `gltf`: None where it is no impostor's card, else its extras read (or why they
/// cannot be).
pub(super) fn impostor_nodes(gltf: &gltf::Gltf) -> Vec<Option<Result<ImpostorGltfExtras, String>>> {
    gltf.nodes()
        .map(|node| {
            let extras = node.extras().as_ref()?;
            let value: gltf::json::Value = gltf::json::deserialize::from_str(extras.get()).ok()?;
            let fields = value.get(IMPOSTOR_GLTF_EXTRAS_KEY)?;
            Some(
                gltf::json::deserialize::from_value::<ImpostorGltfExtras>(fields.clone())
                    .map_err(|e| format!("extras.{IMPOSTOR_GLTF_EXTRAS_KEY}: {e}"))
                    .and_then(|x| x.layout().map(|_| x).map_err(|e| e.to_string())),
            )
        })
        .collect()
}

/// Per image of `gltf`, the first texture that shows it.
pub(super) fn image_textures(gltf: &gltf::Gltf) -> Vec<Option<usize>> {
    let mut out = vec![None; gltf.images().len()];
    for texture in gltf.textures() {
        if let Some(slot) = out.get_mut(texture.source().index()) {
            slot.get_or_insert(texture.index());
        }
    }
    out
}

/// The impostor of extras `x`, its images' handles those Bevy's loader gave each texture
/// (`handles`, by texture index: labelled images of the file, or images of their own files
/// loaded by path), `textures` from [`image_textures`].
pub(super) fn gltf_impostor(
    x: &ImpostorGltfExtras,
    textures: &[Option<usize>],
    handles: &[Option<Handle<Image>>],
) -> Result<GltfLodImpostor, String> {
    let texture = |image: usize, name: &str| {
        let t = textures
            .get(image)
            .ok_or_else(|| format!("its {name} image {image} does not exist"))?
            .ok_or_else(|| {
                format!("its {name} image {image} has no texture (Bevy loads textures)")
            })?;
        handles
            .get(t)
            .cloned()
            .flatten()
            .ok_or_else(|| format!("Bevy's loader did not load texture {t} (its {name} atlas)"))
    };
    Ok(GltfLodImpostor {
        frames: x.frames,
        frame_size: x.frame_size,
        hemi: x.shape.is_hemi(),
        center: Vec3::from_array(x.center),
        radius: x.radius,
        color: texture(x.color_image, "colour")?,
        normal_depth: texture(x.normal_depth_image, "normal and depth")?,
    })
}

/// What draws a node's impostor level: the card and material for the node's first primitive,
/// and for its other primitives a mesh that draws nothing with the same material (one triangle of
/// no area), so that their groups leave at the impostor's switch exactly as the first's enters it
/// (same distances and materials, same transition: where the dither drops the first's last mesh
/// level the impostor shows, and the others' last levels are dropped at the same pixels).
#[derive(Clone)]
pub(super) struct ImpostorDraw {
    pub card: Handle<Mesh>,
    pub material: Handle<ImpostorMaterial>,
    pub nothing: Handle<Mesh>,
}

/// What a drawn impostor is built from: its two images and its layout's fields (as bits).
type ImpostorKey = (AssetId<Image>, AssetId<Image>, [u32; 8]);

/// The [`ImpostorDraw`] of each impostor the spawned scenes draw, built once per atlas and layout
/// (every spawn of a file shares it); an entry goes when its colour image is unloaded (looked at
/// when another impostor is spawned).
#[derive(Resource, Default)]
pub(super) struct GltfImpostors(HashMap<ImpostorKey, Result<ImpostorDraw, String>>);

impl GltfImpostors {
    /// The draw of `impostor`, built on first use; an error says why it cannot be drawn (its
    /// images not loaded, or not an atlas of its layout).
    pub(super) fn get(
        &mut self,
        impostor: &GltfLodImpostor,
        images: &mut Assets<Image>,
        meshes: &mut Assets<Mesh>,
        materials: &mut Assets<ImpostorMaterial>,
    ) -> Result<ImpostorDraw, String> {
        self.0.retain(|(color, _, _), _| images.contains(*color));
        let c = impostor.center;
        let layout_bits = [
            impostor.frames,
            impostor.frame_size,
            u32::from(impostor.hemi),
            c.x.to_bits(),
            c.y.to_bits(),
            c.z.to_bits(),
            impostor.radius.to_bits(),
            0,
        ];
        let key = (impostor.color.id(), impostor.normal_depth.id(), layout_bits);
        if let Some(made) = self.0.get(&key) {
            return made.clone();
        }
        let (Some(color), Some(normal_depth)) = (
            images.get(&impostor.color),
            images.get(&impostor.normal_depth),
        ) else {
            return Err("its atlas images did not load".into());
        };
        let layout = impostor.layout();
        let made = ImpostorMaterial::atlas_of_images(layout, color, normal_depth)
            .and_then(|atlas| ImpostorMaterial::new(&atlas, images))
            .map(|material| ImpostorDraw {
                card: meshes.add(ImpostorMaterial::card_mesh(&layout)),
                material: materials.add(material),
                nothing: meshes.add(nothing_mesh(impostor.center)),
            })
            .map_err(|e| e.to_string());
        self.0.insert(key, made.clone());
        made
    }
}

/// One triangle of no area at `at`, drawn with the impostor's material: its shader places the
/// card's corners by `UV_0`, all (0, 0) here, so no fragment is drawn. Normals for Bevy's
/// pipelines that ask for them.
fn nothing_mesh(at: Vec3) -> Mesh {
    Mesh::new(
        bevy::mesh::PrimitiveTopology::TriangleList,
        bevy::asset::RenderAssetUsages::all(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, vec![at.to_array(); 3])
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, vec![[0.0f32, 1.0, 0.0]; 3])
    .with_inserted_attribute(Mesh::ATTRIBUTE_UV_0, vec![[0.0f32, 0.0]; 3])
    .with_inserted_indices(bevy::mesh::Indices::U16(vec![0, 1, 2]))
}

/// What [`spawn_gltf_groups`](super::spawn_gltf_groups) needs to draw impostors.
#[derive(bevy::ecs::system::SystemParam)]
pub(super) struct ImpostorAssets<'w> {
    cache: ResMut<'w, GltfImpostors>,
    images: ResMut<'w, Assets<Image>>,
    meshes: ResMut<'w, Assets<Mesh>>,
    materials: ResMut<'w, Assets<ImpostorMaterial>>,
    server: Res<'w, AssetServer>,
}

impl ImpostorAssets<'_> {
    /// Whether an atlas image of `impostor` is still loading (a file of its own).
    pub(super) fn loading(&self, impostor: &GltfLodImpostor) -> bool {
        [&impostor.color, &impostor.normal_depth]
            .iter()
            .any(|h| !self.images.contains(h.id()) && self.server.load_state(h.id()).is_loading())
    }

    /// The draw of `impostor` ([`GltfImpostors::get`]).
    pub(super) fn draw(&mut self, impostor: &GltfLodImpostor) -> Result<ImpostorDraw, String> {
        self.cache.get(
            impostor,
            &mut self.images,
            &mut self.meshes,
            &mut self.materials,
        )
    }
}
