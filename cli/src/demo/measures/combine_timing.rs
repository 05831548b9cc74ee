//! The frame-sequential combine's cost as a ratio against plain passes reading the same
//! textures (see [`crate::demo::measures::upsample_timing`] for how pairs are timed): the combine with object motion, its
//! load floors, and the combine of buffers without object motion.

use glam::{Mat4, Vec3, Vec4};

use crate::demo::fixtures::clock::{Record, Timer};
use crate::demo::fixtures::edge_frame::FORMAT;
use crate::demo::measures::reads::{Reads, Texels};
use crate::demo::measures::upsample_timing::{PassRatio, Side, plain_pass_with, record_fullscreen};
use lodkit::gpu::frame_sequential::{
    CombineCoverage, CombineFrame, CombinePass, CombinePassDescriptor, CombineRegions,
    LOD_DEPTH_FORMAT, LodBuffers,
};
use lodkit::gpu::resources::{one_group_layout, texture_2d, textures_and_uniform};
use lodkit::gpu::{GpuContext, GpuError};
use lodkit::lod_buffer::{ID_FORMAT, MOTION_FORMAT};
use lodkit::reproject::new_to_old_matrix;
use lodkit::visibility::{VisibilityPattern, visibility_texture};
use lodkit_scenes::lod_buffer::{LodBufferFrame, LodBufferRenderer, LodDrawItem};
use lodkit_scenes::mesh::{GpuMesh, Mesh};

/// A fullscreen pass reading color, id word and depth of both buffers and, with `motion`, the
/// object motion at the pixel, summed so none is optimized away; `$depth` adds more to the depth
/// sum.
macro_rules! buffer_reads {
    ($depth:literal) => {
        buffer_reads!(
            "\n@group(0) @binding(6) var g: texture_2d<f32>;",
            $depth,
            "textureLoad(g, p, 0).xy"
        )
    };
    (still) => {
        buffer_reads!("", "", "vec2<f32>(0.0)")
    };
    ($motion_binding:literal, $depth:literal, $motion:literal) => {
        concat!(
            "#import lodkit::fullscreen::{FullscreenVertex, fullscreen_vertex}
@group(0) @binding(0) var a: texture_2d<f32>;
@group(0) @binding(1) var b: texture_2d<u32>;
@group(0) @binding(2) var c: texture_2d<f32>;
@group(0) @binding(3) var d: texture_2d<f32>;
@group(0) @binding(4) var e: texture_2d<u32>;
@group(0) @binding(5) var f: texture_2d<f32>;",
            $motion_binding,
            "
@vertex fn vs_main(@builtin(vertex_index) i: u32) -> FullscreenVertex { return fullscreen_vertex(i); }
@fragment fn fs_main(v: FullscreenVertex) -> @location(0) vec4<f32> {
    let p = vec2<u32>(v.position.xy);
    let ids = textureLoad(b, p, 0).x ^ textureLoad(e, p, 0).x;
    let depth = textureLoad(c, p, 0).x + textureLoad(f, p, 0).x",
            $depth,
            ";
    let motion = ",
            $motion,
            ";
    return textureLoad(a, p, 0) + textureLoad(d, p, 0) + vec4<f32>(f32(ids & 1u), depth, motion);
}
"
        )
    };
}

/// The seven textures the combine reads, each once at the pixel: the combine's baseline.
const COPY7: &str = buffer_reads!("");

/// The combine's main-path loads without its arithmetic: COPY7 and the older depth once more
/// (the combine's first estimate), at a neighbouring texel: the floor of any combine.
const LOADS8: &str =
    buffer_reads!(" + textureLoad(f, min(p + 1u, textureDimensions(f, 0) - 1u), 0).x");

/// LOADS8 and the four older-id loads the combine makes under its id-mismatch branch (three side
/// texels and the matched one), all made for every pixel: on a GPU that runs both sides of a
/// divergent branch under a mask (llvmpipe), the floor of the combine as it is written.
const LOADS12: &str = buffer_reads!(
    " + textureLoad(f, min(p + 1u, textureDimensions(f, 0) - 1u), 0).x
        + f32((textureLoad(e, min(p + vec2<u32>(1u, 0u), textureDimensions(e, 0) - 1u), 0).x
        ^ textureLoad(e, min(p + vec2<u32>(0u, 1u), textureDimensions(e, 0) - 1u), 0).x
        ^ textureLoad(e, min(p + 1u, textureDimensions(e, 0) - 1u), 0).x
        ^ textureLoad(e, min(p + vec2<u32>(2u, 0u), textureDimensions(e, 0) - 1u), 0).x) & 1u)"
);

