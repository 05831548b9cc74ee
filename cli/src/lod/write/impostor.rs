//! The impostor level `lodkit lod --impostor` writes: its atlas images, a card mesh and a
//! material that show the frame seen from +z in any viewer, and the layout an engine needs to
//! draw the card as an impostor (docs/impostors.md, "In a glTF file").

use gltf::json::{self, Index, validation::Checked};
use lodkit::impostor::{
    ImpostorGltfExtras, ImpostorLayout, ImpostorShape, impostor_atlas_uv, impostor_blend,
    impostor_frame_basis, impostor_frame_dir, impostor_frame_uv,
};

use super::{Output, serde_json_map};

/// An impostor written into the document: its mesh, and the `extras` its node carries.
pub struct ImpostorLevel {
    pub mesh: Index<json::Mesh>,
    pub extras: json::Value,
}

impl Output {
    /// A PNG in the buffer, an image of it and a texture (linear, mipmapped, clamped).
    fn png_texture(
        &mut self,
        png: &[u8],
        name: String,
    ) -> (Index<json::Image>, Index<json::Texture>) {
        let view = self.strided_view(png, None, None);
        let image = self.root.push(json::Image {
            buffer_view: Some(view),
            mime_type: Some(json::image::MimeType("image/png".into())),
            name: Some(name.clone()),
            uri: None,
            extensions: None,
            extras: Default::default(),
        });
        let sampler = self.root.push(json::texture::Sampler {
            mag_filter: Some(Checked::Valid(json::texture::MagFilter::Linear)),
            min_filter: Some(Checked::Valid(json::texture::MinFilter::LinearMipmapLinear)),
            wrap_s: Checked::Valid(json::texture::WrappingMode::ClampToEdge),
            wrap_t: Checked::Valid(json::texture::WrappingMode::ClampToEdge),
            name: None,
            extensions: None,
            extras: Default::default(),
        });
        let texture = self.root.push(json::Texture {
            sampler: Some(sampler),
            source: image,
            name: Some(name),
            extensions: None,
            extras: Default::default(),
        });
        (image, texture)
    }

    /// Adds the impostor of mesh `base`: the atlas PNGs, a material (the colour atlas as base
    /// colour, alpha-masked at 0.5, double-sided, unlit-looking: metallic 0, roughness 1) and a
    /// card mesh: the bounding sphere's square facing +z, its uvs on the frame nearest +z, so a
    /// viewer that knows nothing of impostors shows the object's front.
    pub fn add_impostor(
        &mut self,
        base: &str,
        color_png: &[u8],
        normal_depth_png: &[u8],
        layout: &ImpostorLayout,
    ) -> ImpostorLevel {
        let (color_image, color) = self.png_texture(color_png, format!("{base}_impostor_color"));
        let (normal_depth_image, _) =
            self.png_texture(normal_depth_png, format!("{base}_impostor_normal_depth"));
        let material = self.root.push(json::Material {
            name: Some(format!("{base}_impostor")),
            alpha_mode: Checked::Valid(json::material::AlphaMode::Mask),
            alpha_cutoff: Some(json::material::AlphaCutoff(0.5)),
            double_sided: true,
            pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                base_color_texture: Some(json::texture::Info {
                    index: color,
                    tex_coord: 0,
                    extensions: None,
                    extras: Default::default(),
                }),
                metallic_factor: json::material::StrengthFactor(0.0),
                roughness_factor: json::material::StrengthFactor(1.0),
                ..Default::default()
            },
            ..Default::default()
        });
        let hemi = layout.shape == ImpostorShape::Hemi;
        let b = impostor_blend(glam::Vec3::Z, layout.frames, hemi);
        let w = b.weights.to_array();
        let heaviest = (0..3).fold(0, |k, i| if w[i] > w[k] { i } else { k });
        let front = b.frames[heaviest];
        let basis = impostor_frame_basis(impostor_frame_dir(front, layout.frames, hemi));
        let (c, r) = (glam::Vec3::from(layout.center), layout.radius);
        let corners = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
        let positions: Vec<[f32; 3]> = corners
            .iter()
            .map(|[x, y]| (c + glam::Vec3::new(*x, *y, 0.0) * r).to_array())
            .collect();
        let uvs: Vec<[f32; 2]> = corners
            .iter()
            .map(|[x, y]| {
                let uv = impostor_frame_uv(&basis, glam::Vec3::new(*x, *y, 0.0));
                impostor_atlas_uv(front, layout.frames, uv).to_array()
            })
            .collect();
        let mut attributes = std::collections::BTreeMap::new();
        let p = self.floats(&positions, true);
        attributes.insert(Checked::Valid(json::mesh::Semantic::Positions), p);
        let n = self.floats(&[[0.0f32, 0.0, 1.0]; 4], false);
        attributes.insert(Checked::Valid(json::mesh::Semantic::Normals), n);
        let t = self.floats(&uvs, false);
        attributes.insert(Checked::Valid(json::mesh::Semantic::TexCoords(0)), t);
        let index_bytes: Vec<u8> = [0u32, 1, 2, 0, 2, 3]
            .iter()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        let view = self.view(&index_bytes, json::buffer::Target::ElementArrayBuffer);
        let indices = self.accessor(
            view,
            6,
            json::accessor::ComponentType::U32,
            json::accessor::Type::Scalar,
            None,
            None,
        );
        let mesh = self.root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: Some(format!("{base}_impostor")),
            primitives: vec![json::mesh::Primitive {
                attributes,
                extensions: None,
                extras: Default::default(),
                indices: Some(indices),
                material: Some(material),
                mode: Checked::Valid(json::mesh::Mode::Triangles),
                targets: None,
            }],
            weights: None,
        });
        let fields =
            ImpostorGltfExtras::new(layout, color_image.value(), normal_depth_image.value());
        let fields = json::serialize::to_value(fields)
            .expect("numbers, strings and arrays always serialize");
        let extras = json::Value::from(serde_json_map([(
            lodkit::impostor::IMPOSTOR_GLTF_EXTRAS_KEY,
            fields,
        )]));
        ImpostorLevel { mesh, extras }
    }
}
