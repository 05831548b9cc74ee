//! What one [`ImpostorPass::draw`] reads: the view's uniform, the instances and the bind group
//! of the atlas (and, in a LOD buffer, the visibility pattern), made by
//! [`ImpostorPass::prepare`] and rewritten in place, frame after frame, by
//! [`ImpostorPass::update`].

use super::ImpostorTextures;
use super::draw::{ImpostorPass, ImpostorTarget};
use super::instance::{
    ImpostorInstance, ImpostorLodView, ImpostorView, InstanceWords, instance_words, view_uniform,
};
use crate::gpu::resources::buffer_with_data;
use crate::gpu::{GpuContext, GpuError};
use crate::visibility::VisibilitySpace;

/// What one [`ImpostorPass::draw`] needs: the view's uniform, the atlas's bind group and the
/// instances. Keep it from frame to frame and [`ImpostorPass::update`] it: nothing is
/// allocated while the instances fit.
#[derive(Debug)]
pub struct PreparedImpostors {
    uniform: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    instances: wgpu::Buffer,
    /// Instances the buffer holds.
    capacity: usize,
    count: u32,
    /// What the bind group binds: the atlas's two textures, its sampler and the pattern's view.
    bound: Bound,
}

impl PreparedImpostors {
    /// The bind group, the instance buffer and how many instances it holds.
    pub(super) fn parts(&self) -> (&wgpu::BindGroup, &wgpu::Buffer, u32) {
        (&self.bind_group, &self.instances, self.count)
    }
}

