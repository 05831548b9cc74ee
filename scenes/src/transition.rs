//! A reference scene for single-frame LOD transitions: an object with two LODs (a fine sphere and
//! a coarse one) in front of a contrasting object, rendered at any point of a transition with any
//! technique. The examples, the tests and the demo measure the techniques on it.

use glam::{Mat4, Vec3, Vec4};

use crate::mesh::{DrawItem, GpuMesh, Mesh, MeshFrame, MeshRenderer, RenderTarget};
use lodkit::gpu::readback::read_texture_rgba8;
use lodkit::gpu::{GpuContext, GpuError};
use lodkit::screen_door::DitherPattern;
use lodkit::select::LodSelection;
use lodkit::unpopping::{LodRenderState, LodRole, TransitionPlan, cross_fade_plan, unpopping_plan};

/// How a single-frame transition is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SingleFrameTechnique {
    /// The new LOD replaces the old at t = 0.5.
    HardSwitch,
    /// Conventional (1 - t, t) alpha cross-fade, no depth writes.
    CrossFade,
    /// Complementary screen-door dither (DigitalRune).
    Dither(DitherPattern),
    /// Giegl & Wimmer's unpopping.
    Unpopping,
}

impl SingleFrameTechnique {
    /// Every technique, for comparisons.
    pub const ALL: [SingleFrameTechnique; 5] = [
        Self::HardSwitch,
        Self::CrossFade,
        Self::Dither(DitherPattern::Bayer4x4),
        Self::Dither(DitherPattern::BlueNoise16x16),
        Self::Unpopping,
    ];

    /// The screen-door pattern the technique draws with, if it dithers.
    pub fn dither_pattern(self) -> Option<DitherPattern> {
        match self {
            Self::Dither(p) => Some(p),
            _ => None,
        }
    }

    /// Short name for tables and file names.
    pub fn name(self) -> &'static str {
        match self {
            Self::HardSwitch => "hard-switch",
            Self::CrossFade => "cross-fade",
            Self::Dither(DitherPattern::Bayer4x4) => "dither-bayer",
            Self::Dither(DitherPattern::BlueNoise16x16) => "dither-blue-noise",
            Self::Unpopping => "unpopping",
        }
    }
}

/// Color of the fine LOD (no red, so any red in its pixels came from behind).
pub const FINE_COLOR: Vec4 = Vec4::new(0.0, 0.9, 0.3, 1.0);
/// Color of the coarse LOD.
pub const COARSE_COLOR: Vec4 = Vec4::new(0.0, 0.45, 1.0, 1.0);
/// Color of the object behind (pure red).
pub const BACKDROP_COLOR: Vec4 = Vec4::new(1.0, 0.0, 0.0, 1.0);

/// The scene, on the GPU, ready to render at any t.
#[derive(Debug)]
pub struct TransitionScene {
    renderers: [MeshRenderer; 2],
    fine: GpuMesh,
    coarse: GpuMesh,
    backdrop: GpuMesh,
    target: RenderTarget,
    size: (u32, u32),
}

/// Which parts of the scene to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneParts {
    /// Backdrop and the LOD object in transition.
    All,
    /// Only the fine LOD, opaque (for masks).
    FineOnly,
    /// Only the coarse LOD, opaque (for masks).
    CoarseOnly,
}

impl TransitionScene {
    /// Builds meshes, pipelines and a `width` x `height` target (a zero side is taken as 1).
    pub fn new(gpu: &GpuContext, width: u32, height: u32) -> Result<Self, GpuError> {
        gpu.guarded("TransitionScene::new", || Self::build(gpu, width, height))
    }

    fn build(gpu: &GpuContext, width: u32, height: u32) -> Result<Self, GpuError> {
        let target = RenderTarget::new(gpu, width, height)?;
        let bayer = MeshRenderer::new(gpu, false)?;
        let blue = MeshRenderer::new(gpu, true)?;
        let fine = GpuMesh::new(gpu, &Mesh::sphere(24, 48))?;
        let coarse = GpuMesh::new(gpu, &Mesh::sphere(3, 6))?;
        let backdrop = GpuMesh::new(gpu, &Mesh::cube())?;
        Ok(Self {
            renderers: [bayer, blue],
            fine,
            coarse,
            backdrop,
            size: target.size(),
            target,
        })
    }

