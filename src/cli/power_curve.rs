//! `aloft endurance --sweep-speed`: the engine's power curve (power, endurance and range against
//! airspeed in level flight) rendered as a table, CSV and a chart.

use std::io::Write;

use anyhow::{Context, Result};

use aloft::engine::{PowerCurve, SweepRow};

use super::output;
use super::plot::{ChartFile, Line};
use super::Format;

/// Draw the curve to `chart` when asked, then print it in `format` (the table names the course
/// `course_deg` the ground speeds and ranges are taken along).
pub fn render(
    curve: &PowerCurve,
    course_deg: f64,
    chart: Option<ChartFile<'_>>,
    format: Format,
) -> Result<()> {
    if let Some(file) = chart {
        plot(file, &curve.context.vehicle, &curve.rows)
            .with_context(|| format!("cannot draw {}", file.path.display()))?;
    }
    let mut out = std::io::stdout().lock();
    match format {
        Format::Json => output::write_json(&mut out, curve),
        Format::Csv => write_csv(out, &curve.rows),
        Format::Table => write_table(&mut out, curve, course_deg),
    }
}

/// One header and one row per airspeed (every number at full precision; empty where there is
/// no ground speed or range).
fn write_csv(out: impl Write, rows: &[SweepRow]) -> Result<()> {
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

/// The airspeeds' power, ground speed, endurance and range, under a title of the vehicle, pack,
/// mass, wind, course and air.
fn write_table(out: &mut impl Write, curve: &PowerCurve, course_deg: f64) -> Result<()> {
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

/// Electrical power (left axis) and endurance (right axis) against airspeed.
fn plot(file: ChartFile<'_>, name: &str, rows: &[SweepRow]) -> Result<()> {
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
