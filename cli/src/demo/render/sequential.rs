//! The frame-sequential runs of a [`SceneRenderer`]: the scheduler, one LOD buffer per frame,
//! the levels' silhouettes, and the combine over the t-instances' rectangles.

use glam::{Mat4, Vec3};

use super::{Background, CLEAR, Coverage, Frame, LEAD_FRAMES, RunSpec, SceneRenderer, color};
use crate::demo::technique::OBJECT;
use lodkit::combine::{
    DepthConvention, PixelSource, ScreenRect, combine_images, merge_rects, screen_rect,
};
use lodkit::combine_coverage::{
    CombineData, CombineDataDescriptor, CombineObjectData, CoverageRoute,
};
use lodkit::frame_sequential::{Drive, Schedule, TransitionScheduler};
use lodkit::gpu::frame_sequential::{
    CombineCoverage, CombineFrame, CombinePass, CombineRegions, read_lod_image,
};
use lodkit::gpu::readback::read_texture_rgba8;
use lodkit::gpu::{GpuContext, GpuError};
use lodkit::reproject::new_to_old_matrix;
use lodkit::silhouette::Segment;
use lodkit::visibility::{VisibilityPattern, VisibilitySpace};
use lodkit_scenes::lod_buffer::{LodBufferFrame, LodDrawItem, LodView};

