//! The default route: every t-instance's older level read from the older-level
//! depth pass, which the engine draws each frame of a transition (`LodBuffers::level_depth` in
//! the wgpu glue). It knows where the older level covers the screen as the rasterizer does (the
//! same triangles, the same fill rule) and how deep it lies this frame, vertex animation
//! included; the silhouette route ([`CoverageLevels`](super::CoverageLevels)) knows the first
//! from the CPU and not the second. The host side lays out the frame's data
//! ([`CombineData::depth_pass`]); [`combine_read_level_depth`] is the combine's read with it.

use glam::{Mat4, Vec2, Vec3};

use super::data::{
    CombineData, CombineDataDescriptor, CombineDataError, CombineObjectData, CoverageRoute,
};
use super::{COMBINE_KNOWN, CombineRead, combine_far_depth, combine_new_to_old, combine_object};
use crate::combine::older::{NOT_FOUND, found, id_at, size_of};
use crate::combine::{
    COMBINE_BLOCK_REACH, DepthConvention, LodImage, combine_cover_texel, combine_other_texel,
    combine_own_color, combine_texel, depth_closer,
};
use crate::frame_sequential::OlderDraw;
use crate::reproject::{reproject, reproject_base, reproject_from_base};

/// One t-instance whose older level the depth pass holds this frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct OlderDepth {
    /// The t-instance's id (`OlderDraw::id`).
    pub id: u32,
    /// This frame's clip space to last frame's for the instance's points where it moved by
    /// itself (`new_to_old_matrix` with the previous view times its motion); None: the
    /// camera's ([`DepthPassFrame::new_to_old`]).
    pub new_to_old: Option<Mat4>,
    /// The threshold at which the older level is displayed this frame with the pattern
    /// anchored to the screen (`OlderDraw::tau`, the default); None to keep the older buffer's
    /// flags (a pattern on the object).
    pub older_tau: Option<f32>,
}

impl From<OlderDraw> for OlderDepth {
    /// The scheduler's older draw with the pattern on the screen (lodkit's default) and the
    /// camera's matrix.
    fn from(draw: OlderDraw) -> Self {
        Self {
            id: draw.id,
            new_to_old: None,
            older_tau: Some(draw.tau),
        }
    }
}

/// What [`CombineData::depth_pass`] needs of the frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthPassFrame<'a> {
    /// The camera's `new_to_old` (this frame's clip space to last frame's; the combine's).
    pub new_to_old: Mat4,
    /// Whether each pixel's object motion is given (a LOD pass's motion target, an engine's
    /// motion vectors; lodkit's `LodBuffers::new` has one, the default).
    pub object_motion: bool,
    /// The t-instances' older levels, each drawn into the depth pass.
    pub objects: &'a [OlderDepth],
}

impl Default for DepthPassFrame<'_> {
    fn default() -> Self {
        Self {
            new_to_old: Mat4::IDENTITY,
            object_motion: true,
            objects: &[],
        }
    }
}

impl CombineData {
    /// The frame's data for the default route: every t-instance in `frame.objects` read from
    /// the older-level depth pass ([`CoverageRoute::DepthPass`], the descriptor's `level_depth`
    /// set). The combine pass then requires that pass's texture, and says so when it is missing.
    ///
    /// ```
    /// # use lodkit::combine_coverage::*;
    /// let objects = [OlderDepth { id: 4, older_tau: Some(0.25), ..Default::default() }];
    /// let frame = DepthPassFrame { objects: &objects, ..Default::default() };
    /// let data = CombineData::depth_pass(&frame).unwrap();
    /// let flags = combine_object(&data.texels, 0).flags;
    /// assert_eq!(flags & COMBINE_LEVEL_DEPTH, COMBINE_LEVEL_DEPTH);
    /// let o = combine_object(&data.texels, 4);
    /// assert_eq!(o.flags, COMBINE_KNOWN | COMBINE_ANCHORED | COMBINE_ROUTE_DEPTH_PASS);
    /// ```
    pub fn depth_pass(frame: &DepthPassFrame) -> Result<Self, CombineDataError> {
        let objects: Vec<CombineObjectData> = frame
            .objects
            .iter()
            .map(|o| CombineObjectData {
                id: o.id,
                new_to_old: o.new_to_old.unwrap_or(frame.new_to_old),
                older_tau: o.older_tau,
                route: CoverageRoute::DepthPass,
            })
            .collect();
        Self::new(&CombineDataDescriptor {
            new_to_old: frame.new_to_old,
            object_motion: frame.object_motion,
            level_depth: true,
            height: 1,
            objects: &objects,
        })
    }
}

