//! The host side of an impostor draw: the view, the frame-sequential view, the instances, and
//! the words the pass's uniform and vertex stage read (`passes/impostor.wgsl`).

use super::ImpostorTextures;
use crate::frame_sequential::FrameDraw;
use crate::visibility::VisibilitySpace;

/// The view impostors are drawn for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImpostorView {
    /// World to clip (wgpu's clip space: z in [0, 1]).
    pub view_proj: glam::Mat4,
    /// The camera's world position.
    pub eye: glam::Vec3,
    /// World-space direction toward the light (unit length).
    pub light: glam::Vec3,
    /// The ambient share of the lighting, in [0, 1].
    pub ambient: f32,
}

/// What the frame-sequential passes ([`ImpostorTarget::LodBuffer`](super::ImpostorTarget::LodBuffer)) need beyond the view: the
/// previous frame's camera and the visibility pattern.
#[derive(Clone, Copy, Debug)]
pub struct ImpostorLodView<'a> {
    /// The previous frame's world to clip (this frame's when there is none): where a surface
    /// point was, for its object motion and for where the pattern is read next frame.
    pub prev_view_proj: glam::Mat4,
    /// The LOD buffers' size in pixels.
    pub size: (u32, u32),
    /// The visibility pattern (`R32Float`, read with `textureLoad`): the one the mesh levels are
    /// drawn with and the combine reads (`CombineCoverage::Known::pattern`).
    pub visibility: &'a wgpu::TextureView,
    /// Where the pattern is anchored: on the screen, one texel per pixel (lodkit's default), or
    /// on the surface point the frames saw.
    pub space: VisibilitySpace,
    /// Pattern repeats per object-space unit where it is anchored to the object (finite,
    /// positive; the mesh levels' value).
    pub vis_scale: f32,
}

/// One impostor instance: its object-to-world transform (a rotation, a uniform scale and a
/// translation; the card and the depth it writes assume no shear), its screen-door alpha and,
/// in a LOD buffer, its instance id and visibility thresholds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImpostorInstance {
    /// Object to world.
    pub model: glam::Mat4,
    /// The complementary screen-door pattern's alpha (`lodkit::screen_door`), in [-1, 1]: 1
    /// draws every pixel; in a transition from a mesh level at `-(1 - t)` the impostor takes
    /// `t` (or the other way round), and the two cover disjoint pixels whose union is the
    /// object's. Values outside are clamped, a NaN taken as 1. Not read in a LOD buffer.
    pub alpha: f32,
    /// LOD buffer: the previous frame's object to world (`model` for an object that did not
    /// move), for the object motion.
    pub prev_model: glam::Mat4,
    /// LOD buffer: the instance id (`FrameDraw::id`; 0: an n-instance, always shown).
    pub id: u32,
    /// LOD buffer: the visibility threshold this frame (`FrameDraw::tau`).
    pub tau: f32,
    /// LOD buffer: the threshold next frame (`FrameDraw::tau_next`).
    pub tau_next: f32,
    /// Linear RGB the baked base colour is multiplied with (1: as baked): one atlas for
    /// objects that differ only in colour.
    pub tint: glam::Vec3,
}

impl ImpostorInstance {
    /// An instance at `model` that did not move, drawn whole (alpha 1; in a LOD buffer an
    /// n-instance).
    pub fn new(model: glam::Mat4) -> Self {
        Self {
            model,
            alpha: 1.0,
            prev_model: model,
            id: 0,
            tau: 1.0,
            tau_next: 1.0,
            tint: glam::Vec3::ONE,
        }
    }

    /// An instance at `model` (at `prev_model` the frame before) drawn into a LOD buffer as the
    /// scheduler's `draw` says (`TransitionScheduler::draw`).
    pub fn from_draw(model: glam::Mat4, prev_model: glam::Mat4, draw: &FrameDraw) -> Self {
        Self {
            prev_model,
            id: draw.id,
            tau: draw.tau,
            tau_next: draw.tau_next,
            ..Self::new(model)
        }
    }
}

/// Rust mirror of `ImpostorView` in `passes/impostor.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct ViewUniform {
    view_proj: [f32; 16],
    eye: [f32; 4],
    light: [f32; 4],
    sphere: [f32; 4],
    atlas: [u32; 4],
    prev_view_proj: [f32; 16],
    viewport: [f32; 4],
}

/// Rust mirror of the instance attributes of `vs_main` in `passes/impostor.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct InstanceWords {
    model: [f32; 16],
    /// Screen-door alpha, tau, tau next, unused.
    door: [f32; 4],
    /// Instance id, unused x 3.
    id: [u32; 4],
    prev_model: [f32; 16],
    /// The tint, 1.
    tint: [f32; 4],
}

/// The attributes of [`InstanceWords`].
pub(super) const INSTANCE_ATTRIBUTES: [wgpu::VertexAttribute; 11] = wgpu::vertex_attr_array![
    0 => Float32x4, 1 => Float32x4, 2 => Float32x4, 3 => Float32x4, 4 => Float32x4,
    5 => Uint32x4, 6 => Float32x4, 7 => Float32x4, 8 => Float32x4, 9 => Float32x4,
    10 => Float32x4
];

/// The instances as the vertex stage reads them.
pub(super) fn instance_words(instances: &[ImpostorInstance]) -> Vec<InstanceWords> {
    instances
        .iter()
        .map(|i| InstanceWords {
            model: i.model.to_cols_array(),
            door: [
                match i.alpha.is_nan() {
                    true => 1.0,
                    false => i.alpha.clamp(-1.0, 1.0),
                },
                i.tau,
                i.tau_next,
                0.0,
            ],
            id: [i.id, 0, 0, 0],
            prev_model: i.prev_model.to_cols_array(),
            tint: i.tint.extend(1.0).to_array(),
        })
        .collect()
}

/// The view's uniform for `textures`' layout.
pub(super) fn view_uniform(
    textures: &ImpostorTextures,
    view: &ImpostorView,
    lod: Option<&ImpostorLodView<'_>>,
) -> ViewUniform {
    let l = textures.layout;
    let (prev_view_proj, viewport) = match lod {
        Some(lod) => (
            lod.prev_view_proj,
            [
                lod.size.0 as f32,
                lod.size.1 as f32,
                f32::from(u8::from(lod.space == VisibilitySpace::Screen)),
                lod.vis_scale,
            ],
        ),
        None => (view.view_proj, [0.0; 4]),
    };
    ViewUniform {
        view_proj: view.view_proj.to_cols_array(),
        eye: view.eye.extend(1.0).to_array(),
        light: view.light.extend(view.ambient.clamp(0.0, 1.0)).to_array(),
        sphere: [l.center[0], l.center[1], l.center[2], l.radius],
        atlas: [l.frames, u32::from(l.shape.is_hemi()), l.frame_size, 0],
        prev_view_proj: prev_view_proj.to_cols_array(),
        viewport,
    }
}
