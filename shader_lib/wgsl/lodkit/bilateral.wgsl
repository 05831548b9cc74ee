// lodkit::bilateral — geometry-aware (joint bilateral) upsampling of a low-resolution buffer
// (Yang, Sander & Lawrence 2008, sec. 2.2, eq. 1).
//
// Each full-resolution pixel is reconstructed from the 2x2 nearest low-resolution samples,
// weighted by a tent (bilinear) domain filter times Gaussian range filters on the depth difference
// (sigma_z) and on the foreshortened normal distance (sigma_n, lodkit::normal_distance). With
// sigma_z = sigma_n = +inf it is exactly bilinear. Where every weight vanishes (fine geometry that
// is missing from the low-res buffer), the sample closest in depth is used instead of dividing by
// ~0: the threshold is BILATERAL_MIN_WEIGHT on the sum of weights (the tent alone sums to 1).
// The value can be a color or any single shading component (fine-grained resizing, sec. 2.3:
// upsample e.g. a shadow term in .x and multiply by full-res albedo).
//
// Sample order everywhere: 0 = (x0, y0), 1 = (x0 + 1, y0), 2 = (x0, y0 + 1), 3 = (x0 + 1, y0 + 1).
//
// Exports:
//   BILATERAL_MIN_WEIGHT: f32   fallback threshold on the sum of weights (1e-4)
//   BILATERAL_SIGMA_OFF: f32   a sigma that turns its range term off (1e30, finite)
//   BILATERAL_MIN_VIEW_DEPTH: f32   the least view depth a relative sigma is taken of (1e-6)
//   bilateral_relative_sigma(relative, view_depth) -> f32   a depth sigma given as a fraction of
//       the pixel's view depth, in the depth's units (BILATERAL_SIGMA_OFF stays off)
//   bilateral_range(difference, sigma) -> f32   exp(-d^2 / (2 sigma^2)); 1 for BILATERAL_SIGMA_OFF
//   bilateral_tent(f) -> vec4<f32>   bilinear weights of the 2x2 samples at fraction f
//   bilateral_weight(tent, depth_diff, normal_dist, sigma_z, sigma_n) -> f32   one term of eq. 1
//   bilateral_upsample(f, values, depths, normals, depth, normal, sigma_z, sigma_n) -> vec4<f32>
//   bilateral_upsample_projected(f, values, depths, projected, depth, here, sigma_z, sigma_n)
//       -> vec4<f32>   eq. 1 with the normals already through the foreshortening map
//   bilateral_low_position(frag_coord, low_viewport, full_size) -> vec2<f32>   position in L's grid
//   bilateral_cell_origin(p, low_viewport) -> vec2<f32>   top-left texel of the 2x2 cell
//   BilateralCell { corners: vec4<u32>, fraction: vec2<f32> }
//   bilateral_cell(frag_coord, low_viewport, full_size) -> BilateralCell   the 2x2 cell of a
//       full-res pixel: texels 0 and 3 as (x0, y0, x1, y1), clamped to the viewport
//       (1 = (x1, y0), 2 = (x0, y1)), and the pixel's fraction f between them
//   bilateral_cell_fraction(frag_coord, low_viewport, full_size) -> vec2<f32>   f of a full-res pixel
//   bilateral_cell_texel(frag_coord, low_viewport, full_size, i) -> vec2<u32>   its 2x2 L texels
//   bilateral_upsample_texels(f, colors, geometry, depth, normal, sigma_z, sigma_n) -> vec4<f32>
//       eq. 1 from four fetched L color and geometry texels (lodkit::gbuffer layout)
//   bilateral_upsample_at(low_color, low_geometry, low_viewport, full_size, frag_coord, depth,
//       normal, sigma_z, sigma_n) -> vec4<f32>   the whole lookup, for a geometry pass that
//       re-renders the scene at full resolution (the paper's route) or a fullscreen pass
//   bilateral_upsample_packed(f, texels, depth, normal, sigma_z, sigma_n) -> vec4<f32>
//       eq. 1 from four packed L texels (lodkit::gbuffer's packed layout)
//   bilateral_upsample_packed_at(low, low_viewport, full_size, frag_coord, depth, normal,
//       sigma_z, sigma_n) -> vec4<f32>   the whole lookup from a packed L: four texel loads. The
//       fold-in upsample: a composite or tonemap pass that already holds the pixel's depth and
//       normal calls it and needs no upsample pass of its own
// L is drawn into the top-left `low_viewport` texels of textures of any size; full_size is the
// full-resolution target's size.
// Shader defs: none.
#define_import_path lodkit::bilateral
#import lodkit::normal_distance::foreshortened_normal
#import lodkit::gbuffer::{gbuffer_depth, gbuffer_normal, gbuffer_texel_color, gbuffer_texel_depth, gbuffer_texel_projected_normal}

