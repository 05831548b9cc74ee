//! An impostor baked from a tree with alpha-masked leaves and drawn by `passes/impostor.wgsl`,
//! held to the mesh drawn from the same camera: from directions between the atlas's frames (the
//! centroids of grid triangles, where a view is farthest from the frames it blends), at the
//! switch distance for a pixel error `p`, the two pictures' outlines stay within `p` pixels of
//! each other (`lodkit::metrics::coverage_distance`).

use glam::{Mat4, UVec2, Vec2, Vec3};
use lodkit::gpu::GpuContext;
use lodkit::gpu::impostor::{
    ImpostorBakeDescriptor, ImpostorBaker, ImpostorInstance, ImpostorMaterial, ImpostorMesh,
    ImpostorPart, ImpostorPass, ImpostorPassDescriptor, ImpostorTexture, ImpostorTextures,
    ImpostorView,
};
use lodkit::impostor::{
    ImpostorShape, impostor_decode, impostor_frame_dir, impostor_switch_distance,
};
use lodkit::lod_chain::PixelErrorCamera;
use lodkit::metrics::coverage_distance;
use lodkit_scenes::tree::LeafyTree;

/// Target side in pixels.
const SIZE: u32 = 256;
/// Vertical field of view.
const FOV: f32 = 30.0;
/// The pixel error the switch distance is derived for.
const PIXELS: f32 = 4.0;

/// Views between frames: the centroids of the grid triangles around these cells (lower and
/// upper triangle of each), from near the horizon to near the top, plus one view on a frame.
fn views(frames: u32) -> Vec<Vec3> {
    let at = |g: Vec2| impostor_decode(g * (2.0 / (frames - 1) as f32) - 1.0, true);
    let mut out = Vec::new();
    for cell in [
        UVec2::new(0, 3),
        UVec2::new(2, 1),
        UVec2::new(3, 3),
        UVec2::new(5, 2),
        UVec2::new(4, 6),
    ] {
        let c = cell.as_vec2();
        out.push(at(c + Vec2::splat(1.0 / 3.0)));
        out.push(at(c + Vec2::splat(2.0 / 3.0)));
    }
    out.push(impostor_frame_dir(UVec2::new(4, 8), frames, true));
    out
}

/// The camera at `distance` from `center` along `view`.
fn clip_from_world(center: Vec3, view: Vec3, distance: f32) -> Mat4 {
    let eye = center + view * distance;
    let up = if view.y.abs() > 0.95 {
        Vec3::Z
    } else {
        Vec3::Y
    };
    let v = glam::camera::rh::view::look_at_mat4(eye, center, up);
    let p = glam::camera::rh::proj::directx::perspective(
        FOV.to_radians(),
        1.0,
        distance * 0.05,
        distance * 3.0,
    );
    p * v
}

/// Pixels covered in an impostor drawn with `clip` from `eye`.
fn impostor_coverage(
    gpu: &GpuContext,
    pass: &ImpostorPass,
    textures: &ImpostorTextures,
    clip: Mat4,
    eye: Vec3,
) -> Vec<bool> {
    screen_door_coverage(gpu, pass, textures, clip, eye, 1.0)
}

/// Pixels covered in an impostor drawn with `clip` from `eye` at screen-door `alpha`.
fn screen_door_coverage(
    gpu: &GpuContext,
    pass: &ImpostorPass,
    textures: &ImpostorTextures,
    clip: Mat4,
    eye: Vec3,
    alpha: f32,
) -> Vec<bool> {
    let view = ImpostorView {
        view_proj: clip,
        eye,
        light: Vec3::new(0.3, 0.8, 0.5).normalize(),
        ambient: 0.4,
    };
    let instances = [ImpostorInstance {
        alpha,
        ..ImpostorInstance::new(Mat4::IDENTITY)
    }];
    pass.render(gpu, textures, &view, &instances, (SIZE, SIZE))
        .unwrap()
        .chunks(4)
        .map(|p| p[3] > 127)
        .collect()
}

/// The largest outline distance, in pixels, between mesh and impostor over `views` at
/// `distance` (object units from the centre), and the pixels the mesh covers in the first view.
fn worst_distance(
    gpu: &GpuContext,
    baker: &ImpostorBaker,
    pass: &ImpostorPass,
    textures: &ImpostorTextures,
    views: &[Vec3],
    distance: f32,
) -> (f32, usize) {
    let center = Vec3::from(textures.layout.center);
    let mut worst = 0.0f32;
    let mut covered = 0;
    for (k, view) in views.iter().enumerate() {
        let clip = clip_from_world(center, *view, distance);
        let mesh: Vec<bool> = baker
            .render(gpu, clip, SIZE, SIZE)
            .unwrap()
            .iter()
            .map(|t| t[3] > 0.5)
            .collect();
        if k == 0 {
            covered = mesh.iter().filter(|c| **c).count();
        }
        let imp = impostor_coverage(gpu, pass, textures, clip, center + *view * distance);
        let d = coverage_distance(&mesh, &imp, SIZE as usize).unwrap();
        crate::harness::say(&format!("  view {k} {view:?} at {distance:.2}: {d:.2} px"));
        worst = worst.max(d);
    }
    (worst, covered)
}

