//! The exact route's host side: an engine registers each level's shape once per mesh
//! ([`CoverageLevels::register`]: a closed mesh's [`Surface`], an alpha-masked card's
//! [`MaskOutline`]), and each frame names the t-instances' older levels with their transforms
//! ([`OlderLevel`]); [`CoverageLevels::data`] finds their silhouettes under this frame's camera
//! and lays out the frame's [`CombineData`]. A t-instance whose older level has no silhouette
//! this frame is an error naming it ([`CoverageError`]), unless the frame says which route it
//! takes instead ([`CoverageFrame::missing`]): the combine never falls back to the estimate
//! unasked.

use glam::{Mat4, Vec3};
use thiserror::Error;

use super::data::{
    CombineData, CombineDataDescriptor, CombineDataError, CombineObjectData, CoverageRoute,
};
use crate::silhouette::{MaskOutline, Segment, SilhouetteError, Surface};

/// A level's shape, whose silhouette under a camera the combine reads.
#[derive(Clone, Debug)]
pub enum LevelShape {
    /// A closed triangle mesh ([`Surface::new`]).
    Surface(Surface),
    /// An alpha-masked card: its mask's outline in the card's plane ([`MaskOutline::new`]).
    Mask(MaskOutline),
}

impl From<Surface> for LevelShape {
    fn from(surface: Surface) -> Self {
        Self::Surface(surface)
    }
}

impl From<MaskOutline> for LevelShape {
    fn from(outline: MaskOutline) -> Self {
        Self::Mask(outline)
    }
}

/// A level registered in a [`CoverageLevels`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CoverageLevel(u32);

/// One t-instance's older level this frame (the level the older LOD buffer holds:
/// `TransitionScheduler::older`).
#[derive(Clone, Copy)]
pub struct OlderLevel<'a> {
    /// The t-instance's id (`OlderDraw::id`).
    pub id: u32,
    /// The older level's shape, as registered.
    pub level: CoverageLevel,
    /// The instance's world_from_local this frame.
    pub world_from_local: Mat4,
    /// This frame's clip space to last frame's for the instance's points where it moved by
    /// itself (`new_to_old_matrix` with the previous view times its motion); None: the
    /// camera's ([`CoverageFrame::new_to_old`]).
    pub new_to_old: Option<Mat4>,
    /// The threshold at which the older level is displayed this frame with the pattern
    /// anchored to the screen (`OlderDraw::tau`); None to keep the older buffer's flags (a
    /// pattern on the object).
    pub older_tau: Option<f32>,
    /// A vertex animation the host evaluates (object space in and out: wind sway), applied to a
    /// [`LevelShape::Surface`] before its silhouette is found; None: the rest pose.
    pub displace: Option<&'a dyn Fn(Vec3) -> Vec3>,
}

impl std::fmt::Debug for OlderLevel<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OlderLevel")
            .field("id", &self.id)
            .field("level", &self.level)
            .field("world_from_local", &self.world_from_local)
            .field("new_to_old", &self.new_to_old)
            .field("older_tau", &self.older_tau)
            .field("displace", &self.displace.is_some())
            .finish()
    }
}

/// The route of a t-instance whose older level has no silhouette this frame (a point behind
/// the camera, a displaced mask card).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MissingSilhouette {
    /// [`CoverageError::NoSilhouette`], naming it (the default): the frame is not combined on a
    /// guess.
    #[default]
    Error,
    /// The older-level depth pass, which the engine draws for those instances
    /// ([`CombineDataDescriptor::level_depth`] is then set).
    DepthPass,
    /// The estimate from last frame's picture, chosen knowingly (it shows the background at a
    /// silhouette that moved by a fraction of a texel).
    Estimate,
}

/// What [`CoverageLevels::data`] needs of the frame.
#[derive(Clone, Copy, Debug)]
pub struct CoverageFrame<'a> {
    /// This frame's clip_from_world (the LOD pass's view-projection).
    pub clip_from_world: Mat4,
    /// The camera's position in world space.
    pub eye: Vec3,
    /// The target's size in pixels.
    pub size: (u32, u32),
    /// The camera's `new_to_old` (this frame's clip space to last frame's; the combine's).
    pub new_to_old: Mat4,
    /// Whether each pixel's object motion is given (a LOD pass's motion target, an engine's
    /// motion vectors).
    pub object_motion: bool,
    /// Whether front faces wind counterclockwise in the meshes' space (default true); a
    /// mirroring transform (negative determinant) flips it per instance.
    pub front_ccw: bool,
    /// The t-instances' older levels.
    pub objects: &'a [OlderLevel<'a>],
    /// The route of one whose silhouette cannot be had (default: an error).
    pub missing: MissingSilhouette,
}

impl Default for CoverageFrame<'_> {
    fn default() -> Self {
        Self {
            clip_from_world: Mat4::IDENTITY,
            eye: Vec3::ZERO,
            size: (1, 1),
            new_to_old: Mat4::IDENTITY,
            object_motion: false,
            front_ccw: true,
            objects: &[],
            missing: MissingSilhouette::Error,
        }
    }
}

/// Why [`CoverageLevels::data`] gave no data.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum CoverageError {
    /// A level not registered in these levels.
    #[error("t-instance {id} names level {level:?}, but {count} levels are registered")]
    UnknownLevel {
        /// The t-instance's id.
        id: u32,
        /// The level it names.
        level: CoverageLevel,
        /// How many are registered.
        count: usize,
    },
    /// The older level has no silhouette this frame and the frame names no other route.
    #[error(
        "t-instance {id}: its older level has no silhouette this frame ({reason}); draw the \
         older-level depth pass for it (CoverageFrame::missing = DepthPass) or choose the \
         estimate knowingly (Estimate)"
    )]
    NoSilhouette {
        /// The t-instance's id.
        id: u32,
        /// Why.
        reason: SilhouetteError,
    },
    /// A displacement given for a mask card, whose outline lies in its plane.
    #[error(
        "t-instance {id}: a displacement moves a Surface's vertices, not a mask card's outline"
    )]
    DisplacedMask {
        /// The t-instance's id.
        id: u32,
    },
    /// The data could not be laid out.
    #[error(transparent)]
    Data(#[from] CombineDataError),
}

