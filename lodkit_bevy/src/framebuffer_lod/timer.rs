//! A camera's GPU time from two timestamp queries: one written before its prepass, one after its
//! upscaling pass (the last of the `Core3d` schedule). The pair is resolved into a small ring of
//! readback buffers, mapped after the frame is submitted and read a frame or two later; each time
//! goes to the main world with the r it was rendered at.

use std::collections::HashMap;
use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::{Arc, Mutex};

use bevy::core_pipeline::upscaling::upscaling;
use bevy::core_pipeline::{Core3d, Core3dSystems};
use bevy::prelude::*;
use bevy::render::render_resource::{
    Buffer, BufferDescriptor, BufferUsages, MapMode, WgpuFeatures,
};
use bevy::render::renderer::{RenderContext, RenderDevice, RenderQueue, ViewQuery};
use bevy::render::sync_world::MainEntity;
use bevy::render::{Render, RenderSystems};

use super::settings::ExtractedFramebufferLod;

/// Readback buffers per camera: enough for a frame or two of latency.
const SLOTS: usize = 4;
const FREE: u8 = 0;
const COPIED: u8 = 1;
const MAPPING: u8 = 2;
const MAPPED: u8 = 3;

/// Whether `features` allow timing a camera with timestamps written into command encoders.
pub(super) fn supported(features: WgpuFeatures) -> bool {
    features.contains(WgpuFeatures::TIMESTAMP_QUERY | WgpuFeatures::TIMESTAMP_QUERY_INSIDE_ENCODERS)
}

/// GPU frame times read back in the render world, waiting for the main world's controller:
/// per camera (main-world entity), (r rendered at, seconds) in order. Shared by both worlds.
#[derive(Resource, Clone, Default)]
pub(super) struct GpuFrameTimes(Arc<Mutex<Measured>>);

/// Per main-world camera, (r rendered at, seconds) in the order measured.
pub(super) type Measured = HashMap<Entity, Vec<(f32, f32)>>;

impl GpuFrameTimes {
    /// Everything measured since the last call.
    pub(super) fn take(&self) -> Measured {
        std::mem::take(&mut *self.0.lock().unwrap_or_else(|e| e.into_inner()))
    }

    fn push(&self, camera: Entity, factor: f32, seconds: f32) {
        self.0
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .entry(camera)
            .or_default()
            .push((factor, seconds));
    }
}

struct Slot {
    buffer: Buffer,
    state: Arc<AtomicU8>,
    factor: f32,
}

/// The timer of one camera (render world).
#[derive(Component)]
pub struct GpuFrameTimer {
    queries: wgpu::QuerySet,
    resolve: Buffer,
    slots: Vec<Slot>,
    /// The slot this frame's pair lands in (none free: the frame is not timed).
    recording: Option<usize>,
}

impl GpuFrameTimer {
    fn new(device: &RenderDevice) -> Self {
        let queries = device
            .wgpu_device()
            .create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("lodkit_frame_timer"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            });
        let resolve = device.create_buffer(&BufferDescriptor {
            label: Some("lodkit_frame_timer_resolve"),
            size: 16,
            usage: BufferUsages::QUERY_RESOLVE | BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let slots = (0..SLOTS)
            .map(|_| Slot {
                buffer: device.create_buffer(&BufferDescriptor {
                    label: Some("lodkit_frame_timer_readback"),
                    size: 16,
                    usage: BufferUsages::MAP_READ | BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                state: Arc::new(AtomicU8::new(FREE)),
                factor: 1.0,
            })
            .collect();
        Self {
            queries,
            resolve,
            slots,
            recording: None,
        }
    }
}

pub(super) fn build(render_app: &mut SubApp) {
    render_app
        .add_systems(
            Render,
            (
                prepare_timers.in_set(RenderSystems::PrepareResources),
                map_timers.in_set(RenderSystems::Cleanup),
            ),
        )
        .add_systems(
            Core3d,
            (
                begin_timer.before(Core3dSystems::Prepass),
                end_timer.after(upscaling),
            ),
        );
}

/// Adds or drops timers, reads the pairs that came back and picks this frame's slot.
fn prepare_timers(
    mut commands: Commands,
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    times: Res<GpuFrameTimes>,
    mut views: Query<(
        Entity,
        &MainEntity,
        &ExtractedFramebufferLod,
        Option<&mut GpuFrameTimer>,
    )>,
) {
    let period = f64::from(queue.get_timestamp_period());
    for (entity, main, extracted, timer) in &mut views {
        if !extracted.gpu_timed {
            if timer.is_some() {
                commands.entity(entity).remove::<GpuFrameTimer>();
            }
            continue;
        }
        let Some(mut timer) = timer else {
            commands.entity(entity).insert(GpuFrameTimer::new(&device));
            continue;
        };
        for slot in &mut timer.slots {
            if slot.state.load(Ordering::Acquire) != MAPPED {
                continue;
            }
            let ticks = {
                // A range that cannot be read gives no measurement, not a panic.
                match slot.buffer.slice(..).get_mapped_range() {
                    Ok(range) => {
                        let words: [u64; 2] = std::array::from_fn(|i| {
                            range
                                .get(i * 8..i * 8 + 8)
                                .and_then(|b| b.try_into().ok())
                                .map_or(0, u64::from_le_bytes)
                        });
                        words[1].saturating_sub(words[0])
                    }
                    Err(_) => 0,
                }
            };
            slot.buffer.unmap();
            slot.state.store(FREE, Ordering::Release);
            let seconds = (ticks as f64 * period * 1e-9) as f32;
            if seconds > 0.0 {
                times.push(main.id(), slot.factor, seconds);
            }
        }
        let free = timer
            .slots
            .iter()
            .position(|s| s.state.load(Ordering::Acquire) == FREE);
        if let Some(i) = free {
            timer.slots[i].factor = extracted.factor;
        }
        timer.recording = free;
    }
}

/// The first timestamp, before the camera's prepass.
fn begin_timer(view: ViewQuery<&GpuFrameTimer>, mut ctx: RenderContext) {
    let timer = view.into_inner();
    if timer.recording.is_some() {
        ctx.command_encoder().write_timestamp(&timer.queries, 0);
    }
}

/// The second timestamp, after the camera's last pass, resolved into this frame's slot.
fn end_timer(view: ViewQuery<&GpuFrameTimer>, mut ctx: RenderContext) {
    let timer = view.into_inner();
    let Some(i) = timer.recording else {
        return;
    };
    let encoder = ctx.command_encoder();
    encoder.write_timestamp(&timer.queries, 1);
    encoder.resolve_query_set(&timer.queries, 0..2, &timer.resolve, 0);
    encoder.copy_buffer_to_buffer(&timer.resolve, 0, &timer.slots[i].buffer, 0, 16);
    timer.slots[i].state.store(COPIED, Ordering::Release);
}

/// Maps the slots copied this frame (after submission: a buffer mapped before its copy is
/// submitted would fail validation).
fn map_timers(views: Query<&GpuFrameTimer>) {
    for timer in &views {
        for slot in &timer.slots {
            if slot.state.load(Ordering::Acquire) != COPIED {
                continue;
            }
            slot.state.store(MAPPING, Ordering::Release);
            let state = slot.state.clone();
            slot.buffer
                .slice(..)
                .map_async(MapMode::Read, move |result| {
                    state.store(
                        if result.is_ok() { MAPPED } else { FREE },
                        Ordering::Release,
                    );
                });
        }
    }
}
