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
}
