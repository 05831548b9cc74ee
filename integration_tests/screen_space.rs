//! The visibility pattern anchored to the screen: `lodkit::visibility::visibility_screen_texel`,
//! `visibility_next_coord` and `visibility_flags_screen` on the GPU (WGSL and GLSL twins)
//! against their Rust twins, and a t-instance sliding through a transition, where every pixel
//! must show the LOD the screen pattern gives it at the frame displayed.

use glam::{Mat4, UVec2, Vec2, Vec3, Vec4};
use lodkit::frame_sequential::{Drive, Schedule, TransitionScheduler};
use lodkit::gpu::frame_sequential::{CombinePass, LodBuffers};
use lodkit::gpu::readback::read_texture;
use lodkit::reproject::new_to_old_matrix;
use lodkit::shaders::SourceLanguage;
use lodkit::visibility::{
    VisibilityPattern, VisibilitySpace, visibility_flags_screen, visibility_next_coord,
    visibility_screen_texel, visibility_shown, visibility_texture,
};
use lodkit_scenes::lod_buffer::{LodDrawItem, LodView};

use crate::display_time::SphereLods;
use crate::harness::{Probe, floats, run_with, say, words};

#[test]
fn screen_space_visibility_twins_match() {
    let gpu = lodkit_test_gpu!();
    let tex = visibility_texture(VisibilityPattern::BlueNoise, 64, 5);
    let viewport = Vec2::new(320.0, 180.0);
    // (frag coord, then clip, tau now, tau next): positions on and off the screen (either sign,
    // past one tile), every fifth point behind the previous camera.
    let cases: Vec<(Vec2, Vec4, f32, f32)> = lodkit::noise::white_noise(8 * 80, 9)
        .chunks(8)
        .enumerate()
        .map(|(i, r)| {
            let frag = Vec2::new(r[0] * 400.0 - 40.0, r[1] * 260.0 - 40.0).floor() + 0.5;
            let w = if i % 5 == 4 { -0.5 } else { 0.5 + r[5] };
            let then = Vec4::new(r[2] * 2.4 - 1.2, r[3] * 2.4 - 1.2, r[4], 1.0) * w;
            (frag, then, r[6] * 2.0 - 1.0, r[7] * 2.0 - 1.0)
        })
        // A point just in front of the previous camera: the prediction flies far off screen.
        .chain([
            (
                Vec2::new(10.5, 20.5),
                Vec4::new(0.3, -0.2, 1e-31, 1e-30),
                0.5,
                0.5,
            ),
            (
                Vec2::new(10.5, 20.5),
                Vec4::new(-0.3, 0.2, 1e-31, 1e-30),
                0.5,
                0.5,
            ),
        ])
        .collect();
    let inputs: Vec<u32> = cases
        .iter()
        .flat_map(|(f, t, a, b)| words(&[f.x, f.y, t.x, t.y, t.z, t.w, *a, *b]))
        .collect();
    let want: Vec<u32> = cases
        .iter()
        .flat_map(|(f, t, a, b)| {
            let next = visibility_next_coord(*f, *t, viewport);
            let texel = visibility_screen_texel(UVec2::splat(64), next);
            let flags = visibility_flags_screen(&tex, *f, next, *a, *b);
            let mut w = words(&[next.x, next.y]);
            w.extend([texel.x, texel.y, flags]);
            w
        })
        .collect();
    let wgsl = "let f = vec2(inp_f(0u), inp_f(1u));
        let next = visibility_next_coord(f, vec4(inp_f(2u), inp_f(3u), inp_f(4u), inp_f(5u)), vec2(320.0, 180.0));
        let t = visibility_screen_texel(vec2(64u), next);
        out_f(0u, next.x); out_f(1u, next.y); out_u(2u, t.x); out_u(3u, t.y);
        out_u(4u, visibility_flags_screen(probe_tex, f, next, inp_f(6u), inp_f(7u)));";
    let glsl = "vec2 f = vec2(inp_f(0u), inp_f(1u));
        vec2 next = lodkit_visibility_next_coord(f, vec4(inp_f(2u), inp_f(3u), inp_f(4u), inp_f(5u)), vec2(320.0, 180.0));
        uvec2 t = lodkit_visibility_screen_texel(uvec2(64u), next);
        out_f(0u, next.x); out_f(1u, next.y); out_u(2u, t.x); out_u(3u, t.y);
        out_u(4u, lodkit_visibility_flags_screen(sampler2D(probe_tex, probe_sampler), f, next, inp_f(6u), inp_f(7u)));";
    for (language, header, body) in [
        (
            SourceLanguage::Wgsl,
            "#import lodkit::visibility::{visibility_next_coord, visibility_screen_texel, visibility_flags_screen}",
            wgsl,
        ),
        (
            SourceLanguage::Glsl(naga::ShaderStage::Compute),
            "#include \"lodkit/visibility.glsl\"",
            glsl,
        ),
    ] {
        let probe = Probe {
            header,
            body,
            inputs: 8,
            outputs: 5,
            texture: Some((64, &tex.texels)),
            rgba: &[],
            urgba: &[],
        };
        let got = run_with(gpu, &probe, &inputs, language, &[]);
        for (i, (g, w)) in got.chunks(5).zip(want.chunks(5)).enumerate() {
            let (gn, wn) = (floats(&g[..2]), floats(&w[..2]));
            let close = |g: f32, w: f32| (g - w).abs() <= 1e-3 * (1.0 + w.abs() * 1e-3);
            assert!(
                close(gn[0], wn[0]) && close(gn[1], wn[1]),
                "{language:?} case {i}: next coord {gn:?} vs {wn:?}"
            );
            // A predicted position within 1e-3 px of a pixel edge may floor either way.
            // (Past 2^23 every float is whole and exact: the clamp decides, not the rounding.)
            let edge = wn
                .iter()
                .any(|v| v.abs() < 8e6 && (v - v.round()).abs() < 1e-3);
            if !edge {
                assert_eq!(g[2..], w[2..], "{language:?} case {i}: texel and flags");
            }
        }
    }
    // Hand-derived: behind the previous camera the fragment stays put; the texel wraps for
    // negative positions; all four flag combinations occur.
    let behind = cases.iter().position(|c| c.1.w < 0.0).unwrap();
    assert_eq!(
        visibility_next_coord(cases[behind].0, cases[behind].1, viewport),
        cases[behind].0
    );
    assert_eq!(
        visibility_screen_texel(UVec2::splat(64), Vec2::new(-1.5, 64.5)),
        UVec2::new(62, 0)
    );
    let far = floats(&want[want.len() - 5..want.len() - 3]);
    assert!(far.iter().all(|v| v.abs() > 1e20), "{far:?}");
    let seen = want.chunks(5).fold(0u32, |m, w| m | (1 << w[4]));
    assert_eq!(seen, 0b1111, "flags 0..=3 all occur: {seen:b}");
}

