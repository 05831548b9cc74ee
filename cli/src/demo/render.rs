//! Renders a [`DemoScene`] frame by frame with any transition technique: single-frame techniques
//! through [`MeshRenderer`], frame-sequential through the LOD buffers and the combine pass.

use glam::{Mat4, Vec3, Vec4};

mod sequential;

use super::impostor::bake;
use super::scene::DemoScene;
use lodkit::combine::{PixelSource, ScreenRect, displaced_bounds, screen_rect};
use lodkit::gpu::counters::FragmentCounter;
use lodkit::gpu::frame_sequential::{CombinePass, CombinePassDescriptor, LodBuffers};
use lodkit::gpu::readback::read_texture_rgba8;
use lodkit::gpu::resources::texture_2d;
use lodkit::gpu::{GpuContext, GpuError};
use lodkit::screen_door::DitherPattern;
use lodkit::silhouette::Surface;
use lodkit::unpopping::LodRenderState;
use lodkit::visibility::{VisibilityPattern, visibility_texture};
use lodkit_scenes::lod_buffer::LodBufferRenderer;
use lodkit_scenes::mesh::{DrawItem, GpuMesh, MeshFrame, MeshRenderer, RenderTarget};
use lodkit_scenes::transition::{SingleFrameTechnique, transition_items};

use super::technique::OBJECT;
pub use super::technique::{Coverage, Technique};

/// What the scene's non-transitioning objects and the clear color look like.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Background {
    /// As the scene describes them.
    Scene,
    /// Everything but the transitioning objects in one flat color (see-through measurement).
    Flat(Vec4),
}

/// One rendered frame.
#[derive(Clone, Debug)]
pub struct Frame {
    /// RGBA8 pixels, rows top to bottom.
    pub pixels: Vec<u8>,
    /// Triangles submitted.
    pub triangles: u64,
    /// The pass's [`FragmentCounter`] reading.
    pub fragments: u64,
}

/// One run of a technique over a scene.
#[derive(Clone, Copy, Debug)]
pub struct RunSpec {
    /// Technique.
    pub technique: Technique,
    /// Whether the camera moves from `eye` to `moving_eye`.
    pub moving: bool,
    /// Whether the transitioning objects transition (false: they stay at `hold_level`, a
    /// reference that camera motion is measured against).
    pub transition: bool,
    /// The level the transitioning objects stay at when they do not transition: 0 the fine
    /// one (where a transition starts), 1 the coarse one (where it ends).
    pub hold_level: usize,
    /// Background.
    pub background: Background,
}

/// Frames before the transition starts (and after it ends) in every run.
pub const LEAD_FRAMES: usize = 2;

/// The scene on the GPU with everything needed to render it with each technique.
#[derive(Debug)]
pub struct SceneRenderer<'a> {
    scene: &'a DemoScene,
    size: (u32, u32),
    frames: usize,
    meshes: Vec<[GpuMesh; 2]>,
    /// Object-space box of both LODs of each object.
    bounds: Vec<Option<(Vec3, Vec3)>>,
    /// Alpha mask rect of both LODs of each object (zero: no alpha test).
    alpha_rects: Vec<[Vec4; 2]>,
    /// Surface of both LODs of each object, for their silhouettes; `None` for a level whose
    /// coverage is not its silhouette (alpha-masked, or not a closed mesh).
    surfaces: Vec<[Option<Surface>; 2]>,
    single: [MeshRenderer; 2],
    target: RenderTarget,
    /// White noise on the screen, blue noise on the screen, blue noise on the object.
    lod_buffer: [LodBufferRenderer; 3],
    buffers: LodBuffers,
    combine: CombinePass,
    combined: wgpu::Texture,
    counter: FragmentCounter,
    /// See [`take_outside_rects`](Self::take_outside_rects).
    outside_rects: std::cell::Cell<u64>,
}

/// Visibility texture repeats per object-space unit: at the demo's sizes a texel covers about
/// two pixels of an object in transition.
const VIS_SCALE: f32 = 0.5;

const CLEAR: Vec4 = Vec4::new(0.03, 0.03, 0.06, 1.0);
const LIGHT: Vec3 = Vec3::new(0.4, 0.8, 0.6);
const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

