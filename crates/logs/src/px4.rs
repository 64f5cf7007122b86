//! PX4 per-topic CSV tables (`<log>_<topic>_0.csv`, as written by `ulog2csv`) joined onto one
//! time base.
//!
//! The time base is `vehicle_local_position` (position, velocity, acceleration, NED). At each of
//! its time stamps, `battery_status` (voltage, current) and `vehicle_attitude` (quaternion, body
//! FRD to NED) are interpolated linearly between their two neighbouring samples (yaw along the
//! shorter arc). Nothing is extrapolated, and no interpolation bridges a topic interval longer than
//! [`Px4Options::max_bracket_s`]: such instants get `None` for that topic's channels, so gaps stay
//! visible. Each table is streamed with a two-sample window: memory does not grow with the log.

use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use crate::column_map::ColumnMap;
use crate::csv_read::{wrap_pi, CsvSamples};
use crate::error::{LogError, Result};
use crate::sample::{Attitude, Sample, TimeReport};

/// Topic tables the PX4 profile reads.
pub const PX4_TOPICS: [&str; 3] = [
    "vehicle_local_position",
    "battery_status",
    "vehicle_attitude",
];

/// Topic names `ulog2csv` writes for the flights in the data set, used to find a log's prefix.
const KNOWN_TOPICS: [&str; 8] = [
    "vehicle_local_position",
    "battery_status",
    "vehicle_attitude",
    "vehicle_global_position",
    "actuator_motors",
    "vehicle_air_data",
    "hover_thrust_estimate",
    "vehicle_land_detected",
];

/// Options of the PX4 join.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Px4Options {
    /// Longest interval of a topic across which values are interpolated, s.
    pub max_bracket_s: f64,
}

impl Default for Px4Options {
    fn default() -> Self {
        // Battery status comes at 5 Hz; 1 s tolerates a few dropped messages, not a gap.
        Self { max_bracket_s: 1.0 }
    }
}

/// The common prefix of a PX4 log's tables, from one table's path, `<log>_params.csv`, or the
/// prefix itself. `None` when the name does not look like a PX4 table and no
/// `<path>_vehicle_local_position_0.csv` exists.
pub fn px4_prefix(path: &Path) -> Option<PathBuf> {
    let name = path.file_name()?.to_str()?;
    for topic in KNOWN_TOPICS {
        for suffix in [format!("_{topic}_0.csv"), format!("_{topic}_1.csv")] {
            if let Some(stem) = name.strip_suffix(&suffix) {
                return Some(path.with_file_name(stem));
            }
        }
    }
    if let Some(stem) = name.strip_suffix("_params.csv") {
        return Some(path.with_file_name(stem));
    }
    if table(path, PX4_TOPICS[0]).exists() {
        return Some(path.to_path_buf());
    }
    None
}

/// The path of one topic table of a prefix.
pub fn table(prefix: &Path, topic: &str) -> PathBuf {
    let mut name = prefix
        .file_name()
        .map(|n| n.to_os_string())
        .unwrap_or_default();
    name.push(format!("_{topic}_0.csv"));
    prefix.with_file_name(name)
}

type Source = CsvSamples<BufReader<File>>;

fn open_table(prefix: &Path, topic: &str, map: &ColumnMap) -> Result<Source> {
    let p = table(prefix, topic);
    if !p.exists() {
        return Err(LogError::Px4TopicMissing {
            prefix: prefix.to_path_buf(),
            expected: p,
        });
    }
    CsvSamples::open(&p, map)
}

/// One interpolated topic: a two-sample window over its stream, in absolute time.
struct Track {
    src: Source,
    prev: Option<(f64, Sample)>,
    next: Option<(f64, Sample)>,
    done: bool,
}

impl Track {
    fn new(src: Source) -> Self {
        Self {
            src,
            prev: None,
            next: None,
            done: false,
        }
    }

    fn pull(&mut self) -> Result<()> {
        match self.src.next() {
            Some(Ok(s)) => {
                let t = self.src.start_time_s().unwrap_or(0.0) + s.time_s;
                self.prev = self.next.take();
                self.next = Some((t, s));
            }
            Some(Err(LogError::Empty { .. })) | None => {
                self.prev = self.next.take();
                self.done = true;
            }
            Some(Err(e)) => return Err(e),
        }
        Ok(())
    }

