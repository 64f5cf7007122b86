//! A summary of a log, accumulated while streaming: duration, per-channel rates, energy.

use aloft_core::{trapezoid, SECONDS_PER_HOUR};
use serde::Serialize;

use crate::sample::{Channel, Sample};

/// Samples and rate of one model channel.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelStats {
    /// The channel.
    pub channel: Channel,
    /// Samples carrying it.
    pub samples: u64,
    /// First and last time, s.
    pub first_s: f64,
    /// Last time, s.
    pub last_s: f64,
}

impl ChannelStats {
    /// Mean rate, Hz (`None` below two samples, with no time span, or with a span so short that
    /// the rate is not a finite number: a subnormal one, 1e-311 s).
    pub fn rate_hz(&self) -> Option<f64> {
        let span = self.last_s - self.first_s;
        (self.samples > 1 && span > 0.0)
            .then(|| (self.samples - 1) as f64 / span)
            .filter(|r| r.is_finite())
    }
}

/// Streaming accumulator of [`ChannelStats`] and the electrical power ([`PowerAccumulator`]).
#[derive(Debug, Clone, Default)]
pub struct InfoAccumulator {
    stats: Vec<ChannelStats>,
    samples: u64,
    power: PowerAccumulator,
    t_min: Option<f64>,
    t_max: Option<f64>,
}

/// What [`InfoAccumulator::finish`] returns.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LogStats {
    /// Samples.
    pub samples: u64,
    /// Last minus first time, s.
    pub duration_s: f64,
    /// Per channel, for the channels present.
    pub channels: Vec<ChannelStats>,
    /// The electrical power.
    pub power: PowerStats,
}

/// The electrical power of a log: energy, mean and peak ([`PowerAccumulator::finish`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PowerStats {
    /// Integrated electrical energy, W h (`None` with fewer than two power samples).
    pub energy_wh: Option<f64>,
    /// Mean electrical power over the power samples, W.
    pub mean_power_w: Option<f64>,
    /// Largest electrical power, W.
    pub max_power_w: Option<f64>,
    /// Power steps skipped because time did not increase.
    pub skipped_steps: u64,
}

/// Streaming accumulator of [`PowerStats`].
///
/// Energy is the trapezoidal integral of the electrical power (V x I when both are logged, else
/// the power channel) over consecutive power samples with increasing time; steps where time does
/// not increase are skipped and counted. Intervals across gaps are integrated as they are (the
/// gaps are in the time report).
#[derive(Debug, Clone, Copy, Default)]
pub struct PowerAccumulator {
    last: Option<(f64, f64)>,
    energy_j: f64,
    samples: u64,
    sum_w: f64,
    max_w: Option<f64>,
    skipped_steps: u64,
}

impl PowerAccumulator {
    /// Add the power `p` (W) at time `t` (s): its statistics, and the energy of the step from
    /// the previous power sample.
    pub fn push(&mut self, t: f64, p: f64) {
        self.samples += 1;
        self.sum_w += p;
        self.max_w = Some(self.max_w.map_or(p, |m| m.max(p)));
        if let Some((t0, p0)) = self.last {
            if t > t0 {
                // One panel of the trapezoid rule at a time: a step where time does not
                // increase is skipped and the next panel starts from it, which a single
                // streaming `Trapezoid` cannot express.
                self.energy_j += trapezoid(&[t0, t], &[p0, p]);
            } else {
                self.skipped_steps += 1;
            }
        }
        self.last = Some((t, p));
    }

    /// The statistics.
    pub fn finish(&self) -> PowerStats {
        PowerStats {
            energy_wh: (self.samples > 1).then(|| self.energy_j / SECONDS_PER_HOUR),
            mean_power_w: (self.samples > 0).then(|| self.sum_w / self.samples as f64),
            max_power_w: self.max_w,
            skipped_steps: self.skipped_steps,
        }
    }
}

impl InfoAccumulator {
    /// Empty.
    pub fn new() -> Self {
        Self::default()
    }

    /// Add a sample.
    pub fn push(&mut self, s: &Sample) {
        self.samples += 1;
        let t = s.time_s;
        self.t_min = Some(self.t_min.map_or(t, |m| m.min(t)));
        self.t_max = Some(self.t_max.map_or(t, |m| m.max(t)));
        for c in Channel::ALL {
            if c.present_in(s) {
                self.count_channel(c, t);
            }
        }
        if let Some(p) = s.electrical_power_w() {
            self.power.push(t, p);
        }
    }

    fn count_channel(&mut self, c: Channel, t: f64) {
        match self.stats.iter_mut().find(|x| x.channel == c) {
            Some(x) => {
                x.samples += 1;
                x.first_s = x.first_s.min(t);
                x.last_s = x.last_s.max(t);
            }
            None => self.stats.push(ChannelStats {
                channel: c,
                samples: 1,
                first_s: t,
                last_s: t,
            }),
        }
    }

    /// The summary.
    pub fn finish(mut self) -> LogStats {
        self.stats.sort_by_key(|s| s.channel);
        LogStats {
            samples: self.samples,
            duration_s: match (self.t_min, self.t_max) {
                (Some(a), Some(b)) => b - a,
                _ => 0.0,
            },
            channels: self.stats,
            power: self.power.finish(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Regression (found by aloft-fuzz): two rows 2.2e-308 ms apart (a span of 2.2e-311 s) gave a
    /// rate of inf Hz, and `aloft log info` refused the log as a non-finite answer. The rate is
    /// left out instead.
    #[test]
    fn a_subnormal_time_span_has_no_rate() {
        let c = ChannelStats {
            channel: Channel::Voltage,
            samples: 2,
            first_s: 0.0,
            last_s: 1e-311,
        };
        assert_eq!(c.rate_hz(), None);
        let c = ChannelStats { last_s: 0.5, ..c };
        assert_eq!(c.rate_hz(), Some(2.0));
    }

    #[test]
    fn energy_of_constant_power() {
        let mut a = InfoAccumulator::new();
        for i in 0..=3600 {
            a.push(&Sample {
                time_s: i as f64,
                voltage_v: Some(10.0),
                current_a: Some(10.0),
                ..Sample::default()
            });
        }
        let s = a.finish();
        // 100 W for 3600 s is 100 W h; trapezoids of a constant are exact to rounding.
        assert!((s.power.energy_wh.unwrap() - 100.0).abs() < 1e-9);
        assert_eq!(s.channels.len(), 2);
        assert!((s.channels[0].rate_hz().unwrap() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn no_power_no_energy() {
        let mut a = InfoAccumulator::new();
        a.push(&Sample {
            time_s: 0.0,
            pos_enu_m: Some([0.0; 3]),
            ..Sample::default()
        });
        assert_eq!(a.finish().power.energy_wh, None);
    }
}
