//! Line charts as SVG (plotters' SVG backend: no system libraries), for the work–precision
//! and spectral figures.

use plotters::prelude::*;
use std::path::Path;

/// One line of a chart: its legend and its points (x, y); points with a non-finite or, on a
/// logarithmic axis, non-positive coordinate are left out.
#[derive(Clone, Debug, Default)]
pub struct Series {
    pub name: String,
    pub points: Vec<(f64, f64)>,
}

/// A chart: title, axis labels and scales.
#[derive(Clone, Debug)]
pub struct Chart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub log_x: bool,
    pub log_y: bool,
    /// width and height in pixels
    pub size: (u32, u32),
    /// where the legend goes (inside the plot area)
    pub legend: Legend,
}

/// A corner of the plot area for the legend.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Legend {
    #[default]
    UpperRight,
    UpperLeft,
    LowerLeft,
    LowerRight,
}

impl Default for Chart {
    fn default() -> Self {
        Chart {
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            log_x: true,
            log_y: true,
            size: (900, 600),
            legend: Legend::UpperRight,
        }
    }
}

impl Series {
    /// A line named `name` through `points`.
    pub fn new(name: impl Into<String>, points: Vec<(f64, f64)>) -> Series {
        Series {
            name: name.into(),
            points,
        }
    }
}

impl Chart {
    /// A chart with linear axes (the default's are logarithmic, for work–precision).
    pub fn linear(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Chart {
        Chart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            log_x: false,
            log_y: false,
            ..Chart::default()
        }
    }
}

/// Why a chart could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    #[error("nothing to plot: every series is empty (or has no point valid on a log axis)")]
    Empty,
    #[error("drawing the chart failed: {0}")]
    Draw(String),
    #[error(
        "values from {lo:e} to {hi:e} span more than an axis can draw (its range, widened, leaves f64): scale them"
    )]
    Range { lo: f64, hi: f64 },
}

fn kept(c: &Chart, p: (f64, f64)) -> bool {
    p.0.is_finite() && p.1.is_finite() && (!c.log_x || p.0 > 0.0) && (!c.log_y || p.1 > 0.0)
}

/// The range of the kept values along one axis, widened a little (by a factor on a log axis),
/// or an error when it cannot be drawn: bounds beyond f64 once widened (plotting code then
/// looks for tick marks without end).
fn range(values: impl Iterator<Item = f64>, log: bool) -> Result<(f64, f64), PlotError> {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let (a, b) = if log {
        let (lo, hi) = if lo == hi {
            (lo / 2.0, hi * 2.0)
        } else {
            (lo, hi)
        };
        (lo / 1.5, hi * 1.5)
    } else {
        // a width below the values' resolution is no width: pad by their size
        let size = lo.abs().max(hi.abs());
        let width = hi - lo;
        let pad = if width > 1e-12 * size {
            0.05 * width
        } else {
            (0.05 * size).max(1.0)
        };
        (lo - pad, hi + pad)
    };
    if a.is_finite() && b.is_finite() && a < b && (b - a).is_finite() && (!log || a > 0.0) {
        Ok((a, b))
    } else {
        Err(PlotError::Range { lo, hi })
    }
}

/// A convergence curve: after each evaluation (x = 1, 2, …), the best of the costs in `log` so
/// far.
pub fn best_so_far(log: &[f64]) -> Vec<(f64, f64)> {
    let mut best = f64::INFINITY;
    log.iter()
        .enumerate()
        .map(|(i, &c)| {
            best = best.min(c);
            ((i + 1) as f64, best)
        })
        .collect()
}

/// Draws `series` as lines with markers into an SVG file at `path`.
pub fn line_chart(path: &Path, chart: &Chart, series: &[Series]) -> Result<(), PlotError> {
    let svg = line_chart_svg(chart, series)?;
    std::fs::write(path, svg).map_err(|e| PlotError::Draw(format!("{}: {e}", path.display())))
}

/// The SVG text of [`line_chart`].
pub fn line_chart_svg(chart: &Chart, series: &[Series]) -> Result<String, PlotError> {
    let pts = || {
        series
            .iter()
            .flat_map(|s| s.points.iter().copied())
            .filter(|&p| kept(chart, p))
    };
    if pts().next().is_none() {
        return Err(PlotError::Empty);
    }
    let (x0, x1) = range(pts().map(|p| p.0), chart.log_x)?;
    let (y0, y1) = range(pts().map(|p| p.1), chart.log_y)?;
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, chart.size).into_drawing_area();
        draw(&root, chart, series, (x0, x1), (y0, y1)).map_err(PlotError::Draw)?;
        root.present().map_err(|e| PlotError::Draw(e.to_string()))?;
    }
    Ok(out)
}

/// Points drawn per series at most: longer series are thinned evenly (first and last kept),
/// which a chart of a few hundred pixels cannot tell apart.
const MAX_POINTS: usize = 1500;

fn thin(points: Vec<(f64, f64)>, max: usize) -> Vec<(f64, f64)> {
    if points.len() <= max {
        return points;
    }
    let last = points.len() - 1;
    (0..max).map(|k| points[k * last / (max - 1)]).collect()
}

