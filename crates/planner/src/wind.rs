//! Wind: constant, a profile with height (power law or logarithmic), a gridded field with
//! trilinear interpolation, and optional seeded gusts. Vectors are east-north-up, m/s, and give
//! the velocity of the air over the ground.
//!
//! Directions follow meteorology: a wind "from" 270 deg (clockwise from north) blows towards the
//! east, so its vector is `-S (sin(from), cos(from), 0)`.
//!
//! Profiles with the height `z` above the ground and a reference height `z_ref` where the speed is
//! `S`:
//! - power law: `S (z / z_ref)^alpha` (alpha about 1/7 over open terrain);
//! - logarithmic: `S ln(z / z0) / ln(z_ref / z0)` with the roughness length `z0`, 0 below `z0`.
//!
//! Gusts: the sum of [`GUST_COMPONENTS`] sinusoids per horizontal axis with frequencies spread
//! log-uniformly over 0.02-1 Hz and random phases from a seeded generator, scaled to the given
//! standard deviation. They are a sensitivity device, not a turbulence model: no spectrum is
//! claimed, the vertical component is not perturbed.

use crate::error::PlannerError;

/// Sinusoids per horizontal axis in the gust signal.
pub const GUST_COMPONENTS: usize = 6;

/// Variation of the wind speed with height.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Profile {
    /// The same speed at every height.
    Uniform,
    /// `S (z / z_ref)^exponent`.
    PowerLaw {
        /// Reference height, m.
        reference_height_m: f64,
        /// Exponent (about 1/7 over open terrain).
        exponent: f64,
    },
    /// `S ln(z / z0) / ln(z_ref / z0)`.
    Log {
        /// Reference height, m.
        reference_height_m: f64,
        /// Roughness length `z0`, m (0.03 for open grass).
        roughness_m: f64,
    },
}

/// A regular grid of wind vectors, interpolated trilinearly.
#[derive(Debug, Clone, PartialEq)]
pub struct WindGrid {
    axes: [Vec<f64>; 3],
    /// `[u, v, w]` at index `(i * ny + j) * nz + k`.
    values: Vec<[f64; 3]>,
}

impl WindGrid {
    /// Build from rows `[x_m, y_m, z_m, u_mps, v_mps, w_mps]` (east, north, up), in any order.
    ///
    /// # Errors
    /// Values that are not finite or out of range (coordinates beyond 1e7 m, wind beyond
    /// [`MAX_WIND_MPS`]), fewer than two distinct values on an axis, or rows that do not fill
    /// every node of the grid exactly once.
    pub fn from_rows(rows: &[[f64; 6]]) -> Result<Self, PlannerError> {
        for r in rows {
            // Coordinates within 10,000 km, wind components within the strongest wind.
            let limit = |k: usize| if k < 3 { 1e7 } else { MAX_WIND_MPS };
            let bad = r
                .iter()
                .enumerate()
                .find(|(k, v)| v.is_nan() || v.abs() > limit(*k));
            if let Some((_, &bad)) = bad {
                return Err(PlannerError::InvalidWindGrid {
                    reason: "a value is not a finite number within range (coordinates 1e7 m, wind 100 m/s)",
                    found: bad,
                });
            }
        }
        let axis = |c: usize| {
            let mut v: Vec<f64> = rows.iter().map(|r| r[c]).collect();
            v.sort_by(f64::total_cmp);
            // Coordinates closer than 1 mm are the same node.
            v.dedup_by(|a, b| (*a - *b).abs() < 1e-3);
            v
        };
        let axes = [axis(0), axis(1), axis(2)];
        for a in &axes {
            if a.len() < 2 {
                return Err(PlannerError::InvalidWindGrid {
                    reason: "each axis needs at least two distinct coordinates",
                    found: a.len() as f64,
                });
            }
        }
        let (nx, ny, nz) = (axes[0].len(), axes[1].len(), axes[2].len());
        if rows.len() != nx * ny * nz {
            return Err(PlannerError::InvalidWindGrid {
                reason: "rows do not fill the grid: expected x count * y count * z count",
                found: rows.len() as f64,
            });
        }
        let mut values = vec![[f64::NAN; 3]; rows.len()];
        let find = |a: &[f64], x: f64| a.iter().position(|&c| (c - x).abs() < 1e-3);
        for r in rows {
            let (i, j, k) = (
                find(&axes[0], r[0]).unwrap_or(0),
                find(&axes[1], r[1]).unwrap_or(0),
                find(&axes[2], r[2]).unwrap_or(0),
            );
            let slot = &mut values[(i * ny + j) * nz + k];
            if slot[0].is_finite() {
                return Err(PlannerError::InvalidWindGrid {
                    reason: "a node appears twice (x_m given)",
                    found: r[0],
                });
            }
            *slot = [r[3], r[4], r[5]];
        }
        Ok(Self { axes, values })
    }

