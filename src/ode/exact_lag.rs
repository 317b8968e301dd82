//! A first-order lag advanced in closed form over each integrator step.
//!
//! A state y that follows a source state x through τ·ẏ = x − y, and feeds nothing back, need
//! not be integrated: over an accepted step the integrator already holds x as its dense-output
//! polynomial p(θ) = Σ c_j θ^j (θ ∈ [0, 1] across the step of size h), and the lag of a
//! polynomial is exact by variation of constants:
//!
//!   y(θ) = e^z·y(0) − z·Σ_j j!·c_j·θ^j·φ_{j+1}(z),   z = −θh/τ,
//!
//! with the exponential integrators' φ_k(z) = Σ_m z^m/(m+k)!. An explicit scheme integrating y
//! instead must keep its step within a few τ, so a lag of microseconds on a millisecond record
//! makes every solve take tens of thousands of steps; in closed form it costs none, and y is
//! as accurate as the dense output of x.

use num_dual::DualNum;

/// A state the integrator advances exactly: `state` lags `source` with time constant `tau`
/// (τ > 0). The system's right-hand side must leave the state's derivative at zero.
#[derive(Clone, Copy, Debug)]
pub struct ExactLag<D> {
    pub state: usize,
    pub source: usize,
    pub tau: D,
}

/// 1/k! for k = 0..=5.
const INV_FACTORIAL: [f64; 6] = [1.0, 1.0, 0.5, 1.0 / 6.0, 1.0 / 24.0, 1.0 / 120.0];

/// Below this |z| φ_1…φ_5 come from φ_5's series and the downward recurrence
/// φ_k = z·φ_{k+1} + 1/k!, which loses nothing there; above it from e^z and the upward
/// recurrence φ_{k+1} = (φ_k − 1/k!)/z, which divides by a large |z| and is stable. At |z| = 4
/// the series' 40 terms leave a remainder below 10⁻²⁵.
const SERIES_RADIUS: f64 = 4.0;
const SERIES_TERMS: usize = 40;

/// e^z and φ_1(z) … φ_5(z) (index k holds φ_k, index 0 holds e^z).
fn phi<D: DualNum<Primitive = f64> + Copy>(z: D) -> [D; 6] {
    let mut out = [D::from(0.0); 6];
    if z.re().abs() <= SERIES_RADIUS {
        // φ_5(z) = Σ_m z^m/(m+5)!, summed from its smallest term (Horner form).
        let mut acc = D::from(0.0);
        for &c in SERIES.iter().rev() {
            acc = acc * z + c;
        }
        out[5] = acc;
        for k in (0..5).rev() {
            out[k] = z * out[k + 1] + INV_FACTORIAL[k];
        }
    } else {
        out[0] = z.exp();
        for k in 1..6 {
            out[k] = (out[k - 1] - INV_FACTORIAL[k - 1]) / z;
        }
    }
    out
}

/// 1/(m+5)! for m = 0..SERIES_TERMS: φ_5's series coefficients.
const SERIES: [f64; SERIES_TERMS] = {
    let mut c = [0.0; SERIES_TERMS];
    let mut v = 1.0 / 120.0;
    let mut m = 0;
    while m < SERIES_TERMS {
        c[m] = v;
        v /= (m + 6) as f64;
        m += 1;
    }
    c
};

/// The source's dense output over a step as monomial coefficients in θ: Hairer's form
/// c0 + θ(c1 + (1−θ)(c2 + θ(c3 + (1−θ)c4))) multiplied out.
pub fn monomials<D: DualNum<Primitive = f64> + Copy>(cont: [D; 5]) -> [D; 5] {
    let [a, b, c, d, e] = cont;
    [a, b + c, d + e - c, -(d + e * 2.0), e]
}

/// y at θ ∈ [0, 1] of a step of size h, from y at the step's start and the source's monomial
/// coefficients.
pub fn lag_at<D: DualNum<Primitive = f64> + Copy>(
    y0: D,
    tau: D,
    h: f64,
    theta: f64,
    coef: &[D; 5],
) -> D {
    if theta <= 0.0 {
        return y0;
    }
    let z = -(tau.recip() * (theta * h));
    let phi = phi(z);
    let mut sum = D::from(0.0);
    let mut power = 1.0;
    for (j, c) in coef.iter().enumerate() {
        // j!·φ_{j+1} = φ_{j+1}/(1/j!)
        sum += *c * (phi[j + 1] * (power / INV_FACTORIAL[j]));
        power *= theta;
    }
    phi[0] * y0 - z * sum
}

#[cfg(test)]
mod tests {
    use super::*;

    /// φ_k against their closed forms where those are well conditioned.
    #[test]
    fn phi_functions_match_their_closed_forms_on_both_branches() {
        for &z in &[-0.3f64, -1.0, -3.9, -4.1, -12.0, -300.0, 0.7] {
            let p = phi(z);
            let e = z.exp();
            assert!((p[0] - e).abs() <= 1e-15 * e.max(1.0), "e^z at {z}");
            let phi1 = (e - 1.0) / z;
            assert!((p[1] - phi1).abs() <= 1e-13 * phi1.abs(), "φ1 at {z}");
            let phi2 = (e - 1.0 - z) / (z * z);
            if z.abs() > 0.5 {
                assert!((p[2] - phi2).abs() <= 1e-12 * phi2.abs(), "φ2 at {z}");
            }
        }
    }

    /// The lag of a cubic against the same ODE integrated by a fine classical RK4.
    #[test]
    fn a_lagged_polynomial_matches_a_fine_integration_of_its_ode() {
        let coef = [0.3, -1.2, 2.5, 0.7, -0.4];
        let p = |th: f64| coef.iter().rev().fold(0.0, |acc, c| acc * th + c);
        for &(tau, h) in &[(1e-6, 1e-3), (1e-3, 1e-3), (5.0, 1e-3), (2e-4, 1e-3)] {
            let y0 = 0.9;
            let n = 200_000;
            let dt = 1.0 / n as f64;
            // dy/dθ = h/τ·(p(θ) − y)
            let f = |th: f64, y: f64| h / tau * (p(th) - y);
            let mut y = y0;
            for i in 0..n {
                let th = i as f64 * dt;
                let k1 = f(th, y);
                let k2 = f(th + dt / 2.0, y + dt / 2.0 * k1);
                let k3 = f(th + dt / 2.0, y + dt / 2.0 * k2);
                let k4 = f(th + dt, y + dt * k3);
                y += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
            }
            let exact = lag_at(y0, tau, h, 1.0, &coef);
            assert!(
                (exact - y).abs() < 1e-9,
                "τ = {tau}: closed form {exact}, integrated {y}"
            );
        }
    }

    #[test]
    fn monomials_reproduce_hairers_dense_form() {
        let cont = [0.5, -0.25, 1.5, 0.75, -2.0];
        let m = monomials(cont);
        for &th in &[0.0, 0.2, 0.6, 1.0] {
            let hairer = cont[0]
                + th * (cont[1] + (1.0 - th) * (cont[2] + th * (cont[3] + (1.0 - th) * cont[4])));
            let mono: f64 = m.iter().rev().fold(0.0, |acc, c| acc * th + c);
            assert!((hairer - mono).abs() < 1e-14);
        }
    }
}
