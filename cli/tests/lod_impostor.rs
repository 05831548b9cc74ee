//! `lodkit lod --impostor`: each mesh's impostor as its last `MSFT_lod` level, with its atlas,
//! card, material and layout written as docs/impostors.md says, read back by a second reader.

use crate::cli::run;
use crate::lod::{sphere, write_gltf};
use crate::support::Scratch;

/// The JSON chunk and the binary chunk of a GLB file.
fn glb(path: &std::path::Path) -> (serde_json::Value, Vec<u8>) {
    let bytes = std::fs::read(path).unwrap();
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    (json, bytes[20 + json_len + 8..].to_vec())
}

/// The bytes of image `i` (in a buffer view of the binary chunk).
fn image(json: &serde_json::Value, bin: &[u8], i: u64) -> Vec<u8> {
    let view =
        &json["bufferViews"][json["images"][i as usize]["bufferView"].as_u64().unwrap() as usize];
    let start = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    bin[start..start + view["byteLength"].as_u64().unwrap() as usize].to_vec()
}

#[test]
fn lod_appends_each_meshs_impostor_as_its_last_level() {
    let _gpu = lodkit_test_gpu!();
    let dir = Scratch::folder();
    // A unit sphere, its material alpha-masked and red.
    write_gltf(&dir, "s", &sphere(12, 24), |doc| {
        doc["materials"] = serde_json::json!([{
            "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.0, 0.0, 1.0]},
            "alphaMode": "MASK"
        }]);
        doc["meshes"][0]["primitives"][0]["material"] = serde_json::json!(0);
    });
    let args = [
        "lod",
        "s.gltf",
        "-o",
        "out.glb",
        "--levels",
        "3",
        "--impostor",
        "--impostor-frames",
        "6",
        "--impostor-frame-size",
        "16",
        "--report",
        "r.json",
    ];
    let (code, stdout, stderr) = run(&dir, &args);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("impostor"), "{stdout}");
    let (json, bin) = glb(&dir.join("out.glb"));
    let node = json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|n| n["extensions"]["MSFT_lod"].is_object())
        .expect("a node with MSFT_lod");
    let ids = node["extensions"]["MSFT_lod"]["ids"].as_array().unwrap();
    assert_eq!(ids.len(), 3, "two mesh levels and the impostor");
    let coverage = node["extras"]["MSFT_screencoverage"].as_array().unwrap();
    assert_eq!(coverage.len(), 4);
    let c: Vec<f64> = coverage.iter().map(|c| c.as_f64().unwrap()).collect();
    assert!(c.windows(2).all(|w| w[0] > w[1]), "{c:?}");
    let last = &json["nodes"][ids[2].as_u64().unwrap() as usize];
    let layout = &last["extras"]["lodkit_impostor"];
    assert_eq!(layout["frames"], 6);
    assert_eq!(layout["frame_size"], 16);
    assert_eq!(layout["shape"], "hemi");
    let radius = layout["radius"].as_f64().unwrap();
    assert!(
        (radius - 1.0).abs() < 1e-3,
        "the unit sphere's radius: {radius}"
    );
    for k in 0..3 {
        assert!(
            layout["center"][k].as_f64().unwrap().abs() < 1e-3,
            "{layout}"
        );
    }
    // The card: two triangles, alpha-masked and double-sided, showing the colour atlas.
    let mesh = &json["meshes"][last["mesh"].as_u64().unwrap() as usize];
    let primitive = &mesh["primitives"][0];
    assert_eq!(
        json["accessors"][primitive["indices"].as_u64().unwrap() as usize]["count"],
        6
    );
    let material = &json["materials"][primitive["material"].as_u64().unwrap() as usize];
    assert_eq!(material["alphaMode"], "MASK");
    assert_eq!(material["doubleSided"], true);
    let texture = material["pbrMetallicRoughness"]["baseColorTexture"]["index"]
        .as_u64()
        .unwrap();
    assert_eq!(
        json["textures"][texture as usize]["source"],
        layout["color_image"]
    );
    // The atlases: 96 x 96, the sphere in the middle of each frame, nothing in its corners.
    let color =
        image::load_from_memory(&image(&json, &bin, layout["color_image"].as_u64().unwrap()))
            .unwrap()
            .to_rgba8();
    assert_eq!(color.dimensions(), (96, 96));
    for (fx, fy) in [(0, 0), (2, 3), (5, 5)] {
        let centre = color.get_pixel(fx * 16 + 8, fy * 16 + 8);
        let corner = color.get_pixel(fx * 16, fy * 16);
        assert_eq!(
            (centre[0], centre[1], centre[3]),
            (255, 0, 255),
            "frame ({fx}, {fy})"
        );
        assert_eq!(corner[3], 0, "frame ({fx}, {fy}) corner");
        assert_eq!(
            (corner[0], corner[1]),
            (255, 0),
            "padded with the sphere's colour"
        );
    }
    let normal_depth = image::load_from_memory(&image(
        &json,
        &bin,
        layout["normal_depth_image"].as_u64().unwrap(),
    ))
    .unwrap();
    assert!(matches!(normal_depth, image::DynamicImage::ImageRgba16(_)));
    // The report marks the level and places it after the mesh levels, before the hide distance.
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("r.json")).unwrap()).unwrap();
    let mesh = &report["meshes"][0];
    let levels = mesh["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 4, "LOD0, two generated levels, the impostor");
    assert_eq!(levels[3]["impostor"], true);
    assert!(levels[2].get("impostor").is_none());
    let d: Vec<f64> = levels
        .iter()
        .map(|l| l["switch_distance"].as_f64().unwrap())
        .collect();
    assert!(
        d[2] >= d[1] && d[2] < mesh["max_distance"].as_f64().unwrap(),
        "{d:?}"
    );
}

#[test]
fn lod_refuses_an_impostor_layout_it_cannot_bake() {
    let dir = Scratch::folder();
    write_gltf(&dir, "s", &sphere(6, 12), |_| {});
    let (code, _, stderr) = run(
        &dir,
        &[
            "lod",
            "s.gltf",
            "-o",
            "o.glb",
            "--impostor",
            "--impostor-frame-size",
            "48",
        ],
    );
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("frame_size") && stderr.contains("48"),
        "{stderr}"
    );
    let (code, _, stderr) = run(
        &dir,
        &["lod", "s.gltf", "-o", "o.glb", "--impostor-frames", "8"],
    );
    assert_eq!(code, 2, "needs --impostor: {stderr}");
}
