//! A plan's samples as files other tools read, written as the flight is flown so that memory does
//! not grow with the flight: a CSV time series, MCAP (the samples and the planned path) that
//! Foxglove displays, and a decimated copy for a chart.
//!
//! The files are written in aloft's one way ([`crate::engine::basics::files`]): each to a temporary file beside
//! it, placed together when the flight is flown (all or nothing); a run that fails, or a program
//! interrupted, leaves none of them; an existing file is kept unless `force`.

use std::io::BufWriter;
use std::path::PathBuf;

use aloft_logs::{Attitude, BatteryPoint, McapFile, MissionSample, PathPoint, PowerTerms};
use aloft_planner::trajectory::Shape;
use aloft_planner::{PlannerError, Sample, SampleSink};

use crate::engine::basics::files::{shown_path, Output, OutputError, OutputSet};
use crate::engine::basics::finite::first_non_finite;
use crate::error::Error;

/// Points drawn per arc of the planned path, so the path shows the circle.
const ARC_POINTS: usize = 36;

/// Most samples kept for a chart: a flight with more is decimated (every 2nd, 4th, ... sample),
/// keeping between half this number and this number.
pub const PLOT_SAMPLES: usize = 10_000;

/// The files a mission run writes beside its answer.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MissionOutputs {
    /// Every sample as CSV (time, segment, position, velocity, acceleration, wind, airspeed,
    /// thrust, attitude, power and its terms, current, voltage, state of charge).
    pub timeseries: Option<PathBuf>,
    /// The samples (pose, attitude, power terms, battery state) and the planned path as MCAP.
    pub mcap: Option<PathBuf>,
    /// Keep a decimated copy of the samples for a chart ([`crate::engine::missions::mission::Plan::plot_samples`]).
    pub plot: bool,
    /// Replace files that exist at `timeseries` and `mcap` (a regular file or a link itself;
    /// never a device, a FIFO or a folder). Without it an existing file is kept and the run
    /// refused before it flies.
    pub force: bool,
}

impl MissionOutputs {
    /// Whether any output wants the samples.
    pub fn any(&self) -> bool {
        self.timeseries.is_some() || self.mcap.is_some() || self.plot
    }
}

/// The sink the planner streams a run's samples into: one writer per output asked for.
pub(crate) struct OutputSink {
    csv: Option<(csv::Writer<BufWriter<Output>>, PathBuf)>,
    mcap: Option<McapStream>,
    plot: Option<Decimator>,
    /// Every sample, when the plan keeps them ([`crate::engine::missions::mission_options::MissionOptions::record_samples`]).
    all: Option<Vec<Sample>>,
    /// The first failure, with the file it names (the planner only sees that the sink failed).
    failure: Option<Error>,
    /// Voltage thresholds watched: (threshold V, first sample below it as (time s, segment)).
    watch: Vec<(f64, Option<(f64, usize)>)>,
}

impl OutputSink {
    /// Create the files asked for; `path_points` is the planned path for MCAP; `keep_all` keeps
    /// every sample too.
    pub(crate) fn create(
        outputs: &MissionOutputs,
        path_points: Vec<PathPoint>,
        keep_all: bool,
    ) -> Result<Self, Error> {
        let mut sink = Self {
            csv: None,
            mcap: None,
            plot: outputs.plot.then(Decimator::default),
            all: keep_all.then(Vec::new),
            failure: None,
            watch: Vec::new(),
        };
        if let (Some(a), Some(b)) = (&outputs.timeseries, &outputs.mcap) {
            if a == b {
                return Err(OutputError::Duplicate { path: a.clone() }.into());
            }
        }
        if let Some(path) = &outputs.timeseries {
            let file = Output::create(path, outputs.force)?;
            sink.csv = Some((csv::Writer::from_writer(BufWriter::new(file)), path.clone()));
        }
        if let Some(path) = &outputs.mcap {
            // On an error the time series' temporary file goes with the sink.
            let writer = McapFile::create(path, outputs.force)?;
            sink.mcap = Some(McapStream::new(writer, path.clone(), path_points));
        }
        Ok(sink)
    }

    /// Finish the files and put them in place together; the decimated samples for a chart and,
    /// when kept, all of them.
    pub(crate) fn finish(mut self) -> Result<(Vec<Sample>, Vec<Sample>), Error> {
        let mut set = OutputSet::new();
        if let Some((w, path)) = self.csv.take() {
            let out = w
                .into_inner()
                .map_err(|e| e.into_error())
                .and_then(|b| b.into_inner().map_err(std::io::IntoInnerError::into_error))
                .map_err(|source| Error::Io {
                    origin: format!("cannot write {}", shown_path(&path)),
                    source,
                })?;
            set.push(out)?;
        }
        if let Some(m) = self.mcap.take() {
            set.push(m.finish()?)?;
        }
        set.commit()?;
        let plot = self.plot.take().map(|d| d.samples).unwrap_or_default();
        Ok((plot, self.all.take().unwrap_or_default()))
    }

