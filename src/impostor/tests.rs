//! The CPU steps of a bake and the sampling twins on atlases whose answers are known by hand.

use glam::{UVec2, Vec2, Vec3};

use super::*;

fn layout(frames: u32, frame_size: u32, shape: ImpostorShape) -> ImpostorLayout {
    ImpostorLayout {
        frames,
        frame_size,
        shape,
        center: [0.0; 3],
        radius: 1.0,
    }
}

#[test]
fn padding_fills_each_frame_from_its_own_covered_texels() {
    // Two frames of 4 x 4 side by side (an 8-wide atlas of 2 x 2 frames); one covered texel in
    // frame (0, 0), none in the others.
    let mut color = ImpostorImage::filled(8, [0.0; 4]);
    let mut depth = ImpostorImage::filled(8, [0.0; 4]);
    color.texels[8 + 1] = [0.2, 0.4, 0.6, 1.0];
    depth.texels[8 + 1] = [0.5, 0.5, 1.0, 0.75];
    dilate_frames(&mut color, &mut [&mut depth], 2, 4);
    for y in 0..8u32 {
        for x in 0..8u32 {
            let (c, d) = (color.texel(x, y), depth.texel(x, y));
            if x < 4 && y < 4 {
                assert_eq!(&c[..3], &[0.2, 0.4, 0.6], "({x}, {y})");
                assert_eq!(c[3], if (x, y) == (1, 1) { 1.0 } else { 0.0 });
                assert_eq!(d, [0.5, 0.5, 1.0, 0.75]);
            } else {
                assert_eq!((c, d), ([0.0; 4], [0.0; 4]), "({x}, {y}) is another frame");
            }
        }
    }
}

#[test]
fn mip_chains_keep_frames_whole() {
    // 2 x 2 frames of 4 texels: each frame one value, so every level of it is that value.
    let mut image = ImpostorImage::filled(8, [0.0; 4]);
    for y in 0..8u32 {
        for x in 0..8u32 {
            let v = (x / 4 + 2 * (y / 4)) as f32;
            image.texels[(y * 8 + x) as usize] = [v, 0.0, 0.0, 1.0];
        }
    }
    let chain = mip_chain(image, 2, 4);
    assert_eq!(chain.iter().map(|i| i.size).collect::<Vec<_>>(), [8, 4, 2]);
    assert_eq!(
        ImpostorAtlas::mip_levels(&layout(2, 4, ImpostorShape::Full)),
        3
    );
    let last = &chain[2];
    for (k, t) in last.texels.iter().enumerate() {
        assert_eq!(t[0], k as f32, "texel {k} of the last level is frame {k}");
    }
}

/// An atlas whose frames are each one colour (red = column, green = row, alpha 1) and one
/// depth (the plane: 0.5).
fn flat_atlas(frames: u32, shape: ImpostorShape) -> ImpostorAtlas {
    let fs = 4;
    let size = frames * fs;
    let mut color = ImpostorImage::filled(size, [0.0; 4]);
    for y in 0..size {
        for x in 0..size {
            color.texels[(y * size + x) as usize] = [(x / fs) as f32, (y / fs) as f32, 0.0, 1.0];
        }
    }
    let normal_depth = ImpostorImage::filled(size, [0.5, 1.0, 0.5, 0.5]);
    ImpostorAtlas {
        layout: layout(frames, fs, shape),
        color: mip_chain(color, frames, fs),
        normal_depth: mip_chain(normal_depth, frames, fs),
    }
}

#[test]
fn a_view_on_a_frame_sees_that_frame_and_between_frames_their_blend() {
    for shape in [ImpostorShape::Full, ImpostorShape::Hemi] {
        let atlas = flat_atlas(5, shape);
        let hemi = shape.is_hemi();
        // Straight at frame (1, 3) through the centre: that frame alone, at height 0.
        let dir = impostor_frame_dir(UVec2::new(1, 3), 5, hemi);
        let s = impostor_sample(&atlas, dir * 4.0, -dir, 0.0);
        assert!(
            (s.color.truncate() - Vec3::new(1.0, 3.0, 0.0)).length() < 1e-4,
            "{shape:?} {s:?}"
        );
        assert!(s.point.length() < 1e-4);
        assert!((s.normal - Vec3::Y).length() < 1e-4);
        // At the centroid of the grid triangle (1, 1), (2, 1), (1, 2): a third of each.
        let view = impostor_decode((Vec2::new(4.0, 4.0) / 3.0) * 0.5 - 1.0, hemi);
        let s = impostor_sample(&atlas, view * 4.0, -view, 0.0);
        let want = Vec3::new(4.0 / 3.0, 4.0 / 3.0, 0.0);
        assert!(
            (s.color.truncate() - want).length() < 1e-3,
            "{shape:?} {s:?}"
        );
        assert!((s.color.w - 1.0).abs() < 1e-5);
        // A ray that misses the frames' squares sees nothing.
        let side = impostor_frame_basis(dir).x_axis;
        let s = impostor_sample(&atlas, dir * 4.0 + side * 1.5, -dir, 0.0);
        assert_eq!(s.color.w, 0.0);
    }
}

