//! Frame-sequential LOD interpolation (Scherzer & Wimmer 2008) in a wgpu frame loop, headless:
//! the smallest complete use of the transition scheduler, the LOD buffer pair and the combine
//! pass. Copy the loop body into your renderer.
//!
//! Each frame:
//! 1. `TransitionScheduler::advance` moves every transition on; LOD selection (hard switches
//!    here: the scheduler does the blending) says which level each instance wants, and an
//!    instance whose level changes begins a time-driven transition;
//! 2. `draw(key)` gives each instance this frame's LOD, id and visibility threshold tau; the
//!    scene goes into LOD buffer `buffer_index()` (your forward pass writes color, id and depth;
//!    `lodkit_scenes::lod_buffer::LodBufferRenderer` is the reference for it);
//! 3. `CombinePass::record` (with `CombineRegions::Only`) merges that buffer with last frame's,
//!    reprojected through the camera motion (`new_to_old_matrix`), into the frame's target, only
//!    inside the screen rectangles of the instances in transition (the rest of the frame is a
//!    copy), told where the level last frame drew covers the screen now and how deep: lodkit's
//!    default route, the older-level depth pass (each t-instance's `older(key)` level drawn
//!    again, whole and depth only, into `LodBuffers::level_depth`; `CombineCoverage::Known` with
//!    the data `CombineData::depth_pass` lays out from the scheduler's `older(key)`).
//!
//! `cargo run --example frame_sequential -- [--out DIR]`
//! Writes DIR/frame_sequential.png (default DIR: lodkit-out): frames of the camera pulling back
//! while a row of spheres turns into boxes, nearest first.

use std::error::Error;

use glam::{Mat4, Vec3, Vec4};
use lodkit::combine::screen_rect;
use lodkit::combine_coverage::{CombineData, DepthPassFrame, OlderDepth};
use lodkit::frame_sequential::{Drive, TransitionScheduler};
use lodkit::gpu::GpuContext;
use lodkit::gpu::frame_sequential::{
    CombineCoverage, CombineFrame, CombinePass, CombinePassDescriptor, CombineRegions, LodBuffers,
};
use lodkit::gpu::readback::read_texture_rgba8;
use lodkit::gpu::resources::texture_2d;
use lodkit::reproject::new_to_old_matrix;
use lodkit::select::{LodCamera, LodGroup, LodSettings, LodState, TransitionMode};
use lodkit::visibility::{VisibilityPattern, visibility_texture};
use lodkit_scenes::lod_buffer::{LodBufferFrame, LodBufferRenderer, LodDrawItem, LodView};
use lodkit_scenes::mesh::{GpuMesh, Mesh};

const SIZE: (u32, u32) = (240, 135);
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// Frames of the run, at 60 frames per second.
const FRAMES: usize = 90;
/// Columns of the strip: frames spread evenly over the run.
const COLUMNS: usize = 6;

/// Object to world of the instance at `p`.
fn model(p: Vec3) -> Mat4 {
    Mat4::from_translation(p) * Mat4::from_scale(Vec3::splat(0.45))
}

