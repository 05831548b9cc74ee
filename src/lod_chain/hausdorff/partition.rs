//! The bound of one source triangle from the target triangles under it.
//!
//! The source triangle `S` is cut into convex pieces by the outlines of the candidate target
//! triangles projected onto `S`'s plane (along its normal), nearest candidate first: the piece
//! under candidate `t` is bounded by `max over the piece's corners of d(corner, t)`, which holds
//! for any convex piece and any one triangle (`d(., t)` is convex). What no candidate's
//! projection covers (an open border, a fold, a candidate list too short) is bounded by the best
//! single candidate over each left-over piece. The pieces cover `S` whatever the candidates
//! are (each cut gives both sides), so the result is an upper bound of `sup_S d(x, target)`;
//! the candidates only decide how tight. Where the target is a height field over `S` and each
//! piece's candidate is the nearest triangle to it, the bound is the distance itself, up to the
//! slope between the two surfaces.

use glam::{DVec2, DVec3};

use super::point_triangle_distance2;
use super::surface::Corners;

/// Most corners a piece may have (a triangle cut by a few lines); a piece that would need more
/// gives the partition up ([`partition_bound`] returns `None`).
const MAX_CORNERS: usize = 10;

/// Distance from a cut line, relative to the source triangle's longest side, below which a
/// corner counts as on the line: far above the rounding of the cuts (1e-16), far below any
/// distance that matters.
const FLAT: f64 = 1e-9;

/// `S`'s plane: a point of it and two orthonormal directions in it.
struct Frame {
    origin: DVec3,
    u: DVec3,
    w: DVec3,
}

impl Frame {
    fn to_plane(&self, p: DVec3) -> DVec2 {
        let d = p - self.origin;
        DVec2::new(d.dot(self.u), d.dot(self.w))
    }

    fn to_space(&self, q: DVec2) -> DVec3 {
        self.origin + self.u * q.x + self.w * q.y
    }
}

/// Which target triangles can cut a source triangle's partition: those within `margin` of its
/// plane whose projections overlap its own (the candidates a flood keeps).
pub(super) struct Under {
    frame: Frame,
    normal: DVec3,
    whole: Piece,
    lo: DVec2,
    hi: DVec2,
    margin: f64,
}

impl Under {
    /// `None` for a triangle of zero area (no plane).
    pub(super) fn new(s: &Corners, margin: f64) -> Option<Under> {
        let normal = (s[1] - s[0]).cross(s[2] - s[0]);
        if normal.length_squared() == 0.0 {
            return None;
        }
        let normal = normal.normalize();
        let u = (s[1] - s[0]).normalize();
        let frame = Frame {
            origin: s[0],
            u,
            w: normal.cross(u),
        };
        let q = s.map(|p| frame.to_plane(p));
        let grow = DVec2::splat(FLAT * super::longest_side(s));
        let mut whole = Piece::new();
        for c in q {
            whole.push(c).ok()?;
        }
        Some(Under {
            lo: q[0].min(q[1]).min(q[2]) - grow,
            hi: q[0].max(q[1]).max(q[2]) + grow,
            frame,
            normal,
            whole,
            margin,
        })
    }

    /// Whether the triangle `t` is within the margin of the plane, over or under the triangle
    /// (its projection overlapping the triangle's; one of zero area, its box meeting the
    /// triangle's).
    pub(super) fn holds(&self, t: &Corners) -> bool {
        let h = t.map(|p| (p - self.frame.origin).dot(self.normal));
        if h[0].min(h[1]).min(h[2]) > self.margin || h[0].max(h[1]).max(h[2]) < -self.margin {
            return false;
        }
        let (q, area) = project(&self.frame, t);
        let (lo, hi) = (q[0].min(q[1]).min(q[2]), q[0].max(q[1]).max(q[2]));
        if lo.cmpgt(self.hi).any() || hi.cmplt(self.lo).any() {
            return false;
        }
        area == 0.0 || overlaps(&self.whole, &q, 0.0)
    }
}

/// A convex piece of `S`, counter-clockwise in plane coordinates.
#[derive(Clone, Copy)]
struct Piece {
    len: usize,
    corners: [DVec2; MAX_CORNERS],
    /// The corners' box (a candidate whose box is apart is not weighed further).
    lo: DVec2,
    hi: DVec2,
}

impl Piece {
    fn new() -> Self {
        Piece {
            len: 0,
            corners: [DVec2::ZERO; MAX_CORNERS],
            lo: DVec2::INFINITY,
            hi: DVec2::NEG_INFINITY,
        }
    }

    fn corners(&self) -> &[DVec2] {
        &self.corners[..self.len]
    }

    fn push(&mut self, c: DVec2) -> Result<(), Overflow> {
        *self.corners.get_mut(self.len).ok_or(Overflow)? = c;
        self.len += 1;
        self.lo = self.lo.min(c);
        self.hi = self.hi.max(c);
        Ok(())
    }

