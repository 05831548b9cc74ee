//! Baking the alpha mask of a billboard impostor: the tree it stands for, drawn head-on through
//! an orthographic camera that maps its front (x, y) extent onto the mask.

use glam::{Mat4, Vec3, Vec4};
use lodkit::alpha_mask::AlphaMask;
use lodkit::gpu::readback::read_texture_rgba8;
use lodkit::gpu::{GpuContext, GpuError};
use lodkit::unpopping::LodRenderState;
use lodkit_scenes::mesh::{DrawItem, GpuMesh, MeshFrame, MeshRenderer, RenderTarget};

use super::scene::Shape;

/// Texels per side of a baked mask.
pub const MASK_SIZE: u32 = 128;

/// The alpha mask of `impostor` (a [`Shape::Impostor`]; `None` for other shapes): its tree's
/// silhouette seen along -z, over [`Shape::card_rect`], row 0 at the top.
pub fn bake(
    gpu: &GpuContext,
    renderer: &MeshRenderer,
    impostor: Shape,
) -> Result<Option<AlphaMask>, GpuError> {
    let Some(tree) = impostor.impostor_of() else {
        return Ok(None);
    };
    let mesh = tree.mesh();
    let (min, max) = impostor.card_rect();
    let (near_z, far_z) = mesh
        .bounds()
        .map_or((-1.0, 1.0), |(lo, hi)| (lo.z - 1.0, hi.z + 1.0));
    let view = glam::camera::rh::view::look_at_mat4(Vec3::Z * far_z, Vec3::ZERO, Vec3::Y);
    let depth = far_z - near_z;
    let proj =
        glam::camera::rh::proj::directx::orthographic(min.x, max.x, min.y, max.y, 0.01, depth);
    let target = RenderTarget::new(gpu, MASK_SIZE, MASK_SIZE)?;
    let gpu_mesh = GpuMesh::new(gpu, &mesh)?;
    let item = DrawItem {
        mesh: &gpu_mesh,
        model: Mat4::IDENTITY,
        color: Vec4::ONE,
        state: LodRenderState::OPAQUE,
        dither_alpha: None,
        sway: [0.0; 2],
        alpha_rect: Vec4::ZERO,
    };
    let black = wgpu::Color::BLACK;
    renderer.render(
        gpu,
        &target,
        &MeshFrame {
            clear: black,
            view_proj: proj * view,
            light_dir: Vec3::Z,
            items: &[item],
            ..Default::default()
        },
    )?;
    // Lit white with an ambient term: every covered texel is well above black.
    let texels = read_texture_rgba8(gpu, &target.color)?
        .chunks(4)
        .map(|p| f32::from(u8::from(p[..3].iter().any(|&c| c > 8))))
        .collect();
    Ok(Some(AlphaMask {
        size: MASK_SIZE,
        texels,
    }))
}
