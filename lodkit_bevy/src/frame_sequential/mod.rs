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
//! frame-sequential LOD draws 0.71x the crossfade's fragments on lavapipe in an app without a
//! prepass and 0.77x in an app that runs Bevy's depth and motion-vector prepass anyway (TAA,
//! motion blur), the combine running over the hulls of the levels' silhouettes
//! ([`CombineRegion`]; 0.73x and 0.78x over screen rectangles), and over rectangles 1.21x and
//! 0.97x on an NVIDIA H200, whose early depth test rejects most of the crossfade's hidden
//! fragments; in GPU time (timestamps, over rectangles) it takes 1.15x and 1.10x the
//! crossfade's on lavapipe (the example reports `gpu_ms_<run>` per pass). The combine is
//! lodkit's (`lodkit::combine_coverage::combine_pixel`); the plugin's shader holds only what is
//! Bevy's. It
//! pops less (0.031 / 0.029 against 0.043 / 0.035, still / moving camera), shows no background
//! through an object, and flickers less on the change-over-net measure (1.89 / 5.06 against
//! 1.97 / 5.52): the level not drawn is placed exactly by its silhouette
//! ([`OlderCoverage::Silhouette`], found on the CPU), and where the paper's schedule shows both
//! levels a pixel shows their average, a true half blend the crossfade's dither cannot make
//! (`cargo run --example frame_sequential -- --report report.json`, and lodkit's
//! docs/engines.md).
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
//! - A level's material is the app's own `StandardMaterial` handle, used as it is (the plugin
//!   derives a [`FrameSequentialMaterial`] from it, sharing its textures, and follows its
//!   changes: [`LevelMaterial`]), or a [`FrameSequentialMaterial`] (Bevy's `StandardMaterial`,
//!   lit by Bevy's PBR functions), whose fragment shader ends with
//!   `lodkit_bevy::frame_sequential_level::lod_level_color`: the main pass's HDR color is the
//!   LOD buffer, its alpha the id word. A material of the app's own type `M` takes part the
//!   same way: [`FrameSequentialMaterialPlugin::<M>`] derives a [`FrameSequentialLevel<M>`]
//!   from each `M` handle a level names ([`LevelMaterial::custom`]), and `M`'s fragment shader
//!   ends with that one call (the `custom_material` example).
//! - A glTF file with `MSFT_lod` levels (the files `lodkit lod` writes) loaded by Bevy's glTF
//!   loader spawns these groups by itself ([`crate::gltf_lod`], feature `gltf`).
//! - After Bevy's opaque pass, before the transparent pass and post-processing, the plugin
//!   copies the main texture and depth (the next frame's older buffer) and runs lodkit's
//!   combine over the convex hulls of the silhouettes of the groups in transition (both
//!   levels'; [`CombineRegion`]), or their screen rectangles where a level has none.
//!
//! Adding the plugin is enough: while LOD groups exist and no camera has
//! [`FrameSequentialLod`], the plugin gives the app's main camera (an active 3D camera drawing
//! to a window, the lowest `Camera::order` first)
//! `FrameSequentialLod::default()` ([`FrameSequentialDefaultCamera`] says which, and turns it
//! off).
//!
//! Limits: one camera per app drives the selection (the first active one with
//! [`FrameSequentialLod`]); the combine needs `Msaa::Off`: on a camera with MSAA (Bevy's
//! default) the plugin logs one warning and its groups blend with lodkit's complementary
//! screen-door dither (both levels each frame on disjoint pixels: no pop, no see-through; in the
//! example pop 0.043 / 0.034 against Bevy's crossfade's 0.044 / 0.035), as do groups with a
//! blending material; with MSAA and a prepass the levels' prepass drops the same pixels (a group
//! with a level whose material has a prepass shader of its own switches at once); a group in transition casts the shadow of the
//! level drawn that frame (use `NotShadowCaster` on levels if that flickers in your scene);
//! at most [`MAX_TAG_ID`] groups in transition at once (more switch at once, with a warning);
//! the combine reads no storage buffer, but the plugin has not been run on WebGL2.

mod camera;
mod data;
mod dither;
mod drawer;
pub(crate) mod level_material;
pub(crate) mod levels;
mod material;
mod older_depth;
mod rects;
mod render;
mod select;
mod silhouette;
mod tag;
mod view;

