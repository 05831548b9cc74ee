//! An octahedral impostor, headless: a tree with alpha-masked leaves baked into an atlas
//! (`bake_impostor`), uploaded (`ImpostorTextures`) and drawn into the app's own render pass
//! (`ImpostorPass`), beside the mesh it stands for, at the distance from which its picture stays
//! within a pixel error of the mesh's (`impostor_switch_distance`). Copy the calls into your
//! renderer.
//!
//! `cargo run --example impostor -- [--out DIR]`
//! Writes DIR/impostor_atlas.png (the colour atlas) and DIR/impostor.png (top: the mesh, bottom:
//! the impostor, each from three directions at the switch distance for 2 pixels on a 240-pixel
//! high view, 30 degrees field of view, enlarged 4x; default DIR: lodkit-out).

use std::error::Error;

use glam::{Mat4, Vec3};
use lodkit::gpu::GpuContext;
use lodkit::gpu::impostor::{
    ImpostorBakeDescriptor, ImpostorBaker, ImpostorInstance, ImpostorPass, ImpostorPassDescriptor,
    ImpostorTextures, ImpostorView,
};
use lodkit::impostor::{impostor_switch_distance, srgba8};
use lodkit::lod_chain::PixelErrorCamera;
use lodkit_scenes::tree::LeafyTree;

const SIZE: u32 = 240;
const FOV: f32 = 30.0;

fn main() -> Result<(), Box<dyn Error>> {
    let out = std::env::args()
        .skip_while(|a| a != "--out")
        .nth(1)
        .unwrap_or_else(|| "lodkit-out".into());
    std::fs::create_dir_all(&out)?;
    let gpu = GpuContext::new_headless(&Default::default())?;
    println!("adapter: {}", gpu.adapter_summary());

    // 1. Bake: the mesh, its material (base colour texture, alpha mask, double-sided), a layout.
    let tree = LeafyTree::new(40, 7);
    let start = std::time::Instant::now();
    let baker = ImpostorBaker::new(&gpu, &[tree.part()])?;
    let atlas = baker.bake(&gpu, &ImpostorBakeDescriptor::default())?;
    let baked = start.elapsed();
    let size = atlas.layout.atlas_size();
    image::RgbaImage::from_raw(size, size, atlas.color[0].to_srgba8())
        .ok_or("atlas size")?
        .save(format!("{out}/impostor_atlas.png"))?;

    // 2. Where it may be shown: the switch distance for 2 pixels on this view.
    let camera = PixelErrorCamera {
        fov_y: FOV.to_radians(),
        viewport_height: SIZE as f32,
        pixel_error: 2.0,
        hysteresis: 0.0,
    };
    let switch = impostor_switch_distance(&atlas.layout, &camera)?;
    let distance = switch * camera.p11() as f32;
    println!(
        "{} triangles; atlas {size} x {size} baked in {:.0} ms (wall clock: render, read back, pad, mips); switch distance {switch:.1} (view-normalized), {distance:.1} object units",
        tree.triangles(),
        baked.as_secs_f64() * 1e3
    );

    // 3. Draw: upload once, build the pass once, prepare per view, draw in your render pass.
    let textures = ImpostorTextures::new(&gpu, &atlas)?;
    let pass = ImpostorPass::new(
        &gpu,
        &ImpostorPassDescriptor::default(), // Rgba8UnormSrgb colour, Depth32Float depth
    )?;
    let center = Vec3::from(atlas.layout.center);
    let mut picture = image::RgbaImage::new(SIZE * 3, SIZE * 2);
    for (k, view) in [
        Vec3::new(1.0, 0.2, 0.3),
        Vec3::new(-0.4, 0.6, 0.7),
        Vec3::new(0.1, 1.0, -0.2),
    ]
    .into_iter()
    .enumerate()
    {
        let eye = center + view.normalize() * distance;
        let up = if view.normalize().y > 0.95 {
            Vec3::Z
        } else {
            Vec3::Y
        };
        let clip = glam::camera::rh::proj::directx::perspective(
            FOV.to_radians(),
            1.0,
            0.1,
            distance * 3.0,
        ) * glam::camera::rh::view::look_at_mat4(eye, center, up);
        // The mesh, as the bake draws it (unlit base colour).
        let reference = baker.render(&gpu, clip, SIZE, SIZE)?;
        // The impostor.
        let view = ImpostorView {
            view_proj: clip,
            eye,
            light: Vec3::new(0.3, 0.8, 0.5).normalize(),
            ambient: 1.0,
        };
        let instances = [ImpostorInstance::new(Mat4::IDENTITY)];
        let drawn = pass.render(&gpu, &textures, &view, &instances, (SIZE, SIZE))?;
        // Both enlarged 4x around the centre so the small pictures can be seen.
        for y in 0..SIZE {
            for x in 0..SIZE {
                let (sx, sy) = (SIZE * 3 / 8 + x / 4, SIZE * 3 / 8 + y / 4);
                let i = (sy * SIZE + sx) as usize;
                let t = reference[i];
                let mesh_px = if t[3] > 0.5 {
                    srgba8([t[0], t[1], t[2], 1.0])
                } else {
                    [255; 4]
                };
                picture.put_pixel(k as u32 * SIZE + x, y, image::Rgba(mesh_px));
                let d = &drawn[i * 4..i * 4 + 4];
                let impostor_px = [d[0], d[1], d[2], 255];
                picture.put_pixel(k as u32 * SIZE + x, SIZE + y, image::Rgba(impostor_px));
            }
        }
    }
    picture.save(format!("{out}/impostor.png"))?;
    println!("wrote {out}/impostor_atlas.png and {out}/impostor.png (top: mesh, bottom: impostor)");
    Ok(())
}
