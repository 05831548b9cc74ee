//! Two rendered frames of a small scene through the real LOD buffers and combine pass, compared
//! pixel by pixel with the combine rule applied on the CPU to the read-back LOD buffers.

use glam::{Mat4, Vec3, Vec4};
use lodkit::combine::{DepthConvention, PixelSource, combine_images};
use lodkit::frame_sequential::{Drive, TransitionScheduler};
use lodkit::gpu::frame_sequential::{
    CombineCoverage, CombineFrame, CombinePass, CombinePassDescriptor, CombineRegions, LodBuffers,
    read_lod_image,
};
use lodkit::gpu::readback::read_texture_rgba8;
use lodkit::reproject::new_to_old_matrix;
use lodkit::visibility::{VisibilityPattern, visibility_texture};
use lodkit_scenes::lod_buffer::{LodBufferFrame, LodBufferRenderer, LodDrawItem, LodView};
use lodkit_scenes::mesh::{GpuMesh, Mesh};

use crate::harness::say;

const W: u32 = 96;
const H: u32 = 80;

#[test]
fn combine_pass_matches_the_cpu_rule_on_two_rendered_frames() {
    let proj = glam::camera::rh::proj::directx::perspective(0.9, W as f32 / H as f32, 0.1, 50.0);
    combine_matches_the_cpu_rule(DepthConvention::Standard, proj);
}

#[test]
fn reversed_z_with_an_infinite_far_plane_runs_end_to_end() {
    // Depth 1 at the near plane, 0 at infinity: the LOD pass tests Greater and clears to 0, the
    // combine pass is built with LODKIT_REVERSE_Z, and the CPU rule uses the same convention.
    let proj = glam::camera::rh::proj::directx::perspective_infinite_reverse(
        0.9,
        W as f32 / H as f32,
        0.1,
    );
    combine_matches_the_cpu_rule(DepthConvention::Reversed, proj);
}

