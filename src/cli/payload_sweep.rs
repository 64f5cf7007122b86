//! `aloft endurance --payload-sweep`: the engine's endurance against payload rendered as a table
//! per pack, CSV, and a chart with one curve per pack.

use std::io::Write;

use anyhow::{Context, Result};

use aloft::engine::{PayloadCurve, PayloadRow};

use super::output;
use super::plot::ChartFile;
use super::Format;

/// Draw the curve to `chart` when asked, then print it in `format`.
pub fn render(curve: &PayloadCurve, chart: Option<ChartFile<'_>>, format: Format) -> Result<()> {
    if let Some(file) = chart {
        plot(file, curve).with_context(|| format!("cannot draw {}", file.path.display()))?;
    }
    let mut out = std::io::stdout().lock();
    match format {
        Format::Json => output::write_json(&mut out, curve),
        Format::Csv => write_csv(out, curve),
        Format::Table => write_table(&mut out, curve),
    }
}

/// A block per pack: payload, take-off mass, hover power and endurance, best endurance and best
/// range; the notes (where a curve stops) last.
fn write_table(out: &mut impl Write, curve: &PayloadCurve) -> Result<()> {
    writeln!(
        out,
        "{}, wind {}, course {:.0} deg, reserve {:.0} %: endurance against payload (maximum take-off mass {:.3} kg)",
        curve.vehicle, curve.wind, curve.course_deg, curve.reserve_percent, curve.max_takeoff_mass_kg
    )?;
    let decimals = payload_decimals(curve);
    for pack in &curve.batteries {
        writeln!(out)?;
        writeln!(
            out,
            "{}: {} Wh, {:.3} kg, payload up to {:.3} kg",
            pack.name,
            pack.energy_wh,
            pack.mass_kg,
            pack.max_payload_kg.max(0.0)
        )?;
        writeln!(
            out,
            "  {:>9} {:>9} {:>7} {:>7}   {:>14}   {:>14}",
            "payload", "take-off", "hover", "hover", "best endurance", "best range"
        )?;
        writeln!(
            out,
            "  {:>9} {:>9} {:>7} {:>7}   {:>6} {:>7}   {:>6} {:>7}",
            "kg", "kg", "W", "min", "m/s", "min", "m/s", "km"
        )?;
        for r in curve.rows_of(&pack.name) {
            let e = &r.report;
            writeln!(
                out,
                "  {:>9.decimals$} {:>9.3} {:>7.0} {:>7.1}   {:>6.1} {:>7.1}   {:>6.1} {:>7.2}",
                r.payload_kg,
                r.takeoff_mass_kg,
                e.hover_power_w,
                e.hover_endurance_s / 60.0,
                e.max_endurance_speed_mps,
                e.max_endurance_s / 60.0,
                e.max_range_speed_mps,
                e.max_range_m / 1000.0
            )?;
        }
    }
    if !curve.notes.is_empty() {
        writeln!(out)?;
    }
    for n in &curve.notes {
        writeln!(out, "note: {n}")?;
    }
    Ok(())
}

/// The fewest decimals (2 to 6) that show every payload of the curve as it is.
fn payload_decimals(curve: &PayloadCurve) -> usize {
    (2..=6)
        .find(|&d| {
            curve.rows.iter().all(|r| {
                let shown: f64 = format!("{:.d$}", r.payload_kg).parse().unwrap_or(f64::NAN);
                // 1e-9 kg: far below any step a sweep is given in, far above the rounding.
                (shown - r.payload_kg).abs() <= 1e-9
            })
        })
        .unwrap_or(6)
}

/// One header and one row per pack and payload (every number at full precision). The notes go
/// to stderr: they are not data.
fn write_csv(out: impl Write, curve: &PayloadCurve) -> Result<()> {
    let orbit = curve
        .rows
        .iter()
        .any(|r| r.report.orbit_endurance_s.is_some());
    let mut header = vec![
        "battery",
        "payload_kg",
        "takeoff_mass_kg",
        "hover_power_w",
        "hover_endurance_s",
        "max_endurance_speed_mps",
        "max_endurance_power_w",
        "max_endurance_s",
        "max_range_speed_mps",
        "max_range_ground_speed_mps",
        "max_range_power_w",
        "max_range_m",
    ];
    if orbit {
        header.extend(["orbit_power_w", "orbit_endurance_s"]);
    }
    output::write_csv(
        out,
        &header,
        curve.rows.iter().map(|r| csv_record(r, orbit)),
    )?;
    for n in &curve.notes {
        eprintln!("aloft: note: {n}");
    }
    Ok(())
}

fn csv_record(r: &PayloadRow, orbit: bool) -> Vec<String> {
    let e = &r.report;
    let mut record = vec![r.battery.clone()];
    record.extend(
        [
            r.payload_kg,
            r.takeoff_mass_kg,
            e.hover_power_w,
            e.hover_endurance_s,
            e.max_endurance_speed_mps,
            e.max_endurance_power_w,
            e.max_endurance_s,
            e.max_range_speed_mps,
            e.max_range_ground_speed_mps,
            e.max_range_power_w,
            e.max_range_m,
        ]
        .map(|v| v.to_string()),
    );
    if orbit {
        let opt = |v: Option<f64>| v.map(|x| x.to_string()).unwrap_or_default();
        record.push(opt(e.orbit_power_w));
        record.push(opt(e.orbit_endurance_s));
    }
    record
}

/// Hover endurance (min) above and best range (km) below, against payload (kg), one line per
/// pack: the chart manufacturers print.
fn plot(file: ChartFile<'_>, curve: &PayloadCurve) -> Result<()> {
    super::plot::svg_file(file, (900, 800), |root| plot_on(root, curve))
}

/// [`plot`] on a picture.
fn plot_on(
    root: &plotters::drawing::DrawingArea<
        plotters::prelude::SVGBackend<'_>,
        plotters::coord::Shift,
    >,
    curve: &PayloadCurve,
) -> Result<()> {
    let (top, bottom) = root.split_vertically(400);
    let (lo, hi) = curve
        .rows
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), r| {
            (lo.min(r.payload_kg), hi.max(r.payload_kg))
        });
    let x = if hi > lo { lo..hi } else { lo..lo + 1.0 };
    let series = |y: fn(&PayloadRow) -> f64| -> Vec<super::plot::Series> {
        curve
            .batteries
            .iter()
            .enumerate()
            .map(|(k, pack)| super::plot::Series {
                label: pack.name.clone(),
                color: super::plot::color(k),
                points: curve
                    .rows_of(&pack.name)
                    .map(|r| (r.payload_kg, y(r)))
                    .collect(),
            })
            .collect()
    };
    super::plot::lines(
        &top,
        format!(
            "{}: hover endurance against payload ({})",
            curve.vehicle, curve.wind
        ),
        (x.clone(), "payload (kg)"),
        "hover endurance (min)",
        series(|r| r.report.hover_endurance_s / 60.0),
    )?;
    super::plot::lines(
        &bottom,
        format!(
            "{}: best range against payload (course {:.0} deg)",
            curve.vehicle, curve.course_deg
        ),
        (x, "payload (kg)"),
        "best range (km)",
        series(|r| r.report.max_range_m / 1000.0),
    )?;
    Ok(())
}
