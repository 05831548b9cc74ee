//! Texture reads per output pixel of a timed pass, counted from its shader by
//! `lodkit::shaders::cost` (the fragment entry point `fs_main`) and weighed by the formats the
//! demo binds: they hold on any GPU (before caches), where milliseconds on a software GPU do not.

use serde::Serialize;

use lodkit::gpu::GpuError;
use lodkit::shaders::cost::{EntryCost, FetchKind, entry_point_costs};
use lodkit::shaders::{ComposeDescriptor, ShaderLibrary, compose_pass};

/// Texels one sample of a resource touches: the sampler decides.
#[derive(Clone, Copy, Debug)]
pub enum Texels {
    /// Nearest filtering, or loads only.
    One,
    /// Bilinear filtering: a 2x2 footprint.
    Linear,
}

/// Texture reads per output pixel of a pass, counted from its shader.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Reads {
    /// Fetch instructions every pixel executes (`textureLoad`, `textureSample*`, gathers).
    pub fetches: u64,
    /// Texels those fetches touch (4 for a bilinear sample or a gather).
    pub texels: u64,
    /// Bytes of those texels, by the bound formats.
    pub bytes: u64,
    /// Fetches under branches, at most (on the costliest path): a pixel makes some of them.
    pub conditional_fetches: u64,
    /// Texels of the conditional fetches.
    pub conditional_texels: u64,
    /// Bytes of the conditional fetches.
    pub conditional_bytes: u64,
}

/// (resource name in the shader, the format bound to it, texels per sample).
pub type Bound<'a> = (&'a str, wgpu::TextureFormat, Texels);

impl Reads {
    /// The reads of `fs_main` of the WGSL `source` (which may import lodkit).
    pub fn of_source(source: &str, name: &str, bound: &[Bound]) -> Result<Self, GpuError> {
        let composed = ShaderLibrary::new()?.compose(&ComposeDescriptor {
            source,
            file_path: name,
            ..Default::default()
        })?;
        Self::of_module(&composed.module, name, bound)
    }

    /// The reads of `fs_main` of lodkit's pass `shader_lib/passes/<pass>.wgsl`.
    pub fn of_pass(pass: &str, bound: &[Bound]) -> Result<Self, GpuError> {
        Self::of_pass_with(pass, &[], bound)
    }

    /// [`Self::of_pass`] with shader defs `defs` set.
    pub fn of_pass_with(pass: &str, defs: &[&str], bound: &[Bound]) -> Result<Self, GpuError> {
        let composed = compose_pass(pass, defs)?;
        Self::of_module(&composed.module, pass, bound)
    }

    fn of_module(module: &naga::Module, name: &str, bound: &[Bound]) -> Result<Self, GpuError> {
        let costs = entry_point_costs(module);
        let fs = costs.iter().find(|c| c.name == "fs_main").ok_or_else(|| {
            unfit(
                name,
                "fs_main",
                "must have a fragment entry point `fs_main`",
            )
        })?;
        Self::weigh(fs, name, bound)
    }

    fn weigh(fs: &EntryCost, name: &str, bound: &[Bound]) -> Result<Self, GpuError> {
        let mut reads = Self::default();
        for r in &fs.resources {
            let (_, format, texels) =
                bound
                    .iter()
                    .find(|(n, _, _)| *n == r.resource)
                    .ok_or_else(|| {
                        unfit(
                            name,
                            &r.resource,
                            "is read, but the demo binds no format to it",
                        )
                    })?;
            let each = match (r.kind, texels) {
                (FetchKind::Gather, _) | (FetchKind::Sample, Texels::Linear) => 4,
                _ => 1,
            };
            let size = u64::from(format.block_copy_size(None).unwrap_or(0));
            reads.fetches += r.always;
            reads.texels += r.always * each;
            reads.bytes += r.always * each * size;
            reads.conditional_fetches += r.conditional;
            reads.conditional_texels += r.conditional * each;
            reads.conditional_bytes += r.conditional * each * size;
        }
        if reads.fetches + reads.conditional_fetches != fs.worst().fetches() {
            return Err(unfit(
                name,
                "fs_main",
                "reads a texture that is not a bound global",
            ));
        }
        Ok(reads)
    }
}

/// A shader that does not fit what the demo binds to it.
fn unfit(shader: &str, value: &str, rule: &'static str) -> GpuError {
    GpuError::Invalid {
        call: "Reads::of_module",
        parameter: "shader",
        value: format!("{shader}: `{value}`"),
        rule,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lodkit::gbuffer::GEOMETRY_FORMAT;
    use lodkit::gpu::frame_sequential::LOD_DEPTH_FORMAT;
    use lodkit::lod_buffer::{ID_FORMAT, MOTION_FORMAT};

    const COLOR: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

    /// Hand-counted from `passes/upsample.wgsl`: the pixel's geometry (8 B) and the 2x2 cell's
    /// colors (4 B) and geometry (8 B), one load each.
    #[test]
    fn the_bilateral_upsample_reads_nine_texels_of_56_bytes() {
        let bound = [
            ("low_color", COLOR, Texels::One),
            ("low_geometry", GEOMETRY_FORMAT, Texels::One),
            ("full_geometry", GEOMETRY_FORMAT, Texels::One),
        ];
        let r = Reads::of_pass("upsample", &bound).unwrap();
        assert_eq!((r.fetches, r.texels, r.bytes), (9, 9, 4 * 4 + 5 * 8));
        assert_eq!(r.conditional_fetches, 0);
    }

    /// Hand-counted from `passes/combine.wgsl`: color, id and depth of both buffers, the older
    /// depth again at the reprojected estimate and the object motion, all 4-byte texels; its
    /// search for the older id loads at most 14 more ids, under branches.
    #[test]
    fn the_combine_counts_its_conditional_id_loads() {
        let buffer = |c, i, d| {
            [
                (c, COLOR, Texels::One),
                (i, ID_FORMAT, Texels::One),
                (d, LOD_DEPTH_FORMAT, Texels::One),
            ]
        };
        let mut bound = [
            buffer("newer_color", "newer_id", "newer_depth"),
            buffer("older_color", "older_id", "older_depth"),
        ]
        .concat();
        bound.push(("object_motion", MOTION_FORMAT, Texels::One));
        let r = Reads::of_pass("combine", &bound).unwrap();
        assert_eq!((r.fetches, r.texels, r.bytes), (8, 8, 32));
        assert_eq!(
            (
                r.conditional_fetches,
                r.conditional_texels,
                r.conditional_bytes
            ),
            (14, 14, 56)
        );
        assert!(
            Reads::of_pass("combine", &bound[..6]).is_err(),
            "motion unbound"
        );
    }

    #[test]
    fn a_linear_sample_touches_four_texels() {
        let source = "@group(0) @binding(0) var t: texture_2d<f32>;
@group(0) @binding(1) var s: sampler;
@fragment fn fs_main(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    return textureSample(t, s, p.xy);
}";
        let r = Reads::of_source(source, "s.wgsl", &[("t", COLOR, Texels::Linear)]).unwrap();
        assert_eq!((r.fetches, r.texels, r.bytes), (1, 4, 16));
    }
}
