//! Switch distances from a pixel error: the view-normalized distance from which a level whose
//! surface lies within `e` of the original (two-sided Hausdorff, object space) is drawn at most
//! `p` pixels away from where the original would be. The derivation is in `docs/selection.md`
//! ("Switch distances from a pixel error").

use super::LodChainError;
use crate::select::{LodGroup, LodLevel};

/// The reference camera switch distances are computed for, and the error allowed on its screen.
///
/// Distances come out view-normalized (divided by `|P[1][1]| = 1 / tan(fov_y / 2)`), so the
/// bound holds for this camera and for every camera with a narrower vertical field of view on a
/// viewport of the same height; a LOD bias `b` scales the allowed error by about `b` (exactly
/// `b` for a zero radius).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelErrorCamera {
    /// Vertical field of view in radians (default 60°).
    pub fov_y: f32,
    /// Viewport height in pixels (default 1080).
    pub viewport_height: f32,
    /// Largest allowed screen-space deviation from the original, in pixels (default 1).
    pub pixel_error: f32,
    /// The hysteresis `h` the group will be selected with
    /// ([`LodSettings::hysteresis`](crate::select::LodSettings::hysteresis), view-normalized;
    /// default 0). A level can be shown from `h / 2` nearer than its switch distance, so every
    /// distance is pushed out by `h / 2`.
    pub hysteresis: f32,
}

impl Default for PixelErrorCamera {
    fn default() -> Self {
        Self {
            fov_y: 60f32.to_radians(),
            viewport_height: 1080.0,
            pixel_error: 1.0,
            hysteresis: 0.0,
        }
    }
}

impl PixelErrorCamera {
    /// Checks the values: field of view in (0, π), positive finite height and pixel error,
    /// finite hysteresis >= 0.
    pub fn validate(&self) -> Result<(), LodChainError> {
        let bad = |field: &'static str, value: f32| LodChainError::BadCamera { field, value };
        if !(self.fov_y > 0.0 && self.fov_y < std::f32::consts::PI) {
            return Err(bad("fov_y", self.fov_y));
        }
        if !(self.viewport_height.is_finite() && self.viewport_height > 0.0) {
            return Err(bad("viewport_height", self.viewport_height));
        }
        if !(self.pixel_error.is_finite() && self.pixel_error > 0.0) {
            return Err(bad("pixel_error", self.pixel_error));
        }
        if !(self.hysteresis.is_finite() && self.hysteresis >= 0.0) {
            return Err(bad("hysteresis", self.hysteresis));
        }
        Ok(())
    }

    /// `|P[1][1]| = 1 / tan(fov_y / 2)`.
    pub fn p11(&self) -> f64 {
        1.0 / (f64::from(self.fov_y) * 0.5).tan()
    }

    /// Pixels per unit of tan-angle at the view axis: `viewport_height / 2 x |P[1][1]|`.
    fn k(&self) -> f64 {
        f64::from(self.viewport_height) * 0.5 * self.p11()
    }
}

/// The screen-space deviation bound, in pixels, of a surface within `error` of the original, for
/// an object inside a sphere of `radius` whose centre is on the view axis at `distance` (object
/// units, > radius): `k e D / ((D - R) sqrt(D² - R²))`, `k = H / 2 x |P[1][1]|`.
///
/// ```
/// # use lodkit::lod_chain::{PixelErrorCamera, projected_error};
/// let cam = PixelErrorCamera { fov_y: 90f32.to_radians(), viewport_height: 1000.0, ..Default::default() };
/// // A point-sized object: k e / D = 500 x 0.01 / 5 = 1 pixel.
/// assert!((projected_error(0.01, 0.0, 5.0, &cam) - 1.0).abs() < 1e-6); // fov_y is an f32
/// assert!(projected_error(0.01, 1.0, 5.0, &cam) > 1.0); // its near side is closer
/// ```
pub fn projected_error(error: f32, radius: f32, distance: f64, camera: &PixelErrorCamera) -> f64 {
    let (e, r, d) = (f64::from(error), f64::from(radius), distance);
    if d <= r {
        return f64::INFINITY;
    }
    camera.k() * e * d / ((d - r) * (d * d - r * r).sqrt())
}

