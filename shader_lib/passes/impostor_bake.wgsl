// passes/impostor_bake — one frame of an octahedral impostor atlas: the mesh seen
// orthographically from the frame's direction over its bounding sphere's square, drawn into the
// frame's viewport of the atlas (lodkit::impostor's space and frame layout; the host builds each
// frame's matrix from the Rust twins of impostor_frame_dir and impostor_frame_basis). With a
// perspective matrix the same pass draws the reference an impostor is compared with.
//
// Entry points:
//   vs_main   @location(0) position, @location(1) normal, @location(2) uv (object space)
//   fs_main   location 0: base colour (linear; alpha 1 where covered), location 1: object-space
//             normal * 0.5 + 0.5 and the stored depth dot(q, dir) * 0.5 + 0.5
// Bindings: group 0: 0 `bake: BakeParams` (uniform, dynamic offset: one slot per frame);
//   group 1: 0 `base_texture` (the material's base colour texture, sRGB; a 1x1 white one
//   without), 1 `base_sampler`.
// The alpha test: a fragment whose base colour alpha (factor x texture) is below
// `bake.material.y` is discarded (a cutoff <= 0 keeps every fragment).
// Shader defs: none.

/// One frame's bake.
struct BakeParams {
    /// Object space to the frame's clip space.
    clip_from_object: mat4x4<f32>,
    /// xyz: the frame's direction; w: unused.
    dir: vec4<f32>,
    /// xyz: the bounding sphere's centre; w: its radius.
    sphere: vec4<f32>,
    /// The material's base colour factor (linear).
    base_color: vec4<f32>,
    /// x: whether a fragment's back face shows its own normal flipped (double-sided, 1) or not;
    /// y: the alpha cutoff (<= 0: none).
    material: vec4<f32>,
}

@group(0) @binding(0) var<uniform> bake: BakeParams;
@group(1) @binding(0) var base_texture: texture_2d<f32>;
@group(1) @binding(1) var base_sampler: sampler;

struct VertexOut {
    @builtin(position) position: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) height: f32,
}

/// The vertex through the frame's (or the reference camera's) matrix, with its height above
/// the frame's plane.
@vertex
fn vs_main(@location(0) position: vec3<f32>, @location(1) normal: vec3<f32>, @location(2) uv: vec2<f32>) -> VertexOut {
    let height = dot((position - bake.sphere.xyz) / bake.sphere.w, bake.dir.xyz);
    var out: VertexOut;
    out.position = bake.clip_from_object * vec4<f32>(position, 1.0);
    out.normal = normal;
    out.uv = uv;
    out.height = height;
    return out;
}

struct BakeOut {
    @location(0) color: vec4<f32>,
    @location(1) normal_depth: vec4<f32>,
}

/// Base colour, normal and depth of the mesh where its alpha test keeps it.
@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front: bool) -> BakeOut {
    let color = bake.base_color * textureSample(base_texture, base_sampler, in.uv);
    if (bake.material.y > 0.0 && color.w < bake.material.y) {
        discard;
    }
    var n = normalize(in.normal);
    if (!front && bake.material.x != 0.0) {
        n = -n;
    }
    var out: BakeOut;
    out.color = vec4<f32>(color.xyz, 1.0);
    out.normal_depth = vec4<f32>(n * 0.5 + 0.5, clamp(in.height * 0.5 + 0.5, 0.0, 1.0));
    return out;
}
