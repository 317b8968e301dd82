//! What the simulation-based calibration tests share: the χ² survival function their
//! uniformity test needs (no statistics crate is a dependency), tested against known values.

use motorcal::bayes::ln_gamma;

/// Q(a, x) for a > 0, x ≥ 0. Below x = a + 1 the power series of P = 1 − Q converges fast;
/// above, Legendre's continued fraction for Γ(a, x) does (evaluated by the modified Lentz
/// method). Each is used where it needs the fewest terms and loses no precision to 1 − P.
fn gamma_q(a: f64, x: f64) -> f64 {
    assert!(a > 0.0 && x >= 0.0, "Q({a}, {x}) is not defined");
    if x == 0.0 {
        1.0
    } else if x < a + 1.0 {
        1.0 - gamma_p_series(a, x)
    } else {
        gamma_q_continued_fraction(a, x)
    }
}

/// e^{−x} x^a / Γ(a), the factor both expansions share, in logs to survive large a and x.
fn prefactor(a: f64, x: f64) -> f64 {
    (a * x.ln() - x - ln_gamma(a)).exp()
}

/// P(a, x) = e^{−x} x^a / Γ(a) · Σ_{n≥0} x^n / (a (a+1) ⋯ (a+n)).
fn gamma_p_series(a: f64, x: f64) -> f64 {
    let mut term = 1.0 / a;
    let mut sum = term;
    for n in 1..10_000 {
        term *= x / (a + n as f64);
        sum += term;
        if term.abs() < sum.abs() * f64::EPSILON {
            return sum * prefactor(a, x);
        }
    }
    panic!("the series of P({a}, {x}) did not converge");
}

/// Q(a, x) = e^{−x} x^a / Γ(a) · 1/(x+1−a − 1·(1−a)/(x+3−a − 2·(2−a)/(x+5−a − ⋯))), the
/// even part of Legendre's continued fraction, by the modified Lentz method: the n-th
/// convergent is the running product of C_n/D_n-style ratios, with tiny values replacing zeros.
fn gamma_q_continued_fraction(a: f64, x: f64) -> f64 {
    let tiny = f64::MIN_POSITIVE / f64::EPSILON;
    let mut b = x + 1.0 - a;
    let mut c = 1.0 / tiny;
    let mut d = 1.0 / b;
    let mut h = d;
    for n in 1..10_000 {
        let n = n as f64;
        let an = -n * (n - a);
        b += 2.0;
        d = an * d + b;
        if d.abs() < tiny {
            d = tiny;
        }
        c = b + an / c;
        if c.abs() < tiny {
            c = tiny;
        }
        d = 1.0 / d;
        let delta = d * c;
        h *= delta;
        if (delta - 1.0).abs() < f64::EPSILON {
            return prefactor(a, x) * h;
        }
    }
    panic!("the continued fraction of Q({a}, {x}) did not converge");
}

/// P(χ²_k > x).
pub fn chi_square_survival(x: f64, dof: usize) -> f64 {
    gamma_q(dof as f64 / 2.0, x / 2.0)
}

#[test]
fn the_incomplete_gamma_and_chi_square_tails_match_known_values() {
    let close = |got: f64, want: f64, what: &str| {
        assert!(
            (got - want).abs() <= 1e-12 * want.max(1e-300) + 1e-15,
            "{what}: {got} vs {want}"
        );
    };
    // Integer a: Q(n, x) = e^{−x} Σ_{k<n} x^k/k!, on both sides of x = a + 1 (series and
    // continued fraction).
    for (n, x) in [
        (1, 0.3),
        (1, 7.0),
        (3, 1.0),
        (3, 10.0),
        (10, 5.0),
        (10, 20.0),
        (25, 24.0),
        (25, 26.5),
    ] {
        let mut term = 1.0;
        let mut sum = 0.0;
        for k in 0..n {
            if k > 0 {
                term *= x / k as f64;
            }
            sum += term;
        }
        close(
            gamma_q(n as f64, x),
            (-x).exp() * sum,
            &format!("Q({n}, {x})"),
        );
    }
    // Half-integer a: Q(3/2, x) = erfc(√x) + 2√(x/π) e^{−x}; with erfc(1) = 0.157299207050285…
    let erfc_1 = 0.157_299_207_050_285_13;
    close(
        gamma_q(1.5, 1.0),
        erfc_1 + 2.0 / std::f64::consts::PI.sqrt() * (-1.0f64).exp(),
        "Q(3/2, 1)",
    );
    close(gamma_q(0.5, 1.0), erfc_1, "Q(1/2, 1)");
    // Quantiles of χ² tables (scipy.stats.chi2.isf): the survival function inverts them.
    for (x, dof, p) in [
        (3.841_458_820_694_124, 1, 0.05),
        (9.487_729_036_781_154, 4, 0.05),
        (13.276_704_135_987_622, 4, 0.01),
        (21.665_994_333_461_924, 9, 0.01),
        (30.143_527_205_646_16, 19, 0.05),
        (2.087_900_774_933_263_5, 9, 0.99),
    ] {
        let got = chi_square_survival(x, dof);
        assert!(
            (got - p).abs() < 1e-9,
            "P(χ²_{dof} > {x}) = {got}, tables say {p}"
        );
    }
    assert_eq!(chi_square_survival(0.0, 4), 1.0);
    assert!(chi_square_survival(200.0, 4) < 1e-40);
}
