//! The arguments of `aloft mission`: the engine's mission and scenario options
//! ([`aloft::engine::flags`]) and what only the command line has (the output format, the files
//! to write, the replay of a log).

use std::path::PathBuf;

use clap::{Args, ValueEnum};

use aloft::engine::flags::{finite, MissionFlags, ScenarioFlags};
use aloft::engine::MissionOutputs;

use super::output::ForceFlag;
use super::Format;

#[derive(Debug, Args)]
pub struct MissionArgs {
    /// Mission file: an aloft mission in TOML or JSON (see fixtures/missions/example.toml), a
    /// QGroundControl .plan or a Mission Planner .waypoints file (QGC WPL 110), recognised from
    /// its content. Without it, the built-in demonstration: a survey with four lines and an
    /// orbit in a 6 m/s breeze.
    pub mission: Option<PathBuf>,
    /// The engine's mission options (vehicle, pack, payload, wind, reserve, ...).
    #[command(flatten)]
    pub flags: MissionFlags,
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
    #[command(flatten)]
    pub force: ForceFlag,
    /// Replay a recorded flight instead of planning: predict its energy from the trajectory alone
    /// (velocities and accelerations through the planner's trim and power model; no power data)
    /// and print it next to the measured energy (integral of V x I over the same span).
    #[arg(
        long,
        value_name = "LOG",
        conflicts_with_all = ["mission", "timeseries", "plot", "mcap", "samples"]
    )]
    pub replay: Option<PathBuf>,
    /// Log layout for --replay: kaist, px4 or a column-map TOML (default: detected).
    #[arg(long, requires = "replay")]
    pub profile: Option<String>,
    /// Lag of the logged power behind the motion for --replay, s (default: estimated by
    /// cross-correlating power with tilt). Only the measured side is shifted.
    #[arg(value_parser = finite(),
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
    #[arg(value_parser = finite(), long, default_value_t = 1.0, value_name = "S")]
    pub acceleration_window: f64,
    /// Monte-Carlo scenarios (--samples N and the spreads).
    #[command(flatten)]
    pub scenarios: ScenarioFlags,
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
    /// The files to write as the flight is flown.
    pub fn outputs(&self) -> MissionOutputs {
        MissionOutputs {
            timeseries: self.timeseries.clone(),
            mcap: self.mcap.clone(),
            plot: self.plot.is_some(),
            force: self.force.force,
        }
    }
}
