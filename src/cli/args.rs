//! What the command line adds to the engine's option groups ([`aloft::engine::flags`]).

use anyhow::{bail, Result};

use aloft::engine::flags::ScenarioFlags;

/// Refuse `--samples` with an option it does not apply to.
pub fn refuse_samples(scenarios: &ScenarioFlags, other: &str) -> Result<()> {
    if scenarios.samples.is_some() {
        bail!("--samples draws scenarios of a planned answer; it cannot be used with {other}");
    }
    Ok(())
}
