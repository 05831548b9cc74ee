// The framebuffer_lod example's expensive effect: single-scattering height fog, ray-marched from
// the camera to the surface (or 80 m into the sky) in `effect_param(0u).x` steps through a
// density with low-frequency value noise. Composited `Over`: it returns the in-scattered light
// and 1 - transmittance, premultiplied.
//
// params[0] = (steps, density, fog height, noise amount); params[1] = (sun direction xyz,
// factor). With factor = 1 it returns the transmittance as a factor instead (composited
// `Modulate`, a stand-in for an ambient-occlusion term: fine-grained resizing).
#import bevy_core_pipeline::fullscreen_vertex_shader::FullscreenVertexOutput
#import lodkit::gbuffer::GBufferOutput
#import lodkit_bevy::framebuffer_lod::{view, effect_sample, effect_output, effect_param}

const MAX_DISTANCE: f32 = 80.0;
const SUN: vec3<f32> = vec3<f32>(1.6, 1.35, 1.0);
const SKY: vec3<f32> = vec3<f32>(0.32, 0.38, 0.48);

fn hash(p: vec3<f32>) -> f32 {
    return fract(sin(dot(p, vec3<f32>(127.1, 311.7, 74.7))) * 43758.5453);
}

// Smooth value noise in [0, 1].
fn noise(p: vec3<f32>) -> f32 {
    let i = floor(p);
    let f = p - i;
    let u = f * f * (3.0 - 2.0 * f);
    let a = mix(hash(i), hash(i + vec3(1.0, 0.0, 0.0)), u.x);
    let b = mix(hash(i + vec3(0.0, 1.0, 0.0)), hash(i + vec3(1.0, 1.0, 0.0)), u.x);
    let c = mix(hash(i + vec3(0.0, 0.0, 1.0)), hash(i + vec3(1.0, 0.0, 1.0)), u.x);
    let d = mix(hash(i + vec3(0.0, 1.0, 1.0)), hash(i + vec3(1.0, 1.0, 1.0)), u.x);
    return mix(mix(a, b, u.y), mix(c, d, u.y), u.z);
}

@fragment
fn fragment(in: FullscreenVertexOutput) -> GBufferOutput {
    let s = effect_sample(in.position);
    let p = effect_param(0u);
    let steps = max(u32(p.x), 1u);
    let sun_dir = normalize(effect_param(1u).xyz);
    let origin = view.world_position;
    let to_surface = s.world_position - origin;
    let length_total = min(length(to_surface), MAX_DISTANCE);
    let dir = to_surface / max(length(to_surface), 1e-6);
    let dt = length_total / f32(steps);
    // Henyey-Greenstein-like forward scattering toward the sun.
    let g = 0.5;
    let cos_theta = dot(dir, sun_dir);
    let phase = (1.0 - g * g) / pow(1.0 + g * g - 2.0 * g * cos_theta, 1.5) * 0.25;
    var transmittance = 1.0;
    var light = vec3<f32>(0.0);
    for (var i = 0u; i < steps; i++) {
        let x = origin + dir * ((f32(i) + 0.5) * dt);
        let height = exp(-max(x.y, 0.0) / p.z);
        let density = p.y * height * (1.0 - p.w + p.w * noise(x * 0.12));
        let absorbed = 1.0 - exp(-density * dt);
        light += transmittance * absorbed * (SUN * phase + SKY);
        transmittance *= 1.0 - absorbed;
    }
    if effect_param(1u).w > 0.5 {
        return effect_output(vec4<f32>(vec3<f32>(0.25 + 0.75 * transmittance), 1.0), s);
    }
    return effect_output(vec4<f32>(light, 1.0 - transmittance), s);
}
