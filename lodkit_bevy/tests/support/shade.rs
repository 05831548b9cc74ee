//! What the framebuffer-LOD tests with real geometry share: a geometry-aware test effect
//! (`Shade`) and its scene.

use bevy::asset::uuid_handle;
use bevy::prelude::*;
use bevy::render::render_resource::AsBindGroup;
use bevy::shader::ShaderRef;
use lodkit_bevy::prelude::*;

use crate::frames::Frame;

/// The handle `Shade`'s shader is inserted at.
pub const SHADE: Handle<Shader> = uuid_handle!("6a2e8b41-0d5c-4f7a-9b13-e8c4a7d2f095");

/// Shades the scene's geometry: a sawtooth of view depth (period 4 m) times how much
/// the surface faces the camera, in the uniform's color, with the uniform's alpha as coverage.
pub const SHADE_SOURCE: &str = "
import bevy_core_pipeline::fullscreen_vertex_shader::FullscreenVertexOutput;
import lodkit::gbuffer::GBufferOutput;
import lodkit_bevy::framebuffer_lod::{effect_sample, effect_output};

@group(constants::FRAMEBUFFER_LOD_EFFECT_BIND_GROUP) @binding(0) var<uniform> tint: vec4<f32>;

@fragment
fn fragment(in: FullscreenVertexOutput) -> GBufferOutput {
    let s = effect_sample(in.position);
    let stripes = fract(s.view_depth * 0.25);
    let facing = 0.5 + 0.5 * s.view_normal.z;
    return effect_output(vec4<f32>(tint.rgb * (stripes * facing * tint.a), tint.a), s);
}
";

/// The geometry-aware test effect of the viewport tests.
#[derive(Asset, TypePath, AsBindGroup, Clone)]
pub struct Shade {
    #[uniform(0)]
    pub tint: Vec4,
}

impl FramebufferLodEffect for Shade {
    fn fragment_shader() -> ShaderRef {
        SHADE.into()
    }
}

/// A ground plane, three boxes and a sun.
pub fn spawn_scene(world: &mut World) {
    world.spawn((
        DirectionalLight {
            shadow_maps_enabled: false,
            illuminance: 5_000.0,
            ..default()
        },
        Transform::from_xyz(2.0, 4.0, 3.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    let ground = world
        .resource_mut::<Assets<Mesh>>()
        .add(Plane3d::default().mesh().size(40.0, 40.0));
    let cube = world
        .resource_mut::<Assets<Mesh>>()
        .add(Cuboid::new(1.0, 2.0, 1.0));
    let material = world
        .resource_mut::<Assets<StandardMaterial>>()
        .add(StandardMaterial {
            base_color: Color::srgb(0.5, 0.45, 0.4),
            ..default()
        });
    world.spawn((Mesh3d(ground), MeshMaterial3d(material.clone())));
    for (x, z) in [(-1.5, 0.0), (1.0, -2.0), (0.5, 1.5)] {
        world.spawn((
            Mesh3d(cube.clone()),
            MeshMaterial3d(material.clone()),
            Transform::from_xyz(x, 1.0, z),
        ));
    }
}

/// A pixel that differs: x, y, what the frame has, what was expected.
pub type Mismatch = (u32, u32, [u8; 3], [u8; 3]);

/// Pixels of `frame` inside `rect` (x, y, w, h) whose RGB differs from `expected` by more than
/// `tolerance` 8-bit steps in a channel, with the first one found.
pub fn mismatches(
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

/// The pixel of `frame` at (x, y).
pub fn pixel(frame: &Frame, x: u32, y: u32) -> [u8; 3] {
    let i = ((y * frame.width + x) * 4) as usize;
    [frame.rgba[i], frame.rgba[i + 1], frame.rgba[i + 2]]
}
