//! The packed low-resolution texel of framebuffer LOD (`lodkit::gbuffer`'s packed layout) and
//! the 4-fetch upsample that reads it: WGSL and GLSL on the GPU against the Rust twins, bit for
//! bit where the shaders only move bits, and against the unpacked upsample within half precision.

use glam::{UVec4, Vec2, Vec3, Vec4};
use lodkit::bilateral::{Image, bilateral_upsample_at, bilateral_upsample_packed_at};
use lodkit::gbuffer::{gbuffer_pack_half2, gbuffer_pack_texel, gbuffer_unpack_half2};
use lodkit::shaders::SourceLanguage;

use crate::harness::{Probe, Word, assert_close, assert_twin, floats, run_with, words};

const GLSL: SourceLanguage = SourceLanguage::Glsl(naga::ShaderStage::Compute);

/// Floats at the edges of the half range and of the rounding, and a spread between.
fn half_inputs() -> Vec<f32> {
    let mut v = vec![
        0.0,
        -0.0,
        1.0,
        -2.0,
        0.1,
        1.0 / 3.0,
        65504.0,
        65519.0,      // rounds down to the largest half
        65520.0,      // would round to infinity: clamped
        1.0e9,        // clamped
        -1.0e9,       // clamped, sign kept
        6.1035156e-5, // 2^-14, the smallest normal half
        6.0e-5,       // below it: zero
        -1.0e-20,     // below 2^-14: +0, whatever the sign
        1.0009766,    // 1 + 2^-10, one half step
        1.0004883,    // 1 + 2^-11: a tie, away from zero
        -1.0004883,
        2047.5,
        2049.0, // a tie at a step of 2
    ];
    let mut x = 7.0e-5_f32;
    while x < 70000.0 {
        v.extend([x, -x * 1.37]);
        x *= 1.7;
    }
    if v.len() % 2 == 1 {
        v.push(0.5);
    }
    v
}

fn probe<'a>(
    header: &'a str,
    body: &'a str,
    inputs: usize,
    outputs: usize,
    urgba: &'a [(u32, u32, &'a [[u32; 4]])],
) -> Probe<'a> {
    Probe {
        header,
        body,
        inputs,
        outputs,
        texture: None,
        rgba: &[],
        urgba,
    }
}

#[test]
fn half_packing_twins_match_bit_for_bit() {
    let gpu = lodkit_test_gpu!(device);
    let values = half_inputs();
    let inputs = words(&values);
    let want: Vec<u32> = values
        .chunks(2)
        .map(|p| gbuffer_pack_half2(Vec2::new(p[0], p[1])))
        .collect();
    let want_back: Vec<f32> = want
        .iter()
        .flat_map(|w| gbuffer_unpack_half2(*w).to_array())
        .collect();
    for (language, header, body) in [
        (
            SourceLanguage::Wgsl,
            "#import lodkit::gbuffer::{gbuffer_pack_half2, gbuffer_unpack_half2}",
            "let w = gbuffer_pack_half2(vec2<f32>(inp_f(0u), inp_f(1u)));
             let b = gbuffer_unpack_half2(w);
             out_u(0u, w); out_f(1u, b.x); out_f(2u, b.y);",
        ),
        (
            GLSL,
            "#include \"lodkit/gbuffer.glsl\"",
            "uint w = lodkit_gbuffer_pack_half2(vec2(inp_f(0u), inp_f(1u)));
             vec2 b = lodkit_gbuffer_unpack_half2(w);
             out_u(0u, w); out_f(1u, b.x); out_f(2u, b.y);",
        ),
    ] {
        let got = run_with(gpu, &probe(header, body, 2, 3, &[]), &inputs, language, &[]);
        let packed: Vec<u32> = got.chunks(3).map(|c| c[0]).collect();
        let back: Vec<u32> = got.chunks(3).flat_map(|c| [c[1], c[2]]).collect();
        for (k, (g, w)) in packed.iter().zip(&want).enumerate() {
            assert_eq!(
                g,
                w,
                "{language:?} gbuffer_pack_half2({}, {}): {g:#010x}, the Rust twin {w:#010x}",
                values[2 * k],
                values[2 * k + 1]
            );
        }
        // Unpacking moves bits and scales a normal float by 2^112: exact, compared as floats
        // (+0 and -0 equal: the word of a zero carries no sign, but a GPU need not keep one).
        let kinds = [Word::Float(0.0); 2];
        assert_twin(
            &back,
            &words(&want_back),
            &kinds,
            &format!("{language:?} gbuffer_unpack_half2"),
        );
    }
}

