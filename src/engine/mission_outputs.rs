//! A plan's samples as files other tools read: a CSV time series, and MCAP (the samples and the
//! planned path) that Foxglove displays. Both need a plan made with
//! [`MissionOptions::record_samples`](super::MissionOptions::record_samples).

use std::path::Path;

use aloft_logs::{Attitude, BatteryPoint, MissionSample, PathPoint, PowerTerms};
use aloft_planner::trajectory::Shape;
use aloft_planner::Sample;

use super::mission::Plan;
use crate::error::Error;

/// Points drawn per arc of the planned path, so the path shows the circle.
const ARC_POINTS: usize = 36;

impl Plan {
    /// Write every sample (time, segment, position, velocity, acceleration, wind, airspeed,
    /// thrust, attitude, power and its terms, current, voltage, state of charge) as CSV.
    ///
    /// # Errors
    /// [`Error::Io`] or [`Error::Csv`] naming the file when it cannot be written.
    pub fn write_timeseries(&self, path: &Path) -> Result<(), Error> {
        let origin = path.display().to_string();
        let csv_error = |e: csv::Error| Error::Csv {
            origin: origin.clone(),
            row: 0,
            message: e.to_string(),
        };
        let file = std::fs::File::create(path).map_err(|source| Error::Io {
            origin: format!("cannot create {origin}"),
            source,
        })?;
        let mut w = csv::Writer::from_writer(std::io::BufWriter::new(file));
        for s in &self.report().samples {
            w.serialize(s).map_err(csv_error)?;
        }
        w.flush().map_err(|source| Error::Io {
            origin: origin.clone(),
            source,
        })
    }

    /// Write the samples (pose, attitude, power terms, battery state) and the path through the
    /// mission's waypoints as MCAP.
    ///
    /// # Errors
    /// [`Error::Log`] naming the file when it cannot be written.
    pub fn write_mcap(&self, path: &Path) -> Result<(), Error> {
        let samples = mcap_samples(&self.report().samples);
        let path_points = self.path_points();
        aloft_logs::write_mission_mcap(path, &samples, &path_points).map_err(|e| Error::Log {
            origin: format!("cannot write {}", path.display()),
            source: Box::new(e),
        })?;
        Ok(())
    }

    /// The planned path: home, then the end of every piece that moves, and points along arcs.
    fn path_points(&self) -> Vec<PathPoint> {
        let mission = self.compiled();
        let point = |pos_enu_m| PathPoint {
            pos_enu_m,
            yaw_rad: None,
        };
        let mut points = vec![point(mission.home_m())];
        for p in mission.pieces() {
            let end = p.end_m();
            let last = points[points.len() - 1].pos_enu_m;
            let is_arc = matches!(p.shape, Shape::Arc { .. });
            if is_arc {
                let d = p.duration_s();
                for k in 1..=ARC_POINTS {
                    points.push(point(p.at(d * k as f64 / ARC_POINTS as f64).pos_m));
                }
            } else if (0..3).any(|c| (end[c] - last[c]).abs() > 1e-6) {
                points.push(point(end));
            }
        }
        points
    }
}

/// The planner's samples as the MCAP writer's, with the energy used to the end of each step.
fn mcap_samples(samples: &[Sample]) -> Vec<MissionSample> {
    let mut energy_wh = 0.0;
    let mut last_t = 0.0;
    samples
        .iter()
        .map(|s| {
            // Energy to the end of this step (samples are step midpoints; the step is twice the
            // distance to the previous step's end).
            let end_t = s.time_s + (s.time_s - last_t);
            energy_wh += s.power_w * (end_t - last_t) / 3600.0;
            last_t = end_t;
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
                    energy_used_wh: energy_wh,
                }),
            }
        })
        .collect()
}