    /// Lower and upper corners, m.
    pub fn bounds_m(&self) -> ([f64; 3], [f64; 3]) {
        let lo = [self.axes[0][0], self.axes[1][0], self.axes[2][0]];
        let hi = [
            self.axes[0][self.axes[0].len() - 1],
            self.axes[1][self.axes[1].len() - 1],
            self.axes[2][self.axes[2].len() - 1],
        ];
        (lo, hi)
    }

    /// Trilinear interpolation at `p` (ENU m); `None` outside the grid.
    pub fn at(&self, p: [f64; 3]) -> Option<[f64; 3]> {
        let mut idx = [0usize; 3];
        let mut frac = [0.0; 3];
        for c in 0..3 {
            let a = &self.axes[c];
            let x = p[c];
            // 1 mm tolerance at the faces, the same as the node matching.
            if !(x >= a[0] - 1e-3 && x <= a[a.len() - 1] + 1e-3) {
                return None;
            }
            let i = a.partition_point(|&v| v <= x).clamp(1, a.len() - 1) - 1;
            idx[c] = i;
            frac[c] = ((x - a[i]) / (a[i + 1] - a[i])).clamp(0.0, 1.0);
        }
        let (ny, nz) = (self.axes[1].len(), self.axes[2].len());
        let mut out = [0.0; 3];
        for di in 0..2 {
            for dj in 0..2 {
                for dk in 0..2 {
                    let w = (if di == 0 { 1.0 - frac[0] } else { frac[0] })
                        * (if dj == 0 { 1.0 - frac[1] } else { frac[1] })
                        * (if dk == 0 { 1.0 - frac[2] } else { frac[2] });
                    let v = self.values[((idx[0] + di) * ny + idx[1] + dj) * nz + idx[2] + dk];
                    for c in 0..3 {
                        out[c] += w * v[c];
                    }
                }
            }
        }
        Some(out)
    }
}

/// Seeded gust signal added to the mean wind.
#[derive(Debug, Clone, PartialEq)]
pub struct Gusts {
    std_mps: f64,
    seed: u64,
    /// Per axis: `(amplitude m/s, angular frequency rad/s, phase rad)`.
    components: [[(f64, f64, f64); GUST_COMPONENTS]; 2],
}

/// Strongest wind a query takes, m/s (above a category-5 hurricane's sustained winds; no
/// multirotor flies in it, and a larger number is a mistake).
pub const MAX_WIND_MPS: f64 = 100.0;

/// Largest gust standard deviation, m/s.
pub const MAX_GUST_STD_MPS: f64 = 50.0;

/// Largest reference height of a wind profile, m.
pub const MAX_REFERENCE_HEIGHT_M: f64 = 10_000.0;

