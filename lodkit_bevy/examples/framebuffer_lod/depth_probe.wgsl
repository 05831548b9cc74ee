// The framebuffer_lod example's depth probe: replaces the image with log2(1 + view depth) / 16 in
// red (composited `Over` with alpha 1, at r = 1, no tonemapping), so the example can find depth
// discontinuities in a captured frame.
#import bevy_core_pipeline::fullscreen_vertex_shader::FullscreenVertexOutput
#import lodkit::gbuffer::GBufferOutput
#import lodkit_bevy::framebuffer_lod::{effect_sample, effect_output}

@fragment
fn fragment(in: FullscreenVertexOutput) -> GBufferOutput {
    let s = effect_sample(in.position);
    let encoded = clamp(log2(1.0 + s.view_depth) / 16.0, 0.0, 1.0);
    return effect_output(vec4<f32>(encoded, 0.0, 0.0, 1.0), s);
}