/// An L of 6x5 texels (5x4 rendered) with a depth step between columns 2 and 3, HDR colors
/// (up to 40) and tilted normals; the full-res pixels of a 10x8 target on either side.
struct Fixture {
    colors: Vec<Vec4>,
    geometry: Vec<Vec4>,
    packed: Vec<[u32; 4]>,
    pixels: Vec<(Vec2, f32, Vec3)>,
}

const LW: u32 = 6;
const LH: u32 = 5;
const VIEWPORT: Vec2 = Vec2::new(5.0, 4.0);
const FULL: Vec2 = Vec2::new(10.0, 8.0);

fn fixture() -> Fixture {
    let noise = lodkit::noise::white_noise((LW * LH * 8) as usize, 33);
    let colors: Vec<Vec4> = noise
        .chunks(8)
        .map(|c| Vec4::new(40.0 * c[0], c[1], 0.01 * c[2], 1.0))
        .collect();
    let normals: Vec<Vec3> = noise
        .chunks(8)
        .map(|c| Vec3::new(c[5] * 0.8 - 0.4, c[6] * 0.8 - 0.4, 0.8).normalize())
        .collect();
    let depths: Vec<f32> = (0..LW * LH)
        .map(|i| {
            let n = noise[(i * 8 + 3) as usize];
            if (i % LW) < 3 {
                3.0 + 0.1 * n
            } else {
                9.0 + 0.1 * n
            }
        })
        .collect();
    let geometry = depths
        .iter()
        .zip(&normals)
        .map(|(d, n)| Vec4::new(*d, n.x, n.y, n.z))
        .collect();
    let packed = (0..colors.len())
        .map(|i| gbuffer_pack_texel(colors[i], depths[i], normals[i]).to_array())
        .collect();
    let pixels = (0..80)
        .map(|i| {
            let p = Vec2::new((i % 10) as f32 + 0.5, (i / 10) as f32 + 0.5);
            let depth = if p.x < 6.0 { 3.05 } else { 9.05 };
            (p, depth, Vec3::new(0.1, -0.1, 0.99).normalize())
        })
        .collect();
    Fixture {
        colors,
        geometry,
        packed,
        pixels,
    }
}

#[test]
fn packed_texel_twins_match_word_for_word_and_within_a_half_step() {
    let gpu = lodkit_test_gpu!(device);
    let f = fixture();
    let inputs: Vec<u32> = (0..f.colors.len())
        .flat_map(|i| {
            let (c, g) = (f.colors[i], f.geometry[i]);
            words(&[c.x, c.y, c.z, c.w, g.x, g.y, g.z, g.w])
        })
        .collect();
    let want: Vec<u32> = f.packed.iter().flatten().copied().collect();
    let fetch = "vec4(inp_f(0u), inp_f(1u), inp_f(2u), inp_f(3u)), inp_f(4u), vec3(inp_f(5u), inp_f(6u), inp_f(7u))";
    let wgsl = format!("let t = gbuffer_pack_texel({fetch}); out_u(0u, t.x); out_u(1u, t.y); out_u(2u, t.z); out_u(3u, t.w);")
        .replace("vec4(", "vec4<f32>(")
        .replace("vec3(", "vec3<f32>(");
    let glsl = format!(
        "uvec4 t = lodkit_gbuffer_pack_texel({fetch}); out_u(0u, t.x); out_u(1u, t.y); out_u(2u, t.z); out_u(3u, t.w);"
    );
    for (language, header, body) in [
        (
            SourceLanguage::Wgsl,
            "#import lodkit::gbuffer::gbuffer_pack_texel",
            wgsl.as_str(),
        ),
        (GLSL, "#include \"lodkit/gbuffer.glsl\"", glsl.as_str()),
    ] {
        let got = run_with(gpu, &probe(header, body, 8, 4, &[]), &inputs, language, &[]);
        check_texels(&got, &want, &format!("{language:?} gbuffer_pack_texel"));
    }
}

