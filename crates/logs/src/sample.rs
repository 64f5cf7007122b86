//! The common log model: one sample type for every source, SI units, ENU, seconds from log start.

use serde::Serialize;

/// Attitude as aerospace Z-Y-X Euler angles of the body (x forward, y right, z down) relative to
/// north-east-down, the convention of `aloft-power`'s `angle_of_attack` module: positive roll
/// lowers the right side, positive pitch raises the nose, yaw is the heading clockwise from north.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Attitude {
    /// Roll `phi`, rad.
    pub roll_rad: f64,
    /// Pitch `theta`, rad.
    pub pitch_rad: f64,
    /// Yaw (heading from north, clockwise) `psi`, rad, in (-pi, pi].
    pub yaw_rad: f64,
}

/// One instant of a flight log. Fields a source does not provide are `None`; a CSV source fills
/// every mapped channel on every row, an MCAP source fills the channels of one message per sample
/// (of one instant, for the topics aloft writes).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Sample {
    /// Time since the first sample of the log, s.
    pub time_s: f64,
    /// Position east, north, up relative to the log's origin, m.
    pub pos_enu_m: Option<[f64; 3]>,
    /// Ground velocity east, north, up, m/s.
    pub vel_enu_mps: Option<[f64; 3]>,
    /// Acceleration east, north, up (kinematic, without gravity), m/s^2.
    pub acc_enu_mps2: Option<[f64; 3]>,
    /// Attitude (aerospace Euler angles relative to NED).
    pub attitude: Option<Attitude>,
    /// Battery terminal voltage, V.
    pub voltage_v: Option<f64>,
    /// Battery current, positive when discharging, A.
    pub current_a: Option<f64>,
    /// Electrical power drawn from the battery, W: a logged power channel when mapped, else V x I.
    pub power_w: Option<f64>,
    /// Remaining charge as logged, A h (KAIST `capacity`, PX4 derived from `discharged_mah`).
    pub charge_ah: Option<f64>,
    /// State of charge as the autopilot reports it, a fraction of the pack (0-1): PX4
    /// `battery_status.remaining`, ArduPilot `BAT.RemPct` / 100. `None` where the log does not
    /// report it or reports it unknown (PX4 negative or NaN, ArduPilot 255). Carried as
    /// reported otherwise (a value outside 0-1 is the reader's to judge: `aloft live` does not
    /// believe it). Not a [`Channel`]: what a log measures is unchanged by it.
    pub soc: Option<f64>,
    /// Wind velocity east, north, up (the velocity of the air), m/s.
    pub wind_enu_mps: Option<[f64; 3]>,
    /// On the ground, as the log itself records it: PX4 `vehicle_land_detected.landed`, ArduPilot
    /// arming and landing events (`ARM`, `EV` armed, disarmed, land complete, not landed). A
    /// state holds from its record to the next; `None` where the log records none (then
    /// [`crate::ground`] detects it from height, speed and power).
    pub landed: Option<bool>,
}

impl Sample {
    /// The power of this sample: V x I when both are present, else the logged power channel.
    pub fn electrical_power_w(&self) -> Option<f64> {
        match (self.voltage_v, self.current_a) {
            (Some(v), Some(i)) => Some(v * i),
            _ => self.power_w,
        }
    }
}

/// Channels of the log model, used to say what a source provides.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Channel {
    /// [`Sample::pos_enu_m`].
    Position,
    /// [`Sample::vel_enu_mps`].
    Velocity,
    /// [`Sample::acc_enu_mps2`].
    Acceleration,
    /// [`Sample::attitude`].
    Attitude,
    /// [`Sample::voltage_v`].
    Voltage,
    /// [`Sample::current_a`].
    Current,
    /// [`Sample::power_w`].
    Power,
    /// [`Sample::charge_ah`].
    Charge,
    /// [`Sample::wind_enu_mps`].
    Wind,
}

