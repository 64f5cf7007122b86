//! `aloft live`: a flight followed as it flies, an answer every `--every` seconds: JSON lines, a
//! status panel refreshed in place on a terminal, or a line of text per update otherwise; the
//! validation replay (`--route log`) ends with how the predictions did.

use std::io::{IsTerminal, Write};

use anyhow::Result;
use clap::{Args, ValueEnum};

use aloft::engine::flags::{LiveFlags, LiveTask};
use aloft::engine::{
    follow_live, replay_live, Error, FailsafeCheck, LiveCheck, LiveCheckpoint, LiveRecorder,
    LiveSummary, LiveUpdate,
};

use super::output::{fixed, fixed_or_dash, percentiles};
use super::Outcome;

/// Output of `aloft live`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, ValueEnum)]
pub enum LiveFormat {
    /// A status panel refreshed in place on a terminal, a line of text per update otherwise.
    #[default]
    Table,
    /// JSON lines: one object per update, then `{"summary": ...}` (or `{"check": ...}`).
    Json,
}

#[derive(Debug, Args)]
pub struct LiveArgs {
    /// The engine's options (source, route, vehicle, update interval).
    #[command(flatten)]
    flags: LiveFlags,
    /// Output format.
    #[arg(long, value_enum, default_value_t = LiveFormat::Table)]
    format: LiveFormat,
    /// Also record every update in this MCAP file for Foxglove (topic `/aloft/live`).
    #[arg(long, value_name = "FILE")]
    mcap: Option<std::path::PathBuf>,
    #[command(flatten)]
    force: super::output::ForceFlag,
}

pub fn run(mut args: LiveArgs) -> Result<Outcome> {
    let flying = aloft::engine::load_flying(&args.flags.vehicle, &mut args.flags.battery)?;
    let vehicle = flying.vehicle;
    let mut task = args.flags.request()?;
    // The pack file's `[failsafe]`, watched where the flags give none.
    if let (LiveTask::Follow { request, .. }, Some(f)) = (&mut task, &flying.failsafe) {
        request.pack_failsafe_v = [f.low_voltage_v, f.critical_voltage_v];
    }
    let stdout = std::io::stdout();
    let panel = args.format == LiveFormat::Table
        && stdout.is_terminal()
        && matches!(task, LiveTask::Follow { .. });
    let mut out = stdout.lock();
    let mut view = View {
        format: args.format,
        panel,
        drawn: 0,
        header: true,
    };
    let force = args.force.force;
    let mut recorder = args
        .mcap
        .as_deref()
        .map(|p| LiveRecorder::create(p, force))
        .transpose()?;
    let mut emit = |u: &LiveUpdate| -> Result<(), Error> {
        if let Some(r) = &mut recorder {
            r.record(u)?;
        }
        view.write(&mut out, u).map_err(|source| Error::Io {
            origin: "standard output".to_string(),
            source,
        })
    };
    match task {
        LiveTask::Validate(request) => {
            let check = replay_live(&vehicle, &request, &mut emit)?;
            match args.format {
                LiveFormat::Json => writeln!(out, "{}", serde_json::json!({ "check": check }))?,
                LiveFormat::Table => render_check(&mut out, &check)?,
            }
        }
        LiveTask::Follow { source, request } => {
            // Ctrl-C (SIGINT) and SIGTERM end the stream: the summary is printed and the exit
            // is 0, as at the end of a log.
            let mut source = match super::signals::stop_flag() {
                Some(stop) => source.open_until(stop)?,
                None => source.open()?,
            };
            let summary = follow_live(&vehicle, &request, &mut source, &mut emit)?;
            match args.format {
                LiveFormat::Json => writeln!(out, "{}", serde_json::json!({ "summary": summary }))?,
                LiveFormat::Table => render_summary(&mut out, &summary)?,
            }
        }
    }
    if let Some(r) = recorder {
        r.finish()?;
    }
    Ok(Outcome::Ok)
}

/// How updates are shown.
struct View {
    format: LiveFormat,
    /// A panel redrawn in place (a terminal).
    panel: bool,
    /// Lines of the panel on screen.
    drawn: usize,
    header: bool,
}

