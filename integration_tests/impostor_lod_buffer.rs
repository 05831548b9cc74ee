//! An octahedral impostor in lodkit's frame-sequential LOD (`ImpostorTarget::LodBuffer` and
//! `ImpostorTarget::LevelDepth`): drawn into a LOD buffer it covers the pixels and writes the
//! depth its colour pass does, with the id word and the visibility flags the CPU twins give and
//! the object motion of the surface it shows; a mesh level handed over to it, frame by frame
//! through the LOD buffers, the older-level depth pass and the combine, shows no background
//! where both levels cover the screen and nothing where neither does.

use glam::{Mat4, Vec2, Vec3, Vec4};
use lodkit::frame_sequential::{Drive, FrameDraw, TransitionScheduler};
use lodkit::gpu::GpuContext;
use lodkit::gpu::frame_sequential::{
    CombineCoverage, CombineFrame, CombinePass, CombinePassDescriptor, CombineRegions, LodBuffers,
    read_lod_image,
};
use lodkit::gpu::impostor::{
    ImpostorBakeDescriptor, ImpostorBaker, ImpostorInstance, ImpostorLodView, ImpostorPass,
    ImpostorPassDescriptor, ImpostorTarget, ImpostorTextures, ImpostorView,
};
use lodkit::gpu::readback::{read_depth32, read_texture_rgba8};
use lodkit::gpu::resources::{begin_targets_pass, texture_2d};
use lodkit::impostor::ImpostorShape;
use lodkit::visibility::{
    VisibilityPattern, VisibilitySpace, visibility_flags_screen, visibility_texture,
};
use lodkit_scenes::lod_buffer::{LodBufferFrame, LodBufferRenderer, LodDrawItem, LodView};
use lodkit_scenes::mesh::{GpuMesh, Mesh};

use crate::harness::say;

const SIZE: u32 = 128;
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
const BLACK: wgpu::Color = wgpu::Color::BLACK;

/// A sphere with a box sticking out of its side: no symmetry the frames could hide behind.
pub(crate) fn lumpy() -> Mesh {
    let mut mesh = Mesh::sphere(16, 24);
    let side =
        Mat4::from_translation(Vec3::new(0.75, 0.3, 0.1)) * Mat4::from_scale(Vec3::splat(0.5));
    mesh.append(&Mesh::cube(), side);
    mesh
}

/// The impostor of `mesh`: 12 x 12 frames of 64 texels over the whole sphere of directions.
pub(crate) fn bake(gpu: &GpuContext, mesh: &Mesh) -> ImpostorTextures {
    let streams = mesh.bake_streams();
    let baker = ImpostorBaker::new(gpu, &[streams.part()]).unwrap();
    let descriptor = ImpostorBakeDescriptor {
        frames: 12,
        frame_size: 64,
        shape: ImpostorShape::Full,
    };
    ImpostorTextures::new(gpu, &baker.bake(gpu, &descriptor).unwrap()).unwrap()
}

/// The camera: 4.5 units from the origin, slightly above, looking at it.
pub(crate) fn camera() -> (Mat4, Vec3) {
    let eye = Vec3::new(1.2, 1.6, 4.0);
    let view = glam::camera::rh::view::look_at_mat4(eye, Vec3::ZERO, Vec3::Y);
    let proj = glam::camera::rh::proj::directx::perspective(0.7, 1.0, 0.1, 20.0);
    (proj * view, eye)
}

pub(crate) fn impostor_view(view_proj: Mat4, eye: Vec3) -> ImpostorView {
    ImpostorView {
        view_proj,
        eye,
        light: Vec3::new(0.3, 0.8, 0.5).normalize(),
        ambient: 0.4,
    }
}

fn pass(gpu: &GpuContext, target: ImpostorTarget) -> ImpostorPass {
    let descriptor = ImpostorPassDescriptor {
        color_format: FORMAT,
        target,
        ..Default::default()
    };
    ImpostorPass::new(gpu, &descriptor).unwrap()
}

/// Normalized device coordinates of pixel `p`'s centre at `depth`.
fn ndc(p: usize, depth: f32) -> Vec3 {
    let (x, y) = (
        (p as u32 % SIZE) as f32 + 0.5,
        (p as u32 / SIZE) as f32 + 0.5,
    );
    let size = SIZE as f32;
    Vec3::new(2.0 * x / size - 1.0, 1.0 - 2.0 * y / size, depth)
}