/// Two frames of a t-instance and an n-instance through the LOD pass and the combine pass in
/// depth convention `depth` with projection `proj`, held pixel by pixel against the CPU rule.
fn combine_matches_the_cpu_rule(depth: DepthConvention, proj: Mat4) {
    let gpu = lodkit_test_gpu!();
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let vis = visibility_texture(VisibilityPattern::WhiteNoise, 64, 1);
    let renderer = LodBufferRenderer::with_depth(gpu, format, &vis, 0.25, depth).unwrap();
    let buffers = LodBuffers::new(gpu, W, H, format).unwrap();
    let descriptor = CombinePassDescriptor {
        target_format: format,
        depth,
    };
    let combine = CombinePass::new(gpu, &descriptor).unwrap();
    let sphere = GpuMesh::new(gpu, &Mesh::sphere(16, 24)).unwrap();
    let cube = GpuMesh::new(gpu, &Mesh::cube()).unwrap();

    let mut scheduler = TransitionScheduler::new();
    let t_instance = scheduler.insert(0);
    let n_instance = scheduler.insert(1);
    scheduler
        .begin_transition(t_instance, 1, Drive::Progress)
        .unwrap();
    scheduler.set_progress(t_instance, 0.35).unwrap();

    let views = [
        glam::camera::rh::view::look_at_mat4(Vec3::new(0.0, 0.5, 5.0), Vec3::ZERO, Vec3::Y),
        glam::camera::rh::view::look_at_mat4(
            Vec3::new(0.35, 0.6, 4.9),
            Vec3::new(0.6, 0.0, 0.0),
            Vec3::Y,
        ),
    ];
    let lods = [
        (&sphere, Vec4::new(1.0, 0.1, 0.1, 1.0)),
        (&cube, Vec4::new(0.1, 0.2, 1.0, 1.0)),
    ];
    for (frame, view) in views.iter().enumerate() {
        if frame > 0 {
            scheduler.advance(1.0 / 60.0);
        }
        let t = scheduler.draw(t_instance).unwrap();
        let n = scheduler.draw(n_instance).unwrap();
        assert_eq!(t.incoming, frame == 1, "odd frames draw the incoming LOD");
        let (mesh, color) = lods[t.lod as usize];
        let items = [
            LodDrawItem::from_draw(mesh, Mat4::from_scale(Vec3::splat(0.9)), color, &t),
            LodDrawItem::from_draw(
                lods[n.lod as usize].0,
                Mat4::from_translation(Vec3::new(0.4, -0.2, -2.5))
                    * Mat4::from_scale(Vec3::new(2.0, 1.2, 0.3)),
                Vec4::new(0.2, 0.9, 0.2, 1.0),
                &n,
            ),
        ];
        renderer
            .render(
                gpu,
                &buffers,
                &LodBufferFrame {
                    index: scheduler.buffer_index(),
                    view: (proj * *view).into(),
                    items: &items,
                    clear: wgpu::Color {
                        r: 0.05,
                        g: 0.05,
                        b: 0.1,
                        a: 1.0,
                    },
                    ..Default::default()
                },
            )
            .unwrap();
    }
    let newer = scheduler.buffer_index();
    let m = new_to_old_matrix(&views[1], &proj, &views[0], &proj);
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let target =
        lodkit::gpu::resources::texture_2d(gpu, (W, H), format, usage, "combined").unwrap();
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let target_view = target.create_view(&Default::default());
    combine
        .record(
            gpu,
            &mut encoder,
            &everywhere(&buffers, newer, m, &target_view),
        )
        .unwrap();
    gpu.queue.submit([encoder.finish()]);

    let got = read_texture_rgba8(gpu, &target).unwrap();
    let newer_image = read_lod_image(gpu, &buffers, newer).unwrap();
    let older_image = read_lod_image(gpu, &buffers, 1 - newer).unwrap();
    let want = combine_images(&newer_image, &older_image, &m, depth);
    let (mut compared, mut ambiguous) = (0, 0);
    let count = |s: PixelSource| want.iter().filter(|p| p.source == s).count();
    let (averaged, older_won, outside) = (
        count(PixelSource::Average),
        count(PixelSource::Older),
        count(PixelSource::OutsideOlder),
    );
    for (p, w) in want.iter().enumerate() {
        if w.on_texel_edge {
            ambiguous += 1;
            continue;
        }
        compared += 1;
        for c in 0..4 {
            let wc = (w.color[c] * 255.0).round() as i32;
            let g = i32::from(got[p * 4 + c]);
            assert!(
                (wc - g).abs() <= 1,
                "pixel ({}, {}) channel {c}: GPU {g} vs CPU {wc}",
                p as u32 % W,
                p as u32 / W
            );
        }
    }
    say(&format!(
        "combine vs CPU: {compared} pixels equal, {ambiguous} on a texel edge skipped; {averaged} averaged (same t-instance), {older_won} taken from the older buffer, {outside} outside the older view"
    ));
    assert!(
        ambiguous * 100 < compared,
        "too many ambiguous pixels: {ambiguous}"
    );
    assert!(
        averaged > 0 && older_won > 0 && outside > 0,
        "the scene must exercise every case"
    );
}

#[test]
fn resizing_lod_buffers_does_not_leak_textures() {
    let _shared = lodkit_test_gpu!();
    // A device of its own: other tests allocate textures on the shared one concurrently.
    let gpu = &lodkit::gpu::GpuContext::new_headless(&Default::default()).unwrap();
    let count = || {
        gpu.instance
            .generate_report()
            .map(|r| r.hub_report().textures.num_kept_from_user)
    };
    let mut buffers = LodBuffers::new(gpu, 32, 32, wgpu::TextureFormat::Rgba8Unorm).unwrap();
    gpu.wait_idle().unwrap();
    let before = count();
    for i in 0..40 {
        buffers.resize(gpu, 32 + i, 24 + 2 * i).unwrap();
    }
    gpu.wait_idle().unwrap();
    assert_eq!(buffers.size(), (71, 102));
    match (before, count()) {
        (Some(b), Some(a)) => assert_eq!(a, b, "textures alive before and after 40 resizes"),
        _ => say("this wgpu build gives no resource report; only the final size was checked"),
    }
    // Without the motion target: two colors, two ids, two depths and the older-level depth
    // pass's, and so after a resize.
    let mut still = LodBuffers::without_motion(gpu, 32, 32, wgpu::TextureFormat::Rgba8Unorm);
    let still = still.as_mut().unwrap();
    still.resize(gpu, 40, 30).unwrap();
    gpu.wait_idle().unwrap();
    assert!(still.motion().is_none() && buffers.motion().is_some());
    if let (Some(b), Some(a)) = (before, count()) {
        assert_eq!(a, b + 7, "LodBuffers::without_motion keeps 7 textures");
    }
}