/// Sum of weights below which eq. 1 falls back to the sample closest in depth.
const BILATERAL_MIN_WEIGHT: f32 = 1e-4;

/// A sigma that turns its range term off: every difference over it squares to 0 (or a denormal,
/// which is as good), so the weight is 1. Finite, unlike +inf, which no shader must be given.
const BILATERAL_SIGMA_OFF: f32 = 1e30;

/// The least view depth a relative sigma is taken of: a pixel with no geometry (depth 0) gets a
/// small sigma, which keeps it from mixing with geometry, not a zero one, which would divide by 0.
const BILATERAL_MIN_VIEW_DEPTH: f32 = 1e-6;

/// A depth sigma given as a fraction of the pixel's view depth (`relative` 0.05: a sample 5 %
/// nearer or farther weighs e^-1/2), in the depth's units, for the sigma_z of eq. 1: the same
/// fraction serves a near wall and a distant slanted floor. BILATERAL_SIGMA_OFF stays off.
fn bilateral_relative_sigma(relative: f32, view_depth: f32) -> f32 {
    return select(relative * max(view_depth, BILATERAL_MIN_VIEW_DEPTH), relative, relative >= BILATERAL_SIGMA_OFF);
}

/// Gaussian range filter exp(-difference^2 / (2 sigma^2)); 1 when sigma is BILATERAL_SIGMA_OFF.
fn bilateral_range(difference: f32, sigma: f32) -> f32 {
    let s = difference / sigma;
    return exp(-0.5 * s * s);
}

/// Tent (bilinear) weights of the 2x2 samples for the fractional position `f` in [0, 1]^2.
fn bilateral_tent(f: vec2<f32>) -> vec4<f32> {
    return vec4<f32>((1.0 - f.x) * (1.0 - f.y), f.x * (1.0 - f.y), (1.0 - f.x) * f.y, f.x * f.y);
}

/// One weight of eq. 1: tent x g(depth difference, sigma_z) x g(normal distance, sigma_n),
/// evaluated as one exponential of the summed exponents.
fn bilateral_weight(tent: f32, depth_diff: f32, normal_dist: f32, sigma_z: f32, sigma_n: f32) -> f32 {
    let z = depth_diff / sigma_z;
    let n = normal_dist / sigma_n;
    return tent * exp(-0.5 * (z * z + n * n));
}

/// Eq. 1 as bilateral_upsample, with the samples' and the pixel's normals given through the
/// foreshortening map (`projected`, `here`: foreshortened_normal of each).
/// Written without loops or dynamic indexing (four lanes of one vec4), and with the squared
/// normal distance instead of a square root: a software rasterizer runs this per pixel.
fn bilateral_upsample_projected(
    f: vec2<f32>,
    values: array<vec4<f32>, 4>,
    depths: vec4<f32>,
    projected: array<vec2<f32>, 4>,
    depth: f32,
    here: vec2<f32>,
    sigma_z: f32,
    sigma_n: f32,
) -> vec4<f32> {
    // Differences scaled by 1 / sigma (about 0 for BILATERAL_SIGMA_OFF: no range term).
    let inv_z = 1.0 / sigma_z;
    let inv_n = 1.0 / sigma_n;
    let dz = depths - depth;
    let z = dz * inv_z;
    let n0 = (projected[0] - here) * inv_n;
    let n1 = (projected[1] - here) * inv_n;
    let n2 = (projected[2] - here) * inv_n;
    let n3 = (projected[3] - here) * inv_n;
    let nn = vec4<f32>(dot(n0, n0), dot(n1, n1), dot(n2, n2), dot(n3, n3));
    let w = bilateral_tent(f) * exp(-0.5 * (z * z + nn));
    let total = w.x + w.y + w.z + w.w;
    if (total < BILATERAL_MIN_WEIGHT) {
        let a = abs(dz);
        let m = min(min(a.x, a.y), min(a.z, a.w));
        return select(select(select(values[3], values[2], a.z == m), values[1], a.y == m), values[0], a.x == m);
    }
    return (w.x * values[0] + w.y * values[1] + w.z * values[2] + w.w * values[3]) * (1.0 / total);
}

