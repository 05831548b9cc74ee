//! `lodkit lod --impostor`: each mesh's impostor, baked from its triangle primitives and their
//! materials (base colour factor and texture, alpha mode, double-sidedness), as the last level.

use std::path::Path;

use lodkit::gpu::GpuContext;
use lodkit::gpu::impostor::{
    ImpostorBakeDescriptor, ImpostorBaker, ImpostorMaterial, ImpostorMesh, ImpostorPart,
    ImpostorTexture,
};
use lodkit::impostor::{ImpostorAtlas, ImpostorShape};

use super::read::MeshInput;
use super::write::local_path;

/// `lodkit lod`'s impostor flags.
#[derive(clap::Args, Clone, Copy, Debug)]
pub struct ImpostorFlags {
    /// Bake each mesh's octahedral impostor (its triangle primitives with their base colour,
    /// alpha mask and double-sidedness) on the GPU and append it as the last MSFT_lod level,
    /// switched to where its picture stays within --pixel-error (docs/impostors.md).
    #[arg(long)]
    impostor: bool,
    /// Impostor frames per side (2 to 64; more frames: nearer switch, bigger atlas).
    #[arg(long, default_value_t = 12, value_name = "N", requires = "impostor")]
    impostor_frames: u32,
    /// Impostor texels per frame side (a power of two, 4 to 1024).
    #[arg(
        long,
        default_value_t = 128,
        value_name = "TEXELS",
        requires = "impostor"
    )]
    impostor_frame_size: u32,
    /// Impostor frames over the whole sphere of directions (default: the upper hemisphere,
    /// for objects on the ground).
    #[arg(long, requires = "impostor")]
    impostor_full: bool,
}

impl ImpostorFlags {
    /// The options, when `--impostor` is given.
    pub fn options(&self) -> Option<ImpostorOptions> {
        self.impostor.then_some(ImpostorOptions {
            frames: self.impostor_frames,
            frame_size: self.impostor_frame_size,
            shape: if self.impostor_full {
                ImpostorShape::Full
            } else {
                ImpostorShape::Hemi
            },
        })
    }
}

/// How the impostors are baked (`--impostor-frames`, `--impostor-frame-size`,
/// `--impostor-full`).
#[derive(Clone, Copy, Debug)]
pub struct ImpostorOptions {
    pub frames: u32,
    pub frame_size: u32,
    pub shape: ImpostorShape,
}

impl ImpostorOptions {
    pub fn descriptor(&self) -> ImpostorBakeDescriptor {
        ImpostorBakeDescriptor {
            frames: self.frames,
            frame_size: self.frame_size,
            shape: self.shape,
        }
    }
}

/// A primitive's material as the bake takes it, the texture decoded.
struct Material {
    base_color: [f32; 4],
    texture: Option<(u32, u32, Vec<u8>)>,
    alpha_cutoff: Option<f32>,
    double_sided: bool,
}

/// The bytes of `image`: from its buffer view, or from the file its URI names beside the
/// input (below `base`).
fn image_bytes(
    image: &gltf::Image,
    buffers: &[gltf::buffer::Data],
    base: &Path,
) -> Result<Vec<u8>, String> {
    match image.source() {
        gltf::image::Source::View { view, .. } => {
            let data = buffers
                .get(view.buffer().index())
                .ok_or("its buffer is missing")?;
            let start = view.offset();
            data.get(start..start.saturating_add(view.length()))
                .map(<[u8]>::to_vec)
                .ok_or_else(|| "its buffer view runs past its buffer".to_owned())
        }
        gltf::image::Source::Uri { uri, .. } => {
            if uri.starts_with("data:") {
                return Err("a data: URI (not read for impostors)".into());
            }
            let path = local_path(uri).ok_or("outside the input's folder")?;
            std::fs::read(base.join(&path)).map_err(|e| format!("cannot read '{path}': {e}"))
        }
    }
}