#[test]
fn lod_buffers_without_motion_combine_a_moving_camera_like_with_it() {
    let gpu = lodkit_test_gpu!();
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let vis = visibility_texture(VisibilityPattern::BlueNoise, 64, 3);
    let renderer = LodBufferRenderer::new(gpu, format, &vis, 0.5).unwrap();
    let combine = CombinePass::new(gpu, &combine_descriptor(format)).unwrap();
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let target = lodkit::gpu::resources::texture_2d(gpu, (W, H), format, usage, "t").unwrap();
    let view_of = target.create_view(&Default::default());
    let meshes = [
        GpuMesh::new(gpu, &Mesh::sphere(16, 24)).unwrap(),
        GpuMesh::new(gpu, &Mesh::cube()).unwrap(),
    ];
    let proj = glam::camera::rh::proj::directx::perspective(0.9, W as f32 / H as f32, 0.1, 50.0);
    let eye =
        |x: f32| glam::camera::rh::view::look_at_mat4(Vec3::new(x, 0.5, 5.0), Vec3::ZERO, Vec3::Y);
    // Two frames of a t-instance (its two LODs) and an n-instance; only the camera moves.
    let frame = |buffers: &LodBuffers| -> Vec<u8> {
        for (i, x) in [0.0f32, 0.3].into_iter().enumerate() {
            let items: Vec<LodDrawItem> = [(0.0f32, 7), (1.5, 0)]
                .into_iter()
                .map(|(dx, id)| {
                    let model = Mat4::from_translation(Vec3::new(dx, 0.0, 0.0));
                    LodDrawItem {
                        mesh: &meshes[i],
                        model,
                        color: Vec4::new(0.9, 0.3, 0.2, 1.0),
                        id,
                        tau: 0.5,
                        tau_next: 0.6,
                        sway: [0.0; 2],
                        prev_model: model,
                        prev_sway_phase: 0.0,
                        alpha_rect: Vec4::ZERO,
                    }
                })
                .collect();
            let view = LodView {
                view_proj: proj * eye(x),
                prev_view_proj: proj * eye(0.0),
            };
            let clear = wgpu::Color::BLACK;
            renderer
                .render(
                    gpu,
                    buffers,
                    &LodBufferFrame {
                        index: i,
                        view,
                        items: &items,
                        clear,
                        ..Default::default()
                    },
                )
                .unwrap();
        }
        let m = new_to_old_matrix(&eye(0.3), &proj, &eye(0.0), &proj);
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        combine
            .record(gpu, &mut encoder, &everywhere(buffers, 1, m, &view_of))
            .unwrap();
        gpu.queue.submit([encoder.finish()]);
        read_texture_rgba8(gpu, &target).unwrap()
    };
    let with = frame(&LodBuffers::new(gpu, W, H, format).unwrap());
    let without = frame(&LodBuffers::without_motion(gpu, W, H, format).unwrap());
    let lit = with.chunks(4).filter(|p| p[..3] != [0, 0, 0]).count();
    assert!(lit > 1000, "the objects cover {lit} pixels");
    assert_eq!(
        with, without,
        "nothing moved by itself: the motion target changes nothing"
    );
    say(&format!(
        "{lit} lit pixels, identical with and without the motion target"
    ));
}

