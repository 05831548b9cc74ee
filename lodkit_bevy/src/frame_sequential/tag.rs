//! The per-instance word a level entity carries in Bevy's `MeshTag`, and the main-pass alpha
//! that carries a fragment's LOD-buffer id word: the Rust side of
//! `lodkit_bevy::frame_sequential` (frame_sequential.wesl decodes what [`encode_tag`] packs).
//!
//! Tag layout (32 bits): bits 0..9 the t-instance id (0: an n-instance, drawn normally),
//! 9..20 tau, 20..31 tau_next (both quantized over [-1, 1] in steps of 1/1023, so -1, 0 and 1
//! are exact), bit 31 set when the visibility pattern sticks to the object (else to the screen).
//! Id [`DITHER_TAG_ID`] marks a level drawn with lodkit's complementary screen-door dither
//! instead (the fallback where the combine cannot run): its tau field holds the screen-door
//! alpha (`lodkit::select::LodSelection::screen_door_alphas`).

/// Largest t-instance id a tag holds: ids and their two display-time flags travel through the
/// main pass as a half-float alpha, exact up to 2048 = (511 << 2) | 3 + 1; id 511 is
/// [`DITHER_TAG_ID`].
pub const MAX_TAG_ID: u32 = 510;

/// The id of a tag that draws its level through lodkit's screen-door dither
/// ([`encode_dither_tag`]): the level is an n-instance (alpha untouched, no combine) whose
/// fragments `lodkit::screen_door::screen_door_keep` keeps or discards.
pub const DITHER_TAG_ID: u32 = 511;

const ID_BITS: u32 = 9;
const TAU_BITS: u32 = 11;
const TAU_STEPS: f32 = 1023.0;
const OBJECT_ANCHORED: u32 = 1 << 31;

fn quantize(tau: f32) -> u32 {
    let t = if tau.is_nan() {
        0.0
    } else {
        tau.clamp(-1.0, 1.0)
    };
    ((t + 1.0) * TAU_STEPS).round() as u32
}

/// The tag of a level entity drawn this frame: `id` 0 for an n-instance; `tau` and `tau_next`
/// the visibility thresholds of this frame and the next (`lodkit::frame_sequential::FrameDraw`).
/// `None` when `id` is over [`MAX_TAG_ID`].
pub fn encode_tag(id: u32, tau: f32, tau_next: f32, object_anchored: bool) -> Option<u32> {
    if id > MAX_TAG_ID {
        return None;
    }
    let anchor = if object_anchored { OBJECT_ANCHORED } else { 0 };
    Some(id | (quantize(tau) << ID_BITS) | (quantize(tau_next) << (ID_BITS + TAU_BITS)) | anchor)
}

/// The tag of a level drawn with the complementary screen-door dither at screen-door `alpha`
/// (`-(1 - t)` for the outgoing level, `t` for the incoming one; quantized to 1/1023).
pub fn encode_dither_tag(alpha: f32) -> u32 {
    DITHER_TAG_ID | (quantize(alpha) << ID_BITS)
}

/// The thresholds a tag carries, as the shader decodes them: (id, tau, tau_next, object anchored).
pub fn decode_tag(tag: u32) -> (u32, f32, f32, bool) {
    let mask = (1 << TAU_BITS) - 1;
    let tau = |q: u32| q as f32 / TAU_STEPS - 1.0;
    (
        tag & ((1 << ID_BITS) - 1),
        tau((tag >> ID_BITS) & mask),
        tau((tag >> (ID_BITS + TAU_BITS)) & mask),
        tag & OBJECT_ANCHORED != 0,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn schedule_ends_are_exact_and_steps_are_fine() {
        for tau in [-1.0, -0.0, 0.0, 1.0] {
            let (_, t, _, _) = decode_tag(encode_tag(3, tau, 0.5, false).unwrap());
            assert_eq!(t, tau, "tau {tau}");
        }
        for k in 0..=200 {
            let tau = -1.0 + k as f32 / 100.0;
            let (id, t, n, object) = decode_tag(encode_tag(MAX_TAG_ID, tau, -tau, true).unwrap());
            assert_eq!((id, object), (MAX_TAG_ID, true));
            assert!((t - tau).abs() <= 0.5 / TAU_STEPS + 1e-6, "{tau} -> {t}");
            assert!((n + tau).abs() <= 0.5 / TAU_STEPS + 1e-6, "{tau} -> {n}");
        }
        assert_eq!(encode_tag(MAX_TAG_ID + 1, 1.0, 1.0, false), None);
        assert_eq!(decode_tag(0).0, 0);
        // The dither's id is no t-instance's, and its alpha's ends and sign survive.
        assert_eq!(encode_tag(DITHER_TAG_ID, 0.0, 0.0, false), None);
        for alpha in [-1.0, -0.75, 0.25, 1.0] {
            let (id, a, _, _) = decode_tag(encode_dither_tag(alpha));
            assert_eq!(id, DITHER_TAG_ID);
            assert!(
                (a - alpha).abs() <= 0.5 / TAU_STEPS + 1e-6,
                "{alpha} -> {a}"
            );
        }
        assert_eq!(decode_tag(encode_dither_tag(-1.0)).1, -1.0);
        assert_eq!(decode_tag(encode_dither_tag(1.0)).1, 1.0);
    }
}