/// The impostor drawn into LOD buffer 0 of `buffers` as `instance`.
fn draw_lod(
    gpu: &GpuContext,
    (pass, textures): (&ImpostorPass, &ImpostorTextures),
    buffers: &LodBuffers,
    (index, lod): (usize, &ImpostorLodView),
    instance: ImpostorInstance,
) {
    let (view_proj, eye) = camera();
    let view = impostor_view(view_proj, eye);
    let prepared = pass
        .prepare_lod_buffer(gpu, textures, &view, lod, &[instance])
        .unwrap();
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    {
        let mut render = buffers.begin_pass(&mut encoder, index, BLACK, 1.0, None);
        pass.draw(&mut render, &prepared);
    }
    gpu.queue.submit([encoder.finish()]);
}

#[test]
fn an_impostor_in_a_lod_buffer_writes_what_its_colour_pass_covers_with_the_patterns_flags() {
    let gpu = lodkit_test_gpu!();
    let textures = bake(gpu, &lumpy());
    let (view_proj, eye) = camera();
    // The colour pass into a target whose depth is read back.
    let color_pass = pass(gpu, ImpostorTarget::Color);
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let color = texture_2d(gpu, (SIZE, SIZE), FORMAT, usage, "colour").unwrap();
    // Bound as a texture too: where depth cannot be copied (GL), read_depth32 draws it out.
    let usage = usage | wgpu::TextureUsages::TEXTURE_BINDING;
    let depth = texture_2d(
        gpu,
        (SIZE, SIZE),
        wgpu::TextureFormat::Depth32Float,
        usage,
        "depth",
    )
    .unwrap();
    let view = impostor_view(view_proj, eye);
    let whole = [ImpostorInstance::new(Mat4::IDENTITY)];
    let prepared = color_pass.prepare(gpu, &textures, &view, &whole).unwrap();
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    {
        let (c, d) = (
            color.create_view(&Default::default()),
            depth.create_view(&Default::default()),
        );
        let mut render = begin_targets_pass(
            &mut encoder,
            &[(&c, wgpu::Color::TRANSPARENT)],
            &d,
            1.0,
            None,
            "colour",
        );
        color_pass.draw(&mut render, &prepared);
    }
    gpu.queue.submit([encoder.finish()]);
    let want_color = read_texture_rgba8(gpu, &color).unwrap();
    let want_depth = read_depth32(gpu, &depth).unwrap();

    let vis = visibility_texture(VisibilityPattern::BlueNoise, 64, 1);
    let vis_texture =
        lodkit::gpu::resources::r32float_texture(gpu, vis.size, &vis.texels, "vis").unwrap();
    let vis_view = vis_texture.create_view(&Default::default());
    let lod_pass = pass(gpu, ImpostorTarget::LodBuffer { motion: true });
    let buffers = LodBuffers::new(gpu, SIZE, SIZE, FORMAT).unwrap();
    let screen = ImpostorLodView {
        prev_view_proj: view_proj,
        size: (SIZE, SIZE),
        visibility: &vis_view,
        space: VisibilitySpace::Screen,
        vis_scale: 1.0,
    };
    let draw = FrameDraw {
        lod: 1,
        id: 7,
        tau: 0.37,
        tau_next: 0.52,
        progress: 0.4,
        incoming: true,
    };
    let t_instance = ImpostorInstance::from_draw(Mat4::IDENTITY, Mat4::IDENTITY, &draw);
    draw_lod(
        gpu,
        (&lod_pass, &textures),
        &buffers,
        (0, &screen),
        t_instance,
    );
    let got = read_lod_image(gpu, &buffers, 0).unwrap();

    let mut covered = 0;
    let (mut shown_now, mut shown_next) = (0, 0);
    for p in 0..(SIZE * SIZE) as usize {
        let (x, y) = (
            (p as u32 % SIZE) as f32 + 0.5,
            (p as u32 / SIZE) as f32 + 0.5,
        );
        let colour_pass = want_color[4 * p + 3] > 127;
        let lod_buffer = got.ids[p] != 0;
        assert_eq!(
            colour_pass, lod_buffer,
            "pixel ({x}, {y}): covered in one pass only"
        );
        if !lod_buffer {
            continue;
        }
        covered += 1;
        assert_eq!(got.ids[p], 7, "pixel ({x}, {y}): the instance id");
        // The same fragment in both pipelines: the same surface point, the same depth.
        assert!(
            (got.depths[p] - want_depth[p]).abs() <= 1e-6,
            "pixel ({x}, {y}): depth {} in the LOD buffer, {} in the colour pass",
            got.depths[p],
            want_depth[p]
        );
        // A still camera and object: the pattern is read at the same pixel next frame.
        let at = Vec2::new(x, y);
        let flags = visibility_flags_screen(&vis, at, at, draw.tau, draw.tau_next);
        assert_eq!(got.flags[p], flags, "pixel ({x}, {y}): display-time flags");
        shown_now += usize::from(flags & 1 != 0);
        shown_next += usize::from(flags & 2 != 0);
        assert_eq!(
            got.motion[p],
            Vec2::ZERO,
            "pixel ({x}, {y}): a still object moved"
        );
    }
    say(&format!(
        "impostor in a LOD buffer: {covered} px covered, {shown_now} shown now, {shown_next} next"
    ));
    assert!(covered > 2000, "the impostor covers only {covered} px");
    // The surface the frames saw, not the card: from the eye, the pixels' points reach from
    // the sphere's front (|eye| - 1, 3.4 units) to its outline (about 4.3), where a card
    // through the centre would span 4.5 to 4.7.
    let inverse = view_proj.inverse();
    let distances: Vec<f32> = (0..got.ids.len())
        .filter(|&p| got.ids[p] != 0)
        .map(|p| {
            let (x, y) = (
                (p as u32 % SIZE) as f32 + 0.5,
                (p as u32 / SIZE) as f32 + 0.5,
            );
            let ndc = Vec3::new(
                2.0 * x / SIZE as f32 - 1.0,
                1.0 - 2.0 * y / SIZE as f32,
                got.depths[p],
            );
            inverse.project_point3(ndc).distance(eye)
        })
        .collect();
    let nearest = distances.iter().copied().fold(f32::MAX, f32::min);
    let spread = distances.iter().copied().fold(f32::MIN, f32::max) - nearest;
    say(&format!(
        "distances from the eye: nearest {nearest:.3}, spread {spread:.3} (|eye| {:.3})",
        eye.length()
    ));
    assert!(
        nearest < eye.length() - 0.8 && spread > 0.5,
        "the impostor's points lie {nearest} to {} from the eye: not the surface",
        nearest + spread
    );

    // Moved since the last frame (0.2 units along +x): each pixel's motion is where its
    // surface point (from the depth it wrote) was, 0.2 units back, minus where it is, on the
    // screen; rg16float's step is 6e-5 at the 0.06 to 0.085 the pixels move: 2e-4 is three
    // steps.
    let step = Vec3::new(0.2, 0.0, 0.0);
    let moved = ImpostorInstance::from_draw(Mat4::from_translation(step), Mat4::IDENTITY, &draw);
    draw_lod(gpu, (&lod_pass, &textures), &buffers, (1, &screen), moved);
    let got = read_lod_image(gpu, &buffers, 1).unwrap();
    let uv = |w: Vec3| {
        let c = view_proj.project_point3(w);
        Vec2::new(c.x * 0.5, -c.y * 0.5)
    };
    let (mut worst, mut largest, mut moving) = (0.0f32, 0.0f32, 0);
    for p in (0..got.ids.len()).filter(|&p| got.ids[p] != 0) {
        let point = inverse.project_point3(ndc(p, got.depths[p]));
        let want = uv(point - step) - uv(point);
        worst = worst.max((got.motion[p] - want).length());
        largest = largest.max(want.length());
        moving += 1;
    }
    say(&format!(
        "moved: {moving} px, motion up to {largest:.4}, worst difference {worst:.6}"
    ));
    assert!(
        moving > 2000 && worst < 2e-4,
        "object motion off by {worst} (of up to {largest})"
    );

    // A still object under a camera that moved since the last frame: no object motion (the
    // camera's is the combine's reprojection), and the pattern read next frame where the
    // previous camera saw the point (visibility_next_coord on the point its depth names; a
    // next coordinate within 1e-3 pixel of a texel edge may fall either side: skipped).
    let before =
        glam::camera::rh::view::look_at_mat4(eye + Vec3::new(0.3, 0.1, 0.0), Vec3::ZERO, Vec3::Y);
    let prev_view_proj = glam::camera::rh::proj::directx::perspective(0.7, 1.0, 0.1, 20.0) * before;
    let turned = ImpostorLodView {
        prev_view_proj,
        ..screen
    };
    draw_lod(
        gpu,
        (&lod_pass, &textures),
        &buffers,
        (1, &turned),
        t_instance,
    );
    let got = read_lod_image(gpu, &buffers, 1).unwrap();
    let (mut checked, mut edge) = (0, 0);
    for p in (0..got.ids.len()).filter(|&p| got.ids[p] != 0) {
        assert_eq!(
            got.motion[p],
            Vec2::ZERO,
            "pixel {p}: a still object moved with the camera"
        );
        let point = inverse.project_point3(ndc(p, got.depths[p]));
        let at = Vec2::new(
            (p as u32 % SIZE) as f32 + 0.5,
            (p as u32 / SIZE) as f32 + 0.5,
        );
        let then_clip = prev_view_proj * point.extend(1.0);
        let next =
            lodkit::visibility::visibility_next_coord(at, then_clip, Vec2::splat(SIZE as f32));
        let off_edge = (next - next.floor() - Vec2::splat(0.5)).abs().max_element() < 0.499;
        if !off_edge {
            edge += 1;
            continue;
        }
        checked += 1;
        let flags = visibility_flags_screen(&vis, at, next, draw.tau, draw.tau_next);
        assert_eq!(
            got.flags[p], flags,
            "pixel {p}: flags with the next frame's coordinate {next}"
        );
    }
    say(&format!(
        "camera moved: {checked} px' flags checked, {edge} within 1e-3 px of a texel edge"
    ));
    assert!(
        checked > 2000 && edge * 50 < checked,
        "{checked} checked, {edge} on an edge"
    );

    // Anchored to the object, the pattern moves with the surface: at the same threshold it
    // shows other pixels than on the screen, still about tau of them.
    let object = ImpostorLodView {
        space: VisibilitySpace::Object,
        vis_scale: 4.0,
        ..screen
    };
    draw_lod(
        gpu,
        (&lod_pass, &textures),
        &buffers,
        (0, &object),
        t_instance,
    );
    let anchored = read_lod_image(gpu, &buffers, 0).unwrap();
    let now = |p: usize| anchored.flags[p] & 1 != 0;
    let on_screen = |p: usize| {
        let at = Vec2::new(
            (p as u32 % SIZE) as f32 + 0.5,
            (p as u32 / SIZE) as f32 + 0.5,
        );
        visibility_flags_screen(&vis, at, at, draw.tau, draw.tau_next) & 1 != 0
    };
    let differ = (0..anchored.ids.len())
        .filter(|&p| anchored.ids[p] != 0 && now(p) != on_screen(p))
        .count();
    assert!(
        differ * 5 > covered,
        "anchored to the object, only {differ} of {covered} pixels differ from the screen's pattern"
    );
    let shown = (0..anchored.ids.len())
        .filter(|&p| anchored.ids[p] != 0 && now(p))
        .count();
    let share = shown as f32 / covered as f32;
    say(&format!(
        "object space: {shown} of {covered} shown at tau {}",
        draw.tau
    ));
    assert!(
        (share - draw.tau).abs() < 0.1,
        "object space shows {share} of the pixels at tau {}",
        draw.tau
    );
    // An n-instance: shown in both frames, id 0.
    draw_lod(
        gpu,
        (&lod_pass, &textures),
        &buffers,
        (0, &screen),
        whole[0],
    );
    let n = read_lod_image(gpu, &buffers, 0).unwrap();
    let drawn: Vec<usize> = (0..n.ids.len()).filter(|&p| n.depths[p] < 1.0).collect();
    assert_eq!(
        drawn.len(),
        covered,
        "an n-instance covers what the t-instance covers"
    );
    assert!(
        drawn.iter().all(|&p| n.ids[p] == 0 && n.flags[p] == 3),
        "an n-instance is shown in both frames"
    );
}

