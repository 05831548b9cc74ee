//! Silhouettes a shader can test per pixel in a few steps: each outline's segments binned by
//! pixel row in a `Rgba32Uint` texture (what GL 3.3, GLSL ES 3.00 and WebGL2 can read, unlike a
//! storage buffer), so that the winding number at a pixel sums only the segments whose y-range
//! reaches its row (a handful) instead of the whole outline; and the convex hull of outlines, the
//! region a combine pass draws over instead of a screen rectangle.

use glam::{UVec4, Vec2};

use super::{Segment, silhouette_crossing, silhouette_distance};

/// How near (pixels) a point must lie to an outline for [`silhouette_covers`] to call it on the
/// outline ([`SILHOUETTE_ON`]): the CPU projects a mesh with other rounding than a GPU's
/// rasterizer, a few millionths of the target's size apart, so a pixel center this near may
/// be covered by one and not by the other.
pub const SILHOUETTE_TIE: f32 = 0.001;

/// What [`silhouette_covers`] answers for a point within [`SILHOUETTE_TIE`] of the outline.
pub const SILHOUETTE_ON: i32 = -1;

/// The largest column the outline table's packed x-range can name.
const MAX_COLUMN: f32 = 65535.0;

/// Texel `index` of a data texture laid out row after row (Rust twin of the shader function of
/// the same name, which reads the texture at `(index % width, index / width)`); zeros past the
/// end.
///
/// ```
/// # use lodkit::silhouette::silhouette_texel;
/// # use glam::UVec4;
/// let data = [[1, 2, 3, 4], [5, 6, 7, 8]];
/// assert_eq!(silhouette_texel(&data, 1), UVec4::new(5, 6, 7, 8));
/// assert_eq!(silhouette_texel(&data, 9), UVec4::ZERO);
/// ```
pub fn silhouette_texel(data: &[[u32; 4]], index: u32) -> UVec4 {
    data.get(index as usize)
        .map_or(UVec4::ZERO, |t| UVec4::from_array(*t))
}

/// Appends an outline to `data` binned by pixel row, for a target `height` pixels tall, and
/// returns its table texel: x the index of its first row's texel, y that row, z the rows, w its
/// columns (the first in the low 16 bits, one past the last in the high ones, both widened by
/// [`SILHOUETTE_TIE`]). Each row's texel holds (index of its first segment, segment count); the
/// segments of a row are those whose y-range, widened by [`SILHOUETTE_TIE`], reaches it, each
/// one texel of f32 bits (x0, y0, x1, y1). Rows outside the target are left out. An empty outline
/// (or one wholly above or below the target) gets no rows.
///
/// ```
/// # use lodkit::silhouette::{bin_silhouette, silhouette_covers};
/// # use glam::Vec2;
/// // A square from (2, 2) to (6, 6).
/// let square = [[2.0, 2.0, 2.0, 6.0], [2.0, 6.0, 6.0, 6.0], [6.0, 6.0, 6.0, 2.0], [6.0, 2.0, 2.0, 2.0]];
/// let mut data = Vec::new();
/// let table = bin_silhouette(&square, 8, &mut data);
/// assert_eq!((table.y, table.z), (1, 6)); // rows 1 ..= 6 (the edges at 2 and 6, widened)
/// assert_eq!(silhouette_covers(&data, table, Vec2::new(4.5, 3.5)), 1);
/// assert_eq!(silhouette_covers(&data, table, Vec2::new(0.5, 3.5)), 0);
/// ```
pub fn bin_silhouette(segments: &[Segment], height: u32, data: &mut Vec<[u32; 4]>) -> UVec4 {
    let start = data.len() as u32;
    let span = |s: &Segment| {
        (
            s[1].min(s[3]) - SILHOUETTE_TIE,
            s[1].max(s[3]) + SILHOUETTE_TIE,
        )
    };
    let (lo, hi) = segments
        .iter()
        .map(span)
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), (a, b)| {
            (lo.min(a), hi.max(b))
        });
    let rows_total = height as f32;
    if segments.is_empty() || hi < 0.0 || lo >= rows_total {
        return UVec4::new(start, 0, 0, 0);
    }
    let first = lo.floor().max(0.0) as u32;
    let last = (hi.floor() as u32).min(height.saturating_sub(1));
    let rows = (last + 1).saturating_sub(first);
    let mut lists: Vec<Vec<u32>> = vec![Vec::new(); rows as usize];
    for (k, s) in segments.iter().enumerate() {
        let (a, b) = span(s);
        let from = a.floor().max(first as f32) as u32;
        let to = (b.floor().max(0.0) as u32).min(last);
        for r in from..=to {
            lists[(r - first) as usize].push(k as u32);
        }
    }
    let mut next = start + rows;
    for list in &lists {
        data.push([next, list.len() as u32, 0, 0]);
        next += list.len() as u32;
    }
    for list in &lists {
        for &k in list {
            data.push(segments[k as usize].map(f32::to_bits));
        }
    }
    let (x0, x1) = segments
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(s[0]).min(s[2]), hi.max(s[0]).max(s[2]))
        });
    let column = |x: f32| x.clamp(0.0, MAX_COLUMN) as u32;
    let columns =
        column((x0 - SILHOUETTE_TIE).floor()) | column((x1 + SILHOUETTE_TIE).ceil()) << 16;
    UVec4::new(start, first, rows, columns)
}

