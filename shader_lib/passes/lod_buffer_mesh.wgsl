// passes/lod_buffer_mesh — a lit mesh drawn into a LOD buffer for frame-sequential LOD: what an
// engine adds to its forward shader (Scherzer & Wimmer 2008, sec. 4.1).
//
// The vertex stage sways the mesh like a plant in the wind when `draw.sway.x` is not 0 (an
// engine's own vertex animation goes there) and passes the object-space position on from
// before the animation. The fragment stage keeps every fragment of a t-instance and flags, in the
// id word, whether it is shown at tau (this frame) and at tau_next (the next frame, when this
// buffer is the older one). With `camera.viewport.z` = 1 the visibility pattern is anchored to
// the screen (lodkit::visibility::visibility_flags_screen: the texel under the pixel displayed
// now, and under the pixel the fragment is expected at next frame); with 0 it sticks to the
// object, looked up at the object-space position (the paper; visibility_flags). The combine pass
// then shows each LOD with its visibility at the frame displayed, so its share changes every
// frame, and a sample hidden in its buffer never leaves a hole where the other buffer has none.
// n-instances use id 0 (always shown). Location 2 gets the fragment's object motion
// (lodkit::lod_buffer::lod_buffer_motion): where its surface point was in the previous frame
// (previous model matrix and sway phase) minus where it is now, both seen by the previous
// camera; the combine reads the older buffer there.
//
// Entry points:
//   vs_main   @location(0) position, @location(1) normal (object space)
//   fs_main   LodBufferMotionOutput (location 0 color, location 1 r32uint id word, location 2
//             rg16float object motion; the depth attachment keeps the depth)
//   fs_level_depth  the older-level depth pass: the alpha test alone, no color target (the level
//             drawn whole, depth only, into LodBuffers::level_depth)
//   sway_offset(p, sway) -> vec3<f32>   helper: the wind sway of the vertex stage
// An alpha-tested LOD (a billboard impostor) discards what its mask does not cover
// (lodkit::alpha_mask) before anything is written.
//
// Bindings: group 0: 0 `camera: LodCamera` (uniform), 1 `vis_tex: texture_2d<f32>`,
//   2 `alpha_mask: texture_2d<f32>` (r32float, lodkit::alpha_mask);
//   group 1: 0 `draw: LodDraw` (uniform, dynamic offset).
// Shader defs: none.
#import lodkit::visibility::{visibility_flags, visibility_flags_screen, visibility_next_coord}
#import lodkit::alpha_mask::alpha_mask_keep
#import lodkit::lod_buffer::{LodBufferMotionOutput, LOD_BUFFER_SHOWN_NOW, LOD_BUFFER_SHOWN_NEXT, lod_buffer_output_motion, lod_buffer_motion}

/// Per-view data.
struct LodCamera {
    view_proj: mat4x4<f32>,
    /// The previous frame's view_proj (the same on a frame without one).
    prev_view_proj: mat4x4<f32>,
    /// World-space direction toward the light (w unused).
    light_dir: vec4<f32>,
    /// x, y: the framebuffer size in pixels; z: 1 = the visibility pattern anchored to the
    /// screen, 0 = in object space; w unused.
    viewport: vec4<f32>,
}

/// Per-draw data.
struct LodDraw {
    model: mat4x4<f32>,
    /// The previous frame's model (the same for an object that did not move).
    prev_model: mat4x4<f32>,
    color: vec4<f32>,
    /// 0 for n-instances.
    instance_id: u32,
    /// Visibility threshold this frame (lodkit::visibility::visibility_shown).
    tau: f32,
    /// Visibility texture repeats per object-space unit.
    vis_scale: f32,
    /// Visibility threshold of the same LOD in the next frame.
    tau_next: f32,
    /// Sway: x amplitude (object units at the top of a unit-high mesh, 0 = none), y phase,
    /// z the previous frame's phase.
    sway: vec4<f32>,
    /// Alpha mask rect (lodkit::alpha_mask; x == 0: no alpha test).
    alpha_rect: vec4<f32>,
}

@group(0) @binding(0) var<uniform> camera: LodCamera;
@group(0) @binding(1) var vis_tex: texture_2d<f32>;
@group(0) @binding(2) var alpha_mask: texture_2d<f32>;
@group(1) @binding(0) var<uniform> draw: LodDraw;

struct VertexOut {
    /// The older-level depth pass (fs_level_depth) runs this same vertex stage, so that it
    /// covers the pixels the LOD pass (fs_main) covers with the same level. Not `@invariant`:
    /// GLSL ES 3.0 (WebGL2) and MSL before 2.1 refuse it on this pass's targets; the same
    /// module and entry point in both pipelines is what the reference relies on.
    @builtin(position) position: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) object_pos: vec3<f32>,
    /// The surface point now and in the previous frame, in the previous frame's clip space.
    @location(2) now_clip: vec4<f32>,
    @location(3) then_clip: vec4<f32>,
}

/// Wind sway of an object-space position: along x, growing with height above the base (y = -1).
fn sway_offset(p: vec3<f32>, sway: vec2<f32>) -> vec3<f32> {
    return vec3<f32>(sway.x * max(p.y + 1.0, 0.0) * sin(sway.y + p.x + p.z), 0.0, 0.0);
}

/// Sways, transforms to clip space; hands the object-space position from before the sway and
/// the point now and in the previous frame, seen by the previous camera, to the fragment stage.
@vertex
fn vs_main(@location(0) position: vec3<f32>, @location(1) normal: vec3<f32>) -> VertexOut {
    let world = draw.model * vec4<f32>(position + sway_offset(position, draw.sway.xy), 1.0);
    let then = draw.prev_model * vec4<f32>(position + sway_offset(position, draw.sway.xz), 1.0);
    return VertexOut(
        camera.view_proj * world,
        (draw.model * vec4<f32>(normal, 0.0)).xyz,
        position,
        camera.prev_view_proj * world,
        camera.prev_view_proj * then,
    );
}

/// Alpha test, display-time visibility flags, Lambert shading, object motion, LOD buffer output.
@fragment
fn fs_main(in: VertexOut) -> LodBufferMotionOutput {
    if (!alpha_mask_keep(alpha_mask, in.object_pos, draw.alpha_rect)) {
        discard;
    }
    var flags = LOD_BUFFER_SHOWN_NOW | LOD_BUFFER_SHOWN_NEXT;
    if (draw.instance_id != 0u && camera.viewport.z > 0.5) {
        let next = visibility_next_coord(in.position.xy, in.then_clip, camera.viewport.xy);
        flags = visibility_flags_screen(vis_tex, in.position.xy, next, draw.tau, draw.tau_next);
    } else if (draw.instance_id != 0u) {
        flags = visibility_flags(vis_tex, in.object_pos * draw.vis_scale, draw.tau, draw.tau_next);
    }
    let lambert = max(dot(normalize(in.normal), normalize(camera.light_dir.xyz)), 0.0);
    let color = vec4<f32>(draw.color.rgb * (0.35 + 0.65 * lambert), 1.0);
    let motion = lod_buffer_motion(in.then_clip, in.now_clip);
    return lod_buffer_output_motion(color, draw.instance_id, flags, motion);
}

/// The older-level depth pass: the level whole (no visibility pattern), its alpha test, depth
/// only.
@fragment
fn fs_level_depth(in: VertexOut) {
    if (!alpha_mask_keep(alpha_mask, in.object_pos, draw.alpha_rect)) {
        discard;
    }
}
