//! The chart of a mission's answer: above, power and state of charge over time (or, with
//! scenarios, the state-of-charge fan with the plan's own line); below, the ground track with
//! home and the point of no return (and the one that holds with 95 % confidence). The shared
//! chart pieces are `plot.rs`.

use anyhow::{bail, Result};

use aloft::engine::{MissionReport, Plan, Sample, Uncertainty};

use super::mission_view::MissionView;
use super::plot::{self, labelled_line, ChartFile, Line};

type Area<'a> =
    plotters::drawing::DrawingArea<plotters::backend::SVGBackend<'a>, plotters::coord::Shift>;

/// Draw the mission's chart to `file`.
pub(super) fn draw(file: ChartFile<'_>, view: &MissionView<'_>) -> Result<()> {
    let (name, plan) = (view.name, view.plan);
    let confident = view.scenarios.and_then(|u| confident_point(plan, u));
    plot_over_track(file, plan, confident, |top| match view.scenarios {
        None => plot_power(top, name, plan.report(), plan.plot_samples()),
        Some(u) => plot_fan(top, name, plan, u),
    })
}

/// Where the plan stands (east, north) when the point of no return that holds with 95 %
/// confidence over the scenarios comes.
fn confident_point(plan: &Plan, u: &Uncertainty) -> Option<(f64, f64)> {
    let t_s = u.point_of_no_return_s.p5?;
    sample_at(plan.plot_samples(), t_s).map(|x| (x.east_m, x.north_m))
}

