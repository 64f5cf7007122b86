//! `aloft mission`: fly a mission file (or the built-in demonstration) with a vehicle, a pack, a
//! payload and a wind; say what it costs, whether the reserve holds and where the point of no
//! return lies. `--replay` predicts a recorded flight instead (see `replay.rs`).

use std::fmt::Write as _;
use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};

use aloft::engine::{
    plan_mission_with, AoaModel, CornerMode, Mission, MissionOptions, MissionOutputs,
    MissionReport, Plan, RouteFigures, Sample, Shortfall, SourceFormat, Vehicle,
};

use super::args::{aoa_parser, corners_parser, MissionWindArgs};
use super::output::{self, Row};
use super::{Format, Outcome, DEFAULT_VEHICLE_ARG};

#[derive(Debug, Args)]
pub struct MissionArgs {
    /// Mission file: an aloft mission in TOML or JSON (see fixtures/missions/example.toml), a
    /// QGroundControl .plan or a Mission Planner .waypoints file (QGC WPL 110), recognised from
    /// its content. Without it, the built-in demonstration: a survey with four lines and an
    /// orbit in a 6 m/s breeze.
    pub mission: Option<PathBuf>,
    /// Vehicle: a built-in name (see `aloft vehicles`) or a vehicle TOML file.
    #[arg(long, default_value = DEFAULT_VEHICLE_ARG)]
    pub vehicle: String,
    /// Battery pack by name (default: the vehicle's default pack). With --replay, the pack flown
    /// in the log: its mass is part of the mass flown (airframe + pack + payload).
    #[arg(long)]
    pub battery: Option<String>,
    /// Payload at take-off, kg (overrides the mission file).
    #[arg(value_parser = super::args::finite(), long, value_name = "KG")]
    pub payload_kg: Option<f64>,
    #[command(flatten)]
    pub wind: MissionWindArgs,
    /// Reserve required at landing, percent of the usable capacity (default: the mission's, else 20).
    #[arg(value_parser = super::args::finite(), long, value_name = "PERCENT")]
    pub reserve_percent: Option<f64>,
    /// State of charge at take-off, percent.
    #[arg(value_parser = super::args::finite(), long, default_value_t = 100.0, value_name = "PERCENT")]
    pub start_percent: f64,
    /// Sampling step, s (default: the mission's, else 0.1).
    #[arg(value_parser = super::args::finite(), long, value_name = "S")]
    pub time_step: Option<f64>,
    /// Planning speed, m/s: the ground speed of legs without one of their own (overrides the
    /// vehicle's cruise_speed_mps and the file's, e.g. a .plan's hoverSpeed).
    #[arg(value_parser = super::args::finite(), long, value_name = "M/S")]
    pub speed: Option<f64>,
    /// Lowest height of a return to launch, m (overrides the vehicle's rtl_altitude_m and the
    /// mission's): a return below it climbs first.
    #[arg(value_parser = super::args::finite(), long, value_name = "M")]
    pub rtl_altitude_m: Option<f64>,
    /// How waypoints without a hold are flown (default: the mission's, else pass).
    #[arg(long, value_parser = corners_parser(), value_name = "MODE")]
    pub corners: Option<CornerMode>,
    /// Angle-of-attack model of the power model.
    #[arg(long, value_parser = aoa_parser(), default_value = "geometric")]
    pub aoa: AoaModel,
    /// Leave out ground effect (survey eq 35) near the ground.
    #[arg(long)]
    pub no_ground_effect: bool,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    pub format: Format,
    /// Write every sample (time, position, velocity, attitude, power, current, voltage, state of
    /// charge) to this CSV.
    #[arg(long, value_name = "CSV")]
    pub timeseries: Option<PathBuf>,
    /// Draw power and state of charge against time and the ground track to this SVG.
    #[arg(long, value_name = "SVG")]
    pub plot: Option<PathBuf>,
    /// Write the mission's samples (pose, attitude, power terms, battery state) and the planned
    /// path to this MCAP file (JSON messages with schemas, for Foxglove).
    #[arg(long, value_name = "MCAP")]
    pub mcap: Option<PathBuf>,
    /// Replay a recorded flight instead of planning: predict its energy from the trajectory alone
    /// (velocities and accelerations through the planner's trim and power model; no power data)
    /// and print it next to the measured energy (integral of V x I over the same span).
    #[arg(
        long,
        value_name = "LOG",
        conflicts_with_all = ["mission", "timeseries", "plot", "mcap"]
    )]
    pub replay: Option<PathBuf>,
    /// Log layout for --replay: kaist, px4 or a column-map TOML (default: detected).
    #[arg(long, requires = "replay")]
    pub profile: Option<String>,
    /// Lag of the logged power behind the motion for --replay, s (default: estimated by
    /// cross-correlating power with tilt). Only the measured side is shifted.
    #[arg(value_parser = super::args::finite(),
        long,
        requires = "replay",
        allow_negative_numbers = true,
        value_name = "S"
    )]
    pub lag: Option<f64>,
    /// Acceleration for --replay: differentiated velocity (default) or the log's own.
    #[arg(long, value_enum, default_value_t = AccelArg::Velocity)]
    pub acceleration: AccelArg,
    /// Window of the velocity difference for --acceleration velocity, s.
    #[arg(value_parser = super::args::finite(), long, default_value_t = 1.0, value_name = "S")]
    pub acceleration_window: f64,
    /// Monte-Carlo scenarios (--samples N and the spreads).
    #[command(flatten)]
    pub scenarios: super::scenarios::ScenarioArgs,
}

