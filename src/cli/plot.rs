//! The chart the subcommands share: two lines against one x axis, each on its own y axis.

use anyhow::Result;
use plotters::chart::DualCoordChartContext;
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

/// One line of the chart with its axis: description, axis maximum, colour and points.
pub struct Line<'s> {
    pub desc: &'s str,
    pub max: f64,
    pub color: RGBColor,
    pub points: Vec<(f64, f64)>,
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
    chart
        .draw_series(LineSeries::new(left.points, &lc))?
        .label(left.desc)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], lc));
    chart
        .draw_secondary_series(LineSeries::new(right.points, &rc))?
        .label(right.desc)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], rc));
    Ok(chart)
}

/// Draw the legend of a chart from [`dual_lines`] at `position`.
pub fn legend<'a, 'b: 'a>(
    chart: &mut DualChart<'a, 'b>,
    position: SeriesLabelPosition,
) -> Result<()> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}
