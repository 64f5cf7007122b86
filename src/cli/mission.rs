//! `aloft mission`: fly a mission file (or the built-in demonstration) with a vehicle, a pack, a
//! payload and a wind; say what it costs, whether the reserve holds and where the point of no
//! return lies.

use std::fmt::Write as _;
use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};

use aloft::power::{AoaModel, ModelOptions};
use aloft_planner::{
    plan, Gusts, MissionReport, MissionSpec, PlanOptions, Wind, WindGrid, WindProfile,
};

use super::output::{self, Row};
use super::{load_vehicle, Format, Outcome, DEFAULT_VEHICLE_ARG};

/// The built-in demonstration mission (identical to `fixtures/missions/demo-survey.toml`).
pub const DEMO_MISSION: &str = include_str!("../../fixtures/missions/demo-survey.toml");

/// Angle-of-attack model of the trim.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum AoaArg {
    /// Exact angle between the air-relative velocity and the rotor plane (default).
    Geometric,
    /// The power seed's eqs (3)-(4) from roll and pitch.
    Paper,
}

impl AoaArg {
    pub fn model(self) -> AoaModel {
        match self {
            AoaArg::Geometric => AoaModel::Geometric,
            AoaArg::Paper => AoaModel::Paper,
        }
    }
}

/// Variation of the wind with height.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ProfileArg {
    /// The same speed at every height.
    Uniform,
    /// `S (z / z_ref)^exponent`.
    PowerLaw,
    /// `S ln(z / z0) / ln(z_ref / z0)`.
    Log,
}

/// Wind options shared by `aloft mission` and `aloft endurance`.
#[derive(Debug, Args)]
pub struct WindArgs {
    /// Wind speed in m/s (at the reference height when a profile is given).
    #[arg(long, value_name = "M/S", requires = "wind_from")]
    pub wind_speed: Option<f64>,
    /// Direction the wind blows FROM, degrees clockwise from north (270 = a westerly).
    #[arg(
        long,
        value_name = "DEG",
        allow_negative_numbers = true,
        requires = "wind_speed"
    )]
    pub wind_from: Option<f64>,
    /// Variation of the wind with height (needs --wind-speed).
    #[arg(long, value_enum, requires = "wind_speed")]
    pub wind_profile: Option<ProfileArg>,
    /// Reference height of the profile, m.
    #[arg(long, default_value_t = 10.0, value_name = "M")]
    pub wind_reference_height: f64,
    /// Power-law exponent.
    #[arg(long, default_value_t = 1.0 / 7.0)]
    pub wind_exponent: f64,
    /// Roughness length of the log profile, m (0.03 open grass, 0.1-0.25 crops and hedges).
    #[arg(long, default_value_t = 0.03, value_name = "M")]
    pub wind_roughness: f64,
    /// Gridded wind field: CSV with columns x_m,y_m,z_m,u_mps,v_mps,w_mps (east, north, up),
    /// interpolated trilinearly; the route must stay inside it.
    #[arg(long, value_name = "CSV", conflicts_with_all = ["wind_speed", "wind_profile"])]
    pub wind_field: Option<PathBuf>,
    /// Add seeded gusts with this standard deviation per horizontal axis, m/s.
    #[arg(long, value_name = "M/S")]
    pub gust_std: Option<f64>,
    /// Seed of the gusts.
    #[arg(long, default_value_t = 1)]
    pub gust_seed: u64,
}

