//! `aloft endurance`: hover endurance and power, best-endurance speed, best-range speed and range
//! along a course in wind, orbit endurance, and the power curve (`--sweep-speed`).

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;
use serde::Serialize;

use aloft::power::ModelOptions;
use aloft_planner::{endurance, sweep_speed, EnduranceQuery, SweepRow};

use super::mission::{AoaArg, WindArgs};
use super::output::{self, Row};
use super::{load_vehicle, Format, Outcome, DEFAULT_VEHICLE_ARG};

#[derive(Debug, Args)]
pub struct EnduranceArgs {
    /// Vehicle: a built-in name (see `aloft vehicles`) or a vehicle TOML file.
    #[arg(long, default_value = DEFAULT_VEHICLE_ARG)]
    vehicle: String,
    /// Battery pack by name (default: the vehicle's default pack).
    #[arg(long)]
    battery: Option<String>,
    /// Payload, kg.
    #[arg(long, default_value_t = 0.0, value_name = "KG")]
    payload_kg: f64,
    #[command(flatten)]
    wind: WindArgs,
    /// Course of the range query, degrees clockwise from north.
    #[arg(
        long,
        default_value_t = 0.0,
        value_name = "DEG",
        allow_negative_numbers = true
    )]
    course: f64,
    /// Reserve kept, percent of the usable capacity.
    #[arg(long, default_value_t = 0.0, value_name = "PERCENT")]
    reserve_percent: f64,
    /// Orbit radius for the orbit-endurance query, m.
    #[arg(long, value_name = "M", requires = "orbit_speed")]
    orbit_radius: Option<f64>,
    /// Orbit ground speed, m/s.
    #[arg(long, value_name = "M/S", requires = "orbit_radius")]
    orbit_speed: Option<f64>,
    /// Angle-of-attack model of the power model.
    #[arg(long, value_enum, default_value_t = AoaArg::Geometric)]
    aoa: AoaArg,
    /// The power curve instead: power, endurance and range against airspeed, in steps of this
    /// many m/s up to the vehicle's maximum speed.
    #[arg(long, value_name = "STEP_M/S")]
    sweep_speed: Option<f64>,
    /// With --sweep-speed: also draw the curve to this SVG.
    #[arg(long, value_name = "SVG", requires = "sweep_speed")]
    plot: Option<PathBuf>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

#[derive(Serialize)]
struct EnduranceJson<'a> {
    vehicle: &'a str,
    battery: &'a str,
    takeoff_mass_kg: f64,
    #[serde(flatten)]
    report: aloft_planner::EnduranceReport,
}

