//! The standard normal distribution: cdf and its inverse.

use crate::Real;

/// Standard normal cumulative distribution function `Phi(x)`.
///
/// Computed as `erfc(-x / sqrt 2) / 2`, which keeps full relative accuracy in the
/// lower tail (`Phi(-10) ~ 7.6e-24`), where `1 - Phi` forms would round to zero.
pub fn normal_cdf(x: Real) -> Real {
    0.5 * libm::erfc(-x * std::f64::consts::FRAC_1_SQRT_2)
}

/// Inverse of the standard normal cdf, `Phi^-1(p)` for `p` in `(0, 1)`.
///
/// Acklam's rational approximation (relative error 1.15e-9) refined by one Halley
/// step on [`normal_cdf`], which brings it to machine precision. Returns `-inf` at
/// `p = 0`, `+inf` at `p = 1` and NaN outside `[0, 1]`.
pub fn normal_quantile(p: Real) -> Real {
    const A: [Real; 6] = [
        -3.969683028665376e+01,
        2.209460984245205e+02,
        -2.759285104469687e+02,
        1.383_577_518_672_69e2,
        -3.066479806614716e+01,
        2.506628277459239e+00,
    ];
    const B: [Real; 5] = [
        -5.447609879822406e+01,
        1.615858368580409e+02,
        -1.556989798598866e+02,
        6.680131188771972e+01,
        -1.328068155288572e+01,
    ];
    const C: [Real; 6] = [
        -7.784894002430293e-03,
        -3.223964580411365e-01,
        -2.400758277161838e+00,
        -2.549732539343734e+00,
        4.374664141464968e+00,
        2.938163982698783e+00,
    ];
    const D: [Real; 4] = [
        7.784695709041462e-03,
        3.224671290700398e-01,
        2.445134137142996e+00,
        3.754408661907416e+00,
    ];
    if p.is_nan() || !(0.0..=1.0).contains(&p) {
        return Real::NAN;
    }
    if p == 0.0 {
        return Real::NEG_INFINITY;
    }
    if p == 1.0 {
        return Real::INFINITY;
    }
    let p_low = 0.02425;
    let x = if p < p_low {
        let q = (-2.0 * p.ln()).sqrt();
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    } else if p <= 1.0 - p_low {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        let q = (-2.0 * (1.0 - p).ln()).sqrt();
        -(((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    // One Halley step: e = Phi(x) - p, u = e * sqrt(2 pi) * exp(x^2 / 2).
    let e = normal_cdf(x) - p;
    let u = e * (2.0 * std::f64::consts::PI).sqrt() * (0.5 * x * x).exp();
    x - u / (1.0 + 0.5 * x * u)
}

/// The probability that a quantity with mean `margin` and standard deviation
/// `sd` is not positive, `Phi(-margin / sd)`; exact (0 or 1) without spread
/// (`sd = 0`, or not finite): 1 for a margin of 0 or less. The one tail every
/// "wrong side" probability of the crate uses.
pub(crate) fn wrong_side(margin: Real, sd: Real) -> Real {
    if sd > 0.0 && sd.is_finite() {
        normal_cdf(-margin / sd)
    } else if margin > 0.0 {
        0.0
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cdf_known_values() {
        assert!((normal_cdf(0.0) - 0.5).abs() < 1e-16);
        assert!((normal_cdf(1.0) - 0.841_344_746_068_542_9).abs() < 1e-15);
        assert!((normal_cdf(-3.0) - 0.001_349_898_031_630_094_6).abs() < 1e-17);
        // Tail keeps relative accuracy.
        let t = normal_cdf(-10.0);
        assert!((t / 7.619_853_024_160_527e-24 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn quantile_inverts_cdf() {
        for &p in &[
            1e-12, 1e-6, 0.001, 0.02, 0.1, 0.3, 0.5, 0.7, 0.975, 0.999_999,
        ] {
            let x = normal_quantile(p);
            assert!((normal_cdf(x) / p - 1.0).abs() < 1e-12, "p = {p}, x = {x}");
        }
        assert!((normal_quantile(0.975) - 1.959_963_984_540_054).abs() < 1e-12);
        assert!(normal_quantile(-0.1).is_nan());
        assert_eq!(normal_quantile(0.0), f64::NEG_INFINITY);
    }
}
