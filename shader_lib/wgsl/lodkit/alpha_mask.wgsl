// lodkit::alpha_mask — alpha-tested LODs (billboard impostors, foliage cards) in every LOD
// technique: a coverage mask looked up at the fragment's object-space position, so the test
// sticks to the object as the visibility pattern does (Scherzer & Wimmer 2008, sec. 1: masked
// and impostor LODs; sec. 3.3: object space).
//
// The mask is a single-channel float texture (a texel >= 0.5 is covered), read with textureLoad:
// no sampler, no derivatives, so shadow and depth-only passes can use it. `rect` maps object
// space into it: uv = p.xy * rect.xy + rect.zw (texture space, row 0 at the top); rect.x == 0
// means the draw has no mask. One texture can hold several masks (an atlas): each draw's rect
// maps into its own part.
//
// Exports:
//   alpha_mask_uv(p, rect) -> vec2<f32>   mask uv of object-space position p
//   alpha_mask_inside(uv) -> bool   uv within [0, 1)
//   alpha_mask_texel(uv, size) -> vec2<u32>   the texel of a `size` mask at uv (clamped)
//   alpha_mask_keep(mask, p, rect) -> bool   whether the fragment survives the alpha test:
//       always without a mask (rect.x == 0); else inside the mask and its texel >= 0.5
// Usage (fragment stage): if (!alpha_mask_keep(mask_tex, in.object_pos, draw.alpha_rect)) { discard; }
// Shader defs: none.
#define_import_path lodkit::alpha_mask

/// Mask uv (texture space) of object-space position `p`: p.xy * rect.xy + rect.zw.
fn alpha_mask_uv(p: vec3<f32>, rect: vec4<f32>) -> vec2<f32> {
    return p.xy * rect.xy + rect.zw;
}

/// Whether `uv` lies within the mask, [0, 1) on both axes.
fn alpha_mask_inside(uv: vec2<f32>) -> bool {
    return all(uv >= vec2<f32>(0.0)) && all(uv < vec2<f32>(1.0));
}

/// The texel of a `size` mask at `uv` (clamped to the mask).
fn alpha_mask_texel(uv: vec2<f32>, size: vec2<u32>) -> vec2<u32> {
    let inside = clamp(uv, vec2<f32>(0.0), vec2<f32>(1.0));
    return min(vec2<u32>(inside * vec2<f32>(size)), size - vec2<u32>(1u));
}

/// Whether the fragment at object-space `p` survives the alpha test of `mask` mapped by `rect`:
/// always when rect.x == 0 (no mask); else when `p` maps inside the mask onto a texel >= 0.5.
fn alpha_mask_keep(mask: texture_2d<f32>, p: vec3<f32>, rect: vec4<f32>) -> bool {
    if (rect.x == 0.0) {
        return true;
    }
    let uv = alpha_mask_uv(p, rect);
    if (!alpha_mask_inside(uv)) {
        return false;
    }
    return textureLoad(mask, alpha_mask_texel(uv, textureDimensions(mask, 0)), 0).x >= 0.5;
}
