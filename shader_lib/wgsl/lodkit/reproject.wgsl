// lodkit::reproject — back-projection of a pixel of the newer LOD buffer into the older one
// (Scherzer & Wimmer 2008, sec. 3.4, eq. 2: p_old = P_old V_old V_new^-1 P_new^-1 p_new).
//
// uv is texture space ((0,0) top-left), depth the clip depth stored in the LOD buffer. The host
// builds `new_to_old` (lodkit::reproject::new_to_old_matrix). Works for standard and reversed Z
// and for infinite far planes: the chain stays homogeneous until the final divide, so a sky pixel
// (a point at infinity) reprojects by the rotation alone.
//
// Exports:
//   reproject(uv, depth, new_to_old) -> vec3<f32>   (old uv, old depth); uv = (-1, -1) when the
//                                                   point is behind the older camera
//   reproject_base(uv, new_to_old) -> vec4<f32>   the depth-independent part, linear in uv: a
//                                                 vertex stage can compute it and let it interpolate
//   reproject_from_base(base, depth, new_to_old) -> vec3<f32>   reproject() given that part
//   in_viewport(uv) -> bool   whether an old uv lies inside the older buffer
//   reproject_refine(base, depth, old_depth, new_to_old) -> vec3<f32>   the point on the same
//       pixel's ray whose old depth is old_depth (the older buffer's depth at the first estimate),
//       reprojected: finds the older surface where a stipple hole or an edge gave the newer
//       pixel another surface's depth; the first estimate where the ray never has that depth
// Shader defs: none (LODKIT_REVERSE_Z matters only where depths are compared: lodkit::combine).
#define_import_path lodkit::reproject

/// new_to_old x (ndc.x, ndc.y, 0, 1) for texture-space `uv`: affine in uv, so it interpolates
/// exactly across a fullscreen triangle.
fn reproject_base(uv: vec2<f32>, new_to_old: mat4x4<f32>) -> vec4<f32> {
    return new_to_old * vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0);
}

/// Finishes `reproject` from `base` = reproject_base(uv, new_to_old): adds depth times the third
/// column, divides, maps to texture space.
fn reproject_from_base(base: vec4<f32>, depth: f32, new_to_old: mat4x4<f32>) -> vec3<f32> {
    let old = base + depth * new_to_old[2];
    if (old.w <= 0.0) {
        return vec3<f32>(-1.0, -1.0, depth);
    }
    let p = old.xyz / old.w;
    return vec3<f32>(p.x * 0.5 + 0.5, 0.5 - p.y * 0.5, p.z);
}

/// Position in the older LOD buffer of the newer buffer's pixel at `uv` with clip `depth`:
/// (old uv, old clip depth). A point behind the older camera gets uv (-1, -1).
fn reproject(uv: vec2<f32>, depth: f32, new_to_old: mat4x4<f32>) -> vec3<f32> {
    return reproject_from_base(reproject_base(uv, new_to_old), depth, new_to_old);
}

/// Whether `uv` lies inside the older buffer ([0, 1] on both axes).
fn in_viewport(uv: vec2<f32>) -> bool {
    return all(uv >= vec2<f32>(0.0)) && all(uv <= vec2<f32>(1.0));
}

/// Reprojects the point on this pixel's ray (`base` = reproject_base) whose old clip depth is
/// `old_depth`: with `old_depth` read from the older buffer at reproject_from_base(base, depth),
/// a second fetch there finds the older surface itself, with its own parallax, where the newer
/// pixel shows another surface (a stipple hole, an edge). Where no point of the ray has that old
/// depth, the reprojection of `depth` itself.
fn reproject_refine(base: vec4<f32>, depth: f32, old_depth: f32, new_to_old: mat4x4<f32>) -> vec3<f32> {
    // old.z / old.w = old_depth along base + z * column 2, solved for z = num / den. Whether it
    // is solved is read from num and den, never from the quotient: a GPU need not give a
    // division by zero (or by a flushed denormal) an infinity or a NaN to test for.
    let c = new_to_old[2];
    let num = old_depth * base.w - base.z;
    let den = c.z - old_depth * c.w;
    let solved = abs(den) >= 1.17549435e-38 && abs(num) <= 3.0e38 * min(abs(den), 1.0);
    return reproject_from_base(base, select(depth, num / den, solved), new_to_old);
}
