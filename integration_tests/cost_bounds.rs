//! The cost counter never undercounts: GLSL `for` loops (naga lowers their exit to
//! `if (!(cond)) { break; }`), WGSL and WESL loops written that way, switch fall-through, and
//! loop counters set under a branch, in an outer block or by an enclosing loop are counted on
//! their costliest path, or the loop is reported in `unknown_loops`. Every expected count is
//! counted by hand in the comment above it.

use lodkit::shaders::SourceLanguage;
use lodkit::shaders::cost::{Counts, EntryCost};
use lodkit::shaders::naga::ShaderStage;

use crate::cost::costs_in;

const FRAG: SourceLanguage = SourceLanguage::Glsl(ShaderStage::Fragment);

/// The one fragment entry point of `source` (GLSL adds no other).
fn fragment(source: &str, language: SourceLanguage) -> EntryCost {
    let all = costs_in(source, language);
    let mut frag: Vec<EntryCost> = all.into_iter().filter(|c| c.stage == "fragment").collect();
    assert_eq!(frag.len(), 1);
    frag.remove(0)
}

fn loads(texture_loads: u64, alu: u64) -> Counts {
    Counts {
        texture_loads,
        alu,
        ..Counts::default()
    }
}

#[test]
fn a_glsl_for_loop_of_constant_trip_count_multiplies_its_body() {
    let c = fragment(
        "#version 450
layout(set = 0, binding = 0) uniform texture2D t;
layout(location = 0) out vec4 o;
void main() {
    vec4 s = vec4(0.0);
    for (int i = 0; i < 4; i++) {
        s += texelFetch(t, ivec2(i, 0), 0);
    }
    o = s;
}
",
        FRAG,
    );
    // i = 0, 1, 2, 3: 4 loads. ALU: the exit test `!(i < 4)` (2 ops) runs 5 times (the fifth
    // leaves) = 10, `s + texel` 4, `i + 1` 4: 18.
    assert_eq!(c.always, loads(4, 18), "{c:?}");
    assert_eq!(c.conditional, Counts::default());
    assert_eq!(c.unknown_loops, 0);
}

#[test]
fn nested_glsl_for_loops_multiply_out() {
    let c = fragment(
        "#version 450
layout(set = 0, binding = 0) uniform texture2D t;
layout(location = 0) out vec4 o;
void main() {
    vec4 s = vec4(0.0);
    for (int i = 0; i < 2; i++) {
        for (int j = 0; j < 3; j++) {
            s += texelFetch(t, ivec2(i, j), 0);
        }
    }
    o = s;
}
",
        FRAG,
    );
    // 2 x 3 = 6 loads. ALU: outer test 2 ops x 3 = 6, outer step 2; per outer trip the inner
    // test 2 x 4 = 8, `s + texel` 3, inner step 3 = 14, twice = 28: 36.
    assert_eq!(c.always, loads(6, 36), "{c:?}");
    assert_eq!(c.unknown_loops, 0);
}

/// `loop { if !(i < 4u) { break; } ... continuing { i += 1u; } }`, the form naga gives a GLSL
/// `for`, written by hand.
const IF_NOT_BREAK: &str = "
@group(0) @binding(0) var t: texture_2d<f32>;
@fragment fn main() -> @location(0) vec4<f32> {
    var sum = vec4<f32>(0.0);
    var i = 0u;
    loop {
        if !(i < 4u) { break; }
        sum += textureLoad(t, vec2<u32>(i, 0u), 0);
        continuing { i += 1u; }
    }
    return sum;
}
";

#[test]
fn an_if_not_break_loop_multiplies_its_body_in_wgsl_and_wesl() {
    for language in [SourceLanguage::Wgsl, SourceLanguage::Wesl] {
        let c = fragment(IF_NOT_BREAK, language);
        // 4 loads. ALU: `!(i < 4u)` 2 ops x 5 tests = 10, `sum + texel` 4, `i + 1u` 4: 18.
        assert_eq!(c.always, loads(4, 18), "{language:?}: {c:?}");
        assert_eq!(c.unknown_loops, 0, "{language:?}");
    }
}

#[test]
fn a_glsl_switch_case_that_falls_through_pays_for_the_next_cases() {
    let c = fragment(
        "#version 450
layout(set = 0, binding = 0) uniform texture2D t;
layout(set = 0, binding = 1) uniform U { int n; };
layout(location = 0) out vec4 o;
void main() {
    vec4 s = vec4(0.0);
    switch (n) {
        case 0: s += texelFetch(t, ivec2(0), 0);
        case 1: s += texelFetch(t, ivec2(1), 0);
        case 2: s += texelFetch(t, ivec2(2), 0); break;
        case 3: s += texelFetch(t, ivec2(3), 0) + texelFetch(t, ivec2(4), 0); break;
        default: s *= 2.0;
    }
    o = s;
}
",
        FRAG,
    );
    // Paths: case 0 runs cases 0, 1, 2: 3 loads, 3 adds; case 1: 2 loads, 2 adds; case 2: 1
    // load, 1 add; case 3: 2 loads, 2 adds; default: 1 multiply. Costliest: 3 loads, 3 ALU.
    assert_eq!(c.always, Counts::default(), "{c:?}");
    assert_eq!(c.conditional, loads(3, 3), "{c:?}");
    let r = &c.resources[0];
    assert_eq!((r.resource.as_str(), r.always, r.conditional), ("t", 0, 3));
}

