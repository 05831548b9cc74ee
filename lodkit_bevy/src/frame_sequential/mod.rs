//! Frame-sequential LOD on a Bevy camera (Scherzer & Wimmer 2008): a LOD group in transition
//! draws ONE of its two levels per frame, alternating, and a combine pass merges this frame's
//! picture with the last one's, reprojected with the main pass's depth and the camera's and
//! groups' motion (or Bevy's motion vectors, where the camera has that prepass). Each level is
//! shown through lodkit's visibility pattern at the frame displayed, so the object never shows
//! what is behind it (no see-through), the change is spread over the transition (no pop), and
//! the group draws one level per frame, not two as a crossfade does.
//!
//! No prepass is needed, as for Bevy's `VisibilityRange` crossfade. In the `frame_sequential`
//! example (the plugin's defaults), each technique on a camera of its own, over its transitions,
//! frame-sequential LOD draws 0.73x the crossfade's fragments in an app without a prepass and
//! 0.78x in an app that runs Bevy's depth and motion-vector prepass anyway (TAA, motion blur),
//! with less pop; on the flicker measure (change over net change) it scores 2.07 / 6.17 against
//! the crossfade's 1.97 / 5.52 (still / moving camera), and a moving group's edge shows where it
//! was last frame in a few pixels (497 pixel-frames over the run; the crossfade none). With
//! [`FrameSequentialLod::exact_coverage`] (a depth-only pass of the levels not drawn this frame)
//! it flickers less than the crossfade, 1.91 / 5.12, and no pixel shows a ghost, but the depth
//! pass's samples bring it to 1.15x the crossfade's fragments without a prepass (0.91x with one)
//! (`cargo run --example frame_sequential -- --report report.json [--exact-coverage]`, and
//! lodkit's docs/engines.md).
//!
//! ```no_run
//! use bevy::prelude::*;
//! use lodkit::select::{LodGroup, LodSettings};
//! use lodkit_bevy::frame_sequential::*;
//!
//! fn setup(
//!     mut commands: Commands,
//!     mut meshes: ResMut<Assets<Mesh>>,
//!     mut materials: ResMut<Assets<FrameSequentialMaterial>>,
//! ) {
//!     commands.spawn((
//!         Camera3d::default(),
//!         Msaa::Off, // the combine reads the main pass per pixel
//!         FrameSequentialLod {
//!             settings: LodSettings { hysteresis: 0.5, ..default() },
//!             ..default()
//!         },
//!     ));
//!     let material = materials.add(FrameSequentialMaterial {
//!         base: StandardMaterial::from(Color::srgb(0.8, 0.5, 0.2)),
//!         extension: FrameSequentialExtension::default(),
//!     });
//!     commands.spawn((
//!         LodLevels(vec![
//!             LodLevel::new(meshes.add(Sphere::new(1.0).mesh().uv(48, 24)), material.clone()),
//!             LodLevel::new(meshes.add(Sphere::new(1.0).mesh().uv(10, 6)), material),
//!         ]),
//!         FrameSequentialGroup::new(LodGroup::from_distances(&[0.0, 4.0]).unwrap()),
//!         Transform::from_xyz(0.0, 0.0, -6.0),
//!     ));
//! }
//!
//! App::new()
//!     .add_plugins((DefaultPlugins, FrameSequentialLodPlugin))
//!     .add_systems(Startup, setup)
//!     .run();
//! ```
//!
//! How it fits into Bevy's frame:
//! - [`FrameSequentialLodPlugin`] selects every [`FrameSequentialGroup`]'s level from the camera
//!   with [`FrameSequentialLod`] (lodkit::select, with hysteresis; distance- or time-driven),
//!   and runs lodkit's transition scheduler: a group shows the level the scheduler draws this
//!   frame, through a child entity of the group, in Bevy's main pass (and prepass, if any). A
//!   group not in transition is an ordinary Bevy mesh.
//! - Levels use [`FrameSequentialMaterial`] (Bevy's `StandardMaterial`, lit by Bevy's PBR
//!   functions), whose fragment shader ends with
//!   `lodkit_bevy::frame_sequential::lod_fragment_alpha`: the main pass's HDR color is the LOD
//!   buffer, its alpha the id word. The WGSL module offers that function to materials of your
//!   own, but the plugin drives only `FrameSequentialMaterial` levels for now.
//! - After Bevy's opaque pass, before the transparent pass and post-processing, the plugin
//!   copies the main texture and depth (the next frame's older buffer) and runs lodkit's
//!   combine over the screen rectangles of the groups in transition.
//!
//! Limits: one camera per app drives the selection (the first active one with
//! [`FrameSequentialLod`]); the combine needs `Msaa::Off` (with MSAA the plugin logs one
//! warning and its groups switch levels at once, with no transition); a group in transition casts the shadow of the
//! level drawn that frame (use `NotShadowCaster` on levels if that flickers in your scene);
//! at most [`MAX_TAG_ID`] groups in transition at once (more switch at once, with a warning);
//! the combine reads a storage buffer in its fragment shader, which WebGL2 does not offer.

