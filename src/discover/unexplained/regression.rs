//! The linearised likelihood ratio every alternative of the verdict is scored by.
//!
//! At the selected model's MAP the whitened residual y (each channel divided by its σ̂) is, under
//! that model, white noise of unit variance, and the model's parameters can still move along
//! the columns of the whitened sensitivity matrix J = ∂G/∂θ / σ̂. An alternative adds the columns
//! B (a polynomial in time, lagged residuals, a sinusoid, the prediction's derivative); refitting
//! model and alternative together gains, to first order, ½·‖P_B̃ y‖² in log likelihood, with B̃
//! the part of B that J cannot reproduce (Frisch–Waugh: B̃ = B − P_J B). Under the model that
//! gain is ½χ² with rank(B̃) degrees of freedom: what makes a threshold on it a false-alarm rate.

use nalgebra::{DMatrix, DVector, SymmetricEigen};

/// Eigenvalues below this share of the largest are treated as zero: columns that are (nearly)
/// combinations of others add nothing and count no degree of freedom.
const RANK_TOLERANCE: f64 = 1e-10;

/// A symmetric positive semi-definite matrix's pseudo-inverse and rank.
fn pseudo_inverse(g: DMatrix<f64>) -> (DMatrix<f64>, usize) {
    let n = g.nrows();
    if n == 0 {
        return (g, 0);
    }
    let eig = SymmetricEigen::new(g);
    let top = eig.eigenvalues.iter().cloned().fold(0.0, f64::max);
    let mut inv = DMatrix::zeros(n, n);
    let mut rank = 0;
    for (k, &lambda) in eig.eigenvalues.iter().enumerate() {
        if lambda > RANK_TOLERANCE * top && lambda > 0.0 {
            rank += 1;
            let v = eig.eigenvectors.column(k);
            inv += (v * v.transpose()) / lambda;
        }
    }
    (inv, rank)
}

/// The model's whitened sensitivities, ready to project alternatives against.
pub struct Projector {
    j: DMatrix<f64>,
    gram_inverse: DMatrix<f64>,
}

impl Projector {
    pub fn new(j: DMatrix<f64>) -> Self {
        let (gram_inverse, _) = pseudo_inverse(j.transpose() * &j);
        Self { j, gram_inverse }
    }

    /// B − P_J B.
    pub fn residualize(&self, b: &DMatrix<f64>) -> DMatrix<f64> {
        if self.j.ncols() == 0 {
            return b.clone();
        }
        let coefficients = &self.gram_inverse * (self.j.transpose() * b);
        b - &self.j * coefficients
    }
}

/// What an alternative's columns explain of the whitened residual.
#[derive(Clone, Debug)]
pub struct Explained {
    /// ½·‖P_B̃ y‖²: the gain in log likelihood (nats).
    pub gain: f64,
    /// rank(B̃): the degrees of freedom it spends.
    pub rank: usize,
    /// The coefficients of B's columns (σ = 1 in whitened units).
    pub coefficients: Vec<f64>,
    /// B̃·coefficients: the part of y it explains.
    pub fitted: DVector<f64>,
    /// The pointwise sd of `fitted`.
    pub fitted_sd: DVector<f64>,
}

/// The gain alone, for searches over many alternatives.
pub fn gain(y: &DVector<f64>, b: &DMatrix<f64>) -> f64 {
    gain_from_normal_equations(&(b.transpose() * y), b.transpose() * b)
}

/// [`gain`] from its normal equations: ½·hᵀG⁺h with h = Bᵀy and G = BᵀB.
pub fn gain_from_normal_equations(h: &DVector<f64>, g: DMatrix<f64>) -> f64 {
    let (g_inv, _) = pseudo_inverse(g);
    0.5 * h.dot(&(&g_inv * h))
}

/// The sds of the coefficients of B̃'s columns (σ = 1 in whitened units): √diag((B̃ᵀB̃)⁺).
pub fn coefficient_sds(b_tilde: &DMatrix<f64>) -> Vec<f64> {
    let (g_inv, _) = pseudo_inverse(b_tilde.transpose() * b_tilde);
    (0..g_inv.nrows())
        .map(|i| g_inv[(i, i)].max(0.0).sqrt())
        .collect()
}

/// Regress y on B̃ (already residualized against the model).
pub fn explain(y: &DVector<f64>, b_tilde: &DMatrix<f64>) -> Explained {
    let h = b_tilde.transpose() * y;
    let (g_inv, rank) = pseudo_inverse(b_tilde.transpose() * b_tilde);
    let beta = &g_inv * &h;
    let fitted = b_tilde * &beta;
    let gain = 0.5 * h.dot(&beta);
    let rows_cov = b_tilde * &g_inv;
    let fitted_sd = DVector::from_iterator(
        b_tilde.nrows(),
        (0..b_tilde.nrows()).map(|i| rows_cov.row(i).dot(&b_tilde.row(i)).max(0.0).sqrt()),
    );
    Explained {
        gain,
        rank,
        coefficients: beta.iter().copied().collect(),
        fitted,
        fitted_sd,
    }
}