impl Channel {
    /// Every channel, in display order.
    pub const ALL: [Channel; 9] = [
        Channel::Position,
        Channel::Velocity,
        Channel::Acceleration,
        Channel::Attitude,
        Channel::Voltage,
        Channel::Current,
        Channel::Power,
        Channel::Charge,
        Channel::Wind,
    ];

    /// The snake_case name.
    pub fn name(self) -> &'static str {
        match self {
            Channel::Position => "position",
            Channel::Velocity => "velocity",
            Channel::Acceleration => "acceleration",
            Channel::Attitude => "attitude",
            Channel::Voltage => "voltage",
            Channel::Current => "current",
            Channel::Power => "power",
            Channel::Charge => "charge",
            Channel::Wind => "wind",
        }
    }

    /// Whether `sample` carries this channel.
    pub fn present_in(self, s: &Sample) -> bool {
        match self {
            Channel::Position => s.pos_enu_m.is_some(),
            Channel::Velocity => s.vel_enu_mps.is_some(),
            Channel::Acceleration => s.acc_enu_mps2.is_some(),
            Channel::Attitude => s.attitude.is_some(),
            Channel::Voltage => s.voltage_v.is_some(),
            Channel::Current => s.current_a.is_some(),
            Channel::Power => s.power_w.is_some(),
            Channel::Charge => s.charge_ah.is_some(),
            Channel::Wind => s.wind_enu_mps.is_some(),
        }
    }
}

/// Geodetic origin of the local ENU positions of a log (first valid fix), WGS84.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GeoOrigin {
    /// Latitude, rad.
    pub lat_rad: f64,
    /// Longitude, rad.
    pub lon_rad: f64,
    /// Altitude, m.
    pub alt_m: f64,
}

/// A gap in time: an interval much longer than the log's nominal sample period.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Gap {
    /// 0-based index of the sample after the gap.
    pub index: u64,
    /// Time of the sample before the gap, s.
    pub from_s: f64,
    /// Time of the sample after the gap, s.
    pub to_s: f64,
}

/// Time going backwards between consecutive samples (an equal time is not a step back).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct NonMonotonic {
    /// 0-based index of the offending sample.
    pub index: u64,
    /// Time of the previous sample, s.
    pub previous_s: f64,
    /// Time of this sample, s.
    pub time_s: f64,
}

/// How regular the time base of a log is. Gaps and non-monotonic steps are reported here and left
/// in the data: nothing is reordered, interpolated or dropped.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct TimeReport {
    /// Samples seen.
    pub samples: u64,
    /// Last minus first time, s (0 for fewer than two samples).
    pub duration_s: f64,
    /// Median positive interval between samples (over the first intervals, see [`TimeChecker`]), s.
    pub nominal_period_s: Option<f64>,
    /// Intervals longer than [`TimeChecker::GAP_FACTOR`] nominal periods.
    pub gap_count: u64,
    /// The first [`TimeChecker::MAX_EVENTS`] gaps.
    pub gaps: Vec<Gap>,
    /// Steps where time decreased (strictly: two samples at one instant are not counted).
    pub non_monotonic_count: u64,
    /// The first [`TimeChecker::MAX_EVENTS`] such steps.
    pub non_monotonic: Vec<NonMonotonic>,
}

impl TimeReport {
    /// True when the time base has no gaps and never goes backwards.
    pub fn is_clean(&self) -> bool {
        self.gap_count == 0 && self.non_monotonic_count == 0
    }
}

/// Streaming checker of a time base, with bounded memory: the nominal period is the median of the
/// first [`Self::WARMUP`] positive intervals, and at most [`Self::MAX_EVENTS`] events of each kind
/// are kept (all are counted).
#[derive(Debug, Clone, Default)]
pub struct TimeChecker {
    report: TimeReport,
    first_s: Option<f64>,
    last_s: Option<f64>,
    max_s: f64,
    warmup: Vec<(u64, f64, f64)>,
}

impl TimeChecker {
    /// Intervals used to estimate the nominal period.
    pub const WARMUP: usize = 32;
    /// An interval longer than this many nominal periods is a gap.
    pub const GAP_FACTOR: f64 = 3.0;
    /// Events of each kind kept in the report.
    pub const MAX_EVENTS: usize = 100;

