//! glTF files with LOD levels (`MSFT_lod`, the files `lodkit lod` writes; Babylon.js's and
//! others') as frame-sequential LOD groups, loaded by Bevy's own glTF loader: adding
//! [`FrameSequentialLodPlugin`](crate::FrameSequentialLodPlugin) is all the code an app writes.
//!
//! Bevy's loader spawns a node's finest level only (the levels' nodes are named by the
//! extension alone). The plugin's glTF extension handler sees each node with `MSFT_lod`, and
//! puts on its entity a [`GltfLod`]: for every primitive of the node's mesh, the same primitive in
//! each level's mesh (with the level's material where it has another), and the switch
//! distances. When the scene is spawned, each primitive's entity becomes a
//! [`FrameSequentialGroup`] with those [`LodLevels`], its `StandardMaterial` used as it is
//! ([`LevelMaterial`]), its transform, its node's children
//! and its skin (`SkinnedMesh`, given to the entities that draw it) kept. A file without
//! `MSFT_lod` loads as before.
//!
//! The switch distances come from `MSFT_screencoverage` (the node's extras: one screen share per
//! level, below which the next level takes over, and below the last the object is hidden) as
//! `lodkit lod` defines it: the share of the viewport that the sphere of half the node's box
//! diagonal covers, `π R² / (4 aspect d²)` at view-normalized distance `d`, so
//! `d = R sqrt(π / (4 aspect c))`, with the aspect [`GLTF_COVERAGE_ASPECT`] (`lodkit lod`'s
//! default). The primitives of one node share them, so the object switches as a whole. A node
//! without coverages switches where its sphere's projected radius halves: level `i` from
//! `d = 2^i R` (a size rule, not a pixel-error bound: give the file coverages, as `lodkit lod`
//! does, for that).
//!
//! An impostor level (`lodkit lod --impostor`: a card node whose extras hold `lodkit_impostor`,
//! [`ImpostorGltfExtras`](lodkit::impostor::ImpostorGltfExtras), the last of the node's levels)
//! is drawn with an [`ImpostorMaterial`](crate::impostor::ImpostorMaterial) (the plugin adds
//! [`ImpostorPlugin`](crate::impostor::ImpostorPlugin)): its two atlas images, as Bevy's loader
//! read them, get their mip chains (`ImpostorMaterial::from_level0_images`) once per atlas, and
//! the card is [`ImpostorMaterial::card_mesh`](crate::impostor::ImpostorMaterial::card_mesh) of
//! the layout, not the file's quad (which shows the object's front from every side). The
//! impostor is the whole mesh's picture: it is the last level of the group of the node's first
//! primitive (the first that has an entity with a `StandardMaterial`), and the groups of its other primitives end in a level that draws nothing, with the
//! same material and distances, so the object enters its impostor as a whole (every group of
//! it mixes material types, so every transition of the object blends with the screen-door
//! dither). A node whose atlas images are files of their own waits for them (its finest level
//! shown meanwhile). An impostor that cannot be drawn (extras that do not read, images that did
//! not load or are not an atlas of the layout, primitives turned by Bevy's
//! `GltfConvertCoordinates::rotate_meshes`) is left out with a warning naming the node and why,
//! and the last mesh level is shown in its place, up to where the node is hidden.

use bevy::asset::LoadContext;
use bevy::gltf::extensions::{
    ErasedGltfExtensionHandler, GltfExtensionHandler, GltfExtensionHandlers,
};
use bevy::gltf::gltf;
use bevy::log::warn;
use bevy::prelude::*;
use lodkit::select::LodGroup;

use crate::frame_sequential::levels::{
    FrameSequentialGroup, FrameSequentialSystems, LevelMaterial, LodLevel, LodLevels,
};

mod impostor;

pub use impostor::GltfLodImpostor;

/// The viewport aspect (width / height) a file's `MSFT_screencoverage` is read with: `lodkit
/// lod`'s default `--aspect`, 16:9.
pub const GLTF_COVERAGE_ASPECT: f32 = 16.0 / 9.0;

