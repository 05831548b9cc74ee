//! Octahedral impostors on the GPU: [`bake_impostor`] renders a mesh and its material from every
//! frame direction into an atlas ([`ImpostorAtlas`]: base colour and coverage, normal and
//! depth, frames padded, mip chains); [`ImpostorTextures`] uploads one; [`ImpostorPass`] draws
//! instances of it (`passes/impostor.wgsl`). docs/impostors.md has the whole picture.

mod baker;
mod draw;
mod instance;
mod prepare;

pub use baker::ImpostorBaker;
pub use draw::{ImpostorPass, ImpostorPassDescriptor, ImpostorTarget};
pub use instance::{ImpostorInstance, ImpostorLodView, ImpostorView};
pub use prepare::PreparedImpostors;

use glam::Vec3;

use crate::gpu::{GpuContext, GpuError};
use crate::impostor::{ImpostorAtlas, ImpostorImage, ImpostorLayout, ImpostorShape};

/// The mesh an impostor is baked from: an indexed triangle list (object space).
#[derive(Clone, Copy, Debug, Default)]
pub struct ImpostorMesh<'a> {
    /// Vertex positions.
    pub positions: &'a [[f32; 3]],
    /// Triangle list, three indices a triangle.
    pub indices: &'a [u32],
    /// Per-vertex normals; without them, the area-weighted normals of the triangles around
    /// each vertex.
    pub normals: Option<&'a [[f32; 3]]>,
    /// Per-vertex texture coordinates of the base colour texture; without them, (0, 0).
    pub uvs: Option<&'a [[f32; 2]]>,
}

/// An RGBA8 texture in sRGB (a glTF base colour texture, decoded), row-major from the top row.
#[derive(Clone, Copy, Debug)]
pub struct ImpostorTexture<'a> {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// `width * height * 4` bytes.
    pub rgba8: &'a [u8],
}

/// The material an impostor is baked with: glTF's metallic-roughness base colour and alpha
/// mode, the part of a material an impostor's picture keeps.
#[derive(Clone, Copy, Debug)]
pub struct ImpostorMaterial<'a> {
    /// Base colour factor (linear RGBA).
    pub base_color: [f32; 4],
    /// Base colour texture, multiplied with the factor.
    pub base_color_texture: Option<ImpostorTexture<'a>>,
    /// The alpha cutoff of an alpha-masked material (glTF `MASK`): fragments whose base colour
    /// alpha is below it are not part of the object. `None`: opaque.
    pub alpha_cutoff: Option<f32>,
    /// Whether back faces are drawn (their normals flipped), as glTF's `doubleSided`.
    pub double_sided: bool,
}

impl Default for ImpostorMaterial<'_> {
    /// White, untextured, opaque, single-sided.
    fn default() -> Self {
        Self {
            base_color: [1.0; 4],
            base_color_texture: None,
            alpha_cutoff: None,
            double_sided: false,
        }
    }
}

/// One part of what an impostor is baked from: a mesh and the material it is drawn with (a
/// glTF primitive). A tree is usually two: the trunk, opaque, and the leaves, alpha-masked.
#[derive(Clone, Copy, Debug, Default)]
pub struct ImpostorPart<'a> {
    /// The part's triangles.
    pub mesh: ImpostorMesh<'a>,
    /// Its material.
    pub material: ImpostorMaterial<'a>,
}

/// How to bake.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImpostorBakeDescriptor {
    /// Frames per side (2..=64; default 12: 144 directions, about 9 degrees apart on the
    /// hemisphere).
    pub frames: u32,
    /// Texels per frame side (a power of two, 4..=1024; default 128: an atlas of 1536 x 1536).
    pub frame_size: u32,
    /// Hemisphere (default: objects on the ground) or full sphere.
    pub shape: ImpostorShape,
}

impl Default for ImpostorBakeDescriptor {
    fn default() -> Self {
        Self {
            frames: 12,
            frame_size: 128,
            shape: ImpostorShape::Hemi,
        }
    }
}

