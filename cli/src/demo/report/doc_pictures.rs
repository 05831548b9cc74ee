//! The pictures the technique guides show (`docs/img/`), cut from this run's output so that
//! `lodkit demo --docs docs` keeps them in step with the code: a strip of each transition
//! technique, close-ups of the `field` scene's objects in transition, the framebuffer-LOD
//! comparison at r = 2, the controller plots, the frame-cost breakdown and the shading-cost
//! sweep.

use std::path::Path;

use crate::demo::error::DemoError;
use crate::demo::error::save;
use crate::demo::measures::DemoReport;

/// Frames of a seven-frame strip that go into a picture: the transition's inner five.
const STRIP_SLOTS: std::ops::Range<u32> = 1..6;

fn open(path: &Path) -> Result<image::RgbaImage, DemoError> {
    Ok(image::open(path)
        .map_err(|e| DemoError::io(path, e))?
        .to_rgba8())
}

/// The inner frames of each of `strips` (files under `out/strips/`), one row per strip.
fn stacked_strips(out: &Path, strips: &[String]) -> Result<image::RgbaImage, DemoError> {
    let rows = strips
        .iter()
        .map(|name| open(&out.join("strips").join(format!("{name}.png"))))
        .collect::<Result<Vec<_>, _>>()?;
    let (w, h) = rows.first().map_or((0, 0), |r| (r.width() / 7, r.height()));
    let mut sheet = image::RgbaImage::new(w * STRIP_SLOTS.len() as u32, h * rows.len() as u32);
    for (y, row) in rows.iter().enumerate() {
        let inner = image::imageops::crop_imm(row, w * STRIP_SLOTS.start, 0, sheet.width(), h);
        image::imageops::replace(&mut sheet, &*inner, 0, i64::from(h) * y as i64);
    }
    Ok(sheet)
}

/// Writes `docs/img/*.png` from the pictures of the run written to `out`.
pub fn write_doc_pictures(report: &DemoReport, out: &Path, docs: &Path) -> Result<(), DemoError> {
    let img = docs.join("img");
    let scene = report.scenes.first().map_or("simple", String::as_str);
    let strips = |techniques: &[&str]| -> Vec<String> {
        techniques
            .iter()
            .map(|t| format!("{scene}-{t}-static"))
            .collect()
    };
    let single = stacked_strips(out, &strips(&["unpopping", "dither-blue-noise"]))?;
    save(&single, &img.join("single-frame-transitions.png"))?;
    let sequential = stacked_strips(out, &strips(&["frame-seq-blue-noise"]))?;
    save(&sequential, &img.join("frame-sequential.png"))?;
    save(
        &open(&out.join("upsample/r2.png"))?,
        &img.join("framebuffer-lod.png"),
    )?;
    let field = out.join("close-ups/field.png");
    if field.exists() {
        save(&open(&field)?, &img.join("field-close-ups.png"))?;
    }
    for (plot, name) in [
        ("controllers", "framerate-control"),
        ("frame-breakdown", "frame-breakdown"),
        ("speedup-vs-shading", "speedup-vs-shading"),
        ("closed-loop-ms", "closed-loop-ms"),
    ] {
        let picture = open(&out.join("plots").join(format!("{plot}.png")))?;
        save(&picture, &img.join(format!("{name}.png")))?;
    }
    Ok(())
}
