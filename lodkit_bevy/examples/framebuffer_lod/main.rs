//! Framebuffer LOD in Bevy 0.20.1, headless: ray-marched height fog over a field of thin pillars,
//! rendered at 1/r resolution and upsampled bilinearly or with lodkit's bilateral filter, then
//! lodkit's controller holding a frame-time target while the fog's cost doubles and halves.
//!
//! ```text
//! cargo run --example framebuffer_lod [-- [--out DIR] [--report FILE] [--size WxH]]
//! ```
//!
//! Writes into DIR (default `lodkit-bevy-framebuffer-lod`): `reference.png` (the effect at full
//! resolution), `bilinear_r2.png`, `bilateral_r2.png`, `bilinear_r3.png`, `bilateral_r3.png`
//! (final frames: fog composited, tonemapped), their error maps `error_*.png` (|difference| x 4)
//! and `figure.png` (reference, bilinear and bilateral at r = 2 above their error maps). With
//! `--report` also the figures as JSON. Exit codes: 0 done, 1 nothing rendered, 2 usage or I/O.
//!
//! The part an application copies is the `Fog` effect type (its bindings: a settings uniform and a
//! noise texture), the camera in `spawn_scene` and `fog.wesl`.

#[path = "../common/frames.rs"]
#[allow(
    dead_code,
    reason = "shared by the examples and tests; each uses a part"
)]
mod frames;
#[path = "../common/headless.rs"]
#[allow(dead_code, reason = "shared by the examples; each uses a part")]
mod headless;
mod measure;
mod run;

use std::path::PathBuf;
use std::process::ExitCode;

use bevy::asset::{RenderAssetUsages, uuid_handle};
use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::{DebandDither, Tonemapping};
use bevy::image::{ImageAddressMode, ImageSampler, ImageSamplerDescriptor};
use bevy::prelude::*;
use bevy::render::diagnostic::RenderDiagnosticsPlugin;
use bevy::render::render_resource::{
    AsBindGroup, Extent3d, ShaderType, TextureDimension, TextureFormat,
};
use bevy::shader::ShaderRef;
use lodkit_bevy::prelude::*;

/// The fog effect (fog.wesl) and the depth probe (depth_probe.wesl), under fixed handles.
const FOG: Handle<Shader> = uuid_handle!("3b0e7c1e-5f0a-4d55-9a62-7f1f6c2d8e41");
const PROBE: Handle<Shader> = uuid_handle!("9d4c2a77-1e3b-4c8f-b0a5-2e6f8d1c3b92");

/// March steps of the fog in the pictures.
const FOG_STEPS: f32 = 48.0;
/// The fog's settings in the pictures.
const FOG_SETTINGS: FogSettings = FogSettings {
    sun: Vec3::new(0.3, 0.25, -1.0),
    steps: FOG_STEPS,
    density: 0.07,
    height: 3.0,
    noise_amount: 0.6,
    as_factor: 0.0,
};
/// Texels of the noise texture a side, and lattice cells of its value noise a side.
const NOISE_TEXELS: u32 = 64;
const NOISE_CELLS: u32 = 8;

/// The fog's uniform (`FogSettings` in fog.wesl).
#[derive(ShaderType, Clone, Copy, Debug)]
pub struct FogSettings {
    /// Direction toward the sun (normalized in the shader).
    sun: Vec3,
    /// March steps from the camera to the surface.
    steps: f32,
    /// Extinction per metre at the ground, before the noise.
    density: f32,
    /// Height over which the density falls by e (m).
    height: f32,
    /// How much the noise texture modulates the density (0: none, 1: fully).
    noise_amount: f32,
    /// 1: return the transmittance as a factor (composited `Modulate`); 0: premultiplied fog.
    as_factor: f32,
}

/// The example's expensive effect: ray-marched height fog whose density a tileable noise
/// texture modulates. Its fields are its bindings (group
/// `constants::FRAMEBUFFER_LOD_EFFECT_BIND_GROUP` in fog.wesl).
#[derive(Asset, TypePath, AsBindGroup, Clone, Debug)]
pub struct Fog {
    #[uniform(0)]
    settings: FogSettings,
    #[texture(1)]
    #[sampler(2)]
    noise: Handle<Image>,
}