/// The smallest distance D (object units, to the centre) at which [`projected_error`] is at most
/// the camera's pixel error: `(D - R) sqrt(1 - R²/D²) = k e / p`, solved by bisection (the left
/// side increases with D).
fn min_distance(error: f32, radius: f32, camera: &PixelErrorCamera) -> f64 {
    let r = f64::from(radius);
    let need = camera.k() * f64::from(error) / f64::from(camera.pixel_error);
    let g = |d: f64| (d - r) * (1.0 - (r / d) * (r / d)).max(0.0).sqrt();
    let (mut lo, mut hi) = (r, r + need.max(r) + 1.0);
    while g(hi) < need {
        hi = r + 2.0 * (hi - r);
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(mid) >= need {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// View-normalized switch distance of each level whose error (object-space Hausdorff bound) is
/// `errors[i]`, for an object of bounding-sphere `radius` selected by the distance to that
/// sphere's centre: level 0 at 0, level i at `D_i / |P[1][1]| + h / 2`, where `D_i` is the
/// nearest centre distance at which the largest error of levels 1..=i stays within the pixel
/// error (so the distances never decrease, even where a level measured a smaller error than the
/// one before).
///
/// ```
/// # use lodkit::lod_chain::{PixelErrorCamera, switch_distances};
/// let cam = PixelErrorCamera { fov_y: 90f32.to_radians(), viewport_height: 1000.0, ..Default::default() };
/// let d = switch_distances(&[0.0, 0.01, 0.02], 0.0, &cam).unwrap();
/// assert_eq!(d[0], 0.0);
/// assert!((d[1] - 5.0).abs() < 1e-4 && (d[2] - 10.0).abs() < 1e-4);
/// ```
pub fn switch_distances(
    errors: &[f32],
    radius: f32,
    camera: &PixelErrorCamera,
) -> Result<Vec<f32>, LodChainError> {
    camera.validate()?;
    check_radius(radius)?;
    if let Some((level, &error)) = errors
        .iter()
        .enumerate()
        .find(|(_, e)| !(e.is_finite() && **e >= 0.0))
    {
        return Err(LodChainError::BadError { level, error });
    }
    let p11 = camera.p11();
    let mut worst = 0.0f32;
    Ok(errors
        .iter()
        .enumerate()
        .map(|(i, &e)| {
            if i == 0 {
                return 0.0;
            }
            worst = worst.max(e);
            let d = min_distance(worst, radius, camera) / p11 + 0.5 * f64::from(camera.hysteresis);
            d as f32
        })
        .collect())
}

/// View-normalized distance from which the whole object (its bounding sphere) covers a disc of at
/// most the pixel error's radius, plus the hysteresis (the fade band before a max distance):
/// `D = R sqrt(1 + (k / p)²)`. A group hidden from there never hides more than that.
pub fn hide_distance(radius: f32, camera: &PixelErrorCamera) -> Result<f32, LodChainError> {
    camera.validate()?;
    check_radius(radius)?;
    let ratio = camera.k() / f64::from(camera.pixel_error);
    let d = f64::from(radius) * (1.0 + ratio * ratio).sqrt() / camera.p11();
    Ok((d + f64::from(camera.hysteresis)) as f32)
}

/// A hysteresis worth selecting with: a tenth of the first switch distance (before the hysteresis
/// itself is added), DigitalRune's 95/105 band; 0 when every level is exact.
pub fn suggested_hysteresis(
    errors: &[f32],
    radius: f32,
    camera: &PixelErrorCamera,
) -> Result<f32, LodChainError> {
    let plain = PixelErrorCamera {
        hysteresis: 0.0,
        ..*camera
    };
    let d = switch_distances(errors, radius, &plain)?;
    Ok(d.iter().copied().find(|&d| d > 0.0).unwrap_or(0.0) * 0.1)
}

/// A [`LodGroup`] whose levels ("lod0", "lod1", ...) switch at [`switch_distances`] and which is
/// hidden beyond [`hide_distance`].
pub fn pixel_error_group(
    errors: &[f32],
    radius: f32,
    camera: &PixelErrorCamera,
) -> Result<LodGroup, LodChainError> {
    let distances = switch_distances(errors, radius, camera)?;
    let levels = distances.iter().enumerate().map(|(i, &distance)| LodLevel {
        distance,
        mesh: format!("lod{i}"),
    });
    let group = LodGroup::new(levels)?;
    let hide = hide_distance(radius, camera)?;
    if hide > 0.0 {
        Ok(group.with_max_distance(hide)?)
    } else {
        Ok(group)
    }
}

fn check_radius(radius: f32) -> Result<(), LodChainError> {
    if radius.is_finite() && radius >= 0.0 {
        Ok(())
    } else {
        Err(LodChainError::BadRadius(radius))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The switch distance puts the bound exactly at the pixel error (an independent check of
    /// the bisection against the closed form).
    #[test]
    fn switch_distance_meets_the_pixel_error() {
        let cam = PixelErrorCamera {
            viewport_height: 720.0,
            pixel_error: 2.0,
            ..Default::default()
        };
        for (e, r) in [(0.01f32, 1.0f32), (0.3, 1.0), (0.001, 5.0)] {
            let d = switch_distances(&[0.0, e], r, &cam).unwrap()[1];
            let px = projected_error(e, r, f64::from(d) * cam.p11(), &cam);
            assert!((px - 2.0).abs() < 1e-4, "e {e} r {r}: {px} px");
        }
    }

    /// Narrower fields of view at the same view-normalized distance see a smaller error.
    #[test]
    fn narrower_fov_keeps_the_bound() {
        let cam = PixelErrorCamera::default();
        let d = f64::from(switch_distances(&[0.0, 0.05], 1.0, &cam).unwrap()[1]);
        for fov in [10f32, 30.0, 59.0] {
            let narrow = PixelErrorCamera {
                fov_y: fov.to_radians(),
                ..cam
            };
            let px = projected_error(0.05, 1.0, d * narrow.p11(), &narrow);
            assert!(px <= 1.0 + 1e-6, "fov {fov}: {px} px");
        }
    }

    #[test]
    fn hysteresis_pushes_every_distance_out_by_half() {
        let cam = PixelErrorCamera::default();
        let plain = switch_distances(&[0.0, 0.01, 0.04], 1.0, &cam).unwrap();
        let banded = switch_distances(
            &[0.0, 0.01, 0.04],
            1.0,
            &PixelErrorCamera {
                hysteresis: 2.0,
                ..cam
            },
        )
        .unwrap();
        assert_eq!(banded[0], 0.0);
        for i in 1..3 {
            assert!((banded[i] - plain[i] - 1.0).abs() < 1e-4);
        }
    }

    #[test]
    fn bad_cameras_are_named() {
        let bad = PixelErrorCamera {
            pixel_error: 0.0,
            ..Default::default()
        };
        assert!(matches!(
            switch_distances(&[0.0], 1.0, &bad),
            Err(LodChainError::BadCamera {
                field: "pixel_error",
                ..
            })
        ));
        let nan = switch_distances(&[0.0, f32::NAN], 1.0, &PixelErrorCamera::default());
        assert!(matches!(nan, Err(LodChainError::BadError { level: 1, .. })));
    }
}
