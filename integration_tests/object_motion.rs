//! Object motion in frame-sequential LOD: `lodkit::lod_buffer::lod_buffer_motion`,
//! `lod_buffer_output_motion` and `lodkit::combine::combine_object_motion` on the GPU (WGSL and
//! GLSL twins) against their Rust twins, and a t-instance that moves and sways through a
//! transition, where the combine must keep the older LOD under the newer one.

use glam::{Mat4, Vec2, Vec3, Vec4};
use lodkit::combine::combine_object_motion;
use lodkit::frame_sequential::{Drive, FrameDraw, InstanceKey, Schedule, TransitionScheduler};
use lodkit::gpu::frame_sequential::{CombinePass, LodBuffers};
use lodkit::gpu::readback::read_texture;
use lodkit::lod_buffer::{lod_buffer_motion, lod_buffer_output_motion};
use lodkit::reproject::new_to_old_matrix;
use lodkit::shaders::SourceLanguage;
use lodkit_scenes::lod_buffer::{LodBufferFrame, LodDrawItem, LodView};

use crate::display_time::SphereLods;
use crate::harness::{Probe, floats, run_with, say, words};

#[test]
fn object_motion_twins_match() {
    let gpu = lodkit_test_gpu!(device);
    let noise = lodkit::noise::white_noise(13 * 40, 21);
    let proj = glam::camera::rh::proj::directx::perspective(0.9, 1.5, 0.1, 50.0);
    let eye =
        |x: f32| glam::camera::rh::view::look_at_mat4(Vec3::new(x, 0.3, 3.0), Vec3::ZERO, Vec3::Y);
    let m = new_to_old_matrix(&eye(0.2), &proj, &eye(0.0), &proj);
    // (then clip, now clip, uv, depth, motion vector); every fifth case has a point behind the
    // camera (w <= 0), where the motion is 0.
    let cases: Vec<(Vec4, Vec4, Vec2, f32, Vec2)> = noise
        .chunks(13)
        .enumerate()
        .map(|(i, r)| {
            let clip = |k: usize| Vec4::new(r[k] - 0.5, r[k + 1] - 0.5, r[k + 2], r[k + 3] + 0.5);
            let mut then = clip(0);
            if i % 5 == 4 {
                then.w = -then.w;
            }
            let uv = Vec2::new(r[8], r[9]);
            (
                then,
                clip(4),
                uv,
                0.9 + 0.09 * r[10],
                Vec2::new(r[11], r[12]) * 0.1 - 0.05,
            )
        })
        .collect();
    let inputs: Vec<u32> = cases
        .iter()
        .flat_map(|(then, now, uv, depth, mv)| {
            let mut w = words(&then.to_array());
            w.extend(words(&now.to_array()));
            w.extend(words(&[uv.x, uv.y, *depth, mv.x, mv.y]));
            w.extend(words(&m.to_cols_array()));
            w
        })
        .collect();
    let want: Vec<u32> = cases
        .iter()
        .enumerate()
        .flat_map(|(i, (then, now, uv, depth, mv))| {
            let motion = lod_buffer_motion(*then, *now);
            let (_, id, stored) = lod_buffer_output_motion([0.0; 4], i as u32 * 7, 1, motion);
            let object = combine_object_motion(*uv, *depth, &m, *mv);
            let mut w = words(&[motion.x, motion.y]);
            w.push(id);
            w.extend(words(&[stored.x, stored.y, object.x, object.y]));
            w
        })
        .collect();
    let matrix = "mat4x4<f32>(vec4(inp_f(13u), inp_f(14u), inp_f(15u), inp_f(16u)), vec4(inp_f(17u), inp_f(18u), inp_f(19u), inp_f(20u)), vec4(inp_f(21u), inp_f(22u), inp_f(23u), inp_f(24u)), vec4(inp_f(25u), inp_f(26u), inp_f(27u), inp_f(28u)))";
    let wgsl = format!(
        "let then = vec4(inp_f(0u), inp_f(1u), inp_f(2u), inp_f(3u));
        let now = vec4(inp_f(4u), inp_f(5u), inp_f(6u), inp_f(7u));
        let m = lod_buffer_motion(then, now);
        out_f(0u, m.x); out_f(1u, m.y);
        let o = lod_buffer_output_motion(vec4(0.0), probe_case * 7u, 1u, m);
        out_u(2u, o.id); out_f(3u, o.motion.x); out_f(4u, o.motion.y);
        let b = combine_object_motion(vec2(inp_f(8u), inp_f(9u)), inp_f(10u), {matrix}, vec2(inp_f(11u), inp_f(12u)));
        out_f(5u, b.x); out_f(6u, b.y);"
    );
    let glsl = format!(
        "vec4 then_clip = vec4(inp_f(0u), inp_f(1u), inp_f(2u), inp_f(3u));
        vec4 now_clip = vec4(inp_f(4u), inp_f(5u), inp_f(6u), inp_f(7u));
        vec2 m = lodkit_lod_buffer_motion(then_clip, now_clip);
        out_f(0u, m.x); out_f(1u, m.y);
        lodkit_LodBufferMotionOutput o = lodkit_lod_buffer_output_motion(vec4(0.0), probe_case * 7u, 1u, m);
        out_u(2u, o.id); out_f(3u, o.motion.x); out_f(4u, o.motion.y);
        vec2 b = lodkit_combine_object_motion(vec2(inp_f(8u), inp_f(9u)), inp_f(10u), {}, vec2(inp_f(11u), inp_f(12u)));
        out_f(5u, b.x); out_f(6u, b.y);",
        matrix.replace("mat4x4<f32>", "mat4")
    );
    for (language, header, body) in [
        (
            SourceLanguage::Wgsl,
            "#import lodkit::lod_buffer::{lod_buffer_motion, lod_buffer_output_motion}\n#import lodkit::combine::combine_object_motion",
            wgsl.as_str(),
        ),
        (
            SourceLanguage::Glsl(naga::ShaderStage::Compute),
            "#include \"lodkit/lod_buffer.glsl\"\n#include \"lodkit/combine.glsl\"",
            glsl.as_str(),
        ),
    ] {
        let probe = Probe {
            header,
            body,
            inputs: 29,
            outputs: 7,
            texture: None,
            rgba: &[],
            urgba: &[],
        };
        let got = run_with(gpu, &probe, &inputs, language, &[]);
        for (i, (g, w)) in got.chunks(7).zip(want.chunks(7)).enumerate() {
            assert_eq!(g[2], w[2], "{language:?} case {i}: id word");
            let (g, w) = (floats(g), floats(w));
            for k in [0, 1, 3, 4, 5, 6] {
                assert!(
                    (g[k] - w[k]).abs() < 1e-5,
                    "{language:?} case {i}, output {k}: {} vs {}",
                    g[k],
                    w[k]
                );
            }
        }
    }
    // Hand-derived: a point behind the camera has no motion; a still camera gives the motion
    // vector back, negated (it points from now to before).
    let w: Vec<f32> = floats(&want);
    assert_eq!((w[4 * 7], w[4 * 7 + 1]), (0.0, 0.0));
    let still = combine_object_motion(Vec2::splat(0.5), 0.95, &Mat4::IDENTITY, Vec2::new(0.1, 0.0));
    assert!((still - Vec2::new(-0.1, 0.0)).length() < 1e-6);
}

