//! What a reader sees of a planned mission, with or without its scenarios (`--samples N`): the
//! header with the verdict, the summary, the scenarios' bands, the segments, the sorties and the
//! model line as a table; the summary (with its `uncertainty`) as JSON. The chart is
//! `mission_chart.rs`; the shared table writer is `output.rs`.

use std::fmt::Write as _;
use std::io::Write;

use anyhow::Result;

use aloft::engine::{
    AoaModel, MissionReport, MissionSummary, Plan, RouteFigures, SegmentReport, Shortfall,
    SourceFormat, Uncertainty,
};

use super::output::{self, mmss, percentiles, MaybeUncertain, Row};
use super::Format;

/// A planned mission as the command line shows it: the plan, and its scenarios when they were
/// drawn.
pub(super) struct MissionView<'a> {
    /// The mission's name (the chart's caption).
    pub name: &'a str,
    /// The plan as flown.
    pub plan: &'a Plan,
    /// The scenarios drawn around it (`--samples N`).
    pub scenarios: Option<&'a Uncertainty>,
}

impl MissionView<'_> {
    /// Print the answer on stdout in `format`: JSON from the summary (with its `uncertainty`),
    /// its warnings then also on stderr; otherwise the table.
    pub fn print(&self, format: Format) -> Result<()> {
        if format == Format::Json {
            output::warn(plan_warnings(self.plan));
        }
        let mut out = std::io::stdout().lock();
        match format {
            Format::Json => {
                let answer = MaybeUncertain::new(self.plan.summary(), self.scenarios);
                output::write_json(&mut out, &answer)
            }
            Format::Table | Format::Csv => self.write_table(&mut out),
        }
    }

    /// The mission as a reader sees it: header (and the scenarios' verdict), summary, the
    /// failsafes or the scenarios' bands, segments, sorties, the model used.
    fn write_table(&self, out: &mut impl Write) -> Result<()> {
        let plan = self.plan;
        out.write_all(header(plan)?.as_bytes())?;
        if let Some(u) = self.scenarios {
            out.write_all(verdict(plan, u).as_bytes())?;
        }
        writeln!(out)?;
        output::write_table(out, "Summary", &summary_rows(plan.report()))?;
        writeln!(out)?;
        match self.scenarios {
            // The table with scenarios has no failsafe lines: their bands stand in that place.
            Some(u) => write_bands(out, u)?,
            None => write_failsafes(out, plan.summary())?,
        }
        write_clearance(out, plan.summary())?;
        write_segments(out, plan.report(), self.scenarios)?;
        writeln!(out)?;
        write_sorties(out, plan.summary())?;
        write_model_line(out, plan)
    }
}

/// The warnings of a plan: the mission file's reader's, then the planner's.
fn plan_warnings(plan: &Plan) -> impl Iterator<Item = &String> {
    let s = plan.summary();
    s.route.warnings.iter().chain(&s.warnings)
}