impl WindArgs {
    /// The wind of the options, or `fallback` when none was given; with a description.
    pub fn build(&self, fallback: Option<(Wind, String)>) -> Result<(Wind, String)> {
        let (wind, text) = if let Some(path) = &self.wind_field {
            let grid = read_wind_grid(path)?;
            let (lo, hi) = grid.bounds_m();
            (
                Wind::grid(grid),
                format!(
                    "gridded field {} (E {:.0}..{:.0} m, N {:.0}..{:.0} m, up {:.0}..{:.0} m)",
                    path.display(),
                    lo[0],
                    hi[0],
                    lo[1],
                    hi[1],
                    lo[2],
                    hi[2]
                ),
            )
        } else if let (Some(s), Some(from)) = (self.wind_speed, self.wind_from) {
            let (profile, text) = match self.wind_profile.unwrap_or(ProfileArg::Uniform) {
                ProfileArg::Uniform => (WindProfile::Uniform, String::new()),
                ProfileArg::PowerLaw => (
                    WindProfile::PowerLaw {
                        reference_height_m: self.wind_reference_height,
                        exponent: self.wind_exponent,
                    },
                    format!(
                        " at {:.0} m, power law exponent {:.3}",
                        self.wind_reference_height, self.wind_exponent
                    ),
                ),
                ProfileArg::Log => (
                    WindProfile::Log {
                        reference_height_m: self.wind_reference_height,
                        roughness_m: self.wind_roughness,
                    },
                    format!(
                        " at {:.0} m, log profile z0 {} m",
                        self.wind_reference_height, self.wind_roughness
                    ),
                ),
            };
            (
                Wind::profiled(s, from, profile).context("invalid wind options")?,
                format!("{s:.1} m/s from {from:.0} deg{text}"),
            )
        } else if let Some(fb) = fallback {
            fb
        } else {
            (Wind::calm(), "still air".to_string())
        };
        Ok(match self.gust_std {
            Some(std) => (
                wind.with_gusts(Gusts::new(std, self.gust_seed).context("invalid --gust-std")?),
                format!("{text}, gusts {std:.1} m/s std (seed {})", self.gust_seed),
            ),
            None => (wind, text),
        })
    }
}

/// Read a wind grid CSV (the planner takes the rows as data).
pub fn read_wind_grid(path: &Path) -> Result<WindGrid> {
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .with_context(|| format!("cannot open wind field {}", path.display()))?;
    let headers = reader.headers()?.clone();
    let names = ["x_m", "y_m", "z_m", "u_mps", "v_mps", "w_mps"];
    let mut cols = [0usize; 6];
    for (c, name) in cols.iter_mut().zip(names) {
        *c = headers.iter().position(|h| h == name).with_context(|| {
            format!(
                "{}: missing column '{name}' (expected x_m,y_m,z_m,u_mps,v_mps,w_mps; found {})",
                path.display(),
                headers.iter().collect::<Vec<_>>().join(",")
            )
        })?;
    }
    let mut rows = Vec::new();
    for (k, rec) in reader.records().enumerate() {
        let rec = rec.with_context(|| format!("{}: row {}", path.display(), k + 1))?;
        let mut row = [0.0; 6];
        for (slot, (&c, name)) in row.iter_mut().zip(cols.iter().zip(names)) {
            let raw = rec.get(c).unwrap_or("");
            *slot = raw.parse().with_context(|| {
                format!(
                    "{}: row {}: {name} = '{raw}' is not a number",
                    path.display(),
                    k + 1
                )
            })?;
        }
        rows.push(row);
    }
    WindGrid::from_rows(&rows).with_context(|| format!("wind field {}", path.display()))
}