/// Frame `f` of a transition to LOD 1 over `frames` frames that begins at frame 2 (progress
/// driven, next frame's progress given): advances `s` and returns the instance's draw.
fn transition_frame(
    s: &mut TransitionScheduler,
    key: InstanceKey,
    f: u64,
    frames: u32,
) -> FrameDraw {
    if f > 0 {
        s.advance(1.0 / 60.0);
    }
    if f == 2 {
        s.begin_transition(key, 1, Drive::Progress).unwrap();
    }
    if f >= 2 {
        let p = |f: u64| ((f - 2) as f32 / frames as f32).min(1.0);
        s.set_progress(key, p(f)).unwrap();
        s.set_next_progress(key, p(f + 1)).unwrap();
    }
    s.draw(key).unwrap()
}

/// Pixels of the object (newer id word not 0) that show the black background in the combined
/// image, and the object's pixels.
fn holes(ids: &[u8], combined: &[u8]) -> (usize, usize) {
    let object = |p: usize| ids[p * 4..p * 4 + 4] != [0; 4];
    let black = |p: usize| combined[p * 4..p * 4 + 3].iter().all(|&c| c < 8);
    let n = ids.len() / 4;
    let covered = (0..n).filter(|&p| object(p)).count();
    ((0..n).filter(|&p| object(p) && black(p)).count(), covered)
}

