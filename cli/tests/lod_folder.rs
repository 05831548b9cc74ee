//! `lodkit lod DIR -o OUT`: every glTF and GLB file below a folder, written to the same
//! relative paths below the output folder; one bad file is named and the rest are written.

use crate::cli::run;
use crate::lod::{assert_levels_in_order, sphere, write_gltf};
use crate::support::Scratch;

/// Two spheres (one in a subfolder, one as `.glb` converted first) and a file that is not
/// glTF: the two are written where their relative paths say, each a valid chain a second
/// reader loads; the bad one is named with its error on stderr and in the report; the exit
/// status is 1; the summary table lists all three. The output folder inside the input folder
/// is not read back as input. Tried against a throwaway edit that stops at the first failure
/// (fails on the second sphere's output).
#[test]
fn lod_over_a_folder_writes_every_file_and_names_the_bad_one() {
    let dir = Scratch::folder();
    let input = dir.join("assets");
    std::fs::create_dir_all(input.join("trees")).unwrap();
    write_gltf(&input.join("trees"), "ball", &sphere(10, 20), |_| {});
    write_gltf(&input, "rock", &sphere(12, 24), |_| {});
    // `rock.glb`: the same sphere as a GLB, so the folder holds both kinds.
    let (code, _, stderr) = run(
        &input,
        &["lod", "rock.gltf", "-o", "rock.glb", "--levels", "1"],
    );
    assert_eq!(code, 0, "{stderr}");
    std::fs::remove_file(input.join("rock.gltf")).unwrap();
    std::fs::remove_file(input.join("rock.bin")).unwrap();
    std::fs::write(input.join("aa_broken.glb"), b"not glTF at all").unwrap();

    let (code, stdout, stderr) = run(
        &dir,
        &[
            "lod",
            "assets",
            "-o",
            "assets/lod",
            "--levels",
            "3",
            "--report",
            "r.json",
        ],
    );
    assert_eq!(code, 1, "{stdout}{stderr}");
    assert!(
        stderr.contains("aa_broken.glb") && stderr.contains("not a valid glTF"),
        "{stderr}"
    );
    assert_levels_in_order(&input.join("lod/trees/ball.gltf"), 3);
    assert_levels_in_order(&input.join("lod/rock.glb"), 3);
    for name in ["aa_broken.glb", "ball.gltf", "rock.glb"] {
        assert!(stdout.contains(name), "{name}: {stdout}");
    }
    assert!(stdout.contains("2 of 3 files written"), "{stdout}");
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("r.json")).unwrap()).unwrap();
    assert_eq!(report["failed"], 1, "{report}");
    let files = report["files"].as_array().unwrap();
    assert_eq!(
        files.len(),
        3,
        "the output folder is not read as input: {report}"
    );
    let broken = files
        .iter()
        .find(|f| f["input"].as_str().unwrap().ends_with("aa_broken.glb"))
        .unwrap();
    assert_eq!(broken["exit_code"], 1);
    assert!(
        broken["error"]
            .as_str()
            .unwrap()
            .contains("not a valid glTF")
    );
    let rock = files
        .iter()
        .find(|f| f["input"].as_str().unwrap().ends_with("rock.glb"))
        .unwrap();
    assert_eq!(rock["meshes"][0]["levels"].as_array().unwrap().len(), 3);

    // A folder in, a file name out: refused before anything is written.
    let (code, _, stderr) = run(&dir, &["lod", "assets", "-o", "out.glb"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("the output is a folder"), "{stderr}");
}
