//! Where a transition shows the wrong thing at an object's outline, counted per frame against
//! what each level alone covers: [`see_through`] (an object both levels cover, shown with the
//! background in it) and [`ghosts`] (an object shown where neither level is).
//!
//! A renderer gives the masks its own way: from single-level reference frames (a pixel that is
//! not the background colour), from renders over two backgrounds, or from its LOD buffers' ids.

use super::MetricsError;

/// Checks that the three per-pixel masks have one length.
fn check(fine: &[bool], coarse: &[bool], shown: &[bool]) -> Result<(), MetricsError> {
    for (what, mask) in [("coarse", coarse), ("shown", shown)] {
        if mask.len() != fine.len() {
            return Err(MetricsError::MaskMismatch {
                what,
                len: mask.len(),
                expected: fine.len(),
            });
        }
    }
    Ok(())
}

/// Pixels of one frame that both levels cover (`fine[i] && coarse[i]`: each level alone,
/// drawn with the same camera, covers pixel `i`) where the frame does not show an object
/// (`!shown[i]`): the object seen through during its transition. A technique that keeps every
/// pixel either level covers scores 0.
///
/// ```
/// use lodkit::metrics::see_through;
/// // Four pixels: both levels cover the first two, the fine level alone the third.
/// let fine = [true, true, true, false];
/// let coarse = [true, true, false, false];
/// let shown = [true, false, false, false]; // the frame shows the background at pixels 1..
/// assert_eq!(see_through(&fine, &coarse, &shown).unwrap(), 1); // pixel 1 only
/// ```
pub fn see_through(fine: &[bool], coarse: &[bool], shown: &[bool]) -> Result<usize, MetricsError> {
    check(fine, coarse, shown)?;
    Ok((0..fine.len())
        .filter(|&i| fine[i] && coarse[i] && !shown[i])
        .count())
}

/// Pixels of one frame that neither level covers where the frame shows an object (`shown[i]`):
/// an object drawn where no level of it is, such as a moving object's last position left
/// behind by a reprojection; the mirror of [`see_through`].
///
/// ```
/// use lodkit::metrics::ghosts;
/// let fine = [true, false, false];
/// let coarse = [false, false, false];
/// let shown = [true, true, false]; // pixel 1 shows an object no level covers
/// assert_eq!(ghosts(&fine, &coarse, &shown).unwrap(), 1);
/// ```
pub fn ghosts(fine: &[bool], coarse: &[bool], shown: &[bool]) -> Result<usize, MetricsError> {
    check(fine, coarse, shown)?;
    Ok((0..fine.len())
        .filter(|&i| !fine[i] && !coarse[i] && shown[i])
        .count())
}

/// How far apart two coverage masks of one `width`-pixel-wide frame are, in pixels: the
/// symmetric Hausdorff distance between their covered pixels (the largest distance from a
/// pixel either mask covers to the nearest pixel the other covers), measured between pixel
/// centres. 0 for equal masks (or both empty); infinite when exactly one is empty. Exact
/// Euclidean distance transforms (Felzenszwalb & Huttenlocher's), linear in the pixel count.
///
/// ```
/// use lodkit::metrics::coverage_distance;
/// // 4 x 1 frames: a pixel at x = 0 against one at x = 3.
/// let a = [true, false, false, false];
/// let b = [false, false, false, true];
/// assert_eq!(coverage_distance(&a, &b, 4).unwrap(), 3.0);
/// assert_eq!(coverage_distance(&a, &a, 4).unwrap(), 0.0);
/// ```
pub fn coverage_distance(a: &[bool], b: &[bool], width: usize) -> Result<f32, MetricsError> {
    if b.len() != a.len() {
        return Err(MetricsError::MaskMismatch {
            what: "second",
            len: b.len(),
            expected: a.len(),
        });
    }
    if width == 0 || !a.len().is_multiple_of(width) {
        return Err(MetricsError::MaskMismatch {
            what: "first",
            len: a.len(),
            expected: a.len().div_ceil(width.max(1)) * width.max(1),
        });
    }
    let (any_a, any_b) = (a.iter().any(|&c| c), b.iter().any(|&c| c));
    if !any_a && !any_b {
        return Ok(0.0);
    }
    if !(any_a && any_b) {
        return Ok(f32::INFINITY);
    }
    let to_b = squared_distances(b, width);
    let to_a = squared_distances(a, width);
    let worst = |mask: &[bool], to: &[f64]| {
        mask.iter()
            .zip(to)
            .filter(|(c, _)| **c)
            .map(|(_, d)| *d)
            .fold(0.0f64, f64::max)
    };
    Ok(worst(a, &to_b).max(worst(b, &to_a)).sqrt() as f32)
}

/// Squared Euclidean distance from every pixel to the nearest covered one.
fn squared_distances(mask: &[bool], width: usize) -> Vec<f64> {
    let height = mask.len() / width;
    let far = ((width * width + height * height) as f64) * 4.0 + 1.0;
    let mut d: Vec<f64> = mask.iter().map(|&c| if c { 0.0 } else { far }).collect();
    let mut line = Vec::new();
    for x in 0..width {
        line.clear();
        line.extend((0..height).map(|y| d[y * width + x]));
        let out = transform_1d(&line);
        for (y, v) in out.into_iter().enumerate() {
            d[y * width + x] = v;
        }
    }
    for y in 0..height {
        let out = transform_1d(&d[y * width..(y + 1) * width]);
        d[y * width..(y + 1) * width].copy_from_slice(&out);
    }
    d
}

