//! Checking the input, simplifying level after level and measuring each level's bound.

use glam::Vec3;
use meshopt::{SimplifyOptions, SimplifyVertex};

use super::hausdorff::{Surface, Tolerance, directed_bound, round_up_f32};
use super::{
    BoundingSphere, LodChain, LodChainDescriptor, LodChainError, LodChainLevel, MeshData,
    Simplifier, SmallMesh,
};

/// A level whose triangle count stays above this share of the previous one is not worth
/// keeping: the chain ends there.
const MIN_REDUCTION: f64 = 0.95;
/// The regular simplifier has stalled when it stays above this multiple of its target.
const STALL: f64 = 1.25;
/// The bound's absolute slack, relative to the bounding radius.
const ABSOLUTE_SLACK: f64 = 1e-5;

pub(super) fn build(
    mesh: &MeshData,
    descriptor: &LodChainDescriptor,
) -> Result<LodChain, LodChainError> {
    check_descriptor(descriptor)?;
    check_mesh(mesh)?;
    let sphere = bounding_sphere(mesh);
    let positions = mesh.positions;
    let vertex_count = positions.len();
    let triangles = mesh.indices.len() / 3;

    // Attributes for the regular simplifier, interleaved: normal (3), uv (2).
    let mut weights = Vec::new();
    if mesh.normals.is_some() {
        weights.extend([descriptor.normal_weight; 3]);
    }
    if mesh.uvs.is_some() {
        weights.extend([descriptor.uv_weight; 2]);
    }
    let stride = weights.len().max(1);
    let mut attributes = vec![0.0f32; vertex_count * stride];
    for v in 0..vertex_count {
        let row = &mut attributes[v * stride..];
        let mut k = 0;
        if let Some(n) = mesh.normals {
            row[..3].copy_from_slice(&n[v]);
            k = 3;
        }
        if let Some(uv) = mesh.uvs {
            row[k..k + 2].copy_from_slice(&uv[v]);
        }
    }
    let locks = vertex_locks(mesh, descriptor);
    let mut options = SimplifyOptions::None;
    if descriptor.lock_border {
        options |= SimplifyOptions::LockBorder;
    }
    // meshoptimizer's relative errors are in units of this extent.
    let scale = meshopt::simplify_scale_decoder(positions);

    let original = Surface::new(positions, mesh.indices);
    let tolerance = Tolerance {
        relative: f64::from(descriptor.bound_tolerance),
        absolute: ABSOLUTE_SLACK * f64::from(sphere.radius),
    };
    let mut levels = vec![make_level(
        mesh,
        mesh.indices,
        0.0,
        Simplifier::Original,
        0.0,
    )];
    let mut current = mesh.indices.to_vec();
    let mut sloppy = false;
    std::thread::scope(|scope| {
        // The original's R-tree, which every level's bound searches, is built on another core
        // while the first level is simplified; each level's bound runs while the next level is
        // simplified (meshoptimizer's simplifier uses one core), one bound at a time (each
        // holds its level's surface and R-tree).
        let original = &original;
        let indexing = (descriptor.levels > 1).then(|| scope.spawn(move || original.index()));
        let mut bounding: Option<std::thread::ScopedJoinHandle<LodChainLevel>> = None;
        for i in 1..descriptor.levels {
            let started = std::time::Instant::now();
            let target = ((triangles as f64) * f64::from(descriptor.ratio).powi(i as i32))
                .round()
                .max(1.0) as usize;
            let mut result_error = 0.0f32;
            let mut simplifier = Simplifier::Regular;
            let mut indices = Vec::new();
            if !sloppy {
                indices = meshopt::simplify_with_attributes_and_locks_decoder(
                    &current,
                    positions,
                    &attributes,
                    if weights.is_empty() { &[] } else { &weights },
                    stride * std::mem::size_of::<f32>(),
                    &locks,
                    target * 3,
                    descriptor.max_relative_error,
                    options,
                    Some(&mut result_error),
                );
                sloppy = descriptor.sloppy_fallback
                    && (indices.len() / 3) as f64 > target as f64 * STALL;
            }
            if sloppy {
                let sloppy_locks: Vec<bool> = locks
                    .iter()
                    .map(|l| l.contains(SimplifyVertex::Lock))
                    .collect();
                let mut sloppy_error = 0.0f32;
                let candidate = meshopt::simplify_sloppy_with_locks_decoder(
                    &current,
                    positions,
                    &sloppy_locks,
                    target * 3,
                    descriptor.max_relative_error,
                    Some(&mut sloppy_error),
                );
                if indices.is_empty() || (!candidate.is_empty() && candidate.len() < indices.len())
                {
                    indices = candidate;
                    result_error = sloppy_error;
                    simplifier = Simplifier::Sloppy;
                }
            }
            let fewer = (indices.len() as f64) <= current.len() as f64 * MIN_REDUCTION;
            if indices.is_empty() || !fewer {
                break;
            }
            if let Some(previous) = bounding.take() {
                levels.push(
                    previous
                        .join()
                        .unwrap_or_else(|e| std::panic::resume_unwind(e)),
                );
            }
            let level = indices.clone();
            bounding = Some(scope.spawn(move || {
                let (error, capped) = level_bound(original, &level, tolerance);
                let mut level = make_level(mesh, &level, error, simplifier, result_error * scale);
                level.error_capped = capped;
                level.time = started.elapsed();
                level
            }));
            current = indices;
        }
        if let Some(last) = bounding {
            levels.push(last.join().unwrap_or_else(|e| std::panic::resume_unwind(e)));
        }
        if let Some(indexing) = indexing {
            indexing
                .join()
                .unwrap_or_else(|e| std::panic::resume_unwind(e));
        }
    });
    if levels.len() == 1 && descriptor.levels > 1 && descriptor.small_mesh == SmallMesh::Error {
        return Err(LodChainError::TooSmall { triangles });
    }
    Ok(LodChain {
        levels,
        sphere,
        camera: descriptor.camera,
    })
}

