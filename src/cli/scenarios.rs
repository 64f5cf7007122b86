//! `--samples N`: Monte-Carlo scenarios of `aloft mission` and `aloft endurance` (the engine's
//! `plan_scenarios` and `endurance_scenarios`), rendered as a line, bands in the tables, the JSON
//! `uncertainty` object and, for a mission, a state-of-charge fan in the chart.

use std::io::Write;

use anyhow::{Context, Result};

use aloft::engine::{
    plan_scenarios, EnduranceUncertainty, Mission, MissionOptions, MissionWithUncertainty,
    Percentiles, Plan, Sample, ScenarioOptions, Uncertainty, Vehicle,
};

use super::mission_view::{self, mmss};
use super::output::{self, Row};
use super::plot::{labelled_line, ChartFile};
use super::{Format, Outcome};

/// What a mission's scenarios are drawn around and rendered with.
pub struct MissionRun<'a> {
    pub vehicle: &'a Vehicle,
    pub mission: &'a Mission,
    pub options: &'a MissionOptions,
    pub plan: &'a Plan,
    pub plot: Option<ChartFile<'a>>,
    pub format: Format,
}

/// Draw the scenarios of a planned mission and print the plan with its uncertainty. The exit
/// code is the plan's (1 when the plan itself is infeasible).
pub fn run_mission(run: &MissionRun<'_>, sc: &ScenarioOptions) -> Result<Outcome> {
    let u = plan_scenarios(run.vehicle, run.mission, run.options, sc)?;
    let plan = run.plan;
    if let Some(file) = run.plot {
        let name = run.mission.spec().name.as_str();
        plot(file, name, plan, &u)
            .with_context(|| format!("cannot draw {}", file.path.display()))?;
    }
    if run.format == Format::Json {
        output::warn(mission_view::plan_warnings(plan));
    }
    let answer = MissionWithUncertainty {
        summary: plan.summary(),
        uncertainty: &u,
    };
    output::print_table_or_json(run.format, &answer, |out| {
        write_mission_table(out, plan, &u)
    })?;
    Ok(if plan.report().feasible {
        Outcome::Ok
    } else {
        Outcome::Failed
    })
}

/// The mission's table with the scenarios' line, bands and segment columns.
fn write_mission_table(out: &mut impl Write, plan: &Plan, u: &Uncertainty) -> Result<()> {
    out.write_all(mission_view::header(plan)?.as_bytes())?;
    out.write_all(verdict(plan, u).as_bytes())?;
    writeln!(out)?;
    output::write_table(out, "Summary", &mission_view::summary_rows(plan.report()))?;
    writeln!(out)?;
    output::write_table(
        out,
        &format!(
            "Uncertainty (5th percentile / median / 95th; energy, battery and time over the {} of {} scenarios that flew the whole route)",
            u.completed_scenarios, u.samples
        ),
        &band_rows(u),
    )?;
    writeln!(out)?;
    write_segments(out, plan, u)?;
    writeln!(out)?;
    mission_view::write_sorties(out, plan.summary())?;
    mission_view::write_model_line(out, plan)
}

/// The drawn spreads in words.
fn spreads_text(u: &Uncertainty) -> String {
    let s = &u.spreads;
    format!(
        "seed {}; wind speed sd {} m/s, wind direction sd {} deg, payload sd {} kg, capacity sd {} %, power sd {} %",
        u.seed,
        s.wind_speed_sd_mps,
        s.wind_from_sd_deg,
        s.payload_sd_kg,
        s.capacity_sd_percent,
        s.power_sd_percent
    )
}

/// The scenarios in two sentences: how often the reserve holds, and the point of no return with
/// 95 % confidence.
fn verdict(plan: &Plan, u: &Uncertainty) -> String {
    let mut text = format!(
        "Scenarios: lands with the reserve in {:.1} % of {} scenarios ({}).\n",
        u.p_feasible * 100.0,
        u.samples,
        spreads_text(u)
    );
    if let Some(why) = &u.cannot_fly_reason {
        text.push_str(&format!(
            "  {} of them cannot be flown (their flight ends where the vehicle cannot make headway or hold its position, or it cannot take off); the first: {why}.\n",
            u.cannot_fly_scenarios
        ));
    }
    let ended_early = u.samples - u.completed_scenarios;
    if ended_early > u.cannot_fly_scenarios {
        text.push_str(&format!(
            "  {} run out of charge on the way (below the empty point or the cut-off voltage).\n",
            ended_early - u.cannot_fly_scenarios
        ));
    }
    match u.point_of_no_return_s.p5 {
        Some(t) if t <= 0.0 => text.push_str(&format!(
            "Point of no return with 95 % confidence: at take-off: in more than 5 % of the scenarios the vehicle cannot fly the route ({:.1} % do not complete it) or cannot turn back from its start.\n",
            (1.0 - u.completed_scenarios as f64 / u.samples as f64) * 100.0
        )),
        Some(t) => {
            let (segment, item) = segment_at(plan, t);
            let item = item.map_or(String::new(), |i| format!(" (item {i})"));
            text.push_str(&format!(
                "Point of no return with 95 % confidence: {} into the flight (t = {t:.0} s), segment {segment}{item}: 95 % of the scenarios can still turn back until then.\n",
                mmss(t)
            ));
        }
        None => text.push_str(&format!(
            "Point of no return with 95 % confidence: none; {:.1} % of the scenarios could fly straight home from every point of the route.\n",
            (1.0 - u.p_point_of_no_return) * 100.0
        )),
    }
    text
}

