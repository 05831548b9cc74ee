//! Silhouettes against a brute-force rasterization of the front faces.

use super::*;

/// A box of half extents `h`: four vertices per face (as a mesh with per-face normals has), two
/// counterclockwise triangles each.
fn cuboid(h: Vec3) -> (Vec<[f32; 3]>, Vec<u32>) {
    let mut positions = Vec::new();
    let mut indices = Vec::new();
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let n = Vec3::from_array(std::array::from_fn(|i| if i == axis { sign } else { 0.0 }));
            let u = Vec3::from_array(std::array::from_fn(|i| f32::from(i == (axis + 1) % 3)));
            let v = n.cross(u);
            let base = positions.len() as u32;
            for (s, t) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                positions.push(((n + u * s + v * t) * h).to_array());
            }
            indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
        }
    }
    (positions, indices)
}

/// A UV sphere of `radius` with `sectors` x `stacks` quads: the seam's vertices twice and each
/// pole's once per sector, computed with sin and cos (the seam's copies a hair apart), as
/// engines build them; the pole quads are degenerate triangles.
fn uv_sphere(radius: f32, sectors: u32, stacks: u32) -> (Vec<[f32; 3]>, Vec<u32>) {
    let mut positions = Vec::new();
    for i in 0..=stacks {
        let phi = std::f32::consts::PI * i as f32 / stacks as f32;
        for j in 0..=sectors {
            let theta = std::f32::consts::TAU * j as f32 / sectors as f32;
            positions.push(
                (Vec3::new(phi.sin() * theta.cos(), phi.cos(), -phi.sin() * theta.sin()) * radius)
                    .to_array(),
            );
        }
    }
    let mut indices = Vec::new();
    for i in 0..stacks {
        for j in 0..sectors {
            let a = i * (sectors + 1) + j;
            let b = a + sectors + 1;
            indices.extend([a, b, a + 1, a + 1, b, b + 1]);
        }
    }
    (positions, indices)
}

/// A camera at `eye` looking at `target`, 90 degrees, on a 64x48 target.
fn camera(eye: Vec3, target: Vec3) -> Mat4 {
    let view = glam::camera::rh::view::look_at_mat4(eye, target, Vec3::Y);
    let proj = glam::camera::rh::proj::directx::perspective_infinite_reverse(
        std::f32::consts::FRAC_PI_2,
        64.0 / 48.0,
        0.1,
    );
    proj * view
}

/// Whether a front face covers pixel center `p`: rasterization, by brute force.
fn covered(mesh: &(Vec<[f32; 3]>, Vec<u32>), clip: Mat4, eye: Vec3, p: Vec2) -> bool {
    let to_px = |v: Vec3| {
        let c = clip * v.extend(1.0);
        let n = c.truncate().truncate() / c.w;
        Vec2::new((n.x + 1.0) * 32.0, (1.0 - n.y) * 24.0)
    };
    mesh.1.chunks_exact(3).any(|t| {
        let [a, b, c] = [0, 1, 2].map(|k| Vec3::from_array(mesh.0[t[k] as usize]));
        if (b - a).cross(c - a).dot(eye - a) <= 0.0 {
            return false;
        }
        let [a, b, c] = [a, b, c].map(to_px);
        let e = [
            (b - a).perp_dot(p - a),
            (c - b).perp_dot(p - b),
            (a - c).perp_dot(p - c),
        ];
        e.iter().all(|&x| x >= 0.0) || e.iter().all(|&x| x <= 0.0)
    })
}

/// Over every pixel center, the winding of the silhouette says covered exactly where a front
/// face covers: a box, and a coarse UV sphere (seam and poles welded), from three sides each.
#[test]
fn the_winding_of_the_silhouette_is_the_coverage() {
    for mesh in [cuboid(Vec3::new(0.5, 0.7, 0.4)), uv_sphere(0.9, 9, 6)] {
        let surface = Surface::new(&mesh.0, Some(&mesh.1)).unwrap();
        for eye in [
            Vec3::new(0.3, 0.4, 2.5),
            Vec3::new(-2.0, 1.1, 0.7),
            Vec3::new(0.2, -1.7, -1.4),
        ] {
            let clip = camera(eye, Vec3::ZERO);
            let segments = surface.silhouette(clip, eye, (64, 48), true).unwrap();
            assert!(segments.len() >= 3);
            let mut inside = 0;
            for y in 0..48 {
                for x in 0..64 {
                    let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                    let want = covered(&mesh, clip, eye, p);
                    assert_eq!(winding(&segments, p) != 0, want, "{eye} at {p}");
                    inside += usize::from(want);
                }
            }
            assert!(inside > 100, "{eye}: the mesh covers {inside} pixels");
        }
    }
}

