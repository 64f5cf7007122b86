//! `sin` and `cos` of an attitude angle together: the first step of every point query.
//!
//! Attitude angles of a flying multirotor are almost always within +-45 deg. There both values
//! come from their Taylor series in `z = x^2` (through `x^17` for sin and `x^16` for cos; the first
//! omitted terms are below 1e-19 at `|x| = pi/4`), evaluated in two interleaved Horner halves so
//! the chain is short. Outside +-45 deg, and for NaN, libm's `sincos` (range reduction included)
//! takes over. Tests hold both results within 2 ulp of the standard library's.

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

/// `1/n!` for the Taylor coefficients (exact to the last bit of the f64 quotient).
const fn inv_factorial(n: u32) -> f64 {
    let mut f = 1.0;
    let mut k = 2;
    while k <= n {
        f *= k as f64;
        k += 1;
    }
    1.0 / f
}

// sin x = x (1 + z S(z)), S(z) = sum_{k=0..7} (-1)^(k+1) z^k / (2k+3)!
const S0: f64 = -inv_factorial(3);
const S1: f64 = inv_factorial(5);
const S2: f64 = -inv_factorial(7);
const S3: f64 = inv_factorial(9);
const S4: f64 = -inv_factorial(11);
const S5: f64 = inv_factorial(13);
const S6: f64 = -inv_factorial(15);
const S7: f64 = inv_factorial(17);
// cos x = 1 - z/2 + z^2 C(z), C(z) = sum_{k=0..6} (-1)^k z^k / (2k+4)!
const C0: f64 = inv_factorial(4);
const C1: f64 = -inv_factorial(6);
const C2: f64 = inv_factorial(8);
const C3: f64 = -inv_factorial(10);
const C4: f64 = inv_factorial(12);
const C5: f64 = -inv_factorial(14);
const C6: f64 = inv_factorial(16);

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
        // Each polynomial as low + z^4 high, the two halves in parallel. (Plain multiply-adds:
        // `mul_add` is a library call on the baseline x86-64 target, which has no FMA.)
        let s_lo = ((S3 * z + S2) * z + S1) * z + S0;
        let s_hi = ((S7 * z + S6) * z + S5) * z + S4;
        let s = s_hi * z4 + s_lo;
        let c_lo = ((C3 * z + C2) * z + C1) * z + C0;
        let c_hi = (C6 * z + C5) * z + C4;
        let c = c_hi * z4 + c_lo;
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