    /// A checker that has seen nothing.
    pub fn new() -> Self {
        Self::default()
    }

    /// Feed the next time stamp, s.
    pub fn push(&mut self, time_s: f64) {
        let index = self.report.samples;
        self.report.samples += 1;
        if self.first_s.is_none() {
            self.first_s = Some(time_s);
            self.max_s = time_s;
        }
        if let Some(prev) = self.last_s {
            let dt = time_s - prev;
            // Only a strictly earlier time goes back; an equal one (two records of one
            // instant) is neither a step back nor an interval of the nominal period.
            if dt < 0.0 {
                self.report.non_monotonic_count += 1;
                if self.report.non_monotonic.len() < Self::MAX_EVENTS {
                    self.report.non_monotonic.push(NonMonotonic {
                        index,
                        previous_s: prev,
                        time_s,
                    });
                }
            } else if dt > 0.0 {
                self.interval(index, prev, time_s);
            }
        }
        self.last_s = Some(time_s);
        self.max_s = self.max_s.max(time_s);
    }

    /// A positive interval: a gap once the nominal period is known, else one more interval to
    /// estimate it from.
    fn interval(&mut self, index: u64, from_s: f64, to_s: f64) {
        if let Some(nominal) = self.report.nominal_period_s {
            self.check_gap(index, from_s, to_s, nominal);
        } else {
            self.warmup.push((index, from_s, to_s));
            if self.warmup.len() == Self::WARMUP {
                self.settle();
            }
        }
    }

    fn check_gap(&mut self, index: u64, from_s: f64, to_s: f64, nominal: f64) {
        if to_s - from_s > Self::GAP_FACTOR * nominal {
            self.report.gap_count += 1;
            if self.report.gaps.len() < Self::MAX_EVENTS {
                self.report.gaps.push(Gap {
                    index,
                    from_s,
                    to_s,
                });
            }
        }
    }

    fn settle(&mut self) {
        let mut dts: Vec<f64> = self.warmup.iter().map(|(_, a, b)| b - a).collect();
        if dts.is_empty() {
            return;
        }
        dts.sort_by(f64::total_cmp);
        let nominal = dts[dts.len() / 2];
        self.report.nominal_period_s = Some(nominal);
        for (index, a, b) in std::mem::take(&mut self.warmup) {
            self.check_gap(index, a, b, nominal);
        }
    }

    /// The report so far.
    pub fn finish(mut self) -> TimeReport {
        if self.report.nominal_period_s.is_none() {
            self.settle();
        }
        if let Some(first) = self.first_s {
            self.report.duration_s = self.max_s - first;
        }
        self.report
    }
}

/// A value that was read but left out of its sample because it contradicts the other channels
/// of the row (e.g. a logged power far from V x I on an isolated row: a sensor glitch). Such
/// values are reported here, not repaired.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DroppedValue {
    /// 1-based line in the file.
    pub row: u64,
    /// The channel.
    pub channel: &'static str,
    /// The value (SI).
    pub value: f64,
}

/// A whole log in memory: samples plus what is known about the source.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Log {
    /// Where it came from (file path or a description).
    pub source: String,
    /// The samples, in file order (not re-sorted).
    pub samples: Vec<Sample>,
    /// The origin of [`Sample::pos_enu_m`] when positions were geodetic.
    pub origin: Option<GeoOrigin>,
    /// Absolute time of the first sample in the source's clock (Unix or boot time), s.
    pub start_time_s: f64,
    /// Regularity of the time base.
    pub time: TimeReport,
    /// Values dropped as isolated contradictions (count of all).
    pub dropped_count: u64,
    /// The first [`TimeChecker::MAX_EVENTS`] dropped values.
    pub dropped: Vec<DroppedValue>,
}