/// Coverage of the object (pixels not of the clear color) in an RGBA8 image.
fn coverage(pixels: &[u8], clear: [u8; 3]) -> usize {
    pixels
        .chunks(4)
        .filter(|p| p[..3].iter().zip(clear).any(|(a, b)| a.abs_diff(b) > 3))
        .count()
}

#[test]
fn a_transition_may_begin_on_any_frame_without_the_object_dropping_out() {
    let gpu = lodkit_test_gpu!();
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let vis = visibility_texture(VisibilityPattern::WhiteNoise, 64, 1);
    let renderer = LodBufferRenderer::new(gpu, format, &vis, 0.25).unwrap();
    let combine = CombinePass::new(gpu, &combine_descriptor(format)).unwrap();
    let lods = [
        GpuMesh::new(gpu, &Mesh::sphere(16, 24)).unwrap(),
        GpuMesh::new(gpu, &Mesh::cube()).unwrap(),
    ];
    let colors = [Vec4::new(1.0, 0.1, 0.1, 1.0), Vec4::new(0.1, 0.2, 1.0, 1.0)];
    let clear = wgpu::Color {
        r: 0.0,
        g: 0.0,
        b: 0.0,
        a: 1.0,
    };
    let proj = glam::camera::rh::proj::directx::perspective(0.9, W as f32 / H as f32, 0.1, 50.0);
    let view = glam::camera::rh::view::look_at_mat4(Vec3::new(0.0, 0.5, 5.0), Vec3::ZERO, Vec3::Y);
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let target =
        lodkit::gpu::resources::texture_2d(gpu, (W, H), format, usage, "combined").unwrap();
    let target_view = target.create_view(&Default::default());
    // Renders one frame of `scheduler`'s instance and returns the combined image's coverage.
    let frame = |buffers: &LodBuffers, scheduler: &TransitionScheduler, key, first: bool| {
        let d = scheduler.draw(key).unwrap();
        let lod = usize::from(d.lod);
        let item = LodDrawItem::from_draw(&lods[lod], Mat4::from_rotation_y(0.5), colors[lod], &d);
        let index = scheduler.buffer_index();
        let vp = proj * view;
        renderer
            .render(
                gpu,
                buffers,
                &LodBufferFrame {
                    index,
                    view: vp.into(),
                    items: &[item],
                    clear,
                    ..Default::default()
                },
            )
            .unwrap();
        let m = if first {
            CombinePass::NO_HISTORY
        } else {
            new_to_old_matrix(&view, &proj, &view, &proj)
        };
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        combine
            .record(
                gpu,
                &mut encoder,
                &everywhere(buffers, index, m, &target_view),
            )
            .unwrap();
        gpu.queue.submit([encoder.finish()]);
        coverage(&read_texture_rgba8(gpu, &target).unwrap(), [0, 0, 0])
    };
    // Each LOD alone, as an n-instance.
    let alone = [0u8, 1].map(|lod| {
        let buffers = LodBuffers::new(gpu, W, H, format).unwrap();
        let mut s = TransitionScheduler::new();
        let key = s.insert(lod);
        frame(&buffers, &s, key, true)
    });
    let floor = alone[0].min(alone[1]);
    assert!(floor > 300, "the object covers {alone:?} pixels");
    let mut rows = Vec::new();
    for start in [1u64, 2, 3, 4, 5] {
        let buffers = LodBuffers::new(gpu, W, H, format).unwrap();
        let mut s = TransitionScheduler::new();
        let key = s.insert(0);
        let mut seen = Vec::new();
        for f in 0..start + 10 {
            if f > 0 {
                s.advance(1.0 / 60.0);
            }
            if f == start {
                s.begin_transition(key, 1, Drive::Progress).unwrap();
            }
            if f >= start {
                s.set_progress(key, ((f - start) as f32 / 6.0).min(1.0))
                    .unwrap();
            }
            let covered = frame(&buffers, &s, key, f == 0);
            assert!(
                covered >= floor,
                "transition begun on frame {start} (parity {}): frame {f} covers {covered} \
                 pixels, below both LODs alone ({alone:?})",
                start % 2
            );
            seen.push(covered);
        }
        rows.push(format!("start {start}: {seen:?}"));
    }
    say(&format!(
        "object coverage per frame (LODs alone: {alone:?}):\n{}",
        rows.join("\n")
    ));
}