/// A counter whose start a branch may lower: 6 normally, 2 when `n == 0u`.
const BRANCH_SET: &str = "
@group(0) @binding(0) var t: texture_2d<f32>;
@group(0) @binding(3) var<uniform> n: u32;
@fragment fn main() -> @location(0) vec4<f32> {
    var sum = vec4<f32>(0.0);
    var i = 6u;
    if n == 0u { i = 2u; }
    for (; i < 8u; i++) {
        sum += textureLoad(t, vec2<u32>(i, 0u), 0);
    }
    return sum;
}
";

#[test]
fn a_counter_set_under_a_branch_counts_its_worst_start_in_wgsl_and_wesl() {
    for language in [SourceLanguage::Wgsl, SourceLanguage::Wesl] {
        let c = fragment(BRANCH_SET, language);
        // Worst start i = 2: i = 2..7, 6 loads. ALU: `n == 0u` 1; `i < 8u` x 7 tests = 7,
        // `sum + texel` 6, `i + 1u` 6: 20.
        assert_eq!(c.always, loads(6, 20), "{language:?}: {c:?}");
        assert_eq!(c.conditional, Counts::default(), "{language:?}");
        assert_eq!(c.unknown_loops, 0, "{language:?}");
    }
}

#[test]
fn a_glsl_counter_set_under_a_branch_counts_its_worst_start() {
    let c = fragment(
        "#version 450
layout(set = 0, binding = 0) uniform texture2D t;
layout(set = 0, binding = 1) uniform U { int n; };
layout(location = 0) out vec4 o;
void main() {
    vec4 s = vec4(0.0);
    int i = 6;
    if (n == 0) { i = 2; }
    for (; i < 8; i++) {
        s += texelFetch(t, ivec2(i, 0), 0);
    }
    o = s;
}
",
        FRAG,
    );
    // Worst start i = 2: 6 loads. ALU: `n == 0` 1; `!(i < 8)` 2 ops x 7 tests = 14, `s + texel`
    // 6, `i + 1` 6: 27.
    assert_eq!(c.always, loads(6, 27), "{c:?}");
    assert_eq!(c.unknown_loops, 0);
}

#[test]
fn a_counter_set_in_an_outer_block_starts_there() {
    let c = fragment(
        "
@group(0) @binding(0) var t: texture_2d<f32>;
@fragment fn main() -> @location(0) vec4<f32> {
    var sum = vec4<f32>(0.0);
    var i = 6u;
    i = 0u;
    {
        for (; i < 8u; i++) {
            sum += textureLoad(t, vec2<u32>(i, 0u), 0);
        }
    }
    return sum;
}
",
        SourceLanguage::Wgsl,
    );
    // i = 0..7: 8 loads. ALU: `i < 8u` x 9 = 9, `sum + texel` 8, `i + 1u` 8: 25.
    assert_eq!(c.always, loads(8, 25), "{c:?}");
    assert_eq!(c.unknown_loops, 0);
}

#[test]
fn loops_the_counter_cannot_bound_are_reported() {
    // An enclosing loop resets `j` after the inner loop ran it up: 2 loads on the first outer
    // trip, 4 on the second. A u32 counting down to `i >= 0u` never stops. Each is reported.
    let c = fragment(
        "
@group(0) @binding(0) var t: texture_2d<f32>;
@fragment fn main() -> @location(0) vec4<f32> {
    var sum = vec4<f32>(0.0);
    var j = 2u;
    for (var i = 0u; i < 2u; i++) {
        for (; j < 4u; j++) {
            sum += textureLoad(t, vec2<u32>(i, j), 0);
        }
        j = 0u;
    }
    for (var k = 3u; k >= 0u; k--) {
        sum += textureLoad(t, vec2<u32>(k, 0u), 0);
    }
    return sum;
}
",
        SourceLanguage::Wgsl,
    );
    assert_eq!(c.unknown_loops, 2, "{c:?}");
    assert_eq!(c.unknown_loops_in, ["main", "main"], "{c:?}");
}

#[test]
fn a_break_if_on_the_value_before_the_step_counts_one_trip_more() {
    let c = fragment(
        "
@group(0) @binding(0) var t: texture_2d<f32>;
@fragment fn main() -> @location(0) vec4<f32> {
    var sum = vec4<f32>(0.0);
    var k = 0u;
    loop {
        let before = k;
        sum += textureLoad(t, vec2<u32>(k, 0u), 0);
        continuing {
            k += 1u;
            break if before >= 2u;
        }
    }
    return sum;
}
",
        SourceLanguage::Wgsl,
    );
    // `before` = 0, 1, 2: the third trip leaves: 3 loads. ALU per trip: `sum + texel`,
    // `k + 1u`, `before >= 2u`: 9.
    assert_eq!(c.always, loads(3, 9), "{c:?}");
    assert_eq!(c.unknown_loops, 0);
}
