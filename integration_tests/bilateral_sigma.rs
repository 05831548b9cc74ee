//! The depth sigma as the hosts take it, a fraction of the pixel's view depth
//! (`lodkit::bilateral::bilateral_relative_sigma`): WGSL and GLSL against the Rust twin.

use lodkit::bilateral::{BILATERAL_SIGMA_OFF, bilateral_relative_sigma};
use lodkit::shaders::SourceLanguage;

use crate::harness::{Probe, assert_close, floats, run_with, words};

/// `bilateral_relative_sigma`, WGSL and GLSL, against the Rust twin: a max and one multiply,
/// which WGSL and GLSL round correctly, so the results are equal bit for bit (a tolerance of
/// 0). The cases: a depth of 20, none (the floor), off, far, behind the camera (the floor), and
/// under the floor.
#[test]
fn relative_sigma_twins_match() {
    let gpu = lodkit_test_gpu!(device);
    let cases: [(f32, f32); 6] = [
        (0.05, 20.0),
        (0.05, 0.0),
        (BILATERAL_SIGMA_OFF, 5.0),
        (0.02, 1.0e4),
        (0.3, -1.0),
        (0.05, 1.0e-7),
    ];
    let want: Vec<f32> = cases
        .iter()
        .map(|&(relative, depth)| bilateral_relative_sigma(relative, depth))
        .collect();
    let inputs: Vec<u32> = cases.iter().flat_map(|&(r, d)| words(&[r, d])).collect();
    for (language, header, body) in [
        (
            SourceLanguage::Wgsl,
            "#import lodkit::bilateral::bilateral_relative_sigma",
            "out_f(0u, bilateral_relative_sigma(inp_f(0u), inp_f(1u)));",
        ),
        (
            SourceLanguage::Glsl(naga::ShaderStage::Compute),
            "#include \"lodkit/bilateral.glsl\"",
            "out_f(0u, lodkit_bilateral_relative_sigma(inp_f(0u), inp_f(1u)));",
        ),
    ] {
        let probe = Probe {
            header,
            body,
            inputs: 2,
            outputs: 1,
            texture: None,
            rgba: &[],
            urgba: &[],
        };
        let got = floats(&run_with(gpu, &probe, &inputs, language, &[]));
        assert_close(
            &got,
            &want,
            0.0,
            &format!("{language:?} bilateral_relative_sigma"),
        );
    }
}
