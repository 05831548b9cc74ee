//! Small constructors shared by the passes and renderers: 2D textures, buffers with contents,
//! uniform buffers for per-draw data with dynamic offsets, pipelines and render passes. Each one
//! that creates a resource checks its sizes and formats against the device and runs inside error
//! scopes (see [`GpuError`]).

use super::checks::{buffer_size, check_format_usages, target_extent, texture_extent};
use super::{GpuContext, GpuError};

mod bind_cache;
mod draw_uniforms;
mod params;
pub(crate) use bind_cache::BindGroupCache;
pub use draw_uniforms::DrawUniforms;
pub use params::RecordedUniform;

/// Vertex buffer layout of the meshes [`mesh_pipeline`] draws: position then normal,
/// 24 bytes a vertex (the `lodkit-scenes` crate's `Mesh`), [`MESH_VERTEX_ATTRIBUTES`].
pub const MESH_VERTEX_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: 24,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &MESH_VERTEX_ATTRIBUTES,
};

/// Vertex attributes of those meshes: position at location 0, normal at location 1.
pub const MESH_VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 2] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3];

/// A 2D texture with one mip level and one sample (a zero side is taken as 1).
pub fn texture_2d(
    gpu: &GpuContext,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    label: &str,
) -> Result<wgpu::Texture, GpuError> {
    const CALL: &str = "resources::texture_2d";
    let (width, height) = texture_extent(gpu, CALL, width, height)?;
    check_format_usages(gpu, CALL, "format", format, usage)?;
    gpu.guarded(CALL, || {
        Ok(gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        }))
    })
}

/// A square `R32Float` texture holding `texels` (row-major, `size` x `size` of them), for
/// `textureLoad` (unfilterable).
pub fn r32float_texture(
    gpu: &GpuContext,
    size: u32,
    texels: &[f32],
    label: &str,
) -> Result<wgpu::Texture, GpuError> {
    const CALL: &str = "resources::r32float_texture";
    let expected = u64::from(size) * u64::from(size);
    if size == 0 || texels.len() as u64 != expected {
        return Err(GpuError::Mismatch {
            call: CALL,
            parameter: "texels",
            found: format!("{} values", texels.len()),
            expected: format!("a {size} x {size} texture needs {expected} (and size >= 1)"),
        });
    }
    let usage = wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST;
    let format = wgpu::TextureFormat::R32Float;
    let texture = texture_2d(gpu, (size, size), format, usage, label)?;
    gpu.guarded(CALL, || {
        gpu.queue.write_texture(
            texture.as_image_copy(),
            bytemuck::cast_slice(texels),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(size * 4),
                rows_per_image: Some(size),
            },
            texture.size(),
        );
        Ok(())
    })?;
    Ok(texture)
}

/// A buffer of `usage` holding `contents` (padded to 4 bytes; at least 4 bytes long).
pub fn buffer_with_data(
    gpu: &GpuContext,
    contents: &[u8],
    usage: wgpu::BufferUsages,
    label: &str,
) -> Result<wgpu::Buffer, GpuError> {
    const CALL: &str = "resources::buffer_with_data";
    let size = (contents.len() as u64).div_ceil(4).max(1) * 4;
    buffer_size(gpu, CALL, "contents", size)?;
    gpu.guarded(CALL, || {
        let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage,
            mapped_at_creation: true,
        });
        match buffer.get_mapped_range_mut(..) {
            Ok(mut view) => view.slice(..contents.len()).copy_from_slice(contents),
            // The creation failed: the error scope holds the reason.
            Err(_) => return Ok(buffer),
        }
        buffer.unmap();
        Ok(buffer)
    })
}

/// A bind group of `layout` binding each of `buffers` whole, at bindings 0, 1, ... in order.
pub fn buffers_bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    buffers: &[&wgpu::Buffer],
    label: &str,
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = buffers
        .iter()
        .enumerate()
        .map(|(k, b)| wgpu::BindGroupEntry {
            binding: k as u32,
            resource: b.as_entire_binding(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// A uniform buffer of `size` bytes that can be written.
pub fn uniform_buffer(
    gpu: &GpuContext,
    size: usize,
    label: &str,
) -> Result<wgpu::Buffer, GpuError> {
    const CALL: &str = "resources::uniform_buffer";
    buffer_size(gpu, CALL, "size", size as u64)?;
    gpu.guarded(CALL, || {
        Ok(gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        }))
    })
}

/// Layout entry of a uniform buffer visible to vertex and fragment stages.
pub fn uniform_entry(binding: u32, dynamic_offset: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: dynamic_offset,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A render pass into one color target, cleared to `clear`, without depth.
pub fn begin_color_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    target: &wgpu::TextureView,
    clear: wgpu::Color,
    label: &str,
) -> wgpu::RenderPass<'e> {
    color_pass(encoder, target, wgpu::LoadOp::Clear(clear), label)
}