/// The 1D squared distance transform of sampled function `f`: `min_q (p - q)² + f(q)`, by the
/// lower envelope of parabolas.
fn transform_1d(f: &[f64]) -> Vec<f64> {
    let n = f.len();
    let mut v = vec![0usize; n];
    let mut z = vec![0.0f64; n + 1];
    let mut k = 0usize;
    z[0] = f64::NEG_INFINITY;
    z[1] = f64::INFINITY;
    let meet = |q: usize, p: usize| {
        let (q2, p2) = ((q * q) as f64, (p * p) as f64);
        ((f[q] + q2) - (f[p] + p2)) / (2.0 * (q as f64 - p as f64))
    };
    for q in 1..n {
        let mut s = meet(q, v[k]);
        while s <= z[k] {
            k -= 1;
            s = meet(q, v[k]);
        }
        k += 1;
        v[k] = q;
        z[k] = s;
        z[k + 1] = f64::INFINITY;
    }
    let mut out = vec![0.0; n];
    k = 0;
    for (q, o) in out.iter_mut().enumerate() {
        while z[k + 1] < q as f64 {
            k += 1;
        }
        let dq = q as f64 - v[k] as f64;
        *o = dq * dq + f[v[k]];
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame from a picture, one character a pixel: `F` fine only, `C` coarse only, `B` both, `.` neither;
    /// lower case where the frame shows the background, upper case where it shows an object
    /// (for `.`: `o` an object, `.` background).
    fn frame(rows: &[&str]) -> (Vec<bool>, Vec<bool>, Vec<bool>) {
        let cells: Vec<char> = rows.iter().flat_map(|r| r.chars()).collect();
        let fine = cells.iter().map(|c| "FfBb".contains(*c)).collect();
        let coarse = cells.iter().map(|c| "CcBb".contains(*c)).collect();
        let shown = cells.iter().map(|c| "FCBo".contains(*c)).collect();
        (fine, coarse, shown)
    }

    #[test]
    fn holes_and_ghosts_are_counted_where_they_are() {
        // An object both levels cover in the middle, the fine level wider on the left, with two
        // holes inside and a trail of two ghost pixels on the right.
        let (fine, coarse, shown) = frame(&["FBBb.", "fBbBo", "FBBBo"]);
        assert_eq!(see_through(&fine, &coarse, &shown), Ok(2));
        assert_eq!(ghosts(&fine, &coarse, &shown), Ok(2));
        // A level's own pixels the frame leaves out are neither (a transition may drop them).
        let (fine, coarse, shown) = frame(&["ffcc."]);
        assert_eq!(see_through(&fine, &coarse, &shown), Ok(0));
        assert_eq!(ghosts(&fine, &coarse, &shown), Ok(0));
        // A frame that is exactly one level: nothing.
        let (fine, coarse, shown) = frame(&["FBBC.", "..B.."]);
        assert_eq!(see_through(&fine, &coarse, &shown), Ok(0));
        assert_eq!(ghosts(&fine, &coarse, &shown), Ok(0));
    }

    #[test]
    fn masks_of_other_lengths_are_refused() {
        let err = see_through(&[true; 4], &[true; 4], &[true; 3]).unwrap_err();
        assert_eq!(
            err,
            MetricsError::MaskMismatch {
                what: "shown",
                len: 3,
                expected: 4
            }
        );
        assert!(ghosts(&[true; 4], &[true; 2], &[true; 4]).is_err());
    }

    /// The distance by brute force over every pair of pixels: the independent answer.
    fn brute(a: &[bool], b: &[bool], width: usize) -> f32 {
        let at = |i: usize| ((i % width) as f64, (i / width) as f64);
        let one_way = |from: &[bool], to: &[bool]| {
            (0..from.len())
                .filter(|&i| from[i])
                .map(|i| {
                    (0..to.len())
                        .filter(|&j| to[j])
                        .map(|j| {
                            let (p, q) = (at(i), at(j));
                            ((p.0 - q.0).powi(2) + (p.1 - q.1).powi(2)).sqrt()
                        })
                        .fold(f64::INFINITY, f64::min)
                })
                .fold(0.0, f64::max)
        };
        one_way(a, b).max(one_way(b, a)) as f32
    }

    #[test]
    fn coverage_distance_matches_brute_force() {
        let mut state = 0x1234_5678_u32;
        let mut bit = |p: u32| {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            state % 100 < p
        };
        for (width, height, p) in [
            (13, 7, 10),
            (9, 9, 3),
            (1, 11, 30),
            (17, 1, 20),
            (20, 15, 1),
        ] {
            for _ in 0..20 {
                let a: Vec<bool> = (0..width * height).map(|_| bit(p)).collect();
                let b: Vec<bool> = (0..width * height).map(|_| bit(p)).collect();
                let want = brute(&a, &b, width);
                let got = coverage_distance(&a, &b, width).unwrap();
                assert!(
                    (got - want).abs() <= 1e-5 * want.max(1.0) || got == want,
                    "{width} x {height}: {got} vs {want}"
                );
            }
        }
    }
}