/// The six textures the combine of buffers without object motion reads, each once at the
/// pixel: its baseline.
const COPY6: &str = buffer_reads!(still);

/// The combine pass against a plain pass reading the same seven textures (color, id and depth of
/// each buffer, the object motion) at `size` x `size`, on two LOD buffers of a grid of spheres
/// and boxes with a third of them in transition and the camera moved between the frames; then,
/// against the same baseline, the combine's eight main-path loads alone (its floor), and those
/// with the four loads of its id-mismatch branch all made (its floor where both sides of a
/// divergent branch run). Last, the combine of the same frames in buffers without object motion
/// (`combine_at`, `LODKIT_COMBINE_STILL`) against a plain pass reading its six textures.
pub fn combine_vs_copy(
    gpu: &GpuContext,
    timer: &Timer,
    size: u32,
    pairs: usize,
) -> Result<[PassRatio; 4], GpuError> {
    let buffers = LodBuffers::new(gpu, size, size, FORMAT)?;
    let still = LodBuffers::without_motion(gpu, size, size, FORMAT)?;
    let vis = visibility_texture(VisibilityPattern::WhiteNoise, 64, 1);
    let renderer = LodBufferRenderer::new(gpu, FORMAT, &vis, 0.25)?;
    let meshes = [
        GpuMesh::new(gpu, &Mesh::sphere(16, 24))?,
        GpuMesh::new(gpu, &Mesh::cube())?,
    ];
    let proj = glam::camera::rh::proj::directx::perspective(0.8, 1.0, 0.1, 100.0);
    let views = [0.0f32, 0.1]
        .map(|x| glam::camera::rh::view::look_at_mat4(Vec3::new(x, 3.0, 7.0), Vec3::ZERO, Vec3::Y));
    // Three rows of five, still (the previous model is the model).
    let grid = |k: usize| {
        Mat4::from_translation(Vec3::new(
            (k % 5) as f32 * 2.0 - 4.0,
            0.0,
            -((k / 5) as f32) * 2.0,
        ))
    };
    for (i, view) in views.iter().enumerate() {
        let items: Vec<LodDrawItem> = (0..15)
            .map(|k| (k, grid(k)))
            .map(|(k, model)| LodDrawItem {
                mesh: &meshes[(k + i) % 2],
                model,
                color: Vec4::new(0.8, 0.2, 0.2, 1.0),
                id: if k % 3 == 0 { k as u32 + 1 } else { 0 },
                tau: if k % 3 == 0 { 0.5 } else { 1.0 },
                tau_next: if k % 3 == 0 { 0.55 } else { 1.0 },
                sway: [0.0; 2],
                prev_model: model,
                prev_sway_phase: 0.0,
                alpha_rect: Vec4::ZERO,
            })
            .collect();
        for buffers in [&buffers, &still] {
            renderer.render(
                gpu,
                buffers,
                &LodBufferFrame {
                    index: i,
                    view: (proj * *view).into(),
                    items: &items,
                    clear: wgpu::Color::BLACK,
                    ..Default::default()
                },
            )?;
        }
    }
    let target = texture_2d(
        gpu,
        (size, size),
        FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT,
        "target",
    )?;
    let target_view = target.create_view(&Default::default());
    let descriptor = CombinePassDescriptor {
        target_format: FORMAT,
        ..Default::default()
    };
    let combine = CombinePass::new(gpu, &descriptor)?;
    let m = new_to_old_matrix(&views[1], &proj, &views[0], &proj);
    let mut entries = CombinePass::buffer_layout_entries(0);
    entries.push(CombinePass::motion_layout_entry(6));
    let (layout, pipeline_layout) = one_group_layout(gpu, &entries, "copy7");
    // The baselines bind the combine's textures in its layout.
    let pipeline = |source, name| plain_pass_with(gpu, source, name, Some(&pipeline_layout));
    let copy7 = pipeline(COPY7, "copy7.wgsl")?;
    let loads8 = pipeline(LOADS8, "loads8.wgsl")?;
    let loads12 = pipeline(LOADS12, "loads12.wgsl")?;
    let textures = [1, 0].map(|i| [buffers.color(i), buffers.id(i), buffers.depth(i)]);
    let mut textures = textures.as_flattened().to_vec();
    // LodBuffers::new has the motion target.
    textures.extend(buffers.motion());
    let group = || textures_and_uniform(gpu, &layout, &textures, None, "copy7");
    let run = |encoder: &mut wgpu::CommandEncoder, buffers: &LodBuffers| {
        let frame = CombineFrame {
            buffers,
            newer: 1,
            new_to_old: m,
            target: &target_view,
            regions: CombineRegions::Everywhere,
            coverage: CombineCoverage::Estimated,
        };
        combine.record(gpu, encoder, &frame).map(drop)
    };
    let run_combine = |e: &mut wgpu::CommandEncoder| run(e, &buffers);
    let run_still = |e: &mut wgpu::CommandEncoder| run(e, &still);
    let (layout6, pipeline_layout6) =
        one_group_layout(gpu, &CombinePass::buffer_layout_entries(0), "copy6");
    let copy6 = plain_pass_with(gpu, COPY6, "copy6.wgsl", Some(&pipeline_layout6))?;
    let still_textures = [1, 0].map(|i| [still.color(i), still.id(i), still.depth(i)]);
    let still_group =
        || textures_and_uniform(gpu, &layout6, still_textures.as_flattened(), None, "copy6");
    let fullscreen = |e: &mut wgpu::CommandEncoder, pipeline, group: &dyn Fn() -> _| {
        record_fullscreen(gpu, e, pipeline, group, None, &target_view)
    };
    let run_copy6 = |e: &mut wgpu::CommandEncoder| fullscreen(e, &copy6, &still_group);
    let run_copy = |e: &mut wgpu::CommandEncoder| fullscreen(e, &copy7, &group);
    let run_loads = |e: &mut wgpu::CommandEncoder| fullscreen(e, &loads8, &group);
    let run_loads12 = |e: &mut wgpu::CommandEncoder| fullscreen(e, &loads12, &group);
    // Counted from the shaders: the copy reads color, id and depth of each buffer and the object
    // motion; the combine the same, the older depth at its first estimate, and under branches
    // the older ids of its search.
    let buffer = |color, id, depth| {
        [
            (color, FORMAT, Texels::One),
            (id, ID_FORMAT, Texels::One),
            (depth, LOD_DEPTH_FORMAT, Texels::One),
        ]
    };
    let copy6_formats = [buffer("a", "b", "c"), buffer("d", "e", "f")].concat();
    let mut copy_formats = copy6_formats.clone();
    copy_formats.push(("g", MOTION_FORMAT, Texels::One));
    let still_formats = [
        buffer("newer_color", "newer_id", "newer_depth"),
        buffer("older_color", "older_id", "older_depth"),
    ]
    .concat();
    let mut combine_formats = still_formats.clone();
    combine_formats.push(("object_motion", MOTION_FORMAT, Texels::One));
    let against_copy7 = (
        "plain copy of the same 7 textures",
        &run_copy as Record<'_>,
        Reads::of_source(COPY7, "copy7.wgsl", &copy_formats)?,
    );
    let against_copy6 = (
        "plain copy of the same 6 textures",
        &run_copy6 as Record<'_>,
        Reads::of_source(COPY6, "copy6.wgsl", &copy6_formats)?,
    );
    type Baseline<'a> = (&'a str, Record<'a>, Reads);
    let time = |pass: &str,
                reads: Reads,
                run: Record<'_>,
                (baseline, run_baseline, baseline_reads): &Baseline| {
        let name = pass.to_owned();
        let baseline = Side {
            name: (*baseline).to_owned(),
            reads: *baseline_reads,
            run: *run_baseline,
        };
        PassRatio::time(
            gpu,
            timer,
            (size, size),
            pairs,
            Side { name, reads, run },
            &baseline,
        )
    };
    Ok([
        time(
            "combine (frame-sequential)",
            Reads::of_pass("combine", &combine_formats)?,
            &run_combine,
            &against_copy7,
        )?,
        time(
            "the combine's 8 main-path loads alone",
            Reads::of_source(LOADS8, "loads8.wgsl", &copy_formats)?,
            &run_loads,
            &against_copy7,
        )?,
        time(
            "the same and the 4 loads of its id-mismatch branch, all made",
            Reads::of_source(LOADS12, "loads12.wgsl", &copy_formats)?,
            &run_loads12,
            &against_copy7,
        )?,
        time(
            "combine, buffers without object motion (combine_at)",
            Reads::of_pass_with("combine", &["LODKIT_COMBINE_STILL"], &still_formats)?,
            &run_still,
            &against_copy6,
        )?,
    ])
}
