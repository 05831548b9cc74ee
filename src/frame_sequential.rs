//! The frame-sequential transition scheduler (Scherzer & Wimmer 2008, sec. 3.2, 3.5, 4.1).
//!
//! Instances are n-instances (no transition: drawn normally, id 0) or t-instances (in a
//! transition between two LODs). A t-instance is drawn with ONE of its two LODs per frame,
//! alternating with its own phase: the frame its transition begins, and every other frame after,
//! draw the outgoing LOD, the frames between the incoming. Each draw carries the instance's id,
//! the LOD's visibility threshold tau under the [`Schedule`] (complementary by default, or the
//! paper's Fig. 2) and the threshold the same LOD will have next frame (display-time visibility:
//! the combine shows each LOD as it is at the frame displayed). A transition may begin on any
//! frame: its first frame draws the outgoing LOD whole (both schedules show all of it at
//! progress 0), so the object never drops out of the newer buffer. Its last frame (progress 1)
//! draws the incoming LOD whole whatever the phase: the outgoing one is shown nowhere by then, and
//! drawing it would leave the whole object to last frame's picture, resampled. The combine pass
//! merges this frame's LOD buffer with last frame's. Pure math, no wgpu.
//!
//! ```
//! use lodkit::frame_sequential::{Drive, TransitionScheduler};
//! let mut s = TransitionScheduler::new();
//! let tree = s.insert(0);
//! s.begin_transition(tree, 1, Drive::Time { seconds: 0.5 }).unwrap();
//! s.advance(1.0 / 60.0);
//! let draw = s.draw(tree).unwrap();
//! assert!(draw.id != 0); // a t-instance
//! ```

/// Frames an id waits after its transition ends before it is handed out again: the older LOD
/// buffer still holds it for one frame, and one more keeps a margin.
pub const ID_QUARANTINE_FRAMES: u64 = 2;

/// Handle of an instance in a [`TransitionScheduler`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct InstanceKey {
    index: u32,
    generation: u32,
}

/// How the two LODs of a t-instance share the visibility texture over a transition.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Schedule {
    /// The paper's Fig. 2: the incoming LOD appears over the first half while the outgoing
    /// stays complete, then the outgoing vanishes over the second half. One LOD is always
    /// complete, so the object's interior never shows what is behind it, whatever the combine
    /// knows of the older level's coverage; at silhouettes, where only one LOD covers a pixel,
    /// the change happens within one half of the transition. Take it where the combine estimates
    /// the older level's coverage from last frame's picture (`CombineCoverage::Estimated`):
    /// there the complementary schedule shows the background through an object about twice as
    /// often (docs/frame-sequential.md, "The two schedules").
    Paper,
    /// Complementary (the default): the incoming LOD shows the texels v <= progress, the
    /// outgoing the others
    /// ([`visibility_threshold_complementary`](crate::visibility::visibility_threshold_complementary)).
    /// The change at silhouettes is spread over the whole transition, like a dither; inside the
    /// object, pixels whose two LOD samples are both shown or both hidden show their average.
    /// Made for a combine that knows the older levels' coverage (their silhouettes, the route
    /// docs/frame-sequential.md recommends): there its pop stays within 1.1x a blue-noise
    /// dither's (Fig. 2's reaches 1.4x) and it reverses fewer pixels than
    /// [`Paper`](Self::Paper).
    #[default]
    Complementary,
}

impl Schedule {
    /// Threshold tau of one LOD at `progress`.
    ///
    /// ```
    /// # use lodkit::frame_sequential::Schedule;
    /// assert_eq!(Schedule::Paper.threshold(0.25, false), 1.0);
    /// assert_eq!(Schedule::Complementary.threshold(0.25, false), -0.75);
    /// ```
    pub fn threshold(self, progress: f32, incoming: bool) -> f32 {
        match self {
            Self::Paper => crate::visibility::visibility_threshold(progress, incoming),
            Self::Complementary => {
                crate::visibility::visibility_threshold_complementary(progress, incoming)
            }
        }
    }
}

/// What drives a transition's progress.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Drive {
    /// Progress grows by dt / seconds each frame; the transition ends at 1.
    Time {
        /// Duration in seconds.
        seconds: f32,
    },
    /// The caller sets progress (e.g. from distance, `LodSelection::transition`) with
    /// [`TransitionScheduler::set_progress`]; the transition ends when it reaches 1.
    Progress,
}