impl Gusts {
    /// Gusts with standard deviation `std_mps` per horizontal axis, reproducible from `seed`.
    ///
    /// # Errors
    /// A negative or non-finite standard deviation.
    pub fn new(std_mps: f64, seed: u64) -> Result<Self, PlannerError> {
        crate::error::non_negative("gust_std_mps", std_mps, "m/s")?;
        let range = (0.0, MAX_GUST_STD_MPS);
        crate::error::within("gust_std_mps", std_mps, range, "m/s", "at most 50 m/s")?;
        let mut state = seed;
        let mut next = || {
            // splitmix64: a small, well-mixed generator, enough for phases and frequencies.
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        };
        // Each sinusoid of amplitude A has variance A^2 / 2: A = std sqrt(2 / K) gives std overall.
        let amp = std_mps * (2.0 / GUST_COMPONENTS as f64).sqrt();
        let mut components = [[(0.0, 0.0, 0.0); GUST_COMPONENTS]; 2];
        for axis in components.iter_mut() {
            for c in axis.iter_mut() {
                let f_hz = 0.02 * (1.0f64 / 0.02).powf(next());
                *c = (
                    amp,
                    std::f64::consts::TAU * f_hz,
                    std::f64::consts::TAU * next(),
                );
            }
        }
        Ok(Self {
            std_mps,
            seed,
            components,
        })
    }

    /// Standard deviation per axis, m/s.
    pub fn std_mps(&self) -> f64 {
        self.std_mps
    }

    /// The seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Gust velocity at time `t_s`, east and north, m/s.
    #[inline]
    pub fn at(&self, t_s: f64) -> [f64; 2] {
        let mut out = [0.0; 2];
        for (o, axis) in out.iter_mut().zip(&self.components) {
            for &(a, w, p) in axis {
                *o += a * (w * t_s + p).sin();
            }
        }
        out
    }
}

/// The mean wind of a mission.
#[derive(Debug, Clone, PartialEq)]
pub enum MeanWind {
    /// The same vector everywhere, ENU m/s.
    Constant([f64; 3]),
    /// Horizontal wind of speed `reference_mps` at the profile's reference height, from
    /// `from_rad`, varying with height.
    Profiled {
        /// Unit vector the wind blows towards, east and north.
        toward: [f64; 2],
        /// Speed at the reference height, m/s.
        reference_mps: f64,
        /// Variation with height.
        profile: Profile,
    },
    /// A gridded field.
    Grid(WindGrid),
}

/// Wind of a mission: a mean field and optional gusts.
#[derive(Debug, Clone, PartialEq)]
pub struct Wind {
    mean: MeanWind,
    gusts: Option<Gusts>,
}

/// Unit vector towards which a wind from `from_rad` (clockwise from north) blows, east and north.
pub fn toward_unit(from_rad: f64) -> [f64; 2] {
    let (s, c) = from_rad.sin_cos();
    [-s, -c]
}

/// The horizontal speed of a wind `[east, north, up]`, m/s, and the direction it blows from,
/// degrees clockwise from north in `[0, 360)`.
pub fn speed_and_from_deg(wind_mps: [f64; 3]) -> (f64, f64) {
    let [e, n, _] = wind_mps;
    (e.hypot(n), (-e).atan2(-n).to_degrees().rem_euclid(360.0))
}

/// A profile's reference height: positive and at most [`MAX_REFERENCE_HEIGHT_M`].
fn check_reference_height(reference_height_m: f64) -> Result<f64, PlannerError> {
    crate::error::positive("reference_height_m", reference_height_m, "m")?;
    let range = (0.0, MAX_REFERENCE_HEIGHT_M);
    crate::error::within(
        "reference_height_m",
        reference_height_m,
        range,
        "m",
        "at most 10000 m",
    )
}

impl Wind {
    /// Still air.
    pub fn calm() -> Self {
        Self {
            mean: MeanWind::Constant([0.0; 3]),
            gusts: None,
        }
    }

    /// Constant horizontal wind of `speed_mps` from `from_deg` (clockwise from north).
    ///
    /// # Errors
    /// Negative or non-finite speed, non-finite direction.
    pub fn constant(speed_mps: f64, from_deg: f64) -> Result<Self, PlannerError> {
        Self::profiled(speed_mps, from_deg, Profile::Uniform)
    }

