//! The wgpu glue never panics on what a host hands it: sizes at and past the device's limits,
//! formats the passes cannot use, inputs of another size or format than a pass was built for,
//! errors wgpu raises outside lodkit's calls, and a lost device. Every call runs inside
//! `catch_unwind`; a panic fails the test, and so does an error that does not name the problem.
//!
//! Each test makes a device of its own: errors recorded by the uncaptured-error handler and a
//! destroyed device are device-wide, and must not reach the other tests.

use std::panic::{AssertUnwindSafe, catch_unwind};

use lodkit::combine::DepthConvention;
use lodkit::combine_coverage::{
    CombineData, CombineDataDescriptor, CombineObjectData, CoverageRoute,
};
use lodkit::gpu::frame_sequential::{
    CombineCoverage, CombineFrame, CombinePass, CombinePassDescriptor, CombineRegions,
    LOD_DEPTH_FORMAT, LodBuffers, read_lod_image,
};
use lodkit::gpu::framebuffer_lod::{
    LowResBuffer, RangeSigmas, UpsampleFrame, UpsamplePass, UpsamplePassDescriptor,
    UpsampleSettings,
};
use lodkit::gpu::readback::{read_buffer, read_texture, read_texture_rgba8};
use lodkit::gpu::resources::{DrawUniforms, r32float_texture, texture_2d, uniform_buffer};
use lodkit::gpu::{GpuContext, GpuError};
use lodkit::visibility::{VisibilityPattern, visibility_texture};
use lodkit_scenes::gbuffer::{EdgeScene, GBufferFrame, GBufferRenderer, ShadingTerm};
use lodkit_scenes::lod_buffer::{LodBufferFrame, LodBufferRenderer};
use lodkit_scenes::mesh::{GpuMesh, Mesh, MeshRenderer, RenderTarget};
use lodkit_scenes::transition::TransitionScene;

use crate::support::say;

const RGBA8: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// A device of this test's own (see the module comment).
fn own_gpu() -> Option<GpuContext> {
    let _shared = crate::support::gpu_for(crate::support::Needs::Passes)?;
    Some(GpuContext::new_headless(&Default::default()).expect("a second device"))
}

/// Runs `f`, failing the test with `what` if it panics.
fn no_panic<T>(what: &str, f: impl FnOnce() -> T) -> T {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(v) => v,
        Err(p) => {
            let message = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            panic!("{what} panicked: {message}")
        }
    }
}

/// What a sized call must return for `(width, height)` on a device whose largest texture side is
/// `limit`: `Ok` when both fit (or an out-of-memory error, which a device may raise for the
/// largest sizes), `TooLarge` naming the first side that does not, with the limit.
fn check_sized<T>(
    call: &str,
    (w, h): (u32, u32),
    limit: u32,
    result: Result<T, GpuError>,
    size_of: impl Fn(&T) -> (u32, u32),
) {
    let over = [("width", w), ("height", h)]
        .into_iter()
        .find(|&(_, v)| v > limit);
    match (over, result) {
        (None, Ok(v)) => assert_eq!(
            size_of(&v),
            (w.max(1), h.max(1)),
            "{call}({w}, {h}): a zero side is taken as 1, others as given"
        ),
        (None, Err(GpuError::OutOfMemory { .. })) => {}
        (None, Err(e)) => panic!("{call}({w}, {h}) fits the limit {limit} but failed: {e}"),
        (
            Some((side, value)),
            Err(GpuError::TooLarge {
                parameter,
                value: got,
                max,
                ..
            }),
        ) => {
            assert_eq!(
                (parameter, got, max),
                (side, u64::from(value), u64::from(limit))
            );
        }
        (Some(_), Err(e)) => panic!("{call}({w}, {h}): TooLarge expected, got {e}"),
        (Some(_), Ok(_)) => panic!("{call}({w}, {h}) is past the limit {limit} but succeeded"),
    }
}