/// Why a scheduler call was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ScheduleError {
    /// The key names no live instance (removed, or from another scheduler).
    #[error("no such instance (removed or stale key)")]
    UnknownInstance,
    /// The instance is already in a transition.
    #[error("the instance is already in a transition")]
    AlreadyInTransition,
    /// A duration that is not finite and positive.
    #[error("transition duration {0} s must be finite and > 0")]
    BadDuration(f32),
    /// Every id in `1..=LOD_BUFFER_MAX_ID` (2^30 - 1) is live or quarantined.
    #[error("out of instance ids")]
    OutOfIds,
}

/// How to draw one instance this frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameDraw {
    /// The LOD to draw.
    pub lod: u8,
    /// Instance id to write into the LOD buffer (0 for n-instances).
    pub id: u32,
    /// Visibility threshold this frame
    /// ([`visibility_shown`](crate::visibility::visibility_shown): 1 = all, 0 = none, negative =
    /// the inverted pattern).
    pub tau: f32,
    /// Visibility threshold of the same LOD in the next frame, when this frame's LOD buffer is
    /// the older one (display-time visibility), from the progress the next frame is expected to
    /// have: the last frame's time step for [`Drive::Time`], the last change continued for
    /// [`Drive::Progress`].
    pub tau_next: f32,
    /// Transition progress in [0, 1] (0 for n-instances).
    pub progress: f32,
    /// Whether this draw is the incoming LOD of a transition.
    pub incoming: bool,
}

/// The level of a t-instance that the older LOD buffer holds (the one drawn last frame) and how
/// this frame displays it: what the combine needs of it ([`TransitionScheduler::older`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OlderDraw {
    /// The LOD drawn last frame.
    pub lod: u8,
    /// The t-instance's id.
    pub id: u32,
    /// The threshold at which that level is displayed this frame with the pattern anchored to
    /// the screen: this frame's threshold for the level not drawn now, exactly complementary to
    /// [`FrameDraw::tau`] (`CombineObjectData::older_tau`).
    pub tau: f32,
}

#[derive(Clone, Debug)]
struct Transition {
    from: u8,
    to: u8,
    id: u32,
    progress: f32,
    /// Progress in the frame before.
    previous: f32,
    /// The caller's progress for the next frame (cleared by `advance`).
    next: Option<f32>,
    drive: Drive,
    /// Frame the transition began: its phase.
    start: u64,
}

#[derive(Clone, Debug)]
struct Slot {
    generation: u32,
    live: bool,
    lod: u8,
    transition: Option<Transition>,
}

/// Tracks instances, their transitions, frame parity and instance ids.
#[derive(Clone, Debug)]
pub struct TransitionScheduler {
    frame: u64,
    schedule: Schedule,
    /// The time step of the last `advance`.
    last_dt: f32,
    slots: Vec<Slot>,
    free_slots: Vec<u32>,
    next_id: u32,
    free_ids: std::collections::VecDeque<(u64, u32)>,
}

impl Default for TransitionScheduler {
    fn default() -> Self {
        Self::new()
    }
}

impl TransitionScheduler {
    /// An empty scheduler at frame 0, with [`Schedule::default`] (the complementary schedule).
    ///
    /// ```
    /// # use lodkit::frame_sequential::{Schedule, TransitionScheduler};
    /// assert_eq!(TransitionScheduler::new().schedule(), Schedule::Complementary);
    /// ```
    pub fn new() -> Self {
        Self {
            frame: 0,
            schedule: Schedule::default(),
            last_dt: 0.0,
            slots: Vec::new(),
            free_slots: Vec::new(),
            next_id: 1,
            free_ids: Default::default(),
        }
    }

    /// The scheduler with visibility schedule `schedule` ([`new`](Self::new) takes
    /// [`Schedule::default`], the complementary schedule).
    pub fn with_schedule(schedule: Schedule) -> Self {
        Self {
            schedule,
            ..Self::new()
        }
    }

    /// The visibility schedule.
    pub fn schedule(&self) -> Schedule {
        self.schedule
    }

    /// Changes the visibility schedule (running transitions follow it from this frame on).
    pub fn set_schedule(&mut self, schedule: Schedule) {
        self.schedule = schedule;
    }

