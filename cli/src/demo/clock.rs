//! The clock every timed figure of the demo is read from: GPU timestamps written around a run of
//! recordings in one command encoder where the device offers them
//! (`TIMESTAMP_QUERY_INSIDE_ENCODERS`), so the submission, the wait and the host's work do not
//! count; the wall clock around one submission of the same recordings and its wait otherwise.
//! Each figure says which clock it came from.

use std::time::Instant;

use lodkit::gpu::{GpuContext, GpuError};
use serde::Serialize;

/// Which clock a figure was read from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Clock {
    /// GPU timestamp queries around the recordings: the GPU's own time.
    GpuTimestamps,
    /// Wall time around a submission and its wait: includes the submission's fixed cost.
    WallClock,
}

impl Clock {
    /// How the report names it.
    pub fn label(self) -> &'static str {
        match self {
            Clock::GpuTimestamps => "GPU timestamps",
            Clock::WallClock => "wall clock (submit and wait)",
        }
    }
}

/// The features a device needs for [`Clock::GpuTimestamps`].
pub const TIMESTAMP_FEATURES: wgpu::Features =
    wgpu::Features::TIMESTAMP_QUERY.union(wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS);

/// What one run of recordings records: any number of passes into the encoder.
pub type Record<'a> = &'a dyn Fn(&mut wgpu::CommandEncoder) -> Result<(), GpuError>;

/// Times runs of recordings on one device.
pub struct Timer {
    clock: Clock,
    queries: Option<Queries>,
    /// Recordings per timed run.
    recordings: usize,
}

/// Two timestamps and the buffers that bring them back.
struct Queries {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    read: wgpu::Buffer,
    /// Nanoseconds per timestamp tick.
    period_ns: f64,
}

impl Timer {
    /// A timer that records `recordings` times per run (at least 1), on GPU timestamps when
    /// `gpu` has [`TIMESTAMP_FEATURES`], else on the wall clock.
    pub fn new(gpu: &GpuContext, recordings: usize) -> Result<Self, GpuError> {
        let recordings = recordings.max(1);
        if !gpu.device.features().contains(TIMESTAMP_FEATURES) {
            return Ok(Self::wall(recordings));
        }
        let queries = gpu.guarded("demo timer", || {
            let set = gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("demo timer"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            });
            let resolve = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("demo timer resolve"),
                size: 16,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let read = gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("demo timer read"),
                size: 16,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            });
            Ok(Queries {
                set,
                resolve,
                read,
                period_ns: f64::from(gpu.queue.get_timestamp_period()),
            })
        })?;
        Ok(Self {
            clock: Clock::GpuTimestamps,
            queries: Some(queries),
            recordings,
        })
    }

    /// A timer on the wall clock whatever the device offers.
    pub fn wall(recordings: usize) -> Self {
        Self {
            clock: Clock::WallClock,
            queries: None,
            recordings: recordings.max(1),
        }
    }

    /// The clock this timer reads.
    pub fn clock(&self) -> Clock {
        self.clock
    }

    /// Recordings per timed run.
    pub fn recordings(&self) -> usize {
        self.recordings
    }

    /// Milliseconds one recording of `record` takes: a run of [`recordings`](Self::recordings)
    /// recordings in one encoder, submitted once and waited for, divided by their number.
    pub fn time(&self, gpu: &GpuContext, record: Record<'_>) -> Result<f64, GpuError> {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        if let Some(q) = &self.queries {
            encoder.write_timestamp(&q.set, 0);
        }
        for _ in 0..self.recordings {
            record(&mut encoder)?;
        }
        let n = self.recordings as f64;
        let Some(q) = &self.queries else {
            let start = Instant::now();
            gpu.queue.submit([encoder.finish()]);
            gpu.wait_idle()?;
            return Ok(start.elapsed().as_secs_f64() * 1e3 / n);
        };
        encoder.write_timestamp(&q.set, 1);
        encoder.resolve_query_set(&q.set, 0..2, &q.resolve, 0);
        encoder.copy_buffer_to_buffer(&q.resolve, 0, &q.read, 0, 16);
        gpu.queue.submit([encoder.finish()]);
        let ticks = read_ticks(gpu, &q.read)?;
        let ns = ticks[1].wrapping_sub(ticks[0]) as f64 * q.period_ns;
        Ok(ns * 1e-6 / n)
    }
}

/// The two resolved timestamps.
fn read_ticks(gpu: &GpuContext, read: &wgpu::Buffer) -> Result<[u64; 2], GpuError> {
    let slice = read.slice(..);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    gpu.wait_idle()?;
    let mapped = rx
        .recv()
        .map_err(|e| GpuError::Internal {
            call: "demo timer",
            description: format!("the map callback never ran: {e}"),
        })?
        .map_err(|e| GpuError::Internal {
            call: "demo timer",
            description: format!("mapping the timestamps: {e}"),
        })
        .and_then(|()| {
            let range = slice.get_mapped_range().map_err(|e| GpuError::Internal {
                call: "demo timer",
                description: format!("reading the timestamps: {e}"),
            })?;
            let words: [u64; 2] = bytemuck::pod_read_unaligned(&range[..16]);
            Ok(words)
        });
    read.unmap();
    mapped
}

/// Median: the middle value, or the mean of the two middle values for an even count; NaN when
/// empty (lodkit's, shared with the Bevy examples).
pub use lodkit::metrics::median;

/// Times `a` and `b` in `pairs` interleaved pairs after a few warm-up rounds, alternating which
/// goes first, on `timer`'s clock. Returns the medians of a, b and a/b (milliseconds per
/// recording).
pub fn interleaved(
    gpu: &GpuContext,
    timer: &Timer,
    a: Record<'_>,
    b: Record<'_>,
    pairs: usize,
) -> Result<(f64, f64, f64), GpuError> {
    for _ in 0..2 {
        timer.time(gpu, a)?;
        timer.time(gpu, b)?;
    }
    let (mut ta, mut tb, mut ratio) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..pairs.max(1) {
        let (x, y) = if i % 2 == 0 {
            let x = timer.time(gpu, a)?;
            (x, timer.time(gpu, b)?)
        } else {
            let y = timer.time(gpu, b)?;
            (timer.time(gpu, a)?, y)
        };
        ta.push(x);
        tb.push(y);
        ratio.push(x / y);
    }
    Ok((median(&ta), median(&tb), median(&ratio)))
}
