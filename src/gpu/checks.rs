//! The checks every allocating call runs against the device's limits and format capabilities
//! before wgpu would see the request, each returning the [`GpuError`] that names the problem.
//!
//! Rule for sizes: a width or height of 0 is taken as 1 (so a minimized window keeps working);
//! the object's `size()` reports the size it really has. A side larger than
//! `Limits::max_texture_dimension_2d` is [`GpuError::TooLarge`].
//!
//! The public ones are for an engine's own passes beside lodkit's (the reference renderers of
//! the `lodkit-scenes` crate call them), so that they refuse what lodkit's passes refuse, with
//! the same errors. Each takes the `call` (the function the user called, e.g.
//! `"MyPass::new"`) and, where a value is checked, the `parameter` that holds it; the error
//! names both. [`texture_extent`] returns [`GpuError::TooLarge`], [`check_color_format`] and
//! [`check_low_res_format`] [`GpuError::UnsupportedFormat`], [`same_color_format`]
//! [`GpuError::Mismatch`].

use super::{GpuContext, GpuError};

/// `width` and `height` with 0 taken as 1, checked against `max_texture_dimension_2d`.
pub fn texture_extent(
    gpu: &GpuContext,
    call: &'static str,
    width: u32,
    height: u32,
) -> Result<(u32, u32), GpuError> {
    let max = gpu.device.limits().max_texture_dimension_2d;
    for (parameter, value) in [("width", width), ("height", height)] {
        if value > max {
            return Err(GpuError::TooLarge {
                call,
                parameter,
                value: value.into(),
                limit: "max_texture_dimension_2d",
                max: max.into(),
            });
        }
    }
    Ok((width.max(1), height.max(1)))
}

/// Checks a buffer of `bytes` bytes against `max_buffer_size`.
pub(crate) fn buffer_size(
    gpu: &GpuContext,
    call: &'static str,
    parameter: &'static str,
    bytes: u64,
) -> Result<(), GpuError> {
    let max = gpu.device.limits().max_buffer_size;
    if bytes > max {
        return Err(GpuError::TooLarge {
            call,
            parameter,
            value: bytes,
            limit: "max_buffer_size",
            max,
        });
    }
    Ok(())
}

/// `UnsupportedFormat` for `parameter` of `call`.
fn unsupported_format(
    call: &'static str,
    parameter: &'static str,
    format: wgpu::TextureFormat,
    reason: String,
) -> GpuError {
    GpuError::UnsupportedFormat {
        call,
        parameter,
        format,
        reason,
    }
}

/// Checks that `format` is a floating-point color format (what lodkit's passes read and write
/// as `vec4<f32>`) that the device allows with `usages`.
pub fn check_color_format(
    gpu: &GpuContext,
    call: &'static str,
    parameter: &'static str,
    format: wgpu::TextureFormat,
    usages: wgpu::TextureUsages,
) -> Result<(), GpuError> {
    let unsupported = |reason: String| unsupported_format(call, parameter, format, reason);
    if format.is_depth_stencil_format() {
        return Err(unsupported(
            "it is a depth/stencil format; a color format is needed".into(),
        ));
    }
    if !matches!(
        format.sample_type(None, None),
        Some(wgpu::TextureSampleType::Float { .. })
    ) {
        return Err(unsupported(
            "its texels are integers; lodkit's passes read and write floating-point color".into(),
        ));
    }
    check_format_usages(gpu, call, parameter, format, usages)
}

/// [`check_color_format`], also accepting `lodkit::gbuffer`'s packed low-resolution format
/// ([`crate::gbuffer::PACKED_FORMAT`]), which lodkit's framebuffer-LOD passes write and read as
/// integers.
pub fn check_low_res_format(
    gpu: &GpuContext,
    call: &'static str,
    parameter: &'static str,
    format: wgpu::TextureFormat,
    usages: wgpu::TextureUsages,
) -> Result<(), GpuError> {
    if format == crate::gbuffer::PACKED_FORMAT {
        return check_format_usages(gpu, call, parameter, format, usages);
    }
    check_color_format(gpu, call, parameter, format, usages)
}

/// Checks that the device has the features `format` needs and allows it with `usages`.
pub(crate) fn check_format_usages(
    gpu: &GpuContext,
    call: &'static str,
    parameter: &'static str,
    format: wgpu::TextureFormat,
    usages: wgpu::TextureUsages,
) -> Result<(), GpuError> {
    let unsupported = |reason: String| unsupported_format(call, parameter, format, reason);
    let missing_features = format.required_features() - gpu.device.features();
    if !missing_features.is_empty() {
        return Err(unsupported(format!(
            "it needs device features {missing_features:?}"
        )));
    }
    let allowed = gpu.format_features(format).allowed_usages;
    if !allowed.contains(usages) {
        return Err(unsupported(format!(
            "the device does not allow it as {:?}",
            usages - allowed
        )));
    }
    Ok(())
}

/// Checks that `texture` is 2D, `size` and of `format`, naming `what` expected it.
pub(crate) fn texture_matches(
    call: &'static str,
    parameter: &'static str,
    texture: &wgpu::Texture,
    size: (u32, u32),
    format: wgpu::TextureFormat,
    what: &str,
) -> Result<(), GpuError> {
    if texture.format() != format {
        return Err(GpuError::Mismatch {
            call,
            parameter,
            found: format!("{:?}", texture.format()),
            expected: format!("{what} needs {format:?}"),
        });
    }
    let found = (texture.width(), texture.height());
    if found != size {
        return Err(GpuError::Mismatch {
            call,
            parameter,
            found: format!("{} x {}", found.0, found.1),
            expected: format!("{what} is {} x {}", size.0, size.1),
        });
    }
    Ok(())
}

/// The size of a target of `width` x `height` in `color_format` for `usages` (see
/// [`texture_extent`] and [`check_color_format`]).
pub(crate) fn target_extent(
    gpu: &GpuContext,
    call: &'static str,
    (width, height): (u32, u32),
    color_format: wgpu::TextureFormat,
    usages: wgpu::TextureUsages,
) -> Result<(u32, u32), GpuError> {
    let size = texture_extent(gpu, call, width, height)?;
    check_color_format(gpu, call, "color_format", color_format, usages)?;
    Ok(size)
}

/// Checks that `parameter` has the color format `built_for` that a renderer was built for.
pub fn same_color_format(
    call: &'static str,
    parameter: &'static str,
    found: wgpu::TextureFormat,
    built_for: wgpu::TextureFormat,
) -> Result<(), GpuError> {
    if found == built_for {
        return Ok(());
    }
    Err(GpuError::Mismatch {
        call,
        parameter,
        found: format!("of color format {found:?}"),
        expected: format!("the renderer was built for {built_for:?}"),
    })
}

/// Checks that a resource with `usage` has the flag `needed` (`contains` says whether it does).
pub(crate) fn has_usage<U: std::fmt::Debug>(
    call: &'static str,
    parameter: &'static str,
    usage: U,
    contains: bool,
    needed: &str,
) -> Result<(), GpuError> {
    if contains {
        return Ok(());
    }
    Err(GpuError::Mismatch {
        call,
        parameter,
        found: format!("{usage:?}"),
        expected: format!("this needs {needed}"),
    })
}