/// A tick label: 1e-6, 0.25, 40, 3e5.
fn tick(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".into()
    } else if !(1e-2..1e4).contains(&a) {
        let s = format!("{v:.1e}");
        s.replace(".0e", "e")
    } else {
        let s = format!("{v:.3}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        s.to_string()
    }
}

const COLORS: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    chart: &Chart,
    series: &[Series],
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(err)?;
    let mut builder = ChartBuilder::on(root);
    builder
        .caption(&chart.title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70);
    macro_rules! body {
        ($ctx:expr) => {{
            let mut ctx = $ctx;
            ctx.configure_mesh()
                .x_desc(chart.x_label.as_str())
                .y_desc(chart.y_label.as_str())
                .x_label_formatter(&|v| tick(*v))
                .y_label_formatter(&|v| tick(*v))
                .draw()
                .map_err(err)?;
            for (i, s) in series.iter().enumerate() {
                let color = COLORS[i % COLORS.len()];
                let points = thin(
                    s.points
                        .iter()
                        .copied()
                        .filter(|&p| kept(chart, p))
                        .collect(),
                    MAX_POINTS,
                );
                ctx.draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))
                    .map_err(err)?
                    .label(s.name.as_str())
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2))
                    });
                // markers only where they stay distinct
                if points.len() <= 60 {
                    ctx.draw_series(
                        points
                            .into_iter()
                            .map(|p| Circle::new(p, 3, color.filled())),
                    )
                    .map_err(err)?;
                }
            }
            ctx.configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .position(match chart.legend {
                    Legend::UpperRight => SeriesLabelPosition::UpperRight,
                    Legend::UpperLeft => SeriesLabelPosition::UpperLeft,
                    Legend::LowerLeft => SeriesLabelPosition::LowerLeft,
                    Legend::LowerRight => SeriesLabelPosition::LowerRight,
                })
                .draw()
                .map_err(err)?;
        }};
    }
    match (chart.log_x, chart.log_y) {
        (true, true) => body!(
            builder
                .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
                .map_err(err)?
        ),
        (true, false) => body!(
            builder
                .build_cartesian_2d((x0..x1).log_scale(), y0..y1)
                .map_err(err)?
        ),
        (false, true) => body!(
            builder
                .build_cartesian_2d(x0..x1, (y0..y1).log_scale())
                .map_err(err)?
        ),
        (false, false) => body!(builder.build_cartesian_2d(x0..x1, y0..y1).map_err(err)?),
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_lines_and_refuses_nothing_to_plot() {
        let c = Chart {
            title: "t".into(),
            ..Chart::default()
        };
        let s = [
            Series {
                name: "a".into(),
                points: vec![(1e-3, 1e-2), (1e-2, 1e-4), (0.0, 1.0), (1e-1, f64::NAN)],
            },
            Series {
                name: "b".into(),
                points: vec![(2e-3, 1e-3), (3e-2, 1e-6)],
            },
        ];
        let svg = line_chart_svg(&c, &s).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("\na\n") && svg.contains("\nb\n"));
        assert!(svg.contains("\n1e-6\n") && !svg.contains("9.99999"));
        assert_eq!(
            (tick(0.25), tick(40.0), tick(3e5), tick(0.0)),
            ("0.25".into(), "40".into(), "3e5".into(), "0".into())
        );
        let empty = [Series {
            name: "x".into(),
            points: vec![(0.0, 1.0)],
        }];
        assert!(matches!(line_chart_svg(&c, &empty), Err(PlotError::Empty)));
    }

    /// Values whose widened range leaves f64 are a typed error (the plotting code looked for
    /// tick marks without end on them); values of one size far from 1, or a span below
    /// their resolution, still draw.
    #[test]
    fn ranges_beyond_f64_are_refused_and_narrow_ones_drawn() {
        let lin = Chart::linear("t", "x", "y");
        let series = |points: Vec<(f64, f64)>| {
            [Series {
                name: "a".into(),
                points,
            }]
        };
        for (chart, points) in [
            (&lin, vec![(0.0, 0.0), (1.0, 1.75e308)]),
            (&lin, vec![(0.0, -1e308), (1.0, 1e308)]),
            (&Chart::default(), vec![(1.0, 1.0), (2.0, 1.5e308)]),
            (&Chart::default(), vec![(1.0, 7e307)]),
        ] {
            let e = line_chart_svg(chart, &series(points.clone())).unwrap_err();
            assert!(matches!(e, PlotError::Range { .. }), "{points:?}: {e}");
        }
        for points in [
            vec![(0.0, 1e300), (1.0, 1e300)],
            vec![(0.0, 1.0), (1.0, 1.0 + 1e-15)],
            vec![(0.0, 3e-320), (1.0, 5e-320)],
        ] {
            let svg = line_chart_svg(&lin, &series(points.clone()));
            assert!(svg.is_ok(), "{points:?}: {svg:?}");
        }
    }
}
