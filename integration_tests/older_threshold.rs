//! The combine pass told the screen pattern (`CombineCoverage::Known::pattern`): an older level
//! the data displays at an `older_tau` is shown at this frame's threshold for it, read from the
//! pattern at the pixel displayed, not by the flag its fragment predicted last frame. Where that
//! prediction missed (here on purpose: the next frame's progress is set wrong on every frame),
//! only the pattern keeps the two levels' shares on the schedule.

use glam::{Mat4, Vec3};
use lodkit::combine_coverage::{
    CombineData, CombineDataDescriptor, CombineObjectData, CoverageRoute,
};
use lodkit::frame_sequential::{Schedule, TransitionScheduler};
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

/// The blue (incoming) share of the sphere on each frame of a complementary transition whose
/// next-frame progress is mispredicted by half a transition, combined with the pattern and
/// `older_tau` (`display`) or with the older buffer's flags.
fn shares(gpu: &lodkit::gpu::GpuContext, lods: &SphereLods, display: bool) -> Vec<f32> {
    let proj = lods.proj;
    let view = glam::camera::rh::view::look_at_mat4(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y);
    let buffers = LodBuffers::new(gpu, W, W, SphereLods::FORMAT).unwrap();
    let mut s = TransitionScheduler::with_schedule(Schedule::Complementary);
    let key = s.insert(0);
    let mut out = Vec::new();
    for f in 0..START + u64::from(FRAMES) + 1 {
        // The next frame's progress mispredicted: half a transition ahead.
        let ahead = Some(u64::from(FRAMES / 2));
        step_transition(&mut s, key, f, START, FRAMES, ahead);
        let d = s.draw(key).unwrap();
        let item = LodDrawItem::from_draw(
            &lods.sphere,
            Mat4::IDENTITY,
            lods.colors[usize::from(d.lod)],
            &d,
        );
        let index = s.buffer_index();
        lods.renderer
            .render(
                gpu,
                &buffers,
                &LodBufferFrame {
                    index,
                    view: (proj * view).into(),
                    items: &[item],
                    clear: wgpu::Color::BLACK,
                    ..Default::default()
                },
            )
            .unwrap();
        let m = if f == 0 {
            CombinePass::NO_HISTORY
        } else {
            new_to_old_matrix(&view, &proj, &view, &proj)
        };
        let older_tau = display.then(|| s.schedule().threshold(d.progress, !d.incoming));
        let objects = [CombineObjectData {
            id: d.id,
            new_to_old: m,
            older_tau,
            route: CoverageRoute::Estimate,
        }];
        let data = CombineData::new(&CombineDataDescriptor {
            new_to_old: m,
            height: W,
            objects: if d.id == 0 { &[] } else { &objects },
            ..Default::default()
        })
        .unwrap();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let frame = CombineFrame {
            buffers: &buffers,
            newer: index,
            new_to_old: m,
            target: &lods.target_view,
            regions: CombineRegions::Everywhere,
            coverage: CombineCoverage::Known {
                data: &data,
                level_depth: None,
                pattern: display.then(|| lods.renderer.visibility_view()),
            },
        };
        lods.combine.record(gpu, &mut encoder, &frame).unwrap();
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
