// passes/gbuffer_mesh — a mesh drawn into the low-resolution buffer of framebuffer LOD (or into a
// full-resolution reference or depth/normal prepass): color plus (view depth, screen-space
// normal) through lodkit::gbuffer.
//
// The shading has a high-frequency but smooth term (a procedural stripe pattern in object space
// over Lambert lighting), the kind of detail resizing blurs and bilateral upsampling keeps from
// bleeding across silhouettes and creases. `camera.light_dir.w` adds synthetic shading cost: that
// many directions of a smooth sky term (0: a constant ambient), standing in for the expensive,
// low-frequency shading that framebuffer LOD saves.
//
// Entry points:
//   vs_main   @location(0) position, @location(1) normal (object space)
//   fs_main   GBufferOutput (location 0 color, location 1 rgba16float geometry); with
//             GBUFFER_MESH_PACKED, location 0 the packed rgba32uint texel
//   (shade    the color and view-space normal both forms of fs_main write)
// Bindings: group 0: 0 `camera: GCamera` (uniform); group 1: 0 `draw: GDraw` (uniform, dynamic
// offset).
// Shader defs: (with neither set, color is the full shading, albedo x lighting)
//   GBUFFER_MESH_LIGHTING_ONLY (bool) — color holds only the lighting term (smooth: the part
//   worth resizing).
//   GBUFFER_MESH_ALBEDO_ONLY (bool) — color holds only the striped albedo (detailed, cheap at full
//   resolution). Fine-grained resizing (sec. 2.3) upsamples the first and multiplies by the second.
//   GBUFFER_MESH_PACKED (bool) — one rgba32uint target at location 0: lodkit::gbuffer's packed
//   texel (gbuffer_pack_texel) instead of color and geometry.
#import lodkit::gbuffer::{GBufferOutput, gbuffer_output, gbuffer_pack_texel}

/// Per-view data.
struct GCamera {
    view_proj: mat4x4<f32>,
    view: mat4x4<f32>,
    /// xyz: world-space direction toward the light; w: sky directions to sum (0: none).
    light_dir: vec4<f32>,
}

/// Per-draw data.
struct GDraw {
    model: mat4x4<f32>,
    color: vec4<f32>,
}

@group(0) @binding(0) var<uniform> camera: GCamera;
@group(1) @binding(0) var<uniform> draw: GDraw;

struct VertexOut {
    @builtin(position) position: vec4<f32>,
    @location(0) world_normal: vec3<f32>,
    @location(1) view_pos: vec3<f32>,
    @location(2) object_pos: vec3<f32>,
}

/// Transforms to clip and view space.
@vertex
fn vs_main(@location(0) position: vec3<f32>, @location(1) normal: vec3<f32>) -> VertexOut {
    let world = draw.model * vec4<f32>(position, 1.0);
    let view_pos = (camera.view * world).xyz;
    return VertexOut(camera.view_proj * world, (draw.model * vec4<f32>(normal, 0.0)).xyz, view_pos, position);
}

/// What the fragment writes: the color and the view-space normal.
struct Shaded {
    color: vec3<f32>,
    view_normal: vec3<f32>,
}

/// The lighting term: Lambert plus `camera.light_dir.w` directions of a smooth sky (the synthetic
/// shading cost), or a constant ambient when that is 0.
fn lighting(n: vec3<f32>) -> vec3<f32> {
    let lambert = max(dot(n, normalize(camera.light_dir.xyz)), 0.0);
    let work = u32(max(camera.light_dir.w, 0.0));
    var sky = 0.0;
    for (var k = 0u; k < work; k++) {
        let a = f32(k) * 2.399963;
        sky += max(dot(n, normalize(vec3<f32>(cos(a), 1.0, sin(a)))), 0.0);
    }
    let ambient = select(0.3, 0.45 * sky / f32(max(work, 1u)), work > 0u);
    return vec3<f32>(ambient + 0.7 * lambert);
}

/// The striped albedo (object-space stripes over the draw's color).
fn albedo(in: VertexOut) -> vec3<f32> {
    let stripes = 0.5 + 0.5 * sin(18.0 * (in.object_pos.x + in.object_pos.y));
    return draw.color.rgb * (0.6 + 0.4 * stripes);
}

/// Stripes over Lambert, or one of the two terms alone. Each variant computes only the term it
/// writes: the albedo variant, drawn at full resolution beside a low-resolution lighting pass,
/// must not pay for the lighting it would throw away (a compiler that keeps a loop whose result
/// is unused, as NVIDIA's does, would otherwise time the sky loop in it).
fn shade(in: VertexOut) -> Shaded {
    let n = normalize(in.world_normal);
    var color: vec3<f32>;
#ifdef GBUFFER_MESH_LIGHTING_ONLY
    color = lighting(n);
#else ifdef GBUFFER_MESH_ALBEDO_ONLY
    color = albedo(in);
#else
    color = albedo(in) * lighting(n);
#endif
    return Shaded(color, normalize((camera.view * vec4<f32>(n, 0.0)).xyz));
}

#ifdef GBUFFER_MESH_PACKED
/// Stripes over Lambert; writes color, view depth and the screen-space normal.
@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<u32> {
    let s = shade(in);
    return gbuffer_pack_texel(vec4<f32>(s.color, 1.0), -in.view_pos.z, s.view_normal);
}
#else
/// Stripes over Lambert; writes color, view depth and the screen-space normal.
@fragment
fn fs_main(in: VertexOut) -> GBufferOutput {
    let s = shade(in);
    return gbuffer_output(vec4<f32>(s.color, 1.0), -in.view_pos.z, s.view_normal);
}
#endif
