//! PNG charts with plotters: lines over a (possibly logarithmic) x axis, and a Pareto scatter.
//!
//! Text needs a TrueType font; plotters' `ab_glyph` backend takes one from the system (DejaVu Sans
//! or Liberation Sans, or the file named by `HISTENCIL_FONT`). Without one the charts are still
//! drawn, without captions, tick labels or legends, and [`text_available`] says so.

use crate::{write_file, LabError, Result};
use plotters::prelude::*;
use std::path::Path;
use std::sync::OnceLock;

const SIZE: (u32, u32) = (900, 560);
const FONT: &str = "sans-serif";
const FONT_FILES: [&str; 4] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
];

/// Whether a font was found and registered (once per process).
pub fn text_available() -> bool {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    *REGISTERED.get_or_init(|| {
        let from_env = std::env::var("HISTENCIL_FONT").ok();
        let bytes = from_env
            .iter()
            .map(String::as_str)
            .chain(FONT_FILES)
            .find_map(|path| std::fs::read(path).ok());
        bytes.is_some_and(|bytes| {
            let leaked: &'static [u8] = Box::leak(bytes.into_boxed_slice());
            plotters::style::register_font(FONT, FontStyle::Normal, leaked).is_ok()
        })
    })
}

/// One named series of `(x, y)` points, with an error bar `(lo, hi)` per point (the 95 %
/// interval) or none (`bars` empty).
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
    pub bars: Vec<(f64, f64)>,
}

/// Axis description: label and whether it is logarithmic (base 10).
pub struct Axis<'a> {
    pub label: &'a str,
    pub log: bool,
}

impl Axis<'_> {
    fn map(&self, v: f64) -> f64 {
        if self.log {
            v.max(1e-12).log10()
        } else {
            v
        }
    }

    fn unmap(&self, v: f64) -> f64 {
        if self.log {
            10f64.powf(v)
        } else {
            v
        }
    }
}

fn range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if !lo.is_finite() {
        return 0.0..1.0;
    }
    let pad = ((hi - lo) * 0.08).max(1e-9);
    (lo - pad)..(hi + pad)
}

/// A line chart of `series`, one colour each, with markers at the points.
pub fn line_chart(path: &Path, title: &str, x: Axis, y: Axis, series: &[Series]) -> Result<()> {
    let all = || series.iter().flat_map(|s| s.points.iter());
    let bar_ends = || {
        series
            .iter()
            .flat_map(|s| s.bars.iter().flat_map(|b| [b.0, b.1]))
    };
    let xr = range(all().map(|p| x.map(p.0)));
    let yr = range(all().map(|p| p.1).chain(bar_ends()).map(|v| y.map(v)));
    draw_png(path, |root| {
        let text = text_available();
        let mut chart = axes(root, title, (&x, xr), (&y, yr))?;
        for (i, s) in series.iter().enumerate() {
            let colour = Palette99::pick(i).to_rgba();
            let points: Vec<(f64, f64)> =
                s.points.iter().map(|p| (x.map(p.0), y.map(p.1))).collect();
            let line =
                chart.draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))?;
            if text {
                line.label(s.name.clone()).legend(move |(px, py)| {
                    PathElement::new(vec![(px, py), (px + 20, py)], colour.stroke_width(2))
                });
            }
            chart.draw_series(points.iter().map(|p| Circle::new(*p, 4, colour.filled())))?;
            let bars = points.iter().zip(&s.bars).map(|(p, (lo, hi))| {
                PathElement::new(
                    vec![(p.0, y.map(*lo)), (p.0, y.map(*hi))],
                    colour.stroke_width(2),
                )
            });
            chart.draw_series(bars)?;
        }
        if text {
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font((FONT, 15))
                .draw()?;
        }
        Ok(())
    })
}

/// A scatter of `(x, y, label)` points with their Pareto front (lower x and lower y are better)
/// drawn as a step line.
pub fn pareto_chart(
    path: &Path,
    title: &str,
    x: Axis,
    y: Axis,
    points: &[(f64, f64, String)],
) -> Result<()> {
    let front = pareto_front(points.iter().map(|p| (p.0, p.1)).collect());
    let xr = range(points.iter().map(|p| x.map(p.0)));
    let yr = range(points.iter().map(|p| y.map(p.1)));
    draw_png(path, |root| {
        let text = text_available();
        let mut chart = axes(root, title, (&x, xr), (&y, yr))?;
        let mapped = |(px, py): (f64, f64)| (x.map(px), y.map(py));
        chart.draw_series(LineSeries::new(
            front.iter().copied().map(mapped),
            RED.stroke_width(2),
        ))?;
        let at = |(px, py, _): &(f64, f64, String)| mapped((*px, *py));
        chart.draw_series(points.iter().map(|p| Circle::new(at(p), 5, BLUE.filled())))?;
        if text {
            // Labels sit up and to the right of their point, clear of the marker.
            chart.draw_series(points.iter().map(|p| {
                EmptyElement::at(at(p)) + Text::new(p.2.clone(), (8, -18), (FONT, 14).into_font())
            }))?;
        }
        Ok(())
    })
}

