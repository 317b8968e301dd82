//! Bases for the discrepancy term δ(t) = Σ_j a_j p_j(t) (eq. 16–18). Legendre polynomials now;
//! the trait is the extension point for bases suited to long records (splines, reduced-rank GPs).

use nalgebra::DMatrix;

/// A finite set of functions of time on a recording's interval.
pub trait DiscrepancyBasis: Send + Sync + std::fmt::Debug {
    /// A short description for reports, e.g. "legendre(K=9)".
    fn describe(&self) -> String;
    fn n_functions(&self) -> usize;
    /// The values of every function at `t`.
    fn evaluate(&self, t: f64, out: &mut [f64]);

    /// The design matrix B with B[i, j] = p_j(t_i).
    fn matrix(&self, times: &[f64]) -> DMatrix<f64> {
        let n = self.n_functions();
        let mut b = DMatrix::zeros(times.len(), n);
        let mut row = vec![0.0; n];
        for (i, &t) in times.iter().enumerate() {
            self.evaluate(t, &mut row);
            for j in 0..n {
                b[(i, j)] = row[j];
            }
        }
        b
    }
}

/// p_j(t) = √(2j+1) P_j(2t/T − 1), j = 0..=K: orthonormal under dt/T on [0, T].
#[derive(Clone, Debug, PartialEq)]
pub struct Legendre {
    pub degree: usize,
    pub t_end: f64,
}

/// K beyond this is refused: the paper's study stops at 20, and the three-term recurrence
/// stays accurate well past 40, but the posterior is then a prior in disguise.
pub const MAX_LEGENDRE_DEGREE: usize = 40;

impl Legendre {
    pub fn new(degree: usize, t_end: f64) -> Result<Self, String> {
        if degree > MAX_LEGENDRE_DEGREE {
            return Err(format!(
                "discrepancy degree K = {degree} is larger than the maximum {MAX_LEGENDRE_DEGREE}"
            ));
        }
        if !(t_end > 0.0 && t_end.is_finite()) {
            return Err(format!(
                "the recording must end after t = 0 (last time {t_end})"
            ));
        }
        Ok(Self { degree, t_end })
    }
}

impl DiscrepancyBasis for Legendre {
    fn describe(&self) -> String {
        format!("legendre(K={})", self.degree)
    }

    fn n_functions(&self) -> usize {
        self.degree + 1
    }

    fn evaluate(&self, t: f64, out: &mut [f64]) {
        let x = 2.0 * t / self.t_end - 1.0;
        let (mut previous, mut current) = (0.0, 1.0);
        for (j, slot) in out.iter_mut().enumerate().take(self.degree + 1) {
            *slot = current * ((2 * j + 1) as f64).sqrt();
            let next = ((2 * j + 1) as f64 * x * current - j as f64 * previous) / (j + 1) as f64;
            previous = current;
            current = next;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn legendre_basis_is_orthonormal_under_dt_over_t() {
        let basis = Legendre::new(12, 0.5).unwrap();
        // Gauss–Legendre would be exact; a fine midpoint rule is accurate enough here.
        let n = 20_000;
        let times: Vec<f64> = (0..n).map(|i| (i as f64 + 0.5) * 0.5 / n as f64).collect();
        let b = basis.matrix(&times);
        let gram = b.transpose() * &b / n as f64;
        for j in 0..13 {
            for k in 0..13 {
                let expected = if j == k { 1.0 } else { 0.0 };
                assert!(
                    (gram[(j, k)] - expected).abs() < 1e-3,
                    "({j},{k}) = {}",
                    gram[(j, k)]
                );
            }
        }
    }

    #[test]
    fn first_polynomials_have_their_closed_forms() {
        let basis = Legendre::new(2, 2.0).unwrap();
        let mut v = [0.0; 3];
        basis.evaluate(1.5, &mut v); // x = 0.5
        assert!((v[0] - 1.0).abs() < 1e-15);
        assert!((v[1] - 3f64.sqrt() * 0.5).abs() < 1e-15);
        assert!((v[2] - 5f64.sqrt() * (1.5 * 0.25 - 0.5)).abs() < 1e-15);
        assert!(Legendre::new(41, 1.0).is_err());
    }
}