/// Packed texels against the twin's: the color halves and the depth bits only move bits (exact);
/// the normal's halves come from a division (n.xy / n.z: 2.5 ULP on a GPU, 0.5 on the CPU), so
/// the two quotients may round to neighbouring halves: each within one half step (2^-10 of its
/// magnitude, or 2^-14 where one side fell below the smallest normal half and became 0).
fn check_texels(got: &[u32], want: &[u32], what: &str) {
    assert_eq!(got.len(), want.len(), "{what}: word count");
    for (k, (g, w)) in got.chunks(4).zip(want.chunks(4)).enumerate() {
        assert_eq!(g[..3], w[..3], "{what}: texel {k}: color and depth words");
        let (gn, wn) = (gbuffer_unpack_half2(g[3]), gbuffer_unpack_half2(w[3]));
        for (a, b) in [(gn.x, wn.x), (gn.y, wn.y)] {
            let step = (b.abs() * 2f32.powi(-10)).max(2f32.powi(-14));
            assert!(
                (a - b).abs() <= step,
                "{what}: texel {k}: normal halves {gn} vs the twin's {wn}"
            );
        }
    }
}

#[test]
fn packed_upsample_at_twins_match_and_stay_within_half_precision_of_the_unpacked() {
    let gpu = lodkit_test_gpu!();
    let f = fixture();
    let texels: Vec<UVec4> = f.packed.iter().map(|t| UVec4::from_array(*t)).collect();
    let low = Image {
        width: LW,
        texels: &texels,
    };
    let inputs: Vec<u32> = f
        .pixels
        .iter()
        .flat_map(|(p, d, n)| words(&[p.x, p.y, *d, n.x, n.y, n.z]))
        .collect();
    let want: Vec<f32> = f
        .pixels
        .iter()
        .flat_map(|(p, d, n)| {
            bilateral_upsample_packed_at(low, VIEWPORT, FULL, *p, *d, *n, 0.3, 0.5).to_array()
        })
        .collect();
    // The same L unpacked (f32 color and geometry), through the 8-fetch lookup.
    let unpacked: Vec<f32> = f
        .pixels
        .iter()
        .flat_map(|(p, d, n)| {
            let c = Image {
                width: LW,
                texels: &f.colors,
            };
            let g = Image {
                width: LW,
                texels: &f.geometry,
            };
            bilateral_upsample_at(c, g, VIEWPORT, FULL, *p, *d, *n, 0.3, 0.5).to_array()
        })
        .collect();
    // Half precision: 2^-11 relative, on colors up to 40, and the weights from half normals.
    for (k, (p, u)) in want.iter().zip(&unpacked).enumerate() {
        assert!(
            (p - u).abs() <= 2e-3 * u.abs().max(0.05),
            "pixel {}, channel {}: packed {p}, unpacked {u}",
            k / 4,
            k % 4
        );
    }
    let textures = [(LW, LH, &f.packed[..])];
    let call = "(probe_urgba0, vec2(5.0, 4.0), vec2(10.0, 8.0), vec2(inp_f(0u), inp_f(1u)), inp_f(2u), vec3(inp_f(3u), inp_f(4u), inp_f(5u)), 0.3, 0.5)";
    let out = "out_f(0u, r.x); out_f(1u, r.y); out_f(2u, r.z); out_f(3u, r.w);";
    let wgsl = format!("let r = bilateral_upsample_packed_at{call}; {out}");
    let glsl = format!(
        "vec4 r = lodkit_bilateral_upsample_packed_at{}; {out}",
        call.replace(
            "(probe_urgba0,",
            "(usampler2D(probe_urgba0, probe_sampler),"
        )
    );
    for (language, header, body) in [
        (
            SourceLanguage::Wgsl,
            "#import lodkit::bilateral::bilateral_upsample_packed_at",
            wgsl.as_str(),
        ),
        (GLSL, "#include \"lodkit/bilateral.glsl\"", glsl.as_str()),
    ] {
        let got = floats(&run_with(
            gpu,
            &probe(header, body, 6, 4, &textures),
            &inputs,
            language,
            &[],
        ));
        assert_close(
            &got,
            &want,
            1e-5,
            &format!("{language:?} bilateral_upsample_packed_at"),
        );
    }
}