/// The segment (and operator's item) the plan flies at time `t_s`.
fn segment_at(plan: &Plan, t_s: f64) -> (usize, Option<u32>) {
    let mut end = 0.0;
    let segments = &plan.report().segments;
    for s in segments {
        end += s.duration_s;
        if t_s <= end {
            return (s.index, s.item);
        }
    }
    segments.last().map_or((1, None), |s| (s.index, s.item))
}

fn band_rows(u: &Uncertainty) -> Vec<Row<'static>> {
    let three = |p: Option<Percentiles>, f: &dyn Fn(f64) -> String| {
        p.map_or("-".to_string(), |p| {
            format!("{} / {} / {}", f(p.p5), f(p.p50), f(p.p95))
        })
    };
    let t = u.point_of_no_return_s;
    let pnr = |v: Option<f64>| v.map_or("none".to_string(), mmss);
    vec![
        Row::new(
            "energy used",
            three(u.energy_wh, &|x| format!("{x:.1}")),
            "Wh",
        ),
        Row::new(
            "battery at the end",
            three(u.end_soc, &|x| format!("{:.1}", x * 100.0)),
            "%",
        ),
        Row::new("flight time", three(u.duration_s, &mmss), "min:s"),
        Row::new(
            "point of no return",
            format!("{} / {} / {}", pnr(t.p5), pnr(t.p50), pnr(t.p95)),
            "min:s",
        ),
    ]
}

/// The segments with the 5th and 95th percentiles of the battery at each segment's end.
fn write_segments(out: &mut impl Write, plan: &Plan, u: &Uncertainty) -> Result<()> {
    let r = plan.report();
    mission_view::write_segments_head(
        out,
        r,
        format_args!(" {:>11} {:>9} {:>9}", "battery end", "p5 end", "p95 end"),
    )?;
    for s in &r.segments {
        let band = u.segments.iter().find(|b| b.index == s.index);
        let pct = |v: Option<f64>| v.map_or("-".to_string(), |x| format!("{:.1} %", x * 100.0));
        writeln!(
            out,
            "{} {:>9.1} % {:>9} {:>9}",
            mission_view::segment_cells(r, s),
            s.end_soc * 100.0,
            pct(band.map(|b| b.end_soc.p5)),
            pct(band.map(|b| b.end_soc.p95)),
        )?;
    }
    Ok(())
}

use super::mission_view::Area;

/// The state-of-charge fan over time (the plan's own line in it) and the ground track with the
/// plan's point of no return and the one that holds with 95 % confidence.
fn plot(file: ChartFile<'_>, name: &str, plan: &Plan, u: &Uncertainty) -> Result<()> {
    let confident = u
        .point_of_no_return_s
        .p5
        .and_then(|t| sample_at(plan.plot_samples(), t))
        .map(|x| (x.east_m, x.north_m));
    mission_view::plot_over_track(file, plan, confident, |top| plot_fan(top, name, plan, u))
}

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
    super::plot::legend(&mut chart, SeriesLabelPosition::LowerLeft)
}

/// The plan's sample nearest to time `t_s`.
fn sample_at(s: &[Sample], t_s: f64) -> Option<&Sample> {
    let k = s.partition_point(|x| x.time_s < t_s);
    s.get(k.min(s.len().saturating_sub(1)))
}

/// The endurance table's lines for the scenarios.
pub fn write_endurance_lines(out: &mut impl Write, u: &EnduranceUncertainty) -> Result<()> {
    let s = &u.spreads;
    writeln!(
        out,
        "Scenarios: {} (seed {}; wind speed sd {} m/s, wind direction sd {} deg, payload sd {} kg, capacity sd {} %, power sd {} %); the vehicle can fly {:.1} % of them.",
        u.samples,
        u.seed,
        s.wind_speed_sd_mps,
        s.wind_from_sd_deg,
        s.payload_sd_kg,
        s.capacity_sd_percent,
        s.power_sd_percent,
        u.p_feasible * 100.0
    )?;
    let three = |p: Option<Percentiles>, f: &dyn Fn(f64) -> String| {
        p.map_or("-".to_string(), |p| {
            format!("{} / {} / {}", f(p.p5), f(p.p50), f(p.p95))
        })
    };
    let min = |t: f64| format!("{:.1}", t / 60.0);
    let mut rows = vec![
        Row::new("hover endurance", three(u.hover_endurance_s, &min), "min"),
        Row::new("best endurance", three(u.max_endurance_s, &min), "min"),
        Row::new(
            "best range",
            three(u.max_range_m, &|m| format!("{:.2}", m / 1000.0)),
            "km",
        ),
    ];
    if u.orbit_endurance_s.is_some() {
        rows.push(Row::new(
            "orbit endurance",
            three(u.orbit_endurance_s, &min),
            "min",
        ));
    }
    output::write_table(out, "Uncertainty (5th percentile / median / 95th)", &rows)?;
    Ok(())
}
