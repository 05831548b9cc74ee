//! How far an impostor's picture can be from the mesh's, and the distance beyond which that
//! stays within a pixel bound. The derivation is in docs/impostors.md ("The switch distance").

use glam::{UVec2, Vec2};

use super::{ImpostorLayout, ImpostorShape, impostor_decode};

/// Steps per triangle edge at which [`impostor_angle`] samples the grid.
const ANGLE_STEPS: u32 = 16;

/// The angle, in radians, within which the frames that hold at least half of a view's blend
/// weight lie, largest over every view the grid covers (for [`ImpostorShape::Hemi`], every view
/// from above the horizon). A coverage test at 0.5 on a weighted blend follows its weighted
/// median, so this, not the farthest frame blended, is how far off the picture's frames are.
/// Each grid triangle is sampled at 16 steps per edge in the map's plane, and the largest angle
/// between neighbouring samples is added as a margin for what the samples miss (an estimate of
/// the maximum from above, not a proof: the frame that holds the median can change between
/// samples).
///
/// ```
/// # use lodkit::impostor::{ImpostorShape, impostor_angle};
/// let coarse = impostor_angle(8, ImpostorShape::Hemi);
/// let fine = impostor_angle(16, ImpostorShape::Hemi);
/// assert!(fine < coarse && coarse < 0.5);
/// ```
pub fn impostor_angle(frames: u32, shape: ImpostorShape) -> f32 {
    let n = frames.max(2);
    let hemi = shape.is_hemi();
    let dir = |e: Vec2| impostor_decode(e, hemi).as_dvec3();
    let at = |g: Vec2| g * (2.0 / (n - 1) as f32) - 1.0;
    let mut worst = 0.0f64;
    let mut step = 0.0f64;
    for cy in 0..n - 1 {
        for cx in 0..n - 1 {
            let c = UVec2::new(cx, cy).as_vec2();
            for corners in [
                [c, c + Vec2::X, c + Vec2::Y],
                [c + Vec2::ONE, c + Vec2::X, c + Vec2::Y],
            ] {
                let frames = corners.map(|g| dir(at(g)));
                for i in 0..=ANGLE_STEPS {
                    for j in 0..=ANGLE_STEPS - i {
                        let (a, b) = (i as f32 / ANGLE_STEPS as f32, j as f32 / ANGLE_STEPS as f32);
                        let w = [1.0 - a - b, a, b];
                        let g = corners[0]
                            + a * (corners[1] - corners[0])
                            + b * (corners[2] - corners[0]);
                        let v = dir(at(g));
                        let mut by = frames
                            .map(|f| v.angle_between(f))
                            .into_iter()
                            .zip(w)
                            .collect::<Vec<_>>();
                        by.sort_by(|x, y| x.0.total_cmp(&y.0));
                        let mut sum = 0.0;
                        for (angle, w) in by {
                            sum += w;
                            if sum >= 0.5 {
                                worst = worst.max(angle);
                                break;
                            }
                        }
                        let along = |da: f32, db: f32| {
                            let g = corners[0]
                                + (a + da) * (corners[1] - corners[0])
                                + (b + db) * (corners[2] - corners[0]);
                            v.angle_between(dir(at(g)))
                        };
                        let d = 1.0 / ANGLE_STEPS as f32;
                        step = step.max(along(d, 0.0)).max(along(0.0, d));
                    }
                }
            }
        }
    }
    (worst + step) as f32
}

/// The largest distance, in object units, between the impostor's picture and the mesh's, both
/// measured across the view ray: `radius (sin(a) + 2 / frame_size)`, with `a` the
/// [`impostor_angle`]. A frame seen `a` off its direction shows each point at height `h` above
/// its plane displaced by `h sin(a)` (`|h| <= radius`); its texels are `2 radius / frame_size`
/// wide, and an edge filtered from them moves by up to one.
pub fn impostor_error(layout: &ImpostorLayout) -> f32 {
    let a = impostor_angle(layout.frames, layout.shape).min(std::f32::consts::FRAC_PI_2);
    layout.radius * (a.sin() + 2.0 / layout.frame_size.max(1) as f32)
}

