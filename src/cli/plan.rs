//! `aloft plan`: the missions to fly, one file per battery, at the speeds the wind favours,
//! beside the mission as given.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;

use aloft::engine::flags::PlanFlags;
use aloft::engine::{answers, plan_to_fly, FlyPlan, Mission, PlanFigures};

use super::output::{self, mmss};
use super::{Format, Outcome};

#[derive(Debug, Args)]
pub struct PlanArgs {
    /// Mission file (any format `aloft mission` reads; the files written are in its format).
    /// Without it, the built-in demonstration.
    pub mission: Option<PathBuf>,
    /// The mission's options and how the plan is made.
    #[command(flatten)]
    pub flags: PlanFlags,
    /// Folder to write the files into (created if missing), named MISSION-K-of-N.EXT.
    #[arg(short = 'o', long, value_name = "DIR")]
    pub output: PathBuf,
    /// Overwrite files that exist.
    #[arg(long)]
    pub force: bool,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    pub format: Format,
}

pub fn run(mut args: PlanArgs) -> Result<Outcome> {
    if args.format == Format::Csv {
        bail!("aloft plan writes table or json");
    }
    let flying =
        aloft::engine::load_flying(&args.flags.mission.vehicle, &mut args.flags.mission.battery)?;
    let vehicle = flying.vehicle;
    let mission = Mission::load(args.mission.as_deref())?;
    let request = args.flags.request()?;
    let mut plan = match plan_to_fly(&vehicle, &mission, &request) {
        Ok(p) => p,
        // No plan keeps the reserve: the answer of an infeasible mission, no file written.
        Err(aloft::Error::NoPlan { reason }) => {
            let mut out = std::io::stdout().lock();
            match args.format {
                Format::Json => writeln!(out, "{}", answers::no_plan_answer(&reason))?,
                _ => writeln!(out, "NO PLAN: {reason}")?,
            }
            return Ok(Outcome::Failed);
        }
        Err(e) => return Err(e.into()),
    };
    plan.write(&args.output, args.force)?;
    let mut out = std::io::stdout().lock();
    match args.format {
        Format::Json => output::write_json(&mut out, &plan)?,
        Format::Table | Format::Csv => write_table(&mut out, &plan)?,
    }
    Ok(Outcome::Ok)
}

/// The plan beside the mission as given, its sorties and what changed.
fn write_table(out: &mut impl Write, plan: &FlyPlan) -> Result<()> {
    let row = |out: &mut dyn Write, name: &str, f: &PlanFigures| -> std::io::Result<()> {
        writeln!(
            out,
            "  {name:<10} {:>9} {:>10.1} {:>11}",
            f.batteries,
            f.energy_wh,
            mmss(f.duration_s)
        )
    };
    writeln!(out, "Air: {}", plan.air.describe())?;
    writeln!(
        out,
        "  {:<10} {:>9} {:>10} {:>11}",
        "", "batteries", "energy Wh", "time min:s"
    )?;
    if let Some(given) = &plan.as_given {
        row(out, "as given", given)?;
    }
    let figures = PlanFigures {
        batteries: plan.batteries,
        energy_wh: plan.energy_wh,
        duration_s: plan.duration_s,
    };
    row(out, "plan", &figures)?;
    writeln!(out)?;
    let sc = &plan.scenarios;
    let sp = &sc.spreads;
    writeln!(
        out,
        "Sorties cut to land with the reserve in {} % of {} scenarios of the day (1 sd: wind \
         {:.1} m/s and {:.0}\u{b0}, pack capacity {:.0} %, power {:.0} %, payload {:.1} kg)",
        100.0 * plan.confidence,
        sc.samples,
        sp.wind_speed_sd_mps,
        sp.wind_from_sd_deg,
        sp.capacity_sd_percent,
        sp.power_sd_percent,
        sp.payload_sd_kg
    )?;
    writeln!(
        out,
        "   #  items      energy     min:s  battery end  at landing p5-p95  with reserve  point of no return  file"
    )?;
    for (k, s) in plan.sorties.iter().enumerate() {
        let items = match (s.first_item, s.last_item) {
            (Some(a), Some(b)) => format!("{a}-{b}"),
            _ => "-".to_string(),
        };
        let pnr = s
            .point_of_no_return_s
            .map_or_else(|| "none".to_string(), mmss);
        let band = s.landing_soc.map_or_else(
            || "-".to_string(),
            |b| format!("{:.1}-{:.1} %", 100.0 * b.p5, 100.0 * b.p95),
        );
        let share = s
            .p_reserve
            .map_or_else(|| "-".to_string(), |p| format!("{:.1} %", 100.0 * p));
        writeln!(
            out,
            "  {:>2}  {items:<9} {:>6.1} Wh {:>7} {:>10.1} %  {band:>17}  {share:>12}  {pnr:>18}  {}",
            k + 1,
            s.energy_wh,
            mmss(s.duration_s),
            100.0 * s.end_soc,
            s.file
        )?;
    }
    let speeds = &plan.changes.speeds;
    if !speeds.is_empty() {
        writeln!(out)?;
        let legs = match speeds.len() {
            1 => "1 leg".to_string(),
            n => format!("{n} legs"),
        };
        writeln!(out, "{legs} at the speed of least energy in their wind")?;
    }
    for a in &plan.changes.angles {
        writeln!(
            out,
            "survey at item {} turned to the wind: grid angle {:.1}\u{b0} -> {:.1}\u{b0}",
            a.item, a.from_deg, a.to_deg
        )?;
    }
    for k in &plan.changes.angles_kept {
        writeln!(
            out,
            "survey at item {} kept at {:.1}\u{b0}: {}",
            k.item, k.angle_deg, k.why
        )?;
    }
    for note in &plan.notes {
        writeln!(out, "note: {note}")?;
    }
    if plan.changes.cut_inside_legs {
        writeln!(
            out,
            "sorties end inside legs, where each pack reaches the reserve at the plan's confidence"
        )?;
    }
    Ok(())
}
