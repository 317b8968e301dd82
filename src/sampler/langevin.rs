//! What the single-proposal Langevin kernels (MALA, Fisher-MALA) share: a Cholesky factor
//! computed in place, products with triangular factors, the evaluation of a proposal, and the
//! Metropolis–Hastings decision.

use nalgebra::DMatrix;
use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use super::State;
use crate::density::{DensityError, LogDensity};

/// Overwrites the lower triangle of a symmetric matrix with its Cholesky factor and zeroes the
/// upper one, without allocating. False when the matrix is not (numerically) positive
/// definite or not finite; the matrix is then garbage.
pub(crate) fn cholesky_in_place(a: &mut DMatrix<f64>) -> bool {
    let n = a.nrows();
    if a.ncols() != n {
        return false;
    }
    for j in 0..n {
        let mut diag = a[(j, j)];
        for k in 0..j {
            diag -= a[(j, k)] * a[(j, k)];
        }
        // `!(diag > 0)` also catches NaN.
        if !(diag > 0.0 && diag.is_finite()) {
            return false;
        }
        let ljj = diag.sqrt();
        a[(j, j)] = ljj;
        for i in j + 1..n {
            let mut v = a[(i, j)];
            for k in 0..j {
                v -= a[(i, k)] * a[(j, k)];
            }
            a[(i, j)] = v / ljj;
        }
        for i in 0..j {
            a[(i, j)] = 0.0;
        }
    }
    true
}

/// out = L v for lower-triangular L (column-major: column j contributes v_j L[j.., j]).
pub(crate) fn lower_mul(l: &DMatrix<f64>, v: &[f64], out: &mut [f64]) {
    let n = l.nrows();
    out.fill(0.0);
    for (j, &vj) in v.iter().enumerate() {
        let col = &l.as_slice()[j * n..(j + 1) * n];
        for i in j..n {
            out[i] += col[i] * vj;
        }
    }
}

/// out = Lᵀ v for lower-triangular L (each entry a dot product with a contiguous column).
pub(crate) fn lower_tr_mul(l: &DMatrix<f64>, v: &[f64], out: &mut [f64]) {
    let n = l.nrows();
    for (j, o) in out.iter_mut().enumerate() {
        let col = &l.as_slice()[j * n..(j + 1) * n];
        *o = col[j..].iter().zip(&v[j..]).map(|(a, b)| a * b).sum();
    }
}

/// What a proposal's density evaluation said: whether it can be weighed at all.
pub(crate) enum Evaluated {
    Finite(f64),
    /// Outside the support (or a non-finite value or gradient): rejected, not a failure.
    Outside,
    /// A recoverable failure: rejected and counted like a divergence.
    Failed,
}

pub(crate) fn evaluate<P: LogDensity>(
    density: &mut P,
    x: &[f64],
    gradient: &mut [f64],
) -> Result<Evaluated, DensityError> {
    match density.log_density_and_gradient(x, gradient) {
        Ok(lp) if lp.is_finite() && gradient.iter().all(|g| g.is_finite()) => {
            Ok(Evaluated::Finite(lp))
        }
        Ok(lp) if lp == f64::NEG_INFINITY => Ok(Evaluated::Outside),
        // +∞, NaN or a non-finite gradient inside the support is a numerical failure.
        Ok(_) => Ok(Evaluated::Failed),
        Err(e) if e.recoverable => Ok(Evaluated::Failed),
        Err(e) => Err(e),
    }
}

/// The Metropolis–Hastings decision for a log acceptance ratio: (accept_stat, accepted).
/// The uniform is drawn whatever happens, so that a rejection never shifts the random stream.
pub(crate) fn metropolis(log_ratio: f64, rng: &mut ChaCha8Rng) -> (f64, bool) {
    let u: f64 = rng.random();
    let accept_stat = if log_ratio.is_nan() {
        0.0
    } else {
        log_ratio.min(0.0).exp()
    };
    (accept_stat, u.ln() < log_ratio)
}

pub(crate) fn check_state(state: &State, dim: usize) -> Result<(), DensityError> {
    if state.x.len() != dim || state.gradient.len() != dim {
        return Err(DensityError::fatal(format!(
            "a state with {} coordinates and {} gradient entries for a kernel of dimension {dim}",
            state.x.len(),
            state.gradient.len()
        )));
    }
    Ok(())
}
