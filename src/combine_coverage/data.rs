//! The combine's data texture: what `combine_pixel` knows of the frame and of each t-instance,
//! in one `Rgba32Uint` texture any GPU can read in a fragment shader (GL 3.3 and WebGL2
//! included: no storage buffer).
//!
//! Layout, texel `i` at `(i % width, i / width)`: per id `k` from 0 to the largest id given, a
//! record of [`COMBINE_RECORD`] texels at `k * 6`: texels 0..3 the columns of its `new_to_old`
//! (f32 bits), texel 4 its older level's silhouette table
//! ([`bin_silhouette`]), texel 5 (flags, older_tau bits, record count, 0). Record 0 is the
//! frame's: the camera's matrix, [`COMBINE_OBJECT_MOTION`], [`COMBINE_LEVEL_DEPTH`] and
//! [`COMBINE_ONLY_DEPTH_PASS`], and the
//! record count; an id between those given has the camera's matrix and no flags. The
//! silhouettes' rows and segments follow the records.

use glam::Mat4;
use thiserror::Error;

use super::{
    COMBINE_ANCHORED, COMBINE_KNOWN, COMBINE_LEVEL_DEPTH, COMBINE_OBJECT_MOTION,
    COMBINE_ONLY_DEPTH_PASS, COMBINE_RECORD, COMBINE_ROUTE_DEPTH_PASS, COMBINE_ROUTE_SILHOUETTE,
};
use crate::silhouette::{Segment, bin_silhouette};

/// The widest data texture [`CombineData::new`] lays out (a row of texels; narrower when there
/// are fewer texels).
pub const COMBINE_DATA_WIDTH: u32 = 1024;

/// The largest t-instance id [`CombineData`] holds: records are indexed by id, so 65,536
/// records of [`COMBINE_RECORD`](super::COMBINE_RECORD) texels take 384 rows of
/// [`COMBINE_DATA_WIDTH`], leaving room for silhouettes within [`COMBINE_MAX_HEIGHT`].
pub const COMBINE_MAX_ID: u32 = 65_535;

/// The most rows the data texture may have: 2048, the texture size WebGL2 and GLES 3.0
/// guarantee.
pub const COMBINE_MAX_HEIGHT: u32 = 2048;

/// How the combine knows where a t-instance's older level (the one not drawn this frame)
/// covers the screen.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum CoverageRoute<'a> {
    /// Its silhouette under this frame's camera, in pixels
    /// ([`Surface::silhouette`](crate::silhouette::Surface::silhouette)): exact, no pass; needs a
    /// closed mesh on the CPU.
    Silhouette(&'a [Segment]),
    /// The older-level depth pass: the host draws the older levels depth only with this frame's
    /// camera into a texture of the target's size, read at each pixel
    /// ([`CombineNewer::level_depth`](super::CombineNewer::level_depth)): exact for any mesh,
    /// for the cost of rasterizing them.
    DepthPass,
    /// From last frame's picture alone: no extra work, but a silhouette that moved by a
    /// fraction of a texel shows the other level or the background every other frame.
    #[default]
    Estimate,
}

/// One t-instance as the combine knows it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CombineObjectData<'a> {
    /// Its id (1 ..= [`COMBINE_MAX_ID`], as in the LOD buffers' id words).
    pub id: u32,
    /// This frame's clip space to last frame's for its points: the camera's, with its own motion
    /// where it moved ([`new_to_old_matrix`](crate::reproject::new_to_old_matrix) with the
    /// previous view times the motion).
    pub new_to_old: Mat4,
    /// The threshold at which its older level is displayed this frame, when the visibility
    /// pattern is anchored to the screen (the older level then shows exactly where the newer one
    /// does not); `None` to keep the flags the older buffer holds.
    pub older_tau: Option<f32>,
    /// Where its older level covers the screen.
    pub route: CoverageRoute<'a>,
}

