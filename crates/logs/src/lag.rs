//! Time lag between a power channel and a motion channel by normalised cross-correlation.
//!
//! For each integer lag `k` in `[-K, K]` (`K = max_lag_s / dt`), the Pearson correlation of
//! `power[i + k]` with `motion[i]` over their overlap is computed, after removing a straight-line
//! trend from each series (the battery's slow voltage sag would otherwise dominate). The lag with
//! the largest correlation is refined by fitting a parabola through it and its two neighbours.
//! A positive lag means power follows motion: `power(t) ~ f(motion(t - lag))`.
//!
//! The motion proxy is the caller's choice (ground speed, tilt, acceleration magnitude); the
//! function only aligns two uniformly sampled series. [`resample_uniform`] brings a log's
//! channel onto a uniform grid first.

use aloft_core::IndexLine;
use serde::Serialize;

use crate::error::{LogError, Result};

/// Result of [`estimate_lag_s`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LagEstimate {
    /// Lag of power behind motion, s (positive: power follows motion).
    pub lag_s: f64,
    /// Correlation at the best integer lag, -1 to 1.
    pub correlation: f64,
    /// Correlation at zero lag, for comparison.
    pub correlation_at_zero: f64,
    /// Samples used.
    pub samples: usize,
    /// Whether the best lag is at the edge of the search window (then the true lag may be larger).
    pub at_window_edge: bool,
}

fn detrend(y: &[f64]) -> Vec<f64> {
    let line = IndexLine::of(y);
    y.iter()
        .enumerate()
        .map(|(i, v)| v - line.mean_y - line.slope * (i as f64 - line.mean_x))
        .collect()
}

fn pearson(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let ma = a.iter().sum::<f64>() / n;
    let mb = b.iter().sum::<f64>() / n;
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        let (dx, dy) = (x - ma, y - mb);
        sab += dx * dy;
        saa += dx * dx;
        sbb += dy * dy;
    }
    if saa > 0.0 && sbb > 0.0 {
        sab / (saa * sbb).sqrt()
    } else {
        0.0
    }
}

/// Estimate the lag of `power` behind `motion_proxy`, both sampled every `dt_s`, searching
/// `[-max_lag_s, max_lag_s]`.
///
/// Errors: different lengths, non-finite values, `dt_s <= 0`, a window that leaves fewer than
/// 10 overlapping samples or half the series, or a constant series.
pub fn estimate_lag_s(
    power: &[f64],
    motion_proxy: &[f64],
    dt_s: f64,
    max_lag_s: f64,
) -> Result<LagEstimate> {
    let k_max = search_window(power, motion_proxy, dt_s, max_lag_s)?;
    let n = power.len();
    let p = detrend(power);
    let m = detrend(motion_proxy);
    let zero = lagged_pearson(&p, &m, 0);
    let km = k_max as i64;
    let cs: Vec<f64> = (-km..=km).map(|k| lagged_pearson(&p, &m, k)).collect();
    if cs.iter().all(|c| c.abs() < 1e-300) {
        return Err(LogError::InvalidArgument {
            name: "series variance",
            value: 0.0,
            reason: "a series is constant (after detrending): no lag can be estimated",
        });
    }
    let (best, &c) = cs
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .unwrap_or((k_max, &0.0));
    let mut lag = best as f64 - km as f64;
    if let Some(offset) = parabola_peak_offset(&cs, best) {
        lag += offset;
    }
    Ok(LagEstimate {
        lag_s: lag * dt_s,
        correlation: c,
        correlation_at_zero: zero,
        samples: n,
        at_window_edge: best == 0 || best + 1 == cs.len(),
    })
}

/// Checks the arguments of [`estimate_lag_s`] and returns the search window in samples.
fn search_window(power: &[f64], motion_proxy: &[f64], dt_s: f64, max_lag_s: f64) -> Result<usize> {
    check_step(dt_s)?;
    if !(max_lag_s.is_finite() && max_lag_s >= 0.0) {
        return Err(LogError::InvalidArgument {
            name: "max_lag_s",
            value: max_lag_s,
            reason: "must be finite and non-negative",
        });
    }
    if power.len() != motion_proxy.len() {
        return Err(LogError::InvalidArgument {
            name: "motion_proxy length",
            value: motion_proxy.len() as f64,
            reason: "must equal the power series length",
        });
    }
    if let Some(v) = power.iter().chain(motion_proxy).find(|v| !v.is_finite()) {
        return Err(LogError::InvalidArgument {
            name: "series value",
            value: *v,
            reason: "all values must be finite",
        });
    }
    let n = power.len();
    let k_max = (max_lag_s / dt_s).round() as usize;
    if n < 10 || k_max * 2 > n || n - k_max < 10 {
        return Err(LogError::InvalidArgument {
            name: "max_lag_s",
            value: max_lag_s,
            reason: "the series must be at least twice the search window and 10 samples long",
        });
    }
    Ok(k_max)
}

