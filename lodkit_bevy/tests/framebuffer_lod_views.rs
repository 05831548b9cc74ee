//! Framebuffer LOD in a headless Bevy app on the GPU, held to hand-derived pixels: an effect's
//! own bindings (a uniform and a texture) reach its shader, and follow the asset when it
//! changes.

#[path = "../examples/common/frames.rs"]
#[allow(dead_code, reason = "shared with the examples")]
mod frames;
#[path = "../examples/common/headless.rs"]
#[allow(dead_code, reason = "shared with the examples")]
mod headless;

use bevy::asset::{RenderAssetUsages, uuid_handle};
use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::{DebandDither, Tonemapping};
use bevy::prelude::*;
use bevy::render::render_resource::{AsBindGroup, Extent3d, TextureDimension, TextureFormat};
use bevy::shader::ShaderRef;
use frames::Frame;
use lodkit_bevy::prelude::*;

const PAINT: Handle<Shader> = uuid_handle!("0c7d1f52-93a4-4b6e-8e2f-5a1b7c3d9e60");

/// Paints every pixel its uniform color times its texture's one texel, with coverage 1.
const PAINT_SOURCE: &str = "
import bevy_core_pipeline::fullscreen_vertex_shader::FullscreenVertexOutput;
import lodkit::gbuffer::GBufferOutput;
import lodkit_bevy::framebuffer_lod::{effect_sample, effect_output};

@group(constants::FRAMEBUFFER_LOD_EFFECT_BIND_GROUP) @binding(0) var<uniform> color: vec4<f32>;
@group(constants::FRAMEBUFFER_LOD_EFFECT_BIND_GROUP) @binding(1) var tint: texture_2d<f32>;
@group(constants::FRAMEBUFFER_LOD_EFFECT_BIND_GROUP) @binding(2) var tint_sampler: sampler;

@fragment
fn fragment(in: FullscreenVertexOutput) -> GBufferOutput {
    let s = effect_sample(in.position);
    let t = textureSampleLevel(tint, tint_sampler, vec2<f32>(0.5), 0.0);
    return effect_output(vec4<f32>(color.rgb * t.rgb, 1.0), s);
}
";

/// The test effect: a color uniform and a texture with its sampler.
#[derive(Asset, TypePath, AsBindGroup, Clone)]
struct Paint {
    #[uniform(0)]
    color: Vec4,
    #[texture(1)]
    #[sampler(2)]
    tint: Handle<Image>,
}

impl FramebufferLodEffect for Paint {
    fn fragment_shader() -> ShaderRef {
        PAINT.into()
    }
}

/// The texel of the tint texture (linear Rgba8Unorm): 1.0, 0.2, 0.4.
const TINT: [u8; 4] = [255, 51, 102, 255];

/// A headless app with the paint effect's plugin and shader.
fn app() -> App {
    let mut app = headless::build_app(|app| {
        app.add_plugins(FramebufferLodEffectPlugin::<Paint>::default());
    });
    app.world_mut()
        .resource_mut::<Assets<Shader>>()
        .insert(&PAINT, Shader::from_wesl(PAINT_SOURCE, "paint.wesl"))
        .expect("a UUID handle");
    app
}