/// A render pass into one color target that keeps its contents, without depth.
pub fn begin_load_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    target: &wgpu::TextureView,
    label: &str,
) -> wgpu::RenderPass<'e> {
    color_pass(encoder, target, wgpu::LoadOp::Load, label)
}

fn color_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    target: &wgpu::TextureView,
    load: wgpu::LoadOp<wgpu::Color>,
    label: &str,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: target,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load,
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// A pipeline for a fullscreen pass: `vs_main` and `fs_main` of `module`, no vertex buffers, no
/// depth, one target of `format`, bind group layouts derived from the shader.
pub fn fullscreen_pipeline(
    gpu: &GpuContext,
    module: &wgpu::ShaderModule,
    format: wgpu::TextureFormat,
    label: &str,
) -> Result<wgpu::RenderPipeline, GpuError> {
    fullscreen_pipeline_with(gpu, module, format, None, label)
}

/// [`fullscreen_pipeline`] with an explicit pipeline `layout` (`None`: derived from the shader),
/// e.g. to bind a depth attachment as an unfilterable float texture.
pub fn fullscreen_pipeline_with(
    gpu: &GpuContext,
    module: &wgpu::ShaderModule,
    format: wgpu::TextureFormat,
    layout: Option<&wgpu::PipelineLayout>,
    label: &str,
) -> Result<wgpu::RenderPipeline, GpuError> {
    gpu.guarded("resources::fullscreen_pipeline", || {
        Ok(gpu
            .device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout,
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: Default::default(),
                depth_stencil: None,
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &[Some(format.into())],
                }),
                multiview_mask: None,
                cache: None,
            }))
    })
}

/// A bind group layout of `entries` and the pipeline layout holding it as group 0.
pub fn one_group_layout(
    gpu: &GpuContext,
    entries: &[wgpu::BindGroupLayoutEntry],
    label: &str,
) -> (wgpu::BindGroupLayout, wgpu::PipelineLayout) {
    let group = gpu
        .device
        .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(label),
            entries,
        });
    let layout = gpu
        .device
        .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &[Some(&group)],
            immediate_size: 0,
        });
    (group, layout)
}

/// A fragment-stage texture binding of `sample_type`, 2D, not multisampled.
pub fn texture_entry(
    binding: u32,
    sample_type: wgpu::TextureSampleType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// A render pipeline for meshes laid out as [`MESH_VERTEX_LAYOUT`]: `vs_main` / `fs_main` of
/// `module`, back faces culled, the given layout, color targets and depth state.
pub fn mesh_pipeline(
    gpu: &GpuContext,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    targets: &[Option<wgpu::ColorTargetState>],
    depth: wgpu::DepthStencilState,
    label: &str,
) -> Result<wgpu::RenderPipeline, GpuError> {
    mesh_pipeline_entry(gpu, (module, "fs_main"), layout, targets, depth, label)
}

/// [`mesh_pipeline`] with the fragment stage `entry` of the module (another pass over the same
/// vertex stage: a depth-only one has no `targets`).
pub fn mesh_pipeline_entry(
    gpu: &GpuContext,
    (module, entry): (&wgpu::ShaderModule, &str),
    layout: &wgpu::PipelineLayout,
    targets: &[Option<wgpu::ColorTargetState>],
    depth: wgpu::DepthStencilState,
    label: &str,
) -> Result<wgpu::RenderPipeline, GpuError> {
    gpu.guarded("resources::mesh_pipeline", || {
        Ok(gpu
            .device
            .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[Some(MESH_VERTEX_LAYOUT)],
                },
                primitive: wgpu::PrimitiveState {
                    cull_mode: Some(wgpu::Face::Back),
                    ..Default::default()
                },
                depth_stencil: Some(depth),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module,
                    entry_point: Some(entry),
                    compilation_options: Default::default(),
                    targets,
                }),
                multiview_mask: None,
                cache: None,
            }))
    })
}

/// Depth-tested, depth-writing state with `compare` (`Less` for standard Z).
pub fn depth_write_state(
    format: wgpu::TextureFormat,
    compare: wgpu::CompareFunction,
) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format,
        depth_write_enabled: Some(true),
        depth_compare: Some(compare),
        stencil: Default::default(),
        bias: Default::default(),
    }
}

/// A bind group of `textures` at bindings 0.. followed, if given, by `uniform` at the next
/// binding.
pub fn textures_and_uniform(
    gpu: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    textures: &[&wgpu::Texture],
    uniform: Option<&wgpu::Buffer>,
    label: &str,
) -> Result<wgpu::BindGroup, GpuError> {
    gpu.guarded("resources::textures_and_uniform", || {
        Ok(bind_textures_and_uniform(
            gpu, layout, textures, uniform, label,
        ))
    })
}

