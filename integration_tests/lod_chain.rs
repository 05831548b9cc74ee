//! Generated LOD chains on screen: each level of three meshes (a smooth closed sphere, a box
//! with hard edges and UV seams whose faces bulge, an open wavy terrain) and the original are
//! rendered at the nearest distance the level can be shown (its switch distance less half the
//! hysteresis) from six directions. Their silhouettes (both ways: from each silhouette pixel of
//! one, the distance to the nearest silhouette pixel of the other) stay within the pixel error
//! `p` plus half a pixel for the rasterizer, and some level of each mesh comes within a factor 2
//! of it (the bound is not loose).

use glam::{Mat4, Vec3, Vec4};
use lodkit::gpu::readback::read_texture_rgba8;
use lodkit::lod_chain::{LodChain, LodChainDescriptor, MeshData, PixelErrorCamera};
use lodkit::unpopping::LodRenderState;
use lodkit_scenes::mesh::{DrawItem, GpuMesh, Mesh, MeshFrame, MeshRenderer, RenderTarget};

use crate::harness::say;

/// Viewport side, pixels.
const SIZE: u32 = 1024;
/// The pixel error the switch distances are computed for.
const PIXEL_ERROR: f32 = 2.0;
/// Where a rasterized silhouette can lie from the true one (a pixel is covered when its centre
/// is inside).
const RASTER: f32 = 0.5;

struct TestMesh {
    name: &'static str,
    positions: Vec<[f32; 3]>,
    indices: Vec<u32>,
    normals: Vec<[f32; 3]>,
    uvs: Vec<[f32; 2]>,
}

fn sphere() -> TestMesh {
    let (positions, indices) = lodkit::lod_chain::uv_sphere(16, 32);
    let uvs = positions.iter().map(|p| [p[0], p[1]]).collect();
    TestMesh {
        name: "sphere",
        normals: positions.clone(),
        positions,
        indices,
        uvs,
    }
}

/// A box of six separate face grids (hard edges, UV seams) whose faces bulge outward.
fn bulged_box() -> TestMesh {
    let (n, bulge) = (8u32, 0.25f32);
    let mut m = TestMesh {
        name: "box",
        positions: vec![],
        indices: vec![],
        normals: vec![],
        uvs: vec![],
    };
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = m.positions.len() as u32;
            for y in 0..=n {
                for x in 0..=n {
                    let (u, v) = (x as f32 / n as f32, y as f32 / n as f32);
                    let (s, t) = (2.0 * u - 1.0, 2.0 * v - 1.0);
                    let mut q = [0.0; 3];
                    q[axis] = sign * (1.0 + bulge * (1.0 - s * s) * (1.0 - t * t));
                    q[a] = s;
                    q[b] = t;
                    let mut normal = [0.0; 3];
                    normal[axis] = sign;
                    m.positions.push(q);
                    m.normals.push(normal);
                    m.uvs.push([u, v]);
                }
            }
            for y in 0..n {
                for x in 0..n {
                    let k = base + y * (n + 1) + x;
                    let (q0, q1, q2, q3) = (k, k + 1, k + n + 2, k + n + 1);
                    m.indices.extend([q0, q1, q2, q0, q2, q3]);
                }
            }
        }
    }
    m
}

/// An open wavy grid over [-1, 1]².
fn terrain() -> TestMesh {
    let n = 24u32;
    let mut m = TestMesh {
        name: "terrain",
        positions: vec![],
        indices: vec![],
        normals: vec![],
        uvs: vec![],
    };
    for y in 0..=n {
        for x in 0..=n {
            let (u, v) = (x as f32 / n as f32, y as f32 / n as f32);
            let (s, t) = (2.0 * u - 1.0, 2.0 * v - 1.0);
            let h = 0.2 * (3.0 * s).sin() * (2.0 * t).cos() + 0.05 * (7.0 * (s + t)).sin();
            m.positions.push([s, h, t]);
            m.normals.push([0.0, 1.0, 0.0]);
            m.uvs.push([u, v]);
        }
    }
    for y in 0..n {
        for x in 0..n {
            let k = y * (n + 1) + x;
            m.indices
                .extend([k, k + n + 1, k + 1, k + 1, k + n + 1, k + n + 2]);
        }
    }
    m
}

