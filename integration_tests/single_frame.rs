//! Single-frame transitions: complementary screen-door dither and unpopping, on the GPU against
//! their Rust twins, and rendered: how much background shows through a transitioning object.

use glam::Vec2;
use lodkit::screen_door::{
    BAYER_4X4, DitherPattern, blue_noise_ranks, pack_ranks, screen_door_keep_with,
};
use lodkit::shaders::{self, SourceLanguage};
use lodkit::unpopping::{unpopping_alpha, unpopping_is_opaque, unpopping_plan};
use lodkit_scenes::transition::{SceneParts, SingleFrameTechnique, TransitionScene, see_through};

use crate::harness::{Probe, floats, run_with, say, words};

const TILE: u32 = 64;

pub(crate) fn screen_door_cases() -> (Vec<f32>, Vec<u32>) {
    let ts: Vec<f32> = (0..=16).map(|k| k as f32 / 16.0).collect();
    let mut cases = Vec::new();
    for &t in &ts {
        for y in 0..TILE {
            cases.extend([t.to_bits(), y]);
        }
    }
    (ts, cases)
}

/// Keep-bits of the current (-(1 - t)) and next (+t) LOD for every pixel of a 64x64 tile.
pub(crate) fn rust_bits(pattern: DitherPattern, ts: &[f32]) -> Vec<u32> {
    let mut out = Vec::new();
    for &t in ts {
        for y in 0..TILE {
            let mut words = [0u32; 4];
            for x in 0..TILE {
                let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let bit = 1 << (x % 32);
                if screen_door_keep_with(pattern, p, -(1.0 - t)) {
                    words[(x / 32) as usize] |= bit;
                }
                if screen_door_keep_with(pattern, p, t) {
                    words[2 + (x / 32) as usize] |= bit;
                }
            }
            out.extend(words);
        }
    }
    out
}

fn check_coverage(bits: &[u32], what: &str) {
    for (row, w) in bits.chunks(4).enumerate() {
        let (t_index, y) = (row / TILE as usize, row % TILE as usize);
        for half in 0..2 {
            let (current, next) = (w[half], w[2 + half]);
            assert_eq!(
                current | next,
                u32::MAX,
                "{what}: a pixel with no LOD at t = {t_index}/16, row {y}"
            );
            assert_eq!(
                current & next,
                0,
                "{what}: a pixel with both LODs at t = {t_index}/16, row {y}"
            );
        }
    }
    // The share of the next LOD is exactly t on the 64x64 tile.
    for (k, rows) in bits.chunks(4 * TILE as usize).enumerate() {
        let next: u32 = rows
            .chunks(4)
            .map(|w| w[2].count_ones() + w[3].count_ones())
            .sum();
        assert_eq!(
            next,
            (k as u32) * TILE * TILE / 16,
            "{what}: coverage at t = {k}/16"
        );
    }
}

/// The WGSL probe of `screen_door_keep`: keep-bits of both LODs (-(1 - t) and +t) along one
/// row of the 64x64 tile, per case (t, row) of [`screen_door_cases`].
pub(crate) const SCREEN_DOOR_PROBE: Probe<'static> = Probe {
    header: "#import lodkit::screen_door::screen_door_keep",
    body: SCREEN_DOOR_WGSL,
    inputs: 2,
    outputs: 4,
    texture: None,
    rgba: &[],
    urgba: &[],
};

const SCREEN_DOOR_WGSL: &str = "let t = inp_f(0u); let y = f32(inp_u(1u)) + 0.5;
               var w = array<u32, 4>(0u, 0u, 0u, 0u);
               for (var x = 0u; x < 64u; x++) {
                   let p = vec2<f32>(f32(x) + 0.5, y);
                   if (screen_door_keep(p, -(1.0 - t))) { w[x / 32u] |= 1u << (x % 32u); }
                   if (screen_door_keep(p, t)) { w[2u + x / 32u] |= 1u << (x % 32u); }
               }
               out_u(0u, w[0]); out_u(1u, w[1]); out_u(2u, w[2]); out_u(3u, w[3]);";

