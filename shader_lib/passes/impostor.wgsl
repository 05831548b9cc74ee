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
//             @location(4) x the screen-door alpha (lodkit::screen_door; 1: every pixel), y the
//             visibility threshold this frame and z the next frame's (lodkit::visibility),
//             @location(5).x the instance id of a LOD buffer (0: n-instance), @location(6..9)
//             the previous frame's object-to-world matrix, @location(10).xyz a tint the base
//             colour is multiplied with (1: as baked)
//   fs_main   location 0: colour (base colour x tint x Lambert from `view.light`; blended by the
//             pipeline's blend constant in an unpopping or cross-fade transition);
//             @builtin(frag_depth)
//   fs_lod_buffer   a LOD buffer of frame-sequential LOD (lodkit::lod_buffer): location 0
//             colour, location 1 the id word with the display-time visibility flags (the pattern
//             anchored to the screen when `view.viewport.z` is 1, to the surface point the frames
//             saw when 0), location 2 the object motion of that point; @builtin(frag_depth). No
//             screen door: the combine shows each level by its flags.
//   fs_level_depth  the older-level depth pass: the impostor whole, @builtin(frag_depth) only
//   shade(in) -> Shaded   helper: the fragment's coverage, colour and surface point, shared by
//             the three fragment entry points; depth_of(world) -> f32   helper: its depth
// Bindings: group 0: 0 `view: ImpostorView` (uniform), 1 `color_atlas`, 2 `normal_atlas`
//   (filterable, with mips), 3 `atlas_sampler` (linear, mipmapped, clamp to edge), 4 `vis_tex`
//   (fs_lod_buffer only: the visibility pattern, r32float).
// Shader defs: LODKIT_SCREEN_DOOR_BLUE_NOISE (bool, default off; lodkit::screen_door's) — the
//   16x16 blue-noise pattern instead of the 4x4 Bayer one, to match the mesh levels'.
#import lodkit::impostor::{ImpostorSample, impostor_sample, impostor_keep}
#import lodkit::screen_door::screen_door_keep
#import lodkit::visibility::{visibility_flags, visibility_flags_screen, visibility_next_coord}
#import lodkit::lod_buffer::{LOD_BUFFER_SHOWN_NOW, LOD_BUFFER_SHOWN_NEXT, lod_buffer_output_motion, lod_buffer_motion}

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
    /// The previous frame's view_proj (fs_lod_buffer; the same on a frame without one).
    prev_view_proj: mat4x4<f32>,
    /// fs_lod_buffer: x, y the target's size in pixels; z 1 = the visibility pattern anchored
    /// to the screen, 0 = to the object; w the pattern's repeats per object-space unit.
    viewport: vec4<f32>,
}

@group(0) @binding(0) var<uniform> view: ImpostorView;
@group(0) @binding(1) var color_atlas: texture_2d<f32>;
@group(0) @binding(2) var normal_atlas: texture_2d<f32>;
@group(0) @binding(3) var atlas_sampler: sampler;
@group(0) @binding(4) var vis_tex: texture_2d<f32>;

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
    /// x: the screen-door alpha, y: the visibility threshold now, z: next frame's.
    @location(6) @interpolate(flat) door: vec4<f32>,
    @location(7) @interpolate(flat) id: u32,
    @location(8) @interpolate(flat) prev_model_0: vec4<f32>,
    @location(9) @interpolate(flat) prev_model_1: vec4<f32>,
    @location(10) @interpolate(flat) prev_model_2: vec4<f32>,
    @location(11) @interpolate(flat) prev_model_3: vec4<f32>,
    @location(12) @interpolate(flat) tint: vec4<f32>,
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
    @location(5) id: vec4<u32>,
    @location(6) prev_model_0: vec4<f32>,
    @location(7) prev_model_1: vec4<f32>,
    @location(8) prev_model_2: vec4<f32>,
    @location(9) prev_model_3: vec4<f32>,
    @location(10) tint: vec4<f32>,
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
    out.door = door;
    out.id = id.x;
    out.prev_model_0 = prev_model_0;
    out.prev_model_1 = prev_model_1;
    out.prev_model_2 = prev_model_2;
    out.prev_model_3 = prev_model_3;
    out.tint = tint;
    return out;
}