mod material;
mod older_depth;
mod render;
mod select;
mod tag;

use bevy::asset::embedded_asset;
use bevy::camera::Hdr;
use bevy::pbr::MaterialPlugin;
use bevy::prelude::*;
use bevy::render::RenderApp;
use bevy::render::extract_component::{ExtractComponentPlugin, UniformComponentPlugin};
use lodkit::frame_sequential::Schedule;
use lodkit::select::{LodGroup, LodSettings};

/// Where lodkit's visibility pattern is anchored: [`FrameSequentialLod::anchor`].
pub use lodkit::visibility::VisibilitySpace;
pub use material::{
    FrameSequentialExtension, FrameSequentialMaterial, VISIBILITY_TEXTURE, VISIBILITY_TEXTURE_SEED,
    VISIBILITY_TEXTURE_SIZE,
};
pub use older_depth::OLDER_DEPTH_PASS;
pub use render::COMBINE_PASS;
pub use select::{FrameSequentialLevels, FrameSequentialStats};
pub use tag::{MAX_TAG_ID, decode_tag, encode_tag};

use crate::LodkitShadersPlugin;

/// Adds frame-sequential LOD: the selection and transition scheduling of every
/// [`FrameSequentialGroup`], the [`FrameSequentialMaterial`], and the combine pass on the camera
/// with [`FrameSequentialLod`].
pub struct FrameSequentialLodPlugin;

impl Plugin for FrameSequentialLodPlugin {
    fn build(&self, app: &mut App) {
        if !app.is_plugin_added::<LodkitShadersPlugin>() {
            app.add_plugins(LodkitShadersPlugin);
        }
        crate::shaders::register_library(
            app,
            "frame_sequential",
            include_str!("frame_sequential.wesl"),
        );
        embedded_asset!(app, "combine.wesl");
        embedded_asset!(app, "older_depth.wesl");
        app.world_mut()
            .resource_mut::<Assets<Shader>>()
            .insert(
                &material::LOD_MATERIAL_SHADER,
                Shader::from_wesl(
                    include_str!("lod_material.wesl"),
                    "embedded://lodkit_bevy/frame_sequential/lod_material.wesl",
                ),
            )
            .expect("UUID handles never fail to insert");
        app.world_mut()
            .resource_mut::<Assets<Image>>()
            .insert(&VISIBILITY_TEXTURE, material::visibility_image())
            .expect("UUID handles never fail to insert");
        app.add_plugins((
            MaterialPlugin::<FrameSequentialMaterial>::default(),
            ExtractComponentPlugin::<render::FrameSequentialView>::default(),
            UniformComponentPlugin::<render::CombineParams>::default(),
        ));
        select::build(app);
        if let Some(render_app) = app.get_sub_app_mut(RenderApp) {
            render::build(render_app);
        }
    }

    fn finish(&self, app: &mut App) {
        if let Some(render_app) = app.get_sub_app_mut(RenderApp) {
            render::finish(render_app);
        }
    }
}

