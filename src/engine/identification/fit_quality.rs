//! How good a fit is: a verdict (`good`, `usable`, `poor`) with its reasons, from what the fit
//! and its logs show. The worst rule decides.
//!
//! | rule | good | usable | poor |
//! |---|---|---|---|
//! | NRMSE of the fitted model (normalised by the mean measured power) | at most 10 % | at most 20 % (the power seed's Table I, full model: 7-18 %) | above 20 % |
//! | a log's alignment: correlation of power with tilt at the lag | 0.5 or more | 0.3 to 0.5 | below 0.3 |
//! | a log's lag: power leading motion (a negative lag) | - | any lead beyond 0.5 s (suspect: a power that responds before the motion asks for it) | - |
//! | samples used | 500 or more | 100 to 500 | fewer than 100 |
//! | the speed covered: the 95th percentile of the fitted airspeeds against the vehicle's `max_speed_mps` | at least 70 % of it | below (the drag is extrapolated) | - |
//! | the climb covered: the 95th percentile of the fitted climb rates against `max_climb_rate_mps` | at least 50 % of it | below | - |
//!
//! The thresholds are stated, not tuned: the NRMSE bands are the paper's own accuracy; the
//! alignment bands are where a lag estimate from a correlation that weak is as likely wrong as
//! right (the flugdrohne log aligned at -2.6 s with correlation 0.28, issue 35).
//!
//! `aloft validate` judges each flight by the same rules ([`judge_flight`]: the NRMSE, the
//! alignment, the samples) and one more: a model whose NRMSE is above that of a constant at the
//! flight's own mean power explains none of the flight's changes of power, and is `poor` ("the
//! model loses to a constant at the flight's mean power"); so is a flight compared over less
//! than 90 % of its time in the air (the rest of its log has no velocity or attitude to pair
//! with its power). The whole validation is its worst flight.

use serde::Serialize;

use aloft_power::FitSample;

/// The verdict of a fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FitQuality {
    /// Within the paper's accuracy, on well-aligned logs that cover the envelope.
    Good,
    /// Fit for planning with the reasons in mind.
    Usable,
    /// Not to be trusted: see the reasons.
    Poor,
}

/// How one log of a fit was aligned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Alignment<'a> {
    /// The log.
    pub file: &'a str,
    /// Lag of power behind motion applied, s.
    pub lag_s: f64,
    /// Correlation of power with tilt at that lag (`None` when the lag was given).
    pub correlation: Option<f64>,
}

/// What the fit covered of the vehicle's envelope, where the vehicle has one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Envelope {
    /// The vehicle's largest speed, m/s.
    pub max_speed_mps: f64,
    /// The vehicle's largest climb rate, m/s.
    pub max_climb_rate_mps: f64,
}

/// The verdicts of a judgement and their reasons; the worst decides.
#[derive(Debug, Default)]
struct Verdict {
    worst: Option<FitQuality>,
    reasons: Vec<String>,
}

impl Verdict {
    fn say(&mut self, q: FitQuality, reason: String) {
        self.worst = Some(self.worst.map_or(q, |w| w.max(q)));
        self.reasons.push(reason);
    }

    fn done(self) -> (FitQuality, Vec<String>) {
        (self.worst.unwrap_or(FitQuality::Good), self.reasons)
    }

    /// The NRMSE rule, `pct` in percent.
    fn nrmse(&mut self, pct: f64) {
        let q = match pct {
            p if p <= 10.0 => FitQuality::Good,
            p if p <= 20.0 => FitQuality::Usable,
            _ => FitQuality::Poor,
        };
        self.say(
            q,
            format!(
                "NRMSE {pct:.1} % (good at most 10 %, usable at most 20 %, the power seed's 7-18 %)"
            ),
        );
    }

