//! What a reader sees of a planned mission, shared by the plain answer (`mission.rs`) and the
//! answer with its scenarios (`scenarios.rs`): the header with the verdict, the summary rows,
//! the sorties, the model line, the warnings and the ground track.

use std::fmt::Write as _;
use std::io::Write;

use anyhow::{bail, Result};

use aloft::engine::{
    AoaModel, MissionReport, Plan, RouteFigures, Sample, SegmentReport, Shortfall, SourceFormat,
};

use super::output::Row;
use super::plot::ChartFile;

/// The warnings of a plan: the mission file's reader's, then the planner's.
pub(super) fn plan_warnings(plan: &Plan) -> impl Iterator<Item = &String> {
    let s = plan.summary();
    s.route.warnings.iter().chain(&s.warnings)
}

/// Minutes and seconds, `m:ss`.
pub(super) fn mmss(t: f64) -> String {
    let s = t.max(0.0).round() as u64;
    format!("{}:{:02}", s / 60, s % 60)
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
    writeln!(head, "Air: {}", s.air.describe())?;
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
pub(super) fn route_line(r: &RouteFigures) -> String {
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
        Row::num("distance flown", r.distance_m, 0, "m"),
        Row::num("energy used", r.energy_wh, 1, "Wh"),
        Row::num("mean power", mean_w, 0, "W"),
        Row::num("peak power", r.peak_power_w, 0, "W"),
        Row::num("peak current", r.peak_current_a, 1, "A"),
        Row::num("battery at take-off", r.start_soc * 100.0, 0, "%"),
        Row::num("battery at the end", r.end_soc * 100.0, 1, "%"),
        Row::num("lowest pack voltage", r.min_voltage_v, 2, "V"),
        Row::num("heat in the pack", r.pack_heat_wh, 1, "Wh"),
    ]
}

pub(super) type Area<'a> =
    plotters::drawing::DrawingArea<plotters::backend::SVGBackend<'a>, plotters::coord::Shift>;

/// A mission's chart file: `upper` draws a chart over time in the upper half, the ground track
/// is below it (`confident`: see [`plot_track`]).
pub(super) fn plot_over_track(
    file: ChartFile<'_>,
    plan: &Plan,
    confident: Option<(f64, f64)>,
    upper: impl FnOnce(&Area<'_>) -> Result<()>,
) -> Result<()> {
    let samples = plan.plot_samples();
    if samples.is_empty() {
        bail!("no samples to plot");
    }
    super::plot::svg_file(file, (1100, 800), |root| {
        let (top, bottom) = root.split_vertically(400);
        upper(&top)?;
        plot_track(&bottom, plan.report(), samples, plan.home_m(), confident)
    })
}

/// The ground track (equal scales) with home and the point of no return; with `confident`, also
/// the point of no return that holds with 95 % confidence over the scenarios (east, north).
fn plot_track(
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
    let points = s.iter().map(|x| (x.east_m, x.north_m));
    super::plot::labelled_line(&mut track, points, RED, "track", RED)?;
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
    super::plot::legend(&mut track, SeriesLabelPosition::MiddleRight)
}

/// The first columns of a segment table's head (number, item when the mission came from a
/// planner file, kind, time, distance, energy, mean power), after the title line.
pub(super) fn write_segments_head(
    out: &mut impl Write,
    r: &MissionReport,
    rest: std::fmt::Arguments<'_>,
) -> Result<()> {
    writeln!(out, "Segments")?;
    writeln!(
        out,
        "  {:>2}  {}{:<9} {:>8} {:>9} {:>9} {:>11}{rest}",
        "#",
        if has_items(r) { "item " } else { "" },
        "kind",
        "time",
        "distance",
        "energy",
        "mean power",
    )?;
    Ok(())
}

/// Whether the segments carry the operator's item numbers.
fn has_items(r: &MissionReport) -> bool {
    r.segments.iter().any(|s| s.item.is_some())
}

/// The first cells of a segment's row, as [`write_segments_head`] names them.
pub(super) fn segment_cells(r: &MissionReport, s: &SegmentReport) -> String {
    let item = match (has_items(r), s.item) {
        (false, _) => String::new(),
        (true, Some(i)) => format!("{i:>4} "),
        (true, None) => "     ".to_string(),
    };
    format!(
        "  {:>2}  {item}{:<9} {:>8} {:>7.0} m {:>6.2} Wh {:>9.0} W",
        s.index,
        s.kind,
        mmss(s.duration_s),
        s.distance_m,
        s.energy_wh,
        s.mean_power_w,
    )
}