fn color(v: Vec4) -> wgpu::Color {
    wgpu::Color {
        r: f64::from(v.x),
        g: f64::from(v.y),
        b: f64::from(v.z),
        a: f64::from(v.w),
    }
}

impl<'a> SceneRenderer<'a> {
    /// Uploads the scene and builds every pipeline for `size` images and transitions of
    /// `frames` frames.
    pub fn new(
        gpu: &GpuContext,
        scene: &'a DemoScene,
        size: (u32, u32),
        frames: usize,
    ) -> Result<Self, GpuError> {
        let meshes = scene
            .objects
            .iter()
            .map(|o| {
                Ok([
                    GpuMesh::new(gpu, &o.fine.mesh())?,
                    GpuMesh::new(gpu, &o.coarse.mesh())?,
                ])
            })
            .collect::<Result<_, GpuError>>()?;
        let bounds = scene
            .objects
            .iter()
            .map(|o| {
                let (fine, coarse) = (o.fine.mesh().bounds(), o.coarse.mesh().bounds());
                match (fine, coarse) {
                    (Some(a), Some(b)) => Some((a.0.min(b.0), a.1.max(b.1))),
                    (a, b) => a.or(b),
                }
            })
            .collect();
        let vis = |p| visibility_texture(p, 64, 1);
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT
            | wgpu::TextureUsages::COPY_SRC
            | wgpu::TextureUsages::COPY_DST;
        let mut single = [
            MeshRenderer::new(gpu, false)?,
            MeshRenderer::new(gpu, true)?,
        ];
        let mut lod_buffer = [
            LodBufferRenderer::new(gpu, FORMAT, &vis(VisibilityPattern::WhiteNoise), VIS_SCALE)?,
            LodBufferRenderer::new(gpu, FORMAT, &vis(VisibilityPattern::BlueNoise), VIS_SCALE)?,
            LodBufferRenderer::new(gpu, FORMAT, &vis(VisibilityPattern::BlueNoise), VIS_SCALE)?,
        ];
        lod_buffer[2].set_visibility_space(OBJECT);
        // A scene has at most one kind of impostor (validated): its mask is every renderer's.
        let impostor = scene
            .objects
            .iter()
            .flat_map(|o| [o.fine, o.coarse])
            .find(|s| s.impostor_of().is_some());
        if let Some(mask) = impostor
            .map(|s| bake(gpu, &single[0], s))
            .transpose()?
            .flatten()
        {
            for r in &mut single {
                r.set_alpha_mask(gpu, &mask)?;
            }
            for r in &mut lod_buffer {
                r.set_alpha_mask(gpu, &mask)?;
            }
        }
        let alpha_rects: Vec<[Vec4; 2]> = scene
            .objects
            .iter()
            .map(|o| [o.fine.alpha_rect(), o.coarse.alpha_rect()])
            .collect();
        let surfaces = scene
            .objects
            .iter()
            .zip(&alpha_rects)
            .map(|(o, rects)| {
                let surface = |shape: super::scene::Shape, rect: Vec4| {
                    (rect == Vec4::ZERO).then(|| shape.mesh().surface().ok())?
                };
                [surface(o.fine, rects[0]), surface(o.coarse, rects[1])]
            })
            .collect();
        Ok(Self {
            scene,
            size,
            frames: frames.max(2),
            meshes,
            bounds,
            alpha_rects,
            surfaces,
            single,
            target: RenderTarget::new(gpu, size.0, size.1)?,
            lod_buffer,
            buffers: LodBuffers::new(gpu, size.0, size.1, FORMAT)?,
            combine: CombinePass::new(
                gpu,
                &CombinePassDescriptor {
                    target_format: FORMAT,
                    ..Default::default()
                },
            )?,
            combined: texture_2d(gpu, size, FORMAT, usage, "combined")?,
            counter: FragmentCounter::new(gpu)?,
            outside_rects: Default::default(),
        })
    }

    /// Frames in a run: the transition's frames plus [`LEAD_FRAMES`] before and after.
    pub fn run_length(&self) -> usize {
        self.frames + 2 * LEAD_FRAMES + 1
    }

    /// Frames the transition lasts.
    pub fn transition_frames(&self) -> usize {
        self.frames
    }