#[test]
fn coverage_preserving_mips_keep_thin_features() {
    // One frame of 8 x 8 texels with a one-texel-wide vertical line at alpha 0.9: an eighth of
    // the texels pass the test.
    let mut image = ImpostorImage::filled(8, [0.0; 4]);
    for y in 0..8 {
        image.texels[y * 8 + 3] = [1.0, 1.0, 1.0, 0.9];
    }
    let mut chain = mip_chain(image, 1, 8);
    // The box filter takes the line to 0.45 at level 1: nothing passes.
    assert!(chain[1].texels.iter().all(|t| t[3] < 0.5));
    preserve_coverage(&mut chain, 1);
    // Each level again has at least an eighth passing: the line's column of texels (4 of 16
    // at level 1, 2 of 4 at level 2, the one texel of level 3); level 0 as it was.
    let passing = |i: &ImpostorImage| i.texels.iter().filter(|t| t[3] >= 0.5).count();
    let counts: Vec<usize> = chain.iter().map(passing).collect();
    assert_eq!(counts, [8, 4, 2, 1]);
    assert!(chain.iter().flat_map(|i| &i.texels).all(|t| t[3] <= 1.0));
}

#[test]
fn coverage_preserving_mips_work_frame_by_frame() {
    // 2 x 2 frames of 4 texels: frame (1, 0) holds a one-texel line at alpha 0.9, frame (0, 1)
    // is solid, the others empty.
    let mut image = ImpostorImage::filled(8, [0.0; 4]);
    for y in 0..4 {
        image.texels[y * 8 + 5] = [1.0, 0.0, 0.0, 0.9];
    }
    for y in 4..8 {
        for x in 0..4 {
            image.texels[y * 8 + x] = [0.0, 1.0, 0.0, 1.0];
        }
    }
    let mut chain = mip_chain(image, 2, 4);
    let before = chain.clone();
    preserve_coverage(&mut chain, 2);
    // Level 1 (4 x 4, 2 x 2 texels a frame): the line's frame gets its column back (2 of 4),
    // the solid and the empty frames are left exactly as they were.
    let level = &chain[1];
    let passing = |x0: u32, y0: u32| {
        (0..2)
            .flat_map(|y| (0..2).map(move |x| (x0 + x, y0 + y)))
            .filter(|&(x, y)| level.texel(x, y)[3] >= 0.5)
            .count()
    };
    assert_eq!(passing(2, 0), 2, "{:?}", level.texels);
    for (x0, y0) in [(0, 0), (0, 2), (2, 2)] {
        for (x, y) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            let (x, y) = (x0 + x, y0 + y);
            assert_eq!(
                level.texel(x, y),
                before[1].texel(x, y),
                "frame at ({x0}, {y0})"
            );
        }
    }
    // Nothing to do for a chain of one level, or a chain that is not one.
    let mut one = vec![ImpostorImage::filled(8, [0.3; 4])];
    preserve_coverage(&mut one, 2);
    assert_eq!(one[0].texels[0], [0.3; 4]);
    let mut odd = vec![
        ImpostorImage::filled(8, [0.3; 4]),
        ImpostorImage::filled(3, [0.3; 4]),
    ];
    preserve_coverage(&mut odd, 2);
    assert_eq!(odd[1].texels[0], [0.3; 4]);
    preserve_coverage(&mut odd, u32::MAX);
}