    /// Watch the terminal voltage for `thresholds_v` (pack volts).
    pub(crate) fn watch_voltage(&mut self, thresholds_v: &[f64]) {
        self.watch = thresholds_v.iter().map(|v| (*v, None)).collect();
    }

    /// For each watched threshold, the first sample whose terminal voltage fell below it: its
    /// time, s, and segment (from 1).
    pub(crate) fn crossings(&self) -> Vec<Option<(f64, usize)>> {
        self.watch.iter().map(|w| w.1).collect()
    }

    /// Drop the files being written (after a failed run): their temporary files go, and nothing
    /// is placed, so no half-written file looks valid.
    pub(crate) fn discard(&mut self) {
        self.csv = None;
        self.mcap = None;
    }

    /// The failure that stopped the run, when the sink was the cause.
    pub(crate) fn take_failure(&mut self) -> Option<Error> {
        self.failure.take()
    }

    fn fail(&mut self, e: Error) -> PlannerError {
        let message = e.to_string();
        self.failure = Some(e);
        PlannerError::Output { message }
    }
}

impl SampleSink for OutputSink {
    fn take(&mut self, s: &Sample) -> Result<(), PlannerError> {
        if let Some((field, value)) = first_non_finite(s) {
            let e = Error::NonFinite {
                answer: "sample",
                field,
                value,
                request: format!("the sample at t = {} s", s.time_s),
            };
            return Err(self.fail(e));
        }
        if let Some((w, path)) = &mut self.csv {
            if let Err(e) = w.serialize(s) {
                let e = Error::Csv {
                    origin: path.display().to_string(),
                    row: 0,
                    message: e.to_string(),
                };
                return Err(self.fail(e));
            }
        }
        if let Some(m) = &mut self.mcap {
            if let Err(e) = m.write(s) {
                return Err(self.fail(e));
            }
        }
        if let Some(d) = &mut self.plot {
            d.push(s);
        }
        if let Some(all) = &mut self.all {
            all.push(*s);
        }
        for (v, first) in &mut self.watch {
            if first.is_none() && s.voltage_v < *v {
                *first = Some((s.time_s, s.segment));
            }
        }
        Ok(())
    }
}

/// A mission's MCAP as it is flown: the planned path at the first sample's time, then every
/// sample with the energy used to the end of its step.
struct McapStream {
    writer: McapFile,
    path: PathBuf,
    path_points: Vec<PathPoint>,
    index: usize,
    energy_wh: f64,
    last_t: f64,
}

impl McapStream {
    fn new(writer: McapFile, path: PathBuf, path_points: Vec<PathPoint>) -> Self {
        Self {
            writer,
            path,
            path_points,
            index: 0,
            energy_wh: 0.0,
            last_t: 0.0,
        }
    }

    fn error(&self, e: aloft_logs::LogError) -> Error {
        Error::Log {
            origin: format!("cannot write {}", self.path.display()),
            source: Box::new(e),
        }
    }

    fn write(&mut self, s: &Sample) -> Result<(), Error> {
        if self.index == 0 && !self.path_points.is_empty() {
            let points = std::mem::take(&mut self.path_points);
            self.writer
                .write_path(s.time_s, &points)
                .map_err(|e| self.error(e))?;
        }
        // Energy to the end of this step (samples are step midpoints; the step is twice the
        // distance to the previous step's end).
        let end_t = s.time_s + (s.time_s - self.last_t);
        self.energy_wh += s.power_w * (end_t - self.last_t) / 3600.0;
        self.last_t = end_t;
        let sample = mcap_sample(s, self.energy_wh);
        self.writer
            .write_mission_sample(self.index, &sample)
            .map_err(|e| self.error(e))?;
        self.index += 1;
        Ok(())
    }

    /// The finished file, to be placed with the run's other files.
    fn finish(self) -> Result<Output, Error> {
        let path = shown_path(&self.path);
        let (_, out) = self.writer.finish_output().map_err(|e| Error::Log {
            origin: format!("cannot write {path}"),
            source: Box::new(e),
        })?;
        Ok(out)
    }
}

