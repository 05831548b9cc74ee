//! wgpu states for single-frame LOD transitions: map a [`LodRenderState`] (unpopping, cross-fade,
//! opaque) onto depth-stencil and blend state.
//!
//! The blend uses the blend constant (`set_blend_constant`) as alpha, so one shader serves every
//! role: two pipelines per material (opaque and blended) are all an engine needs.

use crate::unpopping::LodRenderState;

/// Depth state of a LOD: depth-tested with `compare` (use `Less` for standard Z, `Greater` for
/// reversed Z), writing depth only when the state says so.
pub fn lod_depth_stencil(
    state: &LodRenderState,
    format: wgpu::TextureFormat,
    compare: wgpu::CompareFunction,
) -> wgpu::DepthStencilState {
    wgpu::DepthStencilState {
        format,
        depth_write_enabled: Some(state.depth_write),
        depth_compare: Some(if state.depth_test {
            compare
        } else {
            wgpu::CompareFunction::Always
        }),
        stencil: Default::default(),
        bias: Default::default(),
    }
}

/// Blend state of a LOD: `None` when opaque; otherwise color = src x C + dst x (1 - C) with C the
/// blend constant (set it with [`lod_blend_constant`]).
pub fn lod_blend(state: &LodRenderState) -> Option<wgpu::BlendState> {
    state.blend.then_some(wgpu::BlendState {
        color: wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::Constant,
            dst_factor: wgpu::BlendFactor::OneMinusConstant,
            operation: wgpu::BlendOperation::Add,
        },
        alpha: wgpu::BlendComponent::OVER,
    })
}

/// The blend constant to set before drawing a LOD in `state` (its alpha in every channel).
pub fn lod_blend_constant(state: &LodRenderState) -> wgpu::Color {
    let a = f64::from(state.alpha.clamp(0.0, 1.0));
    wgpu::Color {
        r: a,
        g: a,
        b: a,
        a,
    }
}