/// Where the replay takes the acceleration from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum AccelArg {
    /// Centred difference of the logged velocity over --acceleration-window.
    Velocity,
    /// The log's acceleration channel.
    Log,
}

impl MissionArgs {
    /// The engine's options of these arguments.
    fn options(&self) -> MissionOptions {
        MissionOptions {
            battery: self.battery.clone(),
            payload_kg: self.payload_kg,
            wind: self.wind.steady.spec(),
            wind_field: self.wind.wind_field.clone(),
            gusts: self.wind.gusts(),
            reserve_percent: self.reserve_percent,
            start_percent: self.start_percent,
            time_step_s: self.time_step,
            aoa: self.aoa,
            ground_effect: !self.no_ground_effect,
            record_samples: false,
            speed_mps: self.speed,
            rtl_altitude_m: self.rtl_altitude_m,
            corners: self.corners,
        }
    }

    /// The files to write as the flight is flown.
    fn outputs(&self) -> MissionOutputs {
        MissionOutputs {
            timeseries: self.timeseries.clone(),
            mcap: self.mcap.clone(),
            plot: self.plot.is_some(),
        }
    }
}

pub fn run(args: MissionArgs) -> Result<Outcome> {
    if args.replay.is_some() {
        args.scenarios.refuse_with("--replay")?;
        return super::replay::run(&args);
    }
    if args.format == Format::Csv {
        bail!("aloft mission writes table or json; use --timeseries for a CSV of samples");
    }
    let vehicle = Vehicle::load(&args.vehicle)?;
    let mission = Mission::load(args.mission.as_deref())?;
    let plan = plan_mission_with(&vehicle, &mission, &args.options(), &args.outputs())?;
    if let Some(sc) = args.scenarios.options(args.plot.is_some()) {
        let run = super::scenarios::MissionRun {
            vehicle: &vehicle,
            mission: &mission,
            options: &args.options(),
            plan: &plan,
            plot: args.plot.as_deref(),
            format: args.format,
        };
        return super::scenarios::run_mission(&run, &sc);
    }
    if let Some(path) = &args.plot {
        let name = mission.spec().name.as_str();
        plot(
            path,
            name,
            plan.report(),
            plan.plot_samples(),
            plan.home_m(),
        )
        .with_context(|| format!("cannot draw {}", path.display()))?;
    }
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    match args.format {
        Format::Json => {
            output::warn(plan_warnings(&plan));
            output::write_json(&mut out, plan.summary())?
        }
        Format::Table | Format::Csv => write_table(&mut out, &plan)?,
    }
    Ok(if plan.report().feasible {
        Outcome::Ok
    } else {
        Outcome::Failed
    })
}

