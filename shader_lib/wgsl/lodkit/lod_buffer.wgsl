// lodkit::lod_buffer — what a t-instance (or any object) writes into a LOD buffer for
// frame-sequential LOD (Scherzer & Wimmer 2008, sec. 3.2, 3.5).
//
// Two render targets and a depth attachment: location 0 color (the engine's own format, e.g.
// rgba8unorm), location 1 r32uint, the id word; each LOD buffer keeps its own depth attachment,
// which the combine pass reads as the fragment's clip depth (standard or reversed Z). The id word
// holds the instance id in bits 0..29 (id 0 means n-instance; ids are exact up to 2^30 - 1, the
// paper's 16-bit float id only to 2048) and two display-time visibility flags in bits 30 and 31:
// shown in the frame the buffer is rendered for (LOD_BUFFER_SHOWN_NOW) and in the next one, when
// it is the older buffer (LOD_BUFFER_SHOWN_NEXT). The combine pass shows a sample only in the
// frames its flag names; n-instances are always shown.
// Bytes per pixel per LOD buffer beyond its depth attachment: 4 (rgba8 color) + 4 (id word) = 8
// (the paper: 7, with a 16-bit depth in the target and an id exact to 2048).
// Objects that move or deform between frames (a t-instance on a moving platform, a plant in the
// wind) also write their object motion at location 2 (rg16float, one texture for the frame, not
// per buffer): where the fragment's surface point was in the previous frame minus where it is
// now, both projected with the previous frame's view-projection, in texture-space uv. It is 0
// for anything that did not move by itself (the camera's motion is the combine's reprojection),
// so the target is cleared to 0. The combine reads the older buffer there (combine_at_moved).
//
// Exports:
//   LodBufferOutput { color (location 0), id (location 1) }   fragment output
//   LOD_BUFFER_ID_MASK, LOD_BUFFER_SHOWN_NOW, LOD_BUFFER_SHOWN_NEXT: u32   id bits, flags
//   lod_buffer_output(color, instance_id, depth) -> LodBufferOutput   shown in both frames
//       (depth is kept by the depth attachment; the parameter is not stored)
//   lod_buffer_output_flags(color, instance_id, flags) -> LodBufferOutput
//   lod_buffer_id(word) -> u32, lod_buffer_flags(word) -> u32   unpacking the id word
//   lod_buffer_shown(word, flag) -> bool   n-instance, or the flag is set
//   LodBufferMotionOutput { color (location 0), id (location 1), motion (location 2) }
//   lod_buffer_output_motion(color, instance_id, flags, motion) -> LodBufferMotionOutput
//   lod_buffer_motion(then_clip, now_clip) -> vec2<f32>   object motion from the fragment's
//       surface point in the previous frame and now, both in the previous frame's clip space
//       (0 when either lies behind that camera)
// Usage: return lod_buffer_output(shaded, draw.instance_id, in.position.z); or with
//   lodkit::visibility::visibility_flags for display-time visibility, and lod_buffer_motion for
//   moving objects (passes/lod_buffer_mesh.wgsl).
// Shader defs: none.
#define_import_path lodkit::lod_buffer

/// Fragment output of a LOD buffer pass.
struct LodBufferOutput {
    @location(0) color: vec4<f32>,
    @location(1) id: u32,
}

/// Bits of the id word that hold the instance id (ids exact up to 2^30 - 1).
const LOD_BUFFER_ID_MASK: u32 = 0x3fffffffu;
/// Flag: the fragment is shown in the frame its buffer is rendered for.
const LOD_BUFFER_SHOWN_NOW: u32 = 1u;
/// Flag: the fragment is shown in the next frame, when its buffer is the older one.
const LOD_BUFFER_SHOWN_NEXT: u32 = 2u;

/// Packs `color`, `instance_id` (bits above 29 are dropped) and the display-time `flags`
/// (LOD_BUFFER_SHOWN_NOW | LOD_BUFFER_SHOWN_NEXT, e.g. from visibility_flags).
fn lod_buffer_output_flags(color: vec4<f32>, instance_id: u32, flags: u32) -> LodBufferOutput {
    return LodBufferOutput(color, (instance_id & LOD_BUFFER_ID_MASK) | ((flags & 3u) << 30u));
}

/// Packs `color` and `instance_id` (0 = n-instance), shown in both frames (the fragment stage
/// discards what is not shown, as in the paper). The depth attachment keeps the fragment's
/// depth; `depth` is not stored.
fn lod_buffer_output(color: vec4<f32>, instance_id: u32, depth: f32) -> LodBufferOutput {
    return lod_buffer_output_flags(color, instance_id, LOD_BUFFER_SHOWN_NOW | LOD_BUFFER_SHOWN_NEXT);
}

/// Instance id of an id word.
fn lod_buffer_id(word: u32) -> u32 {
    return word & LOD_BUFFER_ID_MASK;
}

/// Display-time flags of an id word (LOD_BUFFER_SHOWN_NOW, LOD_BUFFER_SHOWN_NEXT).
fn lod_buffer_flags(word: u32) -> u32 {
    return word >> 30u;
}

/// Whether a texel is shown in the frame `flag` names: always for n-instances (id 0).
fn lod_buffer_shown(word: u32, flag: u32) -> bool {
    return lod_buffer_id(word) == 0u || (lod_buffer_flags(word) & flag) != 0u;
}

/// Fragment output of a LOD buffer pass whose objects may move by themselves.
struct LodBufferMotionOutput {
    @location(0) color: vec4<f32>,
    @location(1) id: u32,
    @location(2) motion: vec2<f32>,
}

/// lod_buffer_output_flags with the fragment's object motion (from lod_buffer_motion).
fn lod_buffer_output_motion(color: vec4<f32>, instance_id: u32, flags: u32, motion: vec2<f32>) -> LodBufferMotionOutput {
    let o = lod_buffer_output_flags(color, instance_id, flags);
    return LodBufferMotionOutput(o.color, o.id, motion);
}

/// Object motion of a fragment in texture-space uv: `then_clip` (its surface point in the
/// previous frame) minus `now_clip` (the point now), both projected with the previous frame's
/// view-projection and interpolated from the vertex stage; 0 when either has w <= 0.
fn lod_buffer_motion(then_clip: vec4<f32>, now_clip: vec4<f32>) -> vec2<f32> {
    if (then_clip.w <= 0.0 || now_clip.w <= 0.0) {
        return vec2<f32>(0.0);
    }
    return (then_clip.xy / then_clip.w - now_clip.xy / now_clip.w) * vec2<f32>(0.5, -0.5);
}
