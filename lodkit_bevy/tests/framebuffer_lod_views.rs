//! Framebuffer LOD in a headless Bevy app on the GPU: an effect's own bindings (a uniform and a
//! texture) reach its shader and follow the asset when it changes (held to hand-derived
//! pixels); cameras with viewports (split screen, each its own r) and a main-pass resolution
//! override draw their effect inside their viewport only, and what they draw there is what the
//! same camera draws alone into a target of its viewport's size; after the render target is
//! resized, the first frame is the frame rendered at that size from the start; an effect type
//! that names no shader is reported and draws nothing.

#[path = "../examples/common/frames.rs"]
#[allow(dead_code, reason = "shared with the examples")]
mod frames;
#[path = "../examples/common/headless.rs"]
#[allow(dead_code, reason = "shared with the examples")]
mod headless;
#[path = "support/shade.rs"]
mod shade;

use bevy::asset::{RenderAssetUsages, uuid_handle};
use bevy::camera::RenderTarget;
use bevy::camera::{MainPassResolutionOverride, Viewport};
use bevy::core_pipeline::tonemapping::{DebandDither, Tonemapping};
use bevy::prelude::*;
use bevy::render::render_resource::{AsBindGroup, Extent3d, TextureDimension, TextureFormat};
use bevy::render::sync_world::RenderEntity;
use bevy::render::{Extract, ExtractSchedule, RenderApp};
use bevy::shader::ShaderRef;
use frames::Frame;
use lodkit_bevy::prelude::*;
use shade::{Shade, mismatches, pixel, spawn_scene};

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
        app.add_plugins((
            FramebufferLodEffectPlugin::<Paint>::default(),
            FramebufferLodEffectPlugin::<Shade>::default(),
        ));
    });
    let mut shaders = app.world_mut().resource_mut::<Assets<Shader>>();
    for (handle, source, path) in [
        (&PAINT, PAINT_SOURCE, "paint.wesl"),
        (&shade::SHADE, shade::SHADE_SOURCE, "shade.wesl"),
    ] {
        shaders
            .insert(handle, Shader::from_wesl(source, path))
            .expect("a UUID handle");
    }
    app.sub_app_mut(RenderApp)
        .add_systems(ExtractSchedule, extract_resolution_override);
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

/// Clear color of the viewport tests (linear): not black, so an effect composited over a part
/// of the target it should not touch changes it.
const CLEAR: Vec3 = Vec3::new(0.2, 0.3, 0.4);

/// A main-pass resolution override, put on the camera in the render world (where Bevy reads it).
#[derive(Component, Clone, Copy)]
struct ResolutionOverride(UVec2);

fn extract_resolution_override(
    mut commands: Commands,
    cameras: Extract<Query<(RenderEntity, &ResolutionOverride)>>,
) {
    for (entity, o) in &cameras {
        commands
            .entity(entity)
            .insert(MainPassResolutionOverride(o.0));
    }
}

/// One camera of a viewport test.
#[derive(Clone, Copy)]
struct View {
    eye: Vec3,
    r: f32,
    tint: Vec4,
    /// Physical viewport: corner and size.
    viewport: Option<(UVec2, UVec2)>,
    order: isize,
    /// Whether it clears the target (else it draws over what the cameras before it left in
    /// the main texture they share, which is how it sees their spills).
    clear: bool,
    resolution_override: Option<UVec2>,
}

/// The camera of `view` with framebuffer LOD (no effect yet) rendering into `target`.
fn lod_camera(view: &View, target: Handle<Image>) -> impl Bundle {
    (
        Camera3d::default(),
        Camera {
            clear_color: if view.clear {
                ClearColorConfig::Custom(Color::linear_rgb(CLEAR.x, CLEAR.y, CLEAR.z))
            } else {
                ClearColorConfig::None
            },
            order: view.order,
            viewport: view.viewport.map(|(corner, size)| Viewport {
                physical_position: corner,
                physical_size: size,
                ..default()
            }),
            ..default()
        },
        RenderTarget::from(target),
        Msaa::Off,
        Tonemapping::None,
        DebandDither::Disabled,
        Transform::from_translation(view.eye).looking_at(Vec3::new(0.0, 0.8, 0.0), Vec3::Y),
        FramebufferLod {
            resolution: FramebufferLodResolution::Fixed(view.r),
            ..default()
        },
    )
}

