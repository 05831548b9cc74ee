// Broken only under ALPHA_MASK without VERTEX_UVS: `uv` is defined inside `#ifdef VERTEX_UVS`
// and used outside it (the bug class of Bevy #8409 and #18600).
#import sample::mesh_types::VertexOutput

@fragment
fn fragment(in: VertexOutput) -> @location(0) vec4<f32> {
    var color = vec4<f32>(1.0);
#ifdef VERTEX_UVS
    let uv = in.uv;
    color.r = uv.x;
#endif
#ifdef ALPHA_MASK
    color.a = uv.y;
#endif
    return color;
}
