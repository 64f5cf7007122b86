//! The charts the subcommands share: two lines against one x axis, each on its own y axis
//! ([`dual_lines`]), and several labelled lines against one y axis ([`lines`]).

use std::path::Path;

use anyhow::Result;
use plotters::chart::{ChartContext, DualCoordChartContext};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

/// A chart with a primary (left) and a secondary (right) y axis.
pub type DualChart<'a, 'b> = DualCoordChartContext<
    'a,
    SVGBackend<'b>,
    Cartesian2d<RangedCoordf64, RangedCoordf64>,
    Cartesian2d<RangedCoordf64, RangedCoordf64>,
>;

/// A chart of one x and one y axis (the primary part of a [`DualChart`]).
pub type Chart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// One line of the chart with its axis: description, axis maximum, colour and points.
pub struct Line<'s> {
    pub desc: &'s str,
    pub max: f64,
    pub color: RGBColor,
    pub points: Vec<(f64, f64)>,
}

impl<'s> Line<'s> {
    /// A line whose axis runs a tenth and one unit above its highest point (from 0).
    pub fn with_headroom(desc: &'s str, color: RGBColor, points: Vec<(f64, f64)>) -> Self {
        let max = points.iter().map(|&(_, y)| y).fold(0.0, f64::max) * 1.1 + 1.0;
        Self {
            desc,
            max,
            color,
            points,
        }
    }
}

/// Draw `left` against the left axis and `right` against the right axis over `x` (its range and
/// description); y axes start at 0. Returns the chart so callers can add series before
/// [`legend`].
pub fn dual_lines<'a, 'b>(
    area: &'a DrawingArea<SVGBackend<'b>, Shift>,
    caption: String,
    x: (std::ops::Range<f64>, &str),
    left: Line<'_>,
    right: Line<'_>,
) -> Result<DualChart<'a, 'b>> {
    let (x_range, x_desc) = x;
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 20))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .right_y_label_area_size(60)
        .build_cartesian_2d(x_range.clone(), 0.0..left.max)?
        .set_secondary_coord(x_range, 0.0..right.max);
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(left.desc)
        .draw()?;
    chart.configure_secondary_axes().y_desc(right.desc).draw()?;
    let (lc, rc) = (left.color, right.color);
    labelled_line(&mut chart, left.points, lc, left.desc, lc)?;
    chart
        .draw_secondary_series(LineSeries::new(right.points, &rc))?
        .label(right.desc)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], rc));
    Ok(chart)
}

/// Where a chart goes: its file, and whether it may replace one (`--force`).
#[derive(Debug, Clone, Copy)]
pub struct ChartFile<'p> {
    pub path: &'p Path,
    pub force: bool,
}

/// Draw a picture of `size` pixels on white with `draw`, then write it to `file` in aloft's one
/// way ([`aloft::engine::write_output`]: never half-written, nothing replaced without
/// `--force`, never a device or a FIFO).
pub fn svg_file(
    file: ChartFile<'_>,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend<'_>, Shift>) -> Result<()>,
) -> Result<()> {
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
    }
    aloft::engine::write_output(file.path, text.as_bytes(), file.force)?;
    Ok(())
}

/// A chart file of [`dual_lines`] over the whole picture (`size` in pixels), the legend at the
/// middle right.
pub fn dual_lines_file(
    file: ChartFile<'_>,
    size: (u32, u32),
    caption: String,
    x: (std::ops::Range<f64>, &str),
    left: Line<'_>,
    right: Line<'_>,
) -> Result<()> {
    svg_file(file, size, |root| {
        let mut chart = dual_lines(root, caption, x, left, right)?;
        legend(&mut chart, SeriesLabelPosition::MiddleRight)
    })
}

/// Draw `points` as a line in `style`, with `label` in the legend beside a short stroke in `key`.
pub fn labelled_line(
    chart: &mut Chart<'_, '_>,
    points: impl IntoIterator<Item = (f64, f64)>,
    style: impl Into<ShapeStyle>,
    label: &str,
    key: impl Into<ShapeStyle>,
) -> Result<()> {
    let key = key.into();
    chart
        .draw_series(LineSeries::new(points, style))?
        .label(label)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], key));
    Ok(())
}

/// Draw the legend of a chart (or of a [`DualChart`], whose legend is its primary's) at
/// `position`, on a white background in a black frame.
pub fn legend<'a, 'b: 'a>(chart: &mut Chart<'a, 'b>, position: SeriesLabelPosition) -> Result<()> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}

/// One labelled line of [`lines`].
pub struct Series {
    pub label: String,
    pub color: RGBColor,
    pub points: Vec<(f64, f64)>,
}

/// The `k`-th colour of a chart with several lines of one kind (a colour-blind-safe set, then
/// again from the first).
pub fn color(k: usize) -> RGBColor {
    const COLORS: [RGBColor; 6] = [
        RGBColor(0, 114, 178),
        RGBColor(213, 94, 0),
        RGBColor(0, 158, 115),
        RGBColor(204, 121, 167),
        RGBColor(86, 180, 233),
        RGBColor(230, 159, 0),
    ];
    COLORS[k % COLORS.len()]
}

/// Draw each series as a line with its points marked, against one y axis from 0 (`y_desc`) over
/// `x` (its range and description), with a legend of the series' labels.
pub fn lines(
    area: &DrawingArea<SVGBackend<'_>, Shift>,
    caption: String,
    x: (std::ops::Range<f64>, &str),
    y_desc: &str,
    series: Vec<Series>,
) -> Result<()> {
    let (x_range, x_desc) = x;
    let y_max = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .fold(0.0, f64::max)
        * 1.1
        + 1e-9;
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 20))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(x_range, 0.0..y_max)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .draw()?;
    for s in series {
        let c = s.color;
        let style = c.stroke_width(2);
        labelled_line(&mut chart, s.points.clone(), style, &s.label, style)?;
        chart.draw_series(s.points.into_iter().map(|p| Circle::new(p, 3, c.filled())))?;
    }
    legend(&mut chart, SeriesLabelPosition::UpperRight)
}
