//! Unpopping LOD transitions (Giegl & Wimmer 2007): during a transition one LOD is always drawn
//! opaque with depth writes, so the scene behind never shows through; the other is alpha-blended
//! with depth test and no depth writes. Roles swap at t = 0.5 (their Fig. 2).
//!
//! Rust twins of `lodkit::unpopping`, plus the render states an engine maps onto its pipelines.

/// Alpha of a LOD at transition progress `t` (clamped to [0, 1]; NaN counts as 0 here, while on
/// the GPU it is implementation-defined): the outgoing LOD is opaque
/// (1) for t < 0.5 and then fades as 2(1 - t); the incoming fades in as 2t and is opaque from
/// t = 0.5 on. At t = 0.5 both are 1.
///
/// ```
/// # use lodkit::unpopping::unpopping_alpha;
/// assert_eq!(unpopping_alpha(0.25, true), 0.5);
/// assert_eq!(unpopping_alpha(0.25, false), 1.0);
/// assert_eq!(unpopping_alpha(0.75, false), 0.5);
/// assert_eq!(unpopping_alpha(0.5, true), unpopping_alpha(0.5, false));
/// ```
pub fn unpopping_alpha(t: f32, incoming: bool) -> f32 {
    // NaN counts as 0 (the shaders' clamp of NaN is implementation-defined: pass a number).
    let s = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    if incoming {
        (2.0 * s).min(1.0)
    } else {
        (2.0 * (1.0 - s)).min(1.0)
    }
}

/// Whether a LOD is the opaque, depth-writing one at progress `t`: the outgoing for t < 0.5,
/// the incoming from t = 0.5 on. Exactly one of the two is, at every t.
///
/// ```
/// # use lodkit::unpopping::unpopping_is_opaque;
/// assert!(unpopping_is_opaque(0.49, false) && !unpopping_is_opaque(0.49, true));
/// assert!(unpopping_is_opaque(0.5, true) && !unpopping_is_opaque(0.5, false));
/// ```
pub fn unpopping_is_opaque(t: f32, incoming: bool) -> bool {
    // NaN counts as 0 (the outgoing LOD stays opaque), as in unpopping_alpha.
    let late = t >= 0.5;
    if incoming { late } else { !late }
}

/// Render state of one LOD in a transition.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LodRenderState {
    /// Constant alpha to blend with (1 when opaque).
    pub alpha: f32,
    /// Whether the LOD is depth-tested (always true here; kept so engines map it explicitly).
    pub depth_test: bool,
    /// Whether the LOD writes depth.
    pub depth_write: bool,
    /// Whether the LOD is alpha-blended (false: drawn opaque).
    pub blend: bool,
}

impl LodRenderState {
    /// Drawn opaque: depth-tested, writing depth, not blended.
    pub const OPAQUE: LodRenderState = LodRenderState {
        alpha: 1.0,
        depth_test: true,
        depth_write: true,
        blend: false,
    };
}

/// Which of the two LODs of a transition.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LodRole {
    /// The LOD being replaced (`LodSelection::current`).
    Outgoing,
    /// The LOD being blended in (`LodSelection::next`).
    Incoming,
}

/// How to draw both LODs of a transition at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TransitionPlan {
    /// State of the outgoing LOD.
    pub outgoing: LodRenderState,
    /// State of the incoming LOD.
    pub incoming: LodRenderState,
    /// Draw order: the opaque LOD first (it provides the depth the blended one tests against),
    /// then the blended one, after the scene's other opaque objects.
    pub order: [LodRole; 2],
}

impl TransitionPlan {
    /// The state of `role`.
    pub fn state(&self, role: LodRole) -> LodRenderState {
        match role {
            LodRole::Outgoing => self.outgoing,
            LodRole::Incoming => self.incoming,
        }
    }
}

fn blended(alpha: f32) -> LodRenderState {
    LodRenderState {
        alpha,
        depth_test: true,
        depth_write: false,
        blend: true,
    }
}

/// The unpopping plan at progress `t` (Giegl & Wimmer 2007, Fig. 2).
///
/// ```
/// # use lodkit::unpopping::{unpopping_plan, LodRole};
/// let p = unpopping_plan(0.3);
/// assert!(p.outgoing.depth_write && !p.incoming.depth_write);
/// assert_eq!(p.order, [LodRole::Outgoing, LodRole::Incoming]);
/// assert!((p.incoming.alpha - 0.6).abs() < 1e-6);
/// ```
pub fn unpopping_plan(t: f32) -> TransitionPlan {
    let state = |incoming| {
        if unpopping_is_opaque(t, incoming) {
            LodRenderState::OPAQUE
        } else {
            blended(unpopping_alpha(t, incoming))
        }
    };
    let order = if unpopping_is_opaque(t, false) {
        [LodRole::Outgoing, LodRole::Incoming]
    } else {
        [LodRole::Incoming, LodRole::Outgoing]
    };
    TransitionPlan {
        outgoing: state(false),
        incoming: state(true),
        order,
    }
}

/// The conventional (alpha, 1 - alpha) cross-fade, for comparison: the outgoing LOD at 1 - t, the
/// incoming at t, both blended without depth writes, so the background shows through mid-way.
pub fn cross_fade_plan(t: f32) -> TransitionPlan {
    let s = t.clamp(0.0, 1.0);
    TransitionPlan {
        outgoing: blended(1.0 - s),
        incoming: blended(s),
        order: [LodRole::Outgoing, LodRole::Incoming],
    }
}