/// The maximiser of `g` on [lo, hi] by `steps` golden-section steps (g unimodal there): the
/// one-dimensional search every fitted frequency, decay, delay and sensor time constant uses.
pub fn golden_max(lo: f64, hi: f64, steps: usize, mut g: impl FnMut(f64) -> f64) -> f64 {
    let r = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (lo, hi);
    let (mut x1, mut x2) = (b - r * (b - a), a + r * (b - a));
    let (mut g1, mut g2) = (g(x1), g(x2));
    for _ in 0..steps {
        if g1 > g2 {
            b = x2;
            (x2, g2) = (x1, g1);
            x1 = b - r * (b - a);
            g1 = g(x1);
        } else {
            a = x1;
            (x1, g1) = (x2, g2);
            x2 = a + r * (b - a);
            g2 = g(x2);
        }
    }
    (a + b) / 2.0
}

/// The best of `gain` on the grid lo, lo + step, … ≤ hi, refined by golden section between
/// its neighbours (within [lo, hi]), and the grid's size G (a setting found this way pays
/// ln G): the order search's and the reading's step search's one pattern. None on an empty
/// The column of `b` (among those `offered`) whose gain alone on `y`, ½·(b·y)²/(b·b), is
/// largest, with that gain; the first of equals, so that the same record gives the same
/// column. A shape searched over a grid (a spot of the angle, a step's instant, a fade's τ) is
/// offered at that column alone, paying ln G for the search.
pub fn best_single_column(
    b: &DMatrix<f64>,
    y: &DVector<f64>,
    offered: impl Fn(usize) -> bool,
) -> Option<(f64, usize)> {
    let mut best: Option<(f64, usize)> = None;
    for j in (0..b.ncols()).filter(|&j| offered(j)) {
        let column = b.column(j);
        let bb = column.norm_squared();
        if bb <= 0.0 {
            continue;
        }
        let gain = 0.5 * column.dot(y).powi(2) / bb;
        if best.is_none_or(|(g, _)| gain > g) {
            best = Some((gain, j));
        }
    }
    best
}

/// grid.
pub fn grid_peak(lo: f64, hi: f64, step: f64, gain: impl Fn(f64) -> f64) -> Option<(f64, usize)> {
    let grid: Vec<f64> = (0..)
        .map(|i| lo + i as f64 * step)
        .take_while(|&x| x <= hi)
        .collect();
    let best = grid
        .iter()
        .map(|&x| (x, gain(x)))
        .max_by(|a, b| a.1.total_cmp(&b.1))?
        .0;
    let x = golden_max((best - step).max(lo), (best + step).min(hi), 12, gain);
    Some((x, grid.len()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    /// Under the model the gain is ½χ² with the columns' rank as its degrees of freedom: its
    /// mean over many noise draws is rank/2.
    #[test]
    fn the_gain_under_the_model_is_half_a_chi_square() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let n = 200;
        let t: Vec<f64> = (0..n).map(|i| i as f64 / n as f64).collect();
        let j = DMatrix::from_fn(n, 2, |i, k| t[i].powi(k as i32));
        // Three columns, one a copy of a model column: rank 2 after projection.
        let b = DMatrix::from_fn(n, 3, |i, k| match k {
            0 => (6.0 * t[i]).sin(),
            1 => t[i],
            _ => (11.0 * t[i]).cos(),
        });
        let projector = Projector::new(j);
        let b_tilde = projector.residualize(&b);
        let draws = 4000;
        let mut total = 0.0;
        for _ in 0..draws {
            let y = DVector::from_fn(n, |_, _| StandardNormal.sample(&mut rng));
            let y = DVector::from_column_slice(
                projector
                    .residualize(&DMatrix::from_column_slice(n, 1, y.as_slice()))
                    .as_slice(),
            );
            let e = explain(&y, &b_tilde);
            assert_eq!(e.rank, 2);
            total += e.gain;
        }
        let mean = total / draws as f64;
        // ½χ²₂ has mean 1 and sd 1: the mean of 4000 within 4 standard errors.
        assert!(
            (mean - 1.0).abs() < 4.0 / (draws as f64).sqrt(),
            "mean gain {mean}"
        );
    }

    #[test]
    fn a_column_in_the_residual_is_recovered_with_its_coefficient() {
        let n = 300;
        let x = DMatrix::from_fn(n, 1, |i, _| (i as f64 / 20.0).sin());
        let y = DVector::from_fn(n, |i, _| 0.7 * x[(i, 0)]);
        let e = explain(&y, &x);
        assert!((e.coefficients[0] - 0.7).abs() < 1e-12);
        assert!((e.gain - 0.5 * y.norm_squared()).abs() < 1e-9);
    }
}