#[test]
fn impostor_stays_within_the_pixel_bound_between_frames() {
    let gpu = lodkit_test_gpu!();
    let tree = LeafyTree::new(40, 7);
    // The defaults: 12 x 12 frames of 128 texels, hemisphere.
    let descriptor = ImpostorBakeDescriptor::default();
    assert_eq!(descriptor.shape, ImpostorShape::Hemi);
    let baker = ImpostorBaker::new(gpu, &[tree.part()]).unwrap();
    let atlas = baker.bake(gpu, &descriptor).unwrap();
    let textures = ImpostorTextures::new(gpu, &atlas).unwrap();
    let pass = ImpostorPass::new(
        gpu,
        &ImpostorPassDescriptor {
            color_format: wgpu::TextureFormat::Rgba8Unorm,
            ..Default::default()
        },
    )
    .unwrap();
    let camera = PixelErrorCamera {
        fov_y: FOV.to_radians(),
        viewport_height: SIZE as f32,
        pixel_error: PIXELS,
        hysteresis: 0.0,
    };
    let normalized = impostor_switch_distance(&atlas.layout, &camera).unwrap();
    let distance = normalized * camera.p11() as f32;
    let views = views(descriptor.frames);
    let (at_switch, covered) = worst_distance(gpu, &baker, &pass, &textures, &views, distance);
    let (nearer, _) = worst_distance(gpu, &baker, &pass, &textures, &views, distance * 0.5);
    crate::harness::say(&format!(
        "switch distance {distance:.2} (radius {:.2}): worst {at_switch:.2} px, {covered} px covered; at half: {nearer:.2} px",
        atlas.layout.radius
    ));
    assert!(
        covered >= 100,
        "the tree covers only {covered} pixels: nothing to compare"
    );
    assert!(
        at_switch <= PIXELS,
        "at its switch distance the impostor's outline is {at_switch} px from the mesh's (bound {PIXELS})"
    );
    assert!(
        nearer > PIXELS,
        "at half the switch distance the outline is still within {PIXELS} px ({nearer}): the bound is loose"
    );
    // In a screen-door transition the impostor at alpha t and the other level at -(1 - t)
    // split the pixels: drawn against itself, the two halves are disjoint and make up the whole.
    let (view, near) = (views[3], distance * 0.25);
    let clip = clip_from_world(Vec3::from(textures.layout.center), view, near);
    let eye = Vec3::from(textures.layout.center) + view * near;
    let whole = impostor_coverage(gpu, &pass, &textures, clip, eye);
    for t in [0.0f32, 0.3, 0.5, 0.8] {
        let a = screen_door_coverage(gpu, &pass, &textures, clip, eye, t);
        let b = screen_door_coverage(gpu, &pass, &textures, clip, eye, -(1.0 - t));
        let both = (0..whole.len()).filter(|&i| a[i] && b[i]).count();
        let apart = (0..whole.len())
            .filter(|&i| (a[i] || b[i]) != whole[i])
            .count();
        assert_eq!(
            (both, apart),
            (0, 0),
            "t = {t}: pixels drawn twice, pixels not as the whole"
        );
        let share =
            a.iter().filter(|c| **c).count() as f32 / whole.iter().filter(|c| **c).count() as f32;
        // The 4x4 Bayer pattern keeps t of each 4x4 block to a sixteenth; over an object's
        // irregular outline the share strays a little further: 0.1.
        assert!(
            (share - t).abs() < 0.1,
            "t = {t}: the impostor keeps {share} of its pixels"
        );
    }
    // Depth, standard and reversed (an infinite reversed projection, tested `Greater` against
    // a depth cleared to 0): the near tree drawn first, a second one behind it and to the side;
    // wherever the near one covers a pixel it shows there, byte for byte as drawn alone.
    let reversed = ImpostorPass::new(
        gpu,
        &ImpostorPassDescriptor {
            color_format: wgpu::TextureFormat::Rgba8Unorm,
            depth: lodkit::combine::DepthConvention::Reversed,
            ..Default::default()
        },
    )
    .unwrap();
    let center = Vec3::from(textures.layout.center);
    let up = if view.y.abs() > 0.95 {
        Vec3::Z
    } else {
        Vec3::Y
    };
    let infinite = glam::camera::rh::proj::directx::perspective_infinite_reverse(
        FOV.to_radians(),
        1.0,
        near * 0.05,
    ) * glam::camera::rh::view::look_at_mat4(eye, center, up);
    let radius = textures.layout.radius;
    let side = view.cross(up).normalize();
    let behind = Mat4::from_translation((side * 0.6 - view * 3.0) * radius);
    let alone = [ImpostorInstance::new(Mat4::IDENTITY)];
    let both = [alone[0], ImpostorInstance::new(behind)];
    let standard_clip = clip;
    for (who, depth_pass, clip) in [("standard", &pass, clip), ("reversed", &reversed, infinite)] {
        let view = ImpostorView {
            view_proj: clip,
            eye,
            light: Vec3::new(0.3, 0.8, 0.5).normalize(),
            ambient: 0.4,
        };
        let one = depth_pass
            .render(gpu, &textures, &view, &alone, (SIZE, SIZE))
            .unwrap();
        let two = depth_pass
            .render(gpu, &textures, &view, &both, (SIZE, SIZE))
            .unwrap();
        let shown = |image: &[u8]| image.chunks(4).filter(|p| p[3] > 127).count();
        assert!(
            shown(&two) > shown(&one),
            "{who}: the tree behind shows nowhere"
        );
        let hidden = (0..one.len() / 4)
            .filter(|&i| one[4 * i + 3] > 127 && one[4 * i..4 * i + 4] != two[4 * i..4 * i + 4])
            .count();
        assert_eq!(hidden, 0, "{who}: the tree behind drew over the near one");
        if who == "reversed" {
            let standard_view = ImpostorView {
                view_proj: standard_clip,
                ..view
            };
            let standard = pass
                .render(gpu, &textures, &standard_view, &alone, (SIZE, SIZE))
                .unwrap();
            let differ = (0..one.len() / 4)
                .filter(|&i| (one[4 * i + 3] > 127) != (standard[4 * i + 3] > 127))
                .count();
            assert_eq!(differ, 0, "reversed Z covers other pixels than standard Z");
        }
    }
}

