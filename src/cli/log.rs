//! `aloft log info`: summarise a flight log (CSV through a profile, PX4 tables, or MCAP).

use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use serde::Serialize;

use aloft_logs::{
    estimate_lag_s, open_log, resample_uniform, Channel, InfoAccumulator, LogFormat, McapOptions,
    McapTime, Profile, TimeReport,
};

use super::output::{self, Row};
use super::{Format, Outcome};

#[derive(Debug, Args)]
pub struct LogArgs {
    #[command(subcommand)]
    command: LogCommand,
}

#[derive(Debug, Subcommand)]
enum LogCommand {
    /// Duration, rates, channels or columns found, energy used (integrated V x I) and the
    /// regularity of the time base.
    Info(InfoArgs),
}

/// Options shared by the commands that read a log.
#[derive(Debug, Args)]
pub struct ReadOptions {
    /// CSV profile: kaist, px4, or a column-map TOML file. Default: recognised from the file
    /// (MCAP by magic, KAIST by header, PX4 by table name).
    #[arg(long, value_name = "PROFILE")]
    pub profile: Option<String>,
    /// MCAP: decode only these topics (repeatable); default: chosen by message type.
    #[arg(long = "topic", value_name = "TOPIC")]
    pub topics: Vec<String>,
    /// MCAP: use the header stamps instead of the recording's log time.
    #[arg(long)]
    pub header_time: bool,
    /// MCAP: take sensor_msgs/BatteryState current as positive while discharging (the message
    /// definition says negative; some drivers publish the opposite).
    #[arg(long)]
    pub battery_current_positive: bool,
}

impl ReadOptions {
    pub fn profile(&self) -> Result<Option<Profile>> {
        self.profile
            .as_deref()
            .map(Profile::resolve)
            .transpose()
            .map_err(Into::into)
    }

    pub fn mcap(&self) -> McapOptions {
        let mut o = McapOptions {
            topics: self.topics.clone(),
            ..McapOptions::default()
        };
        if self.header_time {
            o.time = McapTime::HeaderStamp;
        }
        o.decode.battery_current_positive_discharging = self.battery_current_positive;
        o
    }
}