/// Eq. 1 over the 2x2 low-res samples (`values`, `depths`, `normals`) for a full-res pixel at
/// fraction `f` between them with depth `depth` and normal `normal`. Falls back to the sample
/// closest in depth (the first of equals) when the weights sum below BILATERAL_MIN_WEIGHT.
fn bilateral_upsample(
    f: vec2<f32>,
    values: array<vec4<f32>, 4>,
    depths: vec4<f32>,
    normals: array<vec3<f32>, 4>,
    depth: f32,
    normal: vec3<f32>,
    sigma_z: f32,
    sigma_n: f32,
) -> vec4<f32> {
    let projected = array<vec2<f32>, 4>(foreshortened_normal(normals[0]), foreshortened_normal(normals[1]), foreshortened_normal(normals[2]), foreshortened_normal(normals[3]));
    return bilateral_upsample_projected(f, values, depths, projected, depth, foreshortened_normal(normal), sigma_z, sigma_n);
}

/// Continuous position of a full-res pixel in L's texel grid (texel centers at integers).
fn bilateral_low_position(frag_coord: vec2<f32>, low_viewport: vec2<f32>, full_size: vec2<f32>) -> vec2<f32> {
    return frag_coord * low_viewport / full_size - 0.5;
}

/// Top-left texel of the 2x2 cell around position `p`, kept inside the viewport.
fn bilateral_cell_origin(p: vec2<f32>, low_viewport: vec2<f32>) -> vec2<f32> {
    return clamp(floor(p), vec2<f32>(0.0), max(low_viewport - 2.0, vec2<f32>(0.0)));
}

/// The 2x2 cell of a full-res pixel: its texels 0 and 3 as (x0, y0, x1, y1), clamped to the
/// viewport (texel 1 is (x1, y0), texel 2 (x0, y1)), and the pixel's fraction between them.
struct BilateralCell {
    corners: vec4<u32>,
    fraction: vec2<f32>,
}

/// The cell of the full-res pixel at `frag_coord`: what every lookup of this module fetches.
fn bilateral_cell(frag_coord: vec2<f32>, low_viewport: vec2<f32>, full_size: vec2<f32>) -> BilateralCell {
    let p = bilateral_low_position(frag_coord, low_viewport, full_size);
    let origin = bilateral_cell_origin(p, low_viewport);
    let last = vec2<u32>(max(low_viewport - 1.0, vec2<f32>(0.0)));
    let first = vec2<u32>(origin);
    let corners = vec4<u32>(min(first, last), min(first + 1u, last));
    return BilateralCell(corners, clamp(p - origin, vec2<f32>(0.0), vec2<f32>(1.0)));
}

/// Fraction `f` between the 2x2 L texels of the full-res pixel at `frag_coord`.
fn bilateral_cell_fraction(frag_coord: vec2<f32>, low_viewport: vec2<f32>, full_size: vec2<f32>) -> vec2<f32> {
    return bilateral_cell(frag_coord, low_viewport, full_size).fraction;
}

/// L texel `i` (0..3, order as above) of the 2x2 cell of the full-res pixel at `frag_coord`.
fn bilateral_cell_texel(frag_coord: vec2<f32>, low_viewport: vec2<f32>, full_size: vec2<f32>, i: u32) -> vec2<u32> {
    let c = bilateral_cell(frag_coord, low_viewport, full_size).corners;
    return vec2<u32>(select(c.x, c.z, (i & 1u) != 0u), select(c.y, c.w, (i & 2u) != 0u));
}

