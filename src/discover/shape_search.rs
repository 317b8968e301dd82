//! The search through the ODE for a law's shape that is a setting of the law, not one of its
//! parameters: a periodic law's frequency f, or the angle's harmonic k. Each value tried costs a
//! whole fit (the law's coefficients and the model's parameters calibrated at that shape), so
//! the search spends as few fits as the score's smoothness allows.
//!
//! Within the quarter of a Fourier cell searched the score is one smooth peak (the next lies a
//! cell away), near a parabola about its top: Brent's method (argmin's `BrentOpt`) steps to the
//! parabola's vertex through the last three values where it can and falls back to golden
//! section where it cannot. It places the shape within 0.6% of the half-width (the golden
//! search's 11 steps: 0.5%) in about half the fits, and the fit kept is the best one made, not
//! a refit at the bracket's middle.

use std::cell::RefCell;

use argmin::core::{CostFunction, Executor};
use argmin::solver::brent::BrentOpt;

use super::candidate::Candidate;

/// At most this many fits after the start's: the golden search's count (2 + 11 steps), which a
/// smooth peak never needs.
const MAX_FITS: u64 = 13;

/// The accuracy asked of the shape, as a share of the half-width searched: the golden search's
/// 11 steps narrowed the bracket to 0.5% of the half-width either side.
const TOLERANCE: f64 = 0.002;

/// The cost of a shape whose fit failed: finite (Brent's parabola through an infinity is
/// undefined), and far worse than any fit's score.
const FAILED: f64 = 1e12;

/// −score of the fit at a shape, each fit kept.
struct NegativeScore<'a, T, S, F> {
    score: &'a S,
    fit_at: &'a F,
    fits: &'a RefCell<Vec<T>>,
}

impl<T, S, F> CostFunction for NegativeScore<'_, T, S, F>
where
    S: Fn(&T) -> f64,
    F: Fn(f64, Option<&T>) -> Option<T>,
{
    type Param = f64;
    type Output = f64;

    fn cost(&self, x: &f64) -> Result<f64, argmin::core::Error> {
        let fit = {
            let fits = self.fits.borrow();
            let best = fits
                .iter()
                .max_by(|a, b| (self.score)(a).total_cmp(&(self.score)(b)));
            (self.fit_at)(*x, best)
        };
        Ok(match fit {
            Some(fit) => {
                let cost = -(self.score)(&fit);
                self.fits.borrow_mut().push(fit);
                cost
            }
            None => FAILED,
        })
    }
}

/// The best-scoring fit of a shape in [start − width, start + width], `start`'s own fit
/// (`first`) among them; `fit_at(x, warm)` fits the model at shape x from `warm`, the best fit
/// made so far (the nearest valley's estimates), or fails. None where every fit failed.
pub(super) fn best_shape(
    start: f64,
    width: f64,
    first: Option<Candidate>,
    fit_at: impl Fn(f64, Option<&Candidate>) -> Option<Candidate>,
) -> Option<Candidate> {
    best_of(start, width, first, |c: &Candidate| c.score, fit_at)
}

/// [`best_shape`] for fits of any type, scored by `score`.
fn best_of<T>(
    start: f64,
    width: f64,
    first: Option<T>,
    score: impl Fn(&T) -> f64,
    fit_at: impl Fn(f64, Option<&T>) -> Option<T>,
) -> Option<T> {
    let fits = RefCell::new(first.into_iter().collect::<Vec<_>>());
    let cost = NegativeScore {
        score: &score,
        fit_at: &fit_at,
        fits: &fits,
    };
    let solver = BrentOpt::new(start - width, start + width).set_tolerance(0.0, TOLERANCE * width);
    // The solver's end (converged, or out of fits) is no error, and a failed fit is scored
    // FAILED, not raised: whatever `run` returns, the fits made are what is chosen from.
    let _ = Executor::new(cost, solver)
        .configure(|s| s.max_iters(MAX_FITS - 1))
        .run();
    fits.into_inner()
        .into_iter()
        .max_by(|a, b| score(a).total_cmp(&score(b)))
}

#[cfg(test)]
mod tests {
    use std::cell::{Cell, RefCell};

    use super::*;

    /// A score peaked at 5.213 as a law's is about its harmonic k within a quarter cell: a
    /// parabola. A fit is its shape.
    fn score(x: &f64) -> f64 {
        -1e3 * (x - 5.213).powi(2)
    }

    #[test]
    fn a_smooth_peak_is_found_to_the_golden_search_s_accuracy_in_fewer_fits() {
        let made = Cell::new(0);
        let best = best_of(5.211, 0.018, Some(5.211), score, |x, _| {
            made.set(made.get() + 1);
            Some(x)
        })
        .unwrap();
        eprintln!("peak at {best:.6} after {} fits", made.get());
        assert!((best - 5.213).abs() < 3.0 * TOLERANCE * 0.018, "{best}");
        // The golden search spent 13 fits on the same bracket, and one more at its middle.
        assert!(made.get() <= 8, "{} fits", made.get());
    }

    #[test]
    fn each_fit_starts_from_the_best_made_so_far_and_the_best_is_kept() {
        let made = RefCell::new(vec![5.2]);
        let best = best_of(5.211, 0.018, Some(5.2), score, |x, warm| {
            let best_before = made
                .borrow()
                .iter()
                .copied()
                .max_by(|a, b| score(a).total_cmp(&score(b)));
            assert_eq!(warm.copied(), best_before);
            made.borrow_mut().push(x);
            Some(x)
        })
        .unwrap();
        let top = made
            .borrow()
            .iter()
            .copied()
            .max_by(|a, b| score(a).total_cmp(&score(b)));
        assert_eq!(Some(best), top);
    }

    #[test]
    fn failed_fits_are_passed_over_and_none_is_returned_only_where_all_failed() {
        // Fits fail left of 5.205: the search still climbs to the peak on the right.
        let best = best_of(5.211, 0.018, None, score, |x, _| {
            Some(x).filter(|&x| x > 5.205)
        });
        assert!((best.unwrap() - 5.213).abs() < 3.0 * TOLERANCE * 0.018);
        assert!(best_of(5.211, 0.018, None, score, |_, _| None::<f64>).is_none());
    }
}