/// The warnings of a plan: the mission file's reader's, then the planner's.
pub(super) fn plan_warnings(plan: &Plan) -> impl Iterator<Item = &String> {
    let s = plan.summary();
    s.route.warnings.iter().chain(&s.warnings)
}

/// Minutes and seconds, `m:ss`.
pub fn mmss(t: f64) -> String {
    let s = t.max(0.0).round() as u64;
    format!("{}:{:02}", s / 60, s % 60)
}

/// The mission as a reader sees it: header, verdict, summary, segments, the model used.
fn write_table(out: &mut impl Write, plan: &Plan) -> Result<()> {
    out.write_all(header(plan)?.as_bytes())?;
    writeln!(out)?;
    output::write_table(out, "Summary", &summary_rows(plan.report()))?;
    writeln!(out)?;
    write_segments(out, plan.report())?;
    writeln!(out)?;
    write_sorties(out, plan.summary())?;
    write_model_line(out, plan)
}

/// The model the plan was computed with, in one line.
pub(super) fn write_model_line(out: &mut impl Write, plan: &Plan) -> Result<()> {
    let c = plan.context();
    writeln!(
        out,
        "Model: {}{}{}, force balance with the vehicle's cubic drag, pack by charge counting on a LiPo open-circuit curve with {:.3} ohm.",
        c.power_model,
        match (c.power_model.starts_with("four-term"), c.aoa) {
            (false, _) => "",
            (true, AoaModel::Geometric) => " with geometric angle of attack",
            (true, AoaModel::Paper) => " with the paper's angle of attack",
        },
        if c.ground_effect {
            ", ground effect near the ground (survey eq 35)"
        } else {
            ""
        },
        c.battery.resistance_ohm
    )?;
    Ok(())
}

/// Mission, vehicle, pack and wind; the verdict and the point of no return.
pub(super) fn header(plan: &Plan) -> Result<String> {
    let (s, c, r) = (plan.summary(), plan.context(), plan.report());
    let mut head = String::new();
    let desc = if c.description.is_empty() {
        String::new()
    } else {
        format!(": {}", c.description)
    };
    writeln!(head, "Mission '{}' ({}){desc}", s.mission, c.origin)?;
    writeln!(
        head,
        "Vehicle {} with a {} pack ({}S, {:.0} mAh, {} Wh), payload {:.2} kg, take-off mass {:.3} kg",
        s.vehicle,
        c.battery.name,
        c.battery.cells_series,
        c.battery.capacity_mah,
        c.battery.energy_wh,
        s.payload_kg,
        r.takeoff_mass_kg
    )?;
    writeln!(head, "Wind: {}", c.wind)?;
    if let Some(v) = &s.planning_speed {
        writeln!(
            head,
            "Planning speed: {} m/s ({}), for the legs without a speed of their own",
            v.speed_mps,
            match v.source.as_str() {
                "option" => "--speed",
                "vehicle" => "the vehicle's cruise_speed_mps",
                _ => "the mission file's",
            }
        )?;
    }
    writeln!(head, "{}", route_line(&s.route))?;
    for n in &c.notes {
        writeln!(head, "Note: {n}")?;
    }
    for w in plan_warnings(plan) {
        writeln!(head, "Warning: {w}")?;
    }
    writeln!(head)?;
    match &r.shortfall {
        None => writeln!(
            head,
            "FEASIBLE: lands with {:.0} % of the battery's capacity still usable ({:.0} % reserve required).",
            r.reserve_soc * 100.0,
            r.required_reserve_soc * 100.0
        )?,
        Some(why) => writeln!(
            head,
            "NOT FEASIBLE: {}.",
            s.reason.clone().unwrap_or_else(|| why.to_string())
        )?,
    }
    let ended_early = !matches!(r.shortfall, None | Some(Shortfall::Reserve { .. }));
    match r.point_of_no_return {
        None if ended_early => writeln!(
            head,
            "Point of no return: none before the flight ends (t = {:.0} s): until then it could fly straight home and land with the reserve.",
            r.duration_s
        )?,
        None => writeln!(
            head,
            "Point of no return: none. From every point of the route it could fly straight home and land with the reserve."
        )?,
        Some(p) => writeln!(
            head,
            "Point of no return: {} into the flight (t = {:.0} s), segment {}{}, at {:.0} m east, {:.0} m north, {:.0} m up.\n  After it, a straight return home at best-range speed would no longer land with the reserve.",
            mmss(p.time_s),
            p.time_s,
            p.segment,
            s.point_of_no_return
                .as_ref()
                .and_then(|x| x.point_of_no_return_item)
                .map_or(String::new(), |i| format!(" (item {i})")),
            p.position_m[0],
            p.position_m[1],
            p.position_m[2]
        )?,
    }
    if let Some(l) = &s.loiter {
        let item = l.item.map_or(String::new(), |i| format!(" (item {i})"));
        writeln!(
            head,
            "Loiter until the reserve{item}: {}{} of hovering from t = {:.0} s (segment {}), then home to land with the reserve.",
            if l.at_least { "at least " } else { "" },
            mmss(l.duration_s),
            l.start_s,
            l.segment
        )?;
    }
    Ok(head)
}