use bevy::asset::embedded_asset;
use bevy::camera::Hdr;
use bevy::pbr::MaterialPlugin;
use bevy::prelude::*;
use bevy::render::RenderApp;
use bevy::render::extract_component::ExtractComponentPlugin;
use lodkit::frame_sequential::Schedule;
use lodkit::select::LodSettings;

pub use camera::FrameSequentialDefaultCamera;
pub use drawer::FrameSequentialLevels;
pub use level_material::{FrameSequentialLevel, FrameSequentialMaterialPlugin};
pub use levels::{
    FrameSequentialGroup, FrameSequentialSystems, LevelMaterial, LodLevel, LodLevels,
};
/// Where lodkit's visibility pattern is anchored: [`FrameSequentialLod::anchor`].
pub use lodkit::visibility::VisibilitySpace;
pub use material::{
    FrameSequentialBindings, FrameSequentialExtension, FrameSequentialMaterial, LEVEL_SHADER_DEF,
    VISIBILITY_TEXTURE, VISIBILITY_TEXTURE_SEED, VISIBILITY_TEXTURE_SIZE,
};
pub use older_depth::OLDER_DEPTH_PASS;
pub use render::COMBINE_PASS;
pub use select::FrameSequentialStats;
pub use tag::{DITHER_TAG_ID, MAX_TAG_ID, decode_tag, encode_dither_tag, encode_tag};

use crate::LodkitShadersPlugin;

/// Adds frame-sequential LOD: the selection and transition scheduling of every
/// [`FrameSequentialGroup`], the [`FrameSequentialMaterial`], and the combine pass on the camera
/// with [`FrameSequentialLod`]. With the `gltf` feature it also makes groups of glTF files'
/// `MSFT_lod` levels ([`gltf_lod`](crate::gltf_lod)) and adds
/// [`ImpostorPlugin`](crate::impostor::ImpostorPlugin) and
/// [`FrameSequentialMaterialPlugin::<ImpostorMaterial>`](FrameSequentialMaterialPlugin) to draw
/// their impostor levels (an app may add either as well).
pub struct FrameSequentialLodPlugin;