    /// Horizontal wind of `speed_mps` at the profile's reference height from `from_deg`.
    ///
    /// # Errors
    /// Negative or non-finite speed, non-finite direction, a non-positive reference height or
    /// roughness, a roughness not below the reference height, a negative exponent.
    pub fn profiled(speed_mps: f64, from_deg: f64, profile: Profile) -> Result<Self, PlannerError> {
        crate::error::non_negative("wind_speed_mps", speed_mps, "m/s")?;
        let range = (0.0, MAX_WIND_MPS);
        crate::error::within("wind_speed_mps", speed_mps, range, "m/s", "at most 100 m/s")?;
        let ok = from_deg.is_finite();
        aloft_core::parameter("wind_from_deg", from_deg, "deg", ok, "a finite direction")?;
        match profile {
            Profile::Uniform => {}
            Profile::PowerLaw {
                reference_height_m,
                exponent,
            } => {
                check_reference_height(reference_height_m)?;
                crate::error::non_negative("power_law_exponent", exponent, "")?;
                let expected = "at most 1 (open country 0.14, cities 0.4)";
                crate::error::within("power_law_exponent", exponent, (0.0, 1.0), "", expected)?;
            }
            Profile::Log {
                reference_height_m,
                roughness_m,
            } => {
                check_reference_height(reference_height_m)?;
                crate::error::positive("roughness_m", roughness_m, "m")?;
                let ok = roughness_m < reference_height_m;
                aloft_core::parameter(
                    "roughness_m",
                    roughness_m,
                    "m",
                    ok,
                    "below the reference height",
                )?;
            }
        }
        let toward = toward_unit(from_deg.to_radians());
        let mean = match profile {
            Profile::Uniform => {
                MeanWind::Constant([toward[0] * speed_mps, toward[1] * speed_mps, 0.0])
            }
            _ => MeanWind::Profiled {
                toward,
                reference_mps: speed_mps,
                profile,
            },
        };
        Ok(Self { mean, gusts: None })
    }

    /// A gridded field.
    pub fn grid(grid: WindGrid) -> Self {
        Self {
            mean: MeanWind::Grid(grid),
            gusts: None,
        }
    }

    /// The same wind with gusts added.
    pub fn with_gusts(mut self, gusts: Gusts) -> Self {
        self.gusts = Some(gusts);
        self
    }

    /// The mean field.
    pub fn mean(&self) -> &MeanWind {
        &self.mean
    }

    /// The gusts, if any.
    pub fn gusts(&self) -> Option<&Gusts> {
        self.gusts.as_ref()
    }

    /// Mean wind at `pos_m` (ENU, height above the ground), m/s; `None` outside a grid.
    #[inline]
    pub fn mean_at(&self, pos_m: [f64; 3]) -> Option<[f64; 3]> {
        match &self.mean {
            MeanWind::Constant(w) => Some(*w),
            MeanWind::Profiled {
                toward,
                reference_mps,
                profile,
            } => {
                let z = pos_m[2].max(0.0);
                let s = reference_mps
                    * match *profile {
                        Profile::Uniform => 1.0,
                        Profile::PowerLaw {
                            reference_height_m,
                            exponent,
                        } => (z / reference_height_m).powf(exponent),
                        Profile::Log {
                            reference_height_m,
                            roughness_m,
                        } => {
                            if z <= roughness_m {
                                0.0
                            } else {
                                (z / roughness_m).ln() / (reference_height_m / roughness_m).ln()
                            }
                        }
                    };
                Some([toward[0] * s, toward[1] * s, 0.0])
            }
            MeanWind::Grid(g) => g.at(pos_m),
        }
    }

    /// Wind at `pos_m` and mission time `t_s` (mean plus gusts), m/s; `None` outside a grid.
    #[inline]
    pub fn at(&self, pos_m: [f64; 3], t_s: f64) -> Option<[f64; 3]> {
        let mut w = self.mean_at(pos_m)?;
        if let Some(g) = &self.gusts {
            let d = g.at(t_s);
            w[0] += d[0];
            w[1] += d[1];
        }
        Some(w)
    }

