//! The chain's error bounds held against an independent, brute-force measurement of the
//! two-sided Hausdorff distance on three small meshes of different kinds, and its errors on bad
//! input.

use super::*;
use glam::DVec3;

/// Positions, indices, normals and UVs of a test mesh.
type Parts = (Vec<[f32; 3]>, Vec<u32>, Vec<[f32; 3]>, Vec<[f32; 2]>);

/// A sphere, closed and smooth: normals are the positions.
fn sphere() -> Parts {
    let (p, i) = uv_sphere(16, 32);
    let uv = p.iter().map(|q| [q[0], q[1]]).collect();
    (p.clone(), i, p, uv)
}

/// A box whose faces bulge outward, each face its own grid of vertices (flat normal, UVs 0..1):
/// hard edges and UV seams on every cube edge.
fn bulged_box(n: u32, bulge: f32) -> Parts {
    let (mut p, mut i, mut nr, mut uv) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = p.len() as u32;
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
                    p.push(q);
                    nr.push(normal);
                    uv.push([u, v]);
                }
            }
            for y in 0..n {
                for x in 0..n {
                    let k = base + y * (n + 1) + x;
                    let (q0, q1, q2, q3) = (k, k + 1, k + n + 2, k + n + 1);
                    if sign > 0.0 {
                        i.extend([q0, q1, q2, q0, q2, q3]);
                    } else {
                        i.extend([q0, q2, q1, q0, q3, q2]);
                    }
                }
            }
        }
    }
    (p, i, nr, uv)
}

/// An open wavy grid (terrain) over [-1, 1]², with UVs.
fn terrain(n: u32) -> Parts {
    let (mut p, mut i, mut nr, mut uv) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for y in 0..=n {
        for x in 0..=n {
            let (u, v) = (x as f32 / n as f32, y as f32 / n as f32);
            let (s, t) = (2.0 * u - 1.0, 2.0 * v - 1.0);
            let h = 0.2 * (3.0 * s).sin() * (2.0 * t).cos() + 0.05 * (7.0 * (s + t)).sin();
            p.push([s, h, t]);
            nr.push([0.0, 1.0, 0.0]);
            uv.push([u, v]);
        }
    }
    for y in 0..n {
        for x in 0..n {
            let k = y * (n + 1) + x;
            i.extend([k, k + n + 1, k + 1, k + 1, k + n + 1, k + n + 2]);
        }
    }
    (p, i, nr, uv)
}

