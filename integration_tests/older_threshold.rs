//! The combine pass told the screen pattern (`CombineCoverage::Known::pattern`): an older level
//! the data displays at an `older_tau` is shown at this frame's threshold for it, read from the
//! pattern at the pixel displayed, not by the flag its fragment predicted last frame. Where that
//! prediction missed (here on purpose: the next frame's progress is set wrong on every frame),
//! only the pattern keeps the two levels' shares on the schedule.

use glam::{Mat4, Vec3};
use lodkit::combine_coverage::{
    CombineData, CombineDataDescriptor, CombineObjectData, CoverageRoute,
};
use lodkit::frame_sequential::{FrameDraw, InstanceKey, Schedule, TransitionScheduler};
use lodkit::gpu::frame_sequential::{
    CombineCoverage, CombineFrame, CombinePass, CombineRegions, LodBuffers,
};
use lodkit::gpu::readback::read_texture_rgba8;
use lodkit::reproject::new_to_old_matrix;
use lodkit_scenes::lod_buffer::{LodBufferFrame, LodDrawItem};

use crate::display_time::{SphereLods, blue_share, step_transition};
use crate::support::say;

const W: u32 = 64;
const FRAMES: u32 = 12;
const START: u64 = 3;

/// The sphere's transition, frame by frame: its LOD buffers, drawn by `lods`' renderer.
struct Transition {
    buffers: LodBuffers,
    scheduler: TransitionScheduler,
    key: InstanceKey,
    view: Mat4,
}

/// One frame of a [`Transition`]: the buffer drawn, the scheduler's draw and the reprojection.
struct Drawn {
    index: usize,
    draw: FrameDraw,
    new_to_old: Mat4,
}

impl Transition {
    fn new(gpu: &lodkit::gpu::GpuContext) -> Self {
        let mut scheduler = TransitionScheduler::with_schedule(Schedule::Complementary);
        let key = scheduler.insert(0);
        Self {
            buffers: LodBuffers::new(gpu, W, W, SphereLods::FORMAT).unwrap(),
            scheduler,
            key,
            view: glam::camera::rh::view::look_at_mat4(
                Vec3::new(0.0, 0.0, 3.0),
                Vec3::ZERO,
                Vec3::Y,
            ),
        }
    }

    /// Draws frame `f` into the LOD buffers, the next frame's progress mispredicted by half a
    /// transition.
    fn draw(&mut self, gpu: &lodkit::gpu::GpuContext, lods: &SphereLods, f: u64) -> Drawn {
        let (proj, view) = (lods.proj, self.view);
        let ahead = Some(u64::from(FRAMES / 2));
        step_transition(&mut self.scheduler, self.key, f, START, FRAMES, ahead);
        let draw = self.scheduler.draw(self.key).unwrap();
        let item = LodDrawItem::from_draw(
            &lods.sphere,
            Mat4::IDENTITY,
            lods.colors[usize::from(draw.lod)],
            &draw,
        );
        let index = self.scheduler.buffer_index();
        lods.renderer
            .render(
                gpu,
                &self.buffers,
                &LodBufferFrame {
                    index,
                    view: (proj * view).into(),
                    items: &[item],
                    clear: wgpu::Color::BLACK,
                    ..Default::default()
                },
            )
            .unwrap();
        let new_to_old = if f == 0 {
            CombinePass::NO_HISTORY
        } else {
            new_to_old_matrix(&view, &proj, &view, &proj)
        };
        Drawn {
            index,
            draw,
            new_to_old,
        }
    }

    /// The frame's combine data, the older level displayed at `older_tau`.
    fn data(&self, drawn: &Drawn, older_tau: Option<f32>) -> CombineData {
        let objects = [CombineObjectData {
            id: drawn.draw.id,
            new_to_old: drawn.new_to_old,
            older_tau,
            route: CoverageRoute::Estimate,
        }];
        CombineData::new(&CombineDataDescriptor {
            new_to_old: drawn.new_to_old,
            height: W,
            objects: if drawn.draw.id == 0 { &[] } else { &objects },
            ..Default::default()
        })
        .unwrap()
    }

    /// Records the combine of `drawn` with `data` into `target`.
    fn record(
        &self,
        gpu: &lodkit::gpu::GpuContext,
        lods: &SphereLods,
        encoder: &mut wgpu::CommandEncoder,
        (drawn, data, pattern): (&Drawn, &CombineData, bool),
        target: &wgpu::TextureView,
    ) {
        let frame = CombineFrame {
            buffers: &self.buffers,
            newer: drawn.index,
            new_to_old: drawn.new_to_old,
            target,
            regions: CombineRegions::Everywhere,
            coverage: CombineCoverage::Known {
                data,
                level_depth: None,
                pattern: pattern.then(|| lods.renderer.visibility_view()),
            },
        };
        lods.combine.record(gpu, encoder, &frame).unwrap();
    }
}