#[derive(Debug, Args)]
pub struct MissionArgs {
    /// Mission TOML file (see fixtures/missions/example.toml). Without it, the built-in
    /// demonstration: a survey with four lines and an orbit in a 6 m/s breeze.
    mission: Option<PathBuf>,
    /// Vehicle: a built-in name (see `aloft vehicles`) or a vehicle TOML file.
    #[arg(long, default_value = DEFAULT_VEHICLE_ARG)]
    vehicle: String,
    /// Battery pack by name (default: the vehicle's default pack).
    #[arg(long)]
    battery: Option<String>,
    /// Payload at take-off, kg (overrides the mission file).
    #[arg(long, value_name = "KG")]
    payload_kg: Option<f64>,
    #[command(flatten)]
    wind: WindArgs,
    /// Reserve required at landing, percent of the usable capacity (default: the mission's, else 20).
    #[arg(long, value_name = "PERCENT")]
    reserve_percent: Option<f64>,
    /// State of charge at take-off, percent.
    #[arg(long, default_value_t = 100.0, value_name = "PERCENT")]
    start_percent: f64,
    /// Sampling step, s (default: the mission's, else 0.1).
    #[arg(long, value_name = "S")]
    time_step: Option<f64>,
    /// Angle-of-attack model of the power model.
    #[arg(long, value_enum, default_value_t = AoaArg::Geometric)]
    aoa: AoaArg,
    /// Leave out ground effect (survey eq 35) near the ground.
    #[arg(long)]
    no_ground_effect: bool,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
    /// Write every sample (time, position, velocity, attitude, power, current, voltage, state of
    /// charge) to this CSV.
    #[arg(long, value_name = "CSV")]
    timeseries: Option<PathBuf>,
    /// Draw power and state of charge against time and the ground track to this SVG.
    #[arg(long, value_name = "SVG")]
    plot: Option<PathBuf>,
    /// Write the mission's samples (pose, attitude, power terms, battery state) and the planned
    /// path to this MCAP file (JSON messages with schemas, for Foxglove).
    #[arg(long, value_name = "MCAP")]
    mcap: Option<PathBuf>,
    /// Replay a recorded flight instead of planning: predict its energy from the trajectory alone
    /// (velocities and accelerations through the planner's trim and power model; no power data)
    /// and print it next to the measured energy (integral of V x I over the same span).
    #[arg(
        long,
        value_name = "LOG",
        conflicts_with_all = ["mission", "timeseries", "plot", "mcap", "battery"]
    )]
    replay: Option<PathBuf>,
    /// Log layout for --replay: kaist, px4 or a column-map TOML (default: detected).
    #[arg(long, requires = "replay")]
    profile: Option<String>,
    /// Lag of the logged power behind the motion for --replay, s (default: estimated by
    /// cross-correlating power with tilt). Only the measured side is shifted.
    #[arg(
        long,
        requires = "replay",
        allow_negative_numbers = true,
        value_name = "S"
    )]
    lag: Option<f64>,
    /// Acceleration for --replay: differentiated velocity (default) or the log's own.
    #[arg(long, value_enum, default_value_t = AccelArg::Velocity)]
    acceleration: AccelArg,
    /// Window of the velocity difference for --acceleration velocity, s.
    #[arg(long, default_value_t = 1.0, value_name = "S")]
    acceleration_window: f64,
}

/// Where the replay takes the acceleration from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum AccelArg {
    /// Centred difference of the logged velocity over --acceleration-window.
    Velocity,
    /// The log's acceleration channel.
    Log,
}

fn mmss(t: f64) -> String {
    let s = t.max(0.0).round() as u64;
    format!("{}:{:02}", s / 60, s % 60)
}

