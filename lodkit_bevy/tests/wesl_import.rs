//! A user's WESL material shader that imports several lodkit modules (and, through them, the
//! modules they import with `package::`), linked by Bevy 0.20's own shader pipeline after
//! `LodkitShadersPlugin` registered them, renders what lodkit's Rust twins compute.

#[path = "../examples/common/frames.rs"]
#[allow(dead_code, reason = "shared with the examples")]
mod frames;
#[path = "../examples/common/headless.rs"]
#[allow(dead_code, reason = "shared with the examples")]
mod headless;

use bevy::core_pipeline::tonemapping::{DebandDither, Tonemapping};
use bevy::prelude::*;
use bevy::reflect::TypePath;
use bevy::render::render_resource::AsBindGroup;
use bevy::shader::ShaderRef;
use lodkit_bevy::LodkitShadersPlugin;

/// The user's shader: red, green and blue from three lodkit modules, kept by a fourth.
/// `lodkit::bilateral` itself imports `package::normal_distance` and `package::gbuffer`.
const USER_SHADER: &str = r#"
import bevy_pbr::render::forward_io::VertexOutput;
import lodkit::bilateral::bilateral_tent;
import lodkit::normal_distance::foreshortened_normal_distance;
import lodkit::screen_door::screen_door_keep;
import lodkit::unpopping::unpopping_alpha;

@fragment
fn fragment(in: VertexOutput) -> @location(0) vec4<f32> {
    // Alpha 1 keeps every pixel: a wrong screen door shows the clear color through the quad.
    if !screen_door_keep(in.position.xy, 1.0) {
        discard;
    }
    let r = unpopping_alpha(0.3, true);
    let g = foreshortened_normal_distance(vec3<f32>(0.0, 0.0, 1.0), vec3<f32>(0.6, 0.0, 0.8));
    let b = bilateral_tent(vec2<f32>(0.25, 0.5)).x;
    return vec4<f32>(r, g, b, 1.0);
}
"#;

#[derive(Asset, TypePath, AsBindGroup, Clone)]
struct UserMaterial {}

/// The user's shader, under a fixed handle.
const USER: Handle<Shader> = bevy::asset::uuid_handle!("3c9a51e2-7b04-4d8f-a1e6-52f0c7d9b318");

impl Material for UserMaterial {
    fn fragment_shader() -> ShaderRef {
        USER.into()
    }
    fn enable_prepass() -> bool {
        false
    }
    fn enable_shadows() -> bool {
        false
    }
}

fn linear_to_srgb8(v: f32) -> f32 {
    let c = v.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    s * 255.0
}

#[test]
fn a_user_wesl_shader_imports_lodkit_modules_in_bevy() {
    let mut app = headless::build_app(|app| {
        app.add_plugins((
            LodkitShadersPlugin,
            MaterialPlugin::<UserMaterial>::default(),
        ));
        app.world_mut()
            .resource_mut::<Assets<Shader>>()
            .insert(&USER, Shader::from_wesl(USER_SHADER, "shaders/user.wesl"))
            .expect("UUID handles never fail to insert");
    });
    let target = headless::render_target(app.world_mut(), 32, 32);
    let world = app.world_mut();
    let mesh = world
        .resource_mut::<Assets<Mesh>>()
        .add(Rectangle::new(2.0, 2.0));
    let material = world
        .resource_mut::<Assets<UserMaterial>>()
        .add(UserMaterial {});
    world.spawn((Mesh3d(mesh), MeshMaterial3d(material)));
    world.spawn((
        Camera3d::default(),
        Camera {
            clear_color: ClearColorConfig::Custom(Color::BLACK),
            ..default()
        },
        bevy::camera::RenderTarget::from(target.clone()),
        Msaa::Off,
        Tonemapping::None,
        DebandDither::Disabled,
        Transform::from_xyz(0.0, 0.0, 1.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    for _ in 0..3 {
        headless::step(&mut app);
    }
    let frame = headless::capture(&mut app, &target).expect("a frame");
    // The quad covers the whole view (2 x 2 at distance 1 under a 45-degree field of view).
    let expected = [
        lodkit::unpopping::unpopping_alpha(0.3, true),
        lodkit::normal_distance::foreshortened_normal_distance(
            glam::Vec3::Z,
            glam::Vec3::new(0.6, 0.0, 0.8),
        ),
        lodkit::bilateral::bilateral_tent(glam::Vec2::new(0.25, 0.5)).x,
    ]
    .map(linear_to_srgb8);
    let mut off = 0;
    for p in frame.pixels() {
        if (0..3).any(|c| (f32::from(p[c]) - expected[c]).abs() > 1.0) {
            off += 1;
        }
    }
    let center = frame
        .pixels()
        .nth((16 * 32 + 16) as usize)
        .expect("a pixel");
    assert_eq!(
        off,
        0,
        "{off} of {} pixels differ from lodkit's twins {expected:?} (centre {center:?})",
        32 * 32
    );
}