/// What the combine knows this frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CombineDataDescriptor<'a> {
    /// The camera's `new_to_old` (this frame's clip space to last frame's).
    pub new_to_old: Mat4,
    /// Whether each pixel's object motion is given (a LOD pass's motion target, an engine's
    /// motion vectors); otherwise t-instances are reprojected with their own matrices.
    pub object_motion: bool,
    /// Whether the older-level depth pass is read. With it, and objects that all take it, the
    /// frame is flagged [`COMBINE_ONLY_DEPTH_PASS`]: a pixel showing no t-instance where the
    /// pass drew no level in front reads nothing older (a t-instance left out of `objects` is
    /// then not estimated there).
    pub level_depth: bool,
    /// The target's height in pixels (silhouettes are binned by its rows).
    pub height: u32,
    /// The t-instances in transition.
    pub objects: &'a [CombineObjectData<'a>],
}

impl Default for CombineDataDescriptor<'_> {
    fn default() -> Self {
        Self {
            new_to_old: Mat4::IDENTITY,
            object_motion: false,
            level_depth: false,
            height: 1,
            objects: &[],
        }
    }
}

/// Why [`CombineData::new`] refused its objects.
#[derive(Clone, Copy, Debug, Error, PartialEq)]
pub enum CombineDataError {
    /// Id 0 names n-instances (and record 0 is the frame's).
    #[error("objects[{index}] has id 0, which names n-instances: t-instance ids start at 1")]
    ZeroId {
        /// Its index in the objects.
        index: usize,
    },
    /// An id past [`COMBINE_MAX_ID`] (records are indexed by id).
    #[error("objects[{index}] has id {id}, past the largest id the combine's data holds ({max})")]
    IdTooLarge {
        /// Its index in the objects.
        index: usize,
        /// The id.
        id: u32,
        /// [`COMBINE_MAX_ID`].
        max: u32,
    },
    /// Records and silhouettes that need more rows than a texture every GPU takes.
    #[error("the combine's data needs {height} rows of texels, past {max}")]
    TooLarge {
        /// Rows needed.
        height: u32,
        /// [`COMBINE_MAX_HEIGHT`].
        max: u32,
    },
    /// Two objects with one id.
    #[error("objects[{first}] and objects[{second}] both have id {id}")]
    DuplicateId {
        /// The id.
        id: u32,
        /// The first object with it.
        first: usize,
        /// The second.
        second: usize,
    },
    /// The camera's matrix holds a NaN or an infinity.
    #[error("the camera's new_to_old is not finite")]
    CameraNotFinite,
    /// An object's matrix, threshold or silhouette point is NaN or infinite.
    #[error("objects[{index}]'s {what} is not finite")]
    NotFinite {
        /// Its index in the objects.
        index: usize,
        /// What: `new_to_old`, `older_tau` or `silhouette`.
        what: &'static str,
    },
    /// An object asks for the older-level depth pass, which the descriptor says is not read.
    #[error(
        "objects[{index}] takes its coverage from the depth pass, but the descriptor's level_depth \
         is false: draw the older levels' depth pass and set level_depth, or choose another route"
    )]
    NoDepthPass {
        /// Its index in the objects.
        index: usize,
    },
}

/// The combine's data texture, laid out (see the module's docs): `width` x `height` texels, row
/// after row, the last row padded with zeros.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CombineData {
    /// The texels.
    pub texels: Vec<[u32; 4]>,
    /// Texels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
}