/// A packed L drawn by the edge scene and upsampled by a pass built for `LowResLayout::Packed`
/// gives the image of
/// the unpacked route (RGBA8 target: the halves' rounding stays within one 8-bit step); an L and
/// a pass of different layouts are a `Mismatch` naming `frame.low`.
#[test]
fn packed_route_renders_the_unpacked_image_and_layouts_must_match() {
    use lodkit::gpu::GpuError;
    use lodkit::gpu::framebuffer_lod::{
        LowResBuffer, LowResLayout, UpsampleFrame, UpsamplePass, UpsamplePassDescriptor,
        UpsampleSettings,
    };
    use lodkit::gpu::readback::read_texture_rgba8;
    use lodkit::gpu::resources::texture_2d;
    use lodkit_scenes::gbuffer::EdgeScene;
    let gpu = lodkit_test_gpu!();
    let (w, h, r) = (96, 64, 2.0);
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let scene = EdgeScene::new(gpu, format, w as f32 / h as f32).unwrap();
    let full = LowResBuffer::new(gpu, w, h, format).unwrap();
    scene.render(gpu, &full, 1.0).unwrap();
    let lows = [
        LowResBuffer::new(gpu, w, h, format).unwrap(),
        LowResBuffer::packed(gpu, w, h).unwrap(),
    ];
    let passes = [LowResLayout::ColorAndGeometry, LowResLayout::Packed].map(|low_res| {
        let desc = UpsamplePassDescriptor {
            target_format: format,
            low_res,
            ..Default::default()
        };
        UpsamplePass::new(gpu, &desc).unwrap()
    });
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let target = texture_2d(gpu, (w, h), format, usage, "target").unwrap();
    let view = target.create_view(&Default::default());
    let mut images = Vec::new();
    for (low, pass) in lows.iter().zip(&passes) {
        scene.render(gpu, low, r).unwrap();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let frame = UpsampleFrame {
            low,
            full_geometry: full.geometry(),
            full_albedo: None,
            target: &view,
            settings: UpsampleSettings {
                r,
                ..Default::default()
            },
        };
        pass.record(gpu, &mut encoder, &frame).unwrap();
        gpu.queue.submit([encoder.finish()]);
        images.push(read_texture_rgba8(gpu, &target).unwrap());
    }
    let differ = images[0]
        .iter()
        .zip(&images[1])
        .filter(|(a, b)| a.abs_diff(**b) > 1)
        .count();
    crate::support::say(&format!(
        "packed route: {differ} of {} channels differ by more than one 8-bit step",
        images[0].len()
    ));
    // Measured: 0 of 24576 channels differ by more than one step (lavapipe and llvmpipe); the
    // limit leaves 4 for another GPU's rounding.
    assert!(
        differ <= 4,
        "{differ} of {} channels differ by more than 1",
        images[0].len()
    );
    assert!(
        images[1].iter().any(|v| *v > 0),
        "the packed route drew nothing"
    );
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let frame = UpsampleFrame {
        low: &lows[1],
        full_geometry: full.geometry(),
        full_albedo: None,
        target: &view,
        settings: UpsampleSettings::default(),
    };
    let wrong = passes[0].record(gpu, &mut encoder, &frame);
    assert!(
        matches!(
            wrong,
            Err(GpuError::Mismatch {
                parameter: "frame.low",
                ..
            })
        ),
        "{wrong:?}"
    );
}
