//! `aloft power`: the four-term model for one flight state, or a CSV of states streamed through it.

use std::fs::File;
use std::io::{BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use serde::Serialize;

use aloft::power::{AoaInput, FlightState, ModelOptions, PowerBreakdown, PowerModel, Term, Terms};

use super::output::{self, Row};
use super::{load_vehicle, Format, Outcome, DEFAULT_VEHICLE_ARG};

/// Angle-of-attack model of a point query.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum AoaArg {
    /// The paper's eqs (3)-(4) from roll and pitch.
    Paper,
    /// Exact angle between the air-relative velocity and the rotor plane (needs --air-direction-deg).
    Geometric,
}

#[derive(Debug, Args)]
pub struct PowerArgs {
    /// Vehicle: a built-in name (see `aloft vehicles`) or a vehicle TOML file.
    #[arg(long, default_value = DEFAULT_VEHICLE_ARG)]
    vehicle: String,
    /// Airspeed in m/s: the speed of the vehicle relative to the air (horizontal, as the paper assumes).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    airspeed: f64,
    /// Roll in degrees (positive: right side down).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    roll: f64,
    /// Pitch in degrees (positive: nose up; forward flight pitches the nose down, e.g. -8).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pitch: f64,
    /// Vertical speed in m/s, positive up (only the climb term, eq 13, uses it).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    climb_rate: f64,
    /// Remove terms from the model (the ablation rows of the paper's Table I), comma-separated:
    /// induced, parasitic, profile, climb.
    #[arg(long, value_delimiter = ',', value_name = "TERMS")]
    without: Vec<Term>,
    /// Hybrid model: drop the profile term above this airspeed, m/s (the paper's conclusion).
    #[arg(long, value_name = "M/S")]
    profile_cutoff: Option<f64>,
    /// Angle-of-attack model. Default: paper, or geometric when --air-direction-deg is given.
    #[arg(long, value_enum)]
    aoa: Option<AoaArg>,
    /// Direction of the air-relative velocity in degrees from the nose (0 forward, 90 to the
    /// right); selects the geometric angle of attack.
    #[arg(long, allow_negative_numbers = true, value_name = "DEG")]
    air_direction_deg: Option<f64>,
    /// Also report the gradient of electrical power with respect to airspeed, roll and pitch.
    #[arg(long)]
    gradient: bool,
    /// Output format (batch mode always writes CSV).
    #[arg(long, value_enum)]
    format: Option<Format>,
    /// Batch mode: CSV of states with columns airspeed_mps, roll_deg, pitch_deg and optionally
    /// climb_rate_mps and air_direction_deg; streamed row by row.
    #[arg(long, value_name = "CSV", conflicts_with_all = ["gradient"])]
    input: Option<PathBuf>,
    /// Batch mode: write the result CSV here instead of standard output.
    #[arg(long, short = 'o', value_name = "CSV", requires = "input")]
    output: Option<PathBuf>,
}

use aloft::batch::{power_values as values, POWER_KEYS as KEYS};

#[derive(Serialize)]
struct GradientJson {
    d_airspeed_w_per_mps: f64,
    d_roll_w_per_deg: f64,
    d_pitch_w_per_deg: f64,
}

#[derive(Serialize)]
struct PointJson {
    #[serde(flatten)]
    power: PowerBreakdown,
    #[serde(skip_serializing_if = "Option::is_none")]
    electrical_gradient: Option<GradientJson>,
}