/// The material of `primitive`, its base colour texture decoded (a texture that cannot be is
/// left out with a warning: the factor alone is baked).
fn material(
    primitive: &gltf::Primitive,
    buffers: &[gltf::buffer::Data],
    base: &Path,
    warn: &mut dyn FnMut(String),
) -> Material {
    let m = primitive.material();
    let pbr = m.pbr_metallic_roughness();
    let label = format!(
        "material {}",
        m.index().map_or("default".into(), |i| i.to_string())
    );
    let texture = pbr.base_color_texture().and_then(|info| {
        if info.tex_coord() != 0 {
            warn(format!(
                "{label}: its base colour texture reads TEXCOORD_{}; the impostor bakes its factor only",
                info.tex_coord()
            ));
            return None;
        }
        if info.texture_transform().is_some() {
            warn(format!(
                "{label}: KHR_texture_transform is not applied to the impostor's bake"
            ));
        }
        let image = info.texture().source();
        let decoded = image_bytes(&image, buffers, base).and_then(|bytes| {
            image::load_from_memory(&bytes).map_err(|e| format!("cannot decode it: {e}"))
        });
        match decoded {
            Ok(img) => {
                let rgba = img.to_rgba8();
                Some((rgba.width(), rgba.height(), rgba.into_raw()))
            }
            Err(e) => {
                warn(format!(
                    "{label}: base colour image {}: {e}; the impostor bakes its factor only",
                    image.index()
                ));
                None
            }
        }
    });
    let alpha_cutoff = match m.alpha_mode() {
        gltf::material::AlphaMode::Opaque => None,
        gltf::material::AlphaMode::Mask => Some(m.alpha_cutoff().unwrap_or(0.5)),
        gltf::material::AlphaMode::Blend => {
            warn(format!(
                "{label}: alpha mode BLEND is baked as a mask at 0.5 (an impostor is alpha-tested)"
            ));
            Some(0.5)
        }
    };
    Material {
        base_color: pbr.base_color_factor(),
        texture,
        alpha_cutoff,
        double_sided: m.double_sided(),
    }
}

/// Bakes the impostor of `mesh` (read into `input`) on `gpu`.
pub fn bake(
    gpu: &GpuContext,
    mesh: &gltf::Mesh,
    input: &MeshInput,
    buffers: &[gltf::buffer::Data],
    base: &Path,
    options: &ImpostorOptions,
    warn: &mut dyn FnMut(String),
) -> Result<ImpostorAtlas, String> {
    let materials: Vec<Material> = input
        .primitives
        .iter()
        .map(|p| {
            let primitive = mesh.primitives().nth(p.index).expect("read from this mesh");
            material(&primitive, buffers, base, warn)
        })
        .collect();
    let parts: Vec<ImpostorPart> = input
        .primitives
        .iter()
        .zip(&materials)
        .map(|(p, m)| ImpostorPart {
            mesh: ImpostorMesh {
                positions: &p.positions,
                indices: &p.indices,
                normals: p.normals.as_deref(),
                uvs: p.uvs.as_deref(),
            },
            material: ImpostorMaterial {
                base_color: m.base_color,
                base_color_texture: m.texture.as_ref().map(|(w, h, rgba8)| ImpostorTexture {
                    width: *w,
                    height: *h,
                    rgba8,
                }),
                alpha_cutoff: m.alpha_cutoff,
                double_sided: m.double_sided,
            },
        })
        .collect();
    ImpostorBaker::new(gpu, &parts)
        .and_then(|baker| baker.bake(gpu, &options.descriptor()))
        .map_err(|e| format!("impostor: {e}"))
}

/// The atlas's two images as PNG: the colour (RGBA8, sRGB) and the normal-depth (RGBA16,
/// linear), level 0 each.
pub fn pngs(atlas: &ImpostorAtlas) -> Result<(Vec<u8>, Vec<u8>), String> {
    let size = atlas.layout.atlas_size();
    let color = atlas.color[0].to_srgba8();
    let normal_depth: Vec<u16> = atlas.normal_depth[0]
        .texels
        .iter()
        .flat_map(|t| t.map(|c| (c.clamp(0.0, 1.0) * 65535.0).round() as u16))
        .collect();
    let encode = |image: image::DynamicImage| {
        let mut out = std::io::Cursor::new(Vec::new());
        image
            .write_to(&mut out, image::ImageFormat::Png)
            .map(|()| out.into_inner())
            .map_err(|e| format!("cannot encode the impostor atlas: {e}"))
    };
    let color = image::RgbaImage::from_raw(size, size, color).ok_or("atlas size")?;
    let normal_depth =
        image::ImageBuffer::<image::Rgba<u16>, _>::from_raw(size, size, normal_depth)
            .ok_or("atlas size")?;
    Ok((
        encode(image::DynamicImage::ImageRgba8(color))?,
        encode(image::DynamicImage::ImageRgba16(normal_depth))?,
    ))
}
