// Broken only under PACKED and TONEMAP together: PACKED makes `v` a u32, and TONEMAP scales it
// by a float.
@fragment
fn fragment() -> @location(0) vec4<f32> {
#ifdef PACKED
    var v = 3u;
#else
    var v = 0.75;
#endif
#ifdef TONEMAP
    v = v * 0.5;
#endif
    return vec4<f32>(f32(v));
}