impl SceneRenderer<'_> {
    /// The silhouette of object `i`'s level `lod` at `frame` (swayed as `sway_offset` in
    /// `passes/lod_buffer_mesh.wgsl` moves it) under `view_proj`; `None` where that level has
    /// no surface or a point of it lies behind the camera.
    fn silhouette(
        &self,
        i: usize,
        lod: usize,
        frame: usize,
        view: Mat4,
        proj: Mat4,
    ) -> Option<Vec<Segment>> {
        let surface = self.surfaces[i][lod].as_ref()?;
        let model = self.scene.model(i);
        let eye = (view * model).inverse().transform_point3(Vec3::ZERO);
        let [amplitude, phase] = self.sway(i, frame);
        let sway = |p: Vec3| {
            let reach = amplitude * (p.y + 1.0).max(0.0) * (phase + p.x + p.z).sin();
            p + Vec3::new(reach, 0.0, 0.0)
        };
        let front_ccw = model.determinant() > 0.0;
        surface
            .silhouette_displaced(proj * view * model, eye, self.size, front_ccw, sway)
            .ok()
    }

    pub(super) fn run_frame_sequential(
        &self,
        gpu: &GpuContext,
        (pattern, schedule, space, coverage): (
            VisibilityPattern,
            Schedule,
            VisibilitySpace,
            Coverage,
        ),
        spec: RunSpec,
        wanted: &dyn Fn(usize) -> bool,
        on_frame: &mut dyn FnMut(usize, Frame),
        mut on_sources: Option<&mut dyn FnMut(Vec<PixelSource>)>,
    ) -> Result<(), GpuError> {
        let renderer = match (pattern, space) {
            (_, OBJECT) => &self.lod_buffer[2],
            (VisibilityPattern::BlueNoise, _) => &self.lod_buffer[1],
            _ => &self.lod_buffer[0],
        };
        let mut scheduler = TransitionScheduler::with_schedule(schedule);
        let keys: Vec<_> = self
            .scene
            .objects
            .iter()
            .map(|o| match o.transition && !spec.transition {
                true => scheduler.insert(u8::from(spec.hold_level > 0)),
                false => scheduler.insert(0),
            })
            .collect();
        let clear = match spec.background {
            Background::Scene => CLEAR,
            Background::Flat(c) => c,
        };
        let mut previous: Option<Mat4> = None;
        // The level each object was drawn at last frame: the one the older buffer holds.
        let mut older_lod: Vec<Option<usize>> = vec![None; keys.len()];
        let middle = LEAD_FRAMES + self.frames / 2;
        for frame in 0..self.run_length() {
            if frame > 0 {
                scheduler.advance(1.0 / 30.0);
            }
            // Progress is set from the frame number, exactly as the single-frame techniques
            // get it (a time drive sums dt and could end a frame late).
            for (o, key) in self.scene.objects.iter().zip(&keys) {
                if !(o.transition && spec.transition) {
                    continue;
                }
                // A fresh scheduler has ids to spare and the keys are live: these cannot fail.
                if frame == LEAD_FRAMES {
                    let _ = scheduler.begin_transition(*key, 1, Drive::Progress);
                }
                if frame >= LEAD_FRAMES {
                    let _ = scheduler.set_progress(*key, self.progress(frame));
                    let _ = scheduler.set_next_progress(*key, self.progress(frame + 1));
                }
            }
            let (view, proj) = self.camera(frame, spec.moving);
            let items: Vec<LodDrawItem> = keys
                .iter()
                .enumerate()
                .filter_map(|(i, key)| {
                    let d = scheduler.draw(*key).ok()?;
                    let lod = usize::from(d.lod.min(1));
                    let mut item = LodDrawItem::from_draw(
                        &self.meshes[i][lod],
                        self.scene.model(i),
                        self.object_color(i, lod, spec.background),
                        &d,
                    );
                    item.sway = self.sway(i, frame);
                    item.prev_sway_phase = self.sway(i, frame.saturating_sub(1))[1];
                    item.alpha_rect = self.alpha_rects[i][lod];
                    Some(item)
                })
                .collect();
            let index = scheduler.buffer_index();
            let lod_view = LodView {
                view_proj: proj * view,
                prev_view_proj: proj * previous.unwrap_or(view),
            };
            let (triangles, fragments) = renderer.render(
                gpu,
                &self.buffers,
                &LodBufferFrame {
                    index,
                    view: lod_view,
                    items: &items,
                    clear: color(clear),
                    counter: Some(&self.counter),
                },
            )?;
            let m = previous.map_or(CombinePass::NO_HISTORY, |old| {
                new_to_old_matrix(&view, &proj, &old, &proj)
            });
            // The combine runs over the screen rectangles of the t-instances, where this frame's
            // and the previous frame's views see them; the rest of the frame is a copy.
            let views = [proj * view, proj * previous.unwrap_or(view)];
            let regions: Vec<ScreenRect> = keys
                .iter()
                .enumerate()
                .filter(|(_, key)| scheduler.in_transition(**key))
                .filter_map(|(i, _)| {
                    let bounds = self.animated_bounds(i)?;
                    screen_rect(bounds, self.scene.model(i), &views, self.size, 2)
                })
                .collect();
            // Every pixel of either buffer that holds an object in transition must lie inside
            // them: outside, the output is the newer buffer alone.
            let t_ids: Vec<u32> = keys
                .iter()
                .filter(|key| scheduler.in_transition(**key))
                .filter_map(|key| scheduler.draw(*key).ok().map(|d| d.id))
                .collect();
            let merged = merge_rects(&regions);
            let newer = read_lod_image(gpu, &self.buffers, index)?;
            let older = read_lod_image(gpu, &self.buffers, 1 - index)?;
            for image in [&newer, &older] {
                let outside = image.ids.iter().enumerate().filter(|&(p, id)| {
                    let (x, y) = (p as u32 % image.width, p as u32 / image.width);
                    *id != 0 && t_ids.contains(id) && !merged.iter().any(|r| r.contains(x, y))
                });
                let count = outside.count() as u64;
                self.outside_rects.set(self.outside_rects.get() + count);
            }
            // The silhouettes of the levels the older buffer holds, under this frame's camera.
            let silhouettes: Vec<(u32, Option<Vec<Segment>>)> = match coverage {
                Coverage::Estimated => Vec::new(),
                Coverage::Silhouettes => keys
                    .iter()
                    .enumerate()
                    .filter(|(_, key)| scheduler.in_transition(**key))
                    .filter_map(|(i, key)| {
                        let id = scheduler.draw(*key).ok()?.id;
                        let lod = older_lod[i]?;
                        Some((id, self.silhouette(i, lod, frame, view, proj)))
                    })
                    .collect(),
            };
            let objects: Vec<CombineObjectData> = silhouettes
                .iter()
                .map(|(id, segments)| CombineObjectData {
                    id: *id,
                    new_to_old: m,
                    older_tau: None,
                    route: segments
                        .as_deref()
                        .map_or(CoverageRoute::Estimate, CoverageRoute::Silhouette),
                })
                .collect();
            let data = match coverage {
                Coverage::Estimated => None,
                Coverage::Silhouettes => Some(
                    CombineData::new(&CombineDataDescriptor {
                        new_to_old: m,
                        object_motion: true,
                        height: self.size.1,
                        objects: &objects,
                        ..Default::default()
                    })
                    .map_err(|e| GpuError::Invalid {
                        call: "SceneRenderer::run",
                        parameter: "the combine's data",
                        value: e.to_string(),
                        rule: "must be what CombineData::new lays out",
                    })?,
                ),
            };
            let mut encoder = gpu.device.create_command_encoder(&Default::default());
            let target = self.combined.create_view(&Default::default());
            let recording = CombineFrame {
                buffers: &self.buffers,
                newer: index,
                new_to_old: m,
                target: &target,
                regions: CombineRegions::Only(&regions),
                coverage: data.as_ref().map_or(CombineCoverage::Estimated, |data| {
                    CombineCoverage::Known {
                        data,
                        level_depth: None,
                    }
                }),
            };
            let combined = self.combine.record(gpu, &mut encoder, &recording)?;
            gpu.queue.submit([encoder.finish()]);
            for (i, key) in keys.iter().enumerate() {
                older_lod[i] = scheduler.draw(*key).ok().map(|d| usize::from(d.lod.min(1)));
            }
            if let Some(f) = on_sources.as_mut().filter(|_| frame == middle) {
                let sources = combine_images(&newer, &older, &m, DepthConvention::Standard);
                f(sources.iter().map(|p| p.source).collect());
            }
            if wanted(frame) {
                // The combine pass shades each pixel of its rectangles once more.
                let pixels = read_texture_rgba8(gpu, &self.combined)?;
                let fragments = fragments + combined;
                on_frame(
                    frame,
                    Frame {
                        pixels,
                        triangles,
                        fragments,
                    },
                );
            }
            previous = Some(view);
        }
        Ok(())
    }
}
