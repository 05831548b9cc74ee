// lodkit::impostor — octahedral impostors: an object drawn as a camera-facing card that shows
// pictures of it baked from many directions (the last level of a LOD chain). The directions lie
// on an octahedron unfolded into a square grid of N x N frames (full sphere), or on its upper half
// (hemi: ground objects, seen from above the horizon); the three frames nearest the view are
// blended with barycentric weights, each sampled where the view ray meets the surface the frame
// saw (one step of parallax from the depth stored with the frame).
//
// Space: the object's bounding sphere normalized to the unit sphere, y up (q = (p - centre) /
// radius). A frame sees the object orthographically along -dir over the square [-1, 1]^2 of its
// plane (through the centre, normal dir); frame uv = (dot(q, right), -dot(q, up)) * 0.5 + 0.5
// (row 0 at the top); its stored depth is dot(q, dir) * 0.5 + 0.5. Frame (i, j) sits at column
// i, row j of the atlas and looks from impostor_frame_dir((i, j), n, hemi).
//
// Exports:
//   impostor_sign(v) -> vec2<f32>   +1 or -1 per component (+1 for either zero)
//   impostor_octa_encode(d) -> vec2<f32>   unit d to [-1, 1]^2 (full sphere, +y at the centre)
//   impostor_octa_decode(e) -> vec3<f32>   its inverse (unit length)
//   impostor_hemi_encode(d) -> vec2<f32>   unit d (y clamped to >= 0) to [-1, 1]^2 (hemisphere)
//   impostor_hemi_decode(e) -> vec3<f32>   its inverse (unit length, y >= 0)
//   impostor_encode(d, hemi) -> vec2<f32>, impostor_decode(e, hemi) -> vec3<f32>   either map
//   impostor_frame_dir(frame, n, hemi) -> vec3<f32>   direction frame (i, j) was baked from
//   impostor_frame_basis(dir) -> mat3x3<f32>   (right, up, dir) of a frame
//   ImpostorBlend { frames: array<vec2<u32>, 3>, weights: vec3<f32> }
//   impostor_blend(view, n, hemi) -> ImpostorBlend   the three frames around unit `view` (from
//       the centre toward the eye) and their barycentric weights (sum 1)
//   impostor_ray_at_height(origin, ray, dir, height) -> vec3<f32>   the point of the ray
//       origin + t ray where dot(q, dir) = height
//   impostor_frame_uv(basis, q) -> vec2<f32>   uv of point q in the frame of `basis`
//   impostor_atlas_uv(frame, n, uv) -> vec2<f32>   atlas uv of frame uv (clamped into the frame)
//   impostor_frame_inset(texels, level) -> f32   how far inside its frame a sample at mip level
//       stays (half a texel of the coarsest mip it reads), so no neighbouring frame bleeds in
//   impostor_depth_height(depth) -> f32   stored depth [0, 1] back to height [-1, 1]
//   ImpostorSample { color: vec4<f32>, normal: vec3<f32>, point: vec3<f32> }
//   impostor_sample_frame(color_atlas, normal_atlas, samp, frame, n, hemi, origin, ray, level)
//       -> ImpostorSample   one frame's look along the ray (one parallax step)
//   impostor_sample(color_atlas, normal_atlas, samp, n, hemi, origin, ray, level) -> ImpostorSample
//       the blended colour (alpha: coverage), object-space normal and the point on the ray the
//       frames saw (normalized object space: depth for the depth test), at mip `level`
//   impostor_keep(alpha) -> bool   the alpha test (>= 0.5)
// The atlases: colour rgba (alpha = coverage), normal-depth rgba (normal * 0.5 + 0.5, depth);
// both filterable, sampled with `samp` (linear, clamp to edge) at an explicit level, so the
// module runs in any control flow and any stage.
// Shader defs: none.
#define_import_path lodkit::impostor

/// +1 or -1 by the sign of each component; +1 for either zero (a zero's sign is not read).
fn impostor_sign(v: vec2<f32>) -> vec2<f32> {
    return select(vec2<f32>(-1.0), vec2<f32>(1.0), v >= vec2<f32>(0.0));
}

/// Unit direction `d` on the octahedron unfolded into [-1, 1]^2: the upper half (y >= 0) is the
/// diamond |e.x| + |e.y| <= 1 around +y, the lower half folded into the corners.
fn impostor_octa_encode(d: vec3<f32>) -> vec2<f32> {
    let p = d.xz / (abs(d.x) + abs(d.y) + abs(d.z));
    if (d.y >= 0.0) {
        return p;
    }
    return (vec2<f32>(1.0) - abs(p.yx)) * impostor_sign(p);
}

/// Inverse of impostor_octa_encode: the unit direction at `e` in [-1, 1]^2.
fn impostor_octa_decode(e: vec2<f32>) -> vec3<f32> {
    let y = 1.0 - abs(e.x) - abs(e.y);
    var xz = e;
    if (y < 0.0) {
        xz = (vec2<f32>(1.0) - abs(e.yx)) * impostor_sign(e);
    }
    return normalize(vec3<f32>(xz.x, y, xz.y));
}