#[test]
fn a_lod_whose_tau_is_zero_is_not_submitted() {
    let gpu = lodkit_test_gpu!();
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let vis = visibility_texture(VisibilityPattern::WhiteNoise, 64, 1);
    let renderer = LodBufferRenderer::new(gpu, format, &vis, 0.25).unwrap();
    let buffers = LodBuffers::new(gpu, W, H, format).unwrap();
    let sphere = GpuMesh::new(gpu, &Mesh::sphere(16, 24)).unwrap();
    let cube = GpuMesh::new(gpu, &Mesh::cube()).unwrap();
    let proj = glam::camera::rh::proj::directx::perspective(0.9, W as f32 / H as f32, 0.1, 50.0);
    let view = glam::camera::rh::view::look_at_mat4(Vec3::new(0.0, 0.5, 5.0), Vec3::ZERO, Vec3::Y);
    let item = |mesh, tau| LodDrawItem {
        mesh,
        model: Mat4::IDENTITY,
        color: Vec4::ONE,
        id: 7,
        tau,
        tau_next: tau,
        sway: [0.0; 2],
        prev_model: Mat4::IDENTITY,
        prev_sway_phase: 0.0,
        alpha_rect: Vec4::ZERO,
    };
    let render = |items: &[LodDrawItem]| {
        let (triangles, _) = renderer
            .render(
                gpu,
                &buffers,
                &LodBufferFrame {
                    view: (proj * view).into(),
                    items,
                    ..Default::default()
                },
            )
            .unwrap();
        (triangles, read_lod_image(gpu, &buffers, 0).unwrap())
    };
    let (alone, image) = render(&[item(&sphere, 1.0)]);
    for tau in [0.0, -0.0, f32::NAN] {
        let (both, with_cube) = render(&[item(&sphere, 1.0), item(&cube, tau)]);
        assert_eq!(
            both, alone,
            "tau {tau}: only the sphere's triangles are submitted"
        );
        assert_eq!(
            with_cube.ids, image.ids,
            "tau {tau}: and the buffer is the same"
        );
    }
    let (both, _) = render(&[item(&sphere, 1.0), item(&cube, 0.01)]);
    assert_eq!(both, alone + 12, "a cube at tau 0.01 is drawn");
}