/// Distance to a triangle by another construction than the chain's (which tests Ericson's
/// Voronoi regions): the face when `p` projects inside all three edges (the signs of the
/// edges' cross products with the normal), the nearest of the three segments otherwise, so the
/// check does not share its mistakes.
fn reference_distance(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let seg = |a: DVec3, b: DVec3| {
        let ab = b - a;
        let t = if ab.length_squared() > 0.0 {
            ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (a + ab * t).distance(p)
    };
    let n = (b - a).cross(c - a);
    if n.length_squared() > 0.0
        && (b - a).cross(p - a).dot(n) >= 0.0
        && (c - b).cross(p - b).dot(n) >= 0.0
        && (a - c).cross(p - c).dot(n) >= 0.0
    {
        return ((p - a).dot(n) / n.length()).abs();
    }
    seg(a, b).min(seg(b, c)).min(seg(c, a))
}

/// Points on every triangle of `indices`, a barycentric grid with at most `spacing` between
/// neighbours; returns them and the radius within which they cover the surface.
fn dense_samples(p: &[[f32; 3]], indices: &[u32], spacing: f64) -> (Vec<DVec3>, f64) {
    let v = |i: u32| DVec3::from(p[i as usize].map(f64::from));
    let mut out = Vec::new();
    let mut cover = 0.0f64;
    for t in indices.chunks_exact(3) {
        let (a, b, c) = (v(t[0]), v(t[1]), v(t[2]));
        let longest = a.distance(b).max(b.distance(c)).max(c.distance(a));
        let k = (longest / spacing).ceil().max(1.0) as u32;
        cover = cover.max(longest / f64::from(k) / 3f64.sqrt());
        for i in 0..=k {
            for j in 0..=k - i {
                let (s, r) = (f64::from(i) / f64::from(k), f64::from(j) / f64::from(k));
                out.push(a + (b - a) * s + (c - a) * r);
            }
        }
    }
    (out, cover)
}

/// Largest distance from the samples to the triangles of `indices`, brute force (skipping a
/// triangle whose bounding sphere is farther than the nearest distance so far).
fn directed_max(samples: &[DVec3], p: &[[f32; 3]], indices: &[u32]) -> f64 {
    let v = |i: u32| DVec3::from(p[i as usize].map(f64::from));
    let tris: Vec<([DVec3; 3], DVec3, f64)> = indices
        .chunks_exact(3)
        .map(|t| {
            let c = [v(t[0]), v(t[1]), v(t[2])];
            let centre = (c[0] + c[1] + c[2]) / 3.0;
            let radius = c.iter().map(|x| x.distance(centre)).fold(0.0, f64::max);
            (c, centre, radius)
        })
        .collect();
    samples
        .iter()
        .map(|&s| {
            let mut best = f64::INFINITY;
            for (t, centre, radius) in &tris {
                if s.distance(*centre) - radius < best {
                    best = best.min(reference_distance(s, t[0], t[1], t[2]));
                }
            }
            best
        })
        .fold(0.0, f64::max)
}

/// Builds the chain of `mesh` and holds every level's reported error to a dense brute-force
/// measurement: the measured Hausdorff distance may not exceed it, and it may not exceed what
/// the bound's construction allows above the truth (5 % + 1e-5 R above the distance found,
/// and the truth is at most the dense maximum plus the samples' covering radius).
fn holds_to_dense_measurement(name: &str, mesh: MeshData) {
    let chain = LodChain::build(&mesh, &LodChainDescriptor::default()).unwrap();
    let levels = chain.levels();
    let total = levels[0].triangles();
    assert!(levels.len() >= 5, "{name}: {} levels", levels.len());
    let last = levels.last().unwrap().triangles();
    assert!(
        last * 10 <= total,
        "{name}: last level keeps {last} of {total} triangles"
    );
    let radius = f64::from(chain.bounding_sphere().radius);
    for (i, level) in levels.iter().enumerate().skip(1) {
        let (p, idx) = (level.positions(), level.indices());
        let reported = f64::from(level.error());
        // About 3,000 samples a side (brute force: the meshes are small).
        let area = |p: &[[f32; 3]], idx: &[u32]| -> f64 {
            idx.chunks_exact(3)
                .map(|t| {
                    let v = |k: u32| DVec3::from(p[k as usize].map(f64::from));
                    (v(t[1]) - v(t[0])).cross(v(t[2]) - v(t[0])).length() * 0.5
                })
                .sum()
        };
        let spacing = (area(mesh.positions, mesh.indices) / 3000.0).sqrt();
        let (on_level, cover_l) = dense_samples(p, idx, spacing);
        let (on_original, cover_o) = dense_samples(mesh.positions, mesh.indices, spacing);
        let measured = directed_max(&on_level, mesh.positions, mesh.indices).max(directed_max(
            &on_original,
            p,
            idx,
        ));
        let cover = cover_l.max(cover_o);
        assert!(
            measured <= reported * (1.0 + 1e-6),
            "{name} level {i}: measured Hausdorff {measured} above the reported bound {reported}"
        );
        let most = (measured + cover) * 1.05 + 1e-5 * radius;
        assert!(
            reported <= most * (1.0 + 1e-6),
            "{name} level {i}: bound {reported} is looser than its construction allows ({most}; measured {measured}, samples cover {cover})"
        );
        assert!(
            reported > 0.0,
            "{name} level {i}: a simplified level with error 0"
        );
    }
}

#[test]
fn sphere_bounds_hold() {
    let (p, i, n, uv) = sphere();
    let mesh = MeshData {
        positions: &p,
        indices: &i,
        normals: Some(&n),
        uvs: Some(&uv),
    };
    holds_to_dense_measurement("sphere", mesh);
}

#[test]
fn bulged_box_with_seams_bounds_hold() {
    let (p, i, n, uv) = bulged_box(8, 0.2);
    let mesh = MeshData {
        positions: &p,
        indices: &i,
        normals: Some(&n),
        uvs: Some(&uv),
    };
    holds_to_dense_measurement("box", mesh);
}

#[test]
fn open_terrain_bounds_hold() {
    let (p, i, _, uv) = terrain(20);
    let mesh = MeshData {
        positions: &p,
        indices: &i,
        normals: None,
        uvs: Some(&uv),
    };
    holds_to_dense_measurement("terrain", mesh);
}

#[test]
fn bad_meshes_are_named() {
    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let build = |positions: &[[f32; 3]], indices: &[u32]| {
        LodChain::build(
            &MeshData {
                positions,
                indices,
                ..Default::default()
            },
            &LodChainDescriptor::default(),
        )
    };
    assert_eq!(build(&p, &[]), Err(LodChainError::NoTriangles));
    assert_eq!(build(&p, &[0, 1]), Err(LodChainError::PartialTriangle(2)));
    assert!(matches!(
        build(&p, &[0, 1, 7]),
        Err(LodChainError::BadIndex {
            triangle: 0,
            index: 7,
            vertices: 3
        })
    ));
    let nan = [[0.0, 0.0, 0.0], [f32::NAN, 0.0, 0.0], [0.0, 1.0, 0.0]];
    assert!(matches!(
        build(&nan, &[0, 1, 2]),
        Err(LodChainError::NotFinite {
            attribute: "position",
            vertex: 1,
            ..
        })
    ));
    let flat = [[1.0, 2.0, 3.0]; 3];
    assert_eq!(
        build(&flat, &[0, 1, 2]),
        Err(LodChainError::Degenerate { triangles: 1 })
    );
    assert_eq!(
        build(&p, &[0, 1, 2]),
        Err(LodChainError::TooSmall { triangles: 1 })
    );
    let single = LodChain::build(
        &MeshData {
            positions: &p,
            indices: &[0, 1, 2],
            ..Default::default()
        },
        &LodChainDescriptor {
            small_mesh: SmallMesh::SingleLevel,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(single.levels().len(), 1);
    let short_uv = LodChain::build(
        &MeshData {
            positions: &p,
            indices: &[0, 1, 2],
            uvs: Some(&[[0.0, 0.0]]),
            ..Default::default()
        },
        &LodChainDescriptor::default(),
    );
    assert!(matches!(
        short_uv,
        Err(LodChainError::AttributeLength {
            attribute: "uv",
            got: 1,
            want: 3
        })
    ));
    let bad_ratio = LodChain::build(
        &MeshData {
            positions: &p,
            indices: &[0, 1, 2],
            ..Default::default()
        },
        &LodChainDescriptor {
            ratio: 1.5,
            ..Default::default()
        },
    );
    assert!(matches!(
        bad_ratio,
        Err(LodChainError::BadDescriptor { field: "ratio", .. })
    ));
}

/// The levels carry the original's attributes for the vertices they keep.
#[test]
fn levels_keep_their_source_attributes() {
    let (p, i, n, uv) = bulged_box(6, 0.2);
    let mesh = MeshData {
        positions: &p,
        indices: &i,
        normals: Some(&n),
        uvs: Some(&uv),
    };
    let chain = LodChain::build(&mesh, &LodChainDescriptor::default()).unwrap();
    for level in chain.levels() {
        for (k, &src) in level.source_vertices().iter().enumerate() {
            assert_eq!(level.positions()[k], p[src as usize]);
            assert_eq!(level.normals().unwrap()[k], n[src as usize]);
            assert_eq!(level.uvs().unwrap()[k], uv[src as usize]);
        }
        assert!(
            level
                .indices()
                .iter()
                .all(|&x| (x as usize) < level.positions().len())
        );
    }
    let group = chain.lod_group(&PixelErrorCamera::default()).unwrap();
    let d: Vec<f32> = group.levels().iter().map(|l| l.distance).collect();
    assert!(d.windows(2).all(|w| w[0] <= w[1]), "{d:?}");
}

/// A closed mesh (the UV sphere, whose seam and poles repeat positions bit for bit; the bulged
/// box, with seams on every edge) keeps closed levels, with or without UVs: each level's
/// coverage is then its silhouette (`lodkit::silhouette::Surface`), as frame-sequential LOD's
/// combine takes it.
#[test]
fn closed_meshes_keep_closed_levels() {
    for (name, (p, i, n, uv)) in [("sphere", sphere()), ("bulged box", bulged_box(6, 0.2))] {
        for with_uvs in [true, false] {
            let chain = LodChain::build(
                &MeshData {
                    positions: &p,
                    indices: &i,
                    normals: Some(&n),
                    uvs: with_uvs.then_some(uv.as_slice()),
                },
                &LodChainDescriptor::default(),
            )
            .unwrap();
            assert!(
                chain.levels().len() >= 4,
                "{name}: {} levels",
                chain.levels().len()
            );
            for (k, level) in chain.levels().iter().enumerate() {
                let surface =
                    crate::silhouette::Surface::new(level.positions(), Some(level.indices()));
                assert!(
                    surface.is_ok(),
                    "{name} (UVs: {with_uvs}) level {k} ({} triangles) is not closed: {:?}",
                    level.triangles(),
                    surface.err()
                );
            }
        }
    }
}

/// Past its budget of candidate triangles a bound is still an upper bound: with none at all
/// (every triangle keeps its first, cheapest bounds and nothing is refined) the bound from a
/// sphere to a coarser sphere on the same vertices is at least the brute-force distance, and
/// the triangles it cannot refine keep their cheap bounds.
#[test]
fn a_bound_past_its_budget_is_still_an_upper_bound() {
    use super::hausdorff::{Surface, Tolerance, directed_bound, directed_bound_within};
    let (p, fine) = uv_sphere(16, 32);
    // Every other ring and segment of the same grid (rings of 33 vertices).
    let mut coarse = Vec::new();
    for r in (0..16).step_by(2) {
        for s in (0..32).step_by(2) {
            let (a, b) = (r * 33 + s, (r + 2) * 33 + s);
            coarse.extend([a, b, a + 2, a + 2, b, b + 2]);
        }
    }
    let target = Surface::new(&p, &coarse);
    let source = Surface::new(&p, &fine);
    let tolerance = Tolerance {
        relative: 0.05,
        absolute: 1e-6,
    };
    let full = directed_bound(&source, &target, tolerance);
    let none = directed_bound_within(&source, &target, tolerance, 0);
    // Every sample is a point of the fine sphere: no upper bound is below its distance.
    let (samples, _) = dense_samples(&p, &fine, 0.01);
    let measured = directed_max(&samples, &p, &coarse);
    assert!(
        full >= measured,
        "full budget {full} vs measured {measured}"
    );
    assert!(none >= measured, "no budget {none} vs measured {measured}");
    // Without a budget the triangles the cheap bounds do not settle keep those bounds (0.179
    // here, against 0.039 refined and 0.037 measured): looser, not dropped.
    assert!(none > 2.0 * full, "no budget {none} vs full {full}");
    assert!(
        measured > 0.01,
        "the coarse sphere is not the fine one: {measured}"
    );
}

/// A sphere's triangle list read as a fan (what a wrong primitive mode makes: long slivers from
/// one vertex across the whole sphere): its chain is built with the bound's work capped, the
/// level says so, its bound is still at least the distance from each side's vertices and
/// triangle centroids to the other side (points of the surfaces, found by brute force), and a
/// well-shaped mesh's levels are never capped. Tried against a throwaway edit that counts no
/// cap (fails on `error_capped`).
#[test]
fn degenerate_geometry_caps_the_bound_and_says_so() {
    let (p, list) = uv_sphere(12, 24);
    let fan: Vec<u32> = (1..list.len() - 1)
        .flat_map(|k| [list[0], list[k], list[k + 1]])
        .collect();
    let descriptor = LodChainDescriptor {
        levels: 2,
        ..Default::default()
    };
    let mesh = MeshData {
        positions: &p,
        indices: &fan,
        normals: None,
        uvs: None,
    };
    let chain = LodChain::build(&mesh, &descriptor).unwrap();
    let level = &chain.levels()[1];
    assert!(level.error_capped(), "the fan's bound is capped");
    // Points of a surface: its vertices and its triangles' centroids.
    let points = |p: &[[f32; 3]], idx: &[u32]| -> Vec<DVec3> {
        let v = |k: u32| DVec3::from(p[k as usize].map(f64::from));
        idx.iter()
            .map(|&k| v(k))
            .chain(
                idx.chunks_exact(3)
                    .map(|t| (v(t[0]) + v(t[1]) + v(t[2])) / 3.0),
            )
            .collect()
    };
    let (lp, li) = (level.positions(), level.indices());
    let measured =
        directed_max(&points(lp, li), &p, &fan).max(directed_max(&points(&p, &fan), lp, li));
    assert!(
        f64::from(level.error()) >= measured,
        "capped bound {} below the measured {measured}",
        level.error()
    );
    let list_mesh = MeshData {
        positions: &p,
        indices: &list,
        normals: None,
        uvs: None,
    };
    let chain = LodChain::build(&list_mesh, &LodChainDescriptor::default()).unwrap();
    assert!(chain.levels().iter().all(|l| !l.error_capped()));
}

/// The bound's point-to-triangle distance (Ericson's regions) equals the reference
/// construction for points all around triangles of every shape: general, collinear,
/// coincident corners and thin slivers. Tried against a throwaway edit without the degenerate
/// guard (a collinear triangle's rounding reached the face's formula: fails at case 221).
#[test]
fn point_triangle_distance_matches_the_reference() {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
    };
    let mut point = move || DVec3::new(next(), next(), next());
    for k in 0..40_000 {
        let (a, b, p) = (point(), point(), point());
        let c = match k % 4 {
            0 => point(),
            1 => a + (b - a) * 0.3,
            2 => a,
            _ => a + (b - a) * 0.5 + point() * 1e-3,
        };
        let got = super::hausdorff::point_triangle_distance2(p, a, b, c).sqrt();
        let want = reference_distance(p, a, b, c);
        // Both in f64 on coordinates within 2: rounding stays far below 1e-9.
        assert!(
            (got - want).abs() <= 1e-9,
            "case {k}: {got} against {want} for {p} to {a} {b} {c}"
        );
    }
}