#[test]
fn every_allocating_call_reports_sizes_past_the_limits() {
    let Some(gpu) = own_gpu() else { return };
    let gpu = &gpu;
    let limit = gpu.device.limits().max_texture_dimension_2d;
    let sides = [0, 1, limit, limit + 1, u32::MAX];
    let mut calls = 0;
    for w in sides {
        for h in sides {
            let what = |call: &str| format!("{call}({w}, {h})");
            // limit x limit is a real request (16384^2 texels is 268 MB at one byte each, and
            // software GPUs allocate it): it is made once, with a one-byte format, and the calls
            // allocating several textures of 8 to 16 bytes per texel are not asked for it.
            if w == limit && h == limit {
                let usage = wgpu::TextureUsages::TEXTURE_BINDING;
                let r = no_panic(&what("texture_2d"), || {
                    texture_2d(gpu, (w, h), wgpu::TextureFormat::R8Unorm, usage, "largest")
                });
                say(&format!(
                    "texture_2d({w}, {h}, R8Unorm): {:?}",
                    r.as_ref().map(drop)
                ));
                check_sized("texture_2d", (w, h), limit, r, |t| (t.width(), t.height()));
                calls += 1;
                continue;
            }
            let r = no_panic(&what("RenderTarget::new"), || RenderTarget::new(gpu, w, h));
            check_sized("RenderTarget::new", (w, h), limit, r, RenderTarget::size);
            let r = no_panic(&what("LodBuffers::new"), || {
                LodBuffers::new(gpu, w, h, RGBA8)
            });
            check_sized("LodBuffers::new", (w, h), limit, r, LodBuffers::size);
            let r = no_panic(&what("LodBuffers::without_motion"), || {
                LodBuffers::without_motion(gpu, w, h, RGBA8)
            });
            check_sized(
                "LodBuffers::without_motion",
                (w, h),
                limit,
                r,
                LodBuffers::size,
            );
            let r = no_panic(&what("LowResBuffer::new"), || {
                LowResBuffer::new(gpu, w, h, RGBA8)
            });
            check_sized(
                "LowResBuffer::new",
                (w, h),
                limit,
                r,
                LowResBuffer::full_size,
            );
            let usage = wgpu::TextureUsages::TEXTURE_BINDING;
            let r = no_panic(&what("texture_2d"), || {
                texture_2d(gpu, (w, h), RGBA8, usage, "sweep")
            });
            check_sized("texture_2d", (w, h), limit, r, |t| (t.width(), t.height()));
            let mut buffers = LodBuffers::new(gpu, 2, 2, RGBA8).unwrap();
            let r = no_panic(&what("LodBuffers::resize"), || buffers.resize(gpu, w, h));
            check_sized(
                "LodBuffers::resize",
                (w, h),
                limit,
                r.map(|()| &buffers),
                |b| b.size(),
            );
            let mut low = LowResBuffer::new(gpu, 2, 2, RGBA8).unwrap();
            let r = no_panic(&what("LowResBuffer::resize"), || low.resize(gpu, w, h));
            check_sized(
                "LowResBuffer::resize",
                (w, h),
                limit,
                r.map(|()| &low),
                |l| l.full_size(),
            );
            calls += 6;
        }
    }
    // Buffers: sizes in bytes against max_buffer_size.
    let max_buffer = gpu.device.limits().max_buffer_size;
    for bytes in [0usize, 1, 256, usize::MAX] {
        let r = no_panic("uniform_buffer", || uniform_buffer(gpu, bytes, "sweep"));
        match r {
            Err(GpuError::TooLarge { limit, .. }) => assert_eq!(limit, "max_buffer_size"),
            Err(e) => panic!("uniform_buffer({bytes}): {e}"),
            Ok(_) => assert!((bytes as u64) <= max_buffer),
        }
        let r = no_panic("DrawUniforms::new", || {
            DrawUniforms::new(gpu, 64, bytes, "sweep")
        });
        assert!(
            r.is_ok() == (bytes != usize::MAX),
            "DrawUniforms::new(64, {bytes}): {r:?}"
        );
        let r = no_panic("DrawUniforms::new", || {
            DrawUniforms::new(gpu, bytes, 4, "sweep")
        });
        let binding = gpu.device.limits().max_uniform_buffer_binding_size as usize;
        assert!(
            r.is_ok() == (bytes <= binding),
            "DrawUniforms::new({bytes}, 4): {r:?}"
        );
        calls += 3;
    }
    // A visibility texture whose texels do not fill it, and one past the limit.
    let r = no_panic("r32float_texture", || {
        r32float_texture(gpu, 4, &[0.5; 15], "sweep")
    });
    assert!(
        matches!(
            r,
            Err(GpuError::Mismatch {
                parameter: "texels",
                ..
            })
        ),
        "{r:?}"
    );
    let r = no_panic("r32float_texture", || {
        r32float_texture(gpu, limit + 1, &[], "sweep")
    });
    assert!(r.is_err(), "a texture past the limit");
    // The transition scene and an empty mesh go through the same checks.
    let r = no_panic("TransitionScene::new", || {
        TransitionScene::new(gpu, u32::MAX, 4)
    });
    assert!(
        matches!(
            r,
            Err(GpuError::TooLarge {
                parameter: "width",
                ..
            })
        ),
        "{r:?}"
    );
    let scene = no_panic("TransitionScene::new", || TransitionScene::new(gpu, 0, 0)).unwrap();
    assert_eq!(scene.size(), (1, 1));
    no_panic("GpuMesh::new", || GpuMesh::new(gpu, &Mesh::default())).unwrap();
    gpu.check("sweep").expect("no error escaped to the handler");
    say(&format!(
        "{calls} sized calls at sides {sides:?} and buffer sizes up to usize::MAX: no panic, \
         every size past a limit named with the limit ({:?})",
        gpu.adapter.get_info().backend
    ));
}