    /// The current frame number (advanced by [`advance`](Self::advance)).
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// Which LOD buffer of the pair this frame renders into (0 or 1); the other is the older one.
    pub fn buffer_index(&self) -> usize {
        (self.frame % 2) as usize
    }

    /// Adds an n-instance at `lod`.
    pub fn insert(&mut self, lod: u8) -> InstanceKey {
        let slot = Slot {
            generation: 0,
            live: true,
            lod,
            transition: None,
        };
        match self.free_slots.pop() {
            Some(index) => {
                let s = &mut self.slots[index as usize];
                let generation = s.generation.wrapping_add(1);
                *s = Slot { generation, ..slot };
                InstanceKey { index, generation }
            }
            None => {
                self.slots.push(slot);
                InstanceKey {
                    index: self.slots.len() as u32 - 1,
                    generation: 0,
                }
            }
        }
    }

    fn slot_mut(&mut self, key: InstanceKey) -> Result<&mut Slot, ScheduleError> {
        self.slots
            .get_mut(key.index as usize)
            .filter(|s| s.live && s.generation == key.generation)
            .ok_or(ScheduleError::UnknownInstance)
    }

    fn slot(&self, key: InstanceKey) -> Result<&Slot, ScheduleError> {
        self.slots
            .get(key.index as usize)
            .filter(|s| s.live && s.generation == key.generation)
            .ok_or(ScheduleError::UnknownInstance)
    }

    /// Removes an instance; a transition it was in ends and its id is quarantined.
    pub fn remove(&mut self, key: InstanceKey) -> Result<(), ScheduleError> {
        let frame = self.frame;
        let slot = self.slot_mut(key)?;
        slot.live = false;
        let released = slot.transition.take().map(|t| t.id);
        if let Some(id) = released {
            self.free_ids.push_back((frame, id));
        }
        self.free_slots.push(key.index);
        Ok(())
    }

    fn allocate_id(&mut self) -> Result<u32, ScheduleError> {
        if let Some(&(released, id)) = self.free_ids.front()
            && self.frame >= released + ID_QUARANTINE_FRAMES
        {
            self.free_ids.pop_front();
            return Ok(id);
        }
        if self.next_id == 0 || self.next_id > crate::lod_buffer::LOD_BUFFER_MAX_ID {
            return Err(ScheduleError::OutOfIds);
        }
        let id = self.next_id;
        self.next_id = self.next_id.wrapping_add(1);
        Ok(id)
    }

    /// Starts a transition of `key` from its LOD to `to`. A transition to the LOD it already has
    /// is a no-op.
    pub fn begin_transition(
        &mut self,
        key: InstanceKey,
        to: u8,
        drive: Drive,
    ) -> Result<(), ScheduleError> {
        if let Drive::Time { seconds } = drive
            && !(seconds.is_finite() && seconds > 0.0)
        {
            return Err(ScheduleError::BadDuration(seconds));
        }
        let slot = self.slot(key)?;
        if slot.transition.is_some() {
            return Err(ScheduleError::AlreadyInTransition);
        }
        if slot.lod == to {
            return Ok(());
        }
        let id = self.allocate_id()?;
        let start = self.frame;
        let slot = self.slot_mut(key)?;
        slot.transition = Some(Transition {
            from: slot.lod,
            to,
            id,
            progress: 0.0,
            previous: 0.0,
            next: None,
            drive,
            start,
        });
        Ok(())
    }

    /// Sets the progress of a [`Drive::Progress`] transition (clamped to [0, 1]; NaN counts as 0).
    /// At 1 the transition ends at the next [`advance`](Self::advance). No effect on time-driven
    /// transitions or on instances not in a transition.
    pub fn set_progress(&mut self, key: InstanceKey, progress: f32) -> Result<(), ScheduleError> {
        let slot = self.slot_mut(key)?;
        if let Some(t) = slot
            .transition
            .as_mut()
            .filter(|t| t.drive == Drive::Progress)
        {
            t.progress = if progress.is_nan() {
                0.0
            } else {
                progress.clamp(0.0, 1.0)
            };
        }
        Ok(())
    }