/// A renderable mesh that shows both sides of every triangle (the renderer culls back faces; an
/// open mesh's outline is that of its whole surface).
fn two_sided(positions: &[[f32; 3]], indices: &[u32]) -> Mesh {
    let vertices = positions
        .iter()
        .map(|p| [p[0], p[1], p[2], 0.0, 1.0, 0.0])
        .collect();
    let mut all = indices.to_vec();
    all.extend(indices.chunks_exact(3).flat_map(|t| [t[0], t[2], t[1]]));
    Mesh {
        vertices,
        indices: all,
    }
}

/// Covered pixels (alpha > 0) of `mesh` seen from `direction` at `distance` from `center`.
fn coverage(
    gpu: &lodkit::gpu::GpuContext,
    renderer: &MeshRenderer,
    target: &RenderTarget,
    mesh: &GpuMesh,
    view: (Vec3, Vec3, f32, f32),
) -> Vec<bool> {
    let (center, direction, distance, radius) = view;
    let eye = center + direction * distance;
    let up = if direction.y.abs() > 0.9 {
        Vec3::Z
    } else {
        Vec3::Y
    };
    let view = glam::camera::rh::view::look_at_mat4(eye, center, up);
    let near = ((distance - radius) * 0.5).max(1e-3);
    let proj = glam::camera::rh::proj::directx::perspective(
        PixelErrorCamera::default().fov_y,
        1.0,
        near,
        distance + radius + 1.0,
    );
    let item = DrawItem {
        mesh,
        model: Mat4::IDENTITY,
        color: Vec4::ONE,
        state: LodRenderState::OPAQUE,
        dither_alpha: None,
        sway: [0.0; 2],
        alpha_rect: Vec4::ZERO,
    };
    let clear = wgpu::Color::TRANSPARENT;
    renderer
        .render(
            gpu,
            target,
            &MeshFrame {
                clear,
                view_proj: proj * view,
                light_dir: Vec3::Y,
                items: &[item],
                ..Default::default()
            },
        )
        .unwrap();
    let rgba = read_texture_rgba8(gpu, &target.color).unwrap();
    rgba.chunks_exact(4).map(|p| p[3] > 0).collect()
}

/// Covered pixels with an uncovered 4-neighbour (or on the image border), as pixel centres.
fn silhouette(covered: &[bool]) -> Vec<(f32, f32)> {
    let n = SIZE as i32;
    let at = |x: i32, y: i32| x >= 0 && y >= 0 && x < n && y < n && covered[(y * n + x) as usize];
    let mut out = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let edge = [(1, 0), (-1, 0), (0, 1), (0, -1)]
                .iter()
                .any(|(dx, dy)| !at(x + dx, y + dy));
            if at(x, y) && edge {
                out.push((x as f32, y as f32));
            }
        }
    }
    out
}

/// The largest distance from a point of either set to the nearest point of the other.
fn silhouette_distance(a: &[(f32, f32)], b: &[(f32, f32)]) -> f32 {
    let directed = |from: &[(f32, f32)], to: &[(f32, f32)]| {
        from.iter()
            .map(|p| {
                to.iter()
                    .map(|q| (p.0 - q.0).hypot(p.1 - q.1))
                    .fold(f32::INFINITY, f32::min)
            })
            .fold(0.0f32, f32::max)
    };
    directed(a, b).max(directed(b, a))
}