/// Mesh levels that switch in at or beyond the impostor's distance give way to it; LOD0 stays
/// (whatever its distance); an impostor the object is hidden before is refused.
#[cfg(feature = "lod_chain")]
#[test]
fn the_impostor_ends_the_chain_where_it_is_within_the_error() {
    use crate::lod_chain::LodChainError;
    let place = |distances: &[f32], own| {
        impostor_placement(distances, 40.0, own).map(|p| (p.mesh_levels, p.distance))
    };
    assert_eq!(place(&[0.0, 2.0, 5.0, 9.0], 6.0).unwrap(), (3, 6.0));
    // A level switching in exactly where the impostor is within the error gives way.
    assert_eq!(place(&[0.0, 2.0, 5.0, 9.0], 5.0).unwrap(), (2, 5.0));
    assert_eq!(place(&[0.0, 2.0], 0.5).unwrap(), (1, 0.5));
    assert_eq!(place(&[0.0], 3.0).unwrap(), (1, 3.0));
    assert_eq!(place(&[0.0, 2.0, 5.0], 30.0).unwrap(), (3, 30.0));
    assert_eq!(place(&[3.0, 5.0], 1.0).unwrap(), (1, 1.0));
    assert_eq!(place(&[], 1.0).unwrap(), (0, 1.0));
    for (distances, own) in [(&[0.0, 2.0][..], 40.0), (&[0.0, 2.0, 41.0][..], 45.0)] {
        let e = place(distances, own).unwrap_err();
        assert_eq!(
            e,
            LodChainError::ImpostorNeverShown {
                from: own,
                hidden: 40.0
            },
            "{e}"
        );
    }
}

/// `LodChain::impostor_group`: the chain's own switch distances up to the impostor's, the
/// impostor last, hidden where the mesh chain is.
#[cfg(feature = "lod_chain")]
#[test]
fn a_chain_ends_in_its_impostor() {
    use crate::lod_chain::{LodChain, LodChainDescriptor, MeshData, PixelErrorCamera, uv_sphere};
    let (positions, indices) = uv_sphere(32, 64);
    let mesh = MeshData {
        positions: &positions,
        indices: &indices,
        ..Default::default()
    };
    let chain = LodChain::build(&mesh, &LodChainDescriptor::default()).unwrap();
    let camera = PixelErrorCamera::default();
    let sphere = chain.bounding_sphere();
    // Fine enough that the chain's last level gives way to it.
    let layout = ImpostorLayout {
        frames: 64,
        frame_size: 512,
        shape: ImpostorShape::Full,
        center: sphere.center,
        radius: sphere.radius,
    };
    let (group, placement) = chain.impostor_group(&layout, &camera).unwrap();
    assert!(
        placement.mesh_levels < chain.levels().len(),
        "{placement:?}"
    );
    let own = impostor_switch_distance(&layout, &camera).unwrap();
    let mesh: Vec<f32> = chain
        .switch_distances(&camera)
        .unwrap()
        .into_iter()
        .enumerate()
        .filter(|&(i, d)| i == 0 || d < own)
        .map(|(_, d)| d)
        .collect();
    let got: Vec<f32> = group.levels().iter().map(|l| l.distance).collect();
    assert_eq!(got[..got.len() - 1], mesh[..], "{got:?}");
    assert_eq!(got.last(), Some(&own));
    assert_eq!(placement.mesh_levels, mesh.len());
    assert_eq!(group.levels().last().unwrap().mesh, "impostor");
    assert_eq!(group.max_distance(), chain.max_distance(&camera).ok());
}

#[test]
fn a_sample_near_a_frame_edge_takes_nothing_of_the_next_frame() {
    // Frames of one colour each (red = column): a look at frame (1, 1) of a 3 x 3 atlas, 4 texels
    // a frame, straight along its direction, at frame uv (0.95, 0.5). At mip 1 (2 texels a frame)
    // bilinear filtering there reaches 0.4 into frame (2, 1) unless the read stays half a texel
    // of that mip inside the frame (impostor_frame_inset): red 1.4 without it.
    let atlas = flat_atlas(3, ImpostorShape::Full);
    let frame = UVec2::new(1, 1);
    let dir = impostor_frame_dir(frame, 3, false);
    let basis = impostor_frame_basis(dir);
    let (u, v) = (0.95, 0.5);
    let q = basis.x_axis * (2.0 * u - 1.0) - basis.y_axis * (2.0 * v - 1.0);
    for level in [0.0, 0.5, 1.0, 1.7] {
        let s = impostor_sample_frame(&atlas, frame, q + dir * 3.0, -dir, level);
        assert!(
            (s.color.truncate() - Vec3::new(1.0, 1.0, 0.0)).length() < 1e-5,
            "level {level}: {:?}",
            s.color
        );
    }
}