/// The planned route in one line: the file's format, its path, climb, descent and holds, and
/// the items of a planner file.
fn route_line(r: &RouteFigures) -> String {
    let format = match r.source_format {
        SourceFormat::QgcPlan => "QGroundControl plan",
        SourceFormat::QgcWpl => "QGC WPL 110 waypoints",
        SourceFormat::AloftJson => "aloft JSON",
        _ => "aloft TOML",
    };
    let mut line = format!(
        "Route ({format}): {:.0} m horizontal, {:.0} m climb, {:.0} m descent, {:.0} s of holds",
        r.horizontal_m, r.climb_m, r.descent_m, r.hold_s
    );
    if let Some(n) = &r.items {
        line += &format!(
            "; {} items: {} flown, {} speed/jump/gripper, {} free (camera, gimbal, mode), {} unknown, {} never reached",
            n.total, n.flown, n.commands, n.free, n.unknown, n.unreachable
        );
    }
    line
}

/// Batteries and sorties, when the route takes more than one pack or cannot be split.
pub(super) fn write_sorties(out: &mut impl Write, s: &aloft::engine::MissionSummary) -> Result<()> {
    if s.sorties.is_empty() {
        if s.batteries_required.is_none() && !s.feasible {
            writeln!(out, "Batteries required: unknown (see the warning above).")?;
            writeln!(out)?;
        }
        return Ok(());
    }
    writeln!(
        out,
        "Batteries required: {}, one per sortie (each from home and back with the reserve, a fresh pack at home)",
        s.sorties.len()
    )?;
    writeln!(
        out,
        "  {:>2}  {:>11} {:>8} {:>9} {:>11}",
        "#", "items", "time", "energy", "battery end"
    )?;
    for (k, x) in s.sorties.iter().enumerate() {
        let items = match (x.first_item, x.last_item) {
            (Some(a), Some(b)) => format!("{a}-{b}"),
            _ => format!("seg {}-{}", x.first_segment, x.last_segment),
        };
        writeln!(
            out,
            "  {:>2}  {:>11} {:>8} {:>6.1} Wh {:>9.1} %",
            k + 1,
            items,
            mmss(x.duration_s),
            x.energy_wh,
            x.end_soc * 100.0
        )?;
    }
    writeln!(out)?;
    Ok(())
}