    /// The topic's value at absolute time `t`, if bracketed by two samples at most `max` apart.
    fn at(&mut self, t: f64, max: f64) -> Result<Option<Sample>> {
        if self.next.is_none() && !self.done {
            self.pull()?;
        }
        while !self.done && self.next.as_ref().is_some_and(|(tn, _)| *tn < t) {
            self.pull()?;
        }
        let (Some((ta, a)), Some((tb, b))) = (&self.prev, &self.next) else {
            // Exactly on the first sample.
            return Ok(self
                .next
                .as_ref()
                .filter(|(tn, _)| (tn - t).abs() < 1e-9)
                .map(|(_, s)| *s));
        };
        if !(*ta <= t && t <= *tb) || tb - ta > max {
            return Ok(None);
        }
        let w = if tb > ta { (t - ta) / (tb - ta) } else { 0.0 };
        Ok(Some(lerp_sample(a, b, w)))
    }
}

fn lerp(a: f64, b: f64, w: f64) -> f64 {
    a + (b - a) * w
}

fn lerp_opt(a: Option<f64>, b: Option<f64>, w: f64) -> Option<f64> {
    Some(lerp(a?, b?, w))
}

fn lerp_vec(a: Option<[f64; 3]>, b: Option<[f64; 3]>, w: f64) -> Option<[f64; 3]> {
    let (a, b) = (a?, b?);
    Some([
        lerp(a[0], b[0], w),
        lerp(a[1], b[1], w),
        lerp(a[2], b[2], w),
    ])
}

/// Linear interpolation of every channel present in both samples; yaw along the shorter arc.
pub fn lerp_sample(a: &Sample, b: &Sample, w: f64) -> Sample {
    Sample {
        time_s: lerp(a.time_s, b.time_s, w),
        pos_enu_m: lerp_vec(a.pos_enu_m, b.pos_enu_m, w),
        vel_enu_mps: lerp_vec(a.vel_enu_mps, b.vel_enu_mps, w),
        acc_enu_mps2: lerp_vec(a.acc_enu_mps2, b.acc_enu_mps2, w),
        attitude: match (a.attitude, b.attitude) {
            (Some(x), Some(y)) => Some(Attitude {
                roll_rad: lerp(x.roll_rad, y.roll_rad, w),
                pitch_rad: lerp(x.pitch_rad, y.pitch_rad, w),
                yaw_rad: wrap_pi(x.yaw_rad + wrap_pi(y.yaw_rad - x.yaw_rad) * w),
            }),
            _ => None,
        },
        voltage_v: lerp_opt(a.voltage_v, b.voltage_v, w),
        current_a: lerp_opt(a.current_a, b.current_a, w),
        power_w: lerp_opt(a.power_w, b.power_w, w),
        charge_ah: lerp_opt(a.charge_ah, b.charge_ah, w),
        soc: lerp_opt(a.soc, b.soc, w),
        wind_enu_mps: lerp_vec(a.wind_enu_mps, b.wind_enu_mps, w),
        // A state, not a quantity: the earlier record's holds until the later one.
        landed: if w < 1.0 { a.landed } else { b.landed },
    }
}

/// Joined samples of a PX4 log, on the `vehicle_local_position` time base.
pub struct Px4Samples {
    prefix: PathBuf,
    base: Source,
    battery: Track,
    attitude: Track,
    options: Px4Options,
    failed: bool,
}

impl Px4Samples {
    /// Open the three tables of the log that `path` belongs to (any of its tables or the prefix).
    pub fn open(path: &Path, options: Px4Options) -> Result<Self> {
        let prefix = px4_prefix(path).ok_or_else(|| LogError::UnsupportedFormat {
            path: path.to_path_buf(),
            reason: "not a PX4 topic table (<log>_<topic>_0.csv) nor the prefix of one".into(),
        })?;
        Ok(Self {
            base: open_table(&prefix, PX4_TOPICS[0], &ColumnMap::px4_local_position())?,
            battery: Track::new(open_table(
                &prefix,
                PX4_TOPICS[1],
                &ColumnMap::px4_battery(),
            )?),
            attitude: Track::new(open_table(
                &prefix,
                PX4_TOPICS[2],
                &ColumnMap::px4_attitude(),
            )?),
            prefix,
            options,
            failed: false,
        })
    }

    /// The log's common prefix.
    pub fn prefix(&self) -> &Path {
        &self.prefix
    }

    /// Absolute (boot) time of the first sample, s.
    pub fn start_time_s(&self) -> Option<f64> {
        self.base.start_time_s()
    }

    /// Time report of the joined stream (the base topic).
    pub fn time_report(&self) -> TimeReport {
        self.base.time_report()
    }

    /// Time reports of each topic table read so far.
    pub fn topic_reports(&self) -> Vec<(&'static str, TimeReport)> {
        vec![
            (PX4_TOPICS[0], self.base.time_report()),
            (PX4_TOPICS[1], self.battery.src.time_report()),
            (PX4_TOPICS[2], self.attitude.src.time_report()),
        ]
    }