impl View {
    fn write(&mut self, out: &mut impl Write, u: &LiveUpdate) -> std::io::Result<()> {
        match self.format {
            LiveFormat::Json => {
                let line = serde_json::to_string(u).map_err(std::io::Error::from)?;
                writeln!(out, "{line}")
            }
            LiveFormat::Table if self.panel => {
                let lines = panel(u);
                if self.drawn > 0 {
                    // Up to the panel's first line, and clear to the end of the screen.
                    write!(out, "\x1b[{}F\x1b[J", self.drawn)?;
                }
                self.drawn = lines.len();
                for l in lines {
                    writeln!(out, "{l}")?;
                }
                out.flush()
            }
            LiveFormat::Table => {
                let validation = u.measured_remaining_wh.is_some();
                if std::mem::take(&mut self.header) {
                    let head = if validation { HEADER } else { FOLLOW_HEADER };
                    writeln!(out, "{head}")?;
                }
                match validation {
                    true => writeln!(out, "{}", row(u)),
                    false => writeln!(out, "{}", follow_row(u)),
                }
            }
        }
    }
}

/// `p5 / p50 / p95` of a band, scaled, or `-`.
fn band(b: Option<aloft::engine::Percentiles>, scale: f64, digits: usize) -> String {
    percentiles(b, &|x| fixed(scale * x, digits))
}

/// The status panel of one update.
fn panel(u: &LiveUpdate) -> Vec<String> {
    let state = match (u.link_lost, u.in_air) {
        (true, _) => "LINK LOST (last estimate)",
        (false, true) => "in the air",
        (false, false) => "on the ground",
    };
    let item = u
        .mission_item
        .map_or_else(String::new, |i| format!(" · item {i}"));
    let mode = u.mode.as_deref().unwrap_or("-");
    let wind = match (u.wind_mps, u.wind_from_deg) {
        (Some(s), Some(d)) => format!("{s:.1} m/s from {d:.0} deg"),
        _ => "-".to_string(),
    };
    let pnr = match u.point_of_no_return_s {
        Some(s) if s < 0.0 => format!("passed {:.0} s ago", -s),
        Some(s) => format!("in {s:.0} s"),
        None => "none (home is always in reach)".to_string(),
    };
    let mut lines = vec![
        format!("aloft live · t {:.1} s · {mode}{item} · {state}", u.time_s),
        format!(
            "battery   {} %{}{}   used {:.2} Wh   power {} W   eta {:.4}",
            fixed_or_dash(u.soc.map(|s| 100.0 * s), 1),
            u.soc_band.map_or_else(String::new, |b| format!(
                " (p5-p95 {:.0}-{:.0} %)",
                100.0 * b.p5,
                100.0 * b.p95
            )),
            u.reported_soc.map_or_else(String::new, |r| format!(
                "; the vehicle says {:.0} %",
                100.0 * r
            )),
            u.energy_used_wh,
            fixed_or_dash(u.power_w, 0),
            u.efficiency
        ),
        format!("wind      {wind}"),
        format!(
            "ahead     {} Wh (p5 / p50 / p95); naive {} Wh",
            band(u.remaining_wh, 1.0, 2),
            fixed_or_dash(u.naive_remaining_wh, 2)
        ),
        format!(
            "landing   {} % state of charge",
            band(u.landing_soc, 100.0, 1)
        ),
        format!("no return {pnr}"),
        format!("advice    {}", u.advice.unwrap_or("-")),
    ];
    // Each failsafe that comes before home, in the place of the advice it shapes.
    for f in u.failsafes.iter().filter(|f| f.before_home) {
        let t = f.time_s.unwrap_or_default();
        let at = |v: Option<f64>| v.map_or("never".to_string(), |s| format!("{s:.0} s"));
        let threshold = match f.unit {
            "fraction" => format!("{:.0} %", 100.0 * f.threshold),
            unit => format!("{} {unit}", aloft_core::Num(f.threshold)),
        };
        lines.insert(
            lines.len() - 1,
            format!(
                "failsafe  {} ({} {threshold}) in {} / {} / {} (p5 / p50 / p95)",
                f.kind,
                f.source,
                at(t.p5),
                at(t.p50),
                at(t.p95)
            ),
        );
    }
    if let Some(note) = &u.note {
        lines.push(format!("note      {note}"));
    }
    lines
}

