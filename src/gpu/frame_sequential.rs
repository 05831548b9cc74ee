//! wgpu glue for frame-sequential LOD: the LOD buffer pair (ping-pong) and the combine pass.
//!
//! Each frame the engine renders its scene into LOD buffer `scheduler.buffer_index()` (color at
//! location 0, id/depth at location 1, see `lodkit::lod_buffer`), then calls
//! [`CombinePass::encode`] with the matrix from [`new_to_old_matrix`](crate::reproject::new_to_old_matrix)
//! to write the final image into its own target.

use glam::Mat4;

use super::GpuContext;
use super::resources::{
    begin_color_pass, begin_targets_pass, fullscreen_pipeline, texture_2d, textures_and_uniform,
    uniform_buffer,
};
use crate::lod_buffer::ID_DEPTH_FORMAT;
use crate::shaders::ShaderError;

/// Depth format of the pair's shared depth buffer.
pub const LOD_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Two LOD buffers (color + id/depth each) and a depth buffer to render them with.
#[derive(Debug)]
pub struct LodBuffers {
    color_format: wgpu::TextureFormat,
    size: (u32, u32),
    colors: [wgpu::Texture; 2],
    id_depths: [wgpu::Texture; 2],
    depth: wgpu::Texture,
}

impl LodBuffers {
    /// Allocates both buffers at `width` x `height` with color format `color_format`.
    pub fn new(
        gpu: &GpuContext,
        width: u32,
        height: u32,
        color_format: wgpu::TextureFormat,
    ) -> Self {
        let size = (width.max(1), height.max(1));
        let texture = |format, usage, label| texture_2d(gpu, size, format, usage, label);
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::TEXTURE_BINDING
            | wgpu::TextureUsages::COPY_SRC;
        Self {
            color_format,
            size: (width.max(1), height.max(1)),
            colors: [
                texture(color_format, usage, "lod buffer color 0"),
                texture(color_format, usage, "lod buffer color 1"),
            ],
            id_depths: [
                texture(ID_DEPTH_FORMAT, usage, "lod buffer id/depth 0"),
                texture(ID_DEPTH_FORMAT, usage, "lod buffer id/depth 1"),
            ],
            depth: texture(
                LOD_DEPTH_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
                "lod buffer depth",
            ),
        }
    }

    /// Reallocates at a new size (a no-op at the same size). The old textures are destroyed at
    /// once rather than left to the allocator.
    pub fn resize(&mut self, gpu: &GpuContext, width: u32, height: u32) {
        if (width.max(1), height.max(1)) == self.size {
            return;
        }
        let old = std::mem::replace(self, Self::new(gpu, width, height, self.color_format));
        for t in old.colors.iter().chain(&old.id_depths).chain([&old.depth]) {
            t.destroy();
        }
    }

    /// Width and height.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// Color texture of buffer `index` (0 or 1).
    pub fn color(&self, index: usize) -> &wgpu::Texture {
        &self.colors[index % 2]
    }

    /// Id/depth texture of buffer `index`.
    pub fn id_depth(&self, index: usize) -> &wgpu::Texture {
        &self.id_depths[index % 2]
    }

    /// The shared depth texture used while rendering either buffer.
    pub fn depth(&self) -> &wgpu::Texture {
        &self.depth
    }

    /// Begins a render pass into buffer `index` that clears color to `clear`, id to 0 and the
    /// stored depth and the depth buffer to `far_depth` (1 for standard Z, 0 for reversed).
    /// `occlusion_query_set` is passed on to the pass (see
    /// [`FragmentCounter`](super::counters::FragmentCounter)).
    pub fn begin_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        index: usize,
        clear: wgpu::Color,
        far_depth: f32,
        occlusion_query_set: Option<&wgpu::QuerySet>,
    ) -> wgpu::RenderPass<'e> {
        let color = self.colors[index % 2].create_view(&Default::default());
        let id_depth = self.id_depths[index % 2].create_view(&Default::default());
        let depth = self.depth.create_view(&Default::default());
        let id_clear = wgpu::Color {
            r: 0.0,
            g: f64::from(far_depth.to_bits()),
            b: 0.0,
            a: 0.0,
        };
        begin_targets_pass(
            encoder,
            &[(&color, clear), (&id_depth, id_clear)],
            &depth,
            far_depth,
            occlusion_query_set,
            "lod buffer",
        )
    }
}