/// Mission, vehicle, pack and wind; the verdict and the point of no return.
fn header(plan: &Plan) -> Result<String> {
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
        // Over terrain a route the pack flies may still pass too close to the ground.
        None if !s.feasible => writeln!(
            head,
            "NOT FEASIBLE: {}.",
            s.reason.as_deref().unwrap_or("see the segments")
        )?,
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

/// The scenarios in two sentences: how often the reserve holds, and the point of no return with
/// 95 % confidence.
fn verdict(plan: &Plan, u: &Uncertainty) -> String {
    let mut text = format!(
        "Scenarios: lands with the reserve in {:.1} % of {} scenarios ({}).\n",
        u.p_feasible * 100.0,
        u.samples,
        spreads_text(u)
    );
    if let Some(why) = &u.cannot_fly_reason {
        text.push_str(&format!(
            "  {} of them cannot be flown (their flight ends where the vehicle cannot make headway or hold its position, or it cannot take off); the first: {why}.\n",
            u.cannot_fly_scenarios
        ));
    }
    let ended_early = u.samples - u.completed_scenarios;
    if ended_early > u.cannot_fly_scenarios {
        text.push_str(&format!(
            "  {} run out of charge on the way (below the empty point or the cut-off voltage).\n",
            ended_early - u.cannot_fly_scenarios
        ));
    }
    match u.point_of_no_return_s.p5 {
        Some(t) if t <= 0.0 => text.push_str(&format!(
            "Point of no return with 95 % confidence: at take-off: in more than 5 % of the scenarios the vehicle cannot fly the route ({:.1} % do not complete it) or cannot turn back from its start.\n",
            (1.0 - u.completed_scenarios as f64 / u.samples as f64) * 100.0
        )),
        Some(t) => {
            let (segment, item) = segment_at(plan, t);
            let item = item.map_or(String::new(), |i| format!(" (item {i})"));
            text.push_str(&format!(
                "Point of no return with 95 % confidence: {} into the flight (t = {t:.0} s), segment {segment}{item}: 95 % of the scenarios can still turn back until then.\n",
                mmss(t)
            ));
        }
        None => text.push_str(&format!(
            "Point of no return with 95 % confidence: none; {:.1} % of the scenarios could fly straight home from every point of the route.\n",
            (1.0 - u.p_point_of_no_return) * 100.0
        )),
    }
    text
}

/// The drawn spreads in words.
fn spreads_text(u: &Uncertainty) -> String {
    let s = &u.spreads;
    format!(
        "seed {}; wind speed sd {} m/s, wind direction sd {} deg, payload sd {} kg, capacity sd {} %, power sd {} %",
        u.seed,
        s.wind_speed_sd_mps,
        s.wind_from_sd_deg,
        s.payload_sd_kg,
        s.capacity_sd_percent,
        s.power_sd_percent
    )
}

/// The segment (and operator's item) the plan flies at time `t_s`.
fn segment_at(plan: &Plan, t_s: f64) -> (usize, Option<u32>) {
    let mut end = 0.0;
    let segments = &plan.report().segments;
    for s in segments {
        end += s.duration_s;
        if t_s <= end {
            return (s.index, s.item);
        }
    }
    segments.last().map_or((1, None), |s| (s.index, s.item))
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

/// The summary of the plan as flown.
fn summary_rows(r: &MissionReport) -> Vec<Row<'static>> {
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

/// When each voltage failsafe would trigger, one sentence each ("the low-voltage failsafe
/// (21.0 V) would trigger at 17:40, in segment 12"), then a blank line when there were any.
fn write_failsafes(out: &mut impl Write, s: &MissionSummary) -> Result<()> {
    for f in &s.failsafes {
        let name = format!("the {}-voltage failsafe ({:.1} V)", f.kind, f.voltage_v);
        match (f.time_s, f.segment) {
            (Some(t), Some(seg)) => {
                let item = f.item.map(|i| format!(" (item {i})")).unwrap_or_default();
                writeln!(
                    out,
                    "{name} would trigger at {}, in segment {seg}{item}",
                    mmss(t)
                )?;
            }
            _ => writeln!(
                out,
                "{name} would not trigger: the lowest predicted voltage is {:.2} V",
                s.min_voltage_v
            )?,
        }
    }
    if !s.failsafes.is_empty() {
        writeln!(out)?;
    }
    Ok(())
}

/// Over terrain, the least height above the ground of the segments in the air and where
/// ("least clearance: 23.4 m above the ground in segment 7 (item 9), at 44.27012, -71.30310"),
/// then a blank line.
fn write_clearance(out: &mut impl Write, s: &MissionSummary) -> Result<()> {
    let Some(least_m) = s.min_clearance_m else {
        return Ok(());
    };
    // The segment that holds it (the take-off and the landing are not judged, so a judged one
    // holds the least).
    let at = s
        .segments
        .iter()
        .filter(|g| !matches!(g.kind.as_str(), "take-off" | "landing"))
        .find(|g| g.min_clearance_m.is_some_and(|c| c <= least_m));
    match at {
        Some(g) => {
            let item = g.item.map(|i| format!(" (item {i})")).unwrap_or_default();
            let place = g
                .min_clearance_at
                .map(|p| format!(", at {:.5}, {:.5}", p.latitude_deg, p.longitude_deg))
                .unwrap_or_default();
            writeln!(
                out,
                "least clearance: {least_m:.1} m above the ground in segment {}{item}{place}",
                g.index
            )?;
        }
        None => writeln!(out, "least clearance: {least_m:.1} m above the ground")?,
    }
    writeln!(out)?;
    Ok(())
}

/// The scenarios' bands of energy, battery, time and point of no return, then a blank line.
fn write_bands(out: &mut impl Write, u: &Uncertainty) -> Result<()> {
    output::write_table(
        out,
        &format!(
            "Uncertainty (5th percentile / median / 95th; energy, battery and time over the {} of {} scenarios that flew the whole route)",
            u.completed_scenarios, u.samples
        ),
        &band_rows(u),
    )?;
    writeln!(out)?;
    Ok(())
}

/// The scenarios' bands, a row each.
fn band_rows(u: &Uncertainty) -> Vec<Row<'static>> {
    let t = u.point_of_no_return_s;
    let pnr = |v: Option<f64>| v.map_or("none".to_string(), mmss);
    let mut rows = vec![
        Row::new(
            "energy used",
            percentiles(u.energy_wh, &|x| format!("{x:.1}")),
            "Wh",
        ),
        Row::new(
            "battery at the end",
            percentiles(u.end_soc, &|x| format!("{:.1}", x * 100.0)),
            "%",
        ),
        Row::new("flight time", percentiles(u.duration_s, &mmss), "min:s"),
        Row::new(
            "point of no return",
            format!("{} / {} / {}", pnr(t.p5), pnr(t.p50), pnr(t.p95)),
            "min:s",
        ),
    ];
    // A failsafe's time in each percentile: `never` where that scenario does not trigger it.
    let never = |v: Option<f64>| v.map_or("never".to_string(), mmss);
    for f in &u.failsafes {
        let b = f.time_s.unwrap_or_default();
        let label = match f.kind.as_str() {
            "low" => "low-voltage failsafe",
            _ => "critical-voltage failsafe",
        };
        rows.push(Row::new(
            label,
            format!(
                "{} / {} / {} min:s at {:.1} V",
                never(b.p5),
                never(b.p50),
                never(b.p95),
                f.voltage_v
            ),
            "",
        ));
    }
    rows
}

/// The segments with the operator's item numbers when the mission came from a planner file;
/// after the first columns, the plan's peak power and battery (and the time lost at the edge of
/// the envelope when the wind or a limit slowed any segment), or with scenarios the battery at
/// each segment's end with its 5th and 95th percentiles.
fn write_segments(
    out: &mut impl Write,
    r: &MissionReport,
    scenarios: Option<&Uncertainty>,
) -> Result<()> {
    let rest = match scenarios {
        None => {
            let slowed = r.segments.iter().any(|s| s.edge.is_some());
            let lost = if slowed { "   time lost (limit)" } else { "" };
            format!(" {:>11} {:>11}{lost}", "peak power", "battery end")
        }
        Some(_) => format!(" {:>11} {:>9} {:>9}", "battery end", "p5 end", "p95 end"),
    };
    write_segments_head(out, r, &rest)?;
    for s in &r.segments {
        let rest = match scenarios {
            None => plan_cells(s),
            Some(u) => band_cells(s, u),
        };
        writeln!(out, "{}{rest}", segment_cells(r, s))?;
    }
    Ok(())
}

/// The plan's last cells of a segment's row: peak power, battery at the end, time lost.
fn plan_cells(s: &SegmentReport) -> String {
    let lost = match s.edge {
        Some(e) => format!("  {:>8.1} s ({})", s.time_lost_s, e.limit.name()),
        _ => String::new(),
    };
    format!(
        " {:>9.0} W {:>9.1} %{lost}",
        s.peak_power_w,
        s.end_soc * 100.0
    )
}

/// The scenarios' last cells of a segment's row: the plan's battery at the end, then the 5th
/// and 95th percentiles over the scenarios.
fn band_cells(s: &SegmentReport, u: &Uncertainty) -> String {
    let band = u.segments.iter().find(|b| b.index == s.index);
    let pct = |v: Option<f64>| v.map_or("-".to_string(), |x| format!("{:.1} %", x * 100.0));
    format!(
        " {:>9.1} % {:>9} {:>9}",
        s.end_soc * 100.0,
        pct(band.map(|b| b.end_soc.p5)),
        pct(band.map(|b| b.end_soc.p95)),
    )
}

/// The first columns of a segment table's head (number, item when the mission came from a
/// planner file, kind, time, distance, energy, mean power), after the title line.
fn write_segments_head(out: &mut impl Write, r: &MissionReport, rest: &str) -> Result<()> {
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
fn segment_cells(r: &MissionReport, s: &SegmentReport) -> String {
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
/// Batteries and sorties, when the route takes more than one pack or cannot be split.
fn write_sorties(out: &mut impl Write, s: &MissionSummary) -> Result<()> {
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

/// The model the plan was computed with, in one line.
fn write_model_line(out: &mut impl Write, plan: &Plan) -> Result<()> {
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