/// A paint effect asset of `color` (linear RGB).
fn paint(app: &mut App, color: Vec3) -> Handle<Paint> {
    let tint = Image::new(
        Extent3d {
            width: 1,
            height: 1,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        TINT.to_vec(),
        TextureFormat::Rgba8Unorm,
        RenderAssetUsages::RENDER_WORLD,
    );
    let tint = app.world_mut().resource_mut::<Assets<Image>>().add(tint);
    app.world_mut().resource_mut::<Assets<Paint>>().add(Paint {
        color: color.extend(1.0),
        tint,
    })
}

/// A camera with the paint effect at r into `target`: black clear color, no tonemapping and
/// no dithering, so a pixel is the effect's linear color, sRGB-encoded.
fn camera(effect: Handle<Paint>, r: f32, target: Handle<Image>) -> impl Bundle {
    (
        Camera3d::default(),
        Camera {
            clear_color: ClearColorConfig::Custom(Color::BLACK),
            ..default()
        },
        RenderTarget::from(target),
        Msaa::Off,
        Tonemapping::None,
        DebandDither::Disabled,
        FramebufferLodEffectHandle(effect),
        FramebufferLod {
            resolution: FramebufferLodResolution::Fixed(r),
            ..default()
        },
    )
}

/// Linear to 8-bit sRGB (IEC 61966-2-1), computed here, not by the renderer.
fn srgb8(linear: f32) -> u8 {
    let c = if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    };
    (c * 255.0).round() as u8
}

/// The expected pixel of paint `color` over the tint texel.
fn painted(color: Vec3) -> [u8; 3] {
    let tint = Vec3::new(f32::from(TINT[0]), f32::from(TINT[1]), f32::from(TINT[2])) / 255.0;
    let c = color * tint;
    [srgb8(c.x), srgb8(c.y), srgb8(c.z)]
}

/// A pixel that differs: x, y, what the frame has, what was expected.
type Mismatch = (u32, u32, [u8; 3], [u8; 3]);

/// Pixels of `frame` inside `rect` (x, y, w, h) whose RGB differs from `expected` by more than
/// `tolerance` 8-bit steps in a channel, with the first one found.
fn mismatches(
    frame: &Frame,
    rect: [u32; 4],
    expected: impl Fn(u32, u32) -> [u8; 3],
    tolerance: u8,
) -> (usize, Option<Mismatch>) {
    let (mut count, mut first) = (0, None);
    for y in rect[1]..rect[1] + rect[3] {
        for x in rect[0]..rect[0] + rect[2] {
            let i = ((y * frame.width + x) * 4) as usize;
            let got = [frame.rgba[i], frame.rgba[i + 1], frame.rgba[i + 2]];
            let want = expected(x, y);
            if got
                .iter()
                .zip(want)
                .any(|(&g, w)| g.abs_diff(w) > tolerance)
            {
                count += 1;
                first.get_or_insert((x, y, got, want));
            }
        }
    }
    (count, first)
}

/// Steps a few frames (pipelines compile synchronously; assets prepare a frame late), then
/// captures `target`.
fn settle_and_capture(app: &mut App, target: &Handle<Image>) -> Frame {
    for _ in 0..4 {
        headless::step(app);
    }
    headless::capture(app, target).expect("a captured frame")
}

#[test]
fn an_effects_own_uniform_and_texture_reach_its_shader() {
    let mut app = app();
    let target = headless::render_target(app.world_mut(), 48, 32);
    let first = Vec3::new(0.5, 1.0, 0.25);
    let effect = paint(&mut app, first);
    app.world_mut()
        .spawn(camera(effect.clone(), 2.0, target.clone()));
    let frame = settle_and_capture(&mut app, &target);
    // The whole image is the uniform times the texel: (0.5, 0.2, 0.1), sRGB (187, 124, 89).
    let (bad, at) = mismatches(&frame, [0, 0, 48, 32], |_, _| painted(first), 1);
    assert_eq!(
        bad,
        0,
        "{bad} pixels differ from {:?}: {at:?}",
        painted(first)
    );
    // Changing the asset rebuilds its bind group: the image follows.
    let second = Vec3::new(0.1, 0.6, 0.9);
    app.world_mut()
        .resource_mut::<Assets<Paint>>()
        .get_mut(&effect)
        .expect("the effect asset")
        .color = second.extend(1.0);
    let frame = settle_and_capture(&mut app, &target);
    let (bad, at) = mismatches(&frame, [0, 0, 48, 32], |_, _| painted(second), 1);
    assert_eq!(
        bad,
        0,
        "{bad} pixels differ from {:?}: {at:?}",
        painted(second)
    );
}