#[test]
fn screen_door_twins_are_complementary_on_the_gpu() {
    let gpu = lodkit_test_gpu!(device);
    let (ts, cases) = screen_door_cases();
    let wgsl = SCREEN_DOOR_PROBE;
    let glsl = Probe {
        header: "#include \"lodkit/screen_door.glsl\"",
        body: "float t = inp_f(0u); float y = float(inp_u(1u)) + 0.5;
               uint w[4] = uint[4](0u, 0u, 0u, 0u);
               for (uint x = 0u; x < 64u; x++) {
                   vec2 p = vec2(float(x) + 0.5, y);
                   if (lodkit_screen_door_keep(p, -(1.0 - t))) { w[x / 32u] |= 1u << (x % 32u); }
                   if (lodkit_screen_door_keep(p, t)) { w[2u + x / 32u] |= 1u << (x % 32u); }
               }
               out_u(0u, w[0]); out_u(1u, w[1]); out_u(2u, w[2]); out_u(3u, w[3]);",
        inputs: 2,
        outputs: 4,
        texture: None,
        rgba: &[],
        urgba: &[],
    };
    for (pattern, defs) in [
        (DitherPattern::Bayer4x4, &[][..]),
        (
            DitherPattern::BlueNoise16x16,
            &["LODKIT_SCREEN_DOOR_BLUE_NOISE"][..],
        ),
    ] {
        let want = rust_bits(pattern, &ts);
        check_coverage(&want, &format!("Rust {pattern:?}"));
        let got = run_with(gpu, &wgsl, &cases, SourceLanguage::Wgsl, defs);
        assert_eq!(
            got, want,
            "WGSL screen_door_keep ({pattern:?}) differs from the Rust twin"
        );
        let got = run_with(
            gpu,
            &glsl,
            &cases,
            SourceLanguage::Glsl(naga::ShaderStage::Compute),
            defs,
        );
        assert_eq!(
            got, want,
            "GLSL lodkit_screen_door_keep ({pattern:?}) differs from the Rust twin"
        );
    }
}

#[test]
fn unpopping_twins_match_on_the_gpu() {
    let gpu = lodkit_test_gpu!(device);
    let ts: Vec<f32> = (-4..=68)
        .map(|k| k as f32 / 64.0)
        .chain([0.5, 0.4999999, 0.5000001])
        .collect();
    let cases = words(&ts);
    let wgsl = Probe {
        header: "#import lodkit::unpopping::{unpopping_alpha, unpopping_is_opaque}",
        body: "let t = inp_f(0u);
               out_f(0u, unpopping_alpha(t, false)); out_f(1u, unpopping_alpha(t, true));
               out_u(2u, u32(unpopping_is_opaque(t, false))); out_u(3u, u32(unpopping_is_opaque(t, true)));",
        inputs: 1,
        outputs: 4,
        texture: None,
    rgba: &[],
    urgba: &[],
    };
    let glsl = Probe {
        header: "#include \"lodkit/unpopping.glsl\"",
        body: "float t = inp_f(0u);
               out_f(0u, lodkit_unpopping_alpha(t, false)); out_f(1u, lodkit_unpopping_alpha(t, true));
               out_u(2u, uint(lodkit_unpopping_is_opaque(t, false))); out_u(3u, uint(lodkit_unpopping_is_opaque(t, true)));",
        inputs: 1,
        outputs: 4,
        texture: None,
    rgba: &[],
    urgba: &[],
    };
    let want: Vec<u32> = ts
        .iter()
        .flat_map(|&t| {
            [
                unpopping_alpha(t, false).to_bits(),
                unpopping_alpha(t, true).to_bits(),
                u32::from(unpopping_is_opaque(t, false)),
                u32::from(unpopping_is_opaque(t, true)),
            ]
        })
        .collect();
    for (language, probe) in [
        (SourceLanguage::Wgsl, &wgsl),
        (SourceLanguage::Glsl(naga::ShaderStage::Compute), &glsl),
    ] {
        let got = run_with(gpu, probe, &cases, language, &[]);
        for (i, (g, w)) in got.chunks(4).zip(want.chunks(4)).enumerate() {
            let (ga, wa) = (floats(&g[..2]), floats(&w[..2]));
            assert!(
                (ga[0] - wa[0]).abs() <= 1e-6 && (ga[1] - wa[1]).abs() <= 1e-6,
                "{language:?} t = {}: {ga:?} vs {wa:?}",
                ts[i]
            );
            assert_eq!(g[2..], w[2..], "{language:?} opaque flags at t = {}", ts[i]);
        }
    }
}