#[test]
fn the_combine_over_the_t_instances_rectangles_equals_the_full_combine() {
    use lodkit::combine::screen_rect;
    let gpu = lodkit_test_gpu!();
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let vis = visibility_texture(VisibilityPattern::BlueNoise, 64, 3);
    let renderer = LodBufferRenderer::new(gpu, format, &vis, 0.5).unwrap();
    let buffers = LodBuffers::new(gpu, W, H, format).unwrap();
    let combine = CombinePass::new(gpu, &combine_descriptor(format)).unwrap();
    let sphere_mesh = Mesh::sphere(16, 24);
    let bounds = sphere_mesh.bounds().unwrap();
    let sphere = GpuMesh::new(gpu, &sphere_mesh).unwrap();
    let proj = glam::camera::rh::proj::directx::perspective(0.9, W as f32 / H as f32, 0.1, 50.0);
    let eye =
        |x: f32| glam::camera::rh::view::look_at_mat4(Vec3::new(x, 0.5, 6.0), Vec3::ZERO, Vec3::Y);
    let views = [eye(0.0), eye(0.2)];
    // Three spheres: the left one in transition, the others n-instances.
    let mut s = TransitionScheduler::new();
    let keys: Vec<_> = (0..3).map(|_| s.insert(0)).collect();
    s.begin_transition(keys[0], 1, Drive::Progress).unwrap();
    let model = |i: usize| {
        Mat4::from_translation(Vec3::new(i as f32 * 1.8 - 1.8, 0.0, 0.0))
            * Mat4::from_scale(Vec3::splat(0.7))
    };
    let colors = [Vec4::new(1.0, 0.2, 0.1, 1.0), Vec4::new(0.1, 0.3, 1.0, 1.0)];
    for (frame, view) in views.iter().enumerate() {
        if frame > 0 {
            s.advance(1.0 / 60.0);
        }
        s.set_progress(keys[0], 0.3 + 0.1 * frame as f32).unwrap();
        let items: Vec<LodDrawItem> = keys
            .iter()
            .enumerate()
            .map(|(i, k)| {
                let d = s.draw(*k).unwrap();
                LodDrawItem::from_draw(&sphere, model(i), colors[usize::from(d.lod)], &d)
            })
            .collect();
        let clear = wgpu::Color::BLACK;
        renderer
            .render(
                gpu,
                &buffers,
                &LodBufferFrame {
                    index: s.buffer_index(),
                    view: (proj * *view).into(),
                    items: &items,
                    clear,
                    ..Default::default()
                },
            )
            .unwrap();
    }
    let m = new_to_old_matrix(&views[1], &proj, &views[0], &proj);
    let rect = screen_rect(
        bounds,
        model(0),
        &[proj * views[1], proj * views[0]],
        (W, H),
        2,
    )
    .unwrap();
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT
        | wgpu::TextureUsages::COPY_SRC
        | wgpu::TextureUsages::COPY_DST;
    let texture =
        |label| lodkit::gpu::resources::texture_2d(gpu, (W, H), format, usage, label).unwrap();
    let (full, regions, none) = (texture("full"), texture("regions"), texture("none"));
    let newer = s.buffer_index();
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let view = |t: &wgpu::Texture| t.create_view(&Default::default());
    combine
        .record(
            gpu,
            &mut encoder,
            &everywhere(&buffers, newer, m, &view(&full)),
        )
        .unwrap();
    gpu.queue.submit([encoder.finish()]);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let combined = combine
        .record(
            gpu,
            &mut encoder,
            &only(
                everywhere(&buffers, newer, m, &view(&regions)),
                &[rect, rect],
            ),
        )
        .unwrap();
    let skipped = combine
        .record(
            gpu,
            &mut encoder,
            &only(everywhere(&buffers, newer, m, &view(&none)), &[]),
        )
        .unwrap();
    gpu.queue.submit([encoder.finish()]);
    let read = |t: &wgpu::Texture| read_texture_rgba8(gpu, t).unwrap();
    assert_eq!(
        combined,
        rect.area(),
        "overlapping rectangles are combined once"
    );
    assert_eq!(skipped, 0);
    assert!(
        rect.area() * 3 < u64::from(W * H),
        "the rectangle {rect:?} is a small part"
    );
    assert_eq!(
        read(&regions),
        read(&full),
        "the rectangle holds every pixel the combine changes"
    );
    assert_eq!(
        read(&none),
        read(buffers.color(newer)),
        "no region: the newer buffer as it is"
    );
    assert_ne!(
        read(&full),
        read(buffers.color(newer)),
        "the combine does change the frame"
    );
    // A target the pass cannot copy into is refused, not a validation panic.
    let plain = lodkit::gpu::resources::texture_2d(
        gpu,
        (W, H),
        format,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
        "plain",
    )
    .unwrap();
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let err = combine
        .record(
            gpu,
            &mut encoder,
            &only(everywhere(&buffers, newer, m, &view(&plain)), &[rect]),
        )
        .unwrap_err();
    assert!(err.to_string().contains("COPY_DST"), "{err}");

    // Two recordings in one encoder with different matrices: each equals the same recording
    // made alone (each carries its own parameters; a shared uniform written on the queue would
    // give both the last matrix).
    let (alone, first, second) = (texture("alone"), texture("first"), texture("second"));
    let no_history = CombinePass::NO_HISTORY;
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let target = view(&alone);
    let frame = everywhere(&buffers, newer, no_history, &target);
    combine.record(gpu, &mut encoder, &frame).unwrap();
    gpu.queue.submit([encoder.finish()]);
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let target = view(&first);
    let frame = everywhere(&buffers, newer, no_history, &target);
    combine.record(gpu, &mut encoder, &frame).unwrap();
    combine
        .record(
            gpu,
            &mut encoder,
            &everywhere(&buffers, newer, m, &view(&second)),
        )
        .unwrap();
    gpu.queue.submit([encoder.finish()]);
    assert_ne!(
        read(&alone),
        read(&full),
        "the two matrices give two images"
    );
    assert_eq!(read(&first), read(&alone), "the first recording's matrix");
    assert_eq!(read(&second), read(&full), "the second recording's matrix");
}

