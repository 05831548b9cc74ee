// Broken only under SHADOWS: `#{MAX_CASCADES_PER_LIGHT}` is left unsubstituted when the
// pipeline does not set it (the bug class of Bevy #7375).
@fragment
fn fragment(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    var lit = 1.0;
#ifdef SHADOWS
    let cascades = #{MAX_CASCADES_PER_LIGHT}u;
    lit = 1.0 / f32(cascades);
#endif
    return vec4<f32>(lit);
}