#[test]
fn the_issue_example_gets_errors() {
    let Some(gpu) = own_gpu() else { return };
    let gpu = &gpu;
    // 100,000-pixel sides are past every device's max_texture_dimension_2d (WebGPU's default is
    // 8192; the largest devices have 32768).
    let e = LodBuffers::new(gpu, 100_000, 16, RGBA8).unwrap_err();
    say(&format!("LodBuffers::new(100000, 16): {e}"));
    assert!(e.to_string().contains("width = 100000"), "{e}");
    assert!(LowResBuffer::new(gpu, 16, 100_000, RGBA8).is_err());
    assert!(RenderTarget::new(gpu, 100_000, 100_000).is_err());
    let mut buffers = LodBuffers::new(gpu, 16, 16, RGBA8).unwrap();
    let e = buffers.resize(gpu, u32::MAX, u32::MAX).unwrap_err();
    assert!(matches!(e, GpuError::TooLarge { .. }), "{e}");
    assert_eq!(
        buffers.size(),
        (16, 16),
        "a failed resize leaves the buffers as they were"
    );
    let mut low = LowResBuffer::new(gpu, 16, 16, RGBA8).unwrap();
    assert!(low.resize(gpu, u32::MAX, 1).is_err());
    assert_eq!(low.full_size(), (16, 16));
}

#[test]
fn formats_the_passes_cannot_use_are_named() {
    let Some(gpu) = own_gpu() else { return };
    let gpu = &gpu;
    use wgpu::TextureFormat as F;
    let bad = [
        F::Depth32Float,
        F::Stencil8,
        F::Rgba8Uint,
        F::R32Sint,
        F::Rgb9e5Ufloat,
        F::Bc1RgbaUnorm,
        F::Astc {
            block: wgpu::AstcBlock::B4x4,
            channel: wgpu::AstcChannel::Unorm,
        },
    ];
    let vis = visibility_texture(VisibilityPattern::WhiteNoise, 8, 1);
    for format in bad {
        let results: [(&str, Result<(), GpuError>); 7] = [
            (
                "LodBuffers::new",
                LodBuffers::new(gpu, 8, 8, format).map(drop),
            ),
            (
                "LowResBuffer::new",
                LowResBuffer::new(gpu, 8, 8, format).map(drop),
            ),
            ("CombinePass::new", combine_pass(gpu, format).map(drop)),
            (
                "UpsamplePass::new",
                UpsamplePass::new(
                    gpu,
                    &UpsamplePassDescriptor {
                        target_format: format,
                        ..Default::default()
                    },
                )
                .map(drop),
            ),
            (
                "LodBufferRenderer::new",
                LodBufferRenderer::new(gpu, format, &vis, 1.0).map(drop),
            ),
            (
                "GBufferRenderer::new",
                GBufferRenderer::new(gpu, format, ShadingTerm::Full).map(drop),
            ),
            ("EdgeScene::new", EdgeScene::new(gpu, format, 1.0).map(drop)),
        ];
        for (call, r) in results {
            match r {
                Err(GpuError::UnsupportedFormat {
                    format: named,
                    call: c,
                    ..
                }) => assert_eq!((named, c), (format, call)),
                other => {
                    panic!("{call} with {format:?}: UnsupportedFormat expected, got {other:?}")
                }
            }
        }
    }
    // A floating-point format other than the default works everywhere.
    LodBuffers::new(gpu, 8, 8, F::Rgba16Float).unwrap();
    LowResBuffer::new(gpu, 8, 8, F::Rgba16Float).unwrap();
    let descriptor = CombinePassDescriptor {
        target_format: F::Rgba16Float,
        depth: DepthConvention::Reversed,
    };
    CombinePass::new(gpu, &descriptor).unwrap();
    let r = EdgeScene::new(gpu, RGBA8, f32::NAN);
    assert!(
        matches!(
            r,
            Err(GpuError::Invalid {
                parameter: "aspect",
                ..
            })
        ),
        "{r:?}"
    );
    let r = LodBufferRenderer::new(gpu, RGBA8, &vis, 0.0);
    assert!(
        matches!(
            r,
            Err(GpuError::Invalid {
                parameter: "vis_scale",
                ..
            })
        ),
        "{r:?}"
    );
    gpu.check("formats")
        .expect("no error escaped to the handler");
}

