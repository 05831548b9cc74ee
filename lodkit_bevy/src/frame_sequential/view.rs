//! What the main world hands the render world each frame for a frame-sequential camera: the
//! view's matrices, thresholds, silhouettes and older levels.

use bevy::math::Affine2;
use bevy::mesh::{Mesh, UvChannel};
use bevy::prelude::*;
use bevy::render::render_resource::Face;

/// What the render world needs of the camera's frame (inserted every frame by the plugin).
/// When it goes, the render world drops the camera's ping-pong textures, bind group and
/// pipeline with it.
#[derive(Component, Clone, Debug)]
pub struct FrameSequentialView {
    /// This frame's view_from_world (next frame's reprojection source).
    pub view_from_world: Mat4,
    /// This frame's clip_from_view.
    pub clip_from_view: Mat4,
    /// This frame's clip space to last frame's (`lodkit::reproject::new_to_old_matrix`).
    pub new_to_old: Mat4,
    /// The t-instance ids drawn this frame (the groups in transition): each gets a record in
    /// the combine's data (`lodkit::combine_coverage::CombineData`).
    pub transition_ids: Vec<u32>,
    /// Per t-instance id whose group moved since last frame, the same matrix with the group's
    /// motion. Without motion vectors its pixels are reprojected with it; with them, the combine
    /// uses it only to tell where the group moved away from a pixel.
    pub object_new_to_old: Vec<(u32, Mat4)>,
    /// Per t-instance drawn this frame with the pattern anchored to the screen: its id and the
    /// tau at which it is displayed next frame (as its tag carries it).
    pub drawn_tau_next: Vec<(u32, f32)>,
    /// Per t-instance whose other level the older buffer holds (drawn last frame, screen
    /// pattern): its id and the tau at which that level is displayed this frame, this frame's
    /// threshold for it (complementary to the level drawn now).
    pub older_tau: Vec<(u32, f32)>,
    /// The levels this frame does not draw of the groups in transition, for the older-level
    /// depth pass (empty unless the coverage is exact; levels with a silhouette are not here).
    pub older_levels: Vec<OlderLevel>,
    /// Per t-instance whose older level's silhouette is known (`OlderCoverage::Silhouette`):
    /// its id and the silhouette's segments in pixels; the depth pass does not draw it.
    pub silhouettes: Vec<(u32, Vec<[f32; 4]>)>,
    /// Whether the coverage is exact (`FrameSequentialLod::coverage` is not `Estimated`): the
    /// combine reads the silhouettes and the older-level depth pass, which then runs.
    pub exact_coverage: bool,
    /// Whether the combine reads Bevy's motion vectors (the camera has `MotionVectorPrepass`).
    pub motion_vectors: bool,
    /// The combine's rectangles (pixels, top left origin), not overlapping.
    pub rects: Vec<URect>,
    /// Whether this frame is kept (its color and depth copied) as the next frame's older one.
    pub keep: bool,
    /// Which copy of the pair this frame writes (`TransitionScheduler::buffer_index`); the
    /// other holds the older frame.
    pub buffer: usize,
}

/// A level the older-level depth pass draws: the level of a group in transition that this
/// frame does not draw.
#[derive(Clone, Debug)]
pub struct OlderLevel {
    /// The level's mesh.
    pub mesh: AssetId<Mesh>,
    /// The group's world_from_local this frame.
    pub world_from_local: Mat4,
    /// The level material's face culling (the pass culls as the main pass does).
    pub cull_mode: Option<Face>,
    /// The alpha test of an alpha-mask level (the pass discards what the main pass does).
    pub alpha_test: Option<AlphaTest>,
}

/// What Bevy's main pass discards of a `StandardMaterial` with `AlphaMode::Mask`: a fragment
/// whose base colour alpha (the material's, times its base colour texture's, sampled at the
/// transformed UVs with the view's mip bias) is under the cutoff. The older-level depth pass
/// applies the same test, so the combine knows a masked level's coverage exactly (the leaves
/// of a card, not the card). A vertex colour's alpha is not read.
#[derive(Clone, Debug, PartialEq)]
pub struct AlphaTest {
    /// `AlphaMode::Mask`'s cutoff.
    pub cutoff: f32,
    /// The base colour's alpha.
    pub base_alpha: f32,
    /// The base colour texture, if any.
    pub texture: Option<Handle<Image>>,
    /// The material's UV transform.
    pub uv_transform: Affine2,
    /// Whether the texture reads the second UV set (`UvChannel::Uv1`).
    pub uv_b: bool,
}

impl AlphaTest {
    /// The alpha test of `material` (None unless its alpha mode is `Mask`).
    pub fn of(material: &StandardMaterial) -> Option<Self> {
        let AlphaMode::Mask(cutoff) = material.alpha_mode else {
            return None;
        };
        Some(Self {
            cutoff,
            base_alpha: material.base_color.alpha(),
            texture: material.base_color_texture.clone(),
            uv_transform: material.uv_transform,
            uv_b: material.base_color_channel == UvChannel::Uv1,
        })
    }
}
