//! The transition techniques the demo compares.

use lodkit::frame_sequential::Schedule;
use lodkit::screen_door::DitherPattern;
use lodkit::visibility::{VisibilityPattern, VisibilitySpace};
use lodkit_scenes::transition::SingleFrameTechnique;

const WHITE: VisibilityPattern = VisibilityPattern::WhiteNoise;
const BLUE: VisibilityPattern = VisibilityPattern::BlueNoise;
const ESTIMATED: Coverage = Coverage::Estimated;

/// Patterns fixed on the screen.
pub(super) const SCREEN: VisibilitySpace = VisibilitySpace::Screen;
/// Patterns fixed on the objects.
pub(super) const OBJECT: VisibilitySpace = VisibilitySpace::Object;

/// What the frame-sequential combine knows of where the level the older buffer holds covers the
/// screen.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coverage {
    /// Nothing: `combine_at_moved` estimates it from last frame's picture.
    Estimated,
    /// Each level's silhouette (`lodkit::silhouette::Surface`), where the level is a closed mesh
    /// without an alpha mask; the estimate for the others (`combine_pixel`, the library's
    /// default route).
    Silhouettes,
}

/// A transition technique of the harness.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Technique {
    /// A single-frame technique.
    Single(SingleFrameTechnique),
    /// Frame-sequential interpolation with a visibility pattern, schedule, pattern space and
    /// what the combine knows of the older level's coverage.
    FrameSequential(VisibilityPattern, Schedule, VisibilitySpace, Coverage),
}

impl Technique {
    /// Every technique the harness compares.
    pub const ALL: [Technique; 11] = [
        Technique::Single(SingleFrameTechnique::HardSwitch),
        Technique::Single(SingleFrameTechnique::CrossFade),
        Technique::Single(SingleFrameTechnique::Dither(DitherPattern::Bayer4x4)),
        Technique::Single(SingleFrameTechnique::Dither(DitherPattern::BlueNoise16x16)),
        Technique::Single(SingleFrameTechnique::Unpopping),
        Technique::FrameSequential(WHITE, Schedule::Paper, SCREEN, ESTIMATED),
        Technique::FrameSequential(BLUE, Schedule::Paper, SCREEN, ESTIMATED),
        Technique::FrameSequential(BLUE, Schedule::Complementary, SCREEN, ESTIMATED),
        Technique::FrameSequential(BLUE, Schedule::Paper, OBJECT, ESTIMATED),
        Technique::FrameSequential(BLUE, Schedule::Paper, SCREEN, Coverage::Silhouettes),
        Technique::FrameSequential(BLUE, Schedule::Complementary, SCREEN, Coverage::Silhouettes),
    ];

    /// Whether a run writes the map of which rule chose each pixel (`sources/`): the
    /// frame-sequential runs whose combine the Rust twin `combine_images` retraces, those that
    /// estimate the older level's coverage.
    pub fn maps_sources(self) -> bool {
        matches!(self, Technique::FrameSequential(.., Coverage::Estimated))
    }

    /// Short name for tables and file names.
    pub fn name(self) -> &'static str {
        match self {
            Technique::Single(t) => t.name(),
            Technique::FrameSequential(_, _, OBJECT, _) => "frame-seq-object-space",
            Technique::FrameSequential(_, Schedule::Paper, _, Coverage::Silhouettes) => {
                "frame-seq-silhouettes"
            }
            Technique::FrameSequential(_, Schedule::Complementary, _, Coverage::Silhouettes) => {
                "frame-seq-compl-silhouettes"
            }
            Technique::FrameSequential(p, Schedule::Paper, _, _) => match p {
                VisibilityPattern::WhiteNoise => "frame-seq-white-noise",
                VisibilityPattern::BlueNoise => "frame-seq-blue-noise",
                VisibilityPattern::Radial => "frame-seq-radial",
            },
            Technique::FrameSequential(p, Schedule::Complementary, _, _) => match p {
                VisibilityPattern::WhiteNoise => "frame-seq-compl-white-noise",
                VisibilityPattern::BlueNoise => "frame-seq-complementary",
                VisibilityPattern::Radial => "frame-seq-compl-radial",
            },
        }
    }
}