impl ImpostorPass {
    /// Draws the prepared instances into `pass`: one with one colour target of the descriptor's
    /// format and its depth target, a LOD buffer's (`LodBuffers::begin_pass`) or the level-depth
    /// pass (`LodBuffers::begin_level_depth_pass`), as the descriptor's `target` says.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, prepared: &PreparedImpostors) {
        self.draw_instances(pass, prepared, 0..u32::MAX);
    }

    /// Draws the prepared instances in `range` (clamped to those prepared) into `pass`, as
    /// [`draw`](Self::draw) does: one prepared set, one bind group, for draws of a frame that go
    /// in different places of the pass (a blended object between others, sorted far to near).
    /// A bind group switched per instance costs a software rasterizer (lavapipe) about 3 ms a
    /// draw with the default atlas; ranges of one set do not switch it.
    pub fn draw_instances(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        prepared: &PreparedImpostors,
        range: std::ops::Range<u32>,
    ) {
        let (bind_group, instances, count) = prepared.parts();
        let range = range.start.min(count)..range.end.min(count);
        if range.is_empty() {
            return;
        }
        pass.set_pipeline(self.pipeline());
        pass.set_bind_group(0, bind_group, &[]);
        pass.set_vertex_buffer(0, instances.slice(..));
        pass.draw(0..6, range);
    }

    /// The uniform, bind group and instance buffer for drawing `instances` of `textures` seen
    /// from `view`, for a colour or level-depth target ([`GpuError::Mismatch`] for a LOD-buffer
    /// one: [`prepare_lod_buffer`](Self::prepare_lod_buffer)).
    pub fn prepare(
        &self,
        gpu: &GpuContext,
        textures: &ImpostorTextures,
        view: &ImpostorView,
        instances: &[ImpostorInstance],
    ) -> Result<PreparedImpostors, GpuError> {
        const CALL: &str = "ImpostorPass::prepare";
        self.check_lod(CALL, "self", None)?;
        self.allocate(gpu, CALL, textures, view, None, instances)
    }

    /// [`prepare`](Self::prepare) for a LOD-buffer target ([`GpuError::Mismatch`] for another),
    /// with the previous frame's camera and the visibility pattern of `lod`
    /// ([`GpuError::Invalid`] for a `vis_scale` that is not finite and positive where the
    /// pattern is anchored to the object).
    pub fn prepare_lod_buffer(
        &self,
        gpu: &GpuContext,
        textures: &ImpostorTextures,
        view: &ImpostorView,
        lod: &ImpostorLodView<'_>,
        instances: &[ImpostorInstance],
    ) -> Result<PreparedImpostors, GpuError> {
        const CALL: &str = "ImpostorPass::prepare_lod_buffer";
        self.check_lod(CALL, "self", Some(lod))?;
        self.allocate(gpu, CALL, textures, view, Some(lod), instances)
    }

    /// `prepared` rewritten for this frame's `view` (and `lod`, for a LOD-buffer target: as
    /// [`prepare_lod_buffer`](Self::prepare_lod_buffer) checks it) and `instances`: the uniform
    /// and the instances written in place (the instance buffer grows, to the next power of
    /// two, only when they do not fit), the bind group made again only when `textures` or the
    /// pattern are not those it binds. What an engine calls every frame: a new
    /// `PreparedImpostors` a frame allocates its buffers every frame. The writes land at the
    /// queue's next submission: update a set only once the draws recorded with it before are
    /// submitted (or those draws read the new values), and keep one set per draw of a frame
    /// whose instances differ, or draw ranges of one ([`draw_instances`](Self::draw_instances)).
    /// [`GpuError::Mismatch`] names `lod` where it is given to a pass that is not for a LOD
    /// buffer or missing for one.
    pub fn update(
        &self,
        gpu: &GpuContext,
        prepared: &mut PreparedImpostors,
        textures: &ImpostorTextures,
        view: &ImpostorView,
        lod: Option<&ImpostorLodView<'_>>,
        instances: &[ImpostorInstance],
    ) -> Result<(), GpuError> {
        const CALL: &str = "ImpostorPass::update";
        self.check_lod(CALL, "lod", lod)?;
        let words = instance_words(instances);
        let uniform = view_uniform(textures, view, lod);
        gpu.guarded(CALL, || {
            gpu.queue
                .write_buffer(&prepared.uniform, 0, bytemuck::bytes_of(&uniform));
            Ok(())
        })?;
        if instances.len() > prepared.capacity {
            let capacity = instances.len().next_power_of_two();
            prepared.instances = instance_buffer(gpu, &words, capacity)?;
            prepared.capacity = capacity;
        } else if !words.is_empty() {
            gpu.guarded(CALL, || {
                gpu.queue
                    .write_buffer(&prepared.instances, 0, bytemuck::cast_slice(&words));
                Ok(())
            })?;
        }
        prepared.count = instances.len() as u32;
        let visibility = lod.map(|lod| lod.visibility);
        let (color, normal_depth, sampler, pattern) = &prepared.bound;
        let same = *color == textures.color
            && *normal_depth == textures.normal_depth
            && *sampler == textures.sampler
            && pattern.as_ref() == visibility;
        if !same {
            prepared.bind_group = self.bind_group(gpu, CALL, &prepared.uniform, textures, lod)?;
            prepared.bound = bound(textures, lod);
        }
        Ok(())
    }

    /// [`GpuError::Mismatch`] where `lod` is given to a pass that is not for a LOD buffer or
    /// missing for one; [`GpuError::Invalid`] for an object-anchored pattern's bad scale.
    fn check_lod(
        &self,
        call: &'static str,
        parameter: &'static str,
        lod: Option<&ImpostorLodView<'_>>,
    ) -> Result<(), GpuError> {
        let lod_target = matches!(self.descriptor().target, ImpostorTarget::LodBuffer { .. });
        if lod_target != lod.is_some() {
            return Err(GpuError::Mismatch {
                call,
                parameter,
                found: format!("a pass built for {:?}", self.descriptor().target),
                expected: match lod_target {
                    true => "ImpostorPass::prepare_lod_buffer for a LOD-buffer target".into(),
                    false => "ImpostorPass::prepare for a colour or level-depth target".into(),
                },
            });
        }
        if let Some(lod) = lod
            && lod.space == VisibilitySpace::Object
            && !(lod.vis_scale.is_finite() && lod.vis_scale > 0.0)
        {
            return Err(GpuError::Invalid {
                call,
                parameter: "lod.vis_scale",
                value: lod.vis_scale.to_string(),
                rule: "finite and positive where the pattern is anchored to the object",
            });
        }
        Ok(())
    }

    fn allocate(
        &self,
        gpu: &GpuContext,
        call: &'static str,
        textures: &ImpostorTextures,
        view: &ImpostorView,
        lod: Option<&ImpostorLodView<'_>>,
        instances: &[ImpostorInstance],
    ) -> Result<PreparedImpostors, GpuError> {
        let uniform = view_uniform(textures, view, lod);
        let uniform = buffer_with_data(
            gpu,
            bytemuck::bytes_of(&uniform),
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            "impostor view",
        )?;
        let capacity = instances.len().max(1);
        let buffer = instance_buffer(gpu, &instance_words(instances), capacity)?;
        let bind_group = self.bind_group(gpu, call, &uniform, textures, lod)?;
        Ok(PreparedImpostors {
            uniform,
            bind_group,
            instances: buffer,
            capacity,
            count: instances.len() as u32,
            bound: bound(textures, lod),
        })
    }

    fn bind_group(
        &self,
        gpu: &GpuContext,
        call: &'static str,
        uniform: &wgpu::Buffer,
        textures: &ImpostorTextures,
        lod: Option<&ImpostorLodView<'_>>,
    ) -> Result<wgpu::BindGroup, GpuError> {
        gpu.guarded(call, || {
            let view = |t: &wgpu::Texture| t.create_view(&Default::default());
            let (color, normal_depth) = (view(&textures.color), view(&textures.normal_depth));
            let mut entries = vec![
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&color),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&normal_depth),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::Sampler(&textures.sampler),
                },
            ];
            entries.extend(lod.map(|lod| wgpu::BindGroupEntry {
                binding: 4,
                resource: wgpu::BindingResource::TextureView(lod.visibility),
            }));
            Ok(gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("impostor"),
                layout: self.group(),
                entries: &entries,
            }))
        })
    }
}

/// What a bind group binds: the atlas's colour and normal-depth textures, its sampler, the
/// visibility pattern's view.
type Bound = (
    wgpu::Texture,
    wgpu::Texture,
    wgpu::Sampler,
    Option<wgpu::TextureView>,
);

/// What a bind group for `textures` and `lod` binds.
fn bound(textures: &ImpostorTextures, lod: Option<&ImpostorLodView<'_>>) -> Bound {
    (
        textures.color.clone(),
        textures.normal_depth.clone(),
        textures.sampler.clone(),
        lod.map(|lod| lod.visibility.clone()),
    )
}

/// A vertex buffer of `capacity` instances holding `words` first.
fn instance_buffer(
    gpu: &GpuContext,
    words: &[InstanceWords],
    capacity: usize,
) -> Result<wgpu::Buffer, GpuError> {
    let mut all = words.to_vec();
    all.resize(
        capacity.max(words.len()).max(1),
        bytemuck::Zeroable::zeroed(),
    );
    buffer_with_data(
        gpu,
        bytemuck::cast_slice(&all),
        wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        "impostor instances",
    )
}
