//! PNG line plots and stacked bar charts (plotters) for the report. Text needs a TrueType font: `LODKIT_FONT` names
//! one, else common system fonts are tried; without any, plots are drawn without text (the
//! report's tables carry the same figures).

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use plotters::prelude::*;

use crate::demo::error::DemoError;

/// One line of a chart.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend entry.
    pub name: String,
    /// Points, x ascending.
    pub points: Vec<(f32, f32)>,
}

/// A line chart.
#[derive(Clone, Debug)]
pub struct Chart {
    /// Caption.
    pub title: String,
    /// X axis description.
    pub x_label: String,
    /// Y axis description.
    pub y_label: String,
    /// Lines.
    pub series: Vec<Series>,
    /// Draw a marker at every point (for sparse data).
    pub markers: bool,
    /// A horizontal reference line (e.g. a frame-time target).
    pub reference: Option<f32>,
    /// Start the y axis at 0 (else at the smallest value, with a margin).
    pub y_from_zero: bool,
}

const FONT_CANDIDATES: [&str; 6] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/System/Library/Fonts/Supplemental/Arial.ttf",
    "C:\\Windows\\Fonts\\arial.ttf",
];

/// The font the plots use, registered once; `None` when no font was found.
pub fn plot_font() -> Option<&'static Path> {
    static FONT: OnceLock<Option<PathBuf>> = OnceLock::new();
    FONT.get_or_init(|| {
        let from_env = std::env::var_os("LODKIT_FONT").map(PathBuf::from);
        let candidates = from_env
            .into_iter()
            .chain(FONT_CANDIDATES.iter().map(PathBuf::from));
        for path in candidates {
            let Ok(bytes) = std::fs::read(&path) else {
                continue;
            };
            let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
            if plotters::style::register_font("sans-serif", FontStyle::Normal, bytes).is_ok() {
                return Some(path);
            }
        }
        None
    })
    .as_deref()
}

fn plot_error(e: impl std::fmt::Display) -> DemoError {
    DemoError::Plot(e.to_string())
}

/// Draws `chart` into a 900 x 420 PNG at `path`.
pub fn line_chart(path: &Path, chart: &Chart) -> Result<(), DemoError> {
    let text = plot_font().is_some();
    let points = chart.series.iter().flat_map(|s| s.points.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (f32::MAX, f32::MIN, f32::MAX, f32::MIN);
    for &(x, y) in points.filter(|p| p.0.is_finite() && p.1.is_finite()) {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if let Some(r) = chart.reference {
        y0 = y0.min(r);
        y1 = y1.max(r);
    }
    if x0 >= x1 {
        (x0, x1) = (x0.min(0.0), x0.max(0.0) + 1.0);
    }
    if y0 > y1 {
        (y0, y1) = (0.0, 1.0);
    }
    let pad = ((y1 - y0) * 0.08).max(1e-3);
    let y0 = if chart.y_from_zero {
        y0.min(0.0)
    } else {
        y0 - pad
    };
    let y1 = y1 + pad;
    let xpad = if chart.markers { (x1 - x0) * 0.04 } else { 0.0 };
    let (x0, x1) = (x0 - xpad, x1 + xpad);
    with_chart(path, &chart.title, x0..x1, y0..y1, |ctx| {
        draw_lines(ctx, chart, (x0, x1), text)
    })
}

fn draw_lines(
    ctx: &mut Ctx<'_>,
    chart: &Chart,
    (x0, x1): (f32, f32),
    text: bool,
) -> Result<(), DemoError> {
    let mut mesh = ctx.configure_mesh();
    if text {
        mesh.x_desc(&chart.x_label).y_desc(&chart.y_label);
    } else {
        mesh.x_labels(0).y_labels(0);
    }
    mesh.draw().map_err(plot_error)?;
    if let Some(r) = chart.reference {
        ctx.draw_series(LineSeries::new([(x0, r), (x1, r)], BLACK.mix(0.4)))
            .map_err(plot_error)?;
    }
    for (i, s) in chart.series.iter().enumerate() {
        let color = Palette99::pick(i).to_rgba();
        let drawn = ctx
            .draw_series(LineSeries::new(s.points.clone(), color.stroke_width(2)))
            .map_err(plot_error)?;
        if text {
            drawn.label(s.name.clone()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2))
            });
        }
        if chart.markers {
            ctx.draw_series(s.points.iter().map(|&p| Circle::new(p, 4, color.filled())))
                .map_err(plot_error)?;
        }
    }
    Ok(())
}

