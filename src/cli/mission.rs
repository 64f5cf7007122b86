//! `aloft mission`: fly a mission file (or the built-in demonstration) with a vehicle, a pack, a
//! payload and a wind; say what it costs, whether the reserve holds and where the point of no
//! return lies; with `--samples N`, also over N scenarios drawn around the request.
//! `--replay` predicts a recorded flight instead (see `replay.rs`). The answer is rendered in
//! `mission_view.rs` (table and JSON) and `mission_chart.rs` (the chart).

use anyhow::{bail, Context, Result};

use aloft::engine::{plan_mission_with, plan_scenarios, Mission};

use super::mission_args::MissionArgs;
use super::mission_view::MissionView;
use super::{Format, Outcome};

/// The steps of `aloft mission`: check the outputs, load, plan, draw the scenarios when asked,
/// chart, print; the exit code is the plan's (1 when the plan itself is infeasible).
pub fn run(mut args: MissionArgs) -> Result<Outcome> {
    if args.replay.is_some() {
        return super::replay::run(&args);
    }
    if args.format == Format::Csv {
        bail!("aloft mission writes table or json; use --timeseries for a CSV of samples");
    }
    // Every output checked before the flight is flown (the streamed ones again as they open).
    for path in [&args.plot, &args.timeseries, &args.mcap] {
        args.force.check(path.as_deref())?;
    }
    let flying = aloft::engine::load_flying(&args.flags.vehicle, &mut args.flags.battery)?;
    let options = flying.with_failsafes(args.flags.options());
    let vehicle = flying.vehicle;
    let mission = Mission::load(args.mission.as_deref())?;
    let plan = plan_mission_with(&vehicle, &mission, &options, &args.outputs())?;
    let scenarios = match args.scenarios.options(args.plot.is_some()) {
        Some(sc) => Some(plan_scenarios(&vehicle, &mission, &options, &sc)?),
        None => None,
    };
    let view = MissionView {
        name: mission.spec().name.as_str(),
        plan: &plan,
        scenarios: scenarios.as_ref(),
    };
    if let Some(path) = &args.plot {
        super::mission_chart::draw(args.force.chart(path), &view)
            .with_context(|| format!("cannot draw {}", path.display()))?;
    }
    view.print(args.format)?;
    Ok(if plan.summary().feasible {
        Outcome::Ok
    } else {
        Outcome::Failed
    })
}