/// One planner sample as the MCAP writer's.
fn mcap_sample(s: &Sample, energy_used_wh: f64) -> MissionSample {
    MissionSample {
        time_s: s.time_s,
        pos_enu_m: [s.east_m, s.north_m, s.up_m],
        vel_enu_mps: [s.vel_east_mps, s.vel_north_mps, s.vel_up_mps],
        attitude: Attitude {
            roll_rad: s.roll_deg.to_radians(),
            pitch_rad: s.pitch_deg.to_radians(),
            yaw_rad: s.yaw_deg.to_radians(),
        },
        power: PowerTerms {
            induced_w: s.induced_w.unwrap_or(0.0),
            parasitic_w: s.parasitic_w.unwrap_or(0.0),
            profile_w: s.profile_w.unwrap_or(0.0),
            acceleration_w: s.acceleration_w.unwrap_or(0.0),
            climb_w: s.climb_w.unwrap_or(0.0),
            electrical_w: s.power_w,
        },
        battery: Some(BatteryPoint {
            voltage_v: s.voltage_v,
            current_a: s.current_a,
            state_of_charge: s.soc,
            energy_used_wh,
        }),
    }
}

/// Every `stride`-th sample, the stride doubling (and every other kept sample dropped) whenever
/// [`PLOT_SAMPLES`] are held: bounded memory, evenly spaced samples, all of them for a short flight.
#[derive(Default)]
struct Decimator {
    samples: Vec<Sample>,
    stride: usize,
    seen: usize,
}

impl Decimator {
    fn push(&mut self, s: &Sample) {
        let stride = self.stride.max(1);
        if self.seen % stride == 0 {
            if self.samples.len() == PLOT_SAMPLES {
                let mut k = 0;
                self.samples.retain(|_| {
                    k += 1;
                    k % 2 == 1
                });
                self.stride = stride * 2;
            }
            if self.seen % self.stride.max(1) == 0 {
                self.samples.push(*s);
            }
        }
        self.seen += 1;
    }
}

/// The planned path of a compiled mission: home, then the end of every piece that moves, and
/// points along arcs.
pub(crate) fn path_points(mission: &aloft_planner::Mission) -> Vec<PathPoint> {
    let point = |pos_enu_m| PathPoint {
        pos_enu_m,
        yaw_rad: None,
    };
    let mut points = vec![point(mission.home_m())];
    for (_, path) in segment_paths(mission) {
        points.extend(path.into_iter().skip(1).map(point));
    }
    points
}

/// The planned path, segment by segment (segment numbers from 0), each path starting where the
/// one before ended: a line by its end, an arc by [`ARC_POINTS`] points, a hold by its point.
pub(in crate::engine) fn segment_paths(
    mission: &aloft_planner::Mission,
) -> Vec<(usize, Vec<[f64; 3]>)> {
    let mut paths: Vec<(usize, Vec<[f64; 3]>)> = Vec::new();
    let mut last = mission.home_m();
    for p in mission.pieces() {
        if paths.last().is_none_or(|(k, _)| *k != p.segment) {
            paths.push((p.segment, vec![last]));
        }
        let Some((_, points)) = paths.last_mut() else {
            continue;
        };
        if matches!(p.shape, Shape::Arc { .. }) {
            let d = p.duration_s();
            points.extend((1..=ARC_POINTS).map(|k| p.at(d * k as f64 / ARC_POINTS as f64).pos_m));
        } else {
            let end = p.end_m();
            if (0..3).any(|c| (end[c] - last[c]).abs() > 1e-6) {
                points.push(end);
            }
        }
        last = points[points.len() - 1];
    }
    paths
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(t: f64) -> Sample {
        Sample {
            time_s: t,
            segment: 1,
            soc: 1.0,
            ..Sample::default()
        }
    }

    #[test]
    fn the_decimator_keeps_short_flights_whole_and_long_ones_bounded_and_even() {
        let mut d = Decimator::default();
        for k in 0..PLOT_SAMPLES {
            d.push(&sample(k as f64));
        }
        assert_eq!(d.samples.len(), PLOT_SAMPLES);
        let mut d = Decimator::default();
        let n = 1_000_003;
        for k in 0..n {
            d.push(&sample(k as f64));
        }
        assert!(d.samples.len() <= PLOT_SAMPLES && d.samples.len() >= PLOT_SAMPLES / 2);
        // Evenly spaced: every kept sample is a multiple of the final stride apart.
        let step = d.samples[1].time_s - d.samples[0].time_s;
        assert!(step >= 2.0);
        for w in d.samples.windows(2) {
            assert!((w[1].time_s - w[0].time_s - step).abs() < 1e-9);
        }
        // And they reach the end of the flight within one stride.
        assert!(n as f64 - 1.0 - d.samples.last().unwrap().time_s < step);
    }
}
