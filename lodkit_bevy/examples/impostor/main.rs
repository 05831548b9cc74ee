//! An octahedral impostor in Bevy: a tree with alpha-masked leaves baked by lodkit
//! (`lodkit::gpu::impostor::ImpostorBaker`, on a device of its own, as an asset pipeline bakes)
//! and drawn by Bevy with [`ImpostorMaterial`], beside the same tree drawn as a mesh with
//! Bevy's `StandardMaterial` (`AlphaMode::Mask`), at the distance from which the impostor's
//! picture stays within a pixel error of the mesh's (`impostor_switch_distance`).
//!
//! ```text
//! cargo run --example impostor [-- [--out DIR] [--report FILE]]
//! ```
//!
//! The camera (256 x 256 pixels, 30 degree field of view) looks at the tree from eleven
//! directions: ten between the atlas's frames (centroids of the frame grid's triangles, where a
//! view is farthest from the frames it blends) from near the horizon to near the top, and one
//! on a frame; at the switch distance for 4 pixels and at half of it. Each view is rendered
//! with the mesh alone and the impostor alone (no MSAA, so a pixel is covered or not), and the
//! outline distance between the two is the symmetric Hausdorff distance of their coverage
//! (`lodkit::metrics::coverage_distance`). Then, at the switch distance, with a wall across each
//! view a quarter radius in front of the centre: the impostor's written depth must hide what the
//! mesh's triangles behind the wall hide (the card itself lies behind it). Writes
//! `DIR/impostor.png` (top: the mesh, bottom:
//! the impostor, the first four views at the switch distance) and, with `--report`, the
//! figures as JSON.
//!
//! Exit codes: 0 done, 1 nothing rendered, 2 usage or I/O error.

mod crossfade;
#[path = "../common/frames.rs"]
#[allow(
    dead_code,
    reason = "shared by the examples and tests; each uses a part"
)]
mod frames;
mod group;
#[path = "../common/headless.rs"]
#[allow(dead_code, reason = "shared by the examples; each uses a part")]
mod headless;
#[path = "../frame_sequential/measure.rs"]
#[allow(dead_code, reason = "shared with the other examples; each uses a part")]
mod measure;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::prelude::*;
use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};
use lodkit::gpu::GpuContext;
use lodkit::gpu::impostor::{ImpostorBakeDescriptor, ImpostorBaker};
use lodkit::impostor::{
    ImpostorAtlas, impostor_decode, impostor_frame_dir, impostor_switch_distance,
};
use lodkit::lod_chain::PixelErrorCamera;
use lodkit_bevy::frame_sequential::{
    FrameSequentialDefaultCamera, FrameSequentialLodPlugin, FrameSequentialMaterialPlugin,
};
use lodkit_bevy::impostor::{ImpostorMaterial, ImpostorPlugin};
use lodkit_scenes::tree::LeafyTree;

use frames::Frame;
use headless::{build_app, capture, render_target, save_png};

const USAGE: &str = "usage: impostor [--out DIR] [--report FILE]";
/// Target side in pixels.
const SIZE: u32 = 256;
/// Vertical field of view (degrees).
const FOV: f32 = 30.0;
/// The pixel error the switch distance is derived for.
const PIXELS: f32 = 4.0;
/// The clear colour: no colour of the lit tree.
const BACKGROUND: [u8; 3] = [255, 0, 255];
/// The wall's colour (unlit): no colour of the lit tree either.
const WALL: [u8; 3] = [0, 255, 255];
/// How far in front of the bounding sphere's centre the wall stands, in radii.
const WALL_AHEAD: f32 = 0.25;

fn main() -> ExitCode {
    let result = args()
        .map_err(|e| (2, e))
        .and_then(|(out, report)| run(&out, report.as_deref()));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err((code, message)) => {
            eprintln!("error: {message}");
            ExitCode::from(code)
        }
    }
}

fn args() -> Result<(PathBuf, Option<PathBuf>), String> {
    let (mut out, mut report) = (PathBuf::from("lodkit-bevy-impostor"), None);
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        match (arg.as_str(), it.next()) {
            ("--out", Some(v)) => out = v.into(),
            ("--report", Some(v)) => report = Some(v.into()),
            _ => return Err(USAGE.to_owned()),
        }
    }
    Ok((out, report))
}