/// Renders `views` into a `size` target in a fresh app and captures it.
fn render(size: UVec2, views: &[View]) -> Frame {
    let mut app = app();
    let target = headless::render_target(app.world_mut(), size.x, size.y);
    spawn_scene(app.world_mut());
    for view in views {
        let effect = app
            .world_mut()
            .resource_mut::<Assets<Shade>>()
            .add(Shade { tint: view.tint });
        let mut camera = app.world_mut().spawn((
            lod_camera(view, target.clone()),
            FramebufferLodEffectHandle(effect),
        ));
        if let Some(o) = view.resolution_override {
            camera.insert(ResolutionOverride(o));
        }
    }
    settle_and_capture(&mut app, &target)
}

/// Tolerance of a pixel against the same camera rendered alone (8-bit steps per channel).
const TOLERANCE: u8 = 2;

const A: View = View {
    eye: Vec3::new(-1.0, 2.5, 7.0),
    r: 2.0,
    tint: Vec4::new(1.0, 0.5, 0.1, 0.7),
    viewport: None,
    order: 0,
    clear: true,
    resolution_override: None,
};
const B: View = View {
    eye: Vec3::new(5.0, 3.0, -4.0),
    r: 3.0,
    tint: Vec4::new(0.1, 0.6, 1.0, 0.6),
    viewport: None,
    order: 0,
    clear: true,
    resolution_override: None,
};

#[test]
fn split_screen_cameras_each_draw_their_own_effect_inside_their_viewport() {
    let half = UVec2::new(48, 40);
    let size = UVec2::new(2 * half.x, half.y);
    // Each camera alone, in a target of its viewport's size: the reference.
    let alone = [render(half, &[A]), render(half, &[B])];
    // Side by side, in both orders. The cameras share the main texture; the first clears it,
    // the second draws over what the first left there: an effect the first spilled outside its
    // viewport would show in the second's half. (What the second spills into the first's half
    // never reaches the image: Bevy copies each camera's viewport out before the next camera
    // draws. Hence both orders.)
    for first in [0, 1] {
        let mut views = [A, B];
        views[0].viewport = Some((UVec2::ZERO, half));
        views[1].viewport = Some((UVec2::new(half.x, 0), half));
        views[first].order = 0;
        views[1 - first].order = 1;
        views[1 - first].clear = false;
        let split = render(size, &views);
        for (i, reference) in alone.iter().enumerate() {
            let x0 = i as u32 * half.x;
            let (bad, at) = mismatches(
                &split,
                [x0, 0, half.x, half.y],
                |x, y| pixel(reference, x - x0, y),
                TOLERANCE,
            );
            println!(
                "camera {i} (drawn {}): {bad} pixels differ",
                if i == first { "first" } else { "second" }
            );
            assert_eq!(
                bad, 0,
                "camera {i}'s half differs from the camera alone in {bad} pixels: {at:?}"
            );
        }
    }
}

#[test]
fn a_main_pass_resolution_override_keeps_the_effect_in_the_main_pass_viewport() {
    let size = UVec2::new(96, 64);
    let main_pass = UVec2::new(48, 32);
    let alone = render(main_pass, &[A]);
    let view = View {
        resolution_override: Some(main_pass),
        ..A
    };
    let frame = render(size, &[view]);
    // Where the main pass drew: the camera alone at that size.
    let (bad, at) = mismatches(
        &frame,
        [0, 0, main_pass.x, main_pass.y],
        |x, y| pixel(&alone, x, y),
        TOLERANCE,
    );
    println!("main-pass viewport: {bad} pixels differ");
    assert_eq!(bad, 0, "{bad} pixels differ from the camera alone: {at:?}");
    // Elsewhere nothing drew: the clear color.
    let clear = [srgb8(CLEAR.x), srgb8(CLEAR.y), srgb8(CLEAR.z)];
    for rect in [
        [main_pass.x, 0, size.x - main_pass.x, size.y],
        [0, main_pass.y, main_pass.x, size.y - main_pass.y],
    ] {
        let (bad, at) = mismatches(&frame, rect, |_, _| clear, 1);
        assert_eq!(
            bad, 0,
            "{bad} pixels outside the main pass are not the clear color {clear:?}: {at:?}"
        );
    }
}