/// Frame-sequential LOD on a 3D camera: the camera that selects the levels of every
/// [`FrameSequentialGroup`] and combines its frames.
///
/// Requires (and adds) [`Hdr`]. No prepass is needed: the combine reprojects last frame's
/// picture with this frame's depth (the main pass's), the camera's motion and, for a group that
/// moved (its `GlobalTransform` changed), the group's motion. Add Bevy's
/// [`MotionVectorPrepass`](bevy::core_pipeline::prepass::MotionVectorPrepass) (with
/// [`DepthPrepass`](bevy::core_pipeline::prepass::DepthPrepass)) when levels move in ways a transform does not
/// tell (skinned or morphed meshes, vertex animation): the combine then reads each pixel's
/// motion from it; an app that runs that prepass anyway (TAA, motion blur) loses nothing by it.
///
/// The camera must also have `Msaa::Off`: with another `Msaa` the plugin logs one warning, runs
/// no combine and lets no transition begin (groups switch levels at once).
#[derive(Component, Clone, Debug, Reflect)]
#[reflect(Component, Default, Clone)]
#[require(Hdr)]
pub struct FrameSequentialLod {
    /// How the two levels share the visibility pattern over a transition (default: the paper's
    /// Fig. 2; `Schedule::Complementary` spreads the change at silhouettes over the whole
    /// transition).
    #[reflect(ignore)]
    pub schedule: Schedule,
    /// Where the pattern is anchored (default `VisibilitySpace::Screen`: one texel per pixel,
    /// holding still like a dither; `Object`: at the object-space position, the paper's
    /// choice, moving with the object).
    #[reflect(ignore)]
    pub anchor: VisibilitySpace,
    /// Selection settings shared by every group: global bias, hysteresis band and how a switch
    /// is staged (`TransitionMode::Distance` blends across the band, `Time` over a duration,
    /// `Hard` switches at once).
    #[reflect(ignore)]
    pub settings: LodSettings,
    /// Whether the combine reprojects the older frame with the camera's and the groups' motion,
    /// or Bevy's motion vectors with a motion-vector prepass (default true). Off, the older
    /// frame is read at the same pixel: only for
    /// seeing what reprojection does; a moving camera then shows the background through
    /// objects in transition.
    pub reprojection: bool,
    /// Whether the level a group does not draw this frame is drawn again, depth only, with
    /// this frame's camera and transform (default false). The combine then knows exactly which
    /// pixels that level covers and reads its colors at its own depth; without it, it places the
    /// level from last frame's picture, whose pixel centers put a silhouette only to within a
    /// texel. On: no trace of a moved group and no silhouette shown a pixel off every other
    /// frame (in the frame_sequential example, flicker 1.91 / 5.12 against 2.07 / 6.17 off,
    /// Bevy's crossfade 1.97 / 5.52; ghost pixels 0 against 497). The cost: the pass rasterizes
    /// the older levels of the groups in transition each frame with no fragment stage (lavapipe
    /// still counts its samples as fragment invocations: 2.08 M over the example's transitions,
    /// next to 3.66 M shaded), and one `Depth32Float` target of the camera's size. It draws the
    /// level's mesh with the group's transform: skinned, morphed or vertex-animated levels are
    /// drawn in their rest pose.
    pub exact_coverage: bool,
}

impl Default for FrameSequentialLod {
    fn default() -> Self {
        Self {
            schedule: Schedule::default(),
            anchor: VisibilitySpace::default(),
            settings: LodSettings {
                hysteresis: 0.5,
                ..default()
            },
            reprojection: true,
            exact_coverage: false,
        }
    }
}

/// A LOD group: its levels ([`LodLevels`]) are selected by distance from the camera with
/// [`FrameSequentialLod`], and a switch between two levels is a frame-sequential transition.
///
/// The plugin spawns one child entity that draws the group (see [`FrameSequentialLevels`]) and
/// gives it the mesh and material of the level drawn each frame.
#[derive(Component, Clone, Debug)]
#[require(Transform, Visibility)]
pub struct FrameSequentialGroup {
    /// The level distances (view-normalized, lodkit::select's measure: distance / |P\[1\]\[1\]|).
    pub group: LodGroup,
    /// The box that holds every level's vertices (object space; None: the union of the level
    /// meshes' bounds, computed once they are loaded). Give it for vertex animation that moves
    /// vertices beyond the meshes' bounds (`lodkit::combine::displaced_bounds`): the combine
    /// only works inside the box's screen rectangle. Read once, when the group's levels are
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
    /// The level's material.
    pub material: Handle<FrameSequentialMaterial>,
}

impl LodLevel {
    /// A level of `mesh` drawn with `material`.
    pub fn new(mesh: Handle<Mesh>, material: Handle<FrameSequentialMaterial>) -> Self {
        Self { mesh, material }
    }
}

/// The levels of a [`FrameSequentialGroup`], finest first (at most 256).
#[derive(Component, Clone, Debug, Default)]
pub struct LodLevels(pub Vec<LodLevel>);