pub fn run(args: MissionArgs) -> Result<Outcome> {
    if args.replay.is_some() {
        return replay::run(&args);
    }
    let file = load_vehicle(&args.vehicle)?;
    let (text, origin) = match &args.mission {
        Some(p) => (
            std::fs::read_to_string(p)
                .with_context(|| format!("cannot read mission file {}", p.display()))?,
            p.display().to_string(),
        ),
        None => (DEMO_MISSION.to_string(), "built-in demo".to_string()),
    };
    let spec = MissionSpec::from_toml_str(&text).with_context(|| origin.clone())?;
    let (aircraft, notes) = file.aircraft(ModelOptions::default())?;
    let battery = file.battery(args.battery.as_deref())?;
    let mission = spec
        .compile(aircraft.airframe(), battery.mass_kg(), args.payload_kg)
        .with_context(|| format!("mission {origin} cannot be flown by {}", file.name))?;
    let file_wind = match &spec.wind {
        Some(w) => {
            let wind = w.to_wind().with_context(|| format!("{origin}: [wind]"))?;
            let prof = match w.profile {
                aloft_planner::WindProfileKind::Uniform => String::new(),
                aloft_planner::WindProfileKind::PowerLaw => format!(
                    " at {:.0} m, power law exponent {:.3}",
                    w.reference_height_m.unwrap_or(10.0),
                    w.exponent.unwrap_or(1.0 / 7.0)
                ),
                aloft_planner::WindProfileKind::Log => format!(
                    " at {:.0} m, log profile z0 {} m",
                    w.reference_height_m.unwrap_or(10.0),
                    w.roughness_m.unwrap_or(0.03)
                ),
            };
            let gust = match w.gust_std_mps {
                Some(g) => format!(", gusts {g:.1} m/s std"),
                None => String::new(),
            };
            Some((
                wind,
                format!(
                    "{:.1} m/s from {:.0} deg{prof}{gust} (from the mission file)",
                    w.speed_mps, w.from_deg
                ),
            ))
        }
        None => None,
    };
    let (wind, wind_text) = args.wind.build(file_wind)?;
    let reserve_percent = args
        .reserve_percent
        .or(spec.reserve_percent)
        .unwrap_or(20.0);
    if !(0.0..100.0).contains(&reserve_percent) {
        bail!("--reserve-percent {reserve_percent}: expected a percentage in [0, 100)");
    }
    let options = PlanOptions {
        time_step_s: args.time_step.or(spec.time_step_s).unwrap_or(0.1),
        aoa: args.aoa.model(),
        ground_effect: !args.no_ground_effect,
        reserve_fraction: reserve_percent / 100.0,
        start_soc: args.start_percent / 100.0,
        record_samples: args.timeseries.is_some() || args.plot.is_some() || args.mcap.is_some(),
        ..PlanOptions::default()
    };
    let report = plan(&aircraft, &battery, &mission, &wind, &options)
        .with_context(|| format!("mission {origin} with {}", file.name))?;
    let payload = mission.payloads_kg()[0];

    if let Some(path) = &args.timeseries {
        let mut w = csv::Writer::from_path(path)
            .with_context(|| format!("cannot create {}", path.display()))?;
        for s in &report.samples {
            w.serialize(s)?;
        }
        w.flush()?;
    }
    if let Some(path) = &args.plot {
        plot(path, &spec.name, &report, mission.home_m())
            .with_context(|| format!("cannot draw {}", path.display()))?;
    }
    if let Some(path) = &args.mcap {
        write_mcap(path, &report, &mission)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }

    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    let name = if spec.name.is_empty() {
        origin.as_str()
    } else {
        spec.name.as_str()
    };
    match args.format {
        Format::Json => {
            // One definition of the mission JSON, shared with the Rust and C APIs.
            let summary =
                aloft::engine::mission_summary(&report, name, &file.name, battery.name(), payload);
            output::write_json(&mut out, &summary)?;
        }
        Format::Table | Format::Csv => {
            if args.format == Format::Csv {
                bail!("aloft mission writes table or json; use --timeseries for a CSV of samples");
            }
            let mut head = String::new();
            let desc = if spec.description.is_empty() {
                String::new()
            } else {
                format!(": {}", spec.description)
            };
            writeln!(head, "Mission '{name}' ({origin}){desc}")?;
            writeln!(
                head,
                "Vehicle {} with a {} pack ({}S, {:.0} mAh, {} Wh), payload {:.2} kg, take-off mass {:.3} kg",
                file.name,
                battery.name(),
                battery.cells_series(),
                battery.capacity_ah() * 1000.0,
                battery.rated_energy_wh(),
                payload,
                report.takeoff_mass_kg
            )?;
            writeln!(head, "Wind: {wind_text}")?;
            for n in &notes {
                writeln!(head, "Note: {n}")?;
            }
            writeln!(head)?;
            let verdict = match &report.shortfall {
                None => format!(
                    "FEASIBLE: lands with {:.0} % of the battery's capacity still usable ({:.0} % reserve required).",
                    report.reserve_soc * 100.0,
                    report.required_reserve_soc * 100.0
                ),
                Some(s) => format!("NOT FEASIBLE: {s}."),
            };
            writeln!(head, "{verdict}")?;
            match report.point_of_no_return {
                None => writeln!(
                    head,
                    "Point of no return: none. From every point of the route it could fly straight home and land with the reserve."
                )?,
                Some(p) => writeln!(
                    head,
                    "Point of no return: {} into the flight (t = {:.0} s), segment {}, at {:.0} m east, {:.0} m north, {:.0} m up.\n  After it, a straight return home at best-range speed would no longer land with the reserve.",
                    mmss(p.time_s),
                    p.time_s,
                    p.segment,
                    p.position_m[0],
                    p.position_m[1],
                    p.position_m[2]
                )?,
            }
            out.write_all(head.as_bytes())?;
            writeln!(out)?;
            let rows = vec![
                Row::new(
                    "flight time",
                    format!("{} min:s", mmss(report.duration_s)),
                    "",
                ),
                Row::new("distance flown", format!("{:.0}", report.distance_m), "m"),
                Row::new("energy used", format!("{:.1}", report.energy_wh), "Wh"),
                Row::new(
                    "mean power",
                    format!(
                        "{:.0}",
                        if report.duration_s > 0.0 {
                            report.energy_wh * 3600.0 / report.duration_s
                        } else {
                            0.0
                        }
                    ),
                    "W",
                ),
                Row::new("peak power", format!("{:.0}", report.peak_power_w), "W"),
                Row::new("peak current", format!("{:.1}", report.peak_current_a), "A"),
                Row::new(
                    "battery at take-off",
                    format!("{:.0}", report.start_soc * 100.0),
                    "%",
                ),
                Row::new(
                    "battery at the end",
                    format!("{:.1}", report.end_soc * 100.0),
                    "%",
                ),
                Row::new(
                    "lowest pack voltage",
                    format!("{:.2}", report.min_voltage_v),
                    "V",
                ),
                Row::new(
                    "heat in the pack",
                    format!("{:.1}", report.pack_heat_wh),
                    "Wh",
                ),
            ];
            output::write_table(&mut out, "Summary", &rows)?;
            writeln!(out)?;
            writeln!(out, "Segments")?;
            writeln!(
                out,
                "  {:>2}  {:<9} {:>8} {:>9} {:>9} {:>11} {:>11} {:>11}",
                "#",
                "kind",
                "time",
                "distance",
                "energy",
                "mean power",
                "peak power",
                "battery end"
            )?;
            for s in &report.segments {
                writeln!(
                    out,
                    "  {:>2}  {:<9} {:>8} {:>7.0} m {:>6.2} Wh {:>9.0} W {:>9.0} W {:>9.1} %",
                    s.index,
                    s.kind,
                    mmss(s.duration_s),
                    s.distance_m,
                    s.energy_wh,
                    s.mean_power_w,
                    s.peak_power_w,
                    s.end_soc * 100.0
                )?;
            }
            writeln!(out)?;
            writeln!(
                out,
                "Model: four-term power model (power seed) with {} angle of attack{}, force balance with the vehicle's cubic drag, pack by charge counting on a LiPo open-circuit curve with {:.3} ohm.",
                match args.aoa {
                    AoaArg::Geometric => "geometric",
                    AoaArg::Paper => "the paper's",
                },
                if args.no_ground_effect {
                    ""
                } else {
                    ", ground effect near the ground (survey eq 35)"
                },
                battery.resistance_ohm()
            )?;
        }
    }
    Ok(if report.feasible {
        Outcome::Ok
    } else {
        Outcome::Failed
    })
}

