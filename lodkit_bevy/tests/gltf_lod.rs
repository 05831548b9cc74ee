//! A glTF file with LOD levels (`MSFT_lod`, `MSFT_screencoverage`) loaded by Bevy's own glTF
//! loader in an app whose only lodkit code is the plugin: the gltf_lod example run on the GPU
//! (Bevy's default MSAA on its camera), its report held to the file it wrote.

mod support;

/// The file's two spheres become one group each, with both levels and the switch distance the
/// file's coverage was written for (view-normalized 3.0, hidden beyond 100: the example writes
/// `π R² / (4 aspect d²)`, the plugin reads `R sqrt(π / (4 aspect c))`); the camera walking away
/// draws each group's fine level, then its coarse one; the cube without `MSFT_lod` stays a plain
/// Bevy mesh; and every frame shows the objects. Without the plugin's glTF handler the file
/// loads as its finest levels only and the groups are missing.
#[test]
fn a_gltf_file_with_msft_lod_becomes_lod_groups() {
    let Some(r) = support::example_report("gltf_lod") else {
        return;
    };
    let switch = r["intended_switch"].as_f64().unwrap();
    let groups = r["groups"].as_array().expect("groups");
    assert_eq!(groups.len(), 2, "one group per sphere: {r}");
    for g in groups {
        assert_eq!(g["levels"], 2, "{g}");
        let d: Vec<f64> = g["distances"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(d[0], 0.0);
        assert!(
            (d[1] - switch).abs() <= 1e-5 * switch,
            "switch {} vs {switch}",
            d[1]
        );
        let max = g["max_distance"].as_f64().expect("a max distance");
        assert!((max - 100.0).abs() <= 1e-5 * 100.0, "max distance {max}");
        let mut drawn: Vec<u64> = g["drawn"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_u64().unwrap())
            .collect();
        drawn.sort();
        assert_eq!(drawn, [0, 1], "the walk shows both levels: {g}");
    }
    assert_eq!(r["plain_meshes"], 1, "the cube loads as before: {r}");
    assert!(r["min_object_pixels"].as_u64().unwrap() > 0, "{r}");
}