/// Unit direction `d` of the upper hemisphere (y clamped to >= 0) on [-1, 1]^2: the diamond of
/// the octahedron's upper half turned by 45 degrees to fill the square. A view from below the
/// horizon maps onto the rim; one from straight below (no horizontal part) to the corner
/// (1, 1), the horizon's +x.
fn impostor_hemi_encode(d: vec3<f32>) -> vec2<f32> {
    if (abs(d.x) + abs(d.z) == 0.0 && d.y < 0.0) {
        return vec2<f32>(1.0);
    }
    let p = d.xz / max(abs(d.x) + max(d.y, 0.0) + abs(d.z), 1e-30);
    return vec2<f32>(p.x + p.y, p.x - p.y);
}

/// Inverse of impostor_hemi_encode: the unit direction (y >= 0) at `e` in [-1, 1]^2.
fn impostor_hemi_decode(e: vec2<f32>) -> vec3<f32> {
    let p = vec2<f32>(e.x + e.y, e.x - e.y) * 0.5;
    return normalize(vec3<f32>(p.x, 1.0 - abs(p.x) - abs(p.y), p.y));
}

/// impostor_hemi_encode when `hemi`, else impostor_octa_encode.
fn impostor_encode(d: vec3<f32>, hemi: bool) -> vec2<f32> {
    if (hemi) {
        return impostor_hemi_encode(d);
    }
    return impostor_octa_encode(d);
}

/// impostor_hemi_decode when `hemi`, else impostor_octa_decode.
fn impostor_decode(e: vec2<f32>, hemi: bool) -> vec3<f32> {
    if (hemi) {
        return impostor_hemi_decode(e);
    }
    return impostor_octa_decode(e);
}

/// The direction (from the centre toward the camera) frame `frame` of an `n` x `n` grid (n < 2
/// is taken as 2) was baked from: the grid spans [-1, 1]^2 corner to corner, frame (0, 0) at
/// (-1, -1).
fn impostor_frame_dir(frame: vec2<u32>, n: u32, hemi: bool) -> vec3<f32> {
    let e = vec2<f32>(frame) * (2.0 / f32(max(n, 2u) - 1u)) - 1.0;
    return impostor_decode(e, hemi);
}

/// The frame's axes as columns (right, up, dir): up follows +y, except at the poles (x = z = 0,
/// where the encoding puts exact zeros), whose up is -z (from above) or +z (from below).
fn impostor_frame_basis(dir: vec3<f32>) -> mat3x3<f32> {
    var reference = vec3<f32>(0.0, 1.0, 0.0);
    if (abs(dir.x) + abs(dir.z) < 1e-6) {
        reference = vec3<f32>(0.0, 0.0, select(1.0, -1.0, dir.y > 0.0));
    }
    let right = normalize(cross(reference, dir));
    return mat3x3<f32>(right, cross(dir, right), dir);
}

/// The three frames around the unit view direction `view` (object space, from the centre toward
/// the eye) and their barycentric weights in the grid's triangle that holds it: each grid cell
/// is split along its anti-diagonal.
struct ImpostorBlend {
    frames: array<vec2<u32>, 3>,
    weights: vec3<f32>,
}

/// The frames of an `n` x `n` grid (n < 2 is taken as 2) to blend for unit view direction
/// `view`.
fn impostor_blend(view: vec3<f32>, n: u32, hemi: bool) -> ImpostorBlend {
    let last = f32(max(n, 2u) - 1u);
    let g = clamp(impostor_encode(view, hemi) * 0.5 + 0.5, vec2<f32>(0.0), vec2<f32>(1.0)) * last;
    let cell = min(floor(g), vec2<f32>(last - 1.0));
    let f = g - cell;
    let c = vec2<u32>(cell);
    if (f.x + f.y <= 1.0) {
        return ImpostorBlend(array<vec2<u32>, 3>(c, c + vec2<u32>(1u, 0u), c + vec2<u32>(0u, 1u)), vec3<f32>(1.0 - f.x - f.y, f.x, f.y));
    }
    return ImpostorBlend(array<vec2<u32>, 3>(c + vec2<u32>(1u, 1u), c + vec2<u32>(1u, 0u), c + vec2<u32>(0u, 1u)), vec3<f32>(f.x + f.y - 1.0, 1.0 - f.y, 1.0 - f.x));
}

/// The point of the ray origin + t ray (normalized object space) at `height` above the plane of
/// frame direction `dir` (dot(q, dir) = height). A ray that does not run against dir (a frame
/// seen edge-on or from behind, which a blend never picks) is taken as just doing so.
fn impostor_ray_at_height(origin: vec3<f32>, ray: vec3<f32>, dir: vec3<f32>, height: f32) -> vec3<f32> {
    let t = (height - dot(origin, dir)) / min(dot(ray, dir), -1e-4);
    return origin + t * ray;
}