/// The mission as MCAP: every sample (pose, attitude, power terms, battery state) and the path
/// through the mission's waypoints.
fn write_mcap(path: &Path, report: &MissionReport, mission: &aloft_planner::Mission) -> Result<()> {
    use aloft_logs::{Attitude, BatteryPoint, MissionSample, PathPoint, PowerTerms};
    let mut energy_wh = 0.0;
    let mut last_t = 0.0;
    let samples: Vec<MissionSample> = report
        .samples
        .iter()
        .map(|s| {
            // Energy to the end of this step (samples are step midpoints; the step is twice the
            // distance to the previous step's end).
            let end_t = s.time_s + (s.time_s - last_t);
            energy_wh += s.power_w * (end_t - last_t) / 3600.0;
            last_t = end_t;
            MissionSample {
                time_s: s.time_s,
                pos_enu_m: [s.east_m, s.north_m, s.up_m],
                vel_enu_mps: [s.vel_east_mps, s.vel_north_mps, s.vel_up_mps],
                attitude: Attitude {
                    roll_rad: s.roll_deg.to_radians(),
                    pitch_rad: s.pitch_deg.to_radians(),
                    yaw_rad: s.yaw_deg.to_radians(),
                },
                power: PowerTerms {
                    induced_w: s.induced_w.unwrap_or(0.0),
                    parasitic_w: s.parasitic_w.unwrap_or(0.0),
                    profile_w: s.profile_w.unwrap_or(0.0),
                    acceleration_w: s.acceleration_w.unwrap_or(0.0),
                    climb_w: s.climb_w.unwrap_or(0.0),
                    electrical_w: s.power_w,
                },
                battery: Some(BatteryPoint {
                    voltage_v: s.voltage_v,
                    current_a: s.current_a,
                    state_of_charge: s.soc,
                    energy_used_wh: energy_wh,
                }),
            }
        })
        .collect();
    let mut path_points = vec![PathPoint {
        pos_enu_m: mission.home_m(),
        yaw_rad: None,
    }];
    for p in mission.pieces() {
        let end = p.end_m();
        let last = path_points[path_points.len() - 1].pos_enu_m;
        let is_arc = matches!(p.shape, aloft_planner::trajectory::Shape::Arc { .. });
        if is_arc || (0..3).any(|c| (end[c] - last[c]).abs() > 1e-6) {
            // Arcs: 36 points per piece so the path shows the circle.
            if is_arc {
                let d = p.duration_s();
                let n = 36;
                for k in 1..=n {
                    path_points.push(PathPoint {
                        pos_enu_m: p.at(d * k as f64 / n as f64).pos_m,
                        yaw_rad: None,
                    });
                }
            } else {
                path_points.push(PathPoint {
                    pos_enu_m: end,
                    yaw_rad: None,
                });
            }
        }
    }
    aloft_logs::write_mission_mcap(path, &samples, &path_points)?;
    Ok(())
}