/// Upper bound of the two-sided Hausdorff distance between the original and `level` (both index
/// the same vertex buffer), and whether its work was capped (a looser upper bound).
fn level_bound(original: &Surface, level: &[u32], tolerance: Tolerance) -> (f32, bool) {
    let capped_before = original.capped();
    let simplified = Surface::new(original.positions(), level);
    // The level's R-tree (for the second direction's exact searches) is built on another core
    // while the first direction runs.
    let (to_original, to_level) = std::thread::scope(|scope| {
        let indexing = scope.spawn(|| simplified.index());
        let to_original = directed_bound(&simplified, original, tolerance);
        indexing
            .join()
            .unwrap_or_else(|e| std::panic::resume_unwind(e));
        (
            to_original,
            directed_bound(original, &simplified, tolerance),
        )
    });
    let capped = original.capped() > capped_before || simplified.capped() > 0;
    (round_up_f32(to_original.max(to_level)), capped)
}

/// The most triangles a vertex may share for the regular vertex cache optimizer (a well-shaped
/// mesh's vertices share 4 to 12; a UV sphere's poles as many as it has segments).
const MAX_VALENCE: u32 = 1024;

/// A level from `indices` into the original vertices: vertex-cache order, then a compact vertex
/// buffer in first-use order.
fn make_level(
    mesh: &MeshData,
    indices: &[u32],
    error: f32,
    simplifier: Simplifier,
    simplifier_error: f32,
) -> LodChainLevel {
    let n = mesh.positions.len();
    // meshoptimizer's vertex cache optimizer weighs every live triangle of the vertices in its
    // cache for each triangle it emits: a vertex shared by tens of thousands of triangles (a
    // list read as a fan) makes it quadratic (59 % of 9.9 s for a 94,264-triangle fan). Past
    // MAX_VALENCE the FIFO optimizer, linear, orders the level instead.
    let mut valence = vec![0u32; n];
    for &i in indices {
        valence[i as usize] += 1;
    }
    let ordered = if valence.iter().any(|&v| v > MAX_VALENCE) {
        meshopt::optimize_vertex_cache_fifo(indices, n, 16)
    } else {
        meshopt::optimize_vertex_cache(indices, n)
    };
    // First-use order (what meshopt_optimizeVertexFetchRemap computes; the crate's wrapper
    // truncates its table to the new vertex count, so it is done here).
    let mut remap = vec![u32::MAX; n];
    let mut source_vertices = Vec::new();
    for &i in &ordered {
        if remap[i as usize] == u32::MAX {
            remap[i as usize] = source_vertices.len() as u32;
            source_vertices.push(i);
        }
    }
    let gather = |src: &[[f32; 3]]| source_vertices.iter().map(|&v| src[v as usize]).collect();
    LodChainLevel {
        positions: gather(mesh.positions),
        normals: mesh.normals.map(gather),
        uvs: mesh
            .uvs
            .map(|uv| source_vertices.iter().map(|&v| uv[v as usize]).collect()),
        indices: ordered.iter().map(|&i| remap[i as usize]).collect(),
        source_vertices,
        error,
        simplifier,
        simplifier_error,
        error_capped: false,
        time: std::time::Duration::ZERO,
    }
}