    /// Tells the scheduler the progress `key`'s transition will have next frame, when the caller
    /// knows it (a transition driven by frame count, a scripted one): this frame's LOD is drawn
    /// with the visibility it will have when it is shown as the older buffer. Without it the
    /// next progress is predicted (the last time step, or the last change of progress), and the
    /// first frame of a [`Drive::Progress`] transition predicts no change. Clamped to [0, 1]
    /// (NaN is ignored); valid until the next [`advance`](Self::advance); no effect on instances
    /// not in a transition.
    pub fn set_next_progress(&mut self, key: InstanceKey, next: f32) -> Result<(), ScheduleError> {
        let slot = self.slot_mut(key)?;
        if let Some(t) = slot.transition.as_mut().filter(|_| !next.is_nan()) {
            t.next = Some(next.clamp(0.0, 1.0));
        }
        Ok(())
    }

    /// Starts the next frame: flips the parity, moves time-driven transitions on by `dt` seconds,
    /// and ends transitions that reached 1 (the instance becomes an n-instance at the new LOD and
    /// its id goes into quarantine).
    pub fn advance(&mut self, dt: f32) {
        self.frame += 1;
        let dt = if dt > 0.0 && dt.is_finite() { dt } else { 0.0 };
        self.last_dt = dt;
        let frame = self.frame;
        for slot in self.slots.iter_mut().filter(|s| s.live) {
            let Some(t) = slot.transition.as_mut() else {
                continue;
            };
            if t.progress >= 1.0 {
                slot.lod = t.to;
                self.free_ids.push_back((frame, t.id));
                slot.transition = None;
                continue;
            }
            t.previous = t.progress;
            t.next = None;
            if let Drive::Time { seconds } = t.drive {
                t.progress = (t.progress + dt / seconds).min(1.0);
            }
        }
    }

    /// How to draw `key` this frame: for a t-instance, the outgoing LOD on the frames of its
    /// transition's phase and the incoming one between them, and the incoming one on the frame
    /// its progress reaches 1.
    pub fn draw(&self, key: InstanceKey) -> Result<FrameDraw, ScheduleError> {
        let slot = self.slot(key)?;
        Ok(match &slot.transition {
            None => FrameDraw {
                lod: slot.lod,
                id: 0,
                tau: 1.0,
                tau_next: 1.0,
                progress: 0.0,
                incoming: false,
            },
            Some(t) => {
                let incoming = (self.frame - t.start) % 2 == 1 || t.progress >= 1.0;
                let next = match (t.next, t.drive) {
                    (Some(next), _) => next,
                    (None, Drive::Time { seconds }) => t.progress + self.last_dt / seconds,
                    (None, Drive::Progress) => 2.0 * t.progress - t.previous,
                };
                FrameDraw {
                    lod: if incoming { t.to } else { t.from },
                    id: t.id,
                    tau: self.schedule.threshold(t.progress, incoming),
                    tau_next: self.schedule.threshold(next.clamp(0.0, 1.0), incoming),
                    progress: t.progress,
                    incoming,
                }
            }
        })
    }

    /// The older buffer's level of `key` this frame: None for an n-instance. On the frame its
    /// transition begins that is the level it had (drawn last frame as an n-instance); after
    /// that, the level its transition drew last frame.
    pub fn older(&self, key: InstanceKey) -> Result<Option<OlderDraw>, ScheduleError> {
        let slot = self.slot(key)?;
        let Some(t) = &slot.transition else {
            return Ok(None);
        };
        let draw = self.draw(key)?;
        let lod = if self.frame == t.start {
            t.from
        } else {
            let last = self.frame - 1;
            let incoming = (last - t.start) % 2 == 1 || t.previous >= 1.0;
            if incoming { t.to } else { t.from }
        };
        Ok(Some(OlderDraw {
            lod,
            id: t.id,
            tau: self.schedule.threshold(draw.progress, !draw.incoming),
        }))
    }

    /// Whether `key` is a t-instance.
    pub fn in_transition(&self, key: InstanceKey) -> bool {
        self.slot(key).is_ok_and(|s| s.transition.is_some())
    }

    /// Ids of live t-instances.
    pub fn live_ids(&self) -> Vec<u32> {
        self.slots
            .iter()
            .filter(|s| s.live)
            .filter_map(|s| s.transition.as_ref().map(|t| t.id))
            .collect()
    }
}