pub fn run(args: PowerArgs) -> Result<Outcome> {
    let file = load_vehicle(&args.vehicle)?;
    let vehicle = file.power_vehicle()?;
    let options = ModelOptions {
        terms: Terms::all_but(&args.without),
        profile_cutoff_mps: args.profile_cutoff,
    };
    let model = PowerModel::with_options(vehicle, options).context("invalid --profile-cutoff")?;
    if let Some(path) = &args.input {
        if matches!(args.format, Some(Format::Json | Format::Table)) {
            bail!("batch mode (--input) writes CSV only; drop --format or use --format csv");
        }
        if args.aoa.is_some() || args.air_direction_deg.is_some() {
            bail!("in batch mode the angle of attack is per row: add an air_direction_deg column for the geometric model");
        }
        return batch(&model, path, args.output.as_deref());
    }
    let aoa = match (args.aoa, args.air_direction_deg) {
        (Some(AoaArg::Geometric), None) => bail!(
            "--aoa geometric needs --air-direction-deg: a point query has no air-velocity direction otherwise"
        ),
        (Some(AoaArg::Paper), Some(d)) => bail!(
            "--air-direction-deg {d} selects the geometric angle of attack; it contradicts --aoa paper"
        ),
        (_, Some(d)) => AoaInput::Geometric {
            air_direction_rad: d.to_radians(),
        },
        (_, None) => AoaInput::Paper,
    };
    let state = FlightState {
        airspeed_mps: args.airspeed,
        roll_rad: args.roll.to_radians(),
        pitch_rad: args.pitch.to_radians(),
        climb_rate_mps: args.climb_rate,
        aoa,
    };
    let describe = || {
        format!(
            "invalid flight state (--airspeed {} --roll {} --pitch {} --climb-rate {})",
            args.airspeed, args.roll, args.pitch, args.climb_rate
        )
    };
    let p = model.evaluate(&state).with_context(describe)?;
    let gradient = if args.gradient {
        let g = model.electrical_gradient(&state).with_context(describe)?;
        Some(GradientJson {
            d_airspeed_w_per_mps: g.d_airspeed_w_per_mps,
            d_roll_w_per_deg: g.d_roll_w_per_rad.to_radians(),
            d_pitch_w_per_deg: g.d_pitch_w_per_rad.to_radians(),
        })
    } else {
        None
    };
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    match args.format.unwrap_or_default() {
        Format::Json => output::write_json(
            &mut out,
            &PointJson {
                power: p,
                electrical_gradient: gradient,
            },
        )?,
        Format::Csv => {
            let mut w = csv::Writer::from_writer(out);
            let mut header = vec!["airspeed_mps", "roll_deg", "pitch_deg", "climb_rate_mps"];
            header.extend(KEYS);
            let mut row = vec![args.airspeed, args.roll, args.pitch, args.climb_rate];
            row.extend(values(&p));
            if let Some(g) = &gradient {
                header.extend([
                    "d_airspeed_w_per_mps",
                    "d_roll_w_per_deg",
                    "d_pitch_w_per_deg",
                ]);
                row.extend([
                    g.d_airspeed_w_per_mps,
                    g.d_roll_w_per_deg,
                    g.d_pitch_w_per_deg,
                ]);
            }
            w.write_record(&header)?;
            w.write_record(row.iter().map(|v| v.to_string()))?;
            w.flush()?;
        }
        Format::Table => {
            let aoa_text = match aoa {
                AoaInput::Paper => "paper eqs 3-4".to_string(),
                AoaInput::Geometric { .. } => format!(
                    "geometric, air from {:.1} deg off the nose",
                    args.air_direction_deg.unwrap_or_default()
                ),
            };
            let title = format!(
                "{}: airspeed {:.2} m/s, roll {:.2} deg, pitch {:.2} deg, climb {:.2} m/s (angle of attack: {aoa_text})",
                file.name, args.airspeed, args.roll, args.pitch, args.climb_rate
            );
            let removed: Vec<&str> = args.without.iter().map(|t| t.name()).collect();
            let f1 = |v: f64| format!("{v:.1}");
            let f2 = |v: f64| format!("{v:.2}");
            let mut rows = vec![
                Row::new("thrust", f2(p.thrust_n), "N"),
                Row::new("induced velocity", f2(p.induced_velocity_mps), "m/s"),
                Row::new(
                    "hover induced velocity",
                    f2(p.hover_induced_velocity_mps),
                    "m/s",
                ),
                Row::new("induced power (eq 8)", f1(p.induced_w), "W"),
                Row::new("parasitic power (eq 11)", f1(p.parasitic_w), "W"),
                Row::new("profile power (eq 12)", f1(p.profile_w), "W"),
                Row::new(
                    "acceleration work (eq 8, exact AoA)",
                    f1(p.acceleration_w),
                    "W",
                ),
                Row::new("climb power (eq 13)", f1(p.climb_w), "W"),
                Row::new("aerodynamic total (eq 7)", f1(p.aero_w), "W"),
                Row::new("electrical (eq 14)", f1(p.electrical_w), "W"),
            ];
            let eta = format!("{:.4}", model.vehicle().efficiency());
            rows.push(Row::new("efficiency eta", eta, ""));
            if let Some(g) = &gradient {
                rows.push(Row::new(
                    "dP/d airspeed",
                    f2(g.d_airspeed_w_per_mps),
                    "W per m/s",
                ));
                rows.push(Row::new("dP/d roll", f2(g.d_roll_w_per_deg), "W per deg"));
                rows.push(Row::new("dP/d pitch", f2(g.d_pitch_w_per_deg), "W per deg"));
            }
            output::write_table(&mut out, &title, &rows)?;
            if !removed.is_empty() {
                writeln!(out, "  (terms removed: {})", removed.join(", "))?;
            }
        }
    }
    Ok(Outcome::Ok)
}

/// Stream `path` through the model, one row at a time: memory does not grow with the file.
fn batch(model: &PowerModel, path: &Path, output: Option<&Path>) -> Result<Outcome> {
    let file = File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    let input = BufReader::with_capacity(1 << 16, file);
    let origin = path.display().to_string();
    match output {
        Some(p) => {
            let sink = File::create(p).with_context(|| format!("cannot create {}", p.display()))?;
            aloft::batch::power_csv(
                model,
                input,
                BufWriter::with_capacity(1 << 16, sink),
                &origin,
            )?;
        }
        None => {
            let stdout = std::io::stdout();
            let sink = BufWriter::with_capacity(1 << 16, stdout.lock());
            aloft::batch::power_csv(model, input, sink, &origin)?;
        }
    }
    Ok(Outcome::Ok)
}