/// The older read with the older-level depth pass (`level`: its depth at the pixel, far where
/// none): for a pixel showing `id` (0: none), its newer `depth`, the reprojection `old` of that
/// depth and the object `motion`. A pixel showing no t-instance takes a level only where it lies
/// in front of what the pixel shows. Where a level is drawn, its owner is the t-instance the older
/// buffer holds where that level's depth reprojects, in front of the pixel's own level or behind
/// it (the depth pass holds the nearest older level, which may be another t-instance's), or
/// the nearest t-instance of the 3x3 block around that read, else the pixel's own; read where
/// its own surface was, and where none of its texels lies near, nothing (the newer color). Where none is, what lies behind the pixel's own older level.
///
/// Its parameters mirror the shader function's, one for one (hence more than seven).
#[allow(clippy::too_many_arguments)]
pub fn combine_read_level_depth(
    older: &LodImage,
    data: &[[u32; 4]],
    level: f32,
    id: u32,
    uv: Vec2,
    depth: f32,
    old: Vec3,
    motion: Vec2,
    convention: DepthConvention,
) -> CombineRead {
    let size = size_of(older);
    // A pixel showing no t-instance shows a level only in front of what it shows: behind it,
    // the n-instance hides the level in either frame.
    let front = if id == 0 {
        depth
    } else {
        combine_far_depth(convention)
    };
    let covered = depth_closer(level, front, convention);
    let known = |g: u32| g != 0 && combine_object(data, g).flags & COMBINE_KNOWN != 0;
    let mut owner = id;
    if covered {
        let read_at = reproject(uv, level, &combine_new_to_old(data, id)).truncate() + motion;
        let read = combine_texel(read_at, size);
        if known(id_at(older, read)) {
            owner = id_at(older, read);
        } else {
            // The read, made with the pixel's own matrix and motion, may miss another
            // t-instance's level the pass holds: the nearest t-instance of the 3x3 block.
            let t = combine_other_texel(older, 0, read, read_at);
            if known(id_at(older, t)) {
                owner = id_at(older, t);
            }
        }
    }
    if owner == 0 {
        return NOT_FOUND;
    }
    if covered {
        let m = combine_new_to_old(data, owner);
        let base = reproject_base(uv, &m);
        let first = reproject_from_base(base, level, &m).truncate();
        let owned = |at: Vec2, motion: Vec2| {
            let read = combine_texel(at, size);
            match id_at(older, read) == owner {
                true => read,
                false => {
                    let reach = COMBINE_BLOCK_REACH;
                    combine_cover_texel(older, owner, read, base, level, &m, motion, reach)
                }
            }
        };
        let mut read_at = first + motion;
        let mut texel = owned(read_at, motion);
        // The pixel's object motion is its newer level's: where the older level's points moved
        // otherwise (a sway moves other points of the surface), the level is found where the
        // camera alone puts it.
        if id_at(older, texel) != owner {
            (texel, read_at) = (owned(first, Vec2::ZERO), first);
        }
        // No texel of the level near where it was (hidden last frame, or drawn there as an
        // n-instance on its transition's first frame): the newer color, not what the read holds.
        if id_at(older, texel) != owner {
            return NOT_FOUND;
        }
        let r = found(older, texel);
        return CombineRead {
            color: combine_own_color(older, owner, read_at, r.color),
            ..r
        };
    }
    let read_at = old.truncate() + motion;
    found(
        older,
        combine_other_texel(older, owner, combine_texel(read_at, size), read_at),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::combine_coverage::{
        COMBINE_ANCHORED, COMBINE_KNOWN, COMBINE_LEVEL_DEPTH, COMBINE_OBJECT_MOTION,
        COMBINE_ONLY_DEPTH_PASS, COMBINE_ROUTE_DEPTH_PASS, CombineDataDescriptor,
        CombineObjectData, CoverageRoute, combine_new_to_old, combine_object,
    };

    #[test]
    fn every_object_reads_the_depth_pass_with_its_own_matrix() {
        let camera = Mat4::from_translation(glam::Vec3::new(0.01, 0.0, 0.0));
        let own = Mat4::from_scale(glam::Vec3::splat(2.0));
        let objects = [
            OlderDepth::from(OlderDraw {
                lod: 1,
                id: 2,
                tau: 0.75,
            }),
            OlderDepth {
                id: 5,
                new_to_old: Some(own),
                older_tau: None,
            },
        ];
        let frame = DepthPassFrame {
            new_to_old: camera,
            object_motion: false,
            objects: &objects,
        };
        let data = CombineData::depth_pass(&frame).unwrap();
        let record = combine_object(&data.texels, 0);
        let only = COMBINE_LEVEL_DEPTH | COMBINE_ONLY_DEPTH_PASS;
        assert_eq!(record.flags & only, only);
        assert_eq!(record.flags & COMBINE_OBJECT_MOTION, 0);
        let two = combine_object(&data.texels, 2);
        let route = COMBINE_KNOWN | COMBINE_ROUTE_DEPTH_PASS;
        assert_eq!(two.flags, route | COMBINE_ANCHORED);
        assert_eq!(two.older_tau, 0.75);
        assert_eq!(combine_new_to_old(&data.texels, 2), camera);
        assert_eq!(combine_object(&data.texels, 5).flags, route);
        assert_eq!(combine_new_to_old(&data.texels, 5), own);
        // An id between them is unknown: the estimate.
        assert_eq!(combine_object(&data.texels, 3).flags, 0);
        // One object on another route: the pass is read, but not for every t-instance.
        let mixed = [
            CombineObjectData {
                id: 1,
                route: CoverageRoute::DepthPass,
                ..Default::default()
            },
            CombineObjectData {
                id: 2,
                route: CoverageRoute::Estimate,
                ..Default::default()
            },
        ];
        let data = CombineData::new(&CombineDataDescriptor {
            level_depth: true,
            objects: &mixed,
            ..Default::default()
        })
        .unwrap();
        let flags = combine_object(&data.texels, 0).flags;
        assert_eq!(flags & only, COMBINE_LEVEL_DEPTH);
        // No object: nothing to say of every t-instance.
        let none = CombineData::depth_pass(&DepthPassFrame::default()).unwrap();
        let flags = combine_object(&none.texels, 0).flags;
        assert_eq!(flags & only, COMBINE_LEVEL_DEPTH);
        let zero = [OlderDepth::default()];
        let e = CombineData::depth_pass(&DepthPassFrame {
            objects: &zero,
            ..Default::default()
        });
        assert_eq!(e, Err(CombineDataError::ZeroId { index: 0 }));
    }
}
