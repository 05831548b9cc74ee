//! Counting what a render pass costs on the GPU: fragment-shader invocations through pipeline
//! statistics where the device has them, samples that passed the depth test through an
//! occlusion query otherwise.

use super::readback::read_buffer;
use super::{GpuContext, GpuError};

/// What a [`FragmentCounter`] counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CounterKind {
    /// Fragment-shader invocations (pipeline statistics query): every fragment shaded,
    /// including the ones a dither discards or the depth test rejects late, and, as the driver
    /// counts them, helper invocations (lavapipe: 12.5 % over the pixel count of a fullscreen
    /// triangle).
    FragmentInvocations,
    /// Samples that passed the depth test (occlusion query). wgpu does not ask Vulkan for
    /// precise occlusion queries, so a driver may round (lavapipe counts exactly).
    SamplesPassed,
    /// Whether any sample passed (occlusion query on wgpu's GL backend, which only answers
    /// yes or no): not a count.
    AnySamplesPassed,
}

impl CounterKind {
    /// Short description for tables.
    pub fn describe(self) -> &'static str {
        match self {
            Self::FragmentInvocations => "fragment-shader invocations (pipeline statistics)",
            Self::SamplesPassed => "samples passed (occlusion query)",
            Self::AnySamplesPassed => "none: the GL backend's occlusion query only says yes or no",
        }
    }

    /// Whether the reading is a count (false for [`CounterKind::AnySamplesPassed`]).
    pub fn is_count(self) -> bool {
        self != Self::AnySamplesPassed
    }
}

/// One counter around one render pass; read it after the pass is submitted.
#[derive(Debug)]
pub struct FragmentCounter {
    kind: CounterKind,
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
}

impl FragmentCounter {
    /// Counts fragment invocations when the device was created with
    /// `Features::PIPELINE_STATISTICS_QUERY`, samples passed otherwise.
    pub fn new(gpu: &GpuContext) -> Result<Self, GpuError> {
        let statistics = gpu
            .device
            .features()
            .contains(wgpu::Features::PIPELINE_STATISTICS_QUERY);
        let (kind, ty) = if statistics {
            (
                CounterKind::FragmentInvocations,
                wgpu::QueryType::PipelineStatistics(
                    wgpu::PipelineStatisticsTypes::FRAGMENT_SHADER_INVOCATIONS,
                ),
            )
        } else if gpu.adapter.get_info().backend == wgpu::Backend::Gl {
            (CounterKind::AnySamplesPassed, wgpu::QueryType::Occlusion)
        } else {
            (CounterKind::SamplesPassed, wgpu::QueryType::Occlusion)
        };
        gpu.guarded("FragmentCounter::new", || {
            let set = gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("lodkit fragment counter"),
                ty,
                count: 1,
            });
            let resolve = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("lodkit fragment counter resolve"),
                size: 8,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            Ok(Self { kind, set, resolve })
        })
    }

    /// What this counter counts.
    pub fn kind(&self) -> CounterKind {
        self.kind
    }

    /// The query set to put in `RenderPassDescriptor::occlusion_query_set` (only for occlusion
    /// counting; `None` otherwise).
    pub fn occlusion_query_set(&self) -> Option<&wgpu::QuerySet> {
        (self.kind != CounterKind::FragmentInvocations).then_some(&self.set)
    }

    /// Starts counting in `pass` (call once per pass, before the draws).
    pub fn begin(&self, pass: &mut wgpu::RenderPass<'_>) {
        match self.kind {
            CounterKind::FragmentInvocations => pass.begin_pipeline_statistics_query(&self.set, 0),
            _ => pass.begin_occlusion_query(0),
        }
    }

    /// Stops counting in `pass`.
    pub fn end(&self, pass: &mut wgpu::RenderPass<'_>) {
        match self.kind {
            CounterKind::FragmentInvocations => pass.end_pipeline_statistics_query(),
            _ => pass.end_occlusion_query(),
        }
    }

    /// Resolves the query into `encoder` (after the pass ends), submits it and returns the
    /// count.
    pub fn read(
        &self,
        gpu: &GpuContext,
        mut encoder: wgpu::CommandEncoder,
    ) -> Result<u64, GpuError> {
        const CALL: &str = "FragmentCounter::read";
        encoder.resolve_query_set(&self.set, 0..1, &self.resolve, 0);
        let bytes = gpu.guarded(CALL, || read_buffer(gpu, encoder, &self.resolve, 8))?;
        let word = bytes.get(..8).and_then(|b| b.try_into().ok());
        word.map(u64::from_le_bytes).ok_or(GpuError::Readback {
            call: CALL,
            reason: format!("8 bytes expected, {} read", bytes.len()),
        })
    }
}