/// The column heads of the lines of a followed flight.
const FOLLOW_HEADER: &str = "  time s  mode        item  air   soc %  used Wh  power W     eta  wind m/s  from  remaining Wh p5 / p50 / p95  landing % p5 / p50   pnr s  advice";

/// One update of a followed flight as a line of text.
fn follow_row(u: &LiveUpdate) -> String {
    let landing = u.landing_soc.map_or_else(
        || "-".to_string(),
        |l| format!("{:.1} / {:.1}", 100.0 * l.p5, 100.0 * l.p50),
    );
    format!(
        "{:>8.1}  {:<10} {:>5}  {:<4} {:>6} {:>8.2} {:>8} {:>7.4} {:>9} {:>5} {:>29} {:>18} {:>7}  {}{}",
        u.time_s,
        u.mode.as_deref().unwrap_or("-"),
        u.mission_item.map_or_else(|| "-".to_string(), |i| i.to_string()),
        if u.in_air { "yes" } else { "no" },
        fixed_or_dash(u.soc.map(|s| 100.0 * s), 1),
        u.energy_used_wh,
        fixed_or_dash(u.power_w, 0),
        u.efficiency,
        fixed_or_dash(u.wind_mps, 1),
        fixed_or_dash(u.wind_from_deg, 0),
        band(u.remaining_wh, 1.0, 2),
        landing,
        fixed_or_dash(u.point_of_no_return_s, 0),
        u.advice.unwrap_or("-"),
        if u.link_lost { " (link lost)" } else { "" }
    )
}

/// The column heads of the lines of the validation replay.
const HEADER: &str =
    "  time s   used Wh  power W     eta   remaining Wh p5 / p50 / p95  naive Wh  truth Wh";

/// One update of the validation replay as a line of text.
fn row(u: &LiveUpdate) -> String {
    format!(
        "{:>8.1} {:>9.2} {:>8} {:>7.4} {:>29} {:>9} {:>9}",
        u.time_s,
        u.energy_used_wh,
        fixed_or_dash(u.power_w, 2),
        u.efficiency,
        band(u.remaining_wh, 1.0, 2),
        fixed_or_dash(u.naive_remaining_wh, 2),
        fixed_or_dash(u.measured_remaining_wh, 2)
    )
}

/// How a followed stream ended.
fn render_summary(out: &mut impl Write, s: &LiveSummary) -> Result<()> {
    let skipped = match s.skipped.as_str() {
        "" => String::new(),
        text => format!("; skipped {text}"),
    };
    writeln!(
        out,
        "\n{} updates over {:.0} s; {} mission(s) received, {} restart(s) of the vehicle{skipped}",
        s.updates, s.duration_s, s.missions, s.reboots
    )?;
    Ok(())
}

/// How the predictions did against the measured rest.
fn render_check(out: &mut impl Write, c: &LiveCheck) -> Result<()> {
    writeln!(
        out,
        "\n{}: {} updates over {:.0} s; p5-p95 held the measured rest in {:.0} % of them",
        c.file,
        c.updates,
        c.duration_s,
        100.0 * c.band_coverage
    )?;
    writeln!(out, "{CHECK_HEADER}")?;
    for p in &c.checkpoints {
        writeln!(out, "{}", checkpoint_row(p))?;
    }
    for f in &c.failsafes {
        render_failsafe_check(out, f)?;
    }
    Ok(())
}

/// One voltage failsafe of the validation replay: when the log crossed it, and the predictions
/// made before.
fn render_failsafe_check(out: &mut impl Write, f: &FailsafeCheck) -> Result<()> {
    let crossed = f.crossed_s.map_or_else(
        || "the log's 5 s average never fell below it".to_string(),
        |t| format!("the log's 5 s average fell below it at {t:.1} s"),
    );
    writeln!(
        out,
        "\n{} failsafe {:.2} V ({}): {crossed}",
        f.kind, f.threshold, f.source
    )?;
    if f.crossed_s.is_some() {
        writeln!(out, "{FAILSAFE_HEADER}")?;
    }
    for p in &f.checkpoints {
        let predicted = p.predicted_s.map_or_else(
            || "-".to_string(),
            |b| {
                format!(
                    "{} ({} - {})",
                    fixed_or_dash(b.p50, 0),
                    fixed_or_dash(b.p5, 0),
                    fixed_or_dash(b.p95, 0)
                )
            },
        );
        writeln!(
            out,
            "{:>7} {:>8.1} {:>8.0} {:>22} {:>8} {:>8} {:>11} {:>8}",
            p.before,
            p.log_time_s,
            p.actual_s,
            predicted,
            fixed_or_dash(p.error_s, 0),
            fixed_or_dash(p.naive_s, 0),
            fixed_or_dash(p.naive_error_s, 0),
            if p.in_band { "yes" } else { "no" }
        )?;
    }
    Ok(())
}