fn main() -> Result<(), Box<dyn Error>> {
    let out = std::env::args()
        .skip_while(|a| a != "--out")
        .nth(1)
        .unwrap_or_else(|| "lodkit-out".into());
    let gpu = GpuContext::new_headless(&Default::default())?;
    println!("adapter: {}", gpu.adapter_summary());
    let (w, h) = SIZE;

    // Made once: the two LOD buffers, the pass that draws into them, the combine, the target.
    // Nothing here moves by itself (the camera's motion is the combine's reprojection): no
    // object motion target, 8 bytes per pixel per LOD buffer beyond its depth.
    let buffers = LodBuffers::without_motion(&gpu, w, h, FORMAT)?;
    let vis = visibility_texture(VisibilityPattern::BlueNoise, 64, 1);
    let renderer = LodBufferRenderer::new(&gpu, FORMAT, &vis, 0.25)?;
    let combine = CombinePass::new(
        &gpu,
        &CombinePassDescriptor {
            target_format: FORMAT,
            ..Default::default()
        },
    )?;
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT
        | wgpu::TextureUsages::COPY_SRC
        | wgpu::TextureUsages::COPY_DST;
    let target = texture_2d(&gpu, SIZE, FORMAT, usage, "frame")?;
    let target_view = target.create_view(&Default::default());
    let meshes = [Mesh::sphere(16, 32), Mesh::cube()];
    let lods = [
        (
            GpuMesh::new(&gpu, &meshes[0])?,
            Vec4::new(0.9, 0.2, 0.15, 1.0),
        ),
        (
            GpuMesh::new(&gpu, &meshes[1])?,
            Vec4::new(0.15, 0.3, 0.9, 1.0),
        ),
    ];
    // Five instances in a row going away from the camera; level 1 beyond a view-normalized
    // distance of 2.5. Selection switches hard: the scheduler spreads each switch over 0.3 s.
    let group = LodGroup::from_distances(&[0.0, 2.5])?;
    let settings = LodSettings {
        transition: TransitionMode::Hard,
        ..Default::default()
    };
    let positions: Vec<Vec3> = (0..5)
        .map(|i| Vec3::new(-1.0 + 0.9 * i as f32, 0.0, -1.6 * i as f32))
        .collect();
    let mut scheduler = TransitionScheduler::new();
    let keys: Vec<_> = positions.iter().map(|_| scheduler.insert(0)).collect();
    let mut states = vec![LodState::NEW; positions.len()];

    let aspect = w as f32 / h as f32;
    let proj = glam::camera::rh::proj::directx::perspective(0.7, aspect, 0.1, 100.0);
    let mut previous_view: Option<Mat4> = None;
    let mut strip = image::RgbaImage::new(w * COLUMNS as u32, h);
    let mut transitions = 0;
    // Triangles drawn over the frames with an instance in transition, against a hard switch
    // at each transition's midpoint (the outgoing LOD before progress 0.5, the incoming after).
    let (mut drawn, mut hard, mut per_frame) = (0u64, 0u64, Vec::new());
    // Triangles of the older-level depth pass (depth only, no shading).
    let mut depth_pass = 0u64;
    for frame in 0..FRAMES {
        let dt = 1.0 / 60.0;
        if frame > 0 {
            scheduler.advance(dt);
        }
        // The camera pulls back from 2 to 9 units in front of the row.
        let eye = Vec3::new(0.0, 0.5, 2.0 + 7.0 * frame as f32 / FRAMES as f32);
        let view = glam::camera::rh::view::look_at_mat4(eye, Vec3::new(0.0, 0.0, -3.0), Vec3::Y);
        let camera = LodCamera::from_view(&view, proj);

        // 1. Selection: begin a transition where an instance wants another level.
        for ((key, state), &p) in keys.iter().zip(&mut states).zip(&positions) {
            let wanted = group.select(camera.lod_distance(p, 1.0, 1.0), &settings, dt, state);
            let draws = scheduler.draw(*key)?;
            if !scheduler.in_transition(*key) && draws.lod != wanted.current {
                scheduler.begin_transition(*key, wanted.current, Drive::Time { seconds: 0.3 })?;
                transitions += 1;
            }
        }

        // 2. The scene into this frame's LOD buffer, each instance with this frame's draw.
        let items = keys
            .iter()
            .zip(&positions)
            .map(|(key, &p)| {
                let d = scheduler.draw(*key)?;
                let (mesh, color) = &lods[usize::from(d.lod.min(1))];
                Ok(LodDrawItem::from_draw(mesh, model(p), *color, &d))
            })
            .collect::<Result<Vec<_>, Box<dyn Error>>>()?;
        let mut hard_frame = 0;
        for key in &keys {
            let d = scheduler.draw(*key)?;
            let (this, other) = (usize::from(d.lod.min(1)), 1 - usize::from(d.lod.min(1)));
            let (outgoing, incoming) = if d.incoming {
                (other, this)
            } else {
                (this, other)
            };
            let level = match scheduler.in_transition(*key) {
                true if d.progress < 0.5 => outgoing,
                true => incoming,
                false => this,
            };
            hard_frame += u64::from(lods[level].0.triangles());
        }
        let index = scheduler.buffer_index();
        let clear = wgpu::Color {
            r: 0.05,
            g: 0.06,
            b: 0.09,
            a: 1.0,
        };
        // With last frame's camera too: the screen-anchored visibility pattern predicts from it
        // where each fragment is displayed next frame.
        let views = [proj * view, proj * previous_view.unwrap_or(view)];
        let lod_view = LodView {
            view_proj: views[0],
            prev_view_proj: views[1],
        };
        let (triangles, _) = renderer.render(
            &gpu,
            &buffers,
            &LodBufferFrame {
                index,
                view: lod_view,
                items: &items,
                clear,
                ..Default::default()
            },
        )?;
        if keys.iter().any(|key| scheduler.in_transition(*key)) {
            (drawn, hard) = (drawn + triangles, hard + hard_frame);
            per_frame.push(triangles);
        }

        // 3. Combine with last frame's buffer, reprojected through the camera motion, where the
        //    t-instances are in this frame's and last frame's view (both LODs fit the unit box).
        let new_to_old = previous_view.map_or(CombinePass::NO_HISTORY, |old| {
            new_to_old_matrix(&view, &proj, &old, &proj)
        });
        let unit_box = (Vec3::splat(-1.0), Vec3::splat(1.0));
        let regions: Vec<_> = keys
            .iter()
            .zip(&positions)
            .filter(|(key, _)| scheduler.in_transition(**key))
            .filter_map(|(_, &p)| screen_rect(unit_box, model(p), &views, SIZE, 2))
            .collect();
        // Where the level the older buffer holds covers the screen now and how deep: the
        // t-instances' older levels drawn again, whole and depth only, with this frame's camera
        // (the older-level depth pass), each shown at this frame's threshold for it (the
        // pattern is on the screen): exactly complementary to the level drawn now.
        let mut older_items = Vec::new();
        let mut older = Vec::new();
        for (key, &p) in keys.iter().zip(&positions) {
            if let Some(o) = scheduler.older(*key)? {
                let (mesh, color) = &lods[usize::from(o.lod.min(1))];
                let mut item =
                    LodDrawItem::from_draw(mesh, model(p), *color, &scheduler.draw(*key)?);
                item.id = o.id;
                older_items.push(item);
                older.push(OlderDepth::from(o));
            }
        }
        if !older_items.is_empty() {
            let (triangles, _) = renderer.render_level_depth(
                &gpu,
                &buffers,
                &LodBufferFrame {
                    view: lod_view,
                    items: &older_items,
                    ..Default::default()
                },
            )?;
            depth_pass += triangles;
        }
        let data = CombineData::depth_pass(&DepthPassFrame {
            new_to_old,
            objects: &older,
            ..Default::default()
        })?;
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let frame_to_combine = CombineFrame {
            buffers: &buffers,
            newer: index,
            new_to_old,
            target: &target_view,
            regions: CombineRegions::Only(&regions),
            coverage: CombineCoverage::Known {
                data: &data,
                level_depth: Some(buffers.level_depth()),
                pattern: Some(renderer.visibility_view()),
            },
        };
        combine.record(&gpu, &mut encoder, &frame_to_combine)?;
        gpu.queue.submit([encoder.finish()]);
        previous_view = Some(view);

        if frame % (FRAMES / COLUMNS) == FRAMES / COLUMNS - 1 {
            let column = (frame / (FRAMES / COLUMNS)) as i64;
            let pixels = read_texture_rgba8(&gpu, &target)?;
            let tile = image::RgbaImage::from_raw(w, h, pixels).ok_or("tile size")?;
            image::imageops::replace(&mut strip, &tile, i64::from(w) * column, 0);
        }
    }
    println!("{transitions} transitions over {FRAMES} frames");
    let (lo, hi) = (per_frame.iter().min(), per_frame.iter().max());
    println!(
        "frames with a transition: {} triangles each ({} per sphere, {} per box); \
         {drawn} in all, against {hard} for a hard switch at each transition's midpoint; \
         {depth_pass} more drawn depth only in the older-level depth pass",
        match (lo, hi) {
            (Some(lo), Some(hi)) => format!("{lo} to {hi}"),
            _ => "no frame".to_owned(),
        },
        lods[0].0.triangles(),
        lods[1].0.triangles(),
    );
    std::fs::create_dir_all(&out)?;
    let path = std::path::Path::new(&out).join("frame_sequential.png");
    strip.save(&path)?;
    println!("wrote {}", path.display());
    Ok(())
}