/// Views between frames: the centroids of the grid triangles around these cells (lower and
/// upper triangle of each), from near the horizon to near the top, plus one view on a frame
/// (the views of lodkit's own impostor test).
fn views(frames: u32) -> Vec<Vec3> {
    let at = |g: glam::Vec2| impostor_decode(g * (2.0 / (frames - 1) as f32) - 1.0, true);
    let mut out = Vec::new();
    for cell in [[0, 3], [2, 1], [3, 3], [5, 2], [4, 6]] {
        let c = glam::Vec2::new(cell[0] as f32, cell[1] as f32);
        out.push(Vec3::from_array(at(c + 1.0 / 3.0).to_array()));
        out.push(Vec3::from_array(at(c + 2.0 / 3.0).to_array()));
    }
    let on = impostor_frame_dir(glam::UVec2::new(4, 8), frames, true);
    out.push(Vec3::from_array(on.to_array()));
    out
}

/// The tree as a Bevy mesh and `StandardMaterial`: the same triangles, texture and alpha test
/// the atlas was baked from.
fn tree_mesh(tree: &LeafyTree) -> (Mesh, StandardMaterial, Image) {
    let part = tree.part();
    let mesh = Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::RENDER_WORLD,
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, part.mesh.positions.to_vec())
    .with_inserted_attribute(
        Mesh::ATTRIBUTE_NORMAL,
        part.mesh.normals.unwrap_or_default().to_vec(),
    )
    .with_inserted_attribute(
        Mesh::ATTRIBUTE_UV_0,
        part.mesh.uvs.unwrap_or_default().to_vec(),
    )
    .with_inserted_indices(Indices::U32(part.mesh.indices.to_vec()));
    let texture = part
        .material
        .base_color_texture
        .map(|t| {
            Image::new(
                Extent3d {
                    width: t.width,
                    height: t.height,
                    depth_or_array_layers: 1,
                },
                TextureDimension::D2,
                t.rgba8.to_vec(),
                TextureFormat::Rgba8UnormSrgb,
                RenderAssetUsages::RENDER_WORLD,
            )
        })
        .unwrap_or_default();
    let [r, g, b, a] = part.material.base_color;
    let material = StandardMaterial {
        base_color: Color::linear_rgba(r, g, b, a),
        alpha_mode: AlphaMode::Mask(part.material.alpha_cutoff.unwrap_or(0.5)),
        double_sided: part.material.double_sided,
        cull_mode: None,
        perceptual_roughness: 1.0,
        ..default()
    };
    (mesh, material, texture)
}

/// What one distance measured: the largest outline distance over the views, the fewest pixels
/// the mesh covered in any view, and the captures (mesh, impostor) of each view.
struct Measured {
    worst: f32,
    fewest: usize,
    captures: Vec<(Frame, Frame)>,
}