/// The levels' shapes, registered once per mesh (see the module's docs).
///
/// ```
/// use glam::{Mat4, Vec3};
/// use lodkit::combine_coverage::{CoverageFrame, CoverageLevels, OlderLevel, combine_object};
/// use lodkit::silhouette::Surface;
///
/// // A tetrahedron, closed, wound counterclockwise seen from outside.
/// let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
/// let i = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3];
/// let mut levels = CoverageLevels::new();
/// let coarse = levels.register(Surface::new(&p, Some(&i)).unwrap());
/// let view = glam::camera::rh::view::look_at_mat4(Vec3::new(2.0, 2.0, 3.0), Vec3::ZERO, Vec3::Y);
/// let proj = glam::camera::rh::proj::directx::perspective(0.8, 1.0, 0.1, 10.0);
/// let objects = [OlderLevel { id: 7, level: coarse, world_from_local: Mat4::IDENTITY,
///     new_to_old: None, older_tau: Some(0.3), displace: None }];
/// let data = levels.data(&CoverageFrame { clip_from_world: proj * view,
///     eye: Vec3::new(2.0, 2.0, 3.0), size: (64, 64), objects: &objects, ..Default::default() })
///     .unwrap();
/// assert_ne!(combine_object(&data.texels, 7).silhouette.w, 0); // segments found
/// ```
#[derive(Clone, Debug, Default)]
pub struct CoverageLevels {
    shapes: Vec<LevelShape>,
}

impl CoverageLevels {
    /// No levels.
    pub fn new() -> Self {
        Self::default()
    }

    /// Registers a level's shape (once per mesh, shared by every instance drawing it).
    pub fn register(&mut self, shape: impl Into<LevelShape>) -> CoverageLevel {
        self.shapes.push(shape.into());
        CoverageLevel(self.shapes.len() as u32 - 1)
    }

    /// How many levels are registered.
    pub fn len(&self) -> usize {
        self.shapes.len()
    }

    /// Whether none is.
    pub fn is_empty(&self) -> bool {
        self.shapes.is_empty()
    }

    /// The shape of `level`, if registered here.
    pub fn shape(&self, level: CoverageLevel) -> Option<&LevelShape> {
        self.shapes.get(level.0 as usize)
    }

    /// The silhouette of one older level under the frame's camera.
    pub fn silhouette(
        &self,
        frame: &CoverageFrame,
        object: &OlderLevel,
    ) -> Result<Vec<Segment>, CoverageError> {
        let id = object.id;
        let shape = self
            .shape(object.level)
            .ok_or(CoverageError::UnknownLevel {
                id,
                level: object.level,
                count: self.shapes.len(),
            })?;
        let clip_from_local = frame.clip_from_world * object.world_from_local;
        let no_silhouette = |reason| CoverageError::NoSilhouette { id, reason };
        match (shape, object.displace) {
            (LevelShape::Surface(surface), displace) => {
                let eye = object
                    .world_from_local
                    .inverse()
                    .transform_point3(frame.eye);
                let front_ccw = frame.front_ccw == (object.world_from_local.determinant() > 0.0);
                match displace {
                    Some(displace) => surface.silhouette_displaced(
                        clip_from_local,
                        eye,
                        frame.size,
                        front_ccw,
                        displace,
                    ),
                    None => surface.silhouette(clip_from_local, eye, frame.size, front_ccw),
                }
                .map_err(no_silhouette)
            }
            (LevelShape::Mask(outline), None) => outline
                .silhouette(clip_from_local, frame.size)
                .map_err(no_silhouette),
            (LevelShape::Mask(_), Some(_)) => Err(CoverageError::DisplacedMask { id }),
        }
    }

    /// The frame's [`CombineData`]: each t-instance's older level by its silhouette (or by the
    /// frame's [`missing`](CoverageFrame::missing) route where it has none this frame).
    pub fn data(&self, frame: &CoverageFrame) -> Result<CombineData, CoverageError> {
        let mut silhouettes = Vec::with_capacity(frame.objects.len());
        for object in frame.objects {
            let route =
                match self.silhouette(frame, object) {
                    Ok(segments) => Some(segments),
                    Err(
                        CoverageError::NoSilhouette { .. } | CoverageError::DisplacedMask { .. },
                    ) if frame.missing != MissingSilhouette::Error => None,
                    Err(e) => return Err(e),
                };
            silhouettes.push(route);
        }
        let missing_route = match frame.missing {
            MissingSilhouette::DepthPass => CoverageRoute::DepthPass,
            _ => CoverageRoute::Estimate,
        };
        let objects: Vec<CombineObjectData> = frame
            .objects
            .iter()
            .zip(&silhouettes)
            .map(|(object, segments)| CombineObjectData {
                id: object.id,
                new_to_old: object.new_to_old.unwrap_or(frame.new_to_old),
                older_tau: object.older_tau,
                route: segments
                    .as_deref()
                    .map_or(missing_route, CoverageRoute::Silhouette),
            })
            .collect();
        Ok(CombineData::new(&CombineDataDescriptor {
            new_to_old: frame.new_to_old,
            object_motion: frame.object_motion,
            level_depth: frame.missing == MissingSilhouette::DepthPass,
            height: frame.size.1,
            objects: &objects,
        })?)
    }
}
