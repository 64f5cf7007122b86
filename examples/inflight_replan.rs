//! In-flight re-planning, as a ground station would do it: while the built-in DJI M100 flies the
//! built-in demonstration mission, battery samples (voltage and current, 10 Hz) stream in; every
//! second the station re-estimates the efficiency from measured against predicted power
//! ([`InFlightEstimator`]), re-plans the mission with it and predicts the state of charge at
//! landing from the measured state of charge now plus what the rest of the re-planned mission
//! costs ([`Plan::remaining`]).
//!
//! The "real" vehicle is synthetic: the same airframe with an efficiency 12 % lower than the
//! vehicle file's (it draws 1/0.88 times the predicted power), measured with seeded noise. The
//! loop runs in simulated time, as fast as the planner goes.
//!
//! `cargo run --release --example inflight_replan`

use aloft::engine::{plan_mission, InFlightEstimator, Mission, MissionOptions, Plan, Vehicle};

/// How the loop ran: the final estimates against the synthetic truth.
#[derive(Debug, Clone, Copy)]
pub struct Outcome {
    /// Efficiency of the vehicle file.
    pub nominal_efficiency: f64,
    /// Efficiency of the synthetic vehicle.
    pub true_efficiency: f64,
    /// The last re-estimate.
    pub estimated_efficiency: f64,
    /// State of charge at landing predicted before take-off (the nominal plan).
    pub nominal_landing_soc: f64,
    /// The prediction of the re-plan at `check_s` into the flight.
    pub replanned_landing_soc: f64,
    /// The synthetic vehicle's state of charge at landing.
    pub true_landing_soc: f64,
    /// Number of re-plans.
    pub replans: usize,
    /// Flight time of the true flight, s.
    pub duration_s: f64,
}

/// Deterministic noise in [-1, 1] (a 64-bit LCG: the example needs no random crate).
struct Noise(u64);

impl Noise {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

/// The sample of `plan` at `time_s` (the one whose interval holds it).
fn sample_at(plan: &Plan, time_s: f64) -> &aloft::engine::Sample {
    let s = &plan.report().samples;
    let k = s.partition_point(|x| x.time_s < time_s).min(s.len() - 1);
    &s[k]
}

/// Fly the mission, re-planning every `replan_every_s` seconds; report the landing prediction
/// made `check_s` seconds into the flight.
pub fn run(
    out: &mut dyn std::io::Write,
    replan_every_s: f64,
    check_s: f64,
) -> Result<Outcome, Box<dyn std::error::Error>> {
    let mission = Mission::demo();
    let options = MissionOptions {
        record_samples: true,
        ..MissionOptions::default()
    };
    let nominal_vehicle = Vehicle::builtin("dji-m100")?;
    let eta0 = nominal_vehicle
        .efficiency()
        .ok_or("the M100 has a power model")?;
    let true_eta = 0.88 * eta0;
    let nominal = plan_mission(&nominal_vehicle, &mission, &options)?;
    let truth = plan_mission(
        &nominal_vehicle.with_efficiency(true_eta)?,
        &mission,
        &options,
    )?;
    let duration = truth.summary().duration_s;
    writeln!(
        out,
        "before take-off: {:.1} Wh, landing at {:.1} % (vehicle file's eta {:.4})",
        nominal.energy_wh(),
        nominal.summary().end_soc * 100.0,
        eta0
    )?;

    let mut estimator = InFlightEstimator::for_vehicle(&nominal_vehicle)?;
    let mut noise = Noise(7);
    let (mut t, dt) = (0.0, 0.1);
    let mut next_replan = replan_every_s;
    let mut replans = 0;
    let mut estimate = eta0;
    let mut at_check = None;
    while t < duration {
        t += dt;
        // A battery sample: voltage and current with 0.5 % and 2 % noise, the BMS's charge state.
        let real = sample_at(&truth, t);
        let volts = real.voltage_v * (1.0 + 0.005 * noise.next());
        let amps = real.current_a * (1.0 + 0.02 * noise.next());
        let predicted_w = sample_at(&nominal, t).power_w;
        estimator.push(t, predicted_w, volts * amps)?;
        if t + 1e-9 >= next_replan {
            next_replan += replan_every_s;
            // Keep the last estimate while the energy ratio is not yet defined or refused.
            if let Ok(Some(eta)) = estimator.efficiency() {
                estimate = eta;
            }
            let replan = plan_mission(
                &nominal_vehicle.with_efficiency(estimate)?,
                &mission,
                &options,
            )?;
            replans += 1;
            let landing = real.soc - replan.remaining(t)?.soc_used;
            if at_check.is_none() && t + 1e-9 >= check_s {
                at_check = Some(landing);
            }
            if replans % 60 == 0 {
                writeln!(
                    out,
                    "t = {t:5.0} s: soc {:5.1} %, eta {estimate:.4}, landing predicted at {:5.1} %",
                    real.soc * 100.0,
                    landing * 100.0
                )?;
            }
        }
    }
    let true_landing_soc = truth.summary().end_soc;
    writeln!(
        out,
        "landed at {:.1} %: predicted {:.1} % before take-off, {:.1} % after {check_s:.0} s of flight; eta {estimate:.4} (true {true_eta:.4})",
        true_landing_soc * 100.0,
        nominal.summary().end_soc * 100.0,
        at_check.unwrap_or(f64::NAN) * 100.0
    )?;
    Ok(Outcome {
        nominal_efficiency: eta0,
        true_efficiency: true_eta,
        estimated_efficiency: estimate,
        nominal_landing_soc: nominal.summary().end_soc,
        replanned_landing_soc: at_check.ok_or("the check time is after the landing")?,
        true_landing_soc,
        replans,
        duration_s: duration,
    })
}

#[allow(dead_code)]
fn main() -> Result<(), Box<dyn std::error::Error>> {
    run(&mut std::io::stdout(), 1.0, 60.0)?;
    Ok(())
}
