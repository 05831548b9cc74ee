//! The fixture every framebuffer-LOD timing reads: the edge scene's frame (the scene, the
//! full-resolution prepass, L unpacked and packed, the upsample passes and a target), and the
//! demo's upsampling parameters. The pass ratios ([`timing`](super::timing),
//! [`packed_timing`](super::packed_timing)), the frame cost and the closed loop set it up here
//! and nowhere else.

use lodkit::gpu::framebuffer_lod::{
    LowResBuffer, LowResLayout, RangeSigmas, UpsampleComposite, UpsampleFrame, UpsamplePass,
    UpsamplePassDescriptor, UpsampleSettings,
};
use lodkit::gpu::resources::texture_2d;
use lodkit::gpu::{GpuContext, GpuError};
use lodkit_scenes::gbuffer::{EdgeScene, ShadingTerm};

use super::clock::Timer;

/// Target format of the timed passes.
pub(super) const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// The demo's upsample pass over an L of `layout`, times a full-resolution albedo when
/// `times_albedo` (fine-grained resizing), into [`FORMAT`] targets.
pub(super) fn pass_descriptor(layout: LowResLayout, times_albedo: bool) -> UpsamplePassDescriptor {
    UpsamplePassDescriptor {
        target_format: FORMAT,
        low_res: layout,
        composite: if times_albedo {
            UpsampleComposite::TimesAlbedo
        } else {
            UpsampleComposite::Upsampled
        },
    }
}

/// Edge-stopping parameters of the bilateral filter in the demo.
pub const SIGMA_Z: f32 = 0.25;
/// See [`SIGMA_Z`].
pub const SIGMA_N: f32 = 0.4;

/// [`SIGMA_Z`] and [`SIGMA_N`] as the pass takes them.
pub(super) fn sigmas() -> RangeSigmas {
    RangeSigmas {
        depth: SIGMA_Z,
        normal: SIGMA_N,
    }
}

/// The demo's upsampling parameters at resize factor `r`.
pub(super) fn settings(r: f32) -> UpsampleSettings {
    UpsampleSettings {
        r,
        sigmas: sigmas(),
    }
}

/// The resources of a framebuffer-LOD frame of the edge scene (the scene is passed to each
/// call, since its shading work is the knob the measurements turn): the low-resolution buffer,
/// the full-resolution prepass, the upsample pass and the target; each pass timed on request.
/// The pass ratios, the frame cost and the closed loop all set the scene up here.
pub(super) struct EdgeFrame<'a> {
    gpu: &'a GpuContext,
    timer: &'a Timer,
    /// L, unpacked and packed.
    pub(super) low: [LowResBuffer; 2],
    /// The full-resolution prepass: geometry and albedo (the full-resolution side of eq. 1).
    pub(super) prepass: LowResBuffer,
    /// The upsample of each L.
    pub(super) upsample: [UpsamplePass; 2],
    /// The fine-grained route's upsample of each L, which multiplies by the prepass's albedo.
    pub(super) fine: [UpsamplePass; 2],
    /// The target every upsample writes.
    pub(super) view: wgpu::TextureView,
}

impl<'a> EdgeFrame<'a> {
    /// The resources at `size`, RGBA8, and the edge scene for that aspect.
    pub(super) fn new(
        gpu: &'a GpuContext,
        timer: &'a Timer,
        size: (u32, u32),
    ) -> Result<(Self, EdgeScene), GpuError> {
        let ((w, h), format) = (size, FORMAT);
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let scene = EdgeScene::new(gpu, format, w as f32 / h as f32)?;
        let frame = Self {
            gpu,
            timer,
            low: [
                LowResBuffer::new(gpu, w, h, format)?,
                LowResBuffer::packed(gpu, w, h)?,
            ],
            prepass: LowResBuffer::new(gpu, w, h, format)?,
            upsample: [
                UpsamplePass::new(gpu, &pass_descriptor(LowResLayout::ColorAndGeometry, false))?,
                UpsamplePass::new(gpu, &pass_descriptor(LowResLayout::Packed, false))?,
            ],
            fine: [
                UpsamplePass::new(gpu, &pass_descriptor(LowResLayout::ColorAndGeometry, true))?,
                UpsamplePass::new(gpu, &pass_descriptor(LowResLayout::Packed, true))?,
            ],
            view: texture_2d(gpu, size, format, usage, "frame")?.create_view(&Default::default()),
        };
        Ok((frame, scene))
    }

    /// The time of `record` on the timer's clock, ms.
    pub(super) fn timed(&self, record: super::clock::Record<'_>) -> Result<f64, GpuError> {
        self.timer.time(self.gpu, record)
    }

    /// The low-resolution shading at `r` into L (`p`: 0 unpacked, 1 packed).
    pub(super) fn shade(
        &self,
        scene: &EdgeScene,
        r: f32,
        term: ShadingTerm,
        p: usize,
    ) -> Result<f64, GpuError> {
        self.timed(&|e| scene.record_term(self.gpu, e, &self.low[p], r, term))
    }

    pub(super) fn prepass(&self, scene: &EdgeScene) -> Result<f64, GpuError> {
        let albedo = ShadingTerm::Albedo;
        self.timed(&|e| scene.record_term(self.gpu, e, &self.prepass, 1.0, albedo))
    }

    /// Records the upsample of L `p` at `r`; `term` is what L holds (the lighting alone:
    /// fine-grained).
    pub(super) fn record_upsample(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        r: f32,
        term: ShadingTerm,
        p: usize,
    ) -> Result<(), GpuError> {
        let fine = term == ShadingTerm::Lighting;
        let frame = UpsampleFrame {
            low: &self.low[p],
            full_geometry: self.prepass.geometry(),
            full_albedo: fine.then(|| self.prepass.color()),
            target: &self.view,
            settings: settings(r),
        };
        let pass = if fine {
            &self.fine[p]
        } else {
            &self.upsample[p]
        };
        pass.record(self.gpu, encoder, &frame)
    }

    pub(super) fn upsample(&self, r: f32, term: ShadingTerm, p: usize) -> Result<f64, GpuError> {
        self.timed(&|e| self.record_upsample(e, r, term, p))
    }

    /// A whole frame at `r` from L `p` (0 unpacked, 1 packed): its three passes recorded one
    /// after the other; its time in ms.
    pub(super) fn whole(&self, scene: &EdgeScene, r: f32, p: usize) -> Result<f64, GpuError> {
        self.timed(&|e| {
            scene.record_term(self.gpu, e, &self.prepass, 1.0, ShadingTerm::Albedo)?;
            scene.record_term(self.gpu, e, &self.low[p], r, ShadingTerm::Full)?;
            self.record_upsample(e, r, ShadingTerm::Full, p)
        })
    }

    /// The three passes of a frame at `r` from L `p`, each waited for.
    pub(super) fn passes(
        &self,
        scene: &EdgeScene,
        r: f32,
        term: ShadingTerm,
        p: usize,
    ) -> Result<[f64; 3], GpuError> {
        Ok([
            self.prepass(scene)?,
            self.shade(scene, r, term, p)?,
            self.upsample(r, term, p)?,
        ])
    }
}