/// Locks for the seam vertices (a position shared by several vertices) when asked.
fn vertex_locks(mesh: &MeshData, descriptor: &LodChainDescriptor) -> Vec<SimplifyVertex> {
    let mut locks = vec![SimplifyVertex::None; mesh.positions.len()];
    if descriptor.lock_seams {
        let mut first = std::collections::HashMap::new();
        let mut shared = vec![false; mesh.positions.len()];
        for (v, p) in mesh.positions.iter().enumerate() {
            let key = p.map(f32::to_bits);
            match first.entry(key) {
                std::collections::hash_map::Entry::Occupied(e) => {
                    shared[v] = true;
                    shared[*e.get()] = true;
                }
                std::collections::hash_map::Entry::Vacant(e) => {
                    e.insert(v);
                }
            }
        }
        for (lock, s) in locks.iter_mut().zip(shared) {
            if s {
                *lock = SimplifyVertex::Lock;
            }
        }
    }
    locks
}

fn bounding_sphere(mesh: &MeshData) -> BoundingSphere {
    let used = || {
        mesh.indices
            .iter()
            .map(|&i| Vec3::from(mesh.positions[i as usize]))
    };
    let (lo, hi) = used().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
        (lo.min(p), hi.max(p))
    });
    let center = (lo + hi) * 0.5;
    let radius = used().map(|p| p.distance(center)).fold(0.0f32, f32::max);
    // Rounded up so that every vertex is inside.
    BoundingSphere {
        center: center.to_array(),
        radius: radius.next_up(),
    }
}

fn check_descriptor(d: &LodChainDescriptor) -> Result<(), LodChainError> {
    let bad = |field, value: f64, expected| {
        Err(LodChainError::BadDescriptor {
            field,
            value,
            expected,
        })
    };
    if !(1..=255).contains(&d.levels) {
        return bad("levels", d.levels as f64, "1..=255");
    }
    if !(d.ratio > 0.0 && d.ratio < 1.0) {
        return bad("ratio", d.ratio.into(), "in (0, 1)");
    }
    for (field, w) in [
        ("normal_weight", d.normal_weight),
        ("uv_weight", d.uv_weight),
    ] {
        if !(w.is_finite() && w >= 0.0) {
            return bad(field, w.into(), "finite, >= 0");
        }
    }
    if !(d.max_relative_error.is_finite() && d.max_relative_error >= 0.0) {
        return bad(
            "max_relative_error",
            d.max_relative_error.into(),
            "finite, >= 0",
        );
    }
    if !(d.bound_tolerance.is_finite() && d.bound_tolerance > 0.0) {
        return bad("bound_tolerance", d.bound_tolerance.into(), "finite, > 0");
    }
    d.camera.validate()
}

fn check_mesh(mesh: &MeshData) -> Result<(), LodChainError> {
    let n = mesh.positions.len();
    if !mesh.indices.len().is_multiple_of(3) {
        return Err(LodChainError::PartialTriangle(mesh.indices.len()));
    }
    if mesh.indices.is_empty() {
        return Err(LodChainError::NoTriangles);
    }
    if let Some((k, &index)) = mesh
        .indices
        .iter()
        .enumerate()
        .find(|(_, i)| **i as usize >= n)
    {
        return Err(LodChainError::BadIndex {
            triangle: k / 3,
            index,
            vertices: n,
        });
    }
    let attribute_length = |attribute, got| {
        if got == n {
            Ok(())
        } else {
            Err(LodChainError::AttributeLength {
                attribute,
                got,
                want: n,
            })
        }
    };
    if let Some(normals) = mesh.normals {
        attribute_length("normal", normals.len())?;
    }
    if let Some(uvs) = mesh.uvs {
        attribute_length("uv", uvs.len())?;
    }
    let not_finite = |attribute, vertex, value: &[f32]| {
        if value.iter().all(|x| x.is_finite()) {
            Ok(())
        } else {
            Err(LodChainError::NotFinite {
                attribute,
                vertex,
                value: value.to_vec(),
            })
        }
    };
    for (v, p) in mesh.positions.iter().enumerate() {
        not_finite("position", v, p)?;
    }
    for (v, p) in mesh.normals.unwrap_or_default().iter().enumerate() {
        not_finite("normal", v, p)?;
    }
    for (v, p) in mesh.uvs.unwrap_or_default().iter().enumerate() {
        not_finite("uv", v, p)?;
    }
    let has_area = mesh.indices.chunks_exact(3).any(|t| {
        let p = |i: u32| Vec3::from(mesh.positions[i as usize]).as_dvec3();
        (p(t[1]) - p(t[0]))
            .cross(p(t[2]) - p(t[0]))
            .length_squared()
            > 0.0
    });
    if !has_area {
        return Err(LodChainError::Degenerate {
            triangles: mesh.indices.len() / 3,
        });
    }
    Ok(())
}