/// Eq. 1 from four fetched L texels: `colors` and `geometry` (lodkit::gbuffer layout).
fn bilateral_upsample_texels(
    f: vec2<f32>,
    colors: array<vec4<f32>, 4>,
    geometry: array<vec4<f32>, 4>,
    depth: f32,
    normal: vec3<f32>,
    sigma_z: f32,
    sigma_n: f32,
) -> vec4<f32> {
    let depths = vec4<f32>(gbuffer_depth(geometry[0]), gbuffer_depth(geometry[1]), gbuffer_depth(geometry[2]), gbuffer_depth(geometry[3]));
    let normals = array<vec3<f32>, 4>(gbuffer_normal(geometry[0]), gbuffer_normal(geometry[1]), gbuffer_normal(geometry[2]), gbuffer_normal(geometry[3]));
    return bilateral_upsample(f, colors, depths, normals, depth, normal, sigma_z, sigma_n);
}

/// The full lookup for the full-res pixel at `frag_coord` with `depth` and screen `normal`:
/// fetches the 2x2 L texels from `low_color` and `low_geometry` and applies eq. 1. Eight texel
/// loads.
fn bilateral_upsample_at(
    low_color: texture_2d<f32>,
    low_geometry: texture_2d<f32>,
    low_viewport: vec2<f32>,
    full_size: vec2<f32>,
    frag_coord: vec2<f32>,
    depth: f32,
    normal: vec3<f32>,
    sigma_z: f32,
    sigma_n: f32,
) -> vec4<f32> {
    let cell = bilateral_cell(frag_coord, low_viewport, full_size);
    let c = cell.corners;
    let colors = array<vec4<f32>, 4>(
        textureLoad(low_color, c.xy, 0),
        textureLoad(low_color, c.zy, 0),
        textureLoad(low_color, c.xw, 0),
        textureLoad(low_color, c.zw, 0),
    );
    let geometry = array<vec4<f32>, 4>(
        textureLoad(low_geometry, c.xy, 0),
        textureLoad(low_geometry, c.zy, 0),
        textureLoad(low_geometry, c.xw, 0),
        textureLoad(low_geometry, c.zw, 0),
    );
    return bilateral_upsample_texels(cell.fraction, colors, geometry, depth, normal, sigma_z, sigma_n);
}

/// Eq. 1 from four packed L texels (lodkit::gbuffer's packed layout) for a full-res pixel at
/// fraction `f` with `depth` and screen `normal`.
fn bilateral_upsample_packed(
    f: vec2<f32>,
    texels: array<vec4<u32>, 4>,
    depth: f32,
    normal: vec3<f32>,
    sigma_z: f32,
    sigma_n: f32,
) -> vec4<f32> {
    let values = array<vec4<f32>, 4>(gbuffer_texel_color(texels[0]), gbuffer_texel_color(texels[1]), gbuffer_texel_color(texels[2]), gbuffer_texel_color(texels[3]));
    let depths = vec4<f32>(gbuffer_texel_depth(texels[0]), gbuffer_texel_depth(texels[1]), gbuffer_texel_depth(texels[2]), gbuffer_texel_depth(texels[3]));
    let projected = array<vec2<f32>, 4>(gbuffer_texel_projected_normal(texels[0]), gbuffer_texel_projected_normal(texels[1]), gbuffer_texel_projected_normal(texels[2]), gbuffer_texel_projected_normal(texels[3]));
    return bilateral_upsample_projected(f, values, depths, projected, depth, foreshortened_normal(normal), sigma_z, sigma_n);
}

/// The full lookup from a packed L (rgba32uint, lodkit::gbuffer's packed layout) for the
/// full-res pixel at `frag_coord` with `depth` and screen `normal`: four texel loads. Call it
/// from the pass that already has the pixel's depth and normal (a composite or tonemap pass) and
/// the upsample needs no pass of its own.
fn bilateral_upsample_packed_at(
    low: texture_2d<u32>,
    low_viewport: vec2<f32>,
    full_size: vec2<f32>,
    frag_coord: vec2<f32>,
    depth: f32,
    normal: vec3<f32>,
    sigma_z: f32,
    sigma_n: f32,
) -> vec4<f32> {
    let cell = bilateral_cell(frag_coord, low_viewport, full_size);
    let c = cell.corners;
    let texels = array<vec4<u32>, 4>(
        textureLoad(low, c.xy, 0),
        textureLoad(low, c.zy, 0),
        textureLoad(low, c.xw, 0),
        textureLoad(low, c.zw, 0),
    );
    return bilateral_upsample_packed(cell.fraction, texels, depth, normal, sigma_z, sigma_n);
}
