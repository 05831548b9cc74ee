// A Bevy-style prepass: writes normals, and discards masked fragments.
#import sample::mesh_types::VertexOutput

@group(0) @binding(0) var base_color: texture_2d<f32>;
@group(0) @binding(1) var base_sampler: sampler;

@fragment
fn fragment(in: VertexOutput) -> @location(0) vec4<f32> {
#ifdef ALPHA_MASK
    let alpha = textureSample(base_color, base_sampler, in.uv).a;
    if alpha < 0.5 {
        discard;
    }
#endif
#ifdef SKINNED
    let joint = f32(in.joint) * 0.0;
#else
    let joint = 0.0;
#endif
    return vec4<f32>(normalize(in.world_normal) * 0.5 + 0.5 + joint, 1.0);
}
