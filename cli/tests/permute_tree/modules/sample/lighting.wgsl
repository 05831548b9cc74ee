// sample::lighting — lights and shadow cascades; MAX_LIGHTS and MAX_CASCADES_PER_LIGHT are
// valued defs the pipeline sets.
#define_import_path sample::lighting

const MAX_LIGHTS: u32 = #{MAX_LIGHTS}u;

fn light_falloff(n: vec3<f32>, i: u32) -> f32 {
    let l = normalize(vec3<f32>(f32(i) + 1.0, 1.0, 0.5));
    return max(dot(n, l), 0.0) / f32(MAX_LIGHTS);
}

#ifdef SHADOWS
const MAX_CASCADES: u32 = #{MAX_CASCADES_PER_LIGHT}u;

fn shadow(depth: f32) -> f32 {
    var lit = 0.0;
    for (var c = 0u; c < MAX_CASCADES; c++) {
        lit += step(depth, f32(c + 1u) / f32(MAX_CASCADES));
    }
    return lit / f32(MAX_CASCADES);
}
#endif
