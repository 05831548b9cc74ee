// The main-pass fragment shader of lodkit_bevy's FrameSequentialMaterial: Bevy's StandardMaterial
// shading, unchanged (pbr_input_from_standard_material, apply_pbr_lighting,
// main_pass_post_lighting_processing), with the fragment's LOD-buffer id word in alpha
// (lodkit_bevy::frame_sequential::lod_fragment_alpha). The prepass is StandardMaterial's own.
#import bevy_pbr::{
    forward_io::{VertexOutput, FragmentOutput},
    mesh_functions::{get_tag, get_local_from_world},
    mesh_view_bindings::view,
    pbr_fragment::pbr_input_from_standard_material,
    pbr_functions::{alpha_discard, apply_pbr_lighting, main_pass_post_lighting_processing},
    pbr_types::STANDARD_MATERIAL_FLAGS_UNLIT_BIT,
}
#ifdef MOTION_VECTOR_PREPASS
#import bevy_pbr::prepass_utils::prepass_motion_vector
#endif
#import lodkit_bevy::frame_sequential::lod_fragment_alpha

@group(#{MATERIAL_BIND_GROUP}) @binding(100) var lodkit_visibility: texture_2d<f32>;
@group(#{MATERIAL_BIND_GROUP}) @binding(101) var<uniform> lodkit_pattern_scale: vec4<f32>;

@fragment
fn fragment(in: VertexOutput, @builtin(front_facing) is_front: bool) -> FragmentOutput {
    var pbr_input = pbr_input_from_standard_material(in, is_front);
    pbr_input.material.base_color = alpha_discard(pbr_input.material, pbr_input.material.base_color);
    var out: FragmentOutput;
    if (pbr_input.material.flags & STANDARD_MATERIAL_FLAGS_UNLIT_BIT) == 0u {
        out.color = apply_pbr_lighting(pbr_input);
    } else {
        out.color = pbr_input.material.base_color;
    }
    out.color = main_pass_post_lighting_processing(pbr_input, out.color);

    // Where this fragment is expected next frame: as far again as it moved since the last one
    // (Bevy's motion vector: uv now minus uv then).
    var next = in.position.xy;
#ifdef MOTION_VECTOR_PREPASS
    next = in.position.xy + prepass_motion_vector(in.position, 0u) * view.viewport.zw;
#endif
    let object_pos = (get_local_from_world(in.instance_index) * vec4<f32>(in.world_position.xyz, 1.0)).xyz;
    let tag = get_tag(in.instance_index);
    out.color.a = lod_fragment_alpha(lodkit_visibility, tag, in.position.xy, next, object_pos * lodkit_pattern_scale.x);
    return out;
}
