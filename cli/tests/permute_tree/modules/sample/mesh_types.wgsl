// sample::mesh_types — what the vertex stage hands the fragment stage (a Bevy-style module).
#define_import_path sample::mesh_types

struct VertexOutput {
    @builtin(position) position: vec4<f32>,
    @location(0) world_normal: vec3<f32>,
#ifdef VERTEX_UVS
    @location(1) uv: vec2<f32>,
#endif
#ifdef SKINNED
    @location(2) @interpolate(flat) joint: u32,
#endif
}