    /// Size of the images.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    fn view_proj(&self) -> Mat4 {
        let aspect = self.size.0 as f32 / self.size.1 as f32;
        let proj = glam::camera::rh::proj::directx::perspective(0.9, aspect, 0.1, 50.0);
        let view =
            glam::camera::rh::view::look_at_mat4(Vec3::new(0.0, 0.4, 4.0), Vec3::ZERO, Vec3::Y);
        proj * view
    }

    /// Renders the scene with `technique` at transition progress `t` (fine -> coarse) and returns
    /// RGBA8 pixels, rows top to bottom.
    pub fn render(
        &self,
        gpu: &GpuContext,
        technique: SingleFrameTechnique,
        t: f32,
        parts: SceneParts,
    ) -> Result<Vec<u8>, GpuError> {
        let model = Mat4::from_scale(Vec3::splat(1.1));
        let mut items = Vec::new();
        if parts == SceneParts::All {
            items.push(DrawItem {
                mesh: &self.backdrop,
                model: Mat4::from_translation(Vec3::new(0.0, 0.0, -3.0))
                    * Mat4::from_scale(Vec3::new(2.5, 2.5, 0.2)),
                color: BACKDROP_COLOR,
                state: LodRenderState::OPAQUE,
                dither_alpha: None,
                sway: [0.0; 2],
                alpha_rect: Vec4::ZERO,
            });
        }
        // One LOD alone is a hard switch before (fine) or after (coarse) it happens.
        let (technique, t) = match parts {
            SceneParts::All => (technique, t),
            SceneParts::FineOnly => (SingleFrameTechnique::HardSwitch, 0.0),
            SceneParts::CoarseOnly => (SingleFrameTechnique::HardSwitch, 1.0),
        };
        items.extend(transition_items(
            technique,
            t,
            model,
            (&self.fine, FINE_COLOR),
            (&self.coarse, COARSE_COLOR),
        ));
        let pattern = technique
            .dither_pattern()
            .unwrap_or(DitherPattern::Bayer4x4);
        let renderer = &self.renderers[usize::from(pattern == DitherPattern::BlueNoise16x16)];
        let clear = wgpu::Color {
            r: 0.02,
            g: 0.02,
            b: 0.05,
            a: 1.0,
        };
        gpu.recording("TransitionScene::render", || {
            renderer.render(
                gpu,
                &self.target,
                &MeshFrame {
                    clear,
                    view_proj: self.view_proj(),
                    light_dir: Vec3::new(0.4, 0.8, 0.6),
                    items: &items,
                    ..Default::default()
                },
            )?;
            read_texture_rgba8(gpu, &self.target.color)
        })
    }
}

/// The draws of one object in transition from `outgoing` to `incoming` (mesh and color each) at
/// progress `t`, drawn with `technique`, in the order to draw them. Blended items (cross-fade,
/// unpopping) belong after the scene's opaque objects; a dithering technique needs a renderer
/// with its [`SingleFrameTechnique::dither_pattern`]. Outside the transition (t <= 0 or NaN,
/// t >= 1) only the visible LOD is drawn, opaque.
pub fn transition_items<'a>(
    technique: SingleFrameTechnique,
    t: f32,
    model: Mat4,
    outgoing: (&'a GpuMesh, Vec4),
    incoming: (&'a GpuMesh, Vec4),
) -> Vec<DrawItem<'a>> {
    let item = |role, state, dither_alpha| {
        let (mesh, color) = match role {
            LodRole::Outgoing => outgoing,
            LodRole::Incoming => incoming,
        };
        DrawItem {
            mesh,
            model,
            color,
            state,
            dither_alpha,
            sway: [0.0; 2],
            alpha_rect: Vec4::ZERO,
        }
    };
    // Before and after the transition only one LOD is visible: draw only that one.
    if technique != SingleFrameTechnique::HardSwitch && !(t > 0.0 && t < 1.0) {
        let role = if t >= 1.0 {
            LodRole::Incoming
        } else {
            LodRole::Outgoing
        };
        return vec![item(role, LodRenderState::OPAQUE, None)];
    }
    match technique {
        SingleFrameTechnique::HardSwitch => {
            let role = if t < 0.5 {
                LodRole::Outgoing
            } else {
                LodRole::Incoming
            };
            vec![item(role, LodRenderState::OPAQUE, None)]
        }
        SingleFrameTechnique::Dither(_) => {
            let selection = LodSelection {
                current: 0,
                next: Some(1),
                transition: t,
                fade: 1.0,
                visible: true,
            };
            let (current, next) = selection.screen_door_alphas();
            vec![
                item(LodRole::Outgoing, LodRenderState::OPAQUE, Some(current)),
                item(LodRole::Incoming, LodRenderState::OPAQUE, next),
            ]
        }
        SingleFrameTechnique::CrossFade | SingleFrameTechnique::Unpopping => {
            let plan: TransitionPlan = if technique == SingleFrameTechnique::Unpopping {
                unpopping_plan(t)
            } else {
                cross_fade_plan(t)
            };
            plan.order
                .iter()
                .map(|&role| item(role, plan.state(role), None))
                .collect()
        }
    }
}

/// See-through of a transition image: among the pixels both LODs cover (`fine_mask` and
/// `coarse_mask` rendered with [`SceneParts`]), the share where the red backdrop contributes
/// (red above 2/255), and the mean red there (0..1). Pixels past the end of a shorter mask count
/// as not covered.
pub fn see_through(image: &[u8], fine_mask: &[u8], coarse_mask: &[u8]) -> (f32, f32) {
    let covered = |mask: &[u8], i: usize| {
        mask.get(i * 4 + 1..i * 4 + 3)
            .is_some_and(|gb| gb[0] > 20 || gb[1] > 20)
    };
    let (mut interior, mut seen, mut red) = (0usize, 0usize, 0.0f32);
    for (i, pixel) in image.chunks_exact(4).enumerate() {
        if covered(fine_mask, i) && covered(coarse_mask, i) {
            interior += 1;
            let r = pixel[0];
            if r > 2 {
                seen += 1;
            }
            red += f32::from(r) / 255.0;
        }
    }
    if interior == 0 {
        return (0.0, 0.0);
    }
    (seen as f32 / interior as f32, red / interior as f32)
}
