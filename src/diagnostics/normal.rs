//! Inverse of the standard normal CDF, needed by the rank normalisation.
//!
//! Wichura's AS 241 (PPND16), Applied Statistics 37(3), 477–484 (1988). Its rational
//! approximations are accurate to about 1e-16 relative, which is what keeps our z-scores within
//! rounding of scipy's `norm.ppf` (Cephes `ndtri`) and hence our R-hat and ESS within rounding of
//! ArviZ. A single-precision method such as Acklam's would need a refinement step to get there.
//!
//! Why not a crate: `statrs` (the maintained home of a normal quantile) depends on its own
//! nalgebra release, which would put a second nalgebra in the build for one function, and the
//! smaller crates that offer `ndtri` are unmaintained. These ~100 lines are pinned by the
//! reference quantiles below and by the ArviZ agreement of the diagnostics.

/// Standard normal quantile Φ⁻¹(p) for p in (0, 1); ±∞ at 0 and 1, NaN outside [0, 1].
///
/// Wichura (1988), AS 241 PPND16; relative error about 1e-16.
// The coefficients are quoted digit for digit as published, so they can be checked against the
// paper; the compiler rounds them to the nearest f64.
#[allow(clippy::excessive_precision)]
pub fn inverse_normal_cdf(p: f64) -> f64 {
    if p.is_nan() || !(0.0..=1.0).contains(&p) {
        return f64::NAN;
    }
    if p == 0.0 {
        return f64::NEG_INFINITY;
    }
    if p == 1.0 {
        return f64::INFINITY;
    }

    let q = p - 0.5;
    if q.abs() <= 0.425 {
        let r = 0.180625 - q * q;
        let num = poly(
            r,
            &[
                3.387_132_872_796_366_608,
                1.331_416_678_917_843_774_5e2,
                1.971_590_950_306_551_442_7e3,
                1.373_169_376_550_946_112_5e4,
                4.592_195_393_154_987_145_7e4,
                6.726_577_092_700_870_085_3e4,
                3.343_057_558_358_812_810_5e4,
                2.509_080_928_730_122_672_7e3,
            ],
        );
        let den = poly(
            r,
            &[
                1.0,
                4.231_333_070_160_091_125_2e1,
                6.871_870_074_920_579_083e2,
                5.394_196_021_424_751_107_7e3,
                2.121_379_430_158_659_586_7e4,
                3.930_789_580_009_271_061e4,
                2.872_908_573_572_194_267_4e4,
                5.226_495_278_852_854_561e3,
            ],
        );
        return q * num / den;
    }

    // Work with the smaller tail probability so that 1 - p never loses digits.
    let tail = if q < 0.0 { p } else { 1.0 - p };
    let r = (-tail.ln()).sqrt();
    let value = if r <= 5.0 {
        let r = r - 1.6;
        poly(
            r,
            &[
                1.423_437_110_749_683_577_34,
                4.630_337_846_156_545_295_9,
                5.769_497_221_460_691_405_5,
                3.647_848_324_763_204_605_04,
                1.270_458_252_452_368_382_58,
                2.417_807_251_774_506_117_7e-1,
                2.272_384_498_926_918_458_33e-2,
                7.745_450_142_783_414_076_4e-4,
            ],
        ) / poly(
            r,
            &[
                1.0,
                2.053_191_626_637_758_821_87,
                1.676_384_830_183_803_849_4,
                6.897_673_349_851_000_045_5e-1,
                1.481_039_764_274_800_745_9e-1,
                1.519_866_656_361_645_719_66e-2,
                5.475_938_084_995_344_946e-4,
                1.050_750_071_644_416_843_24e-9,
            ],
        )
    } else {
        let r = r - 5.0;
        poly(
            r,
            &[
                6.657_904_643_501_103_777_2,
                5.463_784_911_164_114_369_9,
                1.784_826_539_917_291_335_8,
                2.965_605_718_285_048_912_3e-1,
                2.653_218_952_657_612_309_3e-2,
                1.242_660_947_388_078_438_6e-3,
                2.711_555_568_743_487_578_15e-5,
                2.010_334_399_292_288_132_65e-7,
            ],
        ) / poly(
            r,
            &[
                1.0,
                5.998_322_065_558_879_376_9e-1,
                1.369_298_809_227_358_053_1e-1,
                1.487_536_129_085_061_485_25e-2,
                7.868_691_311_456_132_591e-4,
                1.846_318_317_510_054_681_8e-5,
                1.421_511_758_316_445_888_7e-7,
                2.044_263_103_389_939_785_64e-15,
            ],
        )
    };
    if q < 0.0 { -value } else { value }
}

/// Horner evaluation; `coefficients` in increasing powers, as AS 241 tabulates them.
fn poly(x: f64, coefficients: &[f64]) -> f64 {
    coefficients.iter().rev().fold(0.0, |acc, &c| acc * x + c)
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