/// The uv of normalized object-space point `q` in the frame with axes `basis` (row 0 at the
/// top; [0, 1]^2 is the frame's square [-1, 1]^2).
fn impostor_frame_uv(basis: mat3x3<f32>, q: vec3<f32>) -> vec2<f32> {
    return vec2<f32>(dot(q, basis[0]), -dot(q, basis[1])) * 0.5 + 0.5;
}

/// The atlas uv of frame uv `uv` in frame `frame` of an `n` x `n` atlas, uv clamped to [0, 1].
fn impostor_atlas_uv(frame: vec2<u32>, n: u32, uv: vec2<f32>) -> vec2<f32> {
    return (vec2<f32>(frame) + clamp(uv, vec2<f32>(0.0), vec2<f32>(1.0))) / f32(n);
}

/// How far inside its frame (frame uv) a sample at mip `level` of an atlas whose frames are
/// `texels` texels wide stays: half a texel of the coarsest mip trilinear filtering reads there,
/// so bilinear filtering takes no texel of a neighbouring frame (at most 0.5, the frame's
/// centre).
fn impostor_frame_inset(texels: f32, level: f32) -> f32 {
    return min(0.5 * exp2(ceil(max(level, 0.0))) / texels, 0.5);
}

/// The height [-1, 1] above a frame's plane of a stored depth in [0, 1].
fn impostor_depth_height(depth: f32) -> f32 {
    return depth * 2.0 - 1.0;
}

/// What one impostor fragment sees.
struct ImpostorSample {
    /// Blended colour; alpha is the blended coverage.
    color: vec4<f32>,
    /// Blended object-space normal (unit length, or zero where nothing was covered).
    normal: vec3<f32>,
    /// The point on the ray the frames saw, normalized object space.
    point: vec3<f32>,
}

/// One frame's look along the ray: where the ray meets its plane, that texel's depth, and the
/// colour, normal and point at the height that depth gives (one parallax step), read inside the
/// frame's inset (impostor_frame_inset). Outside the frame's square the coverage is 0.
fn impostor_sample_frame(color_atlas: texture_2d<f32>, normal_atlas: texture_2d<f32>, samp: sampler, frame: vec2<u32>, n: u32, hemi: bool, origin: vec3<f32>, ray: vec3<f32>, level: f32) -> ImpostorSample {
    let dir = impostor_frame_dir(frame, n, hemi);
    let basis = impostor_frame_basis(dir);
    let inset = impostor_frame_inset(f32(textureDimensions(color_atlas, 0).x) / f32(n), level);
    let lo = vec2<f32>(inset);
    let hi = vec2<f32>(1.0 - inset);
    let uv0 = impostor_frame_uv(basis, impostor_ray_at_height(origin, ray, dir, 0.0));
    let depth0 = textureSampleLevel(normal_atlas, samp, impostor_atlas_uv(frame, n, clamp(uv0, lo, hi)), level).w;
    let point = impostor_ray_at_height(origin, ray, dir, impostor_depth_height(depth0));
    let uv = impostor_frame_uv(basis, point);
    let atlas = impostor_atlas_uv(frame, n, clamp(uv, lo, hi));
    var color = textureSampleLevel(color_atlas, samp, atlas, level);
    if (any(uv != clamp(uv, vec2<f32>(0.0), vec2<f32>(1.0)))) {
        color.w = 0.0;
    }
    let normal = textureSampleLevel(normal_atlas, samp, atlas, level).xyz * 2.0 - 1.0;
    return ImpostorSample(color, normal, point);
}

/// The blended look of an impostor along the ray origin + t ray (normalized object space; ray
/// from the eye, not necessarily unit) from an `n` x `n` atlas, at mip `level`.
fn impostor_sample(color_atlas: texture_2d<f32>, normal_atlas: texture_2d<f32>, samp: sampler, n: u32, hemi: bool, origin: vec3<f32>, ray: vec3<f32>, level: f32) -> ImpostorSample {
    let b = impostor_blend(normalize(-ray), n, hemi);
    let s0 = impostor_sample_frame(color_atlas, normal_atlas, samp, b.frames[0], n, hemi, origin, ray, level);
    let s1 = impostor_sample_frame(color_atlas, normal_atlas, samp, b.frames[1], n, hemi, origin, ray, level);
    let s2 = impostor_sample_frame(color_atlas, normal_atlas, samp, b.frames[2], n, hemi, origin, ray, level);
    let w = b.weights;
    let color = w.x * s0.color + w.y * s1.color + w.z * s2.color;
    let normal = w.x * s0.normal + w.y * s1.normal + w.z * s2.normal;
    let length_squared = dot(normal, normal);
    let unit = select(vec3<f32>(0.0), normal * inverseSqrt(length_squared), length_squared > 1e-12);
    return ImpostorSample(color, unit, w.x * s0.point + w.y * s1.point + w.z * s2.point);
}

/// The impostor's alpha test: keep the fragment when the blended coverage is at least 0.5.
fn impostor_keep(alpha: f32) -> bool {
    return alpha >= 0.5;
}
