//! `sin` and `cos` of an attitude angle together: the first step of every point query.
//!
//! Attitude angles of a flying multirotor are almost always within +-45 deg. There both values
//! come from degree-5 polynomials in `z = x^2` (fitted below), evaluated by Estrin's scheme so the
//! chain is short. Outside +-45 deg, and for NaN, libm's `sincos` (range reduction included)
//! takes over. Tests hold both results within 2 ulp of the standard library's.

// The fitted coefficients keep the fit's 20 digits; the compiler rounds them to the nearest f64.
#![allow(clippy::excessive_precision)]

use std::f64::consts::FRAC_PI_4;

/// `(sin x, cos x)`.
#[inline(always)]
pub(crate) fn sin_cos(x: f64) -> (f64, f64) {
    if x.abs() <= FRAC_PI_4 {
        let ([s, _], [c, _]) = kernel([x, 0.0]);
        (s, c)
    } else {
        libm::sincos(x)
    }
}

/// `((sin x, cos x), (sin y, cos y))`: both angles of an attitude at once (the two series run
/// side by side, two lanes of one vector register on x86-64).
#[inline(always)]
pub(crate) fn sin_cos_pair(x: f64, y: f64) -> ((f64, f64), (f64, f64)) {
    if (x.abs() <= FRAC_PI_4) & (y.abs() <= FRAC_PI_4) {
        let ([sx, sy], [cx, cy]) = kernel([x, y]);
        ((sx, cx), (sy, cy))
    } else {
        (sin_cos(x), sin_cos(y))
    }
}

// sin x = x + x z S(z) and cos x = 1 - z/2 + z^2 C(z), z = x^2, |x| <= pi/4. S and C are degree-5
// Chebyshev fits (mpmath `chebyfit`, 50 digits) of (sin(x)/x - 1)/z and (cos x - 1 + z/2)/z^2 on
// z in [0, (pi/4)^2], with fit errors 2.0e-17 and 1.3e-18: below 0.1 ulp of sin and cos there.
// Their first coefficients are -1/6 and 1/24 to within 1e-17.
const S0: f64 = -0.166_666_666_666_666_646_24;
const S1: f64 = 0.008_333_333_333_330_948_485_5;
const S2: f64 = -0.000_198_412_698_367_585_743_23;
const S3: f64 = 0.000_002_755_731_610_255_244_011_9;
const S4: f64 = -0.000_000_025_051_131_845_003_624_417;
const S5: f64 = 0.000_000_000_159_181_292_948_666_086_67;
const C0: f64 = 0.041_666_666_666_666_665_389;
const C1: f64 = -0.001_388_888_888_888_739_723_7;
const C2: f64 = 0.000_024_801_587_298_765_687_927;
const C3: f64 = -0.000_000_275_573_172_717_297_928_82;
const C4: f64 = 0.000_000_002_087_614_626_840_319_789_3;
const C5: f64 = -0.000_000_000_011_382_632_425_521_718_005;

/// Both series for `|x| <= pi/4`, lane by lane.
#[inline(always)]
fn kernel(x: [f64; 2]) -> ([f64; 2], [f64; 2]) {
    let mut sin = [0.0; 2];
    let mut cos = [0.0; 2];
    for k in 0..2 {
        let x = x[k];
        let z = x * x;
        let z2 = z * z;
        let z4 = z2 * z2;
        // Estrin's scheme: pairs in parallel, then powers of z, so the chain is short. (Plain
        // multiply-adds: `mul_add` is a library call on the baseline x86-64 target, which has no
        // FMA.)
        let s = (S0 + S1 * z) + z2 * (S2 + S3 * z) + z4 * (S4 + S5 * z);
        let c = (C0 + C1 * z) + z2 * (C2 + C3 * z) + z4 * (C4 + C5 * z);
        sin[k] = x + (x * z) * s;
        // 1 - z/2 is computed as w + ((1 - w) - z/2) with w = 1 - z/2 rounded, keeping the low
        // bits that rounding w drops (the standard trick for cos near pi/4).
        let hz = 0.5 * z;
        let w = 1.0 - hz;
        cos[k] = w + (((1.0 - w) - hz) + z2 * c);
    }
    (sin, cos)
}

#[cfg(test)]
// Exact comparisons check values that are exact by construction (sin 0, cos 0) and ulp distances.
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Distance in units in the last place (of the reference).
    fn ulps(got: f64, reference: f64) -> f64 {
        if got == reference {
            return 0.0;
        }
        let ulp = f64::from_bits(reference.abs().to_bits() + 1) - reference.abs();
        (got - reference).abs() / ulp
    }

    #[test]
    fn exact_points_and_edges() {
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        assert_eq!(sin_cos(-0.0), (0.0, 1.0));
        let (s, c) = sin_cos(f64::NAN);
        assert!(s.is_nan() && c.is_nan());
        for x in [FRAC_PI_4, -FRAC_PI_4, 1e-300, 1e-8, 0.5, 1.2, -3.0, 100.0] {
            let (s, c) = sin_cos(x);
            assert!(ulps(s, x.sin()) <= 2.0 && ulps(c, x.cos()) <= 2.0, "{x}");
        }
    }

    #[test]
    fn dense_sweep_of_the_kernel_range_within_2_ulp() {
        let n = 200_000;
        let mut worst: f64 = 0.0;
        for i in 0..=n {
            let x = FRAC_PI_4 * (2.0 * f64::from(i) / f64::from(n) - 1.0);
            let (s, c) = sin_cos(x);
            worst = worst.max(ulps(s, x.sin())).max(ulps(c, x.cos()));
        }
        assert!(worst <= 2.0, "worst {worst} ulp");
    }

    proptest! {
        #[test]
        fn within_2_ulp_of_std(x in -3.2f64..3.2) {
            let (s, c) = sin_cos(x);
            prop_assert!(ulps(s, x.sin()) <= 2.0, "sin {}", x);
            prop_assert!(ulps(c, x.cos()) <= 2.0, "cos {}", x);
        }
    }
}
