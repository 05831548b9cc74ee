//! Single-frame LOD transitions in a wgpu frame loop, headless: LOD selection decides when an
//! object switches and how far its transition is; the renderer draws both LODs with Giegl &
//! Wimmer's unpopping states (blend constant, depth writes by role) or with a complementary
//! screen-door dither. Copy the loop body into your renderer.
//!
//! Each frame:
//! 1. `LodGroup::select` with the camera's view-normalized distance gives the current level, the
//!    next one and the transition progress t (time-driven here: 0.5 s);
//! 2. `transition_items` turns (outgoing, incoming, t) into the draws of that frame, in order,
//!    with their render states (`lodkit::unpopping`) or screen-door alphas;
//! 3. `MeshRenderer` draws them after the opaque scenery.
//!
//! `cargo run --example crossfade -- [--out DIR]`
//! Writes DIR/crossfade.png (default DIR: lodkit-out): one row per technique, a column per
//! sampled frame of the transition.

use std::error::Error;

use glam::{Mat4, Vec3, Vec4};
use lodkit::gpu::GpuContext;
use lodkit::gpu::readback::read_texture_rgba8;
use lodkit::screen_door::DitherPattern;
use lodkit::select::{LodCamera, LodGroup, LodSettings, LodState, TransitionMode};
use lodkit::unpopping::LodRenderState;
use lodkit_scenes::mesh::{DrawItem, GpuMesh, Mesh, MeshFrame, MeshRenderer, RenderTarget};
use lodkit_scenes::transition::{SingleFrameTechnique, transition_items};

const SIZE: (u32, u32) = (200, 150);
/// Frames per second of the simulated clock.
const FPS: f32 = 60.0;
/// Frames the camera takes to pull back.
const FRAMES: usize = 120;

fn main() -> Result<(), Box<dyn Error>> {
    let out = std::env::args()
        .skip_while(|a| a != "--out")
        .nth(1)
        .unwrap_or_else(|| "lodkit-out".into());
    let gpu = GpuContext::new_headless(&Default::default())?;
    println!("adapter: {}", gpu.adapter_summary());

    // Two LODs: level 0 up to a view-normalized distance of 2 (6.5 units with this lens), level 1
    // beyond.
    let lods = [
        (
            GpuMesh::new(&gpu, &Mesh::sphere(24, 48))?,
            Vec4::new(0.1, 0.8, 0.3, 1.0),
        ),
        (
            GpuMesh::new(&gpu, &Mesh::sphere(4, 8))?,
            Vec4::new(0.1, 0.4, 1.0, 1.0),
        ),
    ];
    let backdrop = GpuMesh::new(&gpu, &Mesh::cube())?;
    let group = LodGroup::from_distances(&[0.0, 2.0])?;
    let settings = LodSettings {
        hysteresis: 0.1,
        transition: TransitionMode::Time { seconds: 0.5 },
        ..Default::default()
    };
    // Unpopping blends with the blend constant; the dither draws opaque with alphas. The
    // renderer's flag picks the dither pattern (blue noise here).
    let renderer = MeshRenderer::new(&gpu, true)?;
    let target = RenderTarget::new(&gpu, SIZE.0, SIZE.1)?;
    let aspect = SIZE.0 as f32 / SIZE.1 as f32;
    let proj = glam::camera::rh::proj::directx::perspective(0.6, aspect, 0.1, 100.0);
    let techniques = [
        SingleFrameTechnique::Unpopping,
        SingleFrameTechnique::Dither(DitherPattern::BlueNoise16x16),
    ];

    let mut rows: Vec<Vec<Vec<u8>>> = vec![Vec::new(); techniques.len()];
    for (row, &technique) in techniques.iter().enumerate() {
        let mut state = LodState::NEW;
        let mut transition_frames = Vec::new();
        for frame in 0..FRAMES {
            // The camera pulls back from 4 to 10 units.
            let eye = Vec3::new(0.0, 0.6, 4.0 + 6.0 * frame as f32 / FRAMES as f32);
            let view = glam::camera::rh::view::look_at_mat4(eye, Vec3::ZERO, Vec3::Y);
            let distance = LodCamera::from_view(&view, proj).lod_distance(Vec3::ZERO, 1.0, 1.0);
            let selection = group.select(distance, &settings, 1.0 / FPS, &mut state);
            let model = Mat4::IDENTITY;
            let mut items = vec![DrawItem {
                mesh: &backdrop,
                model: Mat4::from_translation(Vec3::new(0.0, 0.0, -2.5))
                    * Mat4::from_scale(Vec3::new(2.0, 1.5, 0.1)),
                color: Vec4::new(0.9, 0.2, 0.1, 1.0),
                state: LodRenderState::OPAQUE,
                dither_alpha: None,
                sway: [0.0; 2],
                alpha_rect: Vec4::ZERO,
            }];
            let current = &lods[usize::from(selection.current.min(1))];
            match selection.next {
                // Outgoing and incoming LODs, in the order and states of the technique.
                Some(next) => {
                    let next = &lods[usize::from(next.min(1))];
                    let (t, outgoing) = (selection.transition, (&current.0, current.1));
                    items.extend(transition_items(
                        technique,
                        t,
                        model,
                        outgoing,
                        (&next.0, next.1),
                    ));
                }
                None => items.push(DrawItem {
                    mesh: &current.0,
                    model,
                    color: current.1,
                    state: LodRenderState::OPAQUE,
                    dither_alpha: None,
                    sway: [0.0; 2],
                    alpha_rect: Vec4::ZERO,
                }),
            }
            let clear = wgpu::Color {
                r: 0.02,
                g: 0.02,
                b: 0.05,
                a: 1.0,
            };
            let light = Vec3::new(0.4, 0.8, 0.6);
            renderer.render(
                &gpu,
                &target,
                &MeshFrame {
                    clear,
                    view_proj: proj * view,
                    light_dir: light,
                    items: &items,
                    ..Default::default()
                },
            )?;
            if selection.next.is_some() {
                transition_frames.push(frame);
                rows[row].push(read_texture_rgba8(&gpu, &target.color)?);
            }
        }
        println!(
            "{}: transition over frames {:?}..={:?}",
            technique.name(),
            transition_frames.first(),
            transition_frames.last()
        );
    }

    // A strip: 6 frames evenly spread over each technique's transition.
    const COLUMNS: usize = 6;
    let (w, h) = SIZE;
    let mut strip = image::RgbaImage::new(w * COLUMNS as u32, h * rows.len() as u32);
    for (y, frames) in rows.iter().enumerate() {
        if frames.is_empty() {
            return Err("the camera path crossed no LOD distance".into());
        }
        for x in 0..COLUMNS {
            let pixels = &frames[x * (frames.len() - 1) / (COLUMNS - 1)];
            let tile = image::RgbaImage::from_raw(w, h, pixels.clone()).ok_or("tile size")?;
            let (tx, ty) = (i64::from(w) * x as i64, i64::from(h) * y as i64);
            image::imageops::replace(&mut strip, &tile, tx, ty);
        }
    }
    std::fs::create_dir_all(&out)?;
    let path = std::path::Path::new(&out).join("crossfade.png");
    strip.save(&path)?;
    println!("wrote {}", path.display());
    Ok(())
}
