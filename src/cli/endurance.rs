//! `aloft endurance`: hover endurance and power, best-endurance speed, best-range speed and range
//! along a course in wind, orbit endurance, the power curve (`--sweep-speed`) and endurance
//! against payload per pack (`--payload-sweep`, rendered in `payload_sweep.rs`).

use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::{ArgGroup, Args};

use aloft::engine::flags::EnduranceFlags;
use aloft::engine::{
    endurance, endurance_scenarios, payload_sweep, power_curve, EnduranceOptions, EnduranceSummary,
    EnduranceUncertainty, Error, PayloadSweep, PowerCurve, SweepRow, Vehicle,
};

use super::output::{self, percentiles, ForceFlag, Row};
use super::plot::{ChartFile, Line};
use super::{Format, Outcome};

#[derive(Debug, Args)]
#[command(group(ArgGroup::new("curve").args(["sweep_speed", "payload_sweep"])))]
pub struct EnduranceArgs {
    /// The engine's endurance options (vehicle, pack, payload, wind, queries, curves, scenarios).
    #[command(flatten)]
    flags: EnduranceFlags,
    /// With --sweep-speed or --payload-sweep: also draw the curves to this SVG.
    #[arg(long, value_name = "SVG", requires = "curve")]
    plot: Option<PathBuf>,
    #[command(flatten)]
    force: ForceFlag,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

pub fn run(mut args: EnduranceArgs) -> Result<Outcome> {
    args.force.check(args.plot.as_deref())?;
    let flying = aloft::engine::load_flying(&args.flags.vehicle, &mut args.flags.battery)?;
    let vehicle = flying.vehicle;
    let options = args.flags.options();
    if let Some(sweep) = &args.flags.payload_sweep {
        return run_payload_sweep(&args, &vehicle, &options, sweep);
    }
    if let Some(step) = args.flags.sweep_speed {
        let curve = power_curve(&vehicle, &options, step)?;
        if let Some(p) = &args.plot {
            plot_sweep(args.force.chart(p), &curve.context.vehicle, &curve.rows)
                .with_context(|| format!("cannot draw {}", p.display()))?;
        }
        output::print(
            args.format,
            &curve,
            |out| write_curve_csv(out, &curve.rows),
            |out| write_curve_table(out, &curve, args.flags.course),
        )?;
        return Ok(Outcome::Ok);
    }
    if args.format == Format::Csv {
        bail!("aloft endurance writes table or json (csv with --sweep-speed or --payload-sweep)");
    }
    let summary = endurance(&vehicle, &options)?;
    let uncertainty = match args.flags.scenarios.options(false) {
        Some(sc) => Some(endurance_scenarios(&vehicle, &options, &sc)?),
        None => None,
    };
    let answer = output::MaybeUncertain::new(&summary, uncertainty.as_ref());
    output::print_table_or_json(args.format, &answer, |out| {
        write_table(out, &summary, args.flags.reserve_percent)?;
        match &uncertainty {
            Some(u) => write_uncertainty(out, u),
            None => Ok(()),
        }
    })?;
    Ok(Outcome::Ok)
}

/// `--payload-sweep`: the engine's curve per pack, drawn when asked, then printed.
fn run_payload_sweep(
    args: &EnduranceArgs,
    vehicle: &Vehicle,
    options: &EnduranceOptions,
    sweep: &PayloadSweep,
) -> Result<Outcome> {
    let curve = payload_sweep(vehicle, options, sweep).map_err(|e| match e {
        // The one error that is the sweep's own: name the flag.
        e @ Error::SweepTooHeavy { .. } => {
            anyhow::Error::new(e).context(format!("--payload-sweep {sweep}"))
        }
        e => e.into(),
    })?;
    if let Some(p) = &args.plot {
        super::payload_sweep::plot(args.force.chart(p), &curve)
            .with_context(|| format!("cannot draw {}", p.display()))?;
    }
    output::print(
        args.format,
        &curve,
        |out| super::payload_sweep::write_csv(out, &curve),
        |out| super::payload_sweep::write_table(out, &curve),
    )?;
    Ok(Outcome::Ok)
}

fn write_curve_csv(out: impl Write, rows: &[SweepRow]) -> Result<()> {
    let header = [
        "airspeed_mps",
        "ground_speed_mps",
        "power_w",
        "endurance_s",
        "range_m",
    ];
    let opt = |v: Option<f64>| v.map(|x| x.to_string()).unwrap_or_default();
    let records = rows.iter().map(|r| {
        [
            r.airspeed_mps.to_string(),
            opt(r.ground_speed_mps),
            r.power_w.to_string(),
            r.endurance_s.to_string(),
            opt(r.range_m),
        ]
    });
    output::write_csv(out, &header, records)
}

fn write_curve_table(out: &mut impl Write, curve: &PowerCurve, course_deg: f64) -> Result<()> {
    let c = &curve.context;
    writeln!(
        out,
        "{} with {}, {}, wind {}, course {:.0} deg: power curve\nAir: {}",
        c.vehicle,
        c.battery,
        c.mass.describe(),
        c.wind,
        course_deg,
        c.air.describe()
    )?;
    for [v, g, p, e, r] in [
        ["airspeed", "ground", "power", "endurance", "range"],
        ["m/s", "m/s", "W", "min", "km"],
    ] {
        writeln!(out, "  {v:>9} {g:>9} {p:>9} {e:>10} {r:>9}")?;
    }
    for r in &curve.rows {
        let g = r
            .ground_speed_mps
            .map(|v| format!("{v:.1}"))
            .unwrap_or_else(|| "-".into());
        let rng = r
            .range_m
            .map(|v| format!("{:.2}", v / 1000.0))
            .unwrap_or_else(|| "-".into());
        writeln!(
            out,
            "  {:>9.1} {:>9} {:>9.0} {:>10.1} {:>9}",
            r.airspeed_mps,
            g,
            r.power_w,
            r.endurance_s / 60.0,
            rng
        )?;
    }
    Ok(())
}

fn write_table(out: &mut impl Write, s: &EnduranceSummary, reserve_percent: f64) -> Result<()> {
    let r = &s.report;
    let title = format!(
        "{} with {} ({} Wh), {}, wind {}, reserve {:.0} %\nAir: {}",
        s.vehicle,
        s.battery,
        s.context.battery_energy_wh,
        s.context.mass.describe(),
        s.context.wind,
        reserve_percent,
        s.air.describe()
    );
    let min = |s: f64| s / 60.0;
    let mut rows = output::num_rows(&[
        ("hover power", r.hover_power_w, 0, "W"),
        ("hover endurance", min(r.hover_endurance_s), 1, "min"),
        (
            "best-endurance airspeed",
            r.max_endurance_speed_mps,
            1,
            "m/s",
        ),
        ("  power there", r.max_endurance_power_w, 0, "W"),
        ("  endurance", min(r.max_endurance_s), 1, "min"),
        ("best-range airspeed", r.max_range_speed_mps, 1, "m/s"),
        (
            "  ground speed on course",
            r.max_range_ground_speed_mps,
            1,
            "m/s",
        ),
        ("  power there", r.max_range_power_w, 0, "W"),
        ("  range on course", r.max_range_m / 1000.0, 2, "km"),
    ]);
    if let (Some(p), Some(e)) = (r.orbit_power_w, r.orbit_endurance_s) {
        rows.extend(output::num_rows(&[
            ("orbit power", p, 0, "W"),
            ("orbit endurance", min(e), 1, "min"),
        ]));
    }
    output::write_table(out, &title, &rows)?;
    for n in &s.context.notes {
        writeln!(out, "  note: {n}")?;
    }
    Ok(())
}

/// The endurance table's lines for the scenarios (`--samples N`), after a blank line.
fn write_uncertainty(out: &mut impl Write, u: &EnduranceUncertainty) -> Result<()> {
    let s = &u.spreads;
    writeln!(
        out,
        "\nScenarios: {} (seed {}; wind speed sd {} m/s, wind direction sd {} deg, payload sd {} kg, capacity sd {} %, power sd {} %); the vehicle can fly {:.1} % of them.",
        u.samples,
        u.seed,
        s.wind_speed_sd_mps,
        s.wind_from_sd_deg,
        s.payload_sd_kg,
        s.capacity_sd_percent,
        s.power_sd_percent,
        u.p_feasible * 100.0
    )?;
    let min = |t: f64| format!("{:.1}", t / 60.0);
    let mut rows = vec![
        Row::new(
            "hover endurance",
            percentiles(u.hover_endurance_s, &min),
            "min",
        ),
        Row::new(
            "best endurance",
            percentiles(u.max_endurance_s, &min),
            "min",
        ),
        Row::new(
            "best range",
            percentiles(u.max_range_m, &|m| format!("{:.2}", m / 1000.0)),
            "km",
        ),
    ];
    if u.orbit_endurance_s.is_some() {
        rows.push(Row::new(
            "orbit endurance",
            percentiles(u.orbit_endurance_s, &min),
            "min",
        ));
    }
    output::write_table(out, "Uncertainty (5th percentile / median / 95th)", &rows)?;
    Ok(())
}

fn plot_sweep(file: ChartFile<'_>, name: &str, rows: &[SweepRow]) -> Result<()> {
    use plotters::prelude::*;
    let v_max = rows.last().map(|r| r.airspeed_mps).unwrap_or(1.0).max(1.0);
    let power = rows.iter().map(|r| (r.airspeed_mps, r.power_w)).collect();
    let endurance = rows.iter().map(|r| (r.airspeed_mps, r.endurance_s / 60.0));
    super::plot::dual_lines_file(
        file,
        (900, 500),
        format!("{name}: power curve (level flight, still air)"),
        (0.0..v_max, "airspeed (m/s)"),
        Line::with_headroom("electrical power (W)", RED, power),
        Line::with_headroom("endurance (min)", BLUE, endurance.collect()),
    )
}
