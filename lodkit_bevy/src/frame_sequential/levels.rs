//! What a LOD group is made of: the [`FrameSequentialGroup`] component, its [`LodLevels`], and
//! each level's mesh and [`LevelMaterial`].

use bevy::asset::UntypedAssetId;
use bevy::prelude::*;
use lodkit::select::LodGroup;

use super::material::FrameSequentialMaterial;

/// The plugin's main-world systems in `PostUpdate` that give each [`FrameSequentialGroup`] its
/// drawers and select what they draw. A system that makes groups (inserts [`LodLevels`] and a
/// [`FrameSequentialGroup`], removing the entity's `Mesh3d`) runs `.before(FrameSequentialSystems)`
/// so the object is drawn in the same frame, as [`AutoLod`](crate::auto_lod::AutoLod) and the
/// glTF loader's groups do.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FrameSequentialSystems;

/// The material a level is drawn with: [`LodLevel::material`].
///
/// A [`StandardMaterial`] handle is used as it is: the plugin derives one
/// [`FrameSequentialMaterial`] per `StandardMaterial` (its `base` a clone of it, so every texture
/// is the same `Handle<Image>`, shared, not copied; the extension's defaults), shared by every
/// level that names it, and copies the `StandardMaterial` into it again whenever it changes
/// (`AssetEvent::Modified`), so an app keeps editing its own material. `From` makes either handle
/// a `LevelMaterial`:
///
/// ```
/// use bevy::prelude::*;
/// use lodkit_bevy::frame_sequential::LodLevel;
///
/// fn level(meshes: &mut Assets<Mesh>, materials: &mut Assets<StandardMaterial>) -> LodLevel {
///     let mesh = meshes.add(Sphere::new(1.0).mesh().ico(3).unwrap());
///     LodLevel::new(mesh, materials.add(Color::srgb(0.8, 0.5, 0.2)))
/// }
/// # let _ = level;
/// ```
///
/// A material of the app's own type `M` takes part the same way through
/// [`LevelMaterial::custom`] and [`FrameSequentialMaterialPlugin::<M>`](super::FrameSequentialMaterialPlugin),
/// its fragment shader ending with one call to `lod_level_color`.
///
/// Opaque and alpha-mask (`AlphaMode::Mask`) materials take part in the combine; a masked
/// `StandardMaterial`'s coverage is its leaves, not its cards (the older-level depth pass
/// repeats its alpha test). A material that blends (`Blend`, `Premultiplied`, `Add`,
/// `Multiply`, `AlphaToCoverage`) cannot carry the combine's id word in its alpha, and a masked
/// material of another type has an alpha test lodkit cannot repeat: a group with such a level
/// is drawn with the complementary screen-door dither instead (both levels each frame,
/// disjoint pixels), with one warning.
#[derive(Clone, Debug, PartialEq)]
pub enum LevelMaterial {
    /// A material of the app's, used as it is (see above).
    Standard(Handle<StandardMaterial>),
    /// A material made for frame-sequential LOD.
    FrameSequential(Handle<FrameSequentialMaterial>),
    /// A material of the app's own type, used as it is: [`LevelMaterial::custom`].
    Custom {
        /// The app's material handle.
        handle: UntypedHandle,
        /// Its type's name, for warnings.
        type_name: &'static str,
    },
}

impl From<Handle<StandardMaterial>> for LevelMaterial {
    fn from(handle: Handle<StandardMaterial>) -> Self {
        Self::Standard(handle)
    }
}

impl From<Handle<FrameSequentialMaterial>> for LevelMaterial {
    fn from(handle: Handle<FrameSequentialMaterial>) -> Self {
        Self::FrameSequential(handle)
    }
}

impl LevelMaterial {
    /// A level material of the app's own material handle, of any type with a
    /// [`FrameSequentialMaterialPlugin`](super::FrameSequentialMaterialPlugin) (a
    /// `StandardMaterial` handle gives [`LevelMaterial::Standard`], a
    /// [`FrameSequentialMaterial`] one [`LevelMaterial::FrameSequential`]).
    pub fn custom<M: Material>(handle: Handle<M>) -> Self {
        let handle = handle.untyped();
        if let Ok(standard) = handle.clone().try_typed::<StandardMaterial>() {
            return Self::Standard(standard);
        }
        if let Ok(made) = handle.clone().try_typed::<FrameSequentialMaterial>() {
            return Self::FrameSequential(made);
        }
        Self::Custom {
            handle,
            type_name: std::any::type_name::<M>(),
        }
    }

    /// The app's material the plugin derives the drawn one from (None for a
    /// [`FrameSequentialMaterial`], drawn as it is).
    pub(super) fn source_id(&self) -> Option<UntypedAssetId> {
        match self {
            Self::Standard(handle) => Some(handle.id().untyped()),
            Self::FrameSequential(_) => None,
            Self::Custom { handle, .. } => Some(handle.id()),
        }
    }
}

/// A LOD group: its levels ([`LodLevels`]) are selected by distance from the camera with
/// [`FrameSequentialLod`](super::FrameSequentialLod), and a switch between two levels is a frame-sequential transition.
///
/// The plugin spawns one child entity that draws the group (see [`FrameSequentialLevels`](super::FrameSequentialLevels)) and
/// gives it the mesh and material of the level drawn each frame.
#[derive(Component, Clone, Debug)]
#[require(Transform, Visibility)]
pub struct FrameSequentialGroup {
    /// The level distances (view-normalized, lodkit::select's measure: distance / |P\[1\]\[1\]|).
    pub group: LodGroup,
    /// The box that holds every level's vertices (object space; None: the union of the level
    /// meshes' bounds, computed once they are loaded). Give it for vertex animation that moves
    /// vertices beyond the meshes' bounds (`lodkit::combine::displaced_bounds`): the combine
    /// then runs over the box's screen rectangle (not the levels' silhouettes' hull) and only
    /// works inside it. Read once, when the group's levels are
    /// first drawn; a change to its [`LodLevels`] reads it again.
    pub bounds: Option<(Vec3, Vec3)>,
}

impl FrameSequentialGroup {
    /// A group selecting with `group`'s distances, bounds from its meshes.
    pub fn new(group: LodGroup) -> Self {
        Self {
            group,
            bounds: None,
        }
    }
}

/// One level of a LOD group: a mesh and its material.
#[derive(Clone, Debug)]
pub struct LodLevel {
    /// The level's mesh.
    pub mesh: Handle<Mesh>,
    /// The level's material: the app's own `StandardMaterial` handle, or a
    /// [`FrameSequentialMaterial`] ([`LevelMaterial`] says what each does).
    pub material: LevelMaterial,
}

impl LodLevel {
    /// A level of `mesh` drawn with `material`: a `Handle<StandardMaterial>` or a
    /// `Handle<FrameSequentialMaterial>`.
    pub fn new(mesh: Handle<Mesh>, material: impl Into<LevelMaterial>) -> Self {
        Self {
            mesh,
            material: material.into(),
        }
    }
}

/// The levels of a [`FrameSequentialGroup`], finest first (at most 256).
#[derive(Component, Clone, Debug, Default)]
pub struct LodLevels(pub Vec<LodLevel>);