type Ctx<'a> = ChartContext<
    'a,
    BitMapBackend<'a>,
    Cartesian2d<plotters::coord::types::RangedCoordf32, plotters::coord::types::RangedCoordf32>,
>;

/// A 900 x 420 PNG at `path` over `x` and `y`, with `title` and a legend when a font exists;
/// `draw` draws the mesh and the series.
fn with_chart(
    path: &Path,
    title: &str,
    x: std::ops::Range<f32>,
    y: std::ops::Range<f32>,
    draw: impl FnOnce(&mut Ctx<'_>) -> Result<(), DemoError>,
) -> Result<(), DemoError> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| DemoError::io(dir, e))?;
    }
    let text = plot_font().is_some();
    let root = BitMapBackend::new(path, (900, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_error)?;
    let mut builder = ChartBuilder::on(&root);
    builder.margin(14);
    if text {
        builder
            .caption(title, ("sans-serif", 20))
            .x_label_area_size(40)
            .y_label_area_size(60);
    }
    let mut ctx = builder.build_cartesian_2d(x, y).map_err(plot_error)?;
    draw(&mut ctx)?;
    if text {
        ctx.configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .border_style(BLACK)
            .background_style(WHITE.mix(0.85))
            .draw()
            .map_err(plot_error)?;
    }
    root.present().map_err(plot_error)?;
    Ok(())
}

/// A stacked bar chart: one bar per entry, its parts stacked bottom to top.
#[derive(Clone, Debug)]
pub struct BarChart {
    /// Caption.
    pub title: String,
    /// Y axis description.
    pub y_label: String,
    /// Names of the parts, bottom to top (the legend).
    pub parts: Vec<String>,
    /// Bars: label and one value per part.
    pub bars: Vec<(String, Vec<f32>)>,
}

/// Draws `chart` into a 900 x 420 PNG at `path`.
pub fn stacked_bars(path: &Path, chart: &BarChart) -> Result<(), DemoError> {
    let text = plot_font().is_some();
    let top = chart
        .bars
        .iter()
        .map(|(_, v)| v.iter().filter(|x| x.is_finite()).sum::<f32>())
        .fold(0.0f32, f32::max)
        .max(1e-3)
        * 1.1;
    let n = chart.bars.len().max(1) as f32;
    with_chart(path, &chart.title, 0f32..n, 0f32..top, |ctx| {
        draw_bars(ctx, chart, text)
    })
}

fn draw_bars(ctx: &mut Ctx<'_>, chart: &BarChart, text: bool) -> Result<(), DemoError> {
    let mut mesh = ctx.configure_mesh();
    mesh.disable_x_mesh();
    let label_of = |x: &f32| {
        let i = (*x - 0.5).round();
        let near = (*x - 0.5 - i).abs() < 0.05 && i >= 0.0;
        chart
            .bars
            .get(i as usize)
            .filter(|_| near)
            .map_or(String::new(), |b| b.0.clone())
    };
    if text {
        mesh.y_desc(&chart.y_label)
            .x_labels(chart.bars.len() * 2 + 1)
            .x_label_formatter(&label_of);
    } else {
        mesh.x_labels(0).y_labels(0);
    }
    mesh.draw().map_err(plot_error)?;
    for (k, part) in chart.parts.iter().enumerate() {
        let color = Palette99::pick(k).to_rgba();
        let rects = chart.bars.iter().enumerate().map(|(i, (_, v))| {
            let below: f32 = v[..k.min(v.len())].iter().filter(|x| x.is_finite()).sum();
            let h = v.get(k).copied().filter(|x| x.is_finite()).unwrap_or(0.0);
            let x = i as f32;
            Rectangle::new([(x + 0.15, below), (x + 0.85, below + h)], color.filled())
        });
        let drawn = ctx.draw_series(rects).map_err(plot_error)?;
        if text {
            drawn.label(part.clone()).legend(move |(x, y)| {
                Rectangle::new([(x, y - 5), (x + 14, y + 5)], color.filled())
            });
        }
    }
    Ok(())
}
