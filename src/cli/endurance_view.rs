//! The answer of `aloft endurance` (without a curve): hover and orbit endurance, best-endurance
//! and best-range speeds as a table, with the scenarios' bands when they were drawn
//! (`--samples N`); JSON with its `uncertainty`.

use std::io::Write;

use anyhow::Result;

use aloft::engine::{EnduranceSummary, EnduranceUncertainty};

use super::output::{self, percentiles, MaybeUncertain, Row};
use super::Format;

/// Print the answer on stdout in `format` (CSV is the table); `reserve_percent` is the reserve
/// the table's title names.
pub fn print(
    summary: &EnduranceSummary,
    scenarios: Option<&EnduranceUncertainty>,
    reserve_percent: f64,
    format: Format,
) -> Result<()> {
    let mut out = std::io::stdout().lock();
    if format == Format::Json {
        return output::write_json(&mut out, &MaybeUncertain::new(summary, scenarios));
    }
    write_table(&mut out, summary, reserve_percent)?;
    match scenarios {
        Some(u) => write_uncertainty(&mut out, u),
        None => Ok(()),
    }
}

/// The endurance figures under a title of the vehicle, pack, mass, wind, reserve and air; the
/// notes last.
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