#[test]
fn passes_given_mismatched_inputs_name_both() {
    let Some(gpu) = own_gpu() else { return };
    let gpu = &gpu;
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
    let target = |w, h, format| {
        texture_2d(gpu, (w, h), format, usage, "target")
            .unwrap()
            .create_view(&Default::default())
    };
    let encoder = || gpu.device.create_command_encoder(&Default::default());
    let mismatch = |r: Result<(), GpuError>, parameter: &str, found: &str, expected: &str| match r {
        Err(GpuError::Mismatch {
            parameter: p,
            found: f,
            expected: e,
            ..
        }) => {
            assert_eq!(p, parameter);
            assert!(f.contains(found), "`{f}` should name {found}");
            assert!(e.contains(expected), "`{e}` should name {expected}");
        }
        other => panic!("{parameter}: Mismatch expected, got {other:?}"),
    };
    // Combine: target of another size, then of another format.
    let buffers = LodBuffers::new(gpu, 32, 24, RGBA8).unwrap();
    let combine = combine_pass(gpu, RGBA8).unwrap();
    let small = target(16, 24, RGBA8);
    let r = no_panic("CombinePass::record", || {
        combine
            .record(gpu, &mut encoder(), &whole(&buffers, 0, &small))
            .map(drop)
    });
    mismatch(r, "target", "16 x 24", "32 x 24");
    let other = target(32, 24, wgpu::TextureFormat::Rgba16Float);
    let r = no_panic("CombinePass::record", || {
        combine
            .record(gpu, &mut encoder(), &whole(&buffers, 0, &other))
            .map(drop)
    });
    mismatch(r, "target", "Rgba16Float", "Rgba8Unorm");
    let right = target(32, 24, RGBA8);
    let mut e = encoder();
    combine
        .record(gpu, &mut e, &whole(&buffers, 1, &right))
        .unwrap();
    gpu.queue.submit([e.finish()]);
    // Combine told the older levels' coverage: data that does not fill its texture, an object
    // displayed at an older_tau with no pattern to display it by, a depth pass read but not
    // given, one of another size.
    let known_with = |data, level_depth, pattern| {
        let frame = CombineFrame {
            coverage: CombineCoverage::Known {
                data,
                level_depth,
                pattern,
            },
            ..whole(&buffers, 0, &right)
        };
        no_panic("CombinePass::record", || {
            combine.record(gpu, &mut encoder(), &frame).map(drop)
        })
    };
    let known = |data, level_depth| known_with(data, level_depth, None);
    let square = [
        [2.0, 2.0, 2.0, 6.0],
        [2.0, 6.0, 6.0, 6.0],
        [6.0, 6.0, 6.0, 2.0],
    ];
    let object = |older_tau, route| CombineObjectData {
        id: 3,
        new_to_old: glam::Mat4::IDENTITY,
        older_tau,
        route,
    };
    let data = |objects: &[CombineObjectData], level_depth| {
        CombineData::new(&CombineDataDescriptor {
            height: 24,
            level_depth,
            objects,
            ..Default::default()
        })
        .unwrap()
    };
    let silhouette = data(&[object(None, CoverageRoute::Silhouette(&square))], false);
    let mut short = silhouette.clone();
    short.texels.pop();
    mismatch(known(&short, None), "coverage.data", "texels", "texels");
    let anchored = data(
        &[object(Some(0.5), CoverageRoute::Silhouette(&square))],
        false,
    );
    mismatch(
        known(&anchored, None),
        "coverage.pattern",
        "id 3",
        "older_tau",
    );
    let pattern = texture_2d(
        gpu,
        (4, 4),
        wgpu::TextureFormat::R32Float,
        wgpu::TextureUsages::TEXTURE_BINDING,
        "pattern",
    )
    .unwrap()
    .create_view(&Default::default());
    known_with(&anchored, None, Some(&pattern)).unwrap();
    let depth_pass = data(&[object(None, CoverageRoute::DepthPass)], true);
    mismatch(
        known(&depth_pass, None),
        "coverage.level_depth",
        "None",
        "depth pass",
    );
    let depth = |w, h| {
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        texture_2d(gpu, (w, h), LOD_DEPTH_FORMAT, usage, "level depth").unwrap()
    };
    let (half, whole_size) = (depth(16, 24), depth(32, 24));
    mismatch(
        known(&depth_pass, Some(&half)),
        "coverage.level_depth",
        "16 x 24",
        "32 x 24",
    );
    known(&depth_pass, Some(&whole_size)).unwrap();
    known(&silhouette, None).unwrap();

    // Upsample: geometry and target of other sizes and formats, and sigmas out of range.
    let low = LowResBuffer::new(gpu, 32, 24, RGBA8).unwrap();
    let full = LowResBuffer::new(gpu, 32, 24, RGBA8).unwrap();
    let half = LowResBuffer::new(gpu, 16, 12, RGBA8).unwrap();
    let desc = UpsamplePassDescriptor {
        target_format: RGBA8,
        ..Default::default()
    };
    let upsample = UpsamplePass::new(gpu, &desc).unwrap();
    let run = |geometry: &wgpu::Texture, sigma: f32, view: &wgpu::TextureView| {
        no_panic("UpsamplePass::record", || {
            let frame = UpsampleFrame {
                low: &low,
                full_geometry: geometry,
                full_albedo: None,
                target: view,
                settings: UpsampleSettings {
                    r: 2.0,
                    sigmas: RangeSigmas {
                        depth: sigma,
                        normal: sigma,
                    },
                },
            };
            upsample.record(gpu, &mut encoder(), &frame)
        })
    };
    mismatch(
        run(half.geometry(), 1.0, &right),
        "frame.full_geometry",
        "16 x 12",
        "32 x 24",
    );
    mismatch(
        run(full.color(), 1.0, &right),
        "frame.full_geometry",
        "Rgba8Unorm",
        "Rgba16Float",
    );
    mismatch(
        run(full.geometry(), 1.0, &small),
        "frame.target",
        "16 x 24",
        "32 x 24",
    );
    mismatch(
        run(full.geometry(), 1.0, &other),
        "frame.target",
        "Rgba16Float",
        "Rgba8Unorm",
    );
    for sigma in [0.0, -1.0, f32::NAN] {
        let r = run(full.geometry(), sigma, &right);
        assert!(
            matches!(
                r,
                Err(GpuError::Invalid {
                    parameter: "frame.settings.sigmas.depth",
                    ..
                })
            ),
            "{r:?}"
        );
    }
    run(full.geometry(), f32::INFINITY, &right).unwrap();

    // Renderers handed targets of another color format.
    let vis = visibility_texture(VisibilityPattern::WhiteNoise, 8, 1);
    let renderer = LodBufferRenderer::new(gpu, RGBA8, &vis, 1.0).unwrap();
    let float_buffers = LodBuffers::new(gpu, 8, 8, wgpu::TextureFormat::Rgba16Float).unwrap();
    let r = renderer.render(gpu, &float_buffers, &LodBufferFrame::default());
    mismatch(r.map(drop), "buffers", "Rgba16Float", "Rgba8Unorm");
    let g = GBufferRenderer::new(gpu, RGBA8, ShadingTerm::Full).unwrap();
    let float_low = LowResBuffer::new(gpu, 8, 8, wgpu::TextureFormat::Rgba16Float).unwrap();
    let r = g.render(gpu, &float_low, &GBufferFrame::default());
    mismatch(r, "target", "Rgba16Float", "Rgba8Unorm");

    // Readback: wrong texel size, no COPY_SRC, a LOD image of another format, too many bytes.
    let r = read_texture(gpu, low.color(), 8).map(drop);
    mismatch(r, "bytes_per_pixel", "8", "4 bytes");
    let sampled = texture_2d(
        gpu,
        (4, 4),
        RGBA8,
        wgpu::TextureUsages::TEXTURE_BINDING,
        "s",
    )
    .unwrap();
    mismatch(
        read_texture_rgba8(gpu, &sampled).map(drop),
        "texture usage",
        "TEXTURE_BINDING",
        "COPY_SRC",
    );
    let r = read_lod_image(gpu, &float_buffers, 0);
    assert!(
        matches!(r, Err(GpuError::UnsupportedFormat { .. })),
        "{r:?}"
    );
    let draws = DrawUniforms::new(gpu, 16, 4, "d").unwrap();
    mismatch(
        draws.write(gpu, &[[0u32; 8]]).map(drop),
        "items",
        "32 bytes",
        "16 bytes",
    );
    let buffer = uniform_buffer(gpu, 16, "u").unwrap();
    mismatch(
        read_buffer(gpu, encoder(), &buffer, 32).map(drop),
        "size",
        "32",
        "16 bytes",
    );
    gpu.check("mismatches")
        .expect("no error escaped to the handler");
}