/// What every entry point takes of a fragment: whether the frames cover it, its colour, the
/// surface point they saw (object space) and where it lies now in the world.
struct Shaded {
    keep: bool,
    color: vec4<f32>,
    point: vec3<f32>,
    world: vec4<f32>,
}

/// The impostor at this fragment: the three frames blended, lit; derivatives taken first, in
/// uniform control flow, before any entry point branches.
fn shade(in: VertexOut) -> Shaded {
    // The mip whose frame texel (2 / frame size in normalized units) matches the pixel's
    // footprint on the card.
    let footprint = max(length(dpdx(in.card)), length(dpdy(in.card)));
    let level = max(log2(footprint * f32(view.atlas.z) * 0.5), 0.0);
    let s = impostor_sample(color_atlas, normal_atlas, atlas_sampler, view.atlas.x, view.atlas.y != 0u, in.eye, in.card - in.eye, level);
    let model = mat4x4<f32>(in.model_0, in.model_1, in.model_2, in.model_3);
    let point = view.sphere.xyz + s.point * view.sphere.w;
    let world = model * vec4<f32>(point, 1.0);
    let normal = normalize((model * vec4<f32>(s.normal, 0.0)).xyz + vec3<f32>(0.0, 1e-6, 0.0));
    let lit = view.light.w + (1.0 - view.light.w) * max(dot(normal, view.light.xyz), 0.0);
    return Shaded(impostor_keep(s.color.w), vec4<f32>(s.color.xyz * in.tint.xyz * lit, 1.0), point, world);
}

/// The depth of a world point under this frame's view.
fn depth_of(world: vec4<f32>) -> f32 {
    let clip = view.view_proj * world;
    return clamp(clip.z / clip.w, 0.0, 1.0);
}

struct FragmentOut {
    @location(0) color: vec4<f32>,
    @builtin(frag_depth) depth: f32,
}

/// The impostor's colour and the depth of the surface its frames saw; discards what they do
/// not cover and what its screen door leaves to the other level.
@fragment
fn fs_main(in: VertexOut) -> FragmentOut {
    let s = shade(in);
    if (!s.keep || !screen_door_keep(in.position.xy, in.door.x)) {
        discard;
    }
    return FragmentOut(s.color, depth_of(s.world));
}

/// A LOD buffer's outputs (lodkit::lod_buffer::LodBufferMotionOutput) and the depth.
struct LodBufferOut {
    @location(0) color: vec4<f32>,
    @location(1) id: u32,
    @location(2) motion: vec2<f32>,
    @builtin(frag_depth) depth: f32,
}

/// Frame-sequential LOD: every covered fragment, flagged with where the visibility pattern shows
/// it now and next frame, its object motion, the depth of the surface the frames saw.
@fragment
fn fs_lod_buffer(in: VertexOut) -> LodBufferOut {
    let s = shade(in);
    if (!s.keep) {
        discard;
    }
    let prev_model = mat4x4<f32>(in.prev_model_0, in.prev_model_1, in.prev_model_2, in.prev_model_3);
    let now_clip = view.prev_view_proj * s.world;
    let then_clip = view.prev_view_proj * (prev_model * vec4<f32>(s.point, 1.0));
    var flags = LOD_BUFFER_SHOWN_NOW | LOD_BUFFER_SHOWN_NEXT;
    if (in.id != 0u && view.viewport.z > 0.5) {
        let next = visibility_next_coord(in.position.xy, then_clip, view.viewport.xy);
        flags = visibility_flags_screen(vis_tex, in.position.xy, next, in.door.y, in.door.z);
    } else if (in.id != 0u) {
        flags = visibility_flags(vis_tex, s.point * view.viewport.w, in.door.y, in.door.z);
    }
    let out = lod_buffer_output_motion(s.color, in.id, flags, lod_buffer_motion(then_clip, now_clip));
    return LodBufferOut(out.color, out.id, out.motion, depth_of(s.world));
}

/// The older-level depth pass: the impostor whole (no pattern), the depth of its surface.
@fragment
fn fs_level_depth(in: VertexOut) -> @builtin(frag_depth) f32 {
    let s = shade(in);
    if (!s.keep) {
        discard;
    }
    return depth_of(s.world);
}