impl CombineData {
    /// Lays out what the combine knows this frame.
    ///
    /// ```
    /// # use lodkit::combine_coverage::*;
    /// # use glam::{Mat4, Vec2};
    /// let square = [[2.0, 2.0, 2.0, 6.0], [2.0, 6.0, 6.0, 6.0], [6.0, 6.0, 6.0, 2.0], [6.0, 2.0, 2.0, 2.0]];
    /// let objects = [CombineObjectData { id: 3, new_to_old: Mat4::IDENTITY, older_tau: Some(0.4),
    ///     route: CoverageRoute::Silhouette(&square) }];
    /// let data = CombineData::new(&CombineDataDescriptor { height: 8, objects: &objects,
    ///     ..Default::default() }).unwrap();
    /// let o = combine_object(&data.texels, 3);
    /// assert_eq!(o.flags, COMBINE_KNOWN | COMBINE_ANCHORED | COMBINE_ROUTE_SILHOUETTE);
    /// assert_eq!(lodkit::silhouette::silhouette_covers(&data.texels, o.silhouette, Vec2::new(4.5, 4.5)), 1);
    /// assert_eq!(combine_object(&data.texels, 2).flags, 0); // no record: unknown
    /// ```
    pub fn new(desc: &CombineDataDescriptor) -> Result<Self, CombineDataError> {
        if !desc.new_to_old.is_finite() {
            return Err(CombineDataError::CameraNotFinite);
        }
        let mut slots = 1u32;
        for (index, o) in desc.objects.iter().enumerate() {
            if o.id == 0 {
                return Err(CombineDataError::ZeroId { index });
            }
            if o.id > COMBINE_MAX_ID {
                return Err(CombineDataError::IdTooLarge {
                    index,
                    id: o.id,
                    max: COMBINE_MAX_ID,
                });
            }
            if let Some(first) = desc.objects[..index].iter().position(|p| p.id == o.id) {
                return Err(CombineDataError::DuplicateId {
                    id: o.id,
                    first,
                    second: index,
                });
            }
            let finite_segments = match o.route {
                CoverageRoute::Silhouette(s) => s.iter().flatten().all(|v| v.is_finite()),
                _ => true,
            };
            let not_finite = if !o.new_to_old.is_finite() {
                Some("new_to_old")
            } else if !o.older_tau.is_none_or(f32::is_finite) {
                Some("older_tau")
            } else if !finite_segments {
                Some("silhouette")
            } else {
                None
            };
            if let Some(what) = not_finite {
                return Err(CombineDataError::NotFinite { index, what });
            }
            if o.route == CoverageRoute::DepthPass && !desc.level_depth {
                return Err(CombineDataError::NoDepthPass { index });
            }
            slots = slots.max(o.id + 1);
        }
        let matrix = |m: &Mat4| m.to_cols_array_2d().map(|c| c.map(f32::to_bits));
        let camera = matrix(&desc.new_to_old);
        let mut texels = Vec::with_capacity((slots * COMBINE_RECORD) as usize);
        for k in 0..slots {
            texels.extend(camera);
            texels.push([0; 4]);
            texels.push([if k == 0 { COMBINE_KNOWN } else { 0 }, 0, 0, 0]);
        }
        let frame_flags = COMBINE_KNOWN
            | if desc.object_motion {
                COMBINE_OBJECT_MOTION
            } else {
                0
            }
            | if desc.level_depth {
                COMBINE_LEVEL_DEPTH
            } else {
                0
            }
            | if desc.level_depth
                && !desc.objects.is_empty()
                && desc
                    .objects
                    .iter()
                    .all(|o| o.route == CoverageRoute::DepthPass)
            {
                COMBINE_ONLY_DEPTH_PASS
            } else {
                0
            };
        texels[5] = [frame_flags, 0, slots, 0];
        for o in desc.objects {
            let record = (o.id * COMBINE_RECORD) as usize;
            texels[record..record + 4].copy_from_slice(&matrix(&o.new_to_old));
            let route = match o.route {
                CoverageRoute::Silhouette(segments) => {
                    let table = bin_silhouette(segments, desc.height, &mut texels);
                    texels[record + 4] = table.to_array();
                    COMBINE_ROUTE_SILHOUETTE
                }
                CoverageRoute::DepthPass => COMBINE_ROUTE_DEPTH_PASS,
                CoverageRoute::Estimate => 0,
            };
            let anchored = if o.older_tau.is_some() {
                COMBINE_ANCHORED
            } else {
                0
            };
            let tau = o.older_tau.unwrap_or(0.0).to_bits();
            texels[record + 5] = [COMBINE_KNOWN | anchored | route, tau, 0, 0];
        }
        let n = texels.len() as u32;
        let width = n.min(COMBINE_DATA_WIDTH);
        let height = n.div_ceil(width);
        if height > COMBINE_MAX_HEIGHT {
            return Err(CombineDataError::TooLarge {
                height,
                max: COMBINE_MAX_HEIGHT,
            });
        }
        texels.resize((width * height) as usize, [0; 4]);
        Ok(Self {
            texels,
            width,
            height,
        })
    }