/// Bad input is an error naming the field and the part, before any GPU work; nothing panics.
#[test]
fn the_bake_refuses_bad_input_by_name() {
    let gpu = lodkit_test_gpu!();
    let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let good = ImpostorMesh {
        positions: &positions,
        indices: &[0, 1, 2],
        ..Default::default()
    };
    let expect = |parts: &[ImpostorPart], descriptor: &ImpostorBakeDescriptor, field: &str| {
        let result = ImpostorBaker::new(gpu, parts).and_then(|b| b.bake(gpu, descriptor));
        match result {
            Err(lodkit::gpu::GpuError::Invalid {
                parameter, value, ..
            }) => {
                assert_eq!(parameter, field, "{value}")
            }
            other => panic!("{field}: {other:?}"),
        }
    };
    let d = ImpostorBakeDescriptor::default();
    expect(&[], &d, "parts");
    let part = |mesh, material| ImpostorPart { mesh, material };
    let m = ImpostorMaterial::default();
    expect(
        &[
            part(good, m),
            part(
                ImpostorMesh {
                    indices: &[0, 1, 3],
                    ..good
                },
                m,
            ),
        ],
        &d,
        "mesh.indices",
    );
    expect(
        &[part(
            ImpostorMesh {
                indices: &[0, 1],
                ..good
            },
            m,
        )],
        &d,
        "mesh",
    );
    let nan = [[f32::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    expect(
        &[part(
            ImpostorMesh {
                positions: &nan,
                ..good
            },
            m,
        )],
        &d,
        "mesh.positions",
    );
    let normals = [[0.0, 0.0, 1.0]];
    expect(
        &[part(
            ImpostorMesh {
                normals: Some(&normals),
                ..good
            },
            m,
        )],
        &d,
        "mesh.normals",
    );
    let short = ImpostorMaterial {
        base_color_texture: Some(ImpostorTexture {
            width: 2,
            height: 2,
            rgba8: &[255; 12],
        }),
        ..m
    };
    expect(&[part(good, short)], &d, "material.base_color_texture");
    let odd = ImpostorBakeDescriptor {
        frame_size: 48,
        ..d
    };
    expect(&[part(good, m)], &odd, "descriptor");
    // And a good one bakes, with a full-sphere layout too.
    let full = ImpostorBakeDescriptor {
        frames: 4,
        frame_size: 8,
        shape: ImpostorShape::Full,
    };
    let atlas = ImpostorBaker::new(gpu, &[part(good, m)])
        .unwrap()
        .bake(gpu, &full)
        .unwrap();
    assert_eq!(atlas.color.len(), 4);
    assert!(
        atlas.color[0].texels.iter().any(|t| t[3] > 0.5),
        "the triangle is in the atlas"
    );
}