#[test]
fn errors_outside_lodkit_are_reported_by_the_next_call() {
    let Some(gpu) = own_gpu() else { return };
    // The engine's own mistake on the device: a texture with no usage. No error scope is open,
    // so it reaches the handler lodkit installed, which records it instead of panicking.
    let _bad = engine_mistake(&gpu);
    let e = no_panic("RenderTarget::new", || RenderTarget::new(&gpu, 4, 4)).unwrap_err();
    say(&format!("after an engine error: {e}"));
    assert!(
        matches!(&e, GpuError::Uncaptured { count: 1, call: "RenderTarget::new", first } if first.contains("engine texture")),
        "{e:?}"
    );
    RenderTarget::new(&gpu, 4, 4).expect("the record is cleared once reported");
}

/// The engine's own mistake on the device, outside lodkit's calls (no error scope is open): a
/// texture with no usage, labelled "engine texture".
fn engine_mistake(gpu: &GpuContext) -> wgpu::Texture {
    gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("engine texture"),
        size: wgpu::Extent3d {
            width: 4,
            height: 4,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: RGBA8,
        usage: wgpu::TextureUsages::empty(),
        view_formats: &[],
    })
}

/// A context over an engine's device leaves the engine's uncaptured-error handler in place
/// (`from_parts`): the engine's own mistake reaches its handler, not lodkit's record; asked to
/// (`DeviceHandlers::Install`), lodkit's handler replaces it and the next call names the error.
#[test]
fn an_engines_handlers_stay_unless_lodkit_is_asked_to_install_its_own() {
    use std::sync::Arc;
    use std::sync::atomic::{AtomicUsize, Ordering};

    use lodkit::gpu::{DeviceHandlers, GpuContextDescriptor};

    let Some(own) = own_gpu() else { return };
    let parts = || {
        (
            own.instance.clone(),
            own.adapter.clone(),
            own.device.clone(),
            own.queue.clone(),
        )
    };
    let seen = Arc::new(AtomicUsize::new(0));
    let counter = Arc::clone(&seen);
    own.device
        .on_uncaptured_error(Arc::new(move |_: wgpu::Error| {
            counter.fetch_add(1, Ordering::SeqCst);
        }));
    let (instance, adapter, device, queue) = parts();
    let kept = GpuContext::from_parts(instance, adapter, device, queue);
    let _bad = engine_mistake(&kept);
    assert_eq!(
        seen.load(Ordering::SeqCst),
        1,
        "the engine's handler saw it"
    );
    kept.check("check").expect("lodkit recorded nothing");
    RenderTarget::new(&kept, 4, 4).expect("lodkit's calls work over the engine's device");

    let (instance, adapter, device, queue) = parts();
    let descriptor = GpuContextDescriptor {
        handlers: DeviceHandlers::Install,
    };
    let installed = GpuContext::from_parts_with(instance, adapter, device, queue, &descriptor);
    let _bad = engine_mistake(&installed);
    assert_eq!(
        seen.load(Ordering::SeqCst),
        1,
        "the engine's handler was replaced"
    );
    let e = installed.check("check").unwrap_err();
    assert!(
        matches!(&e, GpuError::Uncaptured { count: 1, first, .. } if first.contains("engine texture")),
        "{e:?}"
    );
}