    /// The texels as little-endian bytes, for an `Rgba32Uint` texture of `width` x `height`.
    pub fn bytes(&self) -> Vec<u8> {
        self.texels
            .iter()
            .flatten()
            .flat_map(|w| w.to_le_bytes())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_past_the_records_are_refused_and_the_largest_fits() {
        let object = |id| CombineObjectData {
            id,
            new_to_old: Mat4::IDENTITY,
            older_tau: None,
            route: CoverageRoute::Estimate,
        };
        let data = |objects: &[CombineObjectData]| {
            CombineData::new(&CombineDataDescriptor {
                objects,
                ..Default::default()
            })
        };
        let largest = data(&[object(COMBINE_MAX_ID)]).unwrap();
        // 65,536 records of 6 texels in rows of 1024: 384 rows.
        assert_eq!((largest.width, largest.height), (1024, 384));
        assert_eq!(
            data(&[object(COMBINE_MAX_ID + 1)]).unwrap_err(),
            CombineDataError::IdTooLarge {
                index: 0,
                id: COMBINE_MAX_ID + 1,
                max: COMBINE_MAX_ID,
            }
        );
        assert!(matches!(
            data(&[object(u32::MAX)]),
            Err(CombineDataError::IdTooLarge { .. })
        ));
    }

    #[test]
    fn each_bad_object_is_named_by_its_index_and_what_is_wrong() {
        let good = CombineObjectData {
            id: 1,
            new_to_old: Mat4::IDENTITY,
            older_tau: Some(0.5),
            route: CoverageRoute::Estimate,
        };
        let nan = [[0.0, 0.0, f32::NAN, 1.0]];
        let bad = [
            CombineObjectData {
                new_to_old: Mat4::from_cols_array(&[f32::INFINITY; 16]),
                ..good
            },
            CombineObjectData {
                older_tau: Some(f32::NAN),
                ..good
            },
            CombineObjectData {
                route: CoverageRoute::Silhouette(&nan),
                ..good
            },
        ];
        for (o, what) in bad.iter().zip(["new_to_old", "older_tau", "silhouette"]) {
            let objects = [good, CombineObjectData { id: 2, ..*o }];
            let e = CombineData::new(&CombineDataDescriptor {
                objects: &objects,
                ..Default::default()
            })
            .unwrap_err();
            assert_eq!(e, CombineDataError::NotFinite { index: 1, what });
            assert!(e.to_string().contains("objects[1]'s"), "{e}");
        }
        let e = CombineData::new(&CombineDataDescriptor {
            new_to_old: Mat4::from_cols_array(&[f32::NAN; 16]),
            ..Default::default()
        });
        assert_eq!(e.unwrap_err(), CombineDataError::CameraNotFinite);
    }

    #[test]
    fn a_depth_pass_object_needs_the_depth_pass() {
        let objects = [CombineObjectData {
            id: 4,
            route: CoverageRoute::DepthPass,
            ..Default::default()
        }];
        let desc = CombineDataDescriptor {
            objects: &objects,
            ..Default::default()
        };
        let e = CombineData::new(&desc).unwrap_err();
        assert_eq!(e, CombineDataError::NoDepthPass { index: 0 });
        assert!(e.to_string().contains("level_depth"), "{e}");
        let with_pass = CombineDataDescriptor {
            level_depth: true,
            ..desc
        };
        let data = CombineData::new(&with_pass).unwrap();
        let o = crate::combine_coverage::combine_object(&data.texels, 4);
        assert_eq!(o.flags & COMBINE_ROUTE_DEPTH_PASS, COMBINE_ROUTE_DEPTH_PASS);
    }

    #[test]
    fn data_that_is_not_combine_datas_reads_without_a_panic() {
        // Record counts and texel indices near u32::MAX wrap as the shader's u32 arithmetic does
        // (a debug build panics on an unchecked overflow); what such data reads is unspecified.
        let mut texels = vec![[0; 4]; 12];
        texels[5] = [COMBINE_KNOWN, 0, u32::MAX, 0];
        let _ = crate::combine_coverage::combine_object(&texels, u32::MAX - 1);
        // Row 1 of a table at u32::MAX wraps to texel 0, whose entry starts at u32::MAX again.
        let data = [[u32::MAX, 2, 0, 0]];
        let table = glam::UVec4::new(u32::MAX, 0, 4, 0xffff_0000);
        let _ = crate::silhouette::silhouette_covers(&data, table, glam::Vec2::new(1.5, 1.5));
    }
}