/// Mirrored (front faces clockwise), the same mesh has the same coverage.
#[test]
fn a_mirrored_mesh_turns_its_faces_round() {
    let (mut positions, indices) = uv_sphere(0.9, 9, 6);
    for p in &mut positions {
        p[0] = -p[0];
    }
    let surface = Surface::new(&positions, Some(&indices)).unwrap();
    let eye = Vec3::new(0.3, 0.4, 2.5);
    let segments = surface
        .silhouette(camera(eye, Vec3::ZERO), eye, (64, 48), false)
        .unwrap();
    assert_ne!(winding(&segments, Vec2::new(32.5, 24.5)), 0);
    assert_eq!(winding(&segments, Vec2::new(0.5, 0.5)), 0);
}

/// An open mesh, a badly wound one, a bad index and a mesh reaching behind the camera are
/// errors naming the problem; from inside a closed mesh nothing is covered.
#[test]
fn what_has_no_silhouette_says_why() {
    let quad = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let open = Surface::new(&quad, Some(&[0, 1, 2, 0, 2, 3])).unwrap_err();
    assert!(matches!(open, SilhouetteError::NotClosed { .. }), "{open}");
    assert!(open.to_string().contains("not closed"), "{open}");
    let twice = Surface::new(&quad, Some(&[0, 1, 2, 0, 1, 3])).unwrap_err();
    assert!(
        matches!(twice, SilhouetteError::NotManifold { .. }),
        "{twice}"
    );
    assert_eq!(
        Surface::new(&quad, Some(&[0, 1, 7])).unwrap_err(),
        SilhouetteError::IndexOutOfRange {
            triangle: 0,
            index: 7,
            vertices: 4
        }
    );
    let (positions, indices) = uv_sphere(1.0, 9, 6);
    let sphere = Surface::new(&positions, Some(&indices)).unwrap();
    let eye = Vec3::new(0.0, 0.5, 3.0);
    let away = camera(eye, Vec3::new(0.0, 0.5, 6.0));
    assert_eq!(
        sphere.silhouette(away, eye, (64, 48), true),
        Err(SilhouetteError::BehindCamera)
    );
    let (positions, indices) = uv_sphere(5.0, 9, 6);
    let big = Surface::new(&positions, Some(&indices)).unwrap();
    assert_eq!(
        big.silhouette(camera(eye, Vec3::ZERO), eye, (64, 48), true),
        Ok(Vec::new())
    );
}

/// The crossing counts a segment starting on the point's line and not one ending on it, so an
/// outline through a vertex on the line counts once; the distance is to the segment's nearest
/// point.
#[test]
fn crossings_and_distances_by_hand() {
    let p = Vec2::new(1.0, 1.0);
    let v = Vec2::new;
    for (a, b, crossing) in [
        (v(2.0, 0.0), v(2.0, 2.0), 1),  // upwards, p on its left
        (v(2.0, 2.0), v(2.0, 0.0), -1), // downwards, p on its right
        (v(0.0, 0.0), v(0.0, 2.0), 0),  // upwards, p on its right
        (v(2.0, 1.0), v(2.0, 2.0), 1),  // starting on p's line
        (v(2.0, 0.0), v(2.0, 1.0), 0),  // ending on it
    ] {
        assert_eq!(silhouette_crossing(p, a, b), crossing, "{a} -> {b}");
    }
    for (a, b, distance) in [
        (v(4.0, 0.0), v(4.0, 3.0), 3.0), // beside the segment
        (v(4.0, 5.0), v(4.0, 9.0), 5.0), // past its end
        (v(1.0, 4.0), v(1.0, 4.0), 3.0), // a point
    ] {
        assert_eq!(silhouette_distance(p, a, b), distance, "{a} -> {b}");
    }
}