#[derive(Debug, Args)]
struct InfoArgs {
    /// The log: a CSV file, one PX4 topic table (or the tables' common prefix), or an MCAP file.
    file: PathBuf,
    #[command(flatten)]
    read: ReadOptions,
    /// Also estimate the lag of power behind ground speed by cross-correlation (search +-N s).
    #[arg(long, value_name = "MAX_S")]
    lag: Option<f64>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

#[derive(Serialize)]
struct ChannelJson {
    channel: Channel,
    samples: u64,
    #[serde(skip_serializing_if = "Option::is_none")]
    rate_hz: Option<f64>,
}

#[derive(Serialize)]
struct TopicJson {
    topic: String,
    schema: String,
    message_encoding: String,
    messages: u64,
    decoded: u64,
    #[serde(skip_serializing_if = "Option::is_none")]
    rate_hz: Option<f64>,
    used_for: Vec<Channel>,
}

#[derive(Serialize)]
struct TimeJson {
    #[serde(skip_serializing_if = "Option::is_none")]
    nominal_period_s: Option<f64>,
    gap_count: u64,
    non_monotonic_count: u64,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    gaps: Vec<aloft_logs::sample::Gap>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    non_monotonic: Vec<aloft_logs::sample::NonMonotonic>,
}

impl From<&TimeReport> for TimeJson {
    fn from(r: &TimeReport) -> Self {
        Self {
            nominal_period_s: r.nominal_period_s,
            gap_count: r.gap_count,
            non_monotonic_count: r.non_monotonic_count,
            gaps: r.gaps.iter().take(10).copied().collect(),
            non_monotonic: r.non_monotonic.iter().take(10).copied().collect(),
        }
    }
}

#[derive(Serialize)]
struct LagJson {
    lag_s: f64,
    correlation: f64,
    correlation_at_zero: f64,
    at_window_edge: bool,
}

#[derive(Serialize)]
struct InfoJson {
    file: String,
    format: LogFormat,
    #[serde(skip_serializing_if = "Option::is_none")]
    profile: Option<String>,
    samples: u64,
    duration_s: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    start_time_s: Option<f64>,
    channels: Vec<ChannelJson>,
    #[serde(skip_serializing_if = "Option::is_none")]
    columns: Option<Vec<String>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    topics: Option<Vec<TopicJson>>,
    power_available: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    energy_wh: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    mean_power_w: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    max_power_w: Option<f64>,
    time: TimeJson,
    /// Values left out as isolated contradictions (e.g. power far from V x I on one row).
    dropped_values: u64,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    dropped: Vec<aloft_logs::DroppedValue>,
    #[serde(skip_serializing_if = "Option::is_none")]
    lag: Option<LagJson>,
}

pub fn run(args: LogArgs) -> Result<Outcome> {
    match args.command {
        LogCommand::Info(a) => info(a),
    }
}

fn info(args: InfoArgs) -> Result<Outcome> {
    let profile = args.read.profile()?;
    let mut reader = open_log(&args.file, profile.as_ref(), &args.read.mcap())?;
    let mut acc = InfoAccumulator::new();
    let (mut tp, mut p, mut tv, mut v) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for s in reader.by_ref() {
        let s = s?;
        acc.push(&s);
        if args.lag.is_some() {
            if let Some(w) = s.electrical_power_w() {
                tp.push(s.time_s);
                p.push(w);
            }
            if let Some(u) = s.vel_enu_mps {
                tv.push(s.time_s);
                v.push(u[0].hypot(u[1]));
            }
        }
    }
    let stats = acc.finish();
    let time = reader.time_report();
    let (dropped_values, mut dropped) = reader.dropped();
    dropped.truncate(10);
    let lag = match args.lag {
        None => None,
        Some(max) => {
            let file = args.file.display().to_string();
            if p.is_empty() {
                anyhow::bail!("{file}: --lag needs power data (voltage and current), which the log does not have");
            }
            if v.is_empty() {
                anyhow::bail!("{file}: --lag needs velocity data, which the log does not have");
            }
            let dt = time.nominal_period_s.unwrap_or(0.1);
            let (t0p, pu) = resample_uniform(&tp, &p, dt)?;
            let (t0v, vu) = resample_uniform(&tv, &v, dt)?;
            // Align both grids on their common span.
            let off_p = ((t0v - t0p) / dt).round().max(0.0) as usize;
            let off_v = ((t0p - t0v) / dt).round().max(0.0) as usize;
            let n = pu
                .len()
                .saturating_sub(off_p)
                .min(vu.len().saturating_sub(off_v));
            let e = estimate_lag_s(&pu[off_p..off_p + n], &vu[off_v..off_v + n], dt, max)
                .context("lag estimation")?;
            Some(LagJson {
                lag_s: e.lag_s,
                correlation: e.correlation,
                correlation_at_zero: e.correlation_at_zero,
                at_window_edge: e.at_window_edge,
            })
        }
    };
    let json = InfoJson {
        file: args.file.display().to_string(),
        format: reader.format(),
        profile: match reader.format() {
            LogFormat::Mcap => None,
            LogFormat::Px4Csv => Some("px4".into()),
            LogFormat::Csv => Some(profile.map_or("kaist".into(), |p| p.name())),
        },
        samples: stats.samples,
        duration_s: stats.duration_s,
        start_time_s: reader.start_time_s(),
        channels: stats
            .channels
            .iter()
            .map(|c| ChannelJson {
                channel: c.channel,
                samples: c.samples,
                rate_hz: c.rate_hz(),
            })
            .collect(),
        columns: reader.columns().map(|c| c.to_vec()),
        topics: reader.topics().map(|t| {
            t.iter()
                .map(|t| TopicJson {
                    topic: t.topic.clone(),
                    schema: t.schema.clone(),
                    message_encoding: t.message_encoding.clone(),
                    messages: t.messages,
                    decoded: t.decoded,
                    rate_hz: t.rate_hz(),
                    used_for: t.used_for.clone(),
                })
                .collect()
        }),
        power_available: stats.energy_wh.is_some() || stats.mean_power_w.is_some(),
        energy_wh: stats.energy_wh,
        mean_power_w: stats.mean_power_w,
        max_power_w: stats.max_power_w,
        time: TimeJson::from(&time),
        dropped_values,
        dropped,
        lag,
    };
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    match args.format {
        Format::Json => output::write_json(&mut out, &json)?,
        Format::Table | Format::Csv => write_table(&mut out, &json)?,
    }
    Ok(Outcome::Ok)
}

fn write_table(out: &mut impl Write, j: &InfoJson) -> Result<()> {
    let fmt = match j.format {
        LogFormat::Csv => "CSV",
        LogFormat::Px4Csv => "PX4 CSV tables",
        LogFormat::Mcap => "MCAP",
    };
    let title = match &j.profile {
        Some(p) => format!("{} ({fmt}, profile {p})", j.file),
        None => format!("{} ({fmt})", j.file),
    };
    let mut rows = vec![
        Row::new("samples", j.samples.to_string(), ""),
        Row::new("duration", format!("{:.2}", j.duration_s), "s"),
    ];
    if let Some(p) = j.time.nominal_period_s {
        rows.push(Row::new("nominal period", format!("{p:.4}"), "s"));
    }
    rows.push(Row::new(
        "gaps (> 3 periods)",
        j.time.gap_count.to_string(),
        "",
    ));
    rows.push(Row::new(
        "non-monotonic time steps",
        j.time.non_monotonic_count.to_string(),
        "",
    ));
    if j.dropped_values > 0 {
        rows.push(Row::new(
            "values dropped (contradict V x I)",
            j.dropped_values.to_string(),
            "",
        ));
    }
    match j.energy_wh {
        Some(e) => rows.push(Row::new("energy used (V x I)", format!("{e:.2}"), "Wh")),
        None => rows.push(Row::new("energy used", "n/a: no power data".into(), "")),
    }
    if let Some(p) = j.mean_power_w {
        rows.push(Row::new("mean power", format!("{p:.1}"), "W"));
    }
    if let Some(p) = j.max_power_w {
        rows.push(Row::new("max power", format!("{p:.1}"), "W"));
    }
    if let Some(l) = &j.lag {
        rows.push(Row::new(
            "power lag behind ground speed",
            format!(
                "{:.2} (r = {:.2}{})",
                l.lag_s,
                l.correlation,
                if l.at_window_edge {
                    ", at window edge"
                } else {
                    ""
                }
            ),
            "s",
        ));
    }
    output::write_table(out, &title, &rows)?;
    writeln!(out, "channels")?;
    for c in &j.channels {
        let rate = c.rate_hz.map_or("-".into(), |r| format!("{r:.2} Hz"));
        writeln!(
            out,
            "  {:<13} {:>9} samples  {rate}",
            c.channel.name(),
            c.samples
        )?;
    }
    if let Some(cols) = &j.columns {
        writeln!(out, "columns ({}): {}", cols.len(), cols.join(", "))?;
    }
    if let Some(topics) = &j.topics {
        writeln!(out, "topics")?;
        for t in topics {
            let rate = t.rate_hz.map_or("-".into(), |r| format!("{r:.2} Hz"));
            let used: Vec<&str> = t.used_for.iter().map(|c| c.name()).collect();
            let used = if used.is_empty() {
                "not decoded".to_string()
            } else {
                format!("-> {}", used.join(", "))
            };
            writeln!(
                out,
                "  {} [{} {}] {} messages, {rate}, {used}",
                t.topic, t.schema, t.message_encoding, t.messages
            )?;
        }
    }
    for g in j.time.gaps.iter().take(5) {
        writeln!(
            out,
            "gap: {:.3} s -> {:.3} s (sample {})",
            g.from_s, g.to_s, g.index
        )?;
    }
    for d in j.dropped.iter().take(5) {
        writeln!(out, "dropped: row {} {} = {:.1}", d.row, d.channel, d.value)?;
    }
    for n in j.time.non_monotonic.iter().take(5) {
        writeln!(
            out,
            "time goes back: {:.3} s -> {:.3} s (sample {})",
            n.previous_s, n.time_s, n.index
        )?;
    }
    Ok(())
}