    /// Transition progress at `frame` (0 before, 1 after).
    pub fn progress(&self, frame: usize) -> f32 {
        ((frame as f32 - LEAD_FRAMES as f32) / self.frames as f32).clamp(0.0, 1.0)
    }

    /// The counter used for [`Frame::fragments`].
    pub fn counter(&self) -> &FragmentCounter {
        &self.counter
    }

    /// Screen rectangles of the transitioning objects (both LODs' box) seen by the static
    /// camera, in scene order; `None` for one off screen.
    pub fn transition_rects(&self) -> Vec<Option<ScreenRect>> {
        let (view, proj) = self.camera(0, false);
        self.scene
            .objects
            .iter()
            .enumerate()
            .filter(|(_, o)| o.transition)
            .map(|(i, _)| {
                let bounds = self.bounds[i]?;
                screen_rect(bounds, self.scene.model(i), &[proj * view], self.size, 3)
            })
            .collect()
    }

    /// Whether any object sways: the picture changes without a transition or camera motion.
    pub fn animated(&self) -> bool {
        self.scene.objects.iter().any(|o| o.sway != 0.0)
    }

    /// Sway of object `i` at `frame`: its amplitude, a phase advancing 0.35 radians per frame.
    fn sway(&self, i: usize, frame: usize) -> [f32; 2] {
        [self.scene.objects[i].sway, frame as f32 * 0.35]
    }

    /// Object `i`'s box holding every vertex its sway moves (`sway_offset` in
    /// `passes/lod_buffer_mesh.wgsl`: up to the amplitude times the height above y = -1, along x).
    fn animated_bounds(&self, i: usize) -> Option<(Vec3, Vec3)> {
        let bounds = self.bounds[i]?;
        let reach = self.scene.objects[i].sway.abs() * (bounds.1.y + 1.0).max(0.0);
        Some(displaced_bounds(bounds, Vec3::new(reach, 0.0, 0.0)))
    }

    /// Pixels of objects in transition, in either LOD buffer, outside the combine's rectangles,
    /// summed over the frame-sequential frames since the last call (0: the rectangles held all).
    pub fn take_outside_rects(&self) -> u64 {
        self.outside_rects.take()
    }

    fn camera(&self, frame: usize, moving: bool) -> (Mat4, Mat4) {
        let c = &self.scene.camera;
        let s = if moving {
            frame as f32 / (self.run_length() - 1) as f32
        } else {
            0.0
        };
        let eye = Vec3::from(c.eye).lerp(Vec3::from(c.moving_eye), s);
        let view = glam::camera::rh::view::look_at_mat4(eye, c.target.into(), Vec3::Y);
        let aspect = self.size.0 as f32 / self.size.1 as f32;
        let proj = glam::camera::rh::proj::directx::perspective(c.fov_y, aspect, 0.1, 100.0);
        (view, proj)
    }

    fn object_color(&self, i: usize, lod: usize, background: Background) -> Vec4 {
        let o = &self.scene.objects[i];
        match background {
            Background::Flat(c) if !o.transition => c,
            _ => Vec3::from(if lod == 0 {
                o.fine_color
            } else {
                o.coarse_color
            })
            .extend(1.0),
        }
    }

    /// Runs `spec` over [`Self::run_length`] frames and hands each frame `wanted` accepts to
    /// `on_frame` (single-frame techniques only render those; frame-sequential renders every
    /// frame, since each depends on the last). For frame-sequential runs `on_sources` gets which
    /// rule chose each pixel of the middle frame.
    pub fn run(
        &self,
        gpu: &GpuContext,
        spec: RunSpec,
        wanted: &dyn Fn(usize) -> bool,
        on_frame: &mut dyn FnMut(usize, Frame),
        on_sources: Option<&mut dyn FnMut(Vec<PixelSource>)>,
    ) -> Result<(), GpuError> {
        match spec.technique {
            Technique::Single(t) => {
                for f in (0..self.run_length()).filter(|&f| wanted(f)) {
                    on_frame(f, self.render_single(gpu, t, f, spec)?);
                }
                Ok(())
            }
            Technique::FrameSequential(p, schedule, space, coverage) => {
                let variant = (p, schedule, space, coverage);
                self.run_frame_sequential(gpu, variant, spec, wanted, on_frame, on_sources)
            }
        }
    }

