//! `ImpostorMaterial`'s atlases, errors and card, on the CPU.

use crate::impostor::*;
use lodkit::impostor::ImpostorShape;

fn layout() -> ImpostorLayout {
    ImpostorLayout {
        frames: 2,
        frame_size: 4,
        shape: ImpostorShape::Hemi,
        center: [1.0, 2.0, 3.0],
        radius: 0.5,
    }
}

/// An atlas of `layout` whose chains have `levels` levels (the layout's own: 3).
fn atlas(levels: u32) -> ImpostorAtlas {
    let layout = layout();
    let chain = (0..levels)
        .map(|k| ImpostorImage::filled(layout.atlas_size() >> k, [0.5; 4]))
        .collect::<Vec<_>>();
    ImpostorAtlas {
        layout,
        color: chain.clone(),
        normal_depth: chain,
    }
}

#[test]
fn an_atlas_becomes_two_images_with_their_mip_chains() {
    let mut images = Assets::<Image>::default();
    let levels = ImpostorAtlas::mip_levels(&layout());
    assert_eq!(levels, 3, "8, 4 and 2 texels a side");
    let material = ImpostorMaterial::new(&atlas(levels), &mut images).unwrap();
    let color = images.get(&material.color).unwrap();
    assert_eq!(color.texture_descriptor.mip_level_count, 3);
    assert_eq!(
        color.texture_descriptor.format,
        TextureFormat::Rgba8UnormSrgb
    );
    // 8^2 + 4^2 + 2^2 texels of 4 bytes, and of 8 bytes (four halves).
    assert_eq!(color.data.as_ref().map(Vec::len), Some(84 * 4));
    let normal = images.get(&material.normal_depth).unwrap();
    assert_eq!(normal.texture_descriptor.format, TextureFormat::Rgba16Float);
    assert_eq!(normal.data.as_ref().map(Vec::len), Some(84 * 8));
    // 0.5 as a half: 0x3800, little-endian.
    assert_eq!(
        normal.data.as_ref().map(|d| [d[0], d[1]]),
        Some([0x00, 0x38])
    );
    assert_eq!(material.params.sphere, Vec4::new(1.0, 2.0, 3.0, 0.5));
    assert_eq!(material.params.atlas, UVec4::new(2, 1, 4, 0));
}

#[test]
fn an_atlas_it_cannot_draw_is_an_error_naming_the_part() {
    let mut images = Assets::<Image>::default();
    let short = ImpostorMaterial::new(&atlas(2), &mut images).unwrap_err();
    assert!(
        matches!(
            short,
            ImpostorMaterialError::MipChain {
                atlas: "color",
                expected: 3,
                ..
            }
        ),
        "{short}"
    );
    let mut bad = atlas(3);
    bad.layout.frames = 1;
    let layout = ImpostorMaterial::new(&bad, &mut images).unwrap_err();
    assert!(
        matches!(layout, ImpostorMaterialError::Layout(_)),
        "{layout}"
    );
    assert!(layout.to_string().contains("frames"), "{layout}");
    assert_eq!(images.len(), 0, "no image added for an atlas refused");
}

/// An image of `size` texels a side of `format`, every texel `texel`.
fn image(size: u32, format: TextureFormat, texel: &[u8]) -> Image {
    Image::new(
        Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        texel.repeat((size * size) as usize),
        format,
        RenderAssetUsages::all(),
    )
}

/// What `lodkit lod --impostor` writes and Bevy's loader reads (sRGB RGBA8 colour, RGBA16
/// unorm normal and depth) becomes the material of the atlas: the colour's bytes come back
/// (sRGB decoded and encoded again), the normal and depth as halves; an image Bevy did not
/// keep, of a format not read, or of another size is refused by name.
#[test]
fn level_0_images_become_the_atlas_material() {
    let mut images = Assets::<Image>::default();
    let color = image(8, TextureFormat::Rgba8UnormSrgb, &[188, 20, 250, 255]);
    // 0.75 as 16-bit unorm (49151 / 65535 = 0.749996..., 0.75 as a half).
    let nd = image(8, TextureFormat::Rgba16Unorm, &[0xff, 0xbf].repeat(4));
    let material =
        ImpostorMaterial::from_level0_images(layout(), &color, &nd, &mut images).unwrap();
    let c = images.get(&material.color).unwrap();
    assert_eq!(c.texture_descriptor.mip_level_count, 3);
    assert_eq!(
        c.data.as_ref().map(|d| d[..4].to_vec()),
        Some(vec![188, 20, 250, 255])
    );
    let n = images.get(&material.normal_depth).unwrap();
    // 0.75 as a half: 0x3a00, little-endian.
    assert_eq!(n.data.as_ref().map(|d| [d[0], d[1]]), Some([0x00, 0x3a]));
    // The same colour as RGBA8 without the sRGB flag, and as a 16-bit PNG loads (188 x 257):
    // sRGB samples both, the same bytes back.
    for other in [
        image(8, TextureFormat::Rgba8Unorm, &[188, 20, 250, 255]),
        image(
            8,
            TextureFormat::Rgba16Unorm,
            &[188u16, 20, 250, 255]
                .map(|v| (v * 257).to_le_bytes())
                .concat(),
        ),
    ] {
        let m = ImpostorMaterial::from_level0_images(layout(), &other, &nd, &mut images).unwrap();
        let c = images.get(&m.color).unwrap();
        let bytes = c.data.as_ref().map(|d| d[..4].to_vec());
        assert_eq!(
            bytes,
            Some(vec![188, 20, 250, 255]),
            "{:?}",
            other.texture_descriptor.format
        );
    }
    let mut gone = color.clone();
    gone.data = None;
    let wrong = [
        (gone, "color", "MAIN_WORLD"),
        (image(8, TextureFormat::R8Unorm, &[1]), "color", "R8Unorm"),
        (
            image(4, TextureFormat::Rgba8UnormSrgb, &[1; 4]),
            "color",
            "4 x 4",
        ),
    ];
    for (bad, atlas, why) in wrong {
        let e = ImpostorMaterial::from_level0_images(layout(), &bad, &nd, &mut images).unwrap_err();
        assert!(
            matches!(&e, ImpostorMaterialError::Image { atlas: a, problem } if *a == atlas && problem.contains(why)),
            "{e}"
        );
    }
    let small = image(4, TextureFormat::Rgba16Unorm, &[0; 8]);
    let e =
        ImpostorMaterial::from_level0_images(layout(), &color, &small, &mut images).unwrap_err();
    assert!(e.to_string().contains("normal_depth image is 4 x 4"), "{e}");
    assert_eq!(
        images.len(),
        6,
        "images added for the three atlases read only"
    );
}

#[test]
fn the_card_mesh_spans_the_bounding_sphere_box() {
    let mesh = ImpostorMaterial::card_mesh(&layout());
    let Some(bevy::mesh::VertexAttributeValues::Float32x3(positions)) =
        mesh.attribute(Mesh::ATTRIBUTE_POSITION)
    else {
        panic!("positions as Float32x3");
    };
    let (lo, hi) = positions.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(Vec3::from(p)), hi.max(Vec3::from(p))),
    );
    assert_eq!(
        (lo, hi),
        (Vec3::new(0.5, 1.5, 2.5), Vec3::new(1.5, 2.5, 3.5))
    );
    assert_eq!(mesh.count_vertices(), 6);
}