    /// Largest squared distance from the piece's corners to `t`, and the corner where it is.
    fn bound(&self, frame: &Frame, t: &Corners) -> (f64, DVec3) {
        self.corners()
            .iter()
            .map(|&c| {
                let x = frame.to_space(c);
                (point_triangle_distance2(x, t[0], t[1], t[2]), x)
            })
            .fold((-1.0, DVec3::ZERO), |a, b| if b.0 > a.0 { b } else { a })
    }

    /// The piece, `None` when it has less than three corners (a point or a segment of the cut
    /// line, which the other side holds too).
    fn nonempty(self) -> Option<Piece> {
        (self.len >= 3).then_some(self)
    }
}

/// A piece needed more than [`MAX_CORNERS`] corners.
struct Overflow;

/// `piece` cut by the line where `side` is zero: the part where it is >= 0 and the part where it
/// is <= 0, each `None` when empty. A corner within `flat` of the line counts as on it (both
/// parts get it): a corner made on a line by one cut is then on it for another candidate's edge
/// along the same line, and no sliver is cut. Both parts share the same chord, so they cover
/// the piece whatever `flat` is.
fn cut(
    piece: &Piece,
    side: impl Fn(DVec2) -> f64,
    flat: f64,
) -> Result<(Option<Piece>, Option<Piece>), Overflow> {
    let corners = piece.corners();
    let mut s = [0.0; MAX_CORNERS];
    for (s, &c) in s.iter_mut().zip(corners) {
        let x = side(c);
        *s = if x.abs() <= flat { 0.0 } else { x };
    }
    let s = &s[..corners.len()];
    if s.iter().all(|&x| x >= 0.0) {
        return Ok((Some(*piece), None));
    }
    if s.iter().all(|&x| x <= 0.0) {
        return Ok((None, Some(*piece)));
    }
    let (mut inside, mut outside) = (Piece::new(), Piece::new());
    for k in 0..corners.len() {
        let next = (k + 1) % corners.len();
        let (a, sa, sb) = (corners[k], s[k], s[next]);
        if sa >= 0.0 {
            inside.push(a)?;
        }
        if sa <= 0.0 {
            outside.push(a)?;
        }
        if (sa > 0.0 && sb < 0.0) || (sa < 0.0 && sb > 0.0) {
            let x = a + (corners[next] - a) * (sa / (sa - sb));
            inside.push(x)?;
            outside.push(x)?;
        }
    }
    Ok((inside.nonempty(), outside.nonempty()))
}

/// `t`'s corners in `frame`'s plane, counter-clockwise, and twice its projected area (zero for
/// a segment or a point).
fn project(frame: &Frame, t: &Corners) -> ([DVec2; 3], f64) {
    let mut q = t.map(|p| frame.to_plane(p));
    let area = cross(q[0], q[1], q[2]);
    if area < 0.0 {
        q.swap(1, 2);
    }
    (q, area.abs())
}

/// `(b - a) x (p - a)`: positive when `p` is left of the line from `a` to `b`.
fn cross(a: DVec2, b: DVec2, p: DVec2) -> f64 {
    (b - a).perp_dot(p - a)
}

/// Whether the convex `piece` and the counter-clockwise triangle `q` overlap by more than a
/// sliver (separating axes: an edge of either with the other wholly on its outside, or within
/// `flat` of it).
fn overlaps(piece: &Piece, q: &[DVec2; 3], flat: f64) -> bool {
    let corners = piece.corners();
    for k in 0..3 {
        let (a, b) = (q[k], q[(k + 1) % 3]);
        let flat = flat * (b - a).length();
        if corners.iter().all(|&c| cross(a, b, c) <= flat) {
            return false;
        }
    }
    for k in 0..corners.len() {
        let (a, b) = (corners[k], corners[(k + 1) % corners.len()]);
        let flat = flat * (b - a).length();
        if q.iter().all(|&p| cross(a, b, p) <= flat) {
            return false;
        }
    }
    true
}

/// The bound of one source triangle: its value, and the point of `S` where it is reached.
#[derive(Clone, Copy, Debug)]
pub(super) struct PartitionBound {
    /// Upper bound of `sup_S d(x, target)`.
    pub bound: f64,
    /// The corner of the piece that gave the bound (a point of `S`).
    pub at: DVec3,
}

/// A candidate projected onto `S`'s plane: its distance from the plane (at its centroid), its
/// corners counter-clockwise in the plane, and the triangle.
type Projected<'a> = (f64, [DVec2; 3], &'a Corners);