const DIRECTIONS: [Vec3; 6] = [
    Vec3::new(0.0, 0.0, 1.0),
    Vec3::new(1.0, 0.0, 0.0),
    Vec3::new(0.0, 1.0, 0.0),
    Vec3::new(-0.6, 0.48, -0.64),
    Vec3::new(0.577, -0.577, 0.577),
    Vec3::new(-0.8, -0.6, 0.0),
];

#[test]
fn generated_levels_stay_within_the_pixel_error_on_screen() {
    let gpu = lodkit_test_gpu!();
    let renderer = MeshRenderer::new(gpu, false).unwrap();
    let target = RenderTarget::new(gpu, SIZE, SIZE).unwrap();
    for m in [sphere(), bulged_box(), terrain()] {
        let chain = LodChain::build(
            &MeshData {
                positions: &m.positions,
                indices: &m.indices,
                normals: Some(&m.normals),
                uvs: Some(&m.uvs),
            },
            &LodChainDescriptor::default(),
        )
        .unwrap();
        let plain = PixelErrorCamera {
            viewport_height: SIZE as f32,
            pixel_error: PIXEL_ERROR,
            ..Default::default()
        };
        let camera = PixelErrorCamera {
            hysteresis: chain.suggested_hysteresis(&plain).unwrap(),
            ..plain
        };
        let group = chain.lod_group(&camera).unwrap();
        let p11 = camera.p11() as f32;
        let sphere = chain.bounding_sphere();
        let center = Vec3::from(sphere.center);
        let original = GpuMesh::new(gpu, &two_sided(&m.positions, &m.indices)).unwrap();
        let mut worst_mesh = 0.0f32;
        for (i, level) in chain.levels().iter().enumerate().skip(1) {
            // The group keeps chain order: level i at levels()[i].
            let near = group.levels()[i].distance - camera.hysteresis * 0.5;
            let distance = near * p11;
            let gpu_level =
                GpuMesh::new(gpu, &two_sided(level.positions(), level.indices())).unwrap();
            let mut worst = 0.0f32;
            for dir in DIRECTIONS {
                let view = (center, dir.normalize(), distance, sphere.radius);
                let a = silhouette(&coverage(gpu, &renderer, &target, &original, view));
                let b = silhouette(&coverage(gpu, &renderer, &target, &gpu_level, view));
                assert!(
                    !a.is_empty() && !b.is_empty(),
                    "{} level {i}: nothing drawn",
                    m.name
                );
                worst = worst.max(silhouette_distance(&a, &b));
            }
            say(&format!(
                "{} level {i}: {} triangles, error {:.5}, near edge {:.3} (D = {:.3}): silhouettes {worst:.2} px apart",
                m.name,
                level.triangles(),
                level.error(),
                near,
                distance
            ));
            assert!(
                worst <= PIXEL_ERROR + RASTER,
                "{} level {i}: silhouettes {worst} px apart at its switch distance, more than {PIXEL_ERROR} + {RASTER}",
                m.name
            );
            worst_mesh = worst_mesh.max(worst);
        }
        assert!(
            worst_mesh >= PIXEL_ERROR * 0.5,
            "{}: no level comes within 2x of the {PIXEL_ERROR} px bound ({worst_mesh} px at most): the switch distances are too conservative",
            m.name
        );
        // Beyond the max distance (where its fade begins) the whole object fits in a disc of
        // radius p around its centre.
        let hide = (group.max_distance().unwrap() - camera.hysteresis) * p11;
        let c = (SIZE as f32 - 1.0) * 0.5;
        for dir in DIRECTIONS {
            let view = (center, dir.normalize(), hide, sphere.radius);
            let outline = silhouette(&coverage(gpu, &renderer, &target, &original, view));
            let reach = outline
                .iter()
                .map(|p| (p.0 - c).hypot(p.1 - c))
                .fold(0.0f32, f32::max);
            assert!(
                reach <= PIXEL_ERROR + RASTER,
                "{}: {reach} px from its centre at the max distance",
                m.name
            );
        }
    }
}
