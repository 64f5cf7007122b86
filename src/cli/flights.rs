//! Options and loading shared by `aloft fit` and `aloft validate`: flight logs aligned for the
//! power model.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};

use aloft::identify::{align_flight, AlignOptions, AlignedFlight};
use aloft::power::AoaInput;

/// Angle-of-attack model used to evaluate the logged states.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum AoaArg {
    /// Exact geometry from attitude and air velocity (drag work is in the attitude; drag is fitted
    /// from the force balance).
    Geometric,
    /// The paper's eqs (3)-(4) (drag can be fitted from power).
    Paper,
}

/// The flight logs and how to align them.
#[derive(Debug, Args)]
pub struct FlightLogs {
    /// Flight logs (CSV or MCAP).
    #[arg(long, required = true, num_args = 1.., value_name = "FILE")]
    pub log: Vec<PathBuf>,
    /// Log layout: kaist, px4 or a column-map TOML (default: detected).
    #[arg(long)]
    pub profile: Option<String>,
    /// Angle-of-attack model for the logged states.
    #[arg(long, value_enum, default_value_t = AoaArg::Geometric)]
    pub aoa: AoaArg,
    /// Use this lag of power behind motion (s) instead of estimating it.
    #[arg(long, allow_negative_numbers = true, value_name = "S")]
    pub lag: Option<f64>,
    /// Search window of the lag estimate, s.
    #[arg(long, default_value_t = 10.0, value_name = "S")]
    pub max_lag: f64,
}

impl FlightLogs {
    /// Read every log, align power with motion, and set the angle-of-attack model.
    pub fn load(&self) -> Result<Vec<(AlignedFlight, aloft_logs::Log)>> {
        let profile = self
            .profile
            .as_deref()
            .map(aloft_logs::Profile::resolve)
            .transpose()
            .context("--profile")?;
        let align = AlignOptions {
            max_lag_s: self.max_lag,
            lag_s: self.lag,
            ..AlignOptions::default()
        };
        let mut out = Vec::new();
        for path in &self.log {
            let log = aloft_logs::read_log(path, profile.as_ref(), &Default::default())
                .with_context(|| format!("cannot read {}", path.display()))?;
            let mut flight = align_flight(&log, &align)?;
            if self.aoa == AoaArg::Paper {
                for s in &mut flight.samples {
                    s.state.aoa = AoaInput::Paper;
                }
            }
            out.push((flight, log));
        }
        Ok(out)
    }
}

/// The file name of a path, for tables.
pub fn file_name(p: &str) -> &str {
    Path::new(p)
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or(p)
}
