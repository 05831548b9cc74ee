// A Bevy-style material shader: one entry point, its features switched by shader defs.
#import sample::mesh_types::VertexOutput
#import sample::lighting::light_falloff
#ifdef SHADOWS
#import sample::lighting::shadow
#endif
#import lodkit::screen_door::screen_door_keep

@group(0) @binding(0) var base_color: texture_2d<f32>;
@group(0) @binding(1) var base_sampler: sampler;

@fragment
fn fragment(in: VertexOutput) -> @location(0) vec4<f32> {
    var color = vec4<f32>(0.8, 0.8, 0.8, 1.0);
#ifdef VERTEX_UVS
    color *= textureSample(base_color, base_sampler, in.uv);
#endif
#ifdef ALPHA_MASK
    if !screen_door_keep(in.position.xy, color.a) {
        discard;
    }
#endif
    var light = 0.0;
    for (var i = 0u; i < 2u; i++) {
        light += light_falloff(in.world_normal, i);
    }
#ifdef SHADOWS
    light *= shadow(in.position.z);
#endif
#ifdef MESH_PIPELINE
    color = vec4<f32>(color.rgb * light, color.a);
#endif
    return color;
}