/// A glTF node's LOD levels, put on its entity by the glTF loader (with the plugin) and turned
/// into [`FrameSequentialGroup`]s, one per primitive, when the scene is spawned.
#[derive(Component, Reflect, Clone, Debug, Default, PartialEq)]
#[reflect(Component, Default, Clone)]
pub struct GltfLod {
    /// Per primitive of the node's own (finest) mesh: that primitive in every level.
    pub primitives: Vec<GltfLodPrimitive>,
    /// The view-normalized distance from which each level is shown, the finest's 0 first.
    pub distances: Vec<f32>,
    /// Beyond this view-normalized distance nothing is shown (the last coverage).
    pub max_distance: Option<f32>,
    /// The impostor that ends the levels, where the file has one (its switch distance is the
    /// last of [`distances`](Self::distances)).
    pub impostor: Option<GltfLodImpostor>,
}

/// One primitive of a node with LOD levels: [`GltfLod::primitives`].
#[derive(Reflect, Clone, Debug, Default, PartialEq)]
#[reflect(Default, Clone)]
pub struct GltfLodPrimitive {
    /// The primitive's mesh in the finest level (the one Bevy spawns).
    pub mesh: Handle<Mesh>,
    /// The same primitive in each coarser level.
    pub levels: Vec<GltfLodLevel>,
}

/// A primitive in one coarser level: [`GltfLodPrimitive::levels`].
#[derive(Reflect, Clone, Debug, Default, PartialEq)]
#[reflect(Default, Clone)]
pub struct GltfLodLevel {
    /// The level's mesh of the primitive.
    pub mesh: Handle<Mesh>,
    /// The level's material where it is not the finest level's (None: the primitive entity's
    /// own).
    pub material: Option<Handle<StandardMaterial>>,
}

/// Registers the glTF extension handler and the system that makes groups of the nodes it marks.
pub(crate) fn build(app: &mut App) {
    app.register_type::<GltfLod>()
        .register_type::<GltfLodPrimitive>()
        .register_type::<GltfLodLevel>()
        .register_type::<Vec<GltfLodPrimitive>>()
        .register_type::<Vec<GltfLodLevel>>()
        .register_type::<GltfLodImpostor>()
        .register_type::<Option<GltfLodImpostor>>()
        .register_type::<Option<Handle<StandardMaterial>>>()
        .register_type::<Option<f32>>()
        .register_type::<Vec<f32>>();
    app.world_mut()
        .get_resource_or_init::<GltfExtensionHandlers>()
        .0
        .write_blocking()
        .push(Box::new(MsftLod::default()));
    app.init_resource::<impostor::GltfImpostors>();
    app.add_systems(PostUpdate, spawn_gltf_groups.before(FrameSequentialSystems));
}

/// What the handler keeps of the document while it loads (one clone per load).
#[derive(Clone, Default)]
struct MsftLod {
    /// Per node: its mesh's index and each primitive's material index.
    nodes: Vec<Option<(usize, Vec<Option<usize>>)>>,
    /// Per node: None where it is no impostor's card (`lodkit lod --impostor`: its extras hold
    /// `lodkit_impostor`), else what its extras say.
    impostors: Vec<Option<Result<lodkit::impostor::ImpostorGltfExtras, String>>>,
    /// Per image: the first texture that shows it.
    image_textures: Vec<Option<usize>>,
    /// Per texture: the image Bevy's loader made of it (`on_texture`).
    texture_handles: Vec<Option<Handle<Image>>>,
}

impl GltfExtensionHandler for MsftLod {
    fn dyn_clone(&self) -> Box<dyn ErasedGltfExtensionHandler> {
        Box::new(self.clone())
    }