impl FramebufferLodEffect for Fog {
    fn fragment_shader() -> ShaderRef {
        FOG.into()
    }
}

/// The depth probe: no bindings of its own.
#[derive(Asset, TypePath, AsBindGroup, Clone, Debug, Default)]
pub struct DepthProbe {}

impl FramebufferLodEffect for DepthProbe {
    fn fragment_shader() -> ShaderRef {
        PROBE.into()
    }
}

/// The example's effect assets.
#[derive(Resource, Clone)]
pub struct Effects {
    fog: Handle<Fog>,
    probe: Handle<DepthProbe>,
}
const SKY: Color = Color::srgb(0.45, 0.55, 0.72);

/// Command-line options.
pub struct Args {
    out: PathBuf,
    report: Option<PathBuf>,
    width: u32,
    height: u32,
}

/// The example's effect shaders as assets.
struct EffectShadersPlugin;

impl Plugin for EffectShadersPlugin {
    fn build(&self, app: &mut App) {
        let mut shaders = app.world_mut().resource_mut::<Assets<Shader>>();
        for (handle, source, path) in [
            (&FOG, include_str!("fog.wesl"), "fog.wesl"),
            (&PROBE, include_str!("depth_probe.wesl"), "depth_probe.wesl"),
        ] {
            shaders
                .insert(handle, Shader::from_wesl(source, path))
                .expect("UUID handles never fail to insert");
        }
    }
}

/// Tileable value noise in [0, 1]: a `NOISE_CELLS`-square lattice of values from a small LCG,
/// smoothstep-interpolated, wrapping at the edges; sampled with a repeating linear sampler.
fn noise_image() -> Image {
    let mut seed = 0x9e37_79b9_u32;
    let lattice: Vec<f32> = (0..NOISE_CELLS * NOISE_CELLS)
        .map(|_| {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1u32 << 24) as f32
        })
        .collect();
    let at = |x: u32, y: u32| lattice[((y % NOISE_CELLS) * NOISE_CELLS + x % NOISE_CELLS) as usize];
    let per_cell = NOISE_TEXELS / NOISE_CELLS;
    let smooth = |t: f32| t * t * (3.0 - 2.0 * t);
    let texels = (0..NOISE_TEXELS * NOISE_TEXELS)
        .map(|i| {
            let (x, y) = (i % NOISE_TEXELS, i / NOISE_TEXELS);
            let (cx, cy) = (x / per_cell, y / per_cell);
            let fx = smooth((x % per_cell) as f32 / per_cell as f32);
            let fy = smooth((y % per_cell) as f32 / per_cell as f32);
            let top = at(cx, cy) * (1.0 - fx) + at(cx + 1, cy) * fx;
            let bottom = at(cx, cy + 1) * (1.0 - fx) + at(cx + 1, cy + 1) * fx;
            ((top * (1.0 - fy) + bottom * fy) * 255.0).round() as u8
        })
        .collect();
    let mut image = Image::new(
        Extent3d {
            width: NOISE_TEXELS,
            height: NOISE_TEXELS,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        texels,
        TextureFormat::R8Unorm,
        RenderAssetUsages::RENDER_WORLD,
    );
    image.sampler = ImageSampler::Descriptor(ImageSamplerDescriptor {
        address_mode_u: ImageAddressMode::Repeat,
        address_mode_v: ImageAddressMode::Repeat,
        ..ImageSamplerDescriptor::linear()
    });
    image
}