#[test]
fn unpopping_always_has_exactly_one_opaque_depth_writing_lod() {
    for k in 0..=1000 {
        let t = k as f32 / 1000.0;
        let plan = unpopping_plan(t);
        assert!(
            plan.outgoing.depth_write != plan.incoming.depth_write,
            "t = {t}"
        );
        assert!(plan.outgoing.blend != plan.incoming.blend, "t = {t}");
        let first = plan.state(plan.order[0]);
        assert!(
            first.depth_write && !first.blend,
            "the opaque LOD is drawn first at t = {t}"
        );
    }
}

#[test]
fn shader_tables_are_the_generated_patterns() {
    let module = shaders::find_module("lodkit::screen_door").unwrap();
    let twin = shaders::glsl_twin(module).unwrap();
    let literal = |words: &[u32]| {
        words
            .iter()
            .map(|w| format!("0x{w:08x}u"))
            .collect::<Vec<_>>()
    };
    for (name, words) in [
        ("BAYER_4X4", pack_ranks(&BAYER_4X4, 4)),
        ("BLUE_NOISE_16X16", pack_ranks(blue_noise_ranks(), 8)),
    ] {
        for source in [module.source, twin.source] {
            let decl = source
                .lines()
                .position(|l| l.starts_with("const") && l.contains(&format!("SCREEN_DOOR_{name}")))
                .unwrap();
            let body: String = source.lines().skip(decl).collect::<Vec<_>>().join("\n");
            let body = body
                .split(';')
                .next()
                .unwrap()
                .split_once('=')
                .unwrap()
                .1
                .to_owned();
            let found: Vec<String> = body
                .split(|c: char| !c.is_ascii_alphanumeric())
                .filter(|w| w.starts_with("0x"))
                .map(str::to_owned)
                .collect();
            assert_eq!(
                found,
                literal(&words),
                "{name} in the shader is not the generated table"
            );
        }
    }
}

#[test]
fn blue_noise_has_less_low_frequency_power_than_white_noise() {
    let blue: Vec<f32> = blue_noise_ranks()
        .iter()
        .map(|&r| r as f32 / 255.0)
        .collect();
    let white = lodkit::noise::white_noise(256, 7);
    let b = lodkit::noise::radial_power_spectrum(&blue, 16);
    let w = lodkit::noise::radial_power_spectrum(&white, 16);
    let low = |s: &[f32]| s[..3].iter().sum::<f32>() / 3.0;
    let all = |s: &[f32]| s.iter().sum::<f32>() / s.len() as f32;
    // Normalised by each pattern's mean power, the three lowest rings of blue noise hold far less.
    let (rb, rw) = (low(&b) / all(&b), low(&w) / all(&w));
    say(&format!(
        "low-frequency power / mean power: blue noise {rb:.4}, white noise {rw:.4}"
    ));
    assert!(rb < 0.1 * rw, "blue {rb} vs white {rw}");
}

#[test]
fn unpopping_shows_no_background_through_the_object_cross_fade_does() {
    let gpu = lodkit_test_gpu!();
    let scene = TransitionScene::new(gpu, 96, 96).unwrap();
    let fine = scene
        .render(
            gpu,
            SingleFrameTechnique::Unpopping,
            0.0,
            SceneParts::FineOnly,
        )
        .unwrap();
    let coarse = scene
        .render(
            gpu,
            SingleFrameTechnique::Unpopping,
            0.0,
            SceneParts::CoarseOnly,
        )
        .unwrap();
    let mut rows = Vec::new();
    for technique in SingleFrameTechnique::ALL {
        for t in [0.25f32, 0.5, 0.75] {
            let image = scene.render(gpu, technique, t, SceneParts::All).unwrap();
            let (share, red) = see_through(&image, &fine, &coarse);
            rows.push(format!(
                "{:<18} t={t:<4} see-through {:>6.1}% of interior, mean red {red:.3}",
                technique.name(),
                share * 100.0
            ));
            match technique {
                SingleFrameTechnique::CrossFade => {
                    assert!(share > 0.9, "cross-fade should show the backdrop: {share}")
                }
                _ => assert_eq!(
                    share,
                    0.0,
                    "{} shows the backdrop at t = {t}",
                    technique.name()
                ),
            }
        }
    }
    say(&rows.join("\n"));
}
