//! A forest of 10,000 trees with alpha-masked leaves (1,208 triangles each), seen from the
//! distance where its chain ends in impostors, each tree drawn at the level its distance calls
//! for, with and without an impostor as the chain's last level: the triangles each draws, and
//! how far each picture's outline is from the forest drawn at full detail
//! (`lodkit::metrics::coverage_distance`), measured in one run. Switch distances for the pixel
//! error on the 640 x 360 view.
//!
//! `cargo run --release --features wgpu,lod_chain --example impostor_forest -- [--out DIR]
//! [--pixel-error P]` (default 1 pixel; the camera stays where it is)
//! Writes DIR/impostor_forest.png (top: full detail, middle: the mesh-only chain, bottom: the
//! chain ending in impostors; default DIR: lodkit-out) and prints the table.

use std::error::Error;
use std::time::Instant;

use glam::{Mat4, Quat, Vec3};
use lodkit::gpu::GpuContext;
use lodkit::gpu::impostor::{
    ImpostorBakeDescriptor, ImpostorBaker, ImpostorInstance, ImpostorMesh, ImpostorPart,
    ImpostorPass, ImpostorPassDescriptor, ImpostorTextures, ImpostorView,
};
use lodkit::impostor::impostor_switch_distance;
use lodkit::lod_chain::{LodChain, LodChainDescriptor, MeshData, PixelErrorCamera};
use lodkit::metrics::coverage_distance;
use lodkit_scenes::tree::LeafyTree;

const WIDTH: u32 = 640;
const HEIGHT: u32 = 360;
const FOV: f32 = 60.0;
/// Trees per side of the grid.
const SIDE: u32 = 100;
/// Metres between trees: a dense stand, 90 m a side.
const SPACING: f32 = 0.9;
/// The camera's distance from the stand's centre: the stand sits at the impostors' distance.
const DISTANCE: f32 = 220.0;

/// The forest: each tree's object-to-world transform (grid, jittered, turned, scaled).
fn forest() -> Vec<Mat4> {
    let mut state = 0x3c6e_f372_u32;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as f32 / u32::MAX as f32
    };
    (0..SIDE * SIDE)
        .map(|k| {
            let (i, j) = ((k % SIDE) as f32, (k / SIDE) as f32);
            let at = Vec3::new(i + next() * 0.6, 0.0, j + next() * 0.6) * SPACING;
            let turn = Quat::from_rotation_y(next() * std::f32::consts::TAU);
            Mat4::from_scale_rotation_translation(Vec3::splat(0.8 + 0.4 * next()), turn, at)
        })
        .collect()
}

/// Coverage of an image (alpha over a half).
fn covered(texels: &[[f32; 4]]) -> Vec<bool> {
    texels.iter().map(|t| t[3] > 0.5).collect()
}