fn bind_textures_and_uniform(
    gpu: &GpuContext,
    layout: &wgpu::BindGroupLayout,
    textures: &[&wgpu::Texture],
    uniform: Option<&wgpu::Buffer>,
    label: &str,
) -> wgpu::BindGroup {
    let views: Vec<wgpu::TextureView> = textures
        .iter()
        .map(|t| t.create_view(&Default::default()))
        .collect();
    let mut entries: Vec<wgpu::BindGroupEntry> = views
        .iter()
        .enumerate()
        .map(|(i, v)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: wgpu::BindingResource::TextureView(v),
        })
        .collect();
    entries.extend(uniform.map(|u| wgpu::BindGroupEntry {
        binding: views.len() as u32,
        resource: u.as_entire_binding(),
    }));
    gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// A render pass into several color targets (each cleared to its color) and a depth target
/// cleared to `depth_clear`, with an optional occlusion query set.
pub fn begin_targets_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    colors: &[(&wgpu::TextureView, wgpu::Color)],
    depth: &wgpu::TextureView,
    depth_clear: f32,
    occlusion_query_set: Option<&wgpu::QuerySet>,
    label: &str,
) -> wgpu::RenderPass<'e> {
    let attachments: Vec<Option<wgpu::RenderPassColorAttachment>> = colors
        .iter()
        .map(|(view, clear)| {
            Some(wgpu::RenderPassColorAttachment {
                view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(*clear),
                    store: wgpu::StoreOp::Store,
                },
            })
        })
        .collect();
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &attachments,
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: depth,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(depth_clear),
                store: wgpu::StoreOp::Store,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set,
        multiview_mask: None,
    })
}

/// The per-view (a uniform at binding 0, then `view_extra`) and per-draw (a dynamic-offset
/// uniform) bind group layouts of a mesh pass, and the pipeline layout over both.
pub fn camera_draw_layouts(
    gpu: &GpuContext,
    label: &str,
    view_extra: &[wgpu::BindGroupLayoutEntry],
) -> Result<
    (
        wgpu::BindGroupLayout,
        wgpu::BindGroupLayout,
        wgpu::PipelineLayout,
    ),
    GpuError,
> {
    gpu.guarded("resources::camera_draw_layouts", || {
        let mut view_entries = vec![uniform_entry(0, false)];
        view_entries.extend_from_slice(view_extra);
        let layout_of = |entries: &[wgpu::BindGroupLayoutEntry]| {
            gpu.device
                .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                    label: Some(label),
                    entries,
                })
        };
        let (camera, draw) = (
            layout_of(&view_entries),
            layout_of(&[uniform_entry(0, true)]),
        );
        let layout = gpu
            .device
            .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(label),
                bind_group_layouts: &[Some(&camera), Some(&draw)],
                immediate_size: 0,
            });
        Ok((camera, draw, layout))
    })
}

/// Textures of one size and color format allocated together (the LOD buffer pair, the
/// low-resolution buffer), made and resized by [`new_set`] and [`resize_set`].
pub(crate) trait TextureSet: Sized {
    /// Usage of the color textures.
    const USAGE: wgpu::TextureUsages;
    /// Allocates every texture at `size` (already checked).
    fn allocate(
        gpu: &GpuContext,
        size: (u32, u32),
        color_format: wgpu::TextureFormat,
    ) -> Result<Self, GpuError>;
    /// The size the textures have.
    fn extent(&self) -> (u32, u32);
    /// The color format.
    fn format(&self) -> wgpu::TextureFormat;
    /// Every texture, to destroy when replaced.
    fn textures(&self) -> Vec<&wgpu::Texture>;
    /// A set like this one at `size` (already checked): what a resize allocates.
    fn allocate_like(&self, gpu: &GpuContext, size: (u32, u32)) -> Result<Self, GpuError> {
        Self::allocate(gpu, size, self.format())
    }
}

/// A [`TextureSet`] at `width` x `height` in `color_format`, checked and allocated as `call`.
pub(crate) fn new_set<T: TextureSet>(
    gpu: &GpuContext,
    call: &'static str,
    (width, height): (u32, u32),
    color_format: wgpu::TextureFormat,
) -> Result<T, GpuError> {
    let size = target_extent(gpu, call, (width, height), color_format, T::USAGE)?;
    gpu.guarded(call, || T::allocate(gpu, size, color_format))
}

/// Reallocates `set` at `width` x `height` as `call` (a no-op at the same size). The old
/// textures are destroyed once the new ones exist; on an error `set` is unchanged.
pub(crate) fn resize_set<T: TextureSet>(
    gpu: &GpuContext,
    call: &'static str,
    set: &mut T,
    (width, height): (u32, u32),
) -> Result<(), GpuError> {
    let size = texture_extent(gpu, call, width, height)?;
    if size == set.extent() {
        return gpu.check(call);
    }
    let new = gpu.guarded(call, || set.allocate_like(gpu, size))?;
    let old = std::mem::replace(set, new);
    for t in old.textures() {
        t.destroy();
    }
    Ok(())
}
