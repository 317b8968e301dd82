//! Inverse of the standard normal CDF, needed by the rank normalisation: statrs's, which is
//! accurate to a few ulp (the tests below hold it to 4 ulp of scipy's `norm.ppf`), enough to keep
//! our z-scores within rounding of ArviZ's and hence R-hat and ESS within rounding of ArviZ's
//! (`tests/diagnostics_arviz.rs`). statrs is built without its default features, so it brings
//! no second nalgebra or rand.

use statrs::distribution::{ContinuousCDF, Normal};

/// Standard normal quantile Φ⁻¹(p) for p in (0, 1); ±∞ at 0 and 1, NaN outside [0, 1].
pub fn inverse_normal_cdf(p: f64) -> f64 {
    if !(0.0..=1.0).contains(&p) {
        return f64::NAN;
    }
    Normal::standard().inverse_cdf(p)
}

#[cfg(test)]
mod tests {
    use super::inverse_normal_cdf;

    #[test]
    fn matches_reference_quantiles() {
        // Values from scipy.stats.norm.ppf (Cephes ndtri) and a Newton check against erfc.
        let cases: [(f64, f64); 7] = [
            (0.5, 0.0),
            (0.975, 1.959_963_984_540_054),
            (0.3, -0.524_400_512_708_040_7),
            (0.05, -1.644_853_626_951_472_7),
            (0.9, 1.281_551_565_544_600_4),
            (1e-10, -6.361_340_902_404_056),
            (1e-300, -37.047_096_299_361_2),
        ];
        for (p, expected) in cases {
            let got = inverse_normal_cdf(p);
            let tol = 4.0 * f64::EPSILON * f64::max(1.0, expected.abs());
            assert!(
                (got - expected).abs() <= tol,
                "p = {p}: {got} vs {expected}"
            );
        }
    }

    #[test]
    fn symmetric_and_monotone() {
        let mut previous = f64::NEG_INFINITY;
        // Dyadic p so that 1 − p is exact and the mirror image is a fair comparison.
        for i in 1..2048 {
            let p = f64::from(i) / 2048.0;
            let z = inverse_normal_cdf(p);
            assert!(z > previous);
            previous = z;
            let mirrored = inverse_normal_cdf(1.0 - p);
            assert!((z + mirrored).abs() <= 1e-15 * f64::max(1.0, z.abs()));
        }
    }

    #[test]
    fn edges() {
        assert_eq!(inverse_normal_cdf(0.0), f64::NEG_INFINITY);
        assert_eq!(inverse_normal_cdf(1.0), f64::INFINITY);
        assert!(inverse_normal_cdf(-0.1).is_nan());
        assert!(inverse_normal_cdf(1.1).is_nan());
        assert!(inverse_normal_cdf(f64::NAN).is_nan());
    }
}