    fn on_root(
        &mut self,
        _load_context: &mut LoadContext<'_>,
        gltf: &gltf::Gltf,
        _settings: &bevy::gltf::GltfLoaderSettings,
    ) {
        self.nodes = gltf
            .nodes()
            .map(|node| {
                node.mesh().map(|mesh| {
                    let materials = mesh.primitives().map(|p| p.material().index()).collect();
                    (mesh.index(), materials)
                })
            })
            .collect();
        self.impostors = impostor::impostor_nodes(gltf);
        self.image_textures = impostor::image_textures(gltf);
        self.texture_handles = vec![None; gltf.textures().len()];
    }

    fn on_texture(&mut self, gltf_texture: &gltf::Texture, texture: Handle<Image>) {
        if let Some(slot) = self.texture_handles.get_mut(gltf_texture.index()) {
            *slot = Some(texture);
        }
    }

    fn on_gltf_node(
        &mut self,
        load_context: &mut LoadContext<'_>,
        gltf_node: &gltf::Node,
        entity: &mut EntityWorldMut,
    ) {
        let Some(lod) = gltf_node.extension_value("MSFT_lod") else {
            return;
        };
        let path = load_context.path().to_string();
        let name = gltf_node.name().map_or_else(
            || format!("node {}", gltf_node.index()),
            |n| format!("node {n:?}"),
        );
        match self.levels(load_context, gltf_node, lod, &name) {
            Ok(levels) => {
                entity.insert(levels);
            }
            Err(why) => {
                warn!("{path}: {name}: MSFT_lod ignored (the finest level is shown): {why}")
            }
        }
    }
}

impl MsftLod {
    /// The [`GltfLod`] of `node` (`name` in warnings), whose `MSFT_lod` extension is `lod`.
    fn levels(
        &mut self,
        load_context: &mut LoadContext<'_>,
        node: &gltf::Node,
        lod: &gltf::json::Value,
        name: &str,
    ) -> Result<GltfLod, String> {
        let mesh = node.mesh().ok_or("the node has no mesh")?;
        let ids = lod
            .get("ids")
            .and_then(|ids| ids.as_array())
            .ok_or("no \"ids\" array")?;
        let mut level_nodes = Vec::new();
        let mut impostor_node = None;
        for (k, id) in ids.iter().enumerate() {
            let id = id
                .as_u64()
                .and_then(|i| usize::try_from(i).ok())
                .ok_or_else(|| format!("id {id} is not a node index"))?;
            if let Some(Some(extras)) = self.impostors.get(id) {
                if k + 1 < ids.len() {
                    return Err(format!("impostor level node {id} is not the last level"));
                }
                impostor_node = Some((id, extras.clone()));
                continue;
            }
            match self.nodes.get(id) {
                Some(Some(info)) => level_nodes.push(info.clone()),
                Some(None) => return Err(format!("level node {id} has no mesh")),
                None => return Err(format!("level node {id} does not exist")),
            }
        }
        // The sphere `lodkit lod` measures coverage with: half the diagonal of the box of every
        // primitive of the finest mesh.
        // (The accessor's min and max, which glTF requires of positions; read here, not with
        // the gltf crate's `bounding_box`, which panics where a file lacks them.)
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for p in mesh.primitives() {
            let positions = p
                .get(&gltf::Semantic::Positions)
                .ok_or_else(|| format!("primitive {} has no positions", p.index()))?;
            let corner = |v: Option<gltf::json::Value>| -> Option<Vec3> {
                let v: Vec<f32> = gltf::json::deserialize::from_value(v?).ok()?;
                (v.len() == 3).then(|| Vec3::new(v[0], v[1], v[2]))
            };
            let (Some(min), Some(max)) = (corner(positions.min()), corner(positions.max())) else {
                return Err(format!(
                    "primitive {}'s positions have no min and max (glTF requires them)",
                    p.index()
                ));
            };
            lo = lo.min(min);
            hi = hi.max(max);
        }
        let radius = 0.5 * lo.distance(hi);
        if !(radius.is_finite() && radius > 0.0) {
            return Err(format!("the mesh's box has no size (radius {radius})"));
        }
        let mut coverage = screen_coverage(node)?;
        let mut impostor = None;
        if let Some((id, extras)) = impostor_node {
            let read = extras.and_then(|x| {
                impostor::gltf_impostor(&x, &self.image_textures, &self.texture_handles)
            });
            match read {
                Ok(i) => impostor = Some(i),
                Err(why) => {
                    // The last mesh level is shown up to where the node is hidden (the
                    // impostor's switch coverage goes).
                    without_last_level(coverage.as_mut(), ids.len())?;
                    warn!(
                        "{}: {name}: impostor level (node {id}) left out ({why}); the last \
                         mesh level is shown up to where the node is hidden",
                        load_context.path()
                    );
                }
            }
        }
        let coarser = level_nodes.len() + usize::from(impostor.is_some());
        let (distances, max_distance) = switch_distances(radius, coverage.as_deref(), coarser)?;
        let primitives = mesh
            .primitives()
            .map(|p| {
                let own = p.material().index();
                GltfLodPrimitive {
                    mesh: load_context.get_label_handle(format!(
                        "Mesh{}/Primitive{}",
                        mesh.index(),
                        p.index()
                    )),
                    levels: level_nodes
                        .iter()
                        .map(|(m, materials)| {
                            // The same primitive, or the level's last where it has fewer.
                            let k = p.index().min(materials.len().saturating_sub(1));
                            let material = materials.get(k).copied().flatten();
                            let level_mesh =
                                load_context.get_label_handle(format!("Mesh{m}/Primitive{k}"));
                            let material = (material != own)
                                .then_some(material)
                                .flatten()
                                .map(|i| load_context.get_label_handle(format!("Material{i}/std")));
                            GltfLodLevel {
                                mesh: level_mesh,
                                material,
                            }
                        })
                        .collect(),
                }
            })
            .collect();
        Ok(GltfLod {
            primitives,
            distances,
            max_distance,
            impostor,
        })
    }
}