    /// The alignment rules of one log: its correlation and a lead of power over motion.
    fn alignment(&mut self, l: &Alignment<'_>) {
        let name = l.file.rsplit('/').next().unwrap_or(l.file);
        if let Some(c) = l.correlation {
            if c < 0.3 {
                self.say(
                    FitQuality::Poor,
                    format!("{name}: aligned at {:.2} s with correlation {c:.2} (below 0.3: the lag is a guess)", l.lag_s),
                );
            } else if c < 0.5 {
                self.say(
                    FitQuality::Usable,
                    format!(
                        "{name}: aligned at {:.2} s with correlation {c:.2} (below 0.5)",
                        l.lag_s
                    ),
                );
            }
        }
        if l.lag_s < -0.5 {
            self.say(
                FitQuality::Usable,
                format!(
                    "{name}: power leads motion by {:.2} s (suspect: check the log's clocks)",
                    -l.lag_s
                ),
            );
        }
    }

    /// The samples rule.
    fn samples(&mut self, n: usize) {
        if n < 100 {
            self.say(FitQuality::Poor, format!("{n} samples (fewer than 100)"));
        } else if n < 500 {
            self.say(FitQuality::Usable, format!("{n} samples (fewer than 500)"));
        }
    }
}

/// The verdict and why, from the fit's NRMSE (a fraction), its logs and the samples it used.
pub fn judge_fit(
    nrmse: f64,
    logs: &[Alignment<'_>],
    samples: &[FitSample],
    envelope: Option<Envelope>,
) -> (FitQuality, Vec<String>) {
    let mut v = Verdict::default();
    v.nrmse(100.0 * nrmse);
    for l in logs {
        v.alignment(l);
    }
    v.samples(samples.len());
    let p95 = |f: &dyn Fn(&FitSample) -> f64| {
        let mut x: Vec<f64> = samples.iter().map(f).filter(|x| x.is_finite()).collect();
        x.sort_by(f64::total_cmp);
        x.get(((x.len() as f64 - 1.0) * 0.95).round().max(0.0) as usize)
            .copied()
    };
    let speed = p95(&|s| s.state.airspeed_mps);
    let climb = p95(&|s| s.state.climb_rate_mps.abs());
    match (envelope, speed) {
        (Some(e), Some(s)) if s < 0.7 * e.max_speed_mps => v.say(
            FitQuality::Usable,
            format!(
                "drag fitted up to {s:.1} m/s (95 % of the samples), used up to {:.1} m/s (the vehicle's max_speed_mps)",
                e.max_speed_mps
            ),
        ),
        (None, Some(s)) => v.say(
            FitQuality::Good,
            format!("samples up to {s:.1} m/s airspeed (95 %)"),
        ),
        _ => {}
    }
    if let (Some(e), Some(c)) = (envelope, climb) {
        if c < 0.5 * e.max_climb_rate_mps {
            v.say(
                FitQuality::Usable,
                format!(
                    "climb fitted up to {c:.1} m/s (95 %), flown up to {:.1} m/s (max_climb_rate_mps)",
                    e.max_climb_rate_mps
                ),
            );
        }
    }
    v.done()
}

/// What [`judge_flight`] judges of one validated flight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlightJudged<'a> {
    /// How the flight's log was aligned.
    pub alignment: Alignment<'a>,
    /// NRMSE of the model, percent.
    pub nrmse_percent: f64,
    /// NRMSE of a constant at the flight's mean power, percent.
    pub constant_nrmse_percent: f64,
    /// Samples compared.
    pub samples: usize,
    /// The airborne time compared (where the log has samples to compare), s.
    pub compared_s: f64,
    /// The airborne time, s.
    pub airborne_s: f64,
}

/// The verdict on one flight of `aloft validate` and why: the fit's rules for the NRMSE, the
/// alignment and the samples, and `poor` where the model loses to a constant at the flight's
/// mean power (see the module docs).
pub fn judge_flight(f: &FlightJudged<'_>) -> (FitQuality, Vec<String>) {
    let mut v = Verdict::default();
    v.nrmse(f.nrmse_percent);
    if f.nrmse_percent > f.constant_nrmse_percent {
        v.say(
            FitQuality::Poor,
            format!(
                "the model loses to a constant at the flight's mean power (NRMSE {:.1} % against {:.1} %)",
                f.nrmse_percent, f.constant_nrmse_percent
            ),
        );
    }
    // A flight compared over a small part of its time in the air says little of the rest.
    if f.compared_s < 0.9 * f.airborne_s {
        v.say(
            FitQuality::Poor,
            format!(
                "compared over {:.1} s of its {:.1} s in the air: the rest has no velocity or attitude to pair with its power",
                f.compared_s, f.airborne_s
            ),
        );
    }
    v.alignment(&f.alignment);
    v.samples(f.samples);
    v.done()
}

