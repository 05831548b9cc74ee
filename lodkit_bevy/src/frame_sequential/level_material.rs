//! The materials the plugin derives from a level's plain material handle: a
//! [`FrameSequentialMaterial`] from a [`StandardMaterial`] (what a glTF scene or an app already
//! spawns; [`LevelMaterial::Standard`]), a [`FrameSequentialLevel<M>`] from a material of the
//! app's own ([`LevelMaterial::Custom`], with [`FrameSequentialMaterialPlugin`]), kept in step
//! with it; and the system that gives a group's drawers the material each frame draws.

use std::any::{Any, TypeId};
use std::hash::Hash;
use std::marker::PhantomData;

use bevy::asset::UntypedAssetId;
use bevy::ecs::world::EntityWorldMut;
use bevy::pbr::{ExtendedMaterial, MaterialExtension, MaterialPlugin};
use bevy::platform::collections::{HashMap, HashSet};
use bevy::prelude::*;
use bevy::render::render_resource::{AsBindGroup, Face};
use bevy::shader::ShaderRef;

use super::levels::{LevelMaterial, LodLevels};
use super::material::{FrameSequentialBindings, FrameSequentialMaterial};
use super::view::AlphaTest;

/// A material of the app's own as a level of a LOD group: `M` with [`FrameSequentialBindings`]
/// (the bindings `lodkit_bevy::frame_sequential_level::lod_level_color` reads, and the shader
/// def that turns it on). Derived by the plugin from `M`; see [`FrameSequentialMaterialPlugin`].
pub type FrameSequentialLevel<M> = ExtendedMaterial<M, FrameSequentialBindings>;

/// Lets levels use a material of the app's own, `M`: [`LevelMaterial::custom`] takes an
/// `M` handle as it is, as a `StandardMaterial` handle is taken ([`LevelMaterial`]), and
/// `AutoLod` takes an entity's `MeshMaterial3d<M>`.
///
/// `M`'s fragment shader (a WESL file) makes its output a level's with one call:
///
/// ```wgsl
/// import bevy_pbr::render::forward_io::VertexOutput;
/// import lodkit_bevy::frame_sequential_level::lod_level_color;
///
/// @fragment
/// fn fragment(in: VertexOutput) -> @location(0) vec4<f32> {
///     let color = ...; // the material's own shading
///     return lod_level_color(in, color);
/// }
/// ```
///
/// A material whose shading is costly may begin with `if !lod_level_kept(in) { discard; }` (same
/// module) so that what the dither drops is not shaded.
///
/// `lod_level_color` discards the fragments the screen-door dither drops and writes the
/// combine's id word in alpha; where `M` is drawn as itself (not a level) it returns `color`
/// unchanged, so one shader serves both. The plugin derives one [`FrameSequentialLevel<M>`] per
/// `M` asset a level names (`M` cloned, so textures are the same handles; the bindings of
/// [`FrameSequentialBindings`] at 100 and 101, which `M` must leave free, as any Bevy material
/// extension asks), follows the asset's changes, and reads `M::alpha_mode` to tell a blending
/// material (drawn with the screen-door dither) from an opaque or masked one (the combine). `M`
/// is taken to cull back faces, Bevy's default, for the levels' silhouettes; a material that
/// culls none still gets exact coverage, one that culls front faces gets the older-level depth
/// pass. The fragment shader must write alpha only through `lod_level_color`: an opaque
/// material's alpha is 1.
///
/// `cargo run --example custom_material` shows a material of its own through a transition.
pub struct FrameSequentialMaterialPlugin<M>(PhantomData<M>);

impl<M> Default for FrameSequentialMaterialPlugin<M> {
    fn default() -> Self {
        Self(PhantomData)
    }
}

impl<M: Material + Clone> Plugin for FrameSequentialMaterialPlugin<M>
where
    <FrameSequentialLevel<M> as AsBindGroup>::Data: PartialEq + Eq + Hash + Clone,
{
    /// Adding it for one `M` more than once is harmless (the first adds what it adds).
    fn is_unique(&self) -> bool {
        false
    }

    fn build(&self, app: &mut App) {
        if app.is_plugin_added::<MaterialPlugin<FrameSequentialLevel<M>>>() {
            return;
        }
        app.add_plugins(MaterialPlugin::<FrameSequentialLevel<M>>::default());
        add_level_material::<M, FrameSequentialBindings>(app);
    }
}