impl Plugin for FrameSequentialLodPlugin {
    fn build(&self, app: &mut App) {
        if !app.is_plugin_added::<LodkitShadersPlugin>() {
            app.add_plugins(LodkitShadersPlugin);
        }
        crate::shaders::register_level_libraries(app);
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
            .resource_mut::<Assets<Shader>>()
            .insert(
                &material::LOD_PREPASS_SHADER,
                Shader::from_wesl(
                    include_str!("lod_prepass.wesl"),
                    "embedded://lodkit_bevy/frame_sequential/lod_prepass.wesl",
                ),
            )
            .expect("UUID handles never fail to insert");
        app.world_mut()
            .resource_mut::<Assets<Shader>>()
            .insert(
                &material::LOD_DEFAULT_PREPASS_SHADER,
                Shader::from_wesl(
                    include_str!("lod_default_prepass.wesl"),
                    "embedded://lodkit_bevy/frame_sequential/lod_default_prepass.wesl",
                ),
            )
            .expect("UUID handles never fail to insert");
        app.world_mut()
            .resource_mut::<Assets<Image>>()
            .insert(&VISIBILITY_TEXTURE, material::visibility_image())
            .expect("UUID handles never fail to insert");
        app.add_plugins((
            MaterialPlugin::<FrameSequentialMaterial>::default(),
            ExtractComponentPlugin::<view::FrameSequentialView>::default(),
        ));
        select::build(app);
        #[cfg(feature = "gltf")]
        {
            // A glTF file's impostor levels are drawn with ImpostorMaterial.
            app.add_plugins((
                crate::impostor::ImpostorPlugin,
                FrameSequentialMaterialPlugin::<crate::impostor::ImpostorMaterial>::default(),
            ));
            crate::gltf_lod::build(app);
        }
        #[cfg(feature = "lod_chain")]
        crate::auto_lod::build(app);
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
/// The combine needs `Msaa::Off`: with another `Msaa` (Bevy's default is `Sample4`) the plugin
/// logs one warning, runs no combine, and draws each group in transition through lodkit's
/// complementary screen-door dither instead, in the prepass too where the camera has one
/// (groups with a level whose material has a prepass shader of its own then switch levels at
/// once).
#[derive(Component, Clone, Debug, Reflect)]
#[reflect(Component, Default, Clone)]
#[require(Hdr)]
pub struct FrameSequentialLod {
    /// How the two levels share the visibility pattern over a transition (default: the paper's
    /// Fig. 2, `Schedule::Paper`, not lodkit's default: in the frame_sequential example it
    /// flickers less than Bevy's crossfade against the fine level, where
    /// `Schedule::Complementary`, which spreads the change at silhouettes over the whole
    /// transition, flickers a little more; lodkit's docs/engines.md has both).
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
    /// How the combine knows which pixels the level a group does not draw this frame covers
    /// (default [`OlderCoverage::Silhouette`]; see there for what each costs).
    #[reflect(ignore)]
    pub coverage: OlderCoverage,
    /// Where the combine runs (default [`CombineRegion::Hulls`]: only where it can change a
    /// pixel).
    #[reflect(ignore)]
    pub combine_region: CombineRegion,
}

/// Where the combine pass runs: [`FrameSequentialLod::combine_region`]. Either way it draws the
/// same picture; the hulls shade fewer pixels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CombineRegion {
    /// Over the convex hull of both levels' silhouettes, per group in transition (the
    /// default), drawn as rows of 4 pixels. The combine changes a pixel only where this
    /// frame's level was drawn (a t-instance's id is there) or where the older level's
    /// silhouette covers its center or passes within `SILHOUETTE_TIE` of it (the shader reads
    /// no other older coverage for a group with a silhouette; a pixel's motion changes what it
    /// reads, not whether it changes), so the hull of both silhouettes, found with this
    /// frame's camera and transform, grown by one pixel (the tie and the CPU's other rounding
    /// of the projection are far below one), holds every pixel it changes. The levels'
    /// silhouettes cost CPU time: the drawn level's is found as well as the older one's
    /// ([`FrameSequentialStats::silhouette_time`]). A group whose levels do not both have a
    /// silhouette (coverage [`OlderCoverage::Estimated`] or [`OlderCoverage::DepthPass`], a
    /// mesh without one, a level reaching behind the camera) or that names its own
    /// [`bounds`](FrameSequentialGroup::bounds) (vertex animation beyond its meshes, which
    /// silhouettes do not follow) is combined over its rectangles, as with
    /// [`Rectangles`](Self::Rectangles).
    #[default]
    Hulls,
    /// Over the screen rectangles of each group's bounds, this frame and where the older
    /// frame had it: the combine's region before the hulls, kept to compare with them.
    Rectangles,
}

/// How the combine knows which pixels the older level (the one a group in transition does not
/// draw this frame) covers now: [`FrameSequentialLod::coverage`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum OlderCoverage {
    /// Exact, from each older level's silhouette (the default): the edges between its faces
    /// turned to the camera and those turned away, found on the CPU each frame with this frame's
    /// camera and the group's transform (one facing test per triangle; the mesh's welded
    /// topology is built once), and tested per pixel in the combine by their winding number.
    /// No pass is added; the CPU time is in [`FrameSequentialStats::silhouette_time`] (in the
    /// frame_sequential example, a median of 29-47 µs per frame for up to 6,624 triangles).
    /// Needs a closed triangle mesh whose positions stay in the main world
    /// (the default `RenderAssetUsages`); a level without one is drawn by the older-level depth
    /// pass instead, as with [`DepthPass`](Self::DepthPass). Skinned, morphed or
    /// vertex-animated levels are taken in their rest pose.
    #[default]
    Silhouette,
    /// Exact, from the older-level depth pass: the older levels drawn again each frame, depth
    /// only (no fragment stage), with this frame's camera and the group's transform, into one
    /// `Depth32Float` target of the camera's size; the combine also reads the older colors at
    /// that depth. Works for any mesh; costs the rasterization of those levels (lavapipe counts
    /// its samples as fragment invocations). Levels are drawn in their rest pose.
    DepthPass,
    /// From last frame's picture alone: no extra work, but its pixel centers put a silhouette
    /// only to within a texel, so a silhouette that moved by a fraction of one shows the other
    /// level or the background every other frame, and a moving group's edge leaves a trace
    /// where it was last frame.
    Estimated,
}

impl OlderCoverage {
    /// Whether the coverage is exact (not estimated).
    pub fn is_exact(self) -> bool {
        self != Self::Estimated
    }
}

impl Default for FrameSequentialLod {
    fn default() -> Self {
        Self {
            schedule: Schedule::Paper,
            anchor: VisibilitySpace::default(),
            settings: LodSettings {
                hysteresis: 0.5,
                ..default()
            },
            reprojection: true,
            coverage: OlderCoverage::default(),
            combine_region: CombineRegion::default(),
        }
    }
}