/// A sampling step must be finite and positive.
fn check_step(dt_s: f64) -> Result<()> {
    if !(dt_s.is_finite() && dt_s > 0.0) {
        return Err(LogError::InvalidArgument {
            name: "dt_s",
            value: dt_s,
            reason: "must be finite and positive",
        });
    }
    Ok(())
}

/// Correlation of `p[i + k]` with `m[i]` over their overlap.
fn lagged_pearson(p: &[f64], m: &[f64], k: i64) -> f64 {
    let n = p.len();
    if k >= 0 {
        let k = k as usize;
        pearson(&p[k..], &m[..n - k])
    } else {
        let k = (-k) as usize;
        pearson(&p[..n - k], &m[k..])
    }
}

/// Where the parabola through `cs[best]` and its two neighbours peaks, relative to `best`
/// (within half a sample); `None` at the window's edge or without a maximum.
fn parabola_peak_offset(cs: &[f64], best: usize) -> Option<f64> {
    if best == 0 || best + 1 >= cs.len() {
        return None;
    }
    let (y0, y1, y2) = (cs[best - 1], cs[best], cs[best + 1]);
    let den = y0 - 2.0 * y1 + y2;
    (den < 0.0).then(|| (0.5 * (y0 - y2) / den).clamp(-0.5, 0.5))
}

/// Most points [`resample_uniform`] makes (8 bytes each, 128 MiB).
pub const MAX_RESAMPLED_POINTS: usize = 1 << 24;

/// Linear interpolation of `(times_s, values)` onto a uniform grid of step `dt_s` from the first
/// time to the last. Samples whose time does not increase are skipped (they are reported by the
/// log's [`crate::TimeReport`]). Returns the grid's start time and the values; a grid of more
/// than [`MAX_RESAMPLED_POINTS`] is an error.
pub fn resample_uniform(times_s: &[f64], values: &[f64], dt_s: f64) -> Result<(f64, Vec<f64>)> {
    check_step(dt_s)?;
    // The kept samples are walked twice (their count and span, then the grid) rather than
    // copied: memory is the grid alone.
    let (count, first, last) = increasing(times_s, values)
        .fold((0usize, None, None), |(n, f, _), p| {
            (n + 1, f.or(Some(p.0)), Some(p.0))
        });
    let (Some(t0), Some(t1)) = (first, last) else {
        return Err(too_few(count));
    };
    if count < 2 {
        return Err(too_few(count));
    }
    let steps = ((t1 - t0) / dt_s).floor();
    // The grid's size comes from the log's time stamps (finite, so `steps` is not NaN):
    // bound it before allocating.
    if steps >= MAX_RESAMPLED_POINTS as f64 {
        return Err(LogError::InvalidArgument {
            name: "resampled points",
            value: steps + 1.0,
            reason: "more than 2^24 points: the log's time span is too long for the step",
        });
    }
    let n = steps as usize + 1;
    let mut out = Vec::with_capacity(n);
    let mut kept = increasing(times_s, values);
    let (Some(mut a), Some(mut b)) = (kept.next(), kept.next()) else {
        return Err(too_few(count));
    };
    // The index of `b` among the kept samples: `b` moves on while it is not the last one.
    let mut jb = 1;
    for i in 0..n {
        let t = t0 + i as f64 * dt_s;
        while jb + 1 < count && b.0 < t {
            let Some(next) = kept.next() else { break };
            (a, b) = (b, next);
            jb += 1;
        }
        let (ta, ya) = a;
        let (tb, yb) = b;
        let w = ((t - ta) / (tb - ta)).clamp(0.0, 1.0);
        out.push(ya + (yb - ya) * w);
    }
    Ok((t0, out))
}

/// The samples with finite values whose time is above every time kept before.
fn increasing<'a>(times_s: &'a [f64], values: &'a [f64]) -> impl Iterator<Item = (f64, f64)> + 'a {
    let mut last: Option<f64> = None;
    times_s.iter().zip(values).filter_map(move |(&t, &y)| {
        let keep = last.is_none_or(|tl| t > tl) && t.is_finite() && y.is_finite();
        keep.then(|| {
            last = Some(t);
            (t, y)
        })
    })
}