/// A new size for the render target `target` (its GPU texture is recreated at that size).
fn resize_target(app: &mut App, target: &Handle<Image>, size: UVec2) {
    app.world_mut()
        .resource_mut::<Assets<Image>>()
        .get_mut(target)
        .expect("the render target")
        .resize(Extent3d {
            width: size.x,
            height: size.y,
            depth_or_array_layers: 1,
        });
}

#[test]
fn after_a_resize_the_first_frame_is_the_frame_rendered_at_that_size() {
    // r = 1.25: at the larger size the low-resolution viewport (77 x 58) no longer fits in
    // targets allocated at the first size (64 x 48), so stale targets cannot go unnoticed.
    let view = View { r: 1.25, ..A };
    let sizes = [UVec2::new(96, 72), UVec2::new(48, 40)];
    let references = sizes.map(|size| render(size, &[view]));
    let mut app = app();
    let target = headless::render_target(app.world_mut(), 64, 48);
    spawn_scene(app.world_mut());
    let effect = app
        .world_mut()
        .resource_mut::<Assets<Shade>>()
        .add(Shade { tint: view.tint });
    let camera = app
        .world_mut()
        .spawn((
            lod_camera(&view, target.clone()),
            FramebufferLodEffectHandle(effect),
        ))
        .id();
    settle_and_capture(&mut app, &target);
    let camera_size = |app: &App| {
        app.world()
            .get::<Camera>(camera)
            .and_then(Camera::physical_target_size)
    };
    for (size, reference) in sizes.iter().zip(&references) {
        resize_target(&mut app, &target, *size);
        // Bevy's camera learns of an image target's new size a frame late (camera_system runs
        // before the image's asset event is sent): this frame still renders the camera at the
        // old size into the new texture, consistently (the plugin sizes everything from the
        // extracted view).
        headless::step(&mut app);
        let lagged = camera_size(&app) != Some(*size);
        // The next frame is the first at the new size (where Bevy lags; the second otherwise):
        // the screenshot is of that very frame.
        let frame = headless::capture(&mut app, &target).expect("a captured frame");
        assert_eq!(camera_size(&app), Some(*size));
        assert_eq!((frame.width, frame.height), (size.x, size.y));
        println!("camera size lagged the resize by a frame: {lagged}");
        let (bad, at) = mismatches(
            &frame,
            [0, 0, size.x, size.y],
            |x, y| pixel(reference, x, y),
            TOLERANCE,
        );
        println!("resized to {size}: {bad} pixels differ");
        assert_eq!(
            bad, 0,
            "{bad} pixels of the first frame at {size} differ from a frame rendered at that \
             size from the start: {at:?}"
        );
    }
}

/// An effect type that names no shader (`ShaderRef::Default`): a mistake the plugin reports.
#[derive(Asset, TypePath, AsBindGroup, Clone, Default)]
struct Shaderless {}

impl FramebufferLodEffect for Shaderless {
    fn fragment_shader() -> ShaderRef {
        ShaderRef::Default
    }
}

#[test]
fn an_effect_without_a_shader_logs_an_error_and_draws_nothing() {
    let mut app = headless::build_app(|app| {
        app.add_plugins(FramebufferLodEffectPlugin::<Shaderless>::default());
    });
    let target = headless::render_target(app.world_mut(), 48, 32);
    spawn_scene(app.world_mut());
    let camera = app.world_mut().spawn(lod_camera(&A, target.clone())).id();
    // The camera without an effect, then with the shaderless one: the same image, no panic.
    let without = settle_and_capture(&mut app, &target);
    let effect = app
        .world_mut()
        .resource_mut::<Assets<Shaderless>>()
        .add(Shaderless::default());
    app.world_mut()
        .entity_mut(camera)
        .insert(FramebufferLodEffectHandle(effect));
    let with = settle_and_capture(&mut app, &target);
    let (bad, at) = mismatches(&with, [0, 0, 48, 32], |x, y| pixel(&without, x, y), 0);
    assert_eq!(bad, 0, "the shaderless effect changed {bad} pixels: {at:?}");
}
