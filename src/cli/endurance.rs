//! `aloft endurance`: hover endurance and power, best-endurance speed, best-range speed and range
//! along a course in wind, orbit endurance, the power curve (`--sweep-speed`) and endurance
//! against payload per pack (`--payload-sweep`). The answers are rendered in `endurance_view.rs`,
//! `power_curve.rs` and `payload_sweep.rs`.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::{ArgGroup, Args};

use aloft::engine::flags::EnduranceFlags;
use aloft::engine::{
    endurance, endurance_scenarios, payload_sweep, power_curve, EnduranceOptions, Error,
    PayloadCurve, PayloadSweep, Vehicle,
};

use super::output::ForceFlag;
use super::{Format, Outcome};

#[derive(Debug, Args)]
#[command(group(ArgGroup::new("curve").args(["sweep_speed", "payload_sweep"])))]
pub struct EnduranceArgs {
    /// The engine's endurance options (vehicle, pack, payload, wind, queries, curves, scenarios).
    #[command(flatten)]
    flags: EnduranceFlags,
    /// With --sweep-speed or --payload-sweep: also draw the curves to this SVG.
    #[arg(long, value_name = "SVG", requires = "curve")]
    plot: Option<PathBuf>,
    #[command(flatten)]
    force: ForceFlag,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

/// The steps of `aloft endurance`: check the chart's file, load, then one of three answers (the
/// payload sweep, the power curve, or the endurance figures with their scenarios), each drawn
/// and printed by its renderer.
pub fn run(mut args: EnduranceArgs) -> Result<Outcome> {
    args.force.check(args.plot.as_deref())?;
    let flying = aloft::engine::load_flying(&args.flags.vehicle, &mut args.flags.battery)?;
    let vehicle = flying.vehicle;
    let options = args.flags.options();
    let chart = args.plot.as_deref().map(|p| args.force.chart(p));
    if let Some(sweep) = &args.flags.payload_sweep {
        let curve = run_payload_sweep(&vehicle, &options, sweep)?;
        super::payload_sweep::render(&curve, chart, args.format)?;
    } else if let Some(step) = args.flags.sweep_speed {
        let curve = power_curve(&vehicle, &options, step)?;
        super::power_curve::render(&curve, args.flags.course, chart, args.format)?;
    } else {
        if args.format == Format::Csv {
            bail!(
                "aloft endurance writes table or json (csv with --sweep-speed or --payload-sweep)"
            );
        }
        let summary = endurance(&vehicle, &options)?;
        let uncertainty = match args.flags.scenarios.options(false) {
            Some(sc) => Some(endurance_scenarios(&vehicle, &options, &sc)?),
            None => None,
        };
        let reserve_percent = args.flags.reserve_percent;
        super::endurance_view::print(&summary, uncertainty.as_ref(), reserve_percent, args.format)?;
    }
    Ok(Outcome::Ok)
}

/// `--payload-sweep`: the engine's curve per pack; its one error of its own names the flag.
fn run_payload_sweep(
    vehicle: &Vehicle,
    options: &EnduranceOptions,
    sweep: &PayloadSweep,
) -> Result<PayloadCurve> {
    payload_sweep(vehicle, options, sweep).map_err(|e| match e {
        e @ Error::SweepTooHeavy { .. } => {
            anyhow::Error::new(e).context(format!("--payload-sweep {sweep}"))
        }
        e => e.into(),
    })
}
