//! Welford's running mean and (co)variance: the one estimator every adaptation uses (Stan's
//! metric windows, MALA's preconditioner, Haario's adaptive Metropolis).

use nalgebra::DMatrix;

/// How Welford's M₂ takes a draw's deviation: (x − x̄ₙ)·δ with δ = x − x̄ₙ₋₁, as Stan and MALA
/// estimate their metrics, or δ·δ·(n−1)/n, which is the same number in exact arithmetic and
/// symmetric by construction, as Haario's adaptive Metropolis keeps its covariance. The two
/// round differently, so each sampler keeps its own and with it its draws.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WelfordForm {
    #[default]
    DeviationAfter,
    ScaledDelta,
}

/// Welford's running mean and (co)variance, allocation-free after `reset`: the one estimator
/// every adaptation uses.
#[derive(Clone, Debug, Default)]
pub struct Welford {
    dense: bool,
    form: WelfordForm,
    n: usize,
    mean: Vec<f64>,
    delta: Vec<f64>,
    /// Σ of the deviations' products: the diagonal, or the whole matrix column-major.
    m2: Vec<f64>,
}

impl Welford {
    pub fn new(dim: usize, dense: bool, form: WelfordForm) -> Self {
        let mut w = Self {
            dense,
            form,
            ..Self::default()
        };
        w.reset_to(dim);
        w
    }

    /// Forgets every draw (the dimension stays).
    pub fn reset(&mut self) {
        self.reset_to(self.mean.len());
    }

    /// Forgets every draw and takes draws of dimension `dim`.
    pub fn reset_to(&mut self, dim: usize) {
        self.n = 0;
        self.mean.clear();
        self.mean.resize(dim, 0.0);
        self.delta.clear();
        self.delta.resize(dim, 0.0);
        self.m2.clear();
        self.m2
            .resize(if self.dense { dim * dim } else { dim }, 0.0);
    }

    pub fn count(&self) -> usize {
        self.n
    }

    pub fn dim(&self) -> usize {
        self.mean.len()
    }

    pub fn add(&mut self, x: &[f64]) {
        self.n += 1;
        let n = self.n as f64;
        for ((d, m), x) in self.delta.iter_mut().zip(self.mean.iter_mut()).zip(x) {
            *d = x - *m;
            *m += *d / n;
        }
        let d = x.len();
        match (self.form, self.dense) {
            (WelfordForm::DeviationAfter, false) => {
                for i in 0..d {
                    self.m2[i] += (x[i] - self.mean[i]) * self.delta[i];
                }
            }
            (WelfordForm::DeviationAfter, true) => {
                for j in 0..d {
                    for i in 0..d {
                        self.m2[i + j * d] += (x[i] - self.mean[i]) * self.delta[j];
                    }
                }
            }
            (WelfordForm::ScaledDelta, dense) => {
                let shrink = (n - 1.0) / n;
                for j in 0..d {
                    let dj = self.delta[j] * shrink;
                    if dense {
                        for i in 0..d {
                            self.m2[i + j * d] += self.delta[i] * dj;
                        }
                    } else {
                        self.m2[j] += self.delta[j] * dj;
                    }
                }
            }
        }
    }

    /// M₂ of coordinates (i, j) (only i = j when diagonal).
    pub fn m2(&self, i: usize, j: usize) -> f64 {
        if self.dense {
            self.m2[i + j * self.mean.len()]
        } else {
            debug_assert_eq!(i, j);
            self.m2[i]
        }
    }

    /// M₂ as a d×d matrix (dense estimators only).
    pub fn m2_matrix(&self) -> DMatrix<f64> {
        let d = self.mean.len();
        DMatrix::from_column_slice(d, d, &self.m2)
    }

    /// The diagonal of M₂.
    pub fn m2_diagonal(&self) -> Vec<f64> {
        (0..self.mean.len()).map(|i| self.m2(i, i)).collect()
    }
}
