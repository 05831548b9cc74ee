// passes/lod_mesh — a lit mesh drawn as one LOD of a transition: what an engine's forward shader
// needs for screen-door LOD blending, and the opaque/blended draws of unpopping.
//
// The vertex stage sways the mesh like a plant in the wind when `draw.sway.x` is not 0 (an
// engine's own vertex animation goes there) and transforms by camera and model matrices. The
// fragment stage shades with one directional light and, when `draw.dither_alpha` is not
// DITHER_OFF, keeps only the pixels the screen-door pattern gives this LOD (lodkit::screen_door;
// negative alpha = inverted pattern). Alpha blending for unpopping and cross-fades uses the blend
// constant, so the shader is the same for every role (lodkit::gpu::unpopping::lod_blend). An
// alpha-tested LOD (a billboard impostor) discards what its mask does not cover
// (lodkit::alpha_mask, looked up at the object-space position before the sway).
//
// Entry points:
//   vs_main   @location(0) position, @location(1) normal (object space)
//   fs_main   @location(0) color (rgb lit, a = draw.color.a)
//   sway_offset(p, sway) -> vec3<f32>   helper: the wind sway of the vertex stage
// Bindings: group 0 binding 0 `camera: Camera` (uniform), binding 1 `alpha_mask: texture_2d<f32>`
// (r32float, lodkit::alpha_mask); group 1 binding 0 `draw: Draw` (uniform, dynamic offset).
// Shader defs: LODKIT_SCREEN_DOOR_BLUE_NOISE (bool, default off) — passed on to lodkit::screen_door.
#import lodkit::screen_door::screen_door_keep
#import lodkit::alpha_mask::alpha_mask_keep

/// Per-view data.
struct Camera {
    view_proj: mat4x4<f32>,
    /// World-space direction toward the light (w unused).
    light_dir: vec4<f32>,
}

/// Per-draw data.
struct Draw {
    model: mat4x4<f32>,
    color: vec4<f32>,
    /// Sway: x amplitude (object units at the top of a unit-high mesh, 0 = none), y phase.
    sway: vec2<f32>,
    /// Screen-door alpha of this LOD, or DITHER_OFF (any value > 1) for no dithering.
    dither_alpha: f32,
    _pad: f32,
    /// Alpha mask rect (lodkit::alpha_mask; x == 0: no alpha test).
    alpha_rect: vec4<f32>,
}

@group(0) @binding(0) var<uniform> camera: Camera;
@group(0) @binding(1) var alpha_mask: texture_2d<f32>;
@group(1) @binding(0) var<uniform> draw: Draw;

struct VertexOut {
    @builtin(position) position: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) object_pos: vec3<f32>,
}

/// Wind sway of an object-space position: along x, growing with height above the base (y = -1).
fn sway_offset(p: vec3<f32>, sway: vec2<f32>) -> vec3<f32> {
    return vec3<f32>(sway.x * max(p.y + 1.0, 0.0) * sin(sway.y + p.x + p.z), 0.0, 0.0);
}

/// Sways a vertex, transforms it to clip space and its normal to world space; hands the
/// object-space position from before the sway to the fragment stage (alpha mask).
@vertex
fn vs_main(@location(0) position: vec3<f32>, @location(1) normal: vec3<f32>) -> VertexOut {
    let world = draw.model * vec4<f32>(position + sway_offset(position, draw.sway), 1.0);
    return VertexOut(camera.view_proj * world, (draw.model * vec4<f32>(normal, 0.0)).xyz, position);
}

/// Lambert shading; alpha-test discard; screen-door discard when dithering is on.
@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    if (!alpha_mask_keep(alpha_mask, in.object_pos, draw.alpha_rect)) {
        discard;
    }
    if (draw.dither_alpha <= 1.0 && !screen_door_keep(in.position.xy, draw.dither_alpha)) {
        discard;
    }
    let lambert = max(dot(normalize(in.normal), normalize(camera.light_dir.xyz)), 0.0);
    return vec4<f32>(draw.color.rgb * (0.35 + 0.65 * lambert), draw.color.a);
}