pub(super) fn summary_rows(r: &MissionReport) -> Vec<Row<'static>> {
    let mean_w = if r.duration_s > 0.0 {
        r.energy_wh * 3600.0 / r.duration_s
    } else {
        0.0
    };
    vec![
        Row::new("flight time", format!("{} min:s", mmss(r.duration_s)), ""),
        Row::new("distance flown", format!("{:.0}", r.distance_m), "m"),
        Row::new("energy used", format!("{:.1}", r.energy_wh), "Wh"),
        Row::new("mean power", format!("{mean_w:.0}"), "W"),
        Row::new("peak power", format!("{:.0}", r.peak_power_w), "W"),
        Row::new("peak current", format!("{:.1}", r.peak_current_a), "A"),
        Row::new(
            "battery at take-off",
            format!("{:.0}", r.start_soc * 100.0),
            "%",
        ),
        Row::new(
            "battery at the end",
            format!("{:.1}", r.end_soc * 100.0),
            "%",
        ),
        Row::new(
            "lowest pack voltage",
            format!("{:.2}", r.min_voltage_v),
            "V",
        ),
        Row::new("heat in the pack", format!("{:.1}", r.pack_heat_wh), "Wh"),
    ]
}

/// The segments; with the operator's item numbers when the mission came from a planner file.
fn write_segments(out: &mut impl Write, r: &MissionReport) -> Result<()> {
    let items = r.segments.iter().any(|s| s.item.is_some());
    // A column of the time lost at the edge of the envelope, when the wind or a limit slowed
    // any segment.
    let slowed = r.segments.iter().any(|s| s.edge.is_some());
    writeln!(out, "Segments")?;
    writeln!(
        out,
        "  {:>2}  {}{:<9} {:>8} {:>9} {:>9} {:>11} {:>11} {:>11}{}",
        "#",
        if items { "item " } else { "" },
        "kind",
        "time",
        "distance",
        "energy",
        "mean power",
        "peak power",
        "battery end",
        if slowed { "   time lost (limit)" } else { "" }
    )?;
    for s in &r.segments {
        let item = match (items, s.item) {
            (false, _) => String::new(),
            (true, Some(i)) => format!("{i:>4} "),
            (true, None) => "     ".to_string(),
        };
        let lost = match s.edge {
            Some(e) => format!("  {:>8.1} s ({})", s.time_lost_s, e.limit.name()),
            _ => String::new(),
        };
        writeln!(
            out,
            "  {:>2}  {item}{:<9} {:>8} {:>7.0} m {:>6.2} Wh {:>9.0} W {:>9.0} W {:>9.1} %{lost}",
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
    Ok(())
}

/// Power and state of charge against time, and the ground track with the point of no return.
fn plot(
    path: &Path,
    name: &str,
    report: &MissionReport,
    samples: &[Sample],
    home: [f64; 3],
) -> Result<()> {
    use plotters::prelude::*;
    if samples.is_empty() {
        bail!("no samples to plot");
    }
    let root = SVGBackend::new(path, (1100, 800)).into_drawing_area();
    root.fill(&WHITE)?;
    let (top, bottom) = root.split_vertically(400);
    plot_power(&top, name, report, samples)?;
    plot_track(&bottom, report, samples, home, None)?;
    root.present()?;
    Ok(())
}

pub(super) type Area<'a> =
    plotters::drawing::DrawingArea<plotters::backend::SVGBackend<'a>, plotters::coord::Shift>;

fn plot_power(area: &Area<'_>, name: &str, report: &MissionReport, s: &[Sample]) -> Result<()> {
    use plotters::prelude::*;
    let t_max = s[s.len() - 1].time_s.max(1.0);
    let p_max = s.iter().map(|x| x.power_w).fold(0.0, f64::max) * 1.1 + 1.0;
    let mut chart = super::plot::dual_lines(
        area,
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
    if let Some(t) = report.point_of_no_return.map(|p| p.time_s) {
        chart
            .draw_series(LineSeries::new(
                [(t, 0.0), (t, p_max)],
                BLACK.stroke_width(2),
            ))?
            .label("point of no return")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
    }
    super::plot::legend(&mut chart, SeriesLabelPosition::LowerLeft)?;
    Ok(())
}

/// The ground track (equal scales) with home and the point of no return; with `confident`, also
/// the point of no return that holds with 95 % confidence over the scenarios (east, north).
pub(super) fn plot_track(
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
    track
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}