/// The column heads of a failsafe's checkpoints.
const FAILSAFE_HEADER: &str =
    " before   time s  actual s  predicted s p50 (p5 - p95)  error s  naive s  naive err s  in band";

/// The column heads of the checkpoints.
const CHECK_HEADER: &str = "    at   time s    error %  naive err %  in band";

/// One checkpoint as a line of text.
fn checkpoint_row(p: &LiveCheckpoint) -> String {
    let in_band = if p.in_band { "yes" } else { "no" };
    let naive = p
        .naive_error_percent
        .map_or_else(|| "-".to_string(), |e| format!("{e:+.2}"));
    format!(
        "{:>6} {:>8.1} {:>+10.2} {naive:>12} {in_band:>8}",
        p.at, p.time_s, p.error_percent
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The panel says the state, the battery, the band and the advice, and that the link is lost.
    #[test]
    fn the_panel_shows_the_answer_and_a_lost_link() {
        let mut u = sample();
        let lines = panel(&u);
        assert_eq!(lines.len(), 7);
        assert_eq!(
            lines[0],
            "aloft live · t 12.5 s · AUTO · item 3 · in the air"
        );
        assert!(lines[1].contains("60.0 %") && lines[1].contains("used 10.00 Wh"));
        assert_eq!(lines[2], "wind      4.0 m/s from 270 deg");
        assert!(lines[3].contains("4.50 / 5.00 / 5.50 Wh"));
        assert_eq!(lines[5], "no return in 42 s");
        assert_eq!(lines[6], "advice    continue");
        u.link_lost = true;
        u.point_of_no_return_s = Some(-10.0);
        let lines = panel(&u);
        assert!(lines[0].ends_with("LINK LOST (last estimate)"));
        assert_eq!(lines[5], "no return passed 10 s ago");
        // The estimate's band, the vehicle's own figure and a failsafe before home.
        u.soc_band = Some(aloft::engine::SocBand {
            p5: 0.55,
            p95: 0.65,
        });
        u.reported_soc = Some(0.48);
        u.failsafes = vec![aloft::engine::LiveFailsafe {
            kind: "low",
            source: "BAT_LOW_THR".to_string(),
            threshold: 0.15,
            unit: "fraction",
            time_s: Some(aloft::engine::TimeBand {
                p5: Some(190.0),
                p50: Some(230.0),
                p95: None,
            }),
            before_home: true,
            naive_time_s: None,
        }];
        let lines = panel(&u);
        assert!(
            lines[1].starts_with("battery   60.0 % (p5-p95 55-65 %); the vehicle says 48 %"),
            "{}",
            lines[1]
        );
        assert_eq!(
            lines[6],
            "failsafe  low (BAT_LOW_THR 15 %) in 190 s / 230 s / never (p5 / p50 / p95)"
        );
        assert_eq!(lines[7], "advice    continue");
    }

    fn sample() -> LiveUpdate {
        let band = |p5: f64, p50: f64, p95: f64| aloft::engine::Percentiles { p5, p50, p95 };
        LiveUpdate {
            time_s: 12.5,
            in_air: true,
            mode: Some("AUTO".to_string()),
            mission_item: Some(3),
            soc: Some(0.6),
            energy_used_wh: 10.0,
            power_w: Some(300.0),
            efficiency: 0.8,
            wind_mps: Some(4.0),
            wind_from_deg: Some(270.0),
            remaining_wh: Some(band(4.5, 5.0, 5.5)),
            landing_soc: Some(band(0.3, 0.32, 0.34)),
            point_of_no_return_s: Some(42.0),
            advice: Some("continue"),
            ..LiveUpdate::default()
        }
    }
}