#[test]
fn a_moving_t_instance_keeps_its_older_lod_under_it() {
    const W: u32 = 96;
    const FRAMES: u32 = 12;
    let gpu = lodkit_test_gpu!();
    let format = SphereLods::FORMAT;
    // Both LODs are the same sphere (red and blue), so both cover every pixel of the object:
    // any background inside it is see-through. It slides 1.5 px a frame and sways.
    let lods = SphereLods::new(gpu, W);
    let proj = lods.proj;
    let view = glam::camera::rh::view::look_at_mat4(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y);
    let model = |f: u64| Mat4::from_translation(Vec3::new(f as f32 * 0.05 - 0.5, 0.0, 0.0));
    let phase = |f: u64| f as f32 * 0.5;
    let mut rows = Vec::new();
    for follow in [true, false] {
        let buffers = LodBuffers::new(gpu, W, W, format).unwrap();
        let mut s = TransitionScheduler::with_schedule(Schedule::Complementary);
        let key = s.insert(0);
        let (mut worst, mut total, mut center_motion) = (0usize, 0usize, Vec2::ZERO);
        let mut checked = 0;
        for f in 0..u64::from(FRAMES) + 4 {
            let d = transition_frame(&mut s, key, f, FRAMES);
            let mut item =
                LodDrawItem::from_draw(&lods.sphere, model(f), lods.colors[usize::from(d.lod)], &d);
            item.sway = [0.1, phase(f)];
            // Without following, the draw claims it stood still: the older LOD is read where
            // the object is now, not where it was.
            let before = if follow { f.saturating_sub(1) } else { f };
            item.prev_model = model(before);
            item.prev_sway_phase = phase(before);
            let index = s.buffer_index();
            let lod_view = LodView {
                view_proj: proj * view,
                prev_view_proj: proj * view,
            };
            let m = match f {
                0 => CombinePass::NO_HISTORY,
                _ => new_to_old_matrix(&view, &proj, &view, &proj),
            };
            let combined = lods.frame(gpu, &buffers, index, lod_view, item, m);
            if d.id == 0 || !item.shows_anything() {
                // Not in transition (an n-instance, id 0, nothing to tell it by), or the draw
                // is skipped: the object is the older buffer's alone.
                continue;
            }
            checked += 1;
            let ids = read_texture(gpu, buffers.id(index), 4).unwrap();
            let (seen, covered) = holes(&ids, &combined);
            assert!(
                covered > 1000,
                "frame {f}: the sphere covers {covered} pixels ({d:?})"
            );
            worst = worst.max(seen);
            total += seen;
            if f == 6 {
                let image = lodkit::gpu::frame_sequential::read_lod_image(gpu, &buffers, index);
                center_motion = image
                    .unwrap()
                    .motion_at(lod_center(model(f), proj * view, W));
            }
        }
        assert!(checked >= FRAMES - 1, "only {checked} frames checked");
        if follow {
            assert_eq!(
                total, 0,
                "following the object's motion, the background showed through on {total} \
                 pixels (at most {worst} in a frame)"
            );
            // The sphere's front point (0, 0, 1) slid 0.05 units right since the last frame and
            // swayed by 0.1 sin(phase + 1) (passes/lod_buffer_mesh.wgsl): the motion points back
            // to where it was.
            let x = |f: u64| model(f).w_axis.x + 0.1 * (phase(f) + 1.0).sin();
            let ndc = |f: u64| {
                let c = proj * view * Vec4::new(x(f), 0.0, 1.0, 1.0);
                c.x / c.w
            };
            let want = (ndc(5) - ndc(6)) * 0.5;
            assert!(
                (center_motion.x - want).abs() < 2e-3 && center_motion.y.abs() < 2e-3,
                "object motion at the sphere's center {center_motion}, want ({want}, 0)"
            );
        } else {
            assert!(
                total > 50,
                "reading the older LOD where the object is now should uncover the background \
                 behind it (the test cannot tell otherwise): {total} pixels"
            );
        }
        rows.push(format!(
            "follow motion {follow}: {total} see-through pixels over the transition, at most \
             {worst} in a frame"
        ));
    }
    say(&rows.join("\n"));
}

/// Index of the pixel under the object-space origin's front point (0, 0, 1) of `model`.
fn lod_center(model: Mat4, view_proj: Mat4, size: u32) -> usize {
    let clip = view_proj * model * Vec4::new(0.0, 0.0, 1.0, 1.0);
    let uv = Vec2::new(clip.x / clip.w * 0.5 + 0.5, 0.5 - clip.y / clip.w * 0.5);
    let p = (uv * size as f32).as_uvec2();
    (p.y * size + p.x) as usize
}

