//! The transition techniques the demo compares.

use lodkit::frame_sequential::Schedule;
use lodkit::gpu::transition_scene::SingleFrameTechnique;
use lodkit::screen_door::DitherPattern;
use lodkit::visibility::{VisibilityPattern, VisibilitySpace};

/// Patterns fixed on the screen.
pub(super) const SCREEN: VisibilitySpace = VisibilitySpace::Screen;
/// Patterns fixed on the objects.
pub(super) const OBJECT: VisibilitySpace = VisibilitySpace::Object;

/// A transition technique of the harness.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Technique {
    /// A single-frame technique.
    Single(SingleFrameTechnique),
    /// Frame-sequential interpolation with a visibility pattern, schedule and pattern space.
    FrameSequential(VisibilityPattern, Schedule, VisibilitySpace),
}

impl Technique {
    /// Every technique the harness compares.
    pub const ALL: [Technique; 9] = [
        Technique::Single(SingleFrameTechnique::HardSwitch),
        Technique::Single(SingleFrameTechnique::CrossFade),
        Technique::Single(SingleFrameTechnique::Dither(DitherPattern::Bayer4x4)),
        Technique::Single(SingleFrameTechnique::Dither(DitherPattern::BlueNoise16x16)),
        Technique::Single(SingleFrameTechnique::Unpopping),
        Technique::FrameSequential(VisibilityPattern::WhiteNoise, Schedule::Paper, SCREEN),
        Technique::FrameSequential(VisibilityPattern::BlueNoise, Schedule::Paper, SCREEN),
        Technique::FrameSequential(
            VisibilityPattern::BlueNoise,
            Schedule::Complementary,
            SCREEN,
        ),
        Technique::FrameSequential(VisibilityPattern::BlueNoise, Schedule::Paper, OBJECT),
    ];

    /// Short name for tables and file names.
    pub fn name(self) -> &'static str {
        match self {
            Technique::Single(t) => t.name(),
            Technique::FrameSequential(_, _, OBJECT) => "frame-seq-object-space",
            Technique::FrameSequential(p, Schedule::Paper, _) => match p {
                VisibilityPattern::WhiteNoise => "frame-seq-white-noise",
                VisibilityPattern::BlueNoise => "frame-seq-blue-noise",
                VisibilityPattern::Radial => "frame-seq-radial",
            },
            Technique::FrameSequential(p, Schedule::Complementary, _) => match p {
                VisibilityPattern::WhiteNoise => "frame-seq-compl-white-noise",
                VisibilityPattern::BlueNoise => "frame-seq-complementary",
                VisibilityPattern::Radial => "frame-seq-compl-radial",
            },
        }
    }
}