    /// Whether the wind depends on height alone and not on time (constant or profiled, no
    /// grid, no gusts): along a level path it is one value.
    pub fn is_steady_and_level_uniform(&self) -> bool {
        matches!(self.mean, MeanWind::Constant(_) | MeanWind::Profiled { .. })
            && self.gusts.is_none()
    }

    /// Whether the wind is the same everywhere and always (no profile, grid or gusts).
    pub fn is_uniform(&self) -> bool {
        matches!(self.mean, MeanWind::Constant(_)) && self.gusts.is_none()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_west_blows_east() {
        let w = Wind::constant(5.0, 270.0).unwrap();
        let v = w.at([0.0; 3], 0.0).unwrap();
        // sin/cos of 3 pi / 2 round to 1e-16
        assert!((v[0] - 5.0).abs() < 1e-12 && v[1].abs() < 1e-12);
    }

    #[test]
    fn profiles_equal_the_reference_speed_at_the_reference_height() {
        for p in [
            Profile::PowerLaw {
                reference_height_m: 10.0,
                exponent: 1.0 / 7.0,
            },
            Profile::Log {
                reference_height_m: 10.0,
                roughness_m: 0.03,
            },
        ] {
            let w = Wind::profiled(6.0, 0.0, p).unwrap();
            let at10 = w.mean_at([0.0, 0.0, 10.0]).unwrap();
            assert!((at10[1] + 6.0).abs() < 1e-12);
            let at40 = w.mean_at([0.0, 0.0, 40.0]).unwrap();
            assert!(at40[1] < -6.0, "wind grows with height");
        }
        // 1/7 power law: (40/10)^(1/7) = 1.2190
        let w = Wind::profiled(
            6.0,
            0.0,
            Profile::PowerLaw {
                reference_height_m: 10.0,
                exponent: 1.0 / 7.0,
            },
        )
        .unwrap();
        assert!(
            (w.mean_at([0.0, 0.0, 40.0]).unwrap()[1] + 6.0 * 4f64.powf(1.0 / 7.0)).abs() < 1e-12
        );
    }

    #[test]
    fn trilinear_reproduces_a_linear_field_and_rejects_outside() {
        // u = 1 + 0.01 x + 0.02 y + 0.03 z is reproduced exactly by trilinear interpolation.
        let mut rows = vec![];
        for x in [0.0, 100.0, 250.0] {
            for y in [-50.0, 50.0] {
                for z in [0.0, 20.0, 60.0] {
                    rows.push([x, y, z, 1.0 + 0.01 * x + 0.02 * y + 0.03 * z, 2.0, 0.0]);
                }
            }
        }
        let g = WindGrid::from_rows(&rows).unwrap();
        let p = [130.0, 12.5, 33.0];
        let u = g.at(p).unwrap()[0];
        assert!((u - (1.0 + 1.3 + 0.25 + 0.99)).abs() < 1e-12, "{u}");
        assert!(g.at([260.0, 0.0, 10.0]).is_none());
        rows.pop();
        assert!(WindGrid::from_rows(&rows).is_err());
    }

    #[test]
    fn gusts_have_the_asked_spread_and_repeat_with_the_seed() {
        let g = Gusts::new(2.0, 7).unwrap();
        let n = 200_000;
        let (mut s, mut s2) = (0.0, 0.0);
        for k in 0..n {
            let v = g.at(k as f64 * 0.05)[0];
            s += v;
            s2 += v * v;
        }
        let std = (s2 / n as f64 - (s / n as f64).powi(2)).sqrt();
        // 10 000 s of a signal with periods up to 50 s: the sample std is within ~10 % of 2.
        assert!((std - 2.0).abs() < 0.2, "{std}");
        assert_eq!(
            g.at(12.3).map(f64::to_bits),
            Gusts::new(2.0, 7).unwrap().at(12.3).map(f64::to_bits)
        );
    }
}