/// Pixels each LOD covers alone at a frame: `item` drawn with every fragment shown into buffer 0
/// of `scratch`, read back as id words (not 0 where it covers).
fn coverage(
    gpu: &lodkit::gpu::GpuContext,
    lods: &SphereLods,
    scratch: &LodBuffers,
    view_proj: Mat4,
    item: LodDrawItem,
) -> Vec<bool> {
    let whole = LodDrawItem {
        id: 1,
        tau: 1.0,
        tau_next: 1.0,
        ..item
    };
    lods.renderer
        .render(
            gpu,
            scratch,
            &LodBufferFrame {
                index: 0,
                view: view_proj.into(),
                items: &[whole],
                clear: wgpu::Color::BLACK,
                ..Default::default()
            },
        )
        .unwrap();
    read_texture(gpu, scratch.id(0), 4)
        .unwrap()
        .chunks(4)
        .map(|w| w != [0; 4])
        .collect()
}

#[test]
fn lods_that_sway_apart_keep_each_other_covered() {
    const W: u32 = 96;
    const FRAMES: u32 = 12;
    let gpu = lodkit_test_gpu!();
    // The two LODs of an animated t-instance are different surfaces, and a wind that depends on
    // the surface point moves them differently (the demo's trees). Here they sway in opposite
    // phase: where the newer LOD moved right, the older one moved left, so the newer pixel's
    // motion leads away from the older LOD. Where both cover a pixel, no background may show.
    let lods = SphereLods::new(gpu, W);
    let view_proj = lods.proj
        * glam::camera::rh::view::look_at_mat4(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y);
    let phase = |f: u64, lod: u8| f as f32 * 0.35 + f32::from(lod) * std::f32::consts::PI;
    let buffers = LodBuffers::new(gpu, W, W, SphereLods::FORMAT).unwrap();
    let scratch = LodBuffers::new(gpu, W, W, SphereLods::FORMAT).unwrap();
    let mut s = TransitionScheduler::with_schedule(Schedule::Complementary);
    let key = s.insert(0);
    let (mut total, mut worst, mut interior, mut apart) = (0usize, 0usize, 0usize, 0usize);
    for f in 0..u64::from(FRAMES) + 4 {
        let d = transition_frame(&mut s, key, f, FRAMES);
        let item_of = |lod: u8| {
            let mut item = LodDrawItem::from_draw(
                &lods.sphere,
                Mat4::IDENTITY,
                lods.colors[usize::from(lod)],
                &d,
            );
            item.sway = [0.05, phase(f, lod)];
            item.prev_sway_phase = phase(f.saturating_sub(1), lod);
            item
        };
        let view = LodView {
            view_proj,
            prev_view_proj: view_proj,
        };
        let m = match f {
            0 => CombinePass::NO_HISTORY,
            _ => Mat4::IDENTITY,
        };
        let item = item_of(d.lod);
        let combined = lods.frame(gpu, &buffers, s.buffer_index(), view, item, m);
        if d.id == 0 || !item.shows_anything() {
            continue;
        }
        let both: Vec<bool> = {
            let a = coverage(gpu, &lods, &scratch, view_proj, item_of(0));
            let b = coverage(gpu, &lods, &scratch, view_proj, item_of(1));
            apart += a.iter().zip(&b).filter(|(a, b)| a != b).count();
            a.iter().zip(&b).map(|(a, b)| *a && *b).collect()
        };
        let black = |p: usize| combined[p * 4..p * 4 + 3].iter().all(|&c| c < 8);
        let seen = (0..both.len()).filter(|&p| both[p] && black(p)).count();
        interior += both.iter().filter(|b| **b).count();
        worst = worst.max(seen);
        total += seen;
    }
    assert!(
        interior > 10_000 && apart > 100,
        "the LODs cover {interior} pixels together over the transition and {apart} apart: \
         the test would see nothing"
    );
    assert_eq!(
        total, 0,
        "the background showed through {total} pixels both LODs cover (at most {worst} in a frame)"
    );
    say(&format!(
        "LODs swaying apart: {total} see-through pixels of {interior} both cover over the \
         transition ({apart} covered by one LOD only)"
    ));
}
