//! LOD groups, the per-camera state and the selection rule.

use super::LodError;

/// One level of a group: used from `distance` (view-normalized, biased) on.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LodLevel {
    /// Distance from which this level is used.
    pub distance: f32,
    /// Your name for what this level draws (a mesh, a prefab); lodkit only carries it.
    #[serde(default)]
    pub mesh: String,
}

impl LodLevel {
    /// A level at `distance` with no mesh name.
    pub fn at(distance: f32) -> Self {
        Self {
            distance,
            mesh: String::new(),
        }
    }
}

/// How a switch between two levels is staged.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum TransitionMode {
    /// No blend: the level switches at the edges of the hysteresis band (d + h/2 going out,
    /// d - h/2 coming back).
    Hard,
    /// The blend runs across the hysteresis band: transition = (distance - (d - h/2)) / h.
    /// Freezes while the camera stands still inside the band.
    #[default]
    Distance,
    /// The switch is decided at the band edges, then blends over a fixed duration whether or not
    /// the camera moves (Giegl & Wimmer: below one second suffices).
    Time {
        /// Duration of a transition in seconds.
        seconds: f32,
    },
}

/// Settings shared by every group a camera selects for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LodSettings {
    /// Global LOD bias, multiplied with the camera's (default 1; 0 = LOD0, +inf = last LOD).
    pub bias: f32,
    /// Width h of the hysteresis band around each level distance (default 0). Near a group's
    /// max distance it is also the width of the fade-out.
    pub hysteresis: f32,
    /// How switches are staged.
    pub transition: TransitionMode,
}

impl Default for LodSettings {
    fn default() -> Self {
        Self {
            bias: 1.0,
            hysteresis: 0.0,
            transition: TransitionMode::Distance,
        }
    }
}

impl LodSettings {
    /// Checks the values: bias >= 0 (not NaN), hysteresis finite and >= 0, duration > 0.
    ///
    /// ```
    /// # use lodkit::select::{LodSettings, TransitionMode};
    /// assert!(LodSettings::default().validate().is_ok());
    /// assert!(LodSettings { bias: f32::INFINITY, ..Default::default() }.validate().is_ok());
    /// assert!(LodSettings { hysteresis: -1.0, ..Default::default() }.validate().is_err());
    /// let zero = LodSettings { transition: TransitionMode::Time { seconds: 0.0 }, ..Default::default() };
    /// assert!(zero.validate().is_err());
    /// ```
    pub fn validate(&self) -> Result<(), LodError> {
        if self.bias.is_nan() || self.bias < 0.0 {
            return Err(LodError::BadBias(self.bias));
        }
        if !(self.hysteresis.is_finite() && self.hysteresis >= 0.0) {
            return Err(LodError::BadHysteresis(self.hysteresis));
        }
        if let TransitionMode::Time { seconds } = self.transition
            && !(seconds.is_finite() && seconds > 0.0)
        {
            return Err(LodError::BadDuration(seconds));
        }
        Ok(())
    }
}

/// What to draw this frame for one instance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LodSelection {
    /// The level being shown (the outgoing one during a transition).
    pub current: u8,
    /// The level being blended in, during a transition.
    pub next: Option<u8>,
    /// Progress of the transition from `current` to `next`, in [0, 1]; 0 without one.
    pub transition: f32,
    /// Fade near the max draw distance: (max - d) / h inside the last h, else 1.
    pub fade: f32,
    /// False beyond the max draw distance (draw nothing).
    pub visible: bool,
}

impl LodSelection {
    /// Screen-door alphas (DigitalRune): the current level gets -(1 - t) x fade (negative: the
    /// inverted pattern), the next +t x fade. The two patterns never overlap and together cover
    /// `fade` of the pixels. Without a transition: (fade, None).
    ///
    /// ```
    /// # use lodkit::select::LodSelection;
    /// let s = LodSelection { current: 0, next: Some(1), transition: 0.25, fade: 1.0, visible: true };
    /// assert_eq!(s.screen_door_alphas(), (-0.75, Some(0.25)));
    /// ```
    pub fn screen_door_alphas(&self) -> (f32, Option<f32>) {
        match self.next {
            Some(_) => (
                -(1.0 - self.transition) * self.fade,
                Some(self.transition * self.fade),
            ),
            None => (self.fade, None),
        }
    }