/// The scene: a camera with framebuffer LOD rendering into an image, a sun, a ground plane and
/// thin pillars from 3 m to 50 m away in front of the sky.
fn spawn_scene(world: &mut World, width: u32, height: u32) -> (Handle<Image>, Entity) {
    let target = headless::render_target(world, width, height);
    let noise = world.resource_mut::<Assets<Image>>().add(noise_image());
    let effects = Effects {
        fog: world.resource_mut::<Assets<Fog>>().add(Fog {
            settings: FOG_SETTINGS,
            noise,
        }),
        probe: world
            .resource_mut::<Assets<DepthProbe>>()
            .add(DepthProbe::default()),
    };
    world.insert_resource(effects.clone());
    let camera = world.spawn((
        Camera3d::default(),
        Camera {
            clear_color: ClearColorConfig::Custom(SKY),
            ..default()
        },
        RenderTarget::from(target.clone()),
        Msaa::Off,
        Tonemapping::AcesFitted,
        DebandDither::Disabled,
        Transform::from_xyz(0.0, 1.6, 6.0).looking_at(Vec3::new(0.0, 1.4, -30.0), Vec3::Y),
        FramebufferLodEffectHandle(effects.fog),
    ));
    let camera = camera.id();
    world.spawn((
        DirectionalLight {
            shadow_maps_enabled: false,
            illuminance: 8_000.0,
            ..default()
        },
        Transform::from_xyz(2.0, 3.0, 4.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    let ground = world
        .resource_mut::<Assets<Mesh>>()
        .add(Plane3d::default().mesh().size(300.0, 300.0));
    let ground_material = world
        .resource_mut::<Assets<StandardMaterial>>()
        .add(StandardMaterial {
            base_color: Color::srgb(0.28, 0.32, 0.22),
            perceptual_roughness: 0.95,
            ..default()
        });
    world.spawn((Mesh3d(ground), MeshMaterial3d(ground_material)));
    let bark = world
        .resource_mut::<Assets<StandardMaterial>>()
        .add(StandardMaterial {
            base_color: Color::srgb(0.22, 0.16, 0.12),
            perceptual_roughness: 0.8,
            ..default()
        });
    // A deterministic scatter (a small LCG): no two runs differ.
    let mut seed = 0x2545_f491_u32;
    let mut next = move || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1u32 << 24) as f32
    };
    for _ in 0..48 {
        let z = 3.0 - 45.0 * next();
        let spread = 2.0 + 0.45 * (6.0 - z);
        let x = spread * (2.0 * next() - 1.0);
        let radius = 0.05 + 0.12 * next();
        let height = 3.0 + 4.0 * next();
        let mesh = world
            .resource_mut::<Assets<Mesh>>()
            .add(Cylinder::new(radius, height).mesh().resolution(12));
        world.spawn((
            Mesh3d(mesh),
            MeshMaterial3d(bark.clone()),
            Transform::from_xyz(x, height / 2.0, z),
        ));
    }
    (target, camera)
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        out: PathBuf::from("lodkit-bevy-framebuffer-lod"),
        report: None,
        width: 480,
        height: 270,
    };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = || it.next().ok_or(format!("{arg} needs a value"));
        match arg.as_str() {
            "--out" => args.out = PathBuf::from(value()?),
            "--report" => args.report = Some(PathBuf::from(value()?)),
            "--size" => {
                let v = value()?;
                let parsed = v
                    .split_once('x')
                    .and_then(|(w, h)| Some((w.parse().ok()?, h.parse().ok()?)));
                match parsed {
                    Some((w, h)) if (16..=4096).contains(&w) && (16..=4096).contains(&h) => {
                        (args.width, args.height) = (w, h);
                    }
                    _ => return Err(format!("--size {v}: expected WxH, 16..4096 each")),
                }
            }
            _ => return Err(format!("unexpected argument `{arg}`")),
        }
    }
    Ok(args)
}

fn main() -> ExitCode {
    const USAGE: &str = "usage: framebuffer_lod [--out DIR] [--report FILE] [--size WxH]";
    if std::env::args().any(|a| a == "-h" || a == "--help") {
        println!("{USAGE}");
        return ExitCode::SUCCESS;
    }
    let args = match parse_args() {
        Ok(args) => args,
        Err(message) => {
            eprintln!("error: {message}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    let mut app = headless::build_app(|app| {
        app.add_plugins((
            FramebufferLodEffectPlugin::<Fog>::default(),
            FramebufferLodEffectPlugin::<DepthProbe>::default(),
            EffectShadersPlugin,
            RenderDiagnosticsPlugin,
        ));
    });
    let (target, camera) = spawn_scene(app.world_mut(), args.width, args.height);
    match run::run(&mut app, &target, camera, &args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(run::Failure(code, message)) => {
            eprintln!("error: {message}");
            ExitCode::from(code)
        }
    }
}