impl Log {
    /// Channels present in at least one sample.
    pub fn channels(&self) -> Vec<Channel> {
        Channel::ALL
            .into_iter()
            .filter(|c| self.samples.iter().any(|s| c.present_in(s)))
            .collect()
    }

    fn found(&self) -> String {
        let c = self.channels();
        if c.is_empty() {
            "none".into()
        } else {
            c.iter().map(|c| c.name()).collect::<Vec<_>>().join(", ")
        }
    }

    /// Time and electrical power of every sample that has power, or [`crate::LogError::NoPowerData`].
    pub fn power_series(&self) -> crate::Result<(Vec<f64>, Vec<f64>)> {
        let (t, p): (Vec<f64>, Vec<f64>) = self
            .samples
            .iter()
            .filter_map(|s| s.electrical_power_w().map(|p| (s.time_s, p)))
            .unzip();
        if t.is_empty() {
            return Err(crate::LogError::NoPowerData {
                source_name: self.source.clone(),
                found: self.found(),
            });
        }
        Ok((t, p))
    }

    /// Time and ENU velocity of every sample that has velocity, or [`crate::LogError::NoChannel`].
    pub fn velocity_series(&self) -> crate::Result<(Vec<f64>, Vec<[f64; 3]>)> {
        let (t, v): (Vec<f64>, Vec<[f64; 3]>) = self
            .samples
            .iter()
            .filter_map(|s| s.vel_enu_mps.map(|v| (s.time_s, v)))
            .unzip();
        if t.is_empty() {
            return Err(crate::LogError::NoChannel {
                source_name: self.source.clone(),
                channel: "velocity",
                found: self.found(),
            });
        }
        Ok((t, v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples, then the count of gaps and the index of the first, then the same of the steps
    /// back in time.
    fn events(r: &TimeReport) -> (u64, u64, Option<u64>, u64, Option<u64>) {
        let first_gap = r.gaps.first().map(|g| g.index);
        let first_back = r.non_monotonic.first().map(|n| n.index);
        (
            r.samples,
            r.gap_count,
            first_gap,
            r.non_monotonic_count,
            first_back,
        )
    }

    #[test]
    fn checker_reports_gap_and_backwards_step() {
        let mut c = TimeChecker::new();
        let mut times: Vec<f64> = (0..50).map(|i| i as f64 * 0.1).collect();
        times.push(10.0); // gap of 5.1 s
        times.push(9.5); // backwards
        times.push(9.6);
        for t in &times {
            c.push(*t);
        }
        let r = c.finish();
        assert_eq!(events(&r), (53, 1, Some(50), 1, Some(51)));
        // Duration is max - first, 10 s; 1e-12 covers the rounding of 0.1 multiples.
        assert!((r.duration_s - 10.0).abs() < 1e-12);
        assert!((r.nominal_period_s.unwrap() - 0.1).abs() < 1e-12);
    }

    /// Regression (issue 23): two records of one instant (a state and a battery message of an
    /// MCAP aloft wrote) were counted as time going back. Only a strictly earlier time is, and
    /// an equal time is no interval: it neither shortens the nominal period nor hides a gap.
    #[test]
    fn an_equal_time_is_not_a_step_back() {
        let mut c = TimeChecker::new();
        for i in 0..40 {
            let t = i as f64 * 0.1;
            c.push(t);
            c.push(t);
        }
        c.push(10.0); // gap of 6.1 s
        c.push(10.0);
        c.push(9.9); // back
        let r = c.finish();
        assert_eq!(events(&r), (83, 1, Some(80), 1, Some(82)));
        // The median of the positive intervals: 0.1 s (zero steps are no intervals).
        assert!((r.nominal_period_s.unwrap() - 0.1).abs() < 1e-12);
    }

    #[test]
    fn gaps_in_warmup_are_found_once_settled() {
        let mut c = TimeChecker::new();
        for t in [0.0, 0.1, 0.2, 5.0, 5.1, 5.2, 5.3] {
            c.push(t);
        }
        let r = c.finish();
        assert_eq!(r.gap_count, 1);
        assert!(!r.is_clean());
    }
}