/// The smallest sphere lodkit bakes around: the centre of the bounding box and the largest
/// distance of a vertex from it (at least 1e-6 of the box's diagonal, and > 0).
pub fn impostor_bounds(positions: &[[f32; 3]]) -> ([f32; 3], f32) {
    let (lo, hi) = positions.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(Vec3::from(*p)), hi.max(Vec3::from(*p))),
    );
    let center = (lo + hi) * 0.5;
    let radius = positions
        .iter()
        .map(|p| Vec3::from(*p).distance(center))
        .fold(0.0f32, f32::max);
    // Rounding in the shader's (p - centre) / radius must not push a vertex past the square.
    let radius = (radius * 1.0001)
        .max((hi - lo).length() * 1e-6)
        .max(f32::MIN_POSITIVE);
    (center.to_array(), radius)
}

/// Checks part `part`'s mesh and material before any GPU work, naming the first problem.
pub(crate) fn check_input(
    part: usize,
    mesh: &ImpostorMesh,
    material: &ImpostorMaterial,
) -> Result<(), GpuError> {
    const CALL: &str = "ImpostorBaker::new";
    let invalid = |parameter, value: String, rule| GpuError::Invalid {
        call: CALL,
        parameter,
        value: format!("part {part}: {value}"),
        rule,
    };
    let n = mesh.positions.len();
    if n == 0 || mesh.indices.is_empty() || !mesh.indices.len().is_multiple_of(3) {
        return Err(invalid(
            "mesh",
            format!("{n} vertices, {} indices", mesh.indices.len()),
            "needs vertices and a whole number of triangles",
        ));
    }
    if let Some((at, i)) = mesh
        .indices
        .iter()
        .enumerate()
        .find(|(_, i)| **i as usize >= n)
    {
        return Err(invalid(
            "mesh.indices",
            format!("{i} at position {at}"),
            "must be below the vertex count",
        ));
    }
    if let Some(at) = mesh
        .positions
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(invalid(
            "mesh.positions",
            format!("vertex {at}"),
            "must be finite",
        ));
    }
    for (parameter, len) in [
        ("mesh.normals", mesh.normals.map(<[_]>::len)),
        ("mesh.uvs", mesh.uvs.map(<[_]>::len)),
    ] {
        if let Some(len) = len.filter(|&len| len != n) {
            return Err(invalid(
                parameter,
                format!("{len} values"),
                "must have one value per vertex",
            ));
        }
    }
    if let Some(t) = material.base_color_texture {
        let want = u64::from(t.width) * u64::from(t.height) * 4;
        if t.width == 0 || t.height == 0 || t.rgba8.len() as u64 != want {
            return Err(invalid(
                "material.base_color_texture",
                format!("{} x {} with {} bytes", t.width, t.height, t.rgba8.len()),
                "must be non-empty with 4 bytes a texel",
            ));
        }
    }
    if !material.base_color.iter().all(|c| c.is_finite()) {
        return Err(invalid(
            "material.base_color",
            format!("{:?}", material.base_color),
            "must be finite",
        ));
    }
    Ok(())
}

/// Interleaved (position, normal, uv) vertices, normals from the triangles where the mesh has
/// none (a zero normal where no triangle has area).
pub(crate) fn vertices(mesh: &ImpostorMesh) -> Vec<[f32; 8]> {
    let computed;
    let normals = match mesh.normals {
        Some(n) => n,
        None => {
            let mut acc = vec![Vec3::ZERO; mesh.positions.len()];
            for t in mesh.indices.chunks_exact(3) {
                let p = [t[0], t[1], t[2]].map(|i| Vec3::from(mesh.positions[i as usize]));
                let n = (p[1] - p[0]).cross(p[2] - p[0]);
                for i in t {
                    acc[*i as usize] += n;
                }
            }
            computed = acc
                .iter()
                .map(|n| n.normalize_or_zero().to_array())
                .collect::<Vec<_>>();
            &computed
        }
    };
    (0..mesh.positions.len())
        .map(|i| {
            let [px, py, pz] = mesh.positions[i];
            let n = Vec3::from(normals[i]);
            // A zero or non-finite normal would normalize to NaN in the shader: face the viewer
            // of no frame in particular (+y) instead.
            let [nx, ny, nz] = if n.is_finite() && n.length_squared() > 0.0 {
                n.to_array()
            } else {
                [0.0, 1.0, 0.0]
            };
            let [u, v] = mesh.uvs.map_or([0.0; 2], |uv| uv[i]);
            [px, py, pz, nx, ny, nz, u, v]
        })
        .collect()
}