/// A mission's chart file: `upper` draws a chart over time in the upper half, the ground track
/// is below it (`confident`: see [`plot_track`]).
fn plot_over_track(
    file: ChartFile<'_>,
    plan: &Plan,
    confident: Option<(f64, f64)>,
    upper: impl FnOnce(&Area<'_>) -> Result<()>,
) -> Result<()> {
    let samples = plan.plot_samples();
    if samples.is_empty() {
        bail!("no samples to plot");
    }
    plot::svg_file(file, (1100, 800), |root| {
        let (top, bottom) = root.split_vertically(400);
        upper(&top)?;
        plot_track(&bottom, plan.report(), samples, plan.home_m(), confident)
    })
}

/// The ground track (equal scales) with home and the point of no return; with `confident`, also
/// the point of no return that holds with 95 % confidence over the scenarios (east, north).
fn plot_track(
    area: &Area<'_>,
    report: &MissionReport,
    s: &[Sample],
    home: [f64; 3],
    confident: Option<(f64, f64)>,
) -> Result<()> {
    use plotters::prelude::*;
    // Ground track, equal scales.
    let (mut e0, mut e1, mut n0, mut n1) = (home[0], home[0], home[1], home[1]);
    for x in s {
        e0 = e0.min(x.east_m);
        e1 = e1.max(x.east_m);
        n0 = n0.min(x.north_m);
        n1 = n1.max(x.north_m);
    }
    let span = (e1 - e0).max(n1 - n0).max(10.0) * 1.1;
    let (ec, nc) = (0.5 * (e0 + e1), 0.5 * (n0 + n1));
    let mut track = ChartBuilder::on(area)
        .caption("ground track (east, north in m)", ("sans-serif", 18))
        .margin(15)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(
            (ec - span * 0.7)..(ec + span * 0.7),
            (nc - span * 0.5)..(nc + span * 0.5),
        )?;
    track
        .configure_mesh()
        .x_desc("east (m)")
        .y_desc("north (m)")
        .draw()?;
    let points = s.iter().map(|x| (x.east_m, x.north_m));
    plot::labelled_line(&mut track, points, RED, "track", RED)?;
    track
        .draw_series([Circle::new((home[0], home[1]), 6, GREEN.filled())])?
        .label("home")
        .legend(|(x, y)| Circle::new((x + 10, y), 5, GREEN.filled()));
    if let Some(p) = report.point_of_no_return {
        track
            .draw_series([Cross::new(
                (p.position_m[0], p.position_m[1]),
                8,
                BLACK.stroke_width(3),
            )])?
            .label(match confident {
                Some(_) => "point of no return (plan)",
                None => "point of no return",
            })
            .legend(|(x, y)| Cross::new((x + 10, y), 5, BLACK.stroke_width(2)));
    }
    if let Some(at) = confident {
        let style = MAGENTA.stroke_width(3);
        track
            .draw_series([TriangleMarker::new(at, 9, style)])?
            .label("point of no return, 95 % confidence")
            .legend(move |(x, y)| TriangleMarker::new((x + 10, y), 6, style));
    }
    plot::legend(&mut track, SeriesLabelPosition::MiddleRight)
}

/// Power and state of charge against time (above the ground track).
fn plot_power(area: &Area<'_>, name: &str, report: &MissionReport, s: &[Sample]) -> Result<()> {
    use plotters::prelude::*;
    let t_max = s[s.len() - 1].time_s.max(1.0);
    let power = s.iter().map(|x| (x.time_s, x.power_w)).collect();
    let power = Line::with_headroom("power (W)", RED, power);
    let p_max = power.max;
    let mut chart = plot::dual_lines(
        area,
        format!("{name}: electrical power and state of charge"),
        (0.0..t_max, "time (s)"),
        power,
        Line {
            desc: "state of charge (%)",
            max: 100.0,
            color: BLUE,
            points: s.iter().map(|x| (x.time_s, x.soc * 100.0)).collect(),
        },
    )?;
    let floor = (report.empty_soc + report.required_reserve_soc) * 100.0;
    chart
        .draw_secondary_series(LineSeries::new(
            [(0.0, floor), (t_max, floor)],
            BLUE.mix(0.4),
        ))?
        .label("reserve floor")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLUE.mix(0.4)));
    if let Some(t) = report.point_of_no_return.map(|p| p.time_s) {
        let style = BLACK.stroke_width(2);
        plot::labelled_line(
            &mut chart,
            [(t, 0.0), (t, p_max)],
            style,
            "point of no return",
            BLACK,
        )?;
    }
    plot::legend(&mut chart, SeriesLabelPosition::LowerLeft)?;
    Ok(())
}
/// The state-of-charge fan over the scenarios' time (5th to 95th percentile, the median) with
/// the plan's own line, the reserve floor and the point of no return with 95 % confidence.
fn plot_fan(area: &Area<'_>, name: &str, plan: &Plan, u: &Uncertainty) -> Result<()> {
    use plotters::prelude::*;
    let s = plan.plot_samples();
    let fan = u.soc_fan.as_ref();
    let t_fan = fan.and_then(|f| f.time_s.last().copied()).unwrap_or(0.0);
    let t_max = s[s.len() - 1].time_s.max(t_fan).max(1.0);
    let mut chart = ChartBuilder::on(area)
        .caption(
            format!("{name}: state of charge over {} scenarios", u.samples),
            ("sans-serif", 20),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t_max, 0.0..100.0)?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc("state of charge (%)")
        .draw()?;
    if let Some(f) = fan {
        let upper = f.time_s.iter().zip(&f.p95).map(|(&t, &v)| (t, v * 100.0));
        let lower = f
            .time_s
            .iter()
            .zip(&f.p5)
            .rev()
            .map(|(&t, &v)| (t, v * 100.0));
        let band = BLUE.mix(0.2);
        chart
            .draw_series([Polygon::new(
                upper.chain(lower).collect::<Vec<_>>(),
                band.filled(),
            )])?
            .label("5th-95th percentile")
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 20, y + 5)], band.filled()));
        let median = f.time_s.iter().zip(&f.p50).map(|(&t, &v)| (t, v * 100.0));
        let style = BLUE.mix(0.6);
        labelled_line(&mut chart, median, style.stroke_width(1), "median", style)?;
    }
    let own = s.iter().map(|x| (x.time_s, x.soc * 100.0));
    labelled_line(&mut chart, own, BLUE.stroke_width(2), "plan", BLUE)?;
    let r = plan.report();
    let floor = (r.empty_soc + r.required_reserve_soc) * 100.0;
    let style = RED.mix(0.6);
    labelled_line(
        &mut chart,
        [(0.0, floor), (t_max, floor)],
        style,
        "reserve floor",
        style,
    )?;
    if let Some(t) = u.point_of_no_return_s.p5 {
        let line = [(t, 0.0), (t, 100.0)];
        let label = "point of no return, 95 % confidence";
        labelled_line(&mut chart, line, BLACK.stroke_width(2), label, BLACK)?;
    }
    plot::legend(&mut chart, SeriesLabelPosition::LowerLeft)
}

/// The plan's sample nearest to time `t_s`.
fn sample_at(s: &[Sample], t_s: f64) -> Option<&Sample> {
    let k = s.partition_point(|x| x.time_s < t_s);
    s.get(k.min(s.len().saturating_sub(1)))
}