/// Shares of the pixels both LODs cover (LOD 0 red, LOD 1 blue) where the combined image shows
/// the LOD the screen pattern gives the pixel at `progress` (complementary: blue where the texel
/// is at most the progress), and where it shows the other LOD than in the frame before.
struct Agreement {
    matches: usize,
    switched: usize,
    pixels: usize,
}

#[test]
fn a_screen_anchored_pattern_holds_still_while_the_object_slides() {
    const W: u32 = 96;
    let gpu = lodkit_test_gpu!();
    let mut lods = SphereLods::new(gpu, W);
    // The texture SphereLods' renderer draws with.
    let tex = visibility_texture(VisibilityPattern::BlueNoise, 64, 2);
    let look = glam::camera::rh::view::look_at_mat4(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y);
    let view_proj = lods.proj * look;
    // The sphere slides 1.5 px a frame (0.06 units at this distance) while the progress holds
    // at 0.4, so the pattern alone decides which LOD a pixel shows.
    let model = |f: u64| Mat4::from_translation(Vec3::new(f as f32 * 0.06 - 0.4, 0.0, 0.0));
    let mut rows = Vec::new();
    let mut results = Vec::new();
    for space in [VisibilitySpace::Screen, VisibilitySpace::Object] {
        lods.renderer.set_visibility_space(space);
        assert_eq!(lods.renderer.visibility_space(), space);
        let buffers = LodBuffers::new(gpu, W, W, SphereLods::FORMAT).unwrap();
        let mut s = TransitionScheduler::with_schedule(Schedule::Complementary);
        let key = s.insert(0);
        let mut a = Agreement {
            matches: 0,
            switched: 0,
            pixels: 0,
        };
        let mut previous: Option<Vec<u8>> = None;
        for f in 0..10u64 {
            if f > 0 {
                s.advance(1.0 / 60.0);
            }
            if f == 1 {
                s.begin_transition(key, 1, Drive::Progress).unwrap();
            }
            if f >= 1 {
                s.set_progress(key, 0.4).unwrap();
                s.set_next_progress(key, 0.4).unwrap();
            }
            let d = s.draw(key).unwrap();
            let mut item =
                LodDrawItem::from_draw(&lods.sphere, model(f), lods.colors[usize::from(d.lod)], &d);
            item.prev_model = model(f.saturating_sub(1));
            let view = LodView {
                view_proj,
                prev_view_proj: view_proj,
            };
            let m = match f {
                0 => CombinePass::NO_HISTORY,
                _ => new_to_old_matrix(&look, &lods.proj, &look, &lods.proj),
            };
            let combined = lods.frame(gpu, &buffers, s.buffer_index(), view, item, m);
            if f < 3 {
                // Both buffers hold the transition from frame 2 on.
                previous = Some(combined);
                continue;
            }
            let ids = read_texture(gpu, buffers.id(s.buffer_index()), 4).unwrap();
            for p in 0..(W * W) as usize {
                let c = &combined[p * 4..p * 4 + 3];
                let (red, blue) = (c[0] > 40 && c[2] < 8, c[2] > 40 && c[0] < 8);
                let object = ids[p * 4..p * 4 + 4] != [0; 4];
                // Pixels of the object that show it (red, blue, or the average of both).
                if !object || c.iter().all(|&x| x < 8) {
                    continue;
                }
                a.pixels += 1;
                let frag = Vec2::new((p as u32 % W) as f32, (p as u32 / W) as f32) + 0.5;
                let v = tex.lookup_screen(frag);
                let want_blue = visibility_shown(v, 0.4);
                a.matches += usize::from((want_blue && blue) || (!want_blue && red));
                if let Some(prev) = &previous {
                    let pc = &prev[p * 4..p * 4 + 3];
                    let prev_blue = pc[2] > 40 && pc[0] < 8;
                    let prev_red = pc[0] > 40 && pc[2] < 8;
                    a.switched += usize::from((prev_blue && red) || (prev_red && blue));
                }
            }
            previous = Some(combined);
        }
        rows.push(format!(
            "{space:?}: {} of {} pixels show the LOD the screen pattern gives them, {} switched \
             LOD from one frame to the next",
            a.matches, a.pixels, a.switched
        ));
        results.push(a);
    }
    say(&rows.join("\n"));
    let (screen, object) = (&results[0], &results[1]);
    assert!(screen.pixels > 10_000, "{}", rows[0]);
    assert!(
        screen.matches * 100 >= screen.pixels * 97,
        "anchored to the screen, a pixel shows what the pattern under it says: {}",
        rows[0]
    );
    assert!(
        screen.switched * 100 <= screen.pixels * 3,
        "anchored to the screen, the pattern holds still: {}",
        rows[0]
    );
    // The object-space pattern slides with the sphere, so many pixels switch LOD each frame:
    // the test tells the two apart.
    assert!(
        object.switched * 100 >= object.pixels * 20,
        "anchored to the object, the pattern should slide: {}",
        rows[1]
    );
}
