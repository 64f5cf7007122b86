//! Argument parsing and dispatch. Each subcommand lives in its own module and does three things:
//! its arguments become an engine request (`aloft::engine`), the engine answers, and the answer is
//! rendered as a table, JSON or CSV. Exit codes are decided here, once.

mod convert;
mod endurance;
mod endurance_view;
mod fit;
mod flights;
mod live;
mod log;
#[cfg(feature = "logbook")]
pub(crate) mod logbook;
mod mission;
mod mission_args;
mod mission_chart;
mod mission_view;
mod output;
mod pack;
mod payload_sweep;
mod plan;
mod plot;
mod power;
mod power_curve;
mod propulsion;
mod replay;
mod rotor;
#[cfg(feature = "serve")]
mod serve;
mod signals;
mod terrain;
mod validate;
mod vehicles;

use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

/// Energy and feasibility of multirotor flights.
///
/// Exit codes: 0 success, 1 infeasible mission or failed check, 2 bad input.
#[derive(Debug, Parser)]
#[command(name = "aloft", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Electrical power of a flight state from the four-term model (power seed eqs 3-14).
    Power(power::PowerArgs),
    /// Propulsion chain at hover: rotor speed, currents, pack heat and flight time (propulsion seed).
    Propulsion(propulsion::PropulsionArgs),
    /// Rotor inertia, time constants and simulated step response (transient seed).
    Rotor(rotor::RotorArgs),
    /// List the built-in vehicles.
    Vehicles(vehicles::VehiclesArgs),
    /// Summarise a flight log: duration, rates, channels, energy used, time-base gaps.
    Log(log::LogArgs),
    /// Convert a flight log (CSV, MCAP, PX4 ULog, ArduPilot DataFlash) to MCAP that Foxglove
    /// displays.
    Convert(convert::ConvertArgs),
    /// Fit the power model of a vehicle to flight logs (lag alignment, Gauss-Newton, drag from the force balance).
    Fit(fit::FitArgs),
    /// Validate a vehicle's power model against flight logs (NRMSE per airspeed band, energy error).
    Validate(validate::ValidateArgs),
    /// Battery packs from their own logs: `aloft pack fit LOG... -o pack.toml`.
    Pack(pack::PackArgs),
    /// Follow a flight as it flies: the energy of the rest, its spread, and what to do.
    Live(live::LiveArgs),
    /// The operator's logbook: flights, vehicles and packs from their own logs, in one SQLite
    /// file.
    #[cfg(feature = "logbook")]
    Logbook(logbook::LogbookArgs),
    /// Fly a mission (or the built-in demo): energy per segment, battery, reserve, point of no return.
    Mission(Box<mission_args::MissionArgs>),
    /// Hover and orbit endurance, best-endurance and best-range speeds, the power curve.
    Endurance(endurance::EnduranceArgs),
    /// The missions to fly: one file per battery, cut where each pack reaches the reserve, at
    /// the speeds the wind favours.
    Plan(Box<plan::PlanArgs>),
    /// The ground's height at places (LAT,LON...), from elevation tiles read offline (SRTM .hgt,
    /// .hgt.zip, WGS 84 GeoTIFF in --terrain DIR).
    Terrain(terrain::TerrainArgs),
    /// A local web server whose JSON API is the command line (`/api/mission`, `/api/endurance`,
    /// `/api/vehicles`).
    #[cfg(feature = "serve")]
    Serve(serve::ServeArgs),
}

/// Output format of a result.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Default)]
pub enum Format {
    /// Aligned text for a terminal.
    #[default]
    Table,
    /// JSON with snake_case keys carrying their unit (the scripting contract).
    Json,
    /// Comma-separated values with a header.
    Csv,
}

/// What a successful run concluded.
pub enum Outcome {
    /// Everything fine: exit 0.
    Ok,
    /// A mission is infeasible or a check failed: exit 1.
    #[allow(dead_code)]
    Failed,
}

pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return usage_error(e),
    };
    // Every command but the server (which stops on its own handling of the signals): an
    // interrupted command leaves no file behind.
    #[cfg(feature = "serve")]
    let serving = matches!(cli.command, Command::Serve(_));
    #[cfg(not(feature = "serve"))]
    let serving = false;
    if !serving {
        signals::install();
    }
    let result = match cli.command {
        Command::Power(args) => power::run(args),
        Command::Propulsion(args) => propulsion::run(args),
        Command::Rotor(args) => rotor::run(args),
        Command::Vehicles(args) => vehicles::run(args),
        Command::Log(args) => log::run(args),
        Command::Convert(args) => convert::run(args),
        Command::Fit(args) => fit::run(args),
        Command::Validate(args) => validate::run(args),
        Command::Live(args) => live::run(args),
        #[cfg(feature = "logbook")]
        Command::Logbook(args) => logbook::run(args),
        Command::Pack(args) => pack::run(args),
        Command::Mission(args) => mission::run(*args),
        Command::Endurance(args) => endurance::run(args),
        Command::Plan(args) => plan::run(*args),
        Command::Terrain(args) => terrain::run(args),
        #[cfg(feature = "serve")]
        Command::Serve(args) => serve::run(args),
    };
    match result {
        Ok(Outcome::Ok) => ExitCode::SUCCESS,
        Ok(Outcome::Failed) => ExitCode::from(1),
        Err(e) if output::is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("aloft: error: {}", message(&e));
            ExitCode::from(2)
        }
    }
}

/// Help and version go to stdout (exit 0); a usage error is one stderr line (exit 2).
fn usage_error(e: clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    match e.kind() {
        ErrorKind::DisplayHelp
        | ErrorKind::DisplayVersion
        | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            let _ = e.print();
            ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2))
        }
        _ => {
            eprintln!("aloft: error: {}", usage_line(&e.render().to_string()));
            ExitCode::from(2)
        }
    }
}

/// Clap's message without its usage hints, on one line: the first paragraph, lines joined.
fn usage_line(rendered: &str) -> String {
    let first = rendered.split("\n\n").next().unwrap_or(rendered);
    let text = first.strip_prefix("error: ").unwrap_or(first);
    text.split('\n')
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(" ")
}

/// An engine error as the command line says it (without its `aloft: error: ` prefix).
#[cfg(feature = "serve")]
fn engine_message(e: aloft::Error) -> String {
    message(&anyhow::Error::from(e))
}

/// The error and its causes on one line, each cause once: engine errors already say their
/// cause in their own message, so a cause whose text is already there is not repeated.
fn message(e: &anyhow::Error) -> String {
    aloft::engine::error_line(e.as_ref())
}