fn too_few(count: usize) -> LogError {
    LogError::InvalidArgument {
        name: "samples",
        value: count as f64,
        reason: "at least two samples with increasing time are needed",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn signal(n: usize) -> Vec<f64> {
        // A deterministic, non-periodic motion signal.
        (0..n)
            .map(|i| {
                let t = i as f64 * 0.1;
                (0.37 * t).sin() + 0.5 * (1.13 * t).sin() + 0.3 * (0.071 * t * t).cos()
            })
            .collect()
    }

    /// The copy-based version `resample_uniform` had before it walked the samples in place.
    fn resample_reference(times_s: &[f64], values: &[f64], dt_s: f64) -> Vec<f64> {
        let mut pts: Vec<(f64, f64)> = Vec::new();
        for (t, y) in times_s.iter().zip(values) {
            if pts.last().is_none_or(|(tl, _)| t > tl) && t.is_finite() && y.is_finite() {
                pts.push((*t, *y));
            }
        }
        let (t0, t1) = (pts[0].0, pts[pts.len() - 1].0);
        let n = ((t1 - t0) / dt_s).floor() as usize + 1;
        let mut j = 0;
        (0..n)
            .map(|i| {
                let t = t0 + i as f64 * dt_s;
                while j + 2 < pts.len() && pts[j + 1].0 < t {
                    j += 1;
                }
                let ((ta, ya), (tb, yb)) = (pts[j], pts[j + 1]);
                ya + (yb - ya) * ((t - ta) / (tb - ta)).clamp(0.0, 1.0)
            })
            .collect()
    }

    /// Bit for bit the reference, with repeated, backwards, NaN and infinite samples.
    #[test]
    fn resample_matches_the_copying_reference_bit_for_bit() {
        let mut times: Vec<f64> = (0..500)
            .map(|i| i as f64 * 0.037 + (i % 7) as f64 * 1e-3)
            .collect();
        let mut values: Vec<f64> = (0..500).map(|i| (i as f64 * 0.3).sin()).collect();
        times[10] = times[9];
        times[20] = times[15];
        times[30] = f64::NAN;
        values[40] = f64::NAN;
        values[50] = f64::INFINITY;
        for dt in [0.01, 0.1, 0.037, 1.0] {
            let (_, v) = resample_uniform(&times, &values, dt).unwrap();
            let r = resample_reference(&times, &values, dt);
            assert_eq!(v.len(), r.len());
            assert!(
                v.iter().zip(&r).all(|(a, b)| a.to_bits() == b.to_bits()),
                "{dt}"
            );
        }
    }

    /// The grid's size comes from the log's time stamps: a span of 300 years at 0.1 s (a
    /// corrupt stamp) is refused instead of allocating 10^11 points.
    #[test]
    fn a_time_span_too_long_for_the_step_is_refused_before_allocating() {
        for t1 in [1e10, f64::MAX, (MAX_RESAMPLED_POINTS as f64) * 0.1] {
            let e = resample_uniform(&[0.0, t1], &[1.0, 2.0], 0.1).unwrap_err();
            assert!(
                matches!(
                    e,
                    LogError::InvalidArgument {
                        name: "resampled points",
                        ..
                    }
                ),
                "{t1}: {e}"
            );
        }
        let (_, v) = resample_uniform(&[0.0, 1.0], &[1.0, 2.0], 0.1).unwrap();
        assert_eq!(v.len(), 11);
    }

    #[test]
    fn recovers_a_known_shift() {
        let m = signal(3000);
        let shift = 17; // 1.7 s
        let p: Vec<f64> = (0..m.len())
            .map(|i| 100.0 + 50.0 * m[i.saturating_sub(shift)] + 0.01 * i as f64)
            .collect();
        let e = estimate_lag_s(&p, &m, 0.1, 5.0).unwrap();
        // Integer shift: the parabola refinement moves the peak by well under half a sample.
        assert!((e.lag_s - 1.7).abs() < 0.05, "{e:?}");
        assert!(e.correlation > 0.99);
        assert!(e.correlation > e.correlation_at_zero);
        assert!(!e.at_window_edge);
        let e = estimate_lag_s(&m, &p, 0.1, 5.0).unwrap();
        assert!((e.lag_s + 1.7).abs() < 0.05, "{e:?}");
    }

    #[test]
    fn bad_arguments() {
        let m = signal(100);
        assert!(estimate_lag_s(&m, &m[..99], 0.1, 1.0).is_err());
        assert!(estimate_lag_s(&m, &m, 0.0, 1.0).is_err());
        assert!(estimate_lag_s(&m, &m, 0.1, 6.0).is_err());
        let c = vec![1.0; 100];
        assert!(estimate_lag_s(&c, &c, 0.1, 1.0).is_err());
        let mut n = m.clone();
        n[5] = f64::NAN;
        assert!(estimate_lag_s(&n, &m, 0.1, 1.0).is_err());
    }

    #[test]
    fn resample_is_exact_on_lines() {
        let t = [0.0, 0.3, 0.35, 1.0];
        let y: Vec<f64> = t.iter().map(|t| 2.0 * t + 1.0).collect();
        let (t0, v) = resample_uniform(&t, &y, 0.1).unwrap();
        assert_eq!(v.len(), 11);
        // Linear data is reproduced to rounding: 1e-12.
        for (i, v) in v.iter().enumerate() {
            assert!((v - (2.0 * (t0 + i as f64 * 0.1) + 1.0)).abs() < 1e-12);
        }
    }
}