/// The view-normalized distance (lodkit's selection distance: centre distance over
/// `|P[1][1]|`, plus half the camera's hysteresis) beyond which the impostor's picture stays
/// within the camera's pixel error of the mesh's: the switch distance of a level whose error is
/// [`impostor_error`].
///
/// ```
/// # use lodkit::impostor::{ImpostorLayout, ImpostorShape, impostor_switch_distance};
/// # use lodkit::lod_chain::PixelErrorCamera;
/// let layout = ImpostorLayout { frames: 12, frame_size: 128, shape: ImpostorShape::Hemi, center: [0.0; 3], radius: 1.0 };
/// let near = impostor_switch_distance(&layout, &PixelErrorCamera::default()).unwrap();
/// let finer = ImpostorLayout { frames: 24, ..layout };
/// assert!(impostor_switch_distance(&finer, &PixelErrorCamera::default()).unwrap() < near);
/// ```
#[cfg(feature = "lod_chain")]
pub fn impostor_switch_distance(
    layout: &ImpostorLayout,
    camera: &crate::lod_chain::PixelErrorCamera,
) -> Result<f32, crate::lod_chain::LodChainError> {
    let d =
        crate::lod_chain::switch_distances(&[0.0, impostor_error(layout)], layout.radius, camera)?;
    Ok(d[1])
}

/// Where an impostor ends a chain of mesh levels ([`impostor_placement`]).
#[cfg(feature = "lod_chain")]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImpostorPlacement {
    /// The mesh levels kept before it (LOD0 always): the impostor is level `mesh_levels`.
    pub mesh_levels: usize,
    /// Its switch distance (view-normalized): its own ([`impostor_switch_distance`]); every
    /// kept mesh level switches in nearer.
    pub distance: f32,
}

/// Where an impostor whose picture is within the pixel error from `impostor` (its
/// [`impostor_switch_distance`]) ends a chain whose mesh levels switch at `distances` (LOD0's
/// first, 0) and which is hidden beyond `hidden`. Mesh levels that would switch in only where
/// the impostor is already within the pixel error give way to it: it is cheaper there and as
/// close to the mesh. [`LodChainError::ImpostorNeverShown`](crate::lod_chain::LodChainError)
/// where it would switch in only where the object is hidden.
///
/// ```
/// # use lodkit::impostor::impostor_placement;
/// // Levels at 0, 2, 5 and 9; the impostor is within the error from 4: levels 2 and 3 give way.
/// let p = impostor_placement(&[0.0, 2.0, 5.0, 9.0], 40.0, 4.0).unwrap();
/// assert_eq!((p.mesh_levels, p.distance), (2, 4.0));
/// // Within the error from 1, before level 1 switches in: LOD0, then the impostor.
/// let p = impostor_placement(&[0.0, 2.0, 5.0], 40.0, 1.0).unwrap();
/// assert_eq!((p.mesh_levels, p.distance), (1, 1.0));
/// assert!(impostor_placement(&[0.0, 2.0], 40.0, 50.0).is_err());
/// ```
#[cfg(feature = "lod_chain")]
pub fn impostor_placement(
    distances: &[f32],
    hidden: f32,
    impostor: f32,
) -> Result<ImpostorPlacement, crate::lod_chain::LodChainError> {
    if impostor >= hidden {
        return Err(crate::lod_chain::LodChainError::ImpostorNeverShown {
            from: impostor,
            hidden,
        });
    }
    // LOD0 (the first) stays whatever its distance; a chain without levels is the impostor.
    let mesh_levels = distances
        .iter()
        .skip(1)
        .position(|&d| d >= impostor)
        .map_or(distances.len(), |k| k + 1);
    Ok(ImpostorPlacement {
        mesh_levels,
        distance: impostor,
    })
}
