//! Options shared by `aloft fit` and `aloft validate`: the flight logs and how to align power
//! with motion in them.

use std::path::{Path, PathBuf};

use clap::Args;

use aloft::engine::{AoaModel, FlightLogs};

use super::args::aoa_parser;

/// The flight logs and how to align them.
#[derive(Debug, Args)]
pub struct FlightLogArgs {
    /// Flight logs (CSV, MCAP, PX4 ULog or ArduPilot DataFlash).
    #[arg(long, required = true, num_args = 1.., value_name = "FILE")]
    pub log: Vec<PathBuf>,
    /// Log layout: kaist, px4 or a column-map TOML (default: detected).
    #[arg(long)]
    pub profile: Option<String>,
    /// Angle-of-attack model for the logged states: geometric (drag work is in the attitude;
    /// drag is fitted from the force balance) or paper (drag can be fitted from power).
    #[arg(long, value_parser = aoa_parser(), default_value = "geometric")]
    pub aoa: AoaModel,
    /// Use this lag of power behind motion (s) instead of estimating it.
    #[arg(value_parser = super::args::finite(), long, allow_negative_numbers = true, value_name = "S")]
    pub lag: Option<f64>,
    /// Search window of the lag estimate, s.
    #[arg(value_parser = super::args::finite(), long, default_value_t = 10.0, value_name = "S")]
    pub max_lag: f64,
    /// PX4 ULog / ArduPilot DataFlash: the battery instance to read (0: the first).
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub battery_instance: u8,
}

impl FlightLogArgs {
    /// The engine's description of the logs.
    pub fn logs(&self) -> FlightLogs {
        FlightLogs {
            logs: self.log.clone(),
            profile: self.profile.clone(),
            aoa: self.aoa,
            lag_s: self.lag,
            max_lag_s: self.max_lag,
            battery_instance: self.battery_instance,
        }
    }
}

/// The file name of a path, for tables.
pub fn file_name(p: &str) -> &str {
    Path::new(p)
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or(p)
}