/// Rust mirror of `CombineParams` in `passes/combine.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CombineParams {
    /// P_old V_old V_new^-1 P_new^-1, column-major.
    pub new_to_old: [[f32; 4]; 4],
}

/// The combine pass (`passes/combine.wgsl`) as a ready object: create once per target format,
/// call [`encode`](Self::encode) once per frame.
#[derive(Debug)]
pub struct CombinePass {
    pipeline: wgpu::RenderPipeline,
    params: wgpu::Buffer,
}

impl CombinePass {
    /// The `new_to_old` matrix for a frame with no usable older buffer (the first frame, after a
    /// resize or a camera cut): every pixel reprojects behind the older camera, so the newer
    /// buffer is shown as it is.
    pub const NO_HISTORY: Mat4 = Mat4::ZERO;

    /// Builds the pipeline for targets of `target_format`; `reverse_z` selects the depth
    /// convention of the LOD buffers (`LODKIT_REVERSE_Z`).
    pub fn new(
        gpu: &GpuContext,
        target_format: wgpu::TextureFormat,
        reverse_z: bool,
    ) -> Result<Self, ShaderError> {
        let defs: &[&str] = if reverse_z {
            &["LODKIT_REVERSE_Z"]
        } else {
            &[]
        };
        let module = gpu.pass_module("combine", defs)?;
        let pipeline = fullscreen_pipeline(gpu, &module, target_format, "lodkit combine");
        let params = uniform_buffer(gpu, std::mem::size_of::<CombineParams>(), "combine params");
        Ok(Self { pipeline, params })
    }

    /// Records the combination of buffer `newer` with the other one (reprojected through
    /// `new_to_old`) into `target`, which must be as large as the buffers. The parameters go
    /// through one uniform buffer written with `queue.write_buffer`: record one `encode` per
    /// submit (two in one encoder would both see the last matrix).
    pub fn encode(
        &self,
        gpu: &GpuContext,
        encoder: &mut wgpu::CommandEncoder,
        buffers: &LodBuffers,
        newer: usize,
        new_to_old: Mat4,
        target: &wgpu::TextureView,
    ) {
        let params = CombineParams {
            new_to_old: new_to_old.to_cols_array_2d(),
        };
        gpu.queue
            .write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let textures = [
            buffers.color(newer),
            buffers.id_depth(newer),
            buffers.color(newer + 1),
            buffers.id_depth(newer + 1),
        ];
        let layout = self.pipeline.get_bind_group_layout(0);
        let bind_group = textures_and_uniform(
            gpu,
            &layout,
            &textures,
            Some(&self.params),
            "lodkit combine",
        );
        let mut pass = begin_color_pass(encoder, target, wgpu::Color::BLACK, "lodkit combine");
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// Reads buffer `index` of `buffers` back to the CPU (an RGBA8 color format is expected).
pub fn read_lod_image(
    gpu: &GpuContext,
    buffers: &LodBuffers,
    index: usize,
) -> crate::combine::LodImage {
    let colors = super::readback::read_texture_rgba8(gpu, buffers.color(index));
    let id_depth = super::readback::read_texture(gpu, buffers.id_depth(index), 8);
    let words: Vec<u32> = id_depth
        .chunks(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    let (width, height) = buffers.size();
    crate::combine::LodImage {
        width,
        height,
        colors: colors
            .chunks(4)
            .map(|c| glam::Vec4::new(c[0] as f32, c[1] as f32, c[2] as f32, c[3] as f32) / 255.0)
            .collect(),
        ids: words.iter().step_by(2).copied().collect(),
        depths: words
            .iter()
            .skip(1)
            .step_by(2)
            .map(|w| f32::from_bits(*w))
            .collect(),
    }
}