/// Registers `B` as a base of derived level materials `ExtendedMaterial<B, E>`: the
/// derivation, the drawers' material of that type, and `AutoLod`'s
/// taking of `MeshMaterial3d<B>`.
pub(super) fn add_level_material<B, E>(app: &mut App)
where
    B: Material + Clone,
    E: MaterialExtension + Default,
{
    app.init_resource::<DerivedMaterials>()
        .init_resource::<LevelMaterialTakers>();
    app.world_mut()
        .resource_mut::<DerivedMaterials>()
        .bases
        .insert(TypeId::of::<B>());
    if TypeId::of::<B>() != TypeId::of::<StandardMaterial>() {
        app.world_mut()
            .resource_mut::<LevelMaterialTakers>()
            .0
            .push(take_material::<B>);
    }
    app.add_systems(
        PostUpdate,
        (
            sync_derived_materials::<B, E>.in_set(DeriveMaterials),
            apply_drawer_materials::<ExtendedMaterial<B, E>>.in_set(ApplyDrawerMaterials),
        ),
    );
    // A drawer's material changes, and may change type, as its group's level does: Bevy must see
    // the change in the same frame (its check of the entities to specialize again runs after
    // the drawers' commands), or the render world binds the new material on the old type's
    // pipeline (wgpu validation fails where the two types differ) or specializes a frame late.
    app.configure_sets(
        PostUpdate,
        ApplyDrawerMaterials
            .before(bevy::pbr::check_entities_needing_specialization::<ExtendedMaterial<B, E>>),
    );
}

/// The systems that derive level materials: after the groups' drawers are spawned, before
/// the selection reads what the materials are.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) struct DeriveMaterials;

/// The systems that give the drawers the material the selection chose: after it.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) struct ApplyDrawerMaterials;

/// What a level's material is to the selection.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Looks {
    /// Whether it needs the screen-door dither: it blends with what lies behind it (no id word
    /// in its alpha), or it is an alpha mask whose test lodkit cannot repeat (a material type
    /// other than `StandardMaterial`), so the combine could not know its coverage.
    pub(super) blends: bool,
    /// Whether a multisampled camera's prepass keeps the same pixels of it as the main pass when
    /// the dither drops some: `StandardMaterial`'s prepass drops them too (`FrameSequentialExtension`), and so
    /// does Bevy's default prepass of a material of the app's own type with no prepass shader
    /// of its own (`FrameSequentialBindings`); a blending material is not in the prepass. A
    /// material's own prepass shader draws the level whole.
    pub(super) prepass_dithers: bool,
    /// The faces it culls.
    pub(super) cull_mode: Option<Face>,
    /// A masked `StandardMaterial`'s alpha test, which the older-level depth pass repeats.
    pub(super) alpha_test: Option<AlphaTest>,
}

/// The derived material of one source material: its handle (reserved until the source loads)
/// and what it is.
struct Derived {
    handle: UntypedHandle,
    looks: Option<Looks>,
}

/// The material derived from each plain material a level names, by the source's id, and the
/// material types with a [`FrameSequentialMaterialPlugin`] (or `StandardMaterial`).
#[derive(Resource, Default)]
pub(crate) struct DerivedMaterials {
    derived: HashMap<UntypedAssetId, Derived>,
    bases: HashSet<TypeId>,
}

impl DerivedMaterials {
    /// The material a level is drawn with (None: derived, but its source is not loaded yet, or
    /// not derived at all).
    pub(super) fn resolve(&self, material: &LevelMaterial) -> Option<UntypedHandle> {
        match material {
            LevelMaterial::FrameSequential(handle) => Some(handle.clone().untyped()),
            _ => self
                .derived
                .get(&material.source_id()?)
                .map(|d| d.handle.clone()),
        }
    }

    /// What a level's material is, once it is loaded.
    pub(super) fn looks(
        &self,
        material: &LevelMaterial,
        materials: &Assets<FrameSequentialMaterial>,
    ) -> Option<Looks> {
        match material {
            LevelMaterial::FrameSequential(handle) => {
                materials.get(handle).map(|m| looks_of(&m.base))
            }
            _ => self.derived.get(&material.source_id()?)?.looks.clone(),
        }
    }

    /// The type name of a level's material where no plugin derives from it.
    pub(super) fn unregistered(&self, material: &LevelMaterial) -> Option<&'static str> {
        match material {
            LevelMaterial::Custom { handle, type_name } => {
                (!self.bases.contains(&handle.type_id())).then_some(*type_name)
            }
            _ => None,
        }
    }
}

/// Whether `mode` blends the fragment with what lies behind it.
pub(super) fn blends(mode: AlphaMode) -> bool {
    !matches!(mode, AlphaMode::Opaque | AlphaMode::Mask(_))
}

/// What `material` is to the selection: `StandardMaterial` says its cull mode and alpha test;
/// any other material is taken to cull back faces (Bevy's default), and dithered if masked.
fn looks_of<B: Material>(material: &B) -> Looks {
    let mode = material.alpha_mode();
    match (material as &dyn Any).downcast_ref::<StandardMaterial>() {
        Some(standard) => Looks {
            blends: blends(mode),
            prepass_dithers: true,
            cull_mode: standard.cull_mode,
            alpha_test: AlphaTest::of(standard),
        },
        None => Looks {
            blends: blends(mode) || matches!(mode, AlphaMode::Mask(_)),
            prepass_dithers: blends(mode)
                || (matches!(B::prepass_vertex_shader(), ShaderRef::Default)
                    && matches!(B::prepass_fragment_shader(), ShaderRef::Default)),
            cull_mode: Some(Face::Back),
            alpha_test: None,
        },
    }
}