/// The blue (incoming) share of the sphere on each frame of a complementary transition whose
/// next-frame progress is mispredicted by half a transition, combined with the pattern and
/// `older_tau` (`display`) or with the older buffer's flags.
fn shares(gpu: &lodkit::gpu::GpuContext, lods: &SphereLods, display: bool) -> Vec<f32> {
    let mut t = Transition::new(gpu);
    let mut out = Vec::new();
    for f in 0..START + u64::from(FRAMES) + 1 {
        let drawn = t.draw(gpu, lods, f);
        let older_tau = display.then(|| {
            t.scheduler
                .schedule()
                .threshold(drawn.draw.progress, !drawn.draw.incoming)
        });
        let data = t.data(&drawn, older_tau);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        t.record(
            gpu,
            lods,
            &mut encoder,
            (&drawn, &data, display),
            &lods.target_view,
        );
        gpu.queue.submit([encoder.finish()]);
        let (share, covered) = blue_share(&read_texture_rgba8(gpu, &lods.target).unwrap());
        assert!(
            covered > 1000,
            "frame {f}: the sphere covers {covered} pixels"
        );
        out.push(share);
    }
    out.split_off(START as usize)
}

/// Two recordings of one frame in one encoder with different data (the older level displayed
/// at two thresholds) each draw what the same recording draws alone: each recording's data is
/// copied in the encoder before its pass, not written on the queue (which would give both the
/// last data), though the pass keeps one data texture and its bind groups between recordings.
#[test]
fn recordings_in_one_encoder_each_read_their_own_data() {
    let gpu = lodkit_test_gpu!();
    let lods = SphereLods::new(gpu, W);
    let mut t = Transition::new(gpu);
    let mut drawn = t.draw(gpu, &lods, 0);
    for f in 1..=START + u64::from(FRAMES / 2) {
        drawn = t.draw(gpu, &lods, f);
    }
    let (low, high) = (t.data(&drawn, Some(0.2)), t.data(&drawn, Some(0.8)));
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let target = |label| {
        lodkit::gpu::resources::texture_2d(gpu, (W, W), SphereLods::FORMAT, usage, label).unwrap()
    };
    let view = |t: &wgpu::Texture| t.create_view(&Default::default());
    let targets = [
        target("low alone"),
        target("high alone"),
        target("low"),
        target("high"),
    ];
    let read = |t: &wgpu::Texture| read_texture_rgba8(gpu, t).unwrap();
    for (data, target) in [(&low, &targets[0]), (&high, &targets[1])] {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        t.record(
            gpu,
            &lods,
            &mut encoder,
            (&drawn, data, true),
            &view(target),
        );
        gpu.queue.submit([encoder.finish()]);
    }
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    t.record(
        gpu,
        &lods,
        &mut encoder,
        (&drawn, &low, true),
        &view(&targets[2]),
    );
    t.record(
        gpu,
        &lods,
        &mut encoder,
        (&drawn, &high, true),
        &view(&targets[3]),
    );
    gpu.queue.submit([encoder.finish()]);
    let (low_share, _) = blue_share(&read(&targets[0]));
    let (high_share, _) = blue_share(&read(&targets[1]));
    say(&format!(
        "older level displayed at 0.2 and 0.8: incoming shares {low_share:.3} and {high_share:.3}"
    ));
    let images: Vec<Vec<u8>> = targets.iter().map(read).collect();
    assert!(images[0] != images[1], "the two thresholds give two images");
    assert!(
        images[2] == images[0],
        "the first recording reads its own data"
    );
    assert!(
        images[3] == images[1],
        "the second recording reads its own data"
    );
}

#[test]
fn an_older_level_is_shown_at_this_frames_threshold_where_the_prediction_missed() {
    let gpu = lodkit_test_gpu!();
    let lods = SphereLods::new(gpu, W);
    let displayed = shares(gpu, &lods, true);
    let flagged = shares(gpu, &lods, false);
    let off = |s: &[f32]| {
        s.iter()
            .enumerate()
            .map(|(k, share)| (share - k as f32 / FRAMES as f32).abs())
            .fold(0.0, f32::max)
    };
    say(&format!(
        "incoming share, next progress mispredicted by 0.5: with the pattern {displayed:.3?} \
         (largest miss {:.3}), with the older flags {flagged:.3?} (largest miss {:.3})",
        off(&displayed),
        off(&flagged)
    ));
    // The blue-noise pattern's share at a threshold is within 0.05 of it (the test beside this
    // one, each_lod_is_shown_as_it_is_at_the_frame_displayed, holds that with no misprediction).
    assert!(
        off(&displayed) < 0.05,
        "with the pattern the incoming share must follow the progress: {displayed:?}"
    );
    // The measure sees the failure it is named for: the predicted flags miss.
    assert!(
        off(&flagged) > 0.1,
        "the mispredicted flags should miss the progress: {flagged:?}"
    );
}
