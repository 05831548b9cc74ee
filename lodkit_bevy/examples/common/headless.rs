//! A headless Bevy app for the examples, after Bevy's
//! `examples/app/externally_driven_headless_renderer.rs`: no window, no runner, `app.update()`
//! pumped by hand, cameras rendering into an `Image`, `Screenshot`s read back through an observer.

use std::path::Path;

use bevy::asset::RenderAssetUsages;
use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::{DebandDither, Tonemapping};
use bevy::prelude::*;
use bevy::render::RenderPlugin;
use bevy::render::gpu_readback::{Readback, ReadbackComplete};
use bevy::render::render_resource::{
    Extent3d, PollType, TextureDimension, TextureFormat, TextureUsages,
};
use bevy::render::renderer::RenderDevice;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::window::ExitCondition;

use crate::frames::Frame;

/// Updates to wait for one screenshot to come back from the GPU.
const READBACK_UPDATES: usize = 8;

/// Every frame read back since [`start_readback`], in order.
#[derive(Resource, Default)]
pub struct FrameInbox(pub Vec<Vec<u8>>);

/// Reads `target` back every frame into [`FrameInbox`] (emptied first) until the returned
/// entity is despawned.
pub fn start_readback(world: &mut World, target: &Handle<Image>) -> Entity {
    world.resource_mut::<FrameInbox>().0.clear();
    world
        .spawn(Readback::texture(target.clone()))
        .observe(
            |done: On<ReadbackComplete>, mut inbox: ResMut<FrameInbox>| {
                inbox.0.push(done.data.clone());
            },
        )
        .id()
}

/// Where the last screenshot's image lands (filled by the screenshot observer).
#[derive(Resource, Default)]
struct ScreenshotInbox(Option<Image>);

/// Ends a run read back since [`start_readback`]: waits (a few updates at most) until `frames`
/// frames of `width` x `height` came back, despawns the readback and the run's `entities`, lets
/// the last readbacks in flight land and empties the inbox for the next run. Returns the
/// frames, or how many came back.
pub fn finish_readback(
    app: &mut App,
    readback: Entity,
    entities: &[Entity],
    frames: usize,
    (width, height): (u32, u32),
) -> Result<Vec<Frame>, String> {
    for _ in 0..12 {
        if app.world().resource::<FrameInbox>().0.len() >= frames {
            break;
        }
        step(app);
    }
    let world = app.world_mut();
    world.despawn(readback);
    for &entity in entities {
        world.despawn(entity);
    }
    let data = std::mem::take(&mut world.resource_mut::<FrameInbox>().0);
    if data.len() < frames {
        return Err(format!("{} of {frames} frames came back", data.len()));
    }
    for _ in 0..4 {
        step(app);
    }
    app.world_mut().resource_mut::<FrameInbox>().0.clear();
    Ok(data
        .into_iter()
        .take(frames)
        .map(|rgba| Frame::new(width, height, rgba))
        .collect())
}

/// A headless app with `plugins` added: no window, no runner, shaders compiled synchronously so
/// the first frames draw.
pub fn build_app(plugins: impl FnOnce(&mut App)) -> App {
    build_app_with_assets(None, plugins)
}

/// [`build_app`] whose `AssetServer` reads from `assets` (None: Bevy's default `assets` folder).
pub fn build_app_with_assets(assets: Option<&Path>, plugins: impl FnOnce(&mut App)) -> App {
    let mut app = App::new();
    let asset_plugin = match assets {
        Some(dir) => AssetPlugin {
            file_path: dir.to_string_lossy().into_owned(),
            ..default()
        },
        None => AssetPlugin::default(),
    };
    app.add_plugins(
        DefaultPlugins
            .build()
            .set(asset_plugin)
            // The tests' window test enables winit in this crate's dev build; a headless app
            // runs no event loop.
            .disable::<bevy::winit::WinitPlugin>()
            .set(WindowPlugin {
                primary_window: None,
                exit_condition: ExitCondition::DontExit,
                ..default()
            })
            .set(RenderPlugin {
                synchronous_pipeline_compilation: true,
                ..default()
            }),
    )
    .init_resource::<ScreenshotInbox>()
    .init_resource::<FrameInbox>();
    plugins(&mut app);
    // What `App::run` would do before its first update; we never call it.
    app.finish();
    app.cleanup();
    app
}

/// A harness camera drawing into `target`: Bevy's defaults (MSAA `Sample4` included) except
/// the clear colour, `background`, and no tonemapping or deband dither, so the background is
/// that colour exactly (the figures count the other pixels).
pub fn harness_camera(target: &Handle<Image>, background: Color, at: Transform) -> impl Bundle {
    (
        Camera3d::default(),
        Camera {
            clear_color: ClearColorConfig::Custom(background),
            ..default()
        },
        RenderTarget::from(target.clone()),
        Tonemapping::None,
        DebandDither::Disabled,
        at,
    )
}

/// An sRGB image a camera can render into, `width` x `height`.
pub fn render_target(world: &mut World, width: u32, height: u32) -> Handle<Image> {
    let target = render_target_image(width, height);
    world.resource_mut::<Assets<Image>>().add(target)
}

/// The image of [`render_target`], not yet added to the assets.
pub fn render_target_image(width: u32, height: u32) -> Image {
    let size = Extent3d {
        width,
        height,
        depth_or_array_layers: 1,
    };
    let mut target = Image::new_uninit(
        size,
        TextureDimension::D2,
        TextureFormat::Rgba8UnormSrgb,
        RenderAssetUsages::RENDER_WORLD,
    );
    target.texture_descriptor.usage |= TextureUsages::RENDER_ATTACHMENT;
    target
}

/// Runs one frame and waits for the GPU to finish it.
pub fn step(app: &mut App) {
    app.update();
    app.world()
        .resource::<RenderDevice>()
        .wgpu_device()
        .poll(PollType::Wait {
            submission_index: None,
            timeout: None,
        })
        .expect("the GPU device was lost");
}

/// Renders a frame with a screenshot of `target` and pumps updates until its pixels are back.
pub fn capture(app: &mut App, target: &Handle<Image>) -> Result<Frame, String> {
    app.world_mut()
        .spawn(Screenshot::image(target.clone()))
        .observe(
            |shot: On<ScreenshotCaptured>, mut inbox: ResMut<ScreenshotInbox>| {
                inbox.0 = Some(shot.image.clone());
            },
        );
    for _ in 0..READBACK_UPDATES {
        step(app);
        if let Some(image) = app.world_mut().resource_mut::<ScreenshotInbox>().0.take() {
            let (width, height) = (image.width(), image.height());
            let pixels = image
                .try_into_dynamic()
                .map_err(|e| format!("screenshot: {e}"))?;
            return Ok(Frame::new(width, height, pixels.to_rgba8().into_raw()));
        }
    }
    Err(format!(
        "no screenshot came back within {READBACK_UPDATES} updates"
    ))
}

/// Writes `frame` as a PNG through Bevy's own image conversion (`png` feature).
pub fn save_png(frame: &Frame, path: &Path) -> Result<(), String> {
    let size = Extent3d {
        width: frame.width,
        height: frame.height,
        depth_or_array_layers: 1,
    };
    let image = Image::new(
        size,
        TextureDimension::D2,
        frame.rgba.clone(),
        TextureFormat::Rgba8UnormSrgb,
        RenderAssetUsages::MAIN_WORLD,
    );
    let dynamic = image.try_into_dynamic().map_err(|e| e.to_string())?;
    dynamic
        .save(path)
        .map_err(|e| format!("{}: {e}", path.display()))
}