#[test]
fn a_lost_device_is_an_error_and_a_new_context_recovers() {
    let Some(gpu) = own_gpu() else { return };
    let gpu = &gpu;
    let buffers = LodBuffers::new(gpu, 16, 16, RGBA8).unwrap();
    let combine = combine_pass(gpu, RGBA8).unwrap();
    let target = RenderTarget::new(gpu, 16, 16).unwrap();
    let view = target.color.create_view(&Default::default());
    // Stands in for a driver reset.
    gpu.device.destroy();
    let lost = |what: &str, r: Result<(), GpuError>| match r {
        Err(e) if e.is_device_lost() => e,
        other => panic!("{what}: DeviceLost expected, got {other:?}"),
    };
    let e = lost(
        "LodBuffers::new",
        no_panic("new", || LodBuffers::new(gpu, 8, 8, RGBA8).map(drop)),
    );
    say(&format!("after Device::destroy: {e}"));
    let mut b = buffers;
    lost(
        "LodBuffers::resize",
        no_panic("resize", || b.resize(gpu, 32, 32)),
    );
    lost(
        "CombinePass::new",
        no_panic("combine", || combine_pass(gpu, RGBA8).map(drop)),
    );
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    lost(
        "CombinePass::record",
        no_panic("record", || {
            combine
                .record(gpu, &mut encoder, &whole(&b, 0, &view))
                .map(drop)
        }),
    );
    lost(
        "MeshRenderer::new",
        no_panic("mesh", || MeshRenderer::new(gpu, false).map(drop)),
    );
    lost(
        "read_texture_rgba8",
        no_panic("read", || read_texture_rgba8(gpu, &target.color).map(drop)),
    );
    lost("wait_idle", no_panic("wait", || gpu.wait_idle()));
    lost("check", gpu.check("check"));

    // Recovery: a new context and new objects, as docs/errors.md shows.
    let gpu = GpuContext::new_headless(&Default::default()).unwrap();
    let mut buffers = LodBuffers::new(&gpu, 16, 16, RGBA8).unwrap();
    buffers.resize(&gpu, 24, 16).unwrap();
    let target = RenderTarget::new(&gpu, 24, 16).unwrap();
    let combine = combine_pass(&gpu, RGBA8).unwrap();
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    let view = target.color.create_view(&Default::default());
    combine
        .record(&gpu, &mut encoder, &whole(&buffers, 0, &view))
        .unwrap();
    gpu.queue.submit([encoder.finish()]);
    assert_eq!(
        read_texture_rgba8(&gpu, &target.color).unwrap().len(),
        24 * 16 * 4
    );
}

/// The combine for targets of `format`, standard depth.
fn combine_pass(gpu: &GpuContext, format: wgpu::TextureFormat) -> Result<CombinePass, GpuError> {
    let descriptor = CombinePassDescriptor {
        target_format: format,
        ..Default::default()
    };
    CombinePass::new(gpu, &descriptor)
}

/// A recording of the combine over the whole `target` with no history.
fn whole<'a>(
    buffers: &'a LodBuffers,
    newer: usize,
    target: &'a wgpu::TextureView,
) -> CombineFrame<'a> {
    CombineFrame {
        buffers,
        newer,
        new_to_old: CombinePass::NO_HISTORY,
        target,
        regions: CombineRegions::Everywhere,
        coverage: CombineCoverage::Estimated,
    }
}