fn plot(path: &Path, name: &str, report: &MissionReport, home: [f64; 3]) -> Result<()> {
    use plotters::prelude::*;
    let s = &report.samples;
    if s.is_empty() {
        bail!("no samples to plot");
    }
    let root = SVGBackend::new(path, (1100, 800)).into_drawing_area();
    root.fill(&WHITE)?;
    let (top, bottom) = root.split_vertically(400);
    let t_max = s[s.len() - 1].time_s.max(1.0);
    let p_max = s.iter().map(|x| x.power_w).fold(0.0, f64::max) * 1.1 + 1.0;
    let pnr_t = report.point_of_no_return.map(|p| p.time_s);
    let mut chart = super::plot::dual_lines(
        &top,
        format!("{name}: electrical power and state of charge"),
        (0.0..t_max, "time (s)"),
        super::plot::Line {
            desc: "power (W)",
            max: p_max,
            color: RED,
            points: s.iter().map(|x| (x.time_s, x.power_w)).collect(),
        },
        super::plot::Line {
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
    if let Some(t) = pnr_t {
        chart
            .draw_series(LineSeries::new(
                [(t, 0.0), (t, p_max)],
                BLACK.stroke_width(2),
            ))?
            .label("point of no return")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
    }
    super::plot::legend(&mut chart, SeriesLabelPosition::LowerLeft)?;

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
    let mut track = ChartBuilder::on(&bottom)
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
    track
        .draw_series(LineSeries::new(
            s.iter().map(|x| (x.east_m, x.north_m)),
            &RED,
        ))?
        .label("track")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
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
            .label("point of no return")
            .legend(|(x, y)| Cross::new((x + 10, y), 5, BLACK.stroke_width(2)));
    }
    track
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

/// `aloft mission --replay`: the energy of a recorded flight from its trajectory alone.
mod replay {
    use std::io::Write as _;

    use anyhow::{bail, Context, Result};
    use serde::Serialize;

    use aloft::identify::{align_flight, AlignOptions};
    use aloft::power::ModelOptions;
    use aloft_planner::{
        differentiate_velocity, power_only_aircraft, replay, replay::trapezoid, ReplayPoint,
    };

    use super::super::output::{self, Row};
    use super::super::{load_vehicle, Format, Outcome};
    use super::{AccelArg, MissionArgs};

    #[derive(Serialize)]
    struct ReplayJson<'a> {
        file: &'a str,
        vehicle: &'a str,
        mass_kg: f64,
        points: usize,
        duration_s: f64,
        acceleration: &'static str,
        #[serde(skip_serializing_if = "Option::is_none")]
        lag_s: Option<f64>,
        predicted_energy_wh: f64,
        predicted_mean_power_w: f64,
        #[serde(skip_serializing_if = "Option::is_none")]
        measured_energy_wh: Option<f64>,
        #[serde(skip_serializing_if = "Option::is_none")]
        measured_mean_power_w: Option<f64>,
        #[serde(skip_serializing_if = "Option::is_none")]
        energy_error_percent: Option<f64>,
    }

    /// Integral of the piecewise-linear `values(times)` over `[a, b]` (inside the data).
    fn window_integral(times: &[f64], values: &[f64], a: f64, b: f64) -> f64 {
        let interp = |t: f64| {
            let i = times.partition_point(|&x| x <= t).clamp(1, times.len() - 1);
            let (t0, t1) = (times[i - 1], times[i]);
            let w = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
            values[i - 1] + w * (values[i] - values[i - 1])
        };
        let (mut ts, mut vs) = (vec![a], vec![interp(a)]);
        for (&t, &v) in times.iter().zip(values) {
            if t > a && t < b {
                ts.push(t);
                vs.push(v);
            }
        }
        ts.push(b);
        vs.push(interp(b));
        trapezoid(&ts, &vs)
    }

    pub fn run(args: &MissionArgs) -> Result<Outcome> {
        let path = args.replay.as_ref().expect("--replay");
        let file = load_vehicle(&args.vehicle)?;
        let payload = args.payload_kg.unwrap_or(0.0);
        if !(payload.is_finite() && payload >= 0.0) {
            bail!("--payload-kg {payload}: expected a mass of 0 kg or more");
        }
        // The aircraft: with an airframe, airframe + default pack + payload; a vehicle known only
        // by its [power] table (a fit) flies at that table's mass.
        let (aircraft, mass_kg) = if file.airframe.is_some() {
            let (aircraft, _) = file.aircraft(ModelOptions::default())?;
            let pack = if file.batteries.is_empty() {
                0.0
            } else {
                file.battery(None)?.mass_kg()
            };
            let m = aircraft.airframe().mass_kg() + pack + payload;
            (aircraft, m)
        } else {
            let vehicle = file.power_vehicle()?;
            let m = vehicle.mass_kg() + payload;
            (
                power_only_aircraft(vehicle, ModelOptions::default())
                    .context("vehicle for replay")?,
                m,
            )
        };
        let pw = aircraft
            .at_mass(mass_kg, args.aoa.model())
            .context("vehicle mass")?;
        let profile = args
            .profile
            .as_deref()
            .map(aloft_logs::Profile::resolve)
            .transpose()
            .context("--profile")?;
        let log = aloft_logs::read_log(path, profile.as_ref(), &Default::default())
            .context("--replay")?;

        // The trajectory: samples with a velocity, strictly increasing in time.
        let mut times = Vec::new();
        let mut vels = Vec::new();
        let mut rows = Vec::new();
        for s in &log.samples {
            let Some(v) = s.vel_enu_mps else { continue };
            if !s.time_s.is_finite() || times.last().is_some_and(|&t| s.time_s <= t) {
                continue;
            }
            times.push(s.time_s);
            vels.push(v);
            rows.push(s);
        }
        if times.len() < 2 {
            bail!(
                "{}: fewer than two samples with a velocity: nothing to replay",
                path.display()
            );
        }
        let accs: Vec<[f64; 3]> = match args.acceleration {
            AccelArg::Velocity => differentiate_velocity(&times, &vels, args.acceleration_window)
                .context("--acceleration-window")?,
            AccelArg::Log => rows
                .iter()
                .map(|s| s.acc_enu_mps2)
                .collect::<Option<Vec<_>>>()
                .with_context(|| {
                    format!(
                        "{}: the log has no acceleration on every velocity sample; use --acceleration velocity",
                        path.display()
                    )
                })?,
        };
        let points: Vec<ReplayPoint> = rows
            .iter()
            .zip(&accs)
            .map(|(s, a)| ReplayPoint {
                time_s: s.time_s,
                vel_enu_mps: s.vel_enu_mps.unwrap_or([0.0; 3]),
                acc_enu_mps2: *a,
                pos_enu_m: s.pos_enu_m.unwrap_or([0.0; 3]),
                height_above_ground_m: None,
                wind_enu_mps: s.wind_enu_mps,
            })
            .collect();
        let (wind, wind_text) = args.wind.build(None).context("wind for the replay")?;
        let report =
            replay(&pw, &points, &wind).with_context(|| format!("replay of {}", path.display()))?;

        // Measured: V x I of the same span, shifted by the lag of power behind motion.
        let (pt, pp): (Vec<f64>, Vec<f64>) = log
            .samples
            .iter()
            .filter_map(|s| s.electrical_power_w().map(|p| (s.time_s, p)))
            .filter(|(t, p)| t.is_finite() && p.is_finite())
            .unzip();
        let monotonic = pt.windows(2).all(|w| w[1] >= w[0]);
        let (lag_s, measured, predicted_wh, span_s) = if pt.len() >= 2 && monotonic {
            let lag = match args.lag {
                Some(l) => l,
                None => match align_flight(&log, &AlignOptions::default()) {
                    Ok(a) => a.lag_s,
                    Err(e) => {
                        eprintln!("aloft mission --replay: no lag estimate ({e}); using 0 s");
                        0.0
                    }
                },
            };
            let a = times[0].max(pt[0] - lag);
            let b = times[times.len() - 1].min(pt[pt.len() - 1] - lag);
            if b <= a {
                bail!(
                    "{}: the power channel does not overlap the trajectory with a lag of {lag} s",
                    path.display()
                );
            }
            let measured_wh = window_integral(&pt, &pp, a + lag, b + lag) / 3600.0;
            let predicted_wh = window_integral(&times, &report.power_w, a, b) / 3600.0;
            (Some(lag), Some(measured_wh), predicted_wh, b - a)
        } else {
            (None, None, report.energy_wh, report.duration_s)
        };
        let error = measured.map(|m| 100.0 * (predicted_wh - m) / m);
        let source = path.display().to_string();
        let stdout = std::io::stdout();
        let mut out = stdout.lock();
        match args.format {
            Format::Json => output::write_json(
                &mut out,
                &ReplayJson {
                    file: &source,
                    vehicle: &file.name,
                    mass_kg,
                    points: points.len(),
                    duration_s: span_s,
                    acceleration: match args.acceleration {
                        AccelArg::Velocity => "velocity",
                        AccelArg::Log => "log",
                    },
                    lag_s,
                    predicted_energy_wh: predicted_wh,
                    predicted_mean_power_w: predicted_wh * 3600.0 / span_s,
                    measured_energy_wh: measured,
                    measured_mean_power_w: measured.map(|m| m * 3600.0 / span_s),
                    energy_error_percent: error,
                },
            )?,
            Format::Table | Format::Csv => {
                if args.format == Format::Csv {
                    bail!("aloft mission --replay writes table or json");
                }
                writeln!(
                    out,
                    "Replay of {source}: {} trajectory points, {:.0} s, vehicle {} at {mass_kg:.3} kg",
                    points.len(),
                    span_s,
                    file.name
                )?;
                writeln!(
                    out,
                    "Acceleration: {}; wind: {}",
                    match args.acceleration {
                        AccelArg::Velocity => format!(
                            "differentiated velocity over {} s",
                            args.acceleration_window
                        ),
                        AccelArg::Log => "the log's".to_string(),
                    },
                    if points.iter().any(|p| p.wind_enu_mps.is_some()) {
                        "from the log".to_string()
                    } else {
                        wind_text
                    }
                )?;
                writeln!(out)?;
                let mut rows = vec![Row::new(
                    "predicted energy (trajectory only)",
                    format!("{predicted_wh:.1}"),
                    "Wh",
                )];
                if let Some(m) = measured {
                    rows.push(Row::new("measured energy (V x I)", format!("{m:.1}"), "Wh"));
                    rows.push(Row::new(
                        "error",
                        format!("{:+.2}", error.unwrap_or(0.0)),
                        "%",
                    ));
                    rows.push(Row::new(
                        "lag of power behind motion",
                        format!("{:.2}", lag_s.unwrap_or(0.0)),
                        "s",
                    ));
                } else {
                    rows.push(Row::new(
                        "measured energy",
                        "no power in the log".to_string(),
                        "",
                    ));
                }
                output::write_table(&mut out, "Replay", &rows)?;
            }
        }
        Ok(Outcome::Ok)
    }
}