    const HIDDEN: LodSelection = LodSelection {
        current: 0,
        next: None,
        transition: 0.0,
        fade: 0.0,
        visible: false,
    };
}

/// The part of the selection that persists between frames, per instance and per camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LodState {
    pub(super) level: u8,
    pub(super) target: u8,
    pub(super) progress: f32,
}

impl LodState {
    /// No history yet: the first selection takes the level for the distance with no transition.
    pub const NEW: LodState = LodState {
        level: u8::MAX,
        target: u8::MAX,
        progress: 0.0,
    };

    /// The level this state has settled on (`None` before the first selection).
    pub fn level(&self) -> Option<u8> {
        (self.level != u8::MAX).then_some(self.level)
    }
}

impl Default for LodState {
    fn default() -> Self {
        Self::NEW
    }
}

/// Levels of one object sorted by distance, and an optional max draw distance.
#[derive(Clone, Debug, PartialEq)]
pub struct LodGroup {
    levels: Vec<LodLevel>,
    max_distance: f32,
}

impl LodGroup {
    /// A group from levels in any order (sorted by distance; equal distances keep their given
    /// order, and of two levels at the same distance only the later is ever selected).
    ///
    /// ```
    /// # use lodkit::select::{LodGroup, LodLevel};
    /// let g = LodGroup::new([LodLevel::at(8.0), LodLevel::at(0.0), LodLevel::at(3.0)]).unwrap();
    /// assert_eq!(g.level_at(5.0), 1);
    /// assert!(LodGroup::new([]).is_err());
    /// ```
    pub fn new(levels: impl IntoIterator<Item = LodLevel>) -> Result<Self, LodError> {
        let mut levels: Vec<LodLevel> = levels.into_iter().collect();
        if levels.is_empty() {
            return Err(LodError::NoLevels);
        }
        if levels.len() > 255 {
            return Err(LodError::TooManyLevels(levels.len()));
        }
        if let Some((index, l)) = levels
            .iter()
            .enumerate()
            .find(|(_, l)| !(l.distance.is_finite() && l.distance >= 0.0))
        {
            return Err(LodError::BadDistance {
                index,
                distance: l.distance,
            });
        }
        levels.sort_by(|a, b| a.distance.total_cmp(&b.distance));
        Ok(Self {
            levels,
            max_distance: f32::INFINITY,
        })
    }

    /// A group from bare distances.
    pub fn from_distances(distances: &[f32]) -> Result<Self, LodError> {
        Self::new(distances.iter().map(|&d| LodLevel::at(d)))
    }

    /// The same group with a max draw distance (beyond it nothing is drawn; within the last h
    /// before it the object fades out).
    ///
    /// ```
    /// # use lodkit::select::LodGroup;
    /// let g = LodGroup::from_distances(&[0.0, 10.0]).unwrap();
    /// assert_eq!(g.clone().with_max_distance(50.0).unwrap().max_distance(), Some(50.0));
    /// assert!(g.with_max_distance(0.0).is_err());
    /// ```
    pub fn with_max_distance(mut self, max_distance: f32) -> Result<Self, LodError> {
        if max_distance.is_nan() || max_distance <= 0.0 {
            return Err(LodError::BadMaxDistance(max_distance));
        }
        self.max_distance = max_distance;
        Ok(self)
    }

    /// The levels, sorted by distance. Selections index into this.
    pub fn levels(&self) -> &[LodLevel] {
        &self.levels
    }

    /// The max draw distance, if any.
    pub fn max_distance(&self) -> Option<f32> {
        self.max_distance.is_finite().then_some(self.max_distance)
    }