/// Bakes `parts` (each a mesh with its material) into an impostor atlas laid out as
/// `descriptor` says, around the bounding sphere of all of them ([`impostor_bounds`]):
/// [`ImpostorBaker::new`] then [`ImpostorBaker::bake`]. Bad input is [`GpuError::Invalid`]
/// naming the field and the part.
pub fn bake_impostor(
    gpu: &GpuContext,
    parts: &[ImpostorPart],
    descriptor: &ImpostorBakeDescriptor,
) -> Result<ImpostorAtlas, GpuError> {
    ImpostorBaker::new(gpu, parts)?.bake(gpu, descriptor)
}

/// An atlas on the GPU: colour as `Rgba8UnormSrgb`, normal-depth as `Rgba16Float`, both with
/// their mip chains, and the sampler `passes/impostor.wgsl` reads them with.
#[derive(Debug)]
pub struct ImpostorTextures {
    /// The layout baked.
    pub layout: ImpostorLayout,
    /// Base colour and coverage.
    pub color: wgpu::Texture,
    /// Normal and depth.
    pub normal_depth: wgpu::Texture,
    /// Linear, mipmapped, clamped to the edge.
    pub sampler: wgpu::Sampler,
}

impl ImpostorTextures {
    /// Uploads `atlas` (checked: a layout lodkit can draw, a mip chain per atlas that matches it).
    pub fn new(gpu: &GpuContext, atlas: &ImpostorAtlas) -> Result<Self, GpuError> {
        const CALL: &str = "ImpostorTextures::new";
        let layout = atlas.layout;
        layout.validate().map_err(|e| GpuError::Invalid {
            call: CALL,
            parameter: "atlas.layout",
            value: e.to_string(),
            rule: "must describe an atlas lodkit can draw",
        })?;
        let levels = ImpostorAtlas::mip_levels(&layout);
        for (parameter, chain) in [
            ("atlas.color", &atlas.color),
            ("atlas.normal_depth", &atlas.normal_depth),
        ] {
            let ok = chain.len() == levels as usize
                && chain.iter().enumerate().all(|(k, image)| {
                    image.size == layout.atlas_size() >> k
                        && image.texels.len() == (image.size as usize).pow(2)
                });
            if !ok {
                return Err(GpuError::Mismatch {
                    call: CALL,
                    parameter,
                    found: format!("{} levels", chain.len()),
                    expected: format!(
                        "{levels} levels halving from {0} x {0}",
                        layout.atlas_size()
                    ),
                });
            }
        }
        let size = layout.atlas_size();
        crate::gpu::checks::texture_extent(gpu, CALL, size, size)?;
        gpu.guarded(CALL, || {
            let upload = |format, label, bytes: Vec<Vec<u8>>| {
                use wgpu::util::DeviceExt;
                let data: Vec<u8> = bytes.concat();
                gpu.device.create_texture_with_data(
                    &gpu.queue,
                    &wgpu::TextureDescriptor {
                        label: Some(label),
                        size: wgpu::Extent3d {
                            width: size,
                            height: size,
                            depth_or_array_layers: 1,
                        },
                        mip_level_count: levels,
                        sample_count: 1,
                        dimension: wgpu::TextureDimension::D2,
                        format,
                        usage: wgpu::TextureUsages::TEXTURE_BINDING,
                        view_formats: &[],
                    },
                    wgpu::util::TextureDataOrder::MipMajor,
                    &data,
                )
            };
            let color = atlas.color.iter().map(ImpostorImage::to_srgba8).collect();
            let normal_depth = atlas
                .normal_depth
                .iter()
                .map(|image| {
                    image
                        .texels
                        .iter()
                        .flat_map(|t| t.map(|c| half::f16::from_f32(c).to_le_bytes()))
                        .flatten()
                        .collect()
                })
                .collect();
            Ok(Self {
                layout,
                color: upload(
                    wgpu::TextureFormat::Rgba8UnormSrgb,
                    "impostor colour",
                    color,
                ),
                normal_depth: upload(
                    wgpu::TextureFormat::Rgba16Float,
                    "impostor normal-depth",
                    normal_depth,
                ),
                sampler: gpu.device.create_sampler(&wgpu::SamplerDescriptor {
                    label: Some("impostor atlas"),
                    mag_filter: wgpu::FilterMode::Linear,
                    min_filter: wgpu::FilterMode::Linear,
                    mipmap_filter: wgpu::MipmapFilterMode::Linear,
                    ..Default::default()
                }),
            })
        })
    }
}
