//! The hand-made answers of the combine_coverage scene (`super::scene`), worked out from its
//! texels, for every language's words and the Rust twins'.

use super::*;

/// Holds the words of one language (or of the Rust twins) to what the scene was made to give,
/// worked out by hand from its texels (not by the code under test).
pub(super) fn check_known(out: &[u32], s: &Scene, who: &str) {
    let pixel = |x: u32, y: u32| &out[at(x, y) * OUT..(at(x, y) + 1) * OUT];
    let color = |w: &[u32], k: usize| Vec4::from_slice(&floats(&w[k..k + 4]));
    let close = |a: Vec4, b: Vec4, tol: f32| (a - b).abs().max_element() <= tol;
    let older = |x: u32, y: u32| s.older.colors[at(x, y)];
    // The combined color at pixel (x, y) is `want` (within 1e-5: one texel or a blend of two).
    let shows = |x: u32, y: u32, want: Vec4, what: String| {
        let got = color(pixel(x, y), 0);
        assert!(
            close(got, want, 1e-5),
            "{who}: pixel ({x}, {y}) shows {got}, not {what}"
        );
    };
    // Silhouette: pixel (3, 5) shows background and reads older background at x 3.8; the older
    // level's silhouette covers it, so it shows that level: its texel (4, 5), 0.7 texel from the
    // ray (the bilinear blend of texels 3 and 4 keeps only 4, the same object's).
    let got = color(pixel(3, 5), 0);
    assert!(
        close(got, older(4, 5), 1e-5),
        "{who}: pixel (3, 5) inside the older silhouette shows {got}, not the older level's {}",
        older(4, 5)
    );
    for (x, want) in [(2, 0), (3, 1), (8, 1), (9, SILHOUETTE_ON as u32), (10, 0)] {
        assert_eq!(
            pixel(x, 5)[15],
            want,
            "{who}: silhouette_covers at pixel ({x}, 5)"
        );
    }
    // On the ray: pixel (14, 3) reads background at x 14.8; the estimated t-instance's texel
    // (13, 3) lies 1.3 texels from the ray, past COMBINE_COVER_REACH: not taken, and the pixel
    // keeps its newer color (closer than the background). At pixel (10, 3) the read x 10.8 has
    // (11, 3) 0.7 texel away: taken.
    assert_eq!(
        pixel(14, 3)[11..13],
        [14, 3],
        "{who}: cover texel at (14, 3)"
    );
    assert_eq!(
        pixel(10, 3)[11..13],
        [11, 3],
        "{who}: cover texel at (10, 3)"
    );
    let got = color(pixel(14, 3), 0);
    let want = s.newer.colors[at(14, 3)];
    assert!(
        close(got, want, 1e-5),
        "{who}: pixel (14, 3) shows {got}, not its newer color {want}"
    );
    // The blend: the read of the silhouette t-instance at pixel (5, 5) lies at x 5.8, y on the
    // texel row's center: 0.7 of texel 5 and 0.3 of texel 6. At (9, 5) (x 9.8) texel 10 is
    // background: texel 9 alone.
    let blend = 0.7 * older(5, 5) + 0.3 * older(6, 5);
    let got = color(pixel(5, 5), 6);
    assert_eq!(pixel(5, 5)[4..6], [5, 5], "{who}: read texel at (5, 5)");
    assert!(
        close(got, blend, 1e-4),
        "{who}: older color at (5, 5) {got}, not the blend {blend}"
    );
    let got = color(pixel(9, 5), 6);
    assert!(
        close(got, older(9, 5), 1e-5),
        "{who}: older color at (9, 5) {got}, not texel 9's {}",
        older(9, 5)
    );
    // Hidden: pixel (6, 7) shows the silhouette t-instance, whose older silhouette covers it,
    // but the read (x 6.8) finds FRONT in front of that level in the older frame (depth 0.9
    // against 0.95), a t-instance whose older level may cover the pixel now (combine_may_cover):
    // the pixel shows FRONT, as last frame did, not the t-instance's own texels around it
    // (combine_hidden).
    shows(
        6,
        7,
        older(6, 7),
        format!("the older object in front, {}", older(6, 7)),
    );
    // Touching: pixel (5, 8) reads x 5.8 and finds FRONT at texel (5, 8), in front of the
    // t-instance's older level by less than COMBINE_HIDDEN_MARGIN: not hidden. The read takes the
    // t-instance's texel (4, 8) (the block's first at 1.3 texels from the ray; (4, 7) ties), whose
    // 2x2 blend holds no texel of it; both levels are shown and have one id: their average.
    let want = 0.5 * (s.newer.colors[at(5, 8)] + older(4, 8));
    let what = format!(
        "the average of its newer color and texel (4, 8), {want} (FRONT's older color: {})",
        older(5, 8)
    );
    shows(5, 8, want, what);
    // Still: pixel (7, 4) shows the silhouette t-instance and reads x 7.8, texel (7, 4), where
    // STILL, in no transition, lay in front of its older level (depth 0.9 against 0.95). STILL is
    // drawn this frame and lost the depth test to the t-instance here: it hides nothing now. The
    // read takes the t-instance's own texels: the 2x2 blend around x 7.8 holds (7, 4) (STILL) at
    // 0.7 and (8, 4) at 0.3, so (8, 4) alone; both levels are shown and have one id: their average.
    let want = 0.5 * (s.newer.colors[at(7, 4)] + older(8, 4));
    let what = format!(
        "the average of its newer color and texel (8, 4), {want} (STILL's older color, as if it \
         hid the level: {})",
        older(7, 4)
    );
    shows(7, 4, want, what);
    // On the outline: pixel (9, 5) shows background, and its center lies on the older
    // silhouette's right edge; the read (x 9.8) finds the level at texel (9, 5), as last frame
    // had it there. Neither the level drawn now nor, where the rasterizer breaks the tie the
    // other way, the older level covers the pixel: it is not taken as covered, and the estimate
    // leaves a level whose coverage is known to its silhouette. The pixel keeps its newer color.
    let want = s.newer.colors[at(9, 5)];
    let what = format!(
        "its newer color {want} (on the older silhouette's outline; the older level's texel \
         there, as last frame's picture has it: {})",
        older(9, 5)
    );
    shows(9, 5, want, what);
    // On the outline of a level that did not move: pixel (1, 9) shows background, its center
    // lies on TIE's older silhouette's left edge, and it reprojects onto the center of texel
    // (1, 9), which holds TIE: last frame's picture sampled this very point and drew the level
    // there. It shows that level (displayed, pattern 0.1), its texel (1, 9) alone.
    let what = format!(
        "the older level's texel there, {} (on a still level's outline; its newer color: {})",
        older(1, 9),
        s.newer.colors[at(1, 9)]
    );
    shows(1, 9, older(1, 9), what);
    // On the outline of a level that moved: pixel (9, 3) shows the silhouette t-instance's level
    // drawn now, not shown this frame, and its center lies on that t-instance's older
    // silhouette's right edge. Its read (x 9.8, 0.3 texel off texel (9, 3)'s center: the camera
    // moved) lands on background: last frame did not sample this point, so the tie is not
    // decided there, and the level drawn now covers the pixel: the older level is taken as
    // covering it. Its own texel in the 3x3 block nearest the ray is (9, 4) (1.0 texel off; (8, 3)
    // and (8, 4) 1.3), whose 2x2 blend around x 9.8 gives it no weight: the pixel shows texel
    // (9, 4), not the background texel (9, 3) on the ray behind the level.
    let what = format!(
        "the older level's texel (9, 4), {} (the background texel behind it: {})",
        older(9, 4),
        older(9, 3)
    );
    shows(9, 3, older(9, 4), what);
    // Behind a level: pixel (3, 8) shows TIE's level drawn now, not shown this frame, outside
    // TIE's older silhouette; the silhouette t-instance's older silhouette covers its center
    // (3.5, 8.5). Its read (x 3.8) finds background at (3, 8); the level's texel (4, 8) lies 0.7
    // texel from the ray, and the 2x2 blend around x 3.8 holds it alone (weight 0.3): the pixel
    // shows that texel, the level behind TIE's, not the background texel (3, 8) TIE's ray lands on.
    let what = format!(
        "the older level behind TIE's, its texel (4, 8), {} (the background texel the ray lands on: {})",
        older(4, 8),
        older(3, 8)
    );
    shows(3, 8, older(4, 8), what);
    // Behind it where no older silhouette covers the pixel: pixel (12, 9), TIE's level drawn now
    // and not shown, outside every silhouette. What lies behind is read on TIE's ray (its matrix
    // the identity): the background texel (12, 9), shown as last frame had it, not the level
    // drawn now.
    let what = format!(
        "the background texel behind TIE's level, {} (TIE's newer color: {})",
        older(12, 9),
        s.newer.colors[at(12, 9)]
    );
    shows(12, 9, older(12, 9), what);
    // combine_hider, for the silhouette t-instance at each pixel's read: FRONT at (6, 7) and STILL
    // at (7, 4) (0.05 in front, clearly closer), none at (5, 8) (FRONT within the margin) nor at
    // (3, 5) (the background).
    for (x, y, want, what) in [
        (6, 7, FRONT, "FRONT"),
        (7, 4, STILL, "STILL"),
        (5, 8, 0, "none"),
        (3, 5, 0, "none"),
    ] {
        assert_eq!(
            pixel(x, y)[25],
            want,
            "{who}: combine_hider at pixel ({x}, {y}), not {what}"
        );
    }
    // combine_may_cover: the silhouette t-instance inside its rectangle or on its outline
    // (pixels 3..=9 x 3..=8), the estimated t-instances (EST, FRONT) everywhere, STILL (no
    // record) and id 0 nowhere.
    for (x, y) in (0..W).flat_map(|x| (0..H).map(move |y| (x, y))) {
        let inside = (3..=9).contains(&x) && (3..=8).contains(&y);
        assert_eq!(
            pixel(x, y)[24],
            u32::from(inside) | 2 | 4,
            "{who}: combine_may_cover at pixel ({x}, {y}) (bits: SIL, EST, FRONT, STILL, id 0)"
        );
    }
    // combine_known_covers: only the silhouette t-instance has a known silhouette, the rectangle
    // from (3, 3) to (9.5, 9), which holds the centers of pixels 3..=8 x 3..=8 and passes through
    // those of column 9 (rows 3..=8), counted as covering; the estimated t-instances (EST,
    // FRONT) and id 0 never.
    for (x, y) in (0..W).flat_map(|x| (0..H).map(move |y| (x, y))) {
        let inside = (3..=9).contains(&x) && (3..=8).contains(&y);
        assert_eq!(
            pixel(x, y)[20],
            u32::from(inside),
            "{who}: combine_known_covers at pixel ({x}, {y}) (bits: SIL, EST, FRONT, id 0)"
        );
    }
    // combine_edge_uv: columns 0 and 1 lie 5.5 and 4.5 texels out, past COMBINE_EDGE_REACH (4):
    // nothing to read; 2..=4 (3.5 to 1.5 out) read the left column's center, x 0.5 / 16; 5 and
    // on lie in the view and keep their uv.
    assert_eq!(COMBINE_EDGE_REACH, 4.0);
    for (x, y) in (0..W).flat_map(|x| (0..H).map(move |y| (x, y))) {
        let w = pixel(x, y);
        let row = (y as f32 + 0.5) / H as f32;
        let want = match x {
            0 | 1 => None,
            2..=4 => Some(Vec2::new(0.5 / W as f32, row)),
            _ => Some(Vec2::new((x as f32 - 5.0) / W as f32, row)),
        };
        let got = (w[23] == 1).then(|| Vec2::from_slice(&floats(&w[21..23])));
        let agree = match (got, want) {
            (Some(g), Some(e)) => (g - e).abs().max_element() <= 1e-6,
            (g, e) => g.is_none() && e.is_none(),
        };
        assert!(
            agree,
            "{who}: combine_edge_uv at pixel ({x}, {y}): {got:?}, not {want:?}"
        );
    }
    // The ray offset of every read is 0.3 texel; the snap keeps 0.3 and takes 0.995 as 1.
    assert!(
        (f32::from_bits(pixel(0, 0)[16]) - 0.3).abs() < 1e-4,
        "{who}: ray offset"
    );
}