    /// The level for `distance` with no hysteresis: the last level whose distance is <= it.
    /// NaN counts as +inf, negative as 0.
    pub fn level_at(&self, distance: f32) -> usize {
        let d = sanitize(distance);
        self.levels[1..]
            .iter()
            .take_while(|l| l.distance <= d)
            .count()
    }

    /// Half-width of the band around boundary `i` (between levels i-1 and i): h/2, shrunk so
    /// that neighbouring bands never overlap.
    fn half_band(&self, i: usize, h: f32) -> f32 {
        let d = self.levels[i].distance;
        let below = d - self.levels[i - 1].distance;
        let above = self
            .levels
            .get(i + 1)
            .map_or(f32::INFINITY, |l| l.distance - d);
        (h.min(below).min(above)) * 0.5
    }

    /// The band `(lo, hi)` around every boundary for hysteresis `h`; index 0 is unused.
    pub(crate) fn bands(&self, h: f32) -> Vec<(f32, f32)> {
        let h = h.max(0.0);
        (0..self.levels.len())
            .map(|i| {
                if i == 0 {
                    return (f32::NEG_INFINITY, f32::NEG_INFINITY);
                }
                let half = self.half_band(i, h);
                (
                    self.levels[i].distance - half,
                    self.levels[i].distance + half,
                )
            })
            .collect()
    }

    /// Selects the level(s) to draw for view-normalized, biased `distance`, updating `state`
    /// (`dt` in seconds drives time-based transitions).
    ///
    /// Documented edge cases: NaN distance counts as +inf (the last level, or hidden beyond a
    /// max distance), negative as 0; a NaN or negative `dt` counts as 0.
    ///
    /// ```
    /// # use lodkit::select::{LodGroup, LodSettings, LodState, TransitionMode};
    /// let g = LodGroup::from_distances(&[0.0, 100.0]).unwrap();
    /// let s = LodSettings { hysteresis: 10.0, transition: TransitionMode::Hard, ..Default::default() };
    /// let mut state = LodState::NEW;
    /// assert_eq!(g.select(99.0, &s, 0.0, &mut state).current, 0);
    /// assert_eq!(g.select(104.0, &s, 0.0, &mut state).current, 0); // inside the band: stays
    /// assert_eq!(g.select(105.0, &s, 0.0, &mut state).current, 1); // switch up at d + h/2
    /// assert_eq!(g.select(96.0, &s, 0.0, &mut state).current, 1);  // stays until d - h/2
    /// assert_eq!(g.select(94.9, &s, 0.0, &mut state).current, 0);
    /// ```
    pub fn select(
        &self,
        distance: f32,
        settings: &LodSettings,
        dt: f32,
        state: &mut LodState,
    ) -> LodSelection {
        let h = settings.hysteresis.max(0.0);
        self.select_banded(distance, settings, dt, state, |i| {
            let half = self.half_band(i, h);
            (
                self.levels[i].distance - half,
                self.levels[i].distance + half,
            )
        })
    }