    fn render_single(
        &self,
        gpu: &GpuContext,
        technique: SingleFrameTechnique,
        frame: usize,
        spec: RunSpec,
    ) -> Result<Frame, GpuError> {
        let (view, proj) = self.camera(frame, spec.moving);
        let t = self.progress(frame);
        let mut items: Vec<DrawItem> = Vec::new();
        let mut blended: Vec<(f32, DrawItem)> = Vec::new();
        for (i, o) in self.scene.objects.iter().enumerate() {
            let model = self.scene.model(i);
            let fine = (&self.meshes[i][0], self.object_color(i, 0, spec.background));
            if !(o.transition && spec.transition) {
                let held = if o.transition {
                    spec.hold_level.min(1)
                } else {
                    0
                };
                items.push(DrawItem {
                    mesh: &self.meshes[i][held],
                    model,
                    color: self.object_color(i, held, spec.background),
                    state: LodRenderState::OPAQUE,
                    dither_alpha: None,
                    sway: self.sway(i, frame),
                    alpha_rect: self.alpha_rects[i][held],
                });
                continue;
            }
            let coarse = (&self.meshes[i][1], self.object_color(i, 1, spec.background));
            let depth = (view * model).w_axis.z;
            for mut item in transition_items(technique, t, model, fine, coarse) {
                item.sway = self.sway(i, frame);
                let lod = usize::from(std::ptr::eq(item.mesh, coarse.0));
                item.alpha_rect = self.alpha_rects[i][lod];
                if item.state.blend {
                    blended.push((depth, item));
                } else {
                    items.push(item);
                }
            }
        }
        // Blended LODs after every opaque draw, far to near.
        blended.sort_by(|a, b| a.0.total_cmp(&b.0));
        let triangles = items
            .iter()
            .chain(blended.iter().map(|(_, i)| i))
            .map(|i| u64::from(i.mesh.triangles()))
            .sum();
        items.extend(blended.into_iter().map(|(_, i)| i));
        let blue = technique.dither_pattern() == Some(DitherPattern::BlueNoise16x16);
        let clear = match spec.background {
            Background::Scene => CLEAR,
            Background::Flat(c) => c,
        };
        let fragments = self.single[usize::from(blue)].render(
            gpu,
            &self.target,
            &MeshFrame {
                clear: color(clear),
                view_proj: proj * view,
                light_dir: LIGHT,
                items: &items,
                counter: Some(&self.counter),
            },
        )?;
        Ok(Frame {
            pixels: read_texture_rgba8(gpu, &self.target.color)?,
            triangles,
            fragments,
        })
    }

    /// Masks of the transitioning objects drawn opaque at the fine and at the coarse LOD (the
    /// scenery in black, so hidden parts do not count), at the middle frame of the static or
    /// `moving` camera: `true` where the object covers the pixel.
    pub fn lod_masks(&self, gpu: &GpuContext, moving: bool) -> Result<[Vec<bool>; 2], GpuError> {
        let middle = LEAD_FRAMES + self.frames / 2;
        let (view, proj) = self.camera(middle, moving);
        let mask = |lod: usize| -> Result<Vec<bool>, GpuError> {
            let items: Vec<DrawItem> = self
                .scene
                .objects
                .iter()
                .enumerate()
                .map(|(i, o)| {
                    let k = if o.transition { lod } else { 0 };
                    DrawItem {
                        mesh: &self.meshes[i][k],
                        model: self.scene.model(i),
                        color: if o.transition { Vec4::ONE } else { Vec4::ZERO },
                        state: LodRenderState::OPAQUE,
                        dither_alpha: None,
                        sway: self.sway(i, middle),
                        alpha_rect: self.alpha_rects[i][k],
                    }
                })
                .collect();
            self.single[0].render(
                gpu,
                &self.target,
                &MeshFrame {
                    clear: wgpu::Color::BLACK,
                    view_proj: proj * view,
                    light_dir: LIGHT,
                    items: &items,
                    ..Default::default()
                },
            )?;
            Ok(read_texture_rgba8(gpu, &self.target.color)?
                .chunks(4)
                .map(|p| p[..3].iter().any(|&c| c > 8))
                .collect())
        };
        Ok([mask(0)?, mask(1)?])
    }
}
