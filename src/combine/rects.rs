//! The screen rectangles of the t-instances, where the combine pass has work to do.

/// A rectangle of pixels (top-left origin), where the combine pass has work to do.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ScreenRect {
    /// Left column.
    pub x: u32,
    /// Top row.
    pub y: u32,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

impl ScreenRect {
    /// Pixels covered.
    pub fn area(&self) -> u64 {
        u64::from(self.width) * u64::from(self.height)
    }

    /// The smallest rectangle holding both.
    pub fn union(&self, other: &ScreenRect) -> ScreenRect {
        let x = self.x.min(other.x);
        let y = self.y.min(other.y);
        let right = (self.x + self.width).max(other.x + other.width);
        let bottom = (self.y + self.height).max(other.y + other.height);
        ScreenRect {
            x,
            y,
            width: right - x,
            height: bottom - y,
        }
    }

    /// The pixels both cover (None when they share none).
    ///
    /// ```
    /// # use lodkit::combine::ScreenRect;
    /// let a = ScreenRect { x: 0, y: 0, width: 10, height: 10 };
    /// let b = ScreenRect { x: 5, y: 8, width: 10, height: 10 };
    /// assert_eq!(a.intersection(&b), Some(ScreenRect { x: 5, y: 8, width: 5, height: 2 }));
    /// assert_eq!(a.intersection(&ScreenRect { x: 10, ..b }), None);
    /// ```
    pub fn intersection(&self, other: &ScreenRect) -> Option<ScreenRect> {
        let (x0, y0) = (self.x.max(other.x), self.y.max(other.y));
        let x1 = (self.x + self.width).min(other.x + other.width);
        let y1 = (self.y + self.height).min(other.y + other.height);
        (x0 < x1 && y0 < y1).then_some(ScreenRect {
            x: x0,
            y: y0,
            width: x1 - x0,
            height: y1 - y0,
        })
    }

    /// Whether pixel (`x`, `y`) lies inside.
    pub fn contains(&self, x: u32, y: u32) -> bool {
        (self.x..self.x + self.width).contains(&x) && (self.y..self.y + self.height).contains(&y)
    }

    /// Whether the two share a pixel.
    pub fn overlaps(&self, other: &ScreenRect) -> bool {
        self.x < other.x + other.width
            && other.x < self.x + self.width
            && self.y < other.y + other.height
            && other.y < self.y + self.height
    }
}

/// `bounds` (object-space min and max) grown by `displacement` on each axis, both ways: the box
/// that holds every vertex of an animated object whose vertex stage moves its vertices at most
/// that far from the rest pose (wind sway, skinning, morph targets). Pass it to [`screen_rect`]
/// for such an object: the combine pass only works inside the rectangles, and a t-instance
/// pixel outside them would show the newer buffer alone.
///
/// ```
/// # use lodkit::combine::displaced_bounds;
/// # use glam::Vec3;
/// // A unit box whose top sways up to 0.3 along x.
/// let (lo, hi) = displaced_bounds((Vec3::splat(-0.5), Vec3::splat(0.5)), Vec3::new(0.3, 0.0, 0.0));
/// assert_eq!((lo.x, hi.x, hi.y), (-0.8, 0.8, 0.5));
/// ```
pub fn displaced_bounds(
    bounds: (glam::Vec3, glam::Vec3),
    displacement: glam::Vec3,
) -> (glam::Vec3, glam::Vec3) {
    let d = displacement.abs();
    (bounds.0 - d, bounds.1 + d)
}

/// The screen rectangle of a t-instance for the combine pass: the box `bounds` (object-space
/// min and max, the union of both LODs' boxes, holding every vertex the vertex stage may move:
/// see [`displaced_bounds`]) under `model` and each of `view_projs` (this
/// frame's and the previous frame's view-projection: where the newer and the older buffer hold
/// it), in a `size` target, dilated by `dilate` pixels and clipped to the target. `None` when it
/// is off screen; the whole target when a corner is behind a camera.
///
/// ```
/// # use lodkit::combine::{ScreenRect, screen_rect};
/// # use glam::{Mat4, Vec3};
/// let vp = glam::camera::rh::proj::directx::perspective(1.0, 1.0, 0.1, 10.0)
///     * glam::camera::rh::view::look_at_mat4(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y);
/// let r = screen_rect((Vec3::splat(-0.5), Vec3::splat(0.5)), Mat4::IDENTITY, &[vp], (100, 100), 1)
///     .unwrap();
/// assert!(r.x > 30 && r.x + r.width < 70 && r.width == r.height);
/// let away = Mat4::from_translation(Vec3::new(100.0, 0.0, 0.0));
/// assert_eq!(screen_rect((Vec3::splat(-0.5), Vec3::splat(0.5)), away, &[vp], (100, 100), 1), None);
/// ```
pub fn screen_rect(
    bounds: (glam::Vec3, glam::Vec3),
    model: glam::Mat4,
    view_projs: &[glam::Mat4],
    size: (u32, u32),
    dilate: u32,
) -> Option<ScreenRect> {
    use glam::{Vec2, Vec3};
    let (lo, hi) = bounds;
    let (w, h) = (size.0.max(1), size.1.max(1));
    let whole = ScreenRect {
        x: 0,
        y: 0,
        width: w,
        height: h,
    };
    let (mut min, mut max) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
    for vp in view_projs {
        let m = *vp * model;
        for i in 0..8 {
            let corner = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            let clip = m * corner.extend(1.0);
            if !clip.is_finite() || clip.w <= 0.0 {
                return Some(whole);
            }
            let ndc = clip.truncate().truncate() / clip.w;
            let pixel = Vec2::new(
                (ndc.x * 0.5 + 0.5) * w as f32,
                (0.5 - ndc.y * 0.5) * h as f32,
            );
            min = min.min(pixel);
            max = max.max(pixel);
        }
    }
    let d = dilate as f32;
    let (x0, y0) = ((min.x - d).floor().max(0.0), (min.y - d).floor().max(0.0));
    let (x1, y1) = (
        (max.x + d).ceil().min(w as f32),
        (max.y + d).ceil().min(h as f32),
    );
    (x0 < x1 && y0 < y1 && !view_projs.is_empty()).then_some(ScreenRect {
        x: x0 as u32,
        y: y0 as u32,
        width: (x1 - x0) as u32,
        height: (y1 - y0) as u32,
    })
}

/// Merges overlapping rectangles into their unions until none overlap, so no pixel is
/// combined twice.
///
/// ```
/// # use lodkit::combine::{ScreenRect, merge_rects};
/// let r = |x, y| ScreenRect { x, y, width: 10, height: 10 };
/// assert_eq!(merge_rects(&[r(0, 0), r(5, 5), r(40, 40)]).len(), 2);
/// ```
pub fn merge_rects(rects: &[ScreenRect]) -> Vec<ScreenRect> {
    let mut out: Vec<ScreenRect> = Vec::new();
    for r in rects.iter().filter(|r| r.area() > 0) {
        let mut merged = *r;
        while let Some(i) = out.iter().position(|o| o.overlaps(&merged)) {
            merged = merged.union(&out.swap_remove(i));
        }
        out.push(merged);
    }
    out
}