    fn join(&mut self, mut s: Sample) -> Result<Sample> {
        let t = self.base.start_time_s().unwrap_or(0.0) + s.time_s;
        let max = self.options.max_bracket_s;
        if let Some(b) = self.battery.at(t, max)? {
            s.voltage_v = b.voltage_v;
            s.current_a = b.current_a;
        }
        if let Some(a) = self.attitude.at(t, max)? {
            s.attitude = a.attitude;
        }
        Ok(s)
    }
}

impl Iterator for Px4Samples {
    type Item = Result<Sample>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.failed {
            return None;
        }
        let r = match self.base.next()? {
            Ok(s) => self.join(s),
            Err(e) => Err(e),
        };
        if r.is_err() {
            self.failed = true;
        }
        Some(r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prefix_from_any_table_name() {
        let p = Path::new("/d/log_20_2023-6-7-10-52-56_battery_status_0.csv");
        assert_eq!(
            px4_prefix(p).unwrap(),
            PathBuf::from("/d/log_20_2023-6-7-10-52-56")
        );
        let p = Path::new("/d/1x_wo_Last_5m_params.csv");
        assert_eq!(px4_prefix(p).unwrap(), PathBuf::from("/d/1x_wo_Last_5m"));
        assert_eq!(
            table(Path::new("/d/1x_wo_Last_5m"), "vehicle_attitude"),
            PathBuf::from("/d/1x_wo_Last_5m_vehicle_attitude_0.csv")
        );
        assert!(px4_prefix(Path::new("/nonexistent/flight.csv")).is_none());
    }

    /// Write the three tables of a small PX4 log under a fresh directory; `battery_header`
    /// replaces the battery table's header.
    fn write_log(name: &str, battery_header: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("aloft-px4-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let prefix = dir.join("flight");
        let mut pos = String::from("timestamp,x,y,z,vx,vy,vz,ax,ay,az\n");
        let mut bat = format!("{battery_header}\n");
        let mut att = String::from("timestamp,q[0],q[1],q[2],q[3]\n");
        for i in 0..5u64 {
            let t = 1_000_000 + i * 100_000;
            pos.push_str(&format!("{t},0,0,-1,0,0,0,0,0,0\n"));
            bat.push_str(&format!("{t},16.0,12.0,16.0\n"));
            att.push_str(&format!("{t},1,0,0,0\n"));
        }
        std::fs::write(table(&prefix, PX4_TOPICS[0]), pos).unwrap();
        std::fs::write(table(&prefix, PX4_TOPICS[1]), bat).unwrap();
        std::fs::write(table(&prefix, PX4_TOPICS[2]), att).unwrap();
        prefix
    }

    #[test]
    fn a_table_with_a_duplicated_column_is_refused_naming_the_table() {
        let ok = write_log("ok", "timestamp,voltage_v,current_a,voltage_filtered_v");
        let n = Px4Samples::open(&ok, Px4Options::default())
            .unwrap()
            .collect::<Result<Vec<_>>>()
            .unwrap();
        assert_eq!(n.len(), 5);
        assert_eq!(n[2].voltage_v, Some(16.0));
        let bad = write_log("dup", "timestamp,voltage_v,current_a,voltage_v");
        let e = Px4Samples::open(&bad, Px4Options::default())
            .err()
            .expect("a duplicated column must be refused");
        let msg = e.to_string();
        assert!(matches!(e, LogError::DuplicateColumn { .. }), "{msg}");
        assert!(
            msg.contains("flight_battery_status_0.csv") && msg.contains("'voltage_v'"),
            "{msg}"
        );
        for p in [ok, bad] {
            std::fs::remove_dir_all(p.parent().unwrap()).unwrap();
        }
    }

    #[test]
    fn yaw_interpolates_across_pi() {
        let a = Sample {
            attitude: Some(Attitude {
                roll_rad: 0.0,
                pitch_rad: 0.0,
                yaw_rad: 3.1,
            }),
            ..Sample::default()
        };
        let b = Sample {
            attitude: Some(Attitude {
                roll_rad: 0.0,
                pitch_rad: 0.0,
                yaw_rad: -3.1,
            }),
            ..Sample::default()
        };
        let m = lerp_sample(&a, &b, 0.5);
        // Midway along the short arc is +-pi; 1e-9 covers the wrap arithmetic.
        assert!((m.attitude.unwrap().yaw_rad.abs() - std::f64::consts::PI).abs() < 1e-9);
    }
}