/// Whether the outline whose table is `table` ([`bin_silhouette`]) covers the point `p`
/// (pixels): 1 where its winding number there is not 0, 0 where it is, [`SILHOUETTE_ON`] where
/// `p` lies within [`SILHOUETTE_TIE`] of a segment. Reads the row's texel and its segments only
/// (Rust twin of the shader function of the same name).
pub fn silhouette_covers(data: &[[u32; 4]], table: UVec4, p: Vec2) -> i32 {
    let row = p.y.floor() - table.y as f32;
    let (x0, x1) = ((table.w & 0xffff) as f32, (table.w >> 16) as f32);
    if row < 0.0 || row >= table.z as f32 || p.x < x0 || p.x > x1 {
        return 0;
    }
    let entry = silhouette_texel(data, table.x.wrapping_add(row as u32));
    let mut winding = 0;
    let mut on = false;
    for k in 0..entry.y {
        let s = silhouette_texel(data, entry.x.wrapping_add(k));
        let (a, b) = (
            Vec2::new(f32::from_bits(s.x), f32::from_bits(s.y)),
            Vec2::new(f32::from_bits(s.z), f32::from_bits(s.w)),
        );
        winding += silhouette_crossing(p, a, b);
        on |= silhouette_distance(p, a, b) < SILHOUETTE_TIE;
    }
    if on {
        SILHOUETTE_ON
    } else {
        i32::from(winding != 0)
    }
}

/// The convex hull of `points` grown by `dilate` pixels on every side (the hull of squares of
/// half-side `dilate` around the points), counterclockwise in a y-up frame; empty when the
/// points span no area or any is not finite. A combine pass that draws it as triangles
/// ([`hull_triangles`]) shades every pixel center within `dilate` of the points' hull.
///
/// ```
/// # use lodkit::silhouette::convex_hull;
/// # use glam::Vec2;
/// let points = [Vec2::new(0.0, 0.0), Vec2::new(4.0, 0.0), Vec2::new(2.0, 1.0), Vec2::new(0.0, 4.0)];
/// let hull = convex_hull(&points, 0.0);
/// assert_eq!(hull.len(), 3); // (2, 1) lies inside
/// // The corners' squares: (-1, -1), (5, -1), (5, 1), (1, 5), (-1, 5).
/// assert_eq!(convex_hull(&points, 1.0).len(), 5);
/// ```
pub fn convex_hull(points: &[Vec2], dilate: f32) -> Vec<Vec2> {
    if !dilate.is_finite() || points.iter().any(|p| !p.is_finite()) {
        return Vec::new();
    }
    let d = dilate.max(0.0);
    let mut all: Vec<Vec2> = if d > 0.0 {
        points
            .iter()
            .flat_map(|&p| [(-d, -d), (d, -d), (d, d), (-d, d)].map(|(x, y)| p + Vec2::new(x, y)))
            .collect()
    } else {
        points.to_vec()
    };
    all.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    all.dedup();
    if all.len() < 3 {
        return Vec::new();
    }
    // Andrew's monotone chain: the lower hull left to right, then the upper one back.
    let turn = |o: Vec2, a: Vec2, b: Vec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<Vec2> = Vec::with_capacity(all.len() + 1);
    for pass in 0..2 {
        let floor = hull.len();
        let points: Box<dyn Iterator<Item = &Vec2>> = if pass == 0 {
            Box::new(all.iter())
        } else {
            Box::new(all.iter().rev())
        };
        for &p in points {
            while hull.len() >= floor + 2
                && turn(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop(); // the last point starts the other chain
    }
    if hull.len() < 3 { Vec::new() } else { hull }
}

/// The convex hull of the outlines' end points grown by `dilate` pixels ([`convex_hull`]): where
/// a combine pass must run to reach every pixel the outlines' meshes cover (with `dilate` at
/// least [`SILHOUETTE_TIE`]).
pub fn silhouette_hull(outlines: &[&[Segment]], dilate: f32) -> Vec<Vec2> {
    let points: Vec<Vec2> = outlines
        .iter()
        .flat_map(|o| o.iter())
        .flat_map(|s| [Vec2::new(s[0], s[1]), Vec2::new(s[2], s[3])])
        .collect();
    convex_hull(&points, dilate)
}

/// A convex polygon as a triangle list (a fan from its first corner): three points per triangle.
///
/// ```
/// # use lodkit::silhouette::hull_triangles;
/// # use glam::Vec2;
/// let square = [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y];
/// assert_eq!(hull_triangles(&square).len(), 6);
/// assert!(hull_triangles(&square[..2]).is_empty());
/// ```
pub fn hull_triangles(hull: &[Vec2]) -> Vec<Vec2> {
    (2..hull.len())
        .flat_map(|k| [hull[0], hull[k - 1], hull[k]])
        .collect()
}

/// The area of a polygon (pixels; the shoelace formula, either winding).
///
/// ```
/// # use lodkit::silhouette::polygon_area;
/// # use glam::Vec2;
/// assert_eq!(polygon_area(&[Vec2::ZERO, Vec2::new(4.0, 0.0), Vec2::new(4.0, 3.0)]), 6.0);
/// ```
pub fn polygon_area(polygon: &[Vec2]) -> f32 {
    let n = polygon.len();
    let twice: f32 = (0..n)
        .map(|k| polygon[k].perp_dot(polygon[(k + 1) % n]))
        .sum();
    twice.abs() / 2.0
}
