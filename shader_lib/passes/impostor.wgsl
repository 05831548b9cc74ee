// passes/impostor — octahedral impostors drawn from their atlas (lodkit::impostor): one
// camera-facing card per instance that covers the bounding sphere's projection; each fragment
// blends the three frames nearest its view ray (one parallax step each), drops what the atlas
// does not cover (and, in a transition, what its screen-door pattern leaves to the other
// level), and writes the depth of the surface the frames saw, so the depth test sees the
// object, not the card.
//
// Entry points:
//   vs_main   no vertex buffer: six vertices per instance; per instance @location(0..3) the
//             columns of the object-to-world matrix (rotation, uniform scale, translation),
//             @location(4).x the screen-door alpha (lodkit::screen_door; 1: every pixel)
//   fs_main   location 0: colour (base colour x Lambert from `view.light`); @builtin(frag_depth)
// Bindings: group 0: 0 `view: ImpostorView` (uniform), 1 `color_atlas`, 2 `normal_atlas`
//   (filterable, with mips), 3 `atlas_sampler` (linear, mipmapped, clamp to edge).
// Shader defs: LODKIT_SCREEN_DOOR_BLUE_NOISE (bool, default off; lodkit::screen_door's) — the
//   16x16 blue-noise pattern instead of the 4x4 Bayer one, to match the mesh levels'.
#import lodkit::impostor::{ImpostorSample, impostor_sample, impostor_keep}
#import lodkit::screen_door::screen_door_keep

/// The view and the atlas.
struct ImpostorView {
    view_proj: mat4x4<f32>,
    /// xyz: the camera's world position.
    eye: vec4<f32>,
    /// xyz: world-space direction toward the light; w: the ambient term.
    light: vec4<f32>,
    /// xyz: the bounding sphere's centre (object space); w: its radius.
    sphere: vec4<f32>,
    /// x: frames per side, y: 1 for the hemisphere, z: texels per frame side.
    atlas: vec4<u32>,
}

@group(0) @binding(0) var<uniform> view: ImpostorView;
@group(0) @binding(1) var color_atlas: texture_2d<f32>;
@group(0) @binding(2) var normal_atlas: texture_2d<f32>;
@group(0) @binding(3) var atlas_sampler: sampler;

struct VertexOut {
    @builtin(position) position: vec4<f32>,
    /// The card point, normalized object space.
    @location(0) card: vec3<f32>,
    /// The eye, normalized object space.
    @location(1) @interpolate(flat) eye: vec3<f32>,
    @location(2) @interpolate(flat) model_0: vec4<f32>,
    @location(3) @interpolate(flat) model_1: vec4<f32>,
    @location(4) @interpolate(flat) model_2: vec4<f32>,
    @location(5) @interpolate(flat) model_3: vec4<f32>,
    @location(6) @interpolate(flat) alpha: f32,
}

/// The card: six vertices per instance around the bounding sphere's centre, facing the eye.
@vertex
fn vs_main(
    @builtin(vertex_index) vertex: u32,
    @location(0) model_0: vec4<f32>,
    @location(1) model_1: vec4<f32>,
    @location(2) model_2: vec4<f32>,
    @location(3) model_3: vec4<f32>,
    @location(4) door: vec4<f32>,
) -> VertexOut {
    let model = mat4x4<f32>(model_0, model_1, model_2, model_3);
    let scale = length(model_0.xyz);
    let center = (model * vec4<f32>(view.sphere.xyz, 1.0)).xyz;
    let radius = view.sphere.w * scale;
    let to_eye = view.eye.xyz - center;
    let d = length(to_eye);
    let forward = to_eye / d;
    // The cone from the eye tangent to the sphere meets the plane through the centre at
    // radius R d / sqrt(d^2 - R^2); inside the sphere the card collapses (nothing is drawn).
    let inside = d <= radius * 1.001;
    let half_size = select(radius * d / sqrt(max(d * d - radius * radius, 1e-12)), 0.0, inside);
    let helper = select(vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(1.0, 0.0, 0.0), abs(forward.y) > 0.9);
    let right = normalize(cross(helper, forward));
    let up = cross(forward, right);
    let corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0),
    );
    let c = corners[vertex % 6u];
    let world = center + (c.x * right + c.y * up) * half_size;
    // World to normalized object space: the inverse of a rotation times a uniform scale is its
    // transpose over the scale squared.
    let to_object = transpose(mat3x3<f32>(model_0.xyz, model_1.xyz, model_2.xyz)) * (1.0 / (scale * scale));
    var out: VertexOut;
    out.position = view.view_proj * vec4<f32>(world, 1.0);
    out.card = (to_object * (world - model_3.xyz) - view.sphere.xyz) / view.sphere.w;
    out.eye = (to_object * (view.eye.xyz - model_3.xyz) - view.sphere.xyz) / view.sphere.w;
    out.model_0 = model_0;
    out.model_1 = model_1;
    out.model_2 = model_2;
    out.model_3 = model_3;
    out.alpha = door.x;
    return out;
}

struct FragmentOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

/// The impostor's colour and the depth of the surface its frames saw; discards what they do
/// not cover.
@fragment
fn fs_main(in: VertexOut) -> FragmentOut {
    // The mip whose frame texel (2 / frame size in normalized units) matches the pixel's
    // footprint on the card: derivatives taken before any branch.
    let footprint = max(length(dpdx(in.card)), length(dpdy(in.card)));
    let level = max(log2(footprint * f32(view.atlas.z) * 0.5), 0.0);
    let s = impostor_sample(color_atlas, normal_atlas, atlas_sampler, view.atlas.x, view.atlas.y != 0u, in.eye, in.card - in.eye, level);
    if (!impostor_keep(s.color.w) || !screen_door_keep(in.position.xy, in.alpha)) {
        discard;
    }
    let model = mat4x4<f32>(in.model_0, in.model_1, in.model_2, in.model_3);
    let world = model * vec4<f32>(view.sphere.xyz + s.point * view.sphere.w, 1.0);
    let clip = view.view_proj * world;
    let normal = normalize((model * vec4<f32>(s.normal, 0.0)).xyz + vec3<f32>(0.0, 1e-6, 0.0));
    let lit = view.light.w + (1.0 - view.light.w) * max(dot(normal, view.light.xyz), 0.0);
    var out: FragmentOut;
    out.color = vec4<f32>(s.color.xyz * lit, 1.0);
    out.depth = clamp(clip.z / clip.w, 0.0, 1.0);
    return out;
}
