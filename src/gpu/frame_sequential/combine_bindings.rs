//! What a [`CombinePass`](super::CombinePass) keeps between recordings so that a recording costs
//! what a plain pass costs: the [`CombineData`] texture, made once and grown when a frame's data
//! is taller, its texels copied in the encoder with each recording (from a
//! `wgpu::util::StagingBelt` chunk, as [`RecordedUniform`](crate::gpu::resources::RecordedUniform)
//! does the parameters: several recordings in one encoder each read their own data); and the
//! bind groups, kept while the textures they bind are the same.

use std::sync::{Mutex, PoisonError};

use crate::combine_coverage::{COMBINE_DATA_WIDTH, CombineData};
use crate::gpu::resources::BindGroupCache;
use crate::gpu::{GpuContext, GpuError};

/// Bind groups kept: the two buffer parities, with and without known coverage, and a spare.
const KEPT_GROUPS: usize = 6;

/// The texture a recording's [`CombineData`] is copied into, and the belt its copies come from.
#[derive(Debug)]
struct DataTexture {
    texture: Option<wgpu::Texture>,
    belt: wgpu::util::StagingBelt,
}

/// See the [module](self) docs.
#[derive(Debug)]
pub(super) struct CombineBindings {
    data: Mutex<DataTexture>,
    groups: BindGroupCache,
}

impl CombineBindings {
    pub(super) fn new(gpu: &GpuContext) -> Self {
        Self {
            data: Mutex::new(DataTexture {
                texture: None,
                // One data row (16 KiB): a chunk serves one recording (each closes its chunk),
                // so a larger one would be mapped and cleared for nothing.
                belt: wgpu::util::StagingBelt::new(gpu.device.clone(), 1 << 14),
            }),
            groups: BindGroupCache::new(KEPT_GROUPS),
        }
    }

    /// Records into `encoder` the copy of `data`'s texels into the data texture (made, or made
    /// again taller or of another width, where it cannot hold them) and returns the texture.
    /// The data is checked already: `width * height` texels, neither 0.
    pub(super) fn upload(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        data: &CombineData,
    ) -> Result<wgpu::Texture, GpuError> {
        let mut kept = self.data.lock().unwrap_or_else(PoisonError::into_inner);
        let DataTexture { texture, belt } = &mut *kept;
        // The shader reads the data by linear index (x = index % the texture's width): one row
        // of data (fewer than COMBINE_DATA_WIDTH texels, whose width then varies from frame to
        // frame) fits any texture at least as wide; more rows need the data's own width.
        let fits = |t: &wgpu::Texture| {
            t.height() >= data.height
                && (t.width() == data.width || (data.height == 1 && t.width() >= data.width))
        };
        let width = match data.height {
            1 => data.width.max(COMBINE_DATA_WIDTH),
            _ => data.width,
        };
        let texture = match texture {
            Some(t) if fits(t) => t.clone(),
            _ => {
                // Room for the data and as much again: a frame with a few more silhouettes
                // does not make it again.
                let rows = data
                    .height
                    .saturating_mul(2)
                    .min(gpu.device.limits().max_texture_dimension_2d)
                    .max(data.height);
                let made = gpu.device.create_texture(&wgpu::TextureDescriptor {
                    label: Some("lodkit combine data"),
                    size: wgpu::Extent3d {
                        width,
                        height: rows,
                        depth_or_array_layers: 1,
                    },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: wgpu::TextureFormat::Rgba32Uint,
                    usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                    view_formats: &[],
                });
                *texture = Some(made.clone());
                made
            }
        };
        let texel = std::mem::size_of::<[u32; 4]>();
        let row = data.width as usize * texel;
        let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as usize;
        let padded = row.div_ceil(align) * align;
        let bytes = padded * data.height as usize;
        let (Some(size), Some(alignment)) = (
            wgpu::BufferSize::new(bytes as u64),
            wgpu::BufferSize::new(align as u64),
        ) else {
            return Ok(texture);
        };
        let slice = belt.allocate(size, alignment);
        {
            let mut view = slice
                .get_mapped_range_mut()
                .map_err(|e| GpuError::Internal {
                    call: "CombinePass::record",
                    description: format!("the combine data's staging buffer: {e}"),
                })?;
            let texels: &[u8] = bytemuck::cast_slice(&data.texels);
            for (k, from) in texels.chunks(row).enumerate() {
                view.slice(k * padded..k * padded + row)
                    .copy_from_slice(from);
            }
        }
        encoder.copy_buffer_to_texture(
            wgpu::TexelCopyBufferInfo {
                buffer: slice.buffer(),
                layout: wgpu::TexelCopyBufferLayout {
                    offset: slice.offset(),
                    bytes_per_row: Some(padded as u32),
                    rows_per_image: Some(data.height),
                },
            },
            texture.as_image_copy(),
            wgpu::Extent3d {
                width: data.width,
                height: data.height,
                depth_or_array_layers: 1,
            },
        );
        belt.finish_and_recall_on_submit(encoder);
        Ok(texture)
    }

    /// The bind group of `textures` (bindings 0-6, 8, 9) and `pattern` (10), with the
    /// parameters at 7: the one kept for them, or one made now and kept.
    pub(super) fn group(
        &self,
        gpu: &GpuContext,
        layout: &wgpu::BindGroupLayout,
        params: &wgpu::Buffer,
        textures: [&wgpu::Texture; 9],
        pattern: &wgpu::TextureView,
    ) -> Result<wgpu::BindGroup, GpuError> {
        self.groups.get_or_make(&textures, &[pattern], || {
            let views: Vec<wgpu::TextureView> = textures
                .iter()
                .map(|t| t.create_view(&Default::default()))
                .collect();
            let entries: Vec<wgpu::BindGroupEntry> = views
                .iter()
                .chain(std::iter::once(pattern))
                .zip([0, 1, 2, 3, 4, 5, 6, 8, 9, 10])
                .map(|(view, binding)| wgpu::BindGroupEntry {
                    binding,
                    resource: wgpu::BindingResource::TextureView(view),
                })
                .chain(std::iter::once(wgpu::BindGroupEntry {
                    binding: 7,
                    resource: params.as_entire_binding(),
                }))
                .collect();
            Ok(gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("lodkit combine"),
                layout,
                entries: &entries,
            }))
        })
    }
}