/// A file's level 0 becomes the atlas a bake makes: three levels for 4-texel frames, the
/// colour's thin feature kept (one covered texel of 16 in frame (0, 0): its level-1 texel
/// averages to alpha 1/4 and is scaled to the test's 0.5, as is the level-2 texel at 1/16),
/// the normal and depth box-averaged; an image of the wrong size is refused by name.
#[test]
fn an_atlas_from_level_0_gets_the_mip_chains_a_bake_gives() {
    let l = layout(2, 4, ImpostorShape::Hemi);
    let mut color = ImpostorImage::filled(8, [0.2, 0.4, 0.6, 0.0]);
    color.texels[0] = [1.0, 0.0, 0.0, 1.0];
    let mut normal_depth = ImpostorImage::filled(8, [0.5, 0.5, 1.0, 0.25]);
    normal_depth.texels[0] = [0.5, 0.5, 1.0, 1.0];
    let atlas = ImpostorAtlas::from_level0(l, color.clone(), normal_depth.clone()).unwrap();
    let sizes = |chain: &[ImpostorImage]| chain.iter().map(|i| i.size).collect::<Vec<_>>();
    assert_eq!(sizes(&atlas.color), [8, 4, 2]);
    assert_eq!(sizes(&atlas.normal_depth), [8, 4, 2]);
    assert_eq!(atlas.color[0], color);
    assert!((atlas.color[1].texel(0, 0)[3] - 0.5).abs() < 1e-5);
    assert!((atlas.color[2].texel(0, 0)[3] - 0.5).abs() < 1e-5);
    assert_eq!(atlas.color[2].texel(1, 1)[3], 0.0);
    // Depth: (1 + 3 x 0.25) / 4 at level 1, (1 + 15 x 0.25) / 16 at level 2.
    assert!((atlas.normal_depth[1].texel(0, 0)[3] - 0.4375).abs() < 1e-6);
    assert!((atlas.normal_depth[2].texel(0, 0)[3] - 0.296_875).abs() < 1e-6);
    let small = ImpostorImage::filled(4, [0.0; 4]);
    let e = ImpostorAtlas::from_level0(l, color, small).unwrap_err();
    assert!(
        matches!(
            e,
            ImpostorError::ImageSize {
                atlas: "normal_depth",
                width: 4,
                expected: 8,
                ..
            }
        ),
        "{e}"
    );
    let mut bad = l;
    bad.frame_size = 3;
    assert!(matches!(
        ImpostorAtlas::from_level0(bad, normal_depth.clone(), normal_depth),
        Err(ImpostorError::BadLayout {
            field: "frame_size",
            ..
        })
    ));
}

/// The extras `lodkit lod --impostor` writes, as docs/impostors.md spells them, read back; a
/// shape that is not one of them or a missing field is refused, a field it does not know
/// ignored.
#[test]
fn impostor_extras_read_as_the_docs_spell_them() {
    let text = r#"{"frames": 12, "frame_size": 128, "shape": "hemi",
        "center": [0.5, 1.0, -2.0], "radius": 1.5, "color_image": 7, "normal_depth_image": 8}"#;
    let extras: ImpostorGltfExtras = serde_json::from_str(text).unwrap();
    assert_eq!(extras.color_image, 7);
    assert_eq!(extras.normal_depth_image, 8);
    let layout = extras.layout().unwrap();
    assert_eq!(
        layout,
        ImpostorLayout {
            frames: 12,
            frame_size: 128,
            shape: ImpostorShape::Hemi,
            center: [0.5, 1.0, -2.0],
            radius: 1.5,
        }
    );
    let written = serde_json::to_value(ImpostorGltfExtras::new(&layout, 7, 8)).unwrap();
    assert_eq!(
        written,
        serde_json::from_str::<serde_json::Value>(text).unwrap()
    );
    let full = text.replace("\"hemi\"", "\"full\"");
    let full: ImpostorGltfExtras = serde_json::from_str(&full).unwrap();
    assert_eq!(full.shape, ImpostorShape::Full);
    let sideways = text.replace("\"hemi\"", "\"sideways\"");
    let e = serde_json::from_str::<ImpostorGltfExtras>(&sideways).unwrap_err();
    assert!(e.to_string().contains("sideways"), "{e}");
    let extra = text.replace("\"radius\"", "\"depth\": 1, \"radius\"");
    assert_eq!(
        serde_json::from_str::<ImpostorGltfExtras>(&extra).unwrap(),
        extras,
        "a field it does not know is ignored"
    );
    let missing = text.replace("\"color_image\": 7, ", "");
    let e = serde_json::from_str::<ImpostorGltfExtras>(&missing).unwrap_err();
    assert!(e.to_string().contains("color_image"), "{e}");
    let zero = text.replace("1.5", "0.0");
    let zero: ImpostorGltfExtras = serde_json::from_str(&zero).unwrap();
    assert!(zero.layout().is_err());
}