/// The points no other point beats in both coordinates, by increasing x.
pub fn pareto_front(mut points: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    points.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut front: Vec<(f64, f64)> = Vec::new();
    for p in points {
        if front.last().is_none_or(|last| p.1 < last.1) {
            front.push(p);
        }
    }
    front
}

/// A number in at most 4 significant digits.
fn short(v: f64) -> String {
    if v != 0.0 && (v.abs() < 0.01 || v.abs() >= 1e5) {
        format!("{v:.2e}")
    } else {
        format!("{}", (v * 1e3).round() / 1e3)
    }
}

type Chart<'a, 'b> = ChartContext<
    'a,
    BitMapBackend<'b>,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// The chart's caption, axes and grid over `x` and `y` (in mapped coordinates), with tick labels
/// in the axes' own units; text only when a font is available.
fn axes<'a, 'b>(
    root: &'a Root<'b>,
    title: &str,
    (x, xr): (&Axis, std::ops::Range<f64>),
    (y, yr): (&Axis, std::ops::Range<f64>),
) -> std::result::Result<Chart<'a, 'b>, Box<dyn std::error::Error + 'static>> {
    let text = text_available();
    let mut builder = ChartBuilder::on(root);
    builder
        .margin(16)
        .x_label_area_size(44)
        .y_label_area_size(64);
    if text {
        builder.caption(title, (FONT, 22));
    }
    let mut chart = builder.build_cartesian_2d(xr, yr)?;
    let x_fmt = |v: &f64| short(x.unmap(*v));
    let y_fmt = |v: &f64| short(y.unmap(*v));
    let mut mesh = chart.configure_mesh();
    mesh.x_label_formatter(&x_fmt).y_label_formatter(&y_fmt);
    if text {
        mesh.x_desc(x.label).y_desc(y.label);
    } else {
        mesh.x_labels(0).y_labels(0);
    }
    mesh.draw()?;
    Ok(chart)
}

type Root<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;
type DrawResult = std::result::Result<(), Box<dyn std::error::Error + 'static>>;

/// Draws on a white RGB canvas with `body`, then encodes it as PNG at `path`.
fn draw_png(path: &Path, body: impl FnOnce(&Root) -> DrawResult) -> Result<()> {
    let fail = |problem: String| LabError::Plot {
        path: path.display().to_string(),
        problem,
    };
    let mut rgb = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(e.to_string()))?;
        body(&root).map_err(|e| fail(e.to_string()))?;
        root.present().map_err(|e| fail(e.to_string()))?;
    }
    let image = image::RgbImage::from_raw(SIZE.0, SIZE.1, rgb).expect("buffer of the canvas size");
    let mut png = Vec::new();
    image
        .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .map_err(|e| fail(e.to_string()))?;
    write_file(path, &png)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_front_keeps_only_undominated_points() {
        let front = pareto_front(vec![
            (1.0, 5.0),
            (2.0, 3.0),
            (3.0, 4.0),
            (4.0, 1.0),
            (2.0, 6.0),
        ]);
        assert_eq!(front, vec![(1.0, 5.0), (2.0, 3.0), (4.0, 1.0)]);
    }

    #[test]
    fn charts_are_png_files() {
        let dir = std::env::temp_dir().join(format!("histencil-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("lines.png");
        let series = [Series {
            name: "a".into(),
            points: vec![(0.001, 1.0), (0.1, 3.0), (1.0, 2.0)],
            bars: vec![(0.9, 1.1), (2.5, 3.5), (1.9, 2.2)],
        }];
        let (x, y) = (
            Axis {
                label: "coverage",
                log: true,
            },
            Axis {
                label: "ms",
                log: false,
            },
        );
        line_chart(&path, "t", x, y, &series).unwrap();
        let decoded = image::open(&path).unwrap();
        assert_eq!((decoded.width(), decoded.height()), SIZE);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