pub fn run(args: EnduranceArgs) -> Result<Outcome> {
    let file = load_vehicle(&args.vehicle)?;
    let (aircraft, notes) = file.aircraft(ModelOptions::default())?;
    let battery = file.battery(args.battery.as_deref())?;
    if !(args.payload_kg.is_finite() && args.payload_kg >= 0.0) {
        bail!(
            "--payload-kg {}: expected a mass, not negative",
            args.payload_kg
        );
    }
    let mass = aircraft.airframe().mass_kg() + battery.mass_kg() + args.payload_kg;
    if mass > aircraft.airframe().max_takeoff_mass_kg() {
        bail!(
            "take-off mass {mass:.3} kg (airframe + {} + payload) exceeds the vehicle's {:.3} kg limit",
            battery.name(),
            aircraft.airframe().max_takeoff_mass_kg()
        );
    }
    let powered = aircraft.at_mass(mass, args.aoa.model())?;
    let (wind, wind_text) = args.wind.build(None)?;
    if args.wind.wind_field.is_some() || args.wind.gust_std.is_some() {
        bail!("aloft endurance takes a constant wind (--wind-speed, --wind-from); a field or gusts belong to a mission");
    }
    if !(0.0..100.0).contains(&args.reserve_percent) {
        bail!(
            "--reserve-percent {}: expected [0, 100)",
            args.reserve_percent
        );
    }
    // The wind at 10 m stands for the query's wind (a profile is evaluated there).
    let w = wind.mean_at([0.0, 0.0, 10.0]).unwrap_or([0.0; 3]);
    let c = args.course.to_radians();
    let query = EnduranceQuery {
        wind_mps: [w[0], w[1]],
        course: [c.sin(), c.cos()],
        start_soc: 1.0,
        reserve_fraction: args.reserve_percent / 100.0,
        orbit: args.orbit_radius.zip(args.orbit_speed),
    };
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    if let Some(step) = args.sweep_speed {
        let vmax = aircraft.airframe().max_speed_mps();
        let rows = sweep_speed(&powered, &battery, &query, vmax, step)?;
        if let Some(p) = &args.plot {
            plot_sweep(p, &file.name, &rows)
                .with_context(|| format!("cannot draw {}", p.display()))?;
        }
        match args.format {
            Format::Json => output::write_json(&mut out, &rows)?,
            Format::Csv => {
                let mut w = csv::Writer::from_writer(out);
                w.write_record([
                    "airspeed_mps",
                    "ground_speed_mps",
                    "power_w",
                    "endurance_s",
                    "range_m",
                ])?;
                for r in &rows {
                    let opt = |v: Option<f64>| v.map(|x| x.to_string()).unwrap_or_default();
                    w.write_record([
                        r.airspeed_mps.to_string(),
                        opt(r.ground_speed_mps),
                        r.power_w.to_string(),
                        r.endurance_s.to_string(),
                        opt(r.range_m),
                    ])?;
                }
                w.flush()?;
            }
            Format::Table => {
                writeln!(
                    out,
                    "{} with {}, {:.3} kg, wind {wind_text}, course {:.0} deg: power curve",
                    file.name,
                    battery.name(),
                    mass,
                    args.course
                )?;
                writeln!(
                    out,
                    "  {:>9} {:>9} {:>9} {:>10} {:>9}",
                    "airspeed", "ground", "power", "endurance", "range"
                )?;
                writeln!(
                    out,
                    "  {:>9} {:>9} {:>9} {:>10} {:>9}",
                    "m/s", "m/s", "W", "min", "km"
                )?;
                for r in &rows {
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
            }
        }
        return Ok(Outcome::Ok);
    }
    let r = endurance(&powered, &battery, &query)?;
    match args.format {
        Format::Json => output::write_json(
            &mut out,
            &EnduranceJson {
                vehicle: &file.name,
                battery: battery.name(),
                takeoff_mass_kg: mass,
                report: r,
            },
        )?,
        Format::Csv => bail!("aloft endurance writes table or json (csv with --sweep-speed)"),
        Format::Table => {
            let title = format!(
                "{} with {} ({} Wh), take-off mass {:.3} kg, wind {wind_text}, reserve {:.0} %",
                file.name,
                battery.name(),
                battery.rated_energy_wh(),
                mass,
                args.reserve_percent
            );
            let min = |s: f64| format!("{:.1}", s / 60.0);
            let mut rows = vec![
                Row::new("hover power", format!("{:.0}", r.hover_power_w), "W"),
                Row::new("hover endurance", min(r.hover_endurance_s), "min"),
                Row::new(
                    "best-endurance airspeed",
                    format!("{:.1}", r.max_endurance_speed_mps),
                    "m/s",
                ),
                Row::new(
                    "  power there",
                    format!("{:.0}", r.max_endurance_power_w),
                    "W",
                ),
                Row::new("  endurance", min(r.max_endurance_s), "min"),
                Row::new(
                    "best-range airspeed",
                    format!("{:.1}", r.max_range_speed_mps),
                    "m/s",
                ),
                Row::new(
                    "  ground speed on course",
                    format!("{:.1}", r.max_range_ground_speed_mps),
                    "m/s",
                ),
                Row::new("  power there", format!("{:.0}", r.max_range_power_w), "W"),
                Row::new(
                    "  range on course",
                    format!("{:.2}", r.max_range_m / 1000.0),
                    "km",
                ),
            ];
            if let (Some(p), Some(e)) = (r.orbit_power_w, r.orbit_endurance_s) {
                rows.push(Row::new("orbit power", format!("{p:.0}"), "W"));
                rows.push(Row::new("orbit endurance", min(e), "min"));
            }
            output::write_table(&mut out, &title, &rows)?;
            for n in notes {
                writeln!(out, "  note: {n}")?;
            }
        }
    }
    Ok(Outcome::Ok)
}

fn plot_sweep(path: &Path, name: &str, rows: &[SweepRow]) -> Result<()> {
    use plotters::prelude::*;
    let v_max = rows.last().map(|r| r.airspeed_mps).unwrap_or(1.0).max(1.0);
    let p_max = rows.iter().map(|r| r.power_w).fold(0.0, f64::max) * 1.1 + 1.0;
    let e_max = rows
        .iter()
        .map(|r| r.endurance_s / 60.0)
        .fold(0.0, f64::max)
        * 1.1
        + 1.0;
    let root = SVGBackend::new(path, (900, 500)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = super::plot::dual_lines(
        &root,
        format!("{name}: power curve (level flight, still air)"),
        (0.0..v_max, "airspeed (m/s)"),
        super::plot::Line {
            desc: "electrical power (W)",
            max: p_max,
            color: RED,
            points: rows.iter().map(|r| (r.airspeed_mps, r.power_w)).collect(),
        },
        super::plot::Line {
            desc: "endurance (min)",
            max: e_max,
            color: BLUE,
            points: rows
                .iter()
                .map(|r| (r.airspeed_mps, r.endurance_s / 60.0))
                .collect(),
        },
    )?;
    super::plot::legend(&mut chart, SeriesLabelPosition::MiddleRight)?;
    root.present()?;
    Ok(())
}
