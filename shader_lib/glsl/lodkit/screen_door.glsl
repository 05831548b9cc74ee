// lodkit::screen_door — screen-door transparency with complementary patterns
// (DigitalRune LOD blending; ordered dither after Bayer 1973, blue noise after Ulichney 1993).
//
// GLSL twin of shader_lib/wgsl/lodkit/screen_door.wgsl; same semantics, `lodkit_` prefix.
// The current LOD is drawn with alpha -(1 - t), the next with +t: a negative alpha inverts the
// pattern. Uses no derivatives and no textures.
//
// Exports:
//   LODKIT_SCREEN_DOOR_BAYER_4X4: uint[2]   4x4 Bayer ranks, 4 bits each, row-major
//   LODKIT_SCREEN_DOOR_BLUE_NOISE_16X16: uint[64]   16x16 void-and-cluster ranks, 8 bits each
//   lodkit_screen_door_threshold(frag_coord) -> float   (rank + 0.5) / levels at the pixel
//   lodkit_screen_door_keep(frag_coord, alpha) -> bool   keep the fragment? (negative = inverted)
// Usage: if (!lodkit_screen_door_keep(gl_FragCoord.xy, lod_alpha)) discard;
// Shader defs:
//   LODKIT_SCREEN_DOOR_BLUE_NOISE (bool, default off) — use the 16x16 blue-noise dither instead of
//   the 4x4 Bayer matrix.
#ifndef LODKIT_SCREEN_DOOR_GLSL
#define LODKIT_SCREEN_DOOR_GLSL

/// Ranks of the 4x4 Bayer matrix, 4 bits each, lowest bits first, row-major.
const uint LODKIT_SCREEN_DOOR_BAYER_4X4[2] = uint[2](0x6e4ca280u, 0x5d7f91b3u);

/// Ranks of a 16x16 void-and-cluster dither array (seed 0x5c2ee4d0), 8 bits each, lowest first.
const uint LODKIT_SCREEN_DOOR_BLUE_NOISE_16X16[64] = uint[64](
    0x152e7a3fu, 0xdbaf3e8au, 0x7539a363u, 0xc1e029b2u, 0xa961e6b0u, 0x109458cfu, 0xd9924fc2u, 0x8b135e46u,
    0xef970b28u, 0x36f92670u, 0x06cc247bu, 0x71d0ec84u, 0x384ccbfeu, 0x66b5d504u, 0x69fbaae1u, 0x449a30b9u,
    0xbd7c905fu, 0x9145809fu, 0x173c5709u, 0xab1b53a2u, 0x21e30e35u, 0xed1a5cf6u, 0xc8839bbeu, 0xc4df76f2u,
    0x6c52b1eeu, 0x31cdac3bu, 0x4ae72272u, 0x67008c2au, 0x99ce1879u, 0x51860fddu, 0x1264aedeu, 0x9d41d8a6u,
    0x2c8847bfu, 0xa1f878bcu, 0x7ed14003u, 0x23f754bbu, 0x05fcd65bu, 0x6820425du, 0x32ff8dcau, 0xa4850a6du,
    0xa76b3414u, 0xb4d795e8u, 0x9e115a2du, 0xe93ac9e2u, 0x4b82b896u, 0x4d7716c5u, 0x49c07df1u, 0x74b36227u,
    0x25f40ddcu, 0x08e53789u, 0xadea1ea0u, 0x5019f58eu, 0xd34365c3u, 0x93ba59a5u, 0x6f3360d4u, 0x2f7fd202u,
    0x739c1f8fu, 0x2b6efd01u, 0xc687b648u, 0xf0a83d56u, 0xebb7da55u, 0x811dc74eu, 0x1ce40cf3u, 0x076a98fau
);

/// Dither threshold in (0, 1) at framebuffer position `frag_coord`: (rank + 0.5) / levels.
float lodkit_screen_door_threshold(vec2 frag_coord) {
    ivec2 p = ivec2(floor(frag_coord));
#ifdef LODKIT_SCREEN_DOOR_BLUE_NOISE
    uint i = uint((p.y & 15) * 16 + (p.x & 15));
    uint rank = (LODKIT_SCREEN_DOOR_BLUE_NOISE_16X16[i >> 2u] >> ((i & 3u) * 8u)) & 0xffu;
    return (float(rank) + 0.5) / 256.0;
#else
    uint i = uint((p.y & 3) * 4 + (p.x & 3));
    uint rank = (LODKIT_SCREEN_DOOR_BAYER_4X4[i >> 3u] >> ((i & 7u) * 4u)) & 0xfu;
    return (float(rank) + 0.5) / 16.0;
#endif
}

/// Whether the fragment at `frag_coord` survives screen-door alpha `alpha` (negative = inverted).
bool lodkit_screen_door_keep(vec2 frag_coord, float alpha) {
    float threshold = lodkit_screen_door_threshold(frag_coord);
    if (alpha < 0.0) {
        return threshold >= 1.0 + alpha;
    }
    return threshold < alpha;
}

#endif // LODKIT_SCREEN_DOOR_GLSL