/// Upper bound of `sup_{x in S} d(x, target)` for the triangle `s`, from `candidates` (target
/// triangles, any order: those nearest to `S`'s plane cut first). `None` when a piece needs too
/// many corners or a left-over piece has no candidate to bound it; the caller then bounds `S`
/// another way.
pub(super) fn partition_bound(s: Corners, candidates: &[Corners]) -> Option<PartitionBound> {
    let normal = (s[1] - s[0]).cross(s[2] - s[0]);
    if normal.length_squared() == 0.0 {
        // A triangle of zero area is the segment its corners span: bounded as a whole.
        return whole_bound(s, candidates);
    }
    let n = normal.normalize();
    let u = (s[1] - s[0]).normalize();
    let frame = Frame {
        origin: s[0],
        u,
        w: n.cross(u),
    };
    let flat = FLAT * super::longest_side(&s);
    let mut whole = Piece::new();
    for p in s {
        whole.push(frame.to_plane(p)).ok()?;
    }
    let (lo, hi) = whole
        .corners()
        .iter()
        .fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(lo, hi), &c| {
            (lo.min(c), hi.max(c))
        });
    let mut projected: Vec<Projected> = candidates
        .iter()
        .filter_map(|t| {
            let (q, area) = project(&frame, t);
            let (qlo, qhi) = (q[0].min(q[1]).min(q[2]), q[0].max(q[1]).max(q[2]));
            if qlo.cmpge(hi).any() || qhi.cmple(lo).any() || area == 0.0 {
                return None;
            }
            let height = ((t[0] + t[1] + t[2]) / 3.0 - s[0]).dot(n).abs();
            Some((height, q, t))
        })
        .collect();
    projected.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    // The pieces no candidate has covered yet. A candidate cuts only the pieces it overlaps:
    // the part outside each of its edges stays (in place of the piece, or at the end), the part
    // inside all three is bounded by it and leaves.
    let mut left = vec![whole];
    let mut best = (-1.0, s[0]);
    for (_, q, t) in &projected {
        let count = left.len();
        let mut removed = false;
        let (qlo, qhi) = (q[0].min(q[1]).min(q[2]), q[0].max(q[1]).max(q[2]));
        for k in 0..count {
            let piece = &left[k];
            if qlo.cmpge(piece.hi).any() || qhi.cmple(piece.lo).any() || !overlaps(piece, q, flat) {
                continue;
            }
            let mut inside = Some(left[k]);
            let mut kept = false;
            for e in 0..3 {
                let (a, b) = (q[e], q[(e + 1) % 3]);
                let Some(p) = inside else { break };
                let (i, o) = cut(&p, |x| cross(a, b, x), flat * (b - a).length()).ok()?;
                if let Some(o) = o {
                    if kept {
                        left.push(o);
                    } else {
                        left[k] = o;
                        kept = true;
                    }
                }
                inside = i;
            }
            if !kept {
                left[k].len = 0;
                removed = true;
            }
            if let Some(p) = inside {
                let b = p.bound(&frame, t);
                if b.0 > best.0 {
                    best = b;
                }
            }
        }
        if removed {
            left.retain(|p| p.len > 0);
        }
        if left.is_empty() {
            break;
        }
    }
    // What no candidate covered: each left-over piece bounded by its best candidate.
    for piece in &left {
        let b = candidates
            .iter()
            .map(|t| piece.bound(&frame, t))
            .min_by(|a, b| a.0.total_cmp(&b.0))?;
        if b.0 > best.0 {
            best = b;
        }
    }
    Some(PartitionBound {
        bound: best.0.sqrt(),
        at: best.1,
    })
}

/// The bound of a triangle of zero area by its best single candidate.
fn whole_bound(s: Corners, candidates: &[Corners]) -> Option<PartitionBound> {
    candidates
        .iter()
        .map(|t| {
            s.iter()
                .map(|&x| (point_triangle_distance2(x, t[0], t[1], t[2]), x))
                .fold((-1.0, s[0]), |a, b| if b.0 > a.0 { b } else { a })
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(d2, at)| PartitionBound {
            bound: d2.sqrt(),
            at,
        })
}

#[cfg(test)]
mod tests {
    use super::super::Surface;
    use super::*;

    /// A triangle parallel to a flat grid, 0.1 above it, over many grid triangles: the partition
    /// bound is the height itself (every piece lies over one grid triangle), where the convex
    /// bound with any one grid triangle is far larger.
    #[test]
    fn partition_over_a_flat_grid_is_the_height() {
        let n = 20u32;
        let mut p = Vec::new();
        let mut idx = Vec::new();
        for y in 0..=n {
            for x in 0..=n {
                p.push([x as f32 / n as f32, y as f32 / n as f32, 0.0]);
            }
        }
        for y in 0..n {
            for x in 0..n {
                let k = y * (n + 1) + x;
                idx.extend([k, k + 1, k + n + 2, k, k + n + 2, k + n + 1]);
            }
        }
        let s = Surface::new(&p, &idx);
        let tri = [
            DVec3::new(0.13, 0.11, 0.1),
            DVec3::new(0.71, 0.23, 0.1),
            DVec3::new(0.33, 0.87, 0.1),
        ];
        let c: Vec<Corners> = s.candidates(&tri, 0.2).map(|t| t.corners).collect();
        assert!(c.len() > 100, "{} candidates", c.len());
        let b = partition_bound(tri, &c).expect("a bound");
        // The corners are 0.1 above the grid (in f64).
        assert!((b.bound - 0.1).abs() < 1e-9, "{}", b.bound);
        let single = c
            .iter()
            .map(|t| {
                tri.iter()
                    .map(|&x| point_triangle_distance2(x, t[0], t[1], t[2]).sqrt())
                    .fold(0.0, f64::max)
            })
            .fold(f64::INFINITY, f64::min);
        // Measured 0.417: the best single grid triangle is four times as loose.
        assert!(single > 3.0 * b.bound, "{single}");
    }
}