/// The combine's descriptor for targets of `format`, standard depth.
fn combine_descriptor(format: wgpu::TextureFormat) -> CombinePassDescriptor {
    CombinePassDescriptor {
        target_format: format,
        ..Default::default()
    }
}

/// A recording of the combine over the whole target.
fn everywhere<'a>(
    buffers: &'a LodBuffers,
    newer: usize,
    new_to_old: Mat4,
    target: &'a wgpu::TextureView,
) -> CombineFrame<'a> {
    CombineFrame {
        buffers,
        newer,
        new_to_old,
        target,
        regions: CombineRegions::Everywhere,
        coverage: CombineCoverage::Estimated,
    }
}

/// `frame` inside `regions` only.
fn only<'a>(
    frame: CombineFrame<'a>,
    regions: &'a [lodkit::combine::ScreenRect],
) -> CombineFrame<'a> {
    CombineFrame {
        regions: CombineRegions::Only(regions),
        coverage: CombineCoverage::Estimated,
        ..frame
    }
}

#[test]
fn a_swaying_lod_moves_with_its_phase() {
    let gpu = lodkit_test_gpu!();
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let vis = visibility_texture(VisibilityPattern::BlueNoise, 64, 3);
    let renderer = LodBufferRenderer::new(gpu, format, &vis, 0.5).unwrap();
    let buffers = LodBuffers::new(gpu, W, H, format).unwrap();
    let sphere = GpuMesh::new(gpu, &Mesh::sphere(16, 24)).unwrap();
    let proj = glam::camera::rh::proj::directx::perspective(0.9, W as f32 / H as f32, 0.1, 50.0);
    let view = glam::camera::rh::view::look_at_mat4(Vec3::new(0.0, 0.5, 5.0), Vec3::ZERO, Vec3::Y);
    let render = |sway: [f32; 2]| {
        let item = LodDrawItem {
            mesh: &sphere,
            model: Mat4::IDENTITY,
            color: Vec4::ONE,
            id: 3,
            tau: 0.5,
            tau_next: 0.5,
            sway,
            prev_model: Mat4::IDENTITY,
            prev_sway_phase: sway[1],
            alpha_rect: Vec4::ZERO,
        };
        renderer
            .render(
                gpu,
                &buffers,
                &LodBufferFrame {
                    view: (proj * view).into(),
                    items: &[item],
                    ..Default::default()
                },
            )
            .unwrap();
        read_lod_image(gpu, &buffers, 0).unwrap()
    };
    let still = render([0.0, 0.0]);
    let (a, b) = (render([0.3, 1.0]), render([0.3, 2.5]));
    let covered = |i: &lodkit::combine::LodImage| i.ids.iter().filter(|&&id| id == 3).count();
    assert_eq!(
        render([0.0, 2.5]).ids,
        still.ids,
        "no amplitude: the phase changes nothing"
    );
    assert_ne!(a.ids, still.ids, "the sway moves the geometry");
    assert_ne!(a.ids, b.ids, "and follows its phase");
    assert!(covered(&a) > 0 && covered(&b) > 0);
}