/// Derives a material for every `B` a new or changed [`LodLevels`] names, copies each changed
/// one into its derived material, and forgets those the app dropped.
pub(super) fn sync_derived_materials<B, E>(
    mut derived: ResMut<DerivedMaterials>,
    mut events: MessageReader<AssetEvent<B>>,
    bases: Res<Assets<B>>,
    mut materials: ResMut<Assets<ExtendedMaterial<B, E>>>,
    groups: Query<&LodLevels, Changed<LodLevels>>,
) where
    B: Material + Clone,
    E: MaterialExtension + Default,
{
    let derive = |base: &B| ExtendedMaterial {
        base: base.clone(),
        extension: E::default(),
    };
    for levels in &groups {
        for level in &levels.0 {
            let Some(source) = level.material.source_id() else {
                continue;
            };
            let Ok(id) = source.try_typed::<B>() else {
                continue;
            };
            if derived.derived.contains_key(&source) {
                continue;
            }
            // Not loaded yet: its `LoadedWithDependencies` (or `Added`) event derives it.
            let entry = match bases.get(id) {
                Some(base) => Derived {
                    handle: materials.add(derive(base)).untyped(),
                    looks: Some(looks_of(base)),
                },
                None => Derived {
                    handle: materials.reserve_handle().untyped(),
                    looks: None,
                },
            };
            derived.derived.insert(source, entry);
        }
    }
    for event in events.read() {
        match *event {
            AssetEvent::Added { id }
            | AssetEvent::Modified { id }
            | AssetEvent::LoadedWithDependencies { id } => {
                if let (Some(entry), Some(base)) =
                    (derived.derived.get_mut(&id.untyped()), bases.get(id))
                    && let Ok(handle) = entry.handle.clone().try_typed::<ExtendedMaterial<B, E>>()
                {
                    // A reserved handle gets its asset, a derived one the change.
                    let _ = materials.insert(handle.id(), derive(base));
                    entry.looks = Some(looks_of(base));
                }
            }
            AssetEvent::Removed { id } | AssetEvent::Unused { id } => {
                derived.derived.remove(&id.untyped());
            }
        }
    }
}

/// The material a group's drawer shows (set by the selection; None while hidden).
#[derive(Component, Clone, Debug, Default, PartialEq)]
pub(super) struct DrawerMaterial(pub(super) Option<UntypedHandle>);

/// The drawers whose [`DrawerMaterial`] changed, with their `MeshMaterial3d<T>`, if any.
type ChangedDrawers<'w, 's, T> = Query<
    'w,
    's,
    (
        Entity,
        &'static DrawerMaterial,
        Option<&'static mut MeshMaterial3d<T>>,
    ),
    Changed<DrawerMaterial>,
>;

/// Gives every drawer whose [`DrawerMaterial`] changed a `MeshMaterial3d<T>` where the handle
/// is a `T`, and takes it away where it is not (a drawer has one material component at a
/// time, or Bevy would draw it with each).
pub(super) fn apply_drawer_materials<T: Material>(
    mut commands: Commands,
    mut drawers: ChangedDrawers<T>,
) {
    for (entity, material, current) in &mut drawers {
        let wanted = material
            .0
            .as_ref()
            .and_then(|h| h.clone().try_typed::<T>().ok());
        match (wanted, current) {
            (Some(handle), Some(mut current)) => {
                if current.0 != handle {
                    current.0 = handle;
                }
            }
            (Some(handle), None) => {
                commands.entity(entity).insert(MeshMaterial3d(handle));
            }
            (None, Some(_)) => {
                commands.entity(entity).remove::<MeshMaterial3d<T>>();
            }
            (None, None) => {}
        }
    }
}

/// Takes an entity's own material as a level's: removes its `MeshMaterial3d<B>` and returns
/// the handle (None where it has none).
type TakeMaterial = fn(&mut EntityWorldMut) -> Option<LevelMaterial>;

/// For each material type levels may use, how to take an entity's `MeshMaterial3d` of it
/// (`AutoLod`): `StandardMaterial` first, then each type with a
/// [`FrameSequentialMaterialPlugin`].
#[derive(Resource)]
pub(crate) struct LevelMaterialTakers(pub(crate) Vec<TakeMaterial>);

impl Default for LevelMaterialTakers {
    fn default() -> Self {
        Self(vec![take_material::<StandardMaterial>])
    }
}

fn take_material<B: Material>(entity: &mut EntityWorldMut) -> Option<LevelMaterial> {
    let handle = entity.take::<MeshMaterial3d<B>>()?.0;
    Some(LevelMaterial::custom(handle))
}

impl LevelMaterialTakers {
    /// Takes `entity`'s material (the first type registered that it has).
    pub(crate) fn take(&self, entity: &mut EntityWorldMut) -> Option<LevelMaterial> {
        self.0.iter().find_map(|take| take(entity))
    }
}

#[cfg(test)]
#[path = "level_material_tests.rs"]
mod tests;
