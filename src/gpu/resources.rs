//! Small constructors shared by the passes and renderers: 2D textures, uniform buffers for
//! per-draw data with dynamic offsets, and a single-target render pass.

use bytemuck::Pod;
use wgpu::util::DeviceExt;

use super::GpuContext;

/// A 2D texture with one mip level and one sample.
pub fn texture_2d(
    gpu: &GpuContext,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
    label: &str,
) -> wgpu::Texture {
    gpu.device.create_texture(&wgpu::TextureDescriptor {
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
    })
}

/// A square `R32Float` texture holding `texels` (row-major), for `textureLoad` (unfilterable).
pub fn r32float_texture(gpu: &GpuContext, size: u32, texels: &[f32], label: &str) -> wgpu::Texture {
    gpu.device.create_texture_with_data(
        &gpu.queue,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: size,
                height: size,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::R32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        bytemuck::cast_slice(texels),
    )
}

/// A uniform buffer of `size` bytes that can be written.
pub fn uniform_buffer(gpu: &GpuContext, size: usize, label: &str) -> wgpu::Buffer {
    gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
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

/// Per-draw uniforms in one buffer, one aligned slot per draw, bound with a dynamic offset.
#[derive(Debug)]
pub struct DrawUniforms {
    buffer: wgpu::Buffer,
    stride: u64,
    item_size: u64,
    capacity: usize,
}

impl DrawUniforms {
    /// Room for `capacity` items of `item_size` bytes each.
    pub fn new(gpu: &GpuContext, item_size: usize, capacity: usize, label: &str) -> Self {
        let align = u64::from(gpu.device.limits().min_uniform_buffer_offset_alignment);
        let stride = (item_size as u64).div_ceil(align) * align;
        Self {
            buffer: uniform_buffer(gpu, (stride * capacity as u64) as usize, label),
            stride,
            item_size: item_size as u64,
            capacity,
        }
    }

    /// Most items it holds.
    pub fn capacity(&self) -> usize {
        self.capacity
    }

    /// Writes `items` (at most [`capacity`](Self::capacity); the rest are dropped) and returns
    /// how many were written.
    pub fn write<T: Pod>(&self, gpu: &GpuContext, items: &[T]) -> usize {
        let n = items.len().min(self.capacity);
        let mut data = vec![0u8; self.stride as usize * n];
        for (i, item) in items[..n].iter().enumerate() {
            let at = i * self.stride as usize;
            data[at..at + std::mem::size_of::<T>()].copy_from_slice(bytemuck::bytes_of(item));
        }
        if !data.is_empty() {
            gpu.queue.write_buffer(&self.buffer, 0, &data);
        }
        n
    }

    /// Dynamic offset of item `i`.
    pub fn offset(&self, i: usize) -> u32 {
        (i as u64 * self.stride) as u32
    }

    /// A bind group holding the buffer at `binding` 0 of `layout` (one item wide).
    pub fn bind_group(&self, gpu: &GpuContext, layout: &wgpu::BindGroupLayout) -> wgpu::BindGroup {
        gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &self.buffer,
                    offset: 0,
                    size: wgpu::BufferSize::new(self.item_size),
                }),
            }],
        })
    }
}

/// A render pass into one color target, cleared to `clear`, without depth.
pub fn begin_color_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    target: &wgpu::TextureView,
    clear: wgpu::Color,
    label: &str,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: target,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(clear),
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
) -> wgpu::RenderPipeline {
    gpu.device
        .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: None,
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
        })
}

/// A render pipeline for [`Mesh`](super::scene::Mesh) geometry: `vs_main` / `fs_main` of
/// `module`, back faces culled, the given layout, color targets and depth state.
pub fn mesh_pipeline(
    gpu: &GpuContext,
    module: &wgpu::ShaderModule,
    layout: &wgpu::PipelineLayout,
    targets: &[Option<wgpu::ColorTargetState>],
    depth: wgpu::DepthStencilState,
    label: &str,
) -> wgpu::RenderPipeline {
    gpu.device
        .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(super::scene::MESH_VERTEX_LAYOUT)],
            },
            primitive: wgpu::PrimitiveState {
                cull_mode: Some(wgpu::Face::Back),
                ..Default::default()
            },
            depth_stencil: Some(depth),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets,
            }),
            multiview_mask: None,
            cache: None,
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

/// The bind group layouts of a mesh pass with a camera uniform in group 0 and per-draw uniforms
/// (dynamic offset) in group 1, and the pipeline layout over both.
pub fn camera_draw_layouts(
    gpu: &GpuContext,
    label: &str,
) -> (
    wgpu::BindGroupLayout,
    wgpu::BindGroupLayout,
    wgpu::PipelineLayout,
) {
    let layout_of = |dynamic| {
        gpu.device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries: &[uniform_entry(0, dynamic)],
            })
    };
    let (camera, draw) = (layout_of(false), layout_of(true));
    let layout = gpu
        .device
        .create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &[Some(&camera), Some(&draw)],
            immediate_size: 0,
        });
    (camera, draw, layout)
}
