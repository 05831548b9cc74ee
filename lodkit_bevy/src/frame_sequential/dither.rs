//! The fallback where the combine cannot run: lodkit's complementary screen-door dither
//! (DigitalRune's LOD blending). A group in transition draws both levels each frame, the
//! outgoing one with screen-door alpha -(1 - t), the incoming one with +t: disjoint pixels whose
//! union is every pixel the group covers, so nothing behind it shows and the change is spread over
//! the transition instead of one frame. No frame is kept and no combine runs.
//!
//! It serves a camera with MSAA (the combine reads the main pass per pixel, and a multisampled
//! one has no single id per pixel), groups with a blending material (whose alpha cannot carry
//! the combine's id word) and groups with a masked material other than a `StandardMaterial`
//! (whose alpha test the older-level depth pass cannot repeat). On a camera with a prepass, the
//! prepass must drop the same pixels as the main pass, or it would write both levels' depth
//! whole and the main pass could then show neither at a pixel: `FrameSequentialExtension`'s
//! prepass does on a multisampled camera, and so does Bevy's default prepass of a material of
//! the app's own type as `FrameSequentialBindings` gives it (a blending material is not in the
//! prepass); a level whose material has a prepass shader of its own switches at once instead,
//! and so does a group with a blending level on a camera with a prepass but no MSAA (its other
//! levels' prepass is Bevy's there).

use lodkit::select::LodSelection;

use super::tag::encode_dither_tag;

/// Why a group cannot take the combine this frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Fallback {
    /// The combine runs: no fallback.
    None,
    /// Both levels are drawn through the screen-door dither.
    Dither,
    /// The level switches at once (no combine, and a prepass that would draw a dithered level
    /// whole rules the dither out).
    Switch,
}

impl Fallback {
    /// The fallback of a group: `multisampled` camera, a level that `blends`, a camera whose
    /// prepass draws one of the group's levels whole (`prepass_draws_whole`).
    pub(super) fn of(multisampled: bool, blends: bool, prepass_draws_whole: bool) -> Self {
        match (multisampled || blends, prepass_draws_whole) {
            (false, _) => Self::None,
            (true, false) => Self::Dither,
            (true, true) => Self::Switch,
        }
    }
}

/// What the two drawers of a group show through the dither this frame: (level, tag) each, or
/// None (hidden). The first shows the current level (tag 0 when it is shown whole), the second
/// the incoming one during a transition.
pub(super) fn dither_draws(selection: &LodSelection) -> [Option<(u8, u32)>; 2] {
    if !selection.visible {
        return [None, None];
    }
    let (current, next) = selection.screen_door_alphas();
    let tag = |alpha: f32| {
        if alpha >= 1.0 {
            0
        } else {
            encode_dither_tag(alpha)
        }
    };
    [
        Some((selection.current, tag(current))),
        selection
            .next
            .zip(next)
            .map(|(level, alpha)| (level, tag(alpha))),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame_sequential::tag::{DITHER_TAG_ID, decode_tag};

    /// The alphas the shader's screen_door_keep takes, decoded from the tags.
    fn alphas(draws: [Option<(u8, u32)>; 2]) -> [Option<(u8, u32, f32)>; 2] {
        draws.map(|d| {
            d.map(|(level, tag)| {
                let (id, alpha, _, _) = decode_tag(tag);
                (level, id, alpha)
            })
        })
    }

    #[test]
    fn a_transition_draws_both_levels_with_complementary_alphas() {
        let selection = LodSelection {
            current: 1,
            next: Some(2),
            transition: 0.25,
            fade: 1.0,
            visible: true,
        };
        let [a, b] = alphas(dither_draws(&selection));
        let (a, b) = (a.unwrap(), b.unwrap());
        assert_eq!((a.0, a.1, b.0, b.1), (1, DITHER_TAG_ID, 2, DITHER_TAG_ID));
        // -(1 - t) and +t, to the tag's 1/1023 steps.
        assert!((a.2 + 0.75).abs() <= 0.5 / 1023.0 + 1e-6, "{a:?}");
        assert!((b.2 - 0.25).abs() <= 0.5 / 1023.0 + 1e-6, "{b:?}");
    }

    #[test]
    fn a_settled_group_draws_one_level_whole_and_a_hidden_one_nothing() {
        let settled = LodSelection {
            current: 2,
            next: None,
            transition: 0.0,
            fade: 1.0,
            visible: true,
        };
        assert_eq!(dither_draws(&settled), [Some((2, 0)), None]);
        let hidden = LodSelection {
            visible: false,
            ..settled
        };
        assert_eq!(dither_draws(&hidden), [None, None]);
    }

    #[test]
    fn the_fallback_is_the_dither_unless_a_prepass_draws_a_level_whole() {
        assert_eq!(Fallback::of(false, false, true), Fallback::None);
        assert_eq!(Fallback::of(true, false, false), Fallback::Dither);
        assert_eq!(Fallback::of(false, true, false), Fallback::Dither);
        assert_eq!(Fallback::of(true, true, true), Fallback::Switch);
    }
}