fn run(out: &Path, report: Option<&Path>) -> Result<(), (u8, String)> {
    std::fs::create_dir_all(out).map_err(|e| (2, format!("{}: {e}", out.display())))?;
    // Bake, as a pipeline would: lodkit on a device of its own.
    let gpu = GpuContext::new_headless(&Default::default()).map_err(|e| (1, e.to_string()))?;
    let tree = LeafyTree::new(40, 7);
    let descriptor = ImpostorBakeDescriptor::default();
    let atlas: ImpostorAtlas = ImpostorBaker::new(&gpu, &[tree.part()])
        .and_then(|baker| baker.bake(&gpu, &descriptor))
        .map_err(|e| (1, e.to_string()))?;
    let camera = PixelErrorCamera {
        fov_y: FOV.to_radians(),
        viewport_height: SIZE as f32,
        pixel_error: PIXELS,
        hysteresis: 0.0,
    };
    let normalized =
        impostor_switch_distance(&atlas.layout, &camera).map_err(|e| (1, e.to_string()))?;
    let distance = normalized * camera.p11() as f32;

    let mut app = build_app(|app| {
        app.add_plugins((
            ImpostorPlugin,
            FrameSequentialLodPlugin,
            FrameSequentialMaterialPlugin::<ImpostorMaterial>::default(),
        ))
        .insert_resource(FrameSequentialDefaultCamera(false));
    });
    let world = app.world_mut();
    world.spawn((
        DirectionalLight::default(),
        Transform::from_xyz(3.0, 6.0, 4.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    let (mesh, mut material, texture) = tree_mesh(&tree);
    material.base_color_texture = Some(world.resource_mut::<Assets<Image>>().add(texture));
    let mesh = world.resource_mut::<Assets<Mesh>>().add(mesh);
    let material = world
        .resource_mut::<Assets<StandardMaterial>>()
        .add(material);
    let impostor = {
        let mut images = world.resource_mut::<Assets<Image>>();
        ImpostorMaterial::new(&atlas, &mut images).map_err(|e| (1, e.to_string()))?
    };
    let impostor = world
        .resource_mut::<Assets<ImpostorMaterial>>()
        .add(impostor);
    let card = world
        .resource_mut::<Assets<Mesh>>()
        .add(ImpostorMaterial::card_mesh(&atlas.layout));
    let tree_entity = world.spawn((Mesh3d(mesh), MeshMaterial3d(material))).id();
    let impostor_entity = world
        .spawn((Mesh3d(card), MeshMaterial3d(impostor), Visibility::Hidden))
        .id();
    let target = render_target(world, SIZE, SIZE);
    let center = Vec3::from_array(atlas.layout.center);
    let views = views(descriptor.frames);

    let wall_mesh = world
        .resource_mut::<Assets<Mesh>>()
        .add(Rectangle::new(6.0, 6.0).mesh().build());
    let wall_material = world
        .resource_mut::<Assets<StandardMaterial>>()
        .add(StandardMaterial {
            base_color: Color::srgb_u8(WALL[0], WALL[1], WALL[2]),
            unlit: true,
            ..default()
        });
    let radius = atlas.layout.radius;
    // The pixels that show the tree: neither the background nor the wall.
    let coverage = |frame: &Frame| -> Vec<bool> {
        frame
            .pixels()
            .map(|p| !frames::is_background(p, BACKGROUND) && !frames::is_background(p, WALL))
            .collect()
    };
    // With `wall`, a wall across the view a quarter radius in front of the centre: the
    // impostor's written depth must hide what the mesh's triangles behind it hide.
    let measure = |app: &mut App, distance: f32, wall: bool| -> Result<Measured, (u8, String)> {
        let mut measured = Measured {
            worst: 0.0,
            fewest: usize::MAX,
            captures: Vec::new(),
        };
        for &view in &views {
            let eye = center + view * distance;
            let up = if view.y.abs() > 0.95 {
                Vec3::Z
            } else {
                Vec3::Y
            };
            let shot = crossfade::Shot {
                target: target.clone(),
                eye,
                center,
                near: distance * 0.05,
            };
            let camera = app.world_mut().spawn(shot.camera()).id();
            let wall = wall.then(|| {
                let at = center + view * (WALL_AHEAD * radius);
                app.world_mut()
                    .spawn((
                        Mesh3d(wall_mesh.clone()),
                        MeshMaterial3d(wall_material.clone()),
                        Transform::from_translation(at).looking_at(at - view, up),
                    ))
                    .id()
            });
            let mut shots = Vec::new();
            for show_impostor in [false, true] {
                let world = app.world_mut();
                let (shown, hidden) = match show_impostor {
                    false => (tree_entity, impostor_entity),
                    true => (impostor_entity, tree_entity),
                };
                world.entity_mut(shown).insert(Visibility::Visible);
                world.entity_mut(hidden).insert(Visibility::Hidden);
                // A frame for the change to reach the render world, then the capture.
                headless::step(app);
                shots.push(capture(app, &target).map_err(|e| (1, e))?);
            }
            app.world_mut().despawn(camera);
            if let Some(wall) = wall {
                app.world_mut().despawn(wall);
            }
            let (a, b) = (coverage(&shots[0]), coverage(&shots[1]));
            let d = lodkit::metrics::coverage_distance(&a, &b, SIZE as usize)
                .map_err(|e| (1, e.to_string()))?;
            measured.worst = measured.worst.max(d);
            measured.fewest = measured.fewest.min(a.iter().filter(|c| **c).count());
            let mut shots = shots.into_iter();
            if let (Some(mesh), Some(impostor)) = (shots.next(), shots.next()) {
                measured.captures.push((mesh, impostor));
            }
        }
        Ok(measured)
    };
    // Both pipelines compiled and both meshes and atlases uploaded before the first capture.
    for entity in [tree_entity, impostor_entity] {
        app.world_mut()
            .entity_mut(entity)
            .insert(Visibility::Visible);
    }
    let warm_up = crossfade::Shot {
        target: target.clone(),
        eye: center + Vec3::Z * distance,
        center,
        near: distance * 0.05,
    };
    let warm_up = app.world_mut().spawn(warm_up.camera()).id();
    for _ in 0..4 {
        headless::step(&mut app);
    }
    app.world_mut().despawn(warm_up);
    let at_switch = measure(&mut app, distance, false)?;
    let at_half = measure(&mut app, distance * 0.5, false)?;
    let walled = measure(&mut app, distance, true)?;
    // The impostor as the last level: of Bevy's crossfade, of a lodkit group.
    let shot = crossfade::Shot {
        target: target.clone(),
        eye: center + views[0] * distance,
        center,
        near: distance * 0.05,
    };
    let (mesh_alone, impostor_alone) = &at_switch.captures[0];
    let references = crossfade::References {
        mesh: mesh_alone,
        impostor: impostor_alone,
        coverage: &coverage,
    };
    let entities = [tree_entity, impostor_entity];
    let crossfade = crossfade::visibility_range(&mut app, &shot, entities, &references)?;
    let mut group =
        |run| group::frame_sequential_group(&mut app, &shot, entities, &references, run);
    let (smooth, hard, prepass) = (
        group(group::Run::Smooth)?,
        group(group::Run::Hard)?,
        group(group::Run::Prepass)?,
    );
    println!(
        "switch distance {normalized:.1} (view-normalized), {distance:.2} object units (radius \
         {:.2}); outline distance between mesh and impostor over {} views: worst {:.2} px at it, \
         {:.2} px at half of it; the mesh covers at least {} px; with a wall a quarter radius \
         in front of the centre: worst {:.2} px, the mesh in front of it at least {} px",
        atlas.layout.radius,
        views.len(),
        at_switch.worst,
        at_half.worst,
        at_switch.fewest,
        walled.worst,
        walled.fewest
    );
    let shown: Vec<&(Frame, Frame)> = at_switch.captures.iter().take(4).collect();
    let top = frames::strip(&shown.iter().map(|(m, _)| m.clone()).collect::<Vec<_>>());
    let bottom = frames::strip(&shown.iter().map(|(_, i)| i.clone()).collect::<Vec<_>>());
    let mut sheet = top.rgba.clone();
    sheet.extend_from_slice(&bottom.rgba);
    save_png(
        &Frame::new(top.width, top.height * 2, sheet),
        &out.join("impostor.png"),
    )
    .map_err(|e| (2, e))?;
    if let Some(path) = report {
        let json = serde_json::json!({
            "pixels": PIXELS,
            "size": SIZE,
            "fov_degrees": FOV,
            "frames": descriptor.frames,
            "frame_size": descriptor.frame_size,
            "radius": atlas.layout.radius,
            "switch_distance": normalized,
            "distance": distance,
            "views": views.len(),
            "worst_px": at_switch.worst,
            "worst_px_at_half": at_half.worst,
            "fewest_mesh_pixels": at_switch.fewest,
            "worst_px_with_wall": walled.worst,
            "fewest_mesh_pixels_with_wall": walled.fewest,
            "crossfade_see_through": crossfade.see_through,
            "crossfade_impostor_kept": crossfade.kept,
            "crossfade_differs_from_mesh": crossfade.differs,
            "group": smooth,
            "group_hard_switch": hard,
            "group_prepass": prepass,
        });
        let text = serde_json::to_string_pretty(&json).map_err(|e| (2, e.to_string()))?;
        std::fs::write(path, text).map_err(|e| (2, format!("{}: {e}", path.display())))?;
    }
    Ok(())
}