#[cfg(test)]
mod tests {
    use super::*;
    use aloft_power::FlightState;

    fn samples(n: usize, speed: f64, climb: f64) -> Vec<FitSample> {
        (0..n)
            .map(|k| {
                FitSample::new(
                    FlightState::new(speed * k as f64 / n as f64, 0.0, 0.0, climb),
                    100.0,
                )
            })
            .collect()
    }

    fn log(lag_s: f64, c: Option<f64>) -> Alignment<'static> {
        Alignment {
            file: "a/b.ulg",
            lag_s,
            correlation: c,
        }
    }

    const ENVELOPE: Envelope = Envelope {
        max_speed_mps: 12.0,
        max_climb_rate_mps: 3.0,
    };

    /// A good fit, a misaligned log and a slow-only flight each get the verdict its rule says.
    #[test]
    fn verdicts_follow_their_rules() {
        let good = judge_fit(
            0.08,
            &[log(0.2, Some(0.8))],
            &samples(1000, 12.0, 2.0),
            Some(ENVELOPE),
        );
        assert_eq!(good.0, FitQuality::Good, "{:?}", good.1);
        let misaligned = judge_fit(
            0.08,
            &[log(-2.6, Some(0.28))],
            &samples(1000, 12.0, 2.0),
            Some(ENVELOPE),
        );
        assert_eq!(misaligned.0, FitQuality::Poor);
        assert!(misaligned
            .1
            .iter()
            .any(|r| r.contains("-2.60 s") && r.contains("0.28")));
        assert!(misaligned.1.iter().any(|r| r.contains("leads motion")));
        let slow = judge_fit(
            0.08,
            &[log(0.2, Some(0.8))],
            &samples(1000, 5.0, 2.0),
            Some(ENVELOPE),
        );
        assert_eq!(slow.0, FitQuality::Usable);
        assert!(
            slow.1
                .iter()
                .any(|r| r.contains("drag fitted up to 4.7 m/s") && r.contains("12.0 m/s")),
            "{:?}",
            slow.1
        );
        let rough = judge_fit(
            0.338,
            &[log(0.2, Some(0.8))],
            &samples(1000, 12.0, 2.0),
            Some(ENVELOPE),
        );
        assert_eq!(rough.0, FitQuality::Poor);
        let few = judge_fit(
            0.05,
            &[log(0.2, None)],
            &samples(50, 12.0, 2.0),
            Some(ENVELOPE),
        );
        assert_eq!(few.0, FitQuality::Poor);
    }

    /// A validated flight: good within the NRMSE band, poor where a constant at its mean power
    /// does better, and the fit's alignment rule (a lead of power beyond 0.5 s).
    #[test]
    fn a_flight_that_loses_to_a_constant_is_poor() {
        let flight = |nrmse, constant, lag_s| FlightJudged {
            alignment: log(lag_s, Some(0.8)),
            nrmse_percent: nrmse,
            constant_nrmse_percent: constant,
            samples: 1000,
            compared_s: 60.0,
            airborne_s: 60.0,
        };
        assert_eq!(judge_flight(&flight(8.0, 20.0, 0.1)).0, FitQuality::Good);
        let (q, why) = judge_flight(&flight(8.0, 7.0, 0.1));
        assert_eq!(q, FitQuality::Poor);
        assert!(
            why.iter().any(|r| r.contains("loses to a constant")),
            "{why:?}"
        );
        let (q, why) = judge_flight(&flight(8.0, 20.0, -0.6));
        assert_eq!(q, FitQuality::Usable);
        assert!(
            why.iter().any(|r| r.contains("leads motion by 0.60 s")),
            "{why:?}"
        );
    }
}
