//! The demo's measures: each runs on the fixtures and returns a serializable struct (images it
//! renders are written beside it); none of them imports the report.

pub mod closed_loop;
pub mod combine_timing;
pub mod controllers;
pub mod frame_cost;
pub mod gpu_report;
pub mod host_cost;
pub mod impostor_atlas;
pub mod lod_chain;
pub mod packed_upsample_timing;
pub mod reads;
pub mod selection;
pub mod transitions;
pub mod upsample_quality;
pub mod upsample_timing;

use serde::Serialize;

use crate::demo::fixtures::clock;

/// Everything the demo measured.
#[derive(Clone, Debug, Serialize)]
pub struct DemoReport {
    /// Adapter name, backend, driver.
    pub adapter: String,
    /// The driver and its version, as the adapter reports them.
    pub driver: String,
    /// The clock the timed figures were read from (GPU timestamps where the device has them).
    pub clock: clock::Clock,
    /// Backend (Vulkan, Gl, ...).
    pub backend: String,
    /// Device type (Cpu = software rasterizer).
    pub device_type: String,
    /// UTC date of the run, YYYY-MM-DD.
    pub date: String,
    /// The command line that reproduces the run.
    pub command: String,
    /// Image size.
    pub size: (u32, u32),
    /// Transition length in frames.
    pub frames: usize,
    /// What the fragment counts count.
    pub counter: String,
    /// Scenes measured.
    pub scenes: Vec<String>,
    /// Transition metrics, scene by scene, technique by technique.
    pub transitions: Vec<transitions::TransitionMetrics>,
    /// Framebuffer LOD quality and speed.
    pub upsampling: Vec<upsample_quality::UpsampleRow>,
    /// Pass time ratios.
    pub pass_ratios: Vec<upsample_timing::PassRatio>,
    /// Framebuffer LOD: where a frame's time goes, and the speed-up against shading cost.
    pub frame_cost: frame_cost::FrameCost,
    /// Framebuffer LOD: the controllers on the real frame.
    pub closed_loop: closed_loop::ClosedLoop,
    /// Framerate controllers (simulated).
    pub controllers: Vec<controllers::ControllerRow>,
    /// GPU LOD selection against `select_batch`.
    pub selection: selection::SelectionReport,
    /// Host-side figures (composition, selection).
    pub cpu: Vec<host_cost::CpuFigure>,
    /// The octahedral impostor atlases of the scenes that have one.
    pub atlases: Vec<impostor_atlas::AtlasFigure>,
    /// The generated LOD chain's levels, when its scene was measured.
    pub chain: Option<lod_chain::ChainReport>,
    /// Whether the plots have text (a font was found).
    pub plot_text: bool,
    /// Wall time of the whole run, seconds.
    pub seconds: f64,
}
