// lodkit_bevy::framebuffer_lod — what an effect shader of `FramebufferLod` imports: the bindings
// of the low-resolution effect pass and the geometry of the pixel it shades (Yang, Sander &
// Lawrence 2008, sec. 2.1: the low-resolution pass writes color, depth and normal).
//
// The effect runs at 1/r resolution: one fragment per low-resolution pixel, drawn through a
// viewport of `settings.low_size` pixels. Each fragment shades the scene at one full-resolution
// pixel of Bevy's prepass (`effect_sample`) and returns `effect_output(color, sample)`, which also
// stores that pixel's view depth and view-space normal for lodkit's bilateral upsample (eq. 1).
//
// Bindings (group 0): 0 view: View, 1 globals: Globals, 2 depth_prepass: texture_depth_2d,
//   3 normal_prepass: texture_2d<f32> (world normal * 0.5 + 0.5), 4 settings: FramebufferLodSettings.
// Exports:
//   FramebufferLodSettings, the bindings above
//   EffectSample { pixel, uv, ndc_depth, view_depth, world_position, world_normal, view_normal, sky }
//   effect_sample(frag_coord) -> EffectSample   the full-res pixel under a low-res fragment
//   full_sample(pixel) -> EffectSample          a full-res pixel's own geometry
//   effect_output(color, sample) -> GBufferOutput
//   effect_param(i) -> vec4<f32>                the camera's `FramebufferLod::params[i]`
// Shader defs: none.
#define_import_path lodkit_bevy::framebuffer_lod
#import bevy_render::view::View
#import bevy_render::globals::Globals
#import lodkit::gbuffer::{GBufferOutput, gbuffer_output}

/// Per-camera settings (mirrors `FramebufferLodUniform` in render.rs).
struct FramebufferLodSettings {
    /// Pixels of the low-resolution viewport this frame: ceil(full_size / r).
    low_size: vec2<f32>,
    /// Pixels of the camera's viewport.
    full_size: vec2<f32>,
    /// The resize factor r of this frame.
    factor: f32,
    /// Depth range sigma as a fraction of the pixel's view depth (+inf: no depth term).
    depth_sigma: f32,
    /// Normal range sigma on the foreshortened normal distance (+inf: no normal term).
    normal_sigma: f32,
    /// View depth given to the sky (no geometry in the prepass).
    sky_depth: f32,
    /// The camera's `FramebufferLod::params`.
    params: array<vec4<f32>, 2>,
}

@group(0) @binding(0) var<uniform> view: View;
@group(0) @binding(1) var<uniform> globals: Globals;
@group(0) @binding(2) var depth_prepass: texture_depth_2d;
@group(0) @binding(3) var normal_prepass: texture_2d<f32>;
@group(0) @binding(4) var<uniform> settings: FramebufferLodSettings;

/// The geometry of one full-resolution pixel, read from Bevy's prepass.
struct EffectSample {
    /// The full-resolution pixel.
    pixel: vec2<u32>,
    /// Its center in the camera's uv space ((0, 0) top left).
    uv: vec2<f32>,
    /// Prepass depth (reverse-Z: 1 near, 0 at infinity).
    ndc_depth: f32,
    /// Distance along the view direction (world units); `settings.sky_depth` for the sky.
    view_depth: f32,
    /// World position of the surface (for the sky: at `sky_depth` along the pixel's ray).
    world_position: vec3<f32>,
    /// World-space normal ((0, 0, 0) for the sky).
    world_normal: vec3<f32>,
    /// View-space normal ((0, 0, 1) faces the camera; (0, 0, 1) for the sky).
    view_normal: vec3<f32>,
    /// Whether no geometry covers the pixel.
    sky: bool,
}

/// The geometry of the full-resolution pixel `pixel`.
fn full_sample(pixel: vec2<u32>) -> EffectSample {
    let uv = (vec2<f32>(pixel) + 0.5) / settings.full_size;
    let ndc_depth = textureLoad(depth_prepass, pixel, 0);
    let sky = ndc_depth <= 0.0;
    // Depth along -z from the inverse projection; the sky sits at sky_depth.
    let ndc_xy = uv * vec2<f32>(2.0, -2.0) + vec2<f32>(-1.0, 1.0);
    let clip = select(ndc_depth, 1e-7, sky);
    let v = view.view_from_clip * vec4<f32>(ndc_xy, clip, 1.0);
    let view_position = v.xyz / v.w;
    let view_depth = select(min(-view_position.z, settings.sky_depth), settings.sky_depth, sky);
    let ray = view_position / max(-view_position.z, 1e-6);
    let world = (view.world_from_view * vec4<f32>(ray * view_depth, 1.0)).xyz;
    let encoded = textureLoad(normal_prepass, pixel, 0);
    let world_normal = select(normalize(encoded.xyz * 2.0 - 1.0), vec3<f32>(0.0), sky || encoded.w == 0.0);
    let view_normal = select(
        normalize((view.view_from_world * vec4<f32>(world_normal, 0.0)).xyz),
        vec3<f32>(0.0, 0.0, 1.0),
        sky || encoded.w == 0.0,
    );
    return EffectSample(pixel, uv, ndc_depth, view_depth, world, world_normal, view_normal, sky);
}

/// The full-resolution pixel a low-resolution fragment at `frag_coord` shades: the one under the
/// center of the low-resolution pixel.
fn effect_sample(frag_coord: vec4<f32>) -> EffectSample {
    let full = floor(frag_coord.xy * settings.full_size / settings.low_size);
    let pixel = vec2<u32>(min(full, settings.full_size - 1.0));
    return full_sample(pixel);
}

/// What the effect's fragment stage returns: its color (premultiplied alpha for
/// `FramebufferLodComposite::Over`, a factor for `Modulate`) and the sample's geometry.
fn effect_output(color: vec4<f32>, sample: EffectSample) -> GBufferOutput {
    return gbuffer_output(color, sample.view_depth, sample.view_normal);
}

/// The camera's `FramebufferLod::params[i]` (i = 0 or 1).
fn effect_param(i: u32) -> vec4<f32> {
    return settings.params[min(i, 1u)];
}
