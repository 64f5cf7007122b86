//! `aloft mission`: fly a mission file (or the built-in demonstration) with a vehicle, a pack, a
//! payload and a wind; say what it costs, whether the reserve holds and where the point of no
//! return lies. `--replay` predicts a recorded flight instead (see `replay.rs`).

use std::io::Write;

use anyhow::{bail, Context, Result};

use aloft::engine::{plan_mission_with, Mission, MissionReport, Plan, Sample};

use super::mission_args::MissionArgs;
use super::mission_view::{
    header, mmss, plan_warnings, plot_over_track, segment_cells, summary_rows, write_model_line,
    write_segments_head, write_sorties, Area,
};
use super::output;
use super::plot::Line;
use super::{Format, Outcome};

pub fn run(mut args: MissionArgs) -> Result<Outcome> {
    if args.replay.is_some() {
        return super::replay::run(&args);
    }
    if args.format == Format::Csv {
        bail!("aloft mission writes table or json; use --timeseries for a CSV of samples");
    }
    // Every output checked before the flight is flown (the streamed ones again as they open).
    for path in [&args.plot, &args.timeseries, &args.mcap] {
        args.force.check(path.as_deref())?;
    }
    let flying = aloft::engine::load_flying(&args.flags.vehicle, &mut args.flags.battery)?;
    let options = flying.with_failsafes(args.flags.options());
    let vehicle = flying.vehicle;
    let mission = Mission::load(args.mission.as_deref())?;
    let plan = plan_mission_with(&vehicle, &mission, &options, &args.outputs())?;
    if let Some(sc) = args.scenarios.options(args.plot.is_some()) {
        let run = super::scenarios::MissionRun {
            vehicle: &vehicle,
            mission: &mission,
            options: &options,
            plan: &plan,
            plot: args.plot.as_deref().map(|p| args.force.chart(p)),
            format: args.format,
        };
        return super::scenarios::run_mission(&run, &sc);
    }
    if let Some(path) = &args.plot {
        let name = mission.spec().name.as_str();
        let power = |top: &Area<'_>| plot_power(top, name, plan.report(), plan.plot_samples());
        plot_over_track(args.force.chart(path), &plan, None, power)
            .with_context(|| format!("cannot draw {}", path.display()))?;
    }
    if args.format == Format::Json {
        output::warn(plan_warnings(&plan));
    }
    output::print_table_or_json(args.format, plan.summary(), |out| write_table(out, &plan))?;
    Ok(if plan.report().feasible {
        Outcome::Ok
    } else {
        Outcome::Failed
    })
}

/// When each voltage failsafe would trigger, one sentence each: "the low-voltage failsafe
/// (21.0 V) would trigger at 17:40, in segment 12".
fn failsafe_lines(s: &aloft::engine::MissionSummary) -> Vec<String> {
    s.failsafes
        .iter()
        .map(|f| {
            let name = format!("the {}-voltage failsafe ({:.1} V)", f.kind, f.voltage_v);
            match (f.time_s, f.segment) {
                (Some(t), Some(seg)) => {
                    let item = f.item.map(|i| format!(" (item {i})")).unwrap_or_default();
                    format!(
                        "{name} would trigger at {}, in segment {seg}{item}",
                        mmss(t)
                    )
                }
                _ => format!(
                    "{name} would not trigger: the lowest predicted voltage is {:.2} V",
                    s.min_voltage_v
                ),
            }
        })
        .collect()
}

/// The mission as a reader sees it: header, verdict, summary, segments, the model used.
fn write_table(out: &mut impl Write, plan: &Plan) -> Result<()> {
    out.write_all(header(plan)?.as_bytes())?;
    writeln!(out)?;
    output::write_table(out, "Summary", &summary_rows(plan.report()))?;
    writeln!(out)?;
    for line in failsafe_lines(plan.summary()) {
        writeln!(out, "{line}")?;
    }
    if !plan.summary().failsafes.is_empty() {
        writeln!(out)?;
    }
    write_segments(out, plan.report())?;
    writeln!(out)?;
    write_sorties(out, plan.summary())?;
    write_model_line(out, plan)
}

/// The segments; with the operator's item numbers when the mission came from a planner file.
fn write_segments(out: &mut impl Write, r: &MissionReport) -> Result<()> {
    // A column of the time lost at the edge of the envelope, when the wind or a limit slowed
    // any segment.
    let slowed = r.segments.iter().any(|s| s.edge.is_some());
    write_segments_head(
        out,
        r,
        format_args!(
            " {:>11} {:>11}{}",
            "peak power",
            "battery end",
            if slowed { "   time lost (limit)" } else { "" }
        ),
    )?;
    for s in &r.segments {
        let lost = match s.edge {
            Some(e) => format!("  {:>8.1} s ({})", s.time_lost_s, e.limit.name()),
            _ => String::new(),
        };
        writeln!(
            out,
            "{} {:>9.0} W {:>9.1} %{lost}",
            segment_cells(r, s),
            s.peak_power_w,
            s.end_soc * 100.0
        )?;
    }
    Ok(())
}

/// Power and state of charge against time (above the ground track).
fn plot_power(area: &Area<'_>, name: &str, report: &MissionReport, s: &[Sample]) -> Result<()> {
    use plotters::prelude::*;
    let t_max = s[s.len() - 1].time_s.max(1.0);
    let power = s.iter().map(|x| (x.time_s, x.power_w)).collect();
    let power = Line::with_headroom("power (W)", RED, power);
    let p_max = power.max;
    let mut chart = super::plot::dual_lines(
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
        super::plot::labelled_line(
            &mut chart,
            [(t, 0.0), (t, p_max)],
            style,
            "point of no return",
            BLACK,
        )?;
    }
    super::plot::legend(&mut chart, SeriesLabelPosition::LowerLeft)?;
    Ok(())
}
