// Fragment shader of `LodDitherMaterial` (src/main.rs): one discrete LOD of a group, drawn through
// lodkit's complementary screen-door pattern.
//
// Every level of a LOD group gets its own material with a signed alpha from
// `LodSelection::screen_door_alphas()`: the outgoing level -(1 - t), the incoming level +t, a
// settled level 1. A negative alpha selects the inverted pattern, so during a transition the two
// levels keep disjoint pixel sets whose union is every pixel: no blending, no sorting, no
// see-through, and the depth buffer stays valid.
//
// `lodkit::screen_door` resolves because main.rs registers every lodkit WGSL module as a Shader
// asset; Bevy says nothing when a module is missing (the pipeline just never becomes ready).

#import bevy_pbr::forward_io::VertexOutput
#import bevy_pbr::mesh_view_bindings::lights
#import lodkit::screen_door::screen_door_keep

// Mirrors `LodDitherParams` (a `ShaderType`) in main.rs.
struct LodDitherParams {
    // Linear RGB of this level (alpha unused).
    color: vec4<f32>,
    // Signed screen-door alpha: -(1 - t) outgoing, +t incoming, 1 when settled.
    alpha: f32,
}

@group(#{MATERIAL_BIND_GROUP}) @binding(0) var<uniform> lod_dither: LodDitherParams;

@fragment
fn fragment(mesh: VertexOutput) -> @location(0) vec4<f32> {
    // The whole technique: keep this fragment or leave the pixel to the other level.
    if !screen_door_keep(mesh.position.xy, lod_dither.alpha) {
        discard;
    }

    // Minimal Lambert shading from the scene's first directional light, so the strip shows
    // the shapes of the two levels; the technique does not depend on it.
    var to_light = normalize(vec3<f32>(0.4, 0.8, 0.6));
    if lights.n_directional_lights > 0u {
        to_light = lights.directional_lights[0].direction_to_light;
    }
    let lambert = max(dot(normalize(mesh.world_normal), to_light), 0.0);
    return vec4<f32>(lod_dither.color.rgb * (0.25 + 0.75 * lambert), 1.0);
}