    /// The selection rule; `band(i)` gives the band (lo, hi) around boundary i >= 1 (computed on
    /// the fly for one instance, precomputed per group by the batch API).
    #[inline(always)]
    pub(crate) fn select_banded(
        &self,
        distance: f32,
        settings: &LodSettings,
        dt: f32,
        state: &mut LodState,
        band: impl Fn(usize) -> (f32, f32),
    ) -> LodSelection {
        let d = sanitize(distance);
        let h = settings.hysteresis.max(0.0);
        if self.max_distance.is_finite() && d >= self.max_distance {
            *state = LodState::NEW;
            return LodSelection {
                current: (self.levels.len() - 1) as u8,
                ..LodSelection::HIDDEN
            };
        }
        let n = self.levels.len();
        let fade_from = self.max_distance - h;
        let hard = settings.transition == TransitionMode::Hard;
        // Fast path: settled on a level and outside every band around it.
        let s = state.level as usize;
        if s < n && state.target == state.level && d < fade_from {
            let above = if s + 1 < n {
                band(s + 1)
            } else {
                (f32::INFINITY, f32::INFINITY)
            };
            let below = if s > 0 {
                band(s)
            } else {
                (f32::NEG_INFINITY, f32::NEG_INFINITY)
            };
            let (from, to) = if hard {
                (below.0, above.1)
            } else {
                (below.1, above.0)
            };
            if d >= from && d < to {
                return LodSelection {
                    current: state.level,
                    next: None,
                    transition: 0.0,
                    fade: 1.0,
                    visible: true,
                };
            }
        }
        let margin = self.max_distance - d;
        let fade = if margin < h { margin / h } else { 1.0 };
        if s >= n {
            let level = self.level_at(d) as u8;
            *state = LodState {
                level,
                target: level,
                progress: 0.0,
            };
        }
        // Stateful hysteresis: move the settled level until d lies in its window.
        // From the level being approached (the settled one outside a timed transition), so that
        // turning back mid-transition also needs the far edge of the band.
        let mut desired = state.target as usize;
        while desired + 1 < n && d >= band(desired + 1).1 {
            desired += 1;
        }
        while desired > 0 && d < band(desired).0 {
            desired -= 1;
        }
        let (current, next, transition) = match settings.transition {
            TransitionMode::Hard => {
                state.level = desired as u8;
                state.target = state.level;
                (desired, None, 0.0)
            }
            TransitionMode::Distance => {
                state.level = desired as u8;
                state.target = state.level;
                band_blend(desired, n, d, &band)
            }
            TransitionMode::Time { seconds } => self.timed(state, desired, seconds, dt),
        };
        LodSelection {
            current: current as u8,
            next: next.map(|n| n as u8),
            transition,
            fade,
            visible: true,
        }
    }

    /// Time-driven transition toward `desired`.
    fn timed(
        &self,
        state: &mut LodState,
        desired: usize,
        seconds: f32,
        dt: f32,
    ) -> (usize, Option<usize>, f32) {
        let desired = desired as u8;
        if state.target != state.level {
            if desired == state.level {
                // Turned back: run the same blend the other way, without a jump.
                std::mem::swap(&mut state.level, &mut state.target);
                state.progress = 1.0 - state.progress;
            } else if desired != state.target {
                // A third level: start over from whichever level dominates now.
                if state.progress >= 0.5 {
                    state.level = state.target;
                }
                state.target = desired;
                state.progress = 0.0;
            }
        } else if desired != state.level {
            state.target = desired;
            state.progress = 0.0;
        }
        if state.target != state.level {
            let step = if dt > 0.0 && seconds > 0.0 {
                dt / seconds
            } else {
                0.0
            };
            state.progress = (state.progress + step).clamp(0.0, 1.0);
            if state.progress >= 1.0 {
                state.level = state.target;
                state.progress = 0.0;
            }
        }
        if state.target == state.level {
            (state.level as usize, None, 0.0)
        } else {
            (
                state.level as usize,
                Some(state.target as usize),
                state.progress,
            )
        }
    }
}

/// Distance-driven blend toward the neighbour of `level` whose band `d` is in.
fn band_blend(
    level: usize,
    n: usize,
    d: f32,
    band: &impl Fn(usize) -> (f32, f32),
) -> (usize, Option<usize>, f32) {
    if level + 1 < n {
        let (lo, hi) = band(level + 1);
        if hi > lo && d >= lo {
            return (
                level,
                Some(level + 1),
                ((d - lo) / (hi - lo)).clamp(0.0, 1.0),
            );
        }
    }
    if level > 0 {
        let (lo, hi) = band(level);
        if hi > lo && d < hi {
            return (
                level,
                Some(level - 1),
                ((hi - d) / (hi - lo)).clamp(0.0, 1.0),
            );
        }
    }
    (level, None, 0.0)
}

/// NaN -> +inf, negative -> 0.
fn sanitize(d: f32) -> f32 {
    if d.is_nan() {
        f32::INFINITY
    } else {
        d.max(0.0)
    }
}