/// Transition frames of the hand-over test.
const FRAMES: usize = 12;

/// Whether an RGBA8 pixel shows the black background.
fn background(p: &[u8]) -> bool {
    p[..3].iter().all(|&c| c < 8)
}

#[test]
fn a_mesh_handed_over_to_its_impostor_frame_by_frame_shows_no_background() {
    use lodkit::combine_coverage::{CombineData, DepthPassFrame, OlderDepth};
    let gpu = lodkit_test_gpu!();
    let mesh = lumpy();
    let textures = bake(gpu, &mesh);
    let gpu_mesh = GpuMesh::new(gpu, &mesh).unwrap();
    let (view_proj, eye) = camera();
    let vis = visibility_texture(VisibilityPattern::BlueNoise, 64, 1);
    let renderer = LodBufferRenderer::new(gpu, FORMAT, &vis, 1.0).unwrap();
    let lod_pass = pass(gpu, ImpostorTarget::LodBuffer { motion: true });
    let depth_pass = pass(gpu, ImpostorTarget::LevelDepth);
    let buffers = LodBuffers::new(gpu, SIZE, SIZE, FORMAT).unwrap();
    let descriptor = CombinePassDescriptor {
        target_format: FORMAT,
        ..Default::default()
    };
    let combine = CombinePass::new(gpu, &descriptor).unwrap();
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let target = texture_2d(gpu, (SIZE, SIZE), FORMAT, usage, "combined").unwrap();
    let lod_view = ImpostorLodView {
        prev_view_proj: view_proj,
        size: (SIZE, SIZE),
        visibility: renderer.visibility_view(),
        space: VisibilitySpace::Screen,
        vis_scale: 1.0,
    };
    let grey = Vec4::new(0.8, 0.6, 0.5, 1.0);
    let mesh_item =
        |draw: &FrameDraw| LodDrawItem::from_draw(&gpu_mesh, Mat4::IDENTITY, grey, draw);
    let view = LodView::from(view_proj);

    // Each level alone (n-instances): where it covers the screen.
    let whole = FrameDraw {
        lod: 0,
        id: 0,
        tau: 1.0,
        tau_next: 1.0,
        progress: 0.0,
        incoming: false,
    };
    fn frame<'a>(index: usize, view: LodView, items: &'a [LodDrawItem<'a>]) -> LodBufferFrame<'a> {
        LodBufferFrame {
            index,
            view,
            items,
            clear: BLACK,
            ..Default::default()
        }
    }
    renderer
        .render(gpu, &buffers, &frame(0, view, &[mesh_item(&whole)]))
        .unwrap();
    let mesh_alone = read_lod_image(gpu, &buffers, 0).unwrap();
    draw_lod(
        gpu,
        (&lod_pass, &textures),
        &buffers,
        (0, &lod_view),
        ImpostorInstance::new(Mat4::IDENTITY),
    );
    let impostor_alone = read_lod_image(gpu, &buffers, 0).unwrap();
    let covers = |image: &lodkit::combine::LodImage, p: usize| image.depths[p] < 1.0;
    let n = (SIZE * SIZE) as usize;
    let both: Vec<usize> = (0..n)
        .filter(|&p| covers(&mesh_alone, p) && covers(&impostor_alone, p))
        .collect();
    let neither: Vec<usize> = (0..n)
        .filter(|&p| !covers(&mesh_alone, p) && !covers(&impostor_alone, p))
        .collect();
    assert!(both.len() > 2000, "the levels share only {} px", both.len());

    let mut scheduler = TransitionScheduler::new();
    let key = scheduler.insert(0);
    let (mut see_through, mut ghosts) = (0, 0);
    let mut middle_mix = (0, 0);
    for f in 0..FRAMES + 5 {
        if f > 0 {
            scheduler.advance(1.0 / 30.0);
        }
        let progress = |f: usize| ((f as f32 - 2.0) / FRAMES as f32).clamp(0.0, 1.0);
        if f == 2 {
            scheduler.begin_transition(key, 1, Drive::Progress).unwrap();
        }
        if f >= 2 {
            scheduler.set_progress(key, progress(f)).unwrap();
            scheduler.set_next_progress(key, progress(f + 1)).unwrap();
        }
        let draw = scheduler.draw(key).unwrap();
        let index = scheduler.buffer_index();
        match draw.lod {
            0 => {
                renderer
                    .render(gpu, &buffers, &frame(index, view, &[mesh_item(&draw)]))
                    .unwrap();
            }
            _ => {
                let instance = ImpostorInstance::from_draw(Mat4::IDENTITY, Mat4::IDENTITY, &draw);
                draw_lod(
                    gpu,
                    (&lod_pass, &textures),
                    &buffers,
                    (index, &lod_view),
                    instance,
                );
            }
        }
        // The older-level depth pass: the level the older buffer holds, whole, depth only.
        let older = scheduler.older(key).unwrap();
        let objects: Vec<OlderDepth> = older
            .iter()
            .map(|o| OlderDepth {
                older_tau: Some(o.tau),
                ..OlderDepth::from(*o)
            })
            .collect();
        match older.map(|o| o.lod) {
            Some(0) => {
                let item = LodDrawItem {
                    id: older.unwrap().id,
                    ..mesh_item(&draw)
                };
                renderer
                    .render_level_depth(
                        gpu,
                        &buffers,
                        &LodBufferFrame {
                            view,
                            items: &[item],
                            ..Default::default()
                        },
                    )
                    .unwrap();
            }
            Some(_) => {
                let v = impostor_view(view_proj, eye);
                let whole = [ImpostorInstance::new(Mat4::IDENTITY)];
                let prepared = depth_pass.prepare(gpu, &textures, &v, &whole).unwrap();
                let mut encoder = gpu.device.create_command_encoder(&Default::default());
                {
                    let mut render = buffers.begin_level_depth_pass(&mut encoder, 1.0, None);
                    depth_pass.draw(&mut render, &prepared);
                }
                gpu.queue.submit([encoder.finish()]);
            }
            None => {}
        }
        let new_to_old = match f {
            0 => CombinePass::NO_HISTORY,
            _ => view_proj * view_proj.inverse(),
        };
        let data = CombineData::depth_pass(&DepthPassFrame {
            new_to_old,
            objects: &objects,
            ..Default::default()
        })
        .unwrap();
        let target_view = target.create_view(&Default::default());
        let recording = CombineFrame {
            buffers: &buffers,
            newer: index,
            new_to_old,
            target: &target_view,
            regions: CombineRegions::Everywhere,
            coverage: CombineCoverage::Known {
                data: &data,
                level_depth: Some(buffers.level_depth()),
                pattern: Some(renderer.visibility_view()),
            },
        };
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        combine.record(gpu, &mut encoder, &recording).unwrap();
        gpu.queue.submit([encoder.finish()]);
        let got = read_texture_rgba8(gpu, &target).unwrap();
        let pixel = |p: usize| &got[4 * p..4 * p + 4];
        see_through += both.iter().filter(|&&p| background(pixel(p))).count();
        ghosts += neither.iter().filter(|&&p| !background(pixel(p))).count();
        if f == 2 + FRAMES / 2 {
            // Halfway: both levels on the screen, each on about half the shared pixels.
            let like = |image: &lodkit::combine::LodImage, p: usize| {
                (0..3).all(|c| (f32::from(pixel(p)[c]) - image.colors[p][c] * 255.0).abs() <= 2.0)
            };
            let mesh = both.iter().filter(|&&p| like(&mesh_alone, p)).count();
            let impostor = both.iter().filter(|&&p| like(&impostor_alone, p)).count();
            middle_mix = (mesh, impostor);
        }
        if f == FRAMES + 4 {
            assert_eq!(draw.lod, 1, "the impostor is shown at the end");
        }
    }
    say(&format!(
        "mesh -> impostor over {FRAMES} frames: {} px shared; see-through {see_through}, ghosts {ghosts} pixel-frames; halfway {} px as the mesh, {} as the impostor",
        both.len(),
        middle_mix.0,
        middle_mix.1
    ));
    let share = |k: usize| k as f32 / both.len() as f32;
    assert!(
        share(middle_mix.0) > 0.3 && share(middle_mix.1) > 0.3,
        "halfway the shared pixels show {:.2} mesh and {:.2} impostor: not a transition",
        share(middle_mix.0),
        share(middle_mix.1)
    );
    assert_eq!(
        (see_through, ghosts),
        (0, 0),
        "see-through and ghost pixel-frames"
    );
}