fn main() -> Result<(), Box<dyn Error>> {
    let out = std::env::args()
        .skip_while(|a| a != "--out")
        .nth(1)
        .unwrap_or_else(|| "lodkit-out".into());
    let pixel_error: f32 = std::env::args()
        .skip_while(|a| a != "--pixel-error")
        .nth(1)
        .map_or(Ok(1.0), |p| p.parse())?;
    std::fs::create_dir_all(&out)?;
    let gpu = GpuContext::new_headless(&Default::default())?;
    println!("adapter: {}", gpu.adapter_summary());

    // The tree and its chain (the leaves thin out level by level).
    let tree = LeafyTree::new(600, 11);
    let data = MeshData {
        positions: &tree.positions,
        indices: &tree.indices,
        normals: Some(&tree.normals),
        uvs: Some(&tree.uvs),
    };
    let camera = PixelErrorCamera {
        fov_y: FOV.to_radians(),
        viewport_height: HEIGHT as f32,
        pixel_error,
        hysteresis: 0.0,
    };
    let chain = LodChain::build(
        &data,
        &LodChainDescriptor {
            levels: 4,
            camera,
            ..Default::default()
        },
    )?;
    let material = tree.material();
    let parts: Vec<ImpostorPart> = chain
        .levels()
        .iter()
        .map(|l| ImpostorPart {
            mesh: ImpostorMesh {
                positions: l.positions(),
                indices: l.indices(),
                normals: l.normals(),
                uvs: l.uvs(),
            },
            material,
        })
        .collect();
    let levels = ImpostorBaker::new(&gpu, &parts)?;
    let atlas =
        ImpostorBaker::new(&gpu, &parts[..1])?.bake(&gpu, &ImpostorBakeDescriptor::default())?;
    let textures = ImpostorTextures::new(&gpu, &atlas)?;
    let distances = chain.switch_distances(&camera)?;
    let hide = chain.max_distance(&camera)?;
    // The chain with an impostor: the mesh levels that switch in before the impostor's own
    // distance, then the impostor (levels that would switch in later give way to it).
    let own = impostor_switch_distance(&atlas.layout, &camera)?;
    let kept: Vec<f32> = distances
        .iter()
        .enumerate()
        .filter(|(i, d)| *i == 0 || **d < own)
        .map(|(_, d)| *d)
        .collect();
    let impostor_at = own.max(*kept.last().unwrap_or(&0.0));

    // Each tree's level: the chain's (and the impostor's) switch distances against its
    // view-normalized distance (centre distance over |P11|, divided by its scale).
    let target = Vec3::new(SIDE as f32, 0.0, SIDE as f32) * (SPACING * 0.5);
    let eye = target + Vec3::new(-1.0, 0.35, -1.0).normalize() * DISTANCE;
    let proj = glam::camera::rh::proj::directx::perspective(
        FOV.to_radians(),
        WIDTH as f32 / HEIGHT as f32,
        0.5,
        2000.0,
    );
    let clip = proj * glam::camera::rh::view::look_at_mat4(eye, target, Vec3::Y);
    let center = Vec3::from(chain.bounding_sphere().center);
    let trees = forest();
    let mut lod0 = Vec::new();
    let mut mesh_only = Vec::new();
    let mut near = Vec::new();
    let mut far = Vec::new();
    let (mut tri_full, mut tri_chain, mut tri_impostor) = (0usize, 0usize, 0usize);
    for model in &trees {
        let (scale, _, _) = model.to_scale_rotation_translation();
        let world = model.transform_point3(center);
        let d = lodkit::select::view_normalized_distance(world.distance(eye), &proj, scale.x);
        if d >= hide {
            continue;
        }
        let level = distances[1..].iter().filter(|&&s| s <= d).count();
        lod0.push((0, *model));
        mesh_only.push((level, *model));
        tri_full += chain.levels()[0].triangles();
        tri_chain += chain.levels()[level].triangles();
        if d >= impostor_at {
            far.push(ImpostorInstance::new(*model));
            tri_impostor += 2;
        } else {
            let level = kept[1..].iter().filter(|&&s| s <= d).count();
            near.push((level, *model));
            tri_impostor += chain.levels()[level].triangles();
        }
    }

    // The three pictures.
    let start = Instant::now();
    let full = covered(&levels.render_instances(&gpu, clip, &lod0, WIDTH, HEIGHT)?);
    let full_time = start.elapsed();
    let start = Instant::now();
    let chained = covered(&levels.render_instances(&gpu, clip, &mesh_only, WIDTH, HEIGHT)?);
    let chain_time = start.elapsed();
    let pass = ImpostorPass::new(&gpu, &ImpostorPassDescriptor::default())?;
    let start = Instant::now();
    let near_mask = covered(&levels.render_instances(&gpu, clip, &near, WIDTH, HEIGHT)?);
    let view = ImpostorView {
        view_proj: clip,
        eye,
        light: Vec3::new(0.3, 0.8, 0.5).normalize(),
        ambient: 1.0,
    };
    let drawn = pass.render(&gpu, &textures, &view, &far, (WIDTH, HEIGHT))?;
    let impostor_time = start.elapsed();
    let with_impostors: Vec<bool> = near_mask
        .iter()
        .zip(drawn.chunks(4))
        .map(|(n, p)| *n || p[3] > 127)
        .collect();
    let w = WIDTH as usize;
    let missing = (0..full.len())
        .filter(|&i| full[i] && !with_impostors[i])
        .count();
    let extra = (0..full.len())
        .filter(|&i| !full[i] && with_impostors[i])
        .count();
    let covered_px = full.iter().filter(|c| **c).count();
    let chain_px = coverage_distance(&full, &chained, w)?;
    let impostor_px = coverage_distance(&full, &with_impostors, w)?;
    let counts: Vec<usize> = chain.levels().iter().map(|l| l.triangles()).collect();
    println!(
        "chain levels (triangles): {counts:?}, switch distances {distances:?}, hidden from {hide:.1}; the impostor within {pixel_error} px from {own:.1}"
    );
    println!(
        "{} trees drawn ({} beyond the hide distance); {} as impostors (from {impostor_at:.1}, view-normalized)",
        lod0.len(),
        trees.len() - lod0.len(),
        far.len()
    );
    println!("| forest | triangles | outline vs full detail | wall clock (draw + read back) |");
    println!("|---|---|---|---|");
    println!(
        "| full detail | {tri_full} | 0 px | {:.0} ms |",
        full_time.as_secs_f64() * 1e3
    );
    println!(
        "| mesh-only chain | {tri_chain} | {chain_px:.2} px | {:.0} ms |",
        chain_time.as_secs_f64() * 1e3
    );
    println!(
        "| chain with impostors | {tri_impostor} ({:.1}x fewer than the mesh-only chain) | {impostor_px:.2} px | {:.0} ms |",
        tri_chain as f64 / tri_impostor.max(1) as f64,
        impostor_time.as_secs_f64() * 1e3
    );
    println!(
        "pixels the full-detail forest covers and the impostors do not: {missing} of {covered_px}; the other way: {extra}"
    );
    let mut picture = image::RgbImage::new(WIDTH, HEIGHT * 3);
    for (row, mask) in [&full, &chained, &with_impostors].into_iter().enumerate() {
        for (i, c) in mask.iter().enumerate() {
            let px = if *c { [40, 110, 40] } else { [235, 240, 250] };
            picture.put_pixel(
                i as u32 % WIDTH,
                row as u32 * HEIGHT + i as u32 / WIDTH,
                image::Rgb(px),
            );
        }
    }
    picture.save(format!("{out}/impostor_forest.png"))?;
    println!("wrote {out}/impostor_forest.png");
    Ok(())
}