/// Takes the last of `coarser` levels' coverage out of `coverage` (one per level from the
/// finest, below which the next takes over, and where present the hide coverage last): the
/// level before it is then shown up to the hide coverage. Too few coverages is an error that
/// counts every level.
fn without_last_level(coverage: Option<&mut Vec<f32>>, coarser: usize) -> Result<(), String> {
    if let Some(c) = coverage
        && coarser > 0
    {
        if c.len() < coarser {
            return Err(format!(
                "MSFT_screencoverage has {} values for {} levels",
                c.len(),
                coarser + 1
            ));
        }
        c.remove(coarser - 1);
    }
    Ok(())
}

/// The node's `MSFT_screencoverage` (its extras), None where it has none.
fn screen_coverage(node: &gltf::Node) -> Result<Option<Vec<f32>>, String> {
    let Some(extras) = node.extras() else {
        return Ok(None);
    };
    let value: gltf::json::Value =
        gltf::json::deserialize::from_str(extras.get()).map_err(|e| format!("extras: {e}"))?;
    let Some(list) = value.get("MSFT_screencoverage") else {
        return Ok(None);
    };
    let list = list
        .as_array()
        .ok_or("MSFT_screencoverage is not an array")?;
    list.iter()
        .map(|c| {
            c.as_f64()
                .map(|c| c as f32)
                .ok_or_else(|| format!("MSFT_screencoverage holds {c}, not a number"))
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Some)
}

/// The view-normalized distances from which each of `1 + coarser` levels is shown and the
/// distance beyond which none is, for a sphere of `radius` with `coverage` (see the module
/// docs).
pub fn switch_distances(
    radius: f32,
    coverage: Option<&[f32]>,
    coarser: usize,
) -> Result<(Vec<f32>, Option<f32>), String> {
    let Some(coverage) = coverage else {
        let distances = (0..=coarser)
            .map(|i| {
                if i == 0 {
                    0.0
                } else {
                    radius * (1u64 << i.min(60)) as f32
                }
            })
            .collect();
        return Ok((distances, None));
    };
    if coverage.len() < coarser {
        return Err(format!(
            "MSFT_screencoverage has {} values for {} levels",
            coverage.len(),
            coarser + 1
        ));
    }
    let distance = |c: f32| -> Result<f32, String> {
        if !(c.is_finite() && c > 0.0) {
            return Err(format!("screen coverage {c} is not a positive number"));
        }
        Ok(radius * (std::f32::consts::PI / (4.0 * GLTF_COVERAGE_ASPECT * c)).sqrt())
    };
    let mut distances = vec![0.0];
    for &c in &coverage[..coarser] {
        distances.push(distance(c)?);
    }
    let max_distance = coverage.get(coarser).map(|&c| distance(c)).transpose()?;
    Ok((distances, max_distance))
}

/// The group of `distances` hidden beyond `max` (where given).
fn lod_group(distances: &[f32], max: Option<f32>) -> Result<LodGroup, String> {
    let group = LodGroup::from_distances(distances).map_err(|e| e.to_string())?;
    match max {
        Some(max) => group.with_max_distance(max).map_err(|e| e.to_string()),
        None => Ok(group),
    }
}

/// Turns the primitive entities of each node the loader marked into LOD groups: where the node
/// has an impostor, the first primitive's group ends in it and the others' in a level that
/// draws nothing, at the same distance.
fn spawn_gltf_groups(
    mut commands: Commands,
    nodes: Query<(Entity, &GltfLod, &Children, Option<&Name>), Without<GltfLodSpawned>>,
    primitives: Query<(&Mesh3d, &MeshMaterial3d<StandardMaterial>, &Transform)>,
    mut impostors: impostor::ImpostorAssets,
) {
    for (node, lod, children, name) in &nodes {
        let name = name.map_or_else(|| format!("{node}"), |n| format!("{n:?} ({node})"));
        // An atlas in files of its own may still be loading: the node waits for it (its
        // finest level shown meanwhile).
        if lod.impostor.as_ref().is_some_and(|i| impostors.loading(i)) {
            continue;
        }
        commands.entity(node).insert(GltfLodSpawned);
        let Some(mesh_levels) = lod
            .distances
            .len()
            .checked_sub(usize::from(lod.impostor.is_some()))
            .filter(|&n| n > 0)
        else {
            warn!("glTF node {name}: MSFT_lod ignored: no switch distance for its finest level");
            continue;
        };
        // The card is placed in the primitive's space, which Bevy's coordinate conversion
        // (`GltfConvertCoordinates::rotate_meshes`) turns by the child's transform.
        let turned = children
            .iter()
            .filter_map(|c| primitives.get(c).ok())
            .any(|(_, _, t)| *t != Transform::IDENTITY);
        let drawn = lod.impostor.as_ref().and_then(|i| {
            let made = match turned {
                true => Err(
                    "the primitives' entities are transformed (GltfConvertCoordinates \
                             rotate_meshes): an impostor is drawn in the file's space only"
                        .to_owned(),
                ),
                false => impostors.draw(i),
            };
            made.inspect_err(|why| {
                warn!(
                    "glTF node {name}: impostor level left out ({why}); the last mesh level is \
                     shown up to where the node is hidden"
                )
            })
            .ok()
        });
        let distances = match &drawn {
            Some(_) => &lod.distances[..],
            None => &lod.distances[..mesh_levels],
        };
        let group = match lod_group(distances, lod.max_distance) {
            Ok(group) => group,
            Err(e) => {
                warn!(
                    "glTF node {name}: MSFT_lod ignored: the switch distances {distances:?} and \
                     max distance {:?}: {e}",
                    lod.max_distance
                );
                continue;
            }
        };
        let mut card_taken = false;
        for &child in children {
            let Ok((mesh, material, _)) = primitives.get(child) else {
                continue;
            };
            let Some(primitive) = lod.primitives.iter().find(|p| p.mesh == mesh.0) else {
                continue;
            };
            let mut levels = vec![LodLevel::new(mesh.0.clone(), material.0.clone())];
            levels.extend(primitive.levels.iter().map(|level| {
                let material = level.material.clone().unwrap_or_else(|| material.0.clone());
                LodLevel::new(level.mesh.clone(), material)
            }));
            if let Some(draw) = &drawn {
                // The first primitive shows the impostor; the others' last level draws nothing,
                // with the impostor's material, so every group of the object takes the same
                // way through each transition (one that mixes material types blends with the
                // screen-door dither).
                let mesh = match std::mem::replace(&mut card_taken, true) {
                    false => draw.card.clone(),
                    true => draw.nothing.clone(),
                };
                levels.push(LodLevel::new(
                    mesh,
                    LevelMaterial::custom(draw.material.clone()),
                ));
            }
            commands
                .entity(child)
                .remove::<(Mesh3d, MeshMaterial3d<StandardMaterial>)>()
                .insert((LodLevels(levels), FrameSequentialGroup::new(group.clone())));
        }
    }
}

/// Marks a node whose primitives [`spawn_gltf_groups`] made groups of (or left as they are).
#[derive(Component)]
struct GltfLodSpawned;

#[cfg(test)]
mod tests {
    use crate::gltf_lod::*;

    /// An impostor level left out: the last mesh level takes its place up to the hide coverage;
    /// without a hide coverage, up to any distance.
    #[test]
    fn a_left_out_last_level_gives_its_range_to_the_level_before() {
        let mut with_hide = vec![0.5, 0.1, 0.02, 0.004, 0.001];
        without_last_level(Some(&mut with_hide), 4).unwrap();
        assert_eq!(with_hide, [0.5, 0.1, 0.02, 0.001]);
        let (d, max) = switch_distances(1.0, Some(&with_hide), 3).unwrap();
        assert_eq!(d.len(), 4);
        let hide = (std::f32::consts::PI / (4.0 * GLTF_COVERAGE_ASPECT * 0.001)).sqrt();
        assert!((max.unwrap() - hide).abs() <= 1e-5 * hide);
        let mut without_hide = vec![0.5, 0.1, 0.02, 0.004];
        without_last_level(Some(&mut without_hide), 4).unwrap();
        assert_eq!(without_hide, [0.5, 0.1, 0.02]);
        assert_eq!(
            switch_distances(1.0, Some(&without_hide), 3).unwrap().1,
            None
        );
        without_last_level(None, 4).unwrap();
        let mut short = vec![0.5, 0.1];
        let e = without_last_level(Some(&mut short), 4).unwrap_err();
        assert!(e.contains("2 values for 5 levels"), "{e}");
    }

    #[test]
    fn coverages_give_the_distances_lodkit_lod_wrote_them_from() {
        // lodkit lod: c = π R² / (4 aspect d²) at the next level's distance.
        let radius = 1.5;
        let written = [3.0f32, 7.5, 20.0];
        let coverage: Vec<f32> = written
            .iter()
            .map(|d| std::f32::consts::PI * radius * radius / (4.0 * GLTF_COVERAGE_ASPECT * d * d))
            .collect();
        let (distances, max) = switch_distances(radius, Some(&coverage), 2).unwrap();
        assert_eq!(distances.len(), 3);
        assert_eq!(distances[0], 0.0);
        for (d, w) in distances[1..].iter().chain(max.iter()).zip(written) {
            assert!((d - w).abs() <= 1e-5 * w, "{d} vs {w}");
        }
    }

    #[test]
    fn bad_coverages_are_named_and_missing_ones_fall_back_to_size() {
        assert!(
            switch_distances(1.0, Some(&[0.5]), 2)
                .unwrap_err()
                .contains("1 values for 3 levels")
        );
        assert!(
            switch_distances(1.0, Some(&[0.5, -1.0]), 2)
                .unwrap_err()
                .contains("-1")
        );
        assert!(switch_distances(1.0, Some(&[f32::NAN, 0.1]), 2).is_err());
        assert_eq!(
            switch_distances(2.0, None, 2).unwrap(),
            (vec![0.0, 4.0, 8.0], None)
        );
    }
}
