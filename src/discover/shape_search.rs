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
//!
//! Where the score is flat in the shape (a weak law, whose shape the record hardly pins), that
//! accuracy buys nothing: the search also stops once the fits made bound what the score can
//! still gain below [`SCORE_TOLERANCE`].

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

/// What the score may still gain when the search stops, in nats. A shape whose score lies
/// within 0.05 nats of the peak's is within 0.32 posterior sds of the peak (the score falls by
/// ½·z² nats at z sds), 40 times below the 2-nat threshold of every verdict: no choice and no
/// interval the diagnosis reports can move by so little.
const SCORE_TOLERANCE: f64 = 0.05;

/// The cost of a shape whose fit failed: finite (Brent's parabola through an infinity is
/// undefined), and far worse than any fit's score.
const FAILED: f64 = 1e12;

/// −score of the fit at a shape, each fit kept, with the (shape, score) of each fit made.
struct NegativeScore<'a, T, S, F> {
    score: &'a S,
    fit_at: &'a F,
    fits: &'a RefCell<Vec<T>>,
    tried: &'a RefCell<Vec<(f64, f64)>>,
    bracket: (f64, f64),
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
                let mut tried = self.tried.borrow_mut();
                tried.push((*x, -cost));
                let (lower, upper) = self.bracket;
                // Brent's method has no stop on the objective's value: an error ends its run,
                // and the fits made are chosen from as on any other end.
                if gain_left(&tried, lower, upper) < SCORE_TOLERANCE {
                    return Err(argmin::core::Error::msg("the score can gain no more"));
                }
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
    let tried = RefCell::new(first.iter().map(|f| (start, score(f))).collect());
    let fits = RefCell::new(first.into_iter().collect::<Vec<_>>());
    let cost = NegativeScore {
        score: &score,
        fit_at: &fit_at,
        fits: &fits,
        tried: &tried,
        bracket: (start - width, start + width),
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

/// The most the score can rise above the best of `tried` (shape, score) within [lower, upper],
/// were it concave there, as one smooth peak is: between two neighbouring shapes it lies under
/// both chords beside them, extended (the chord of the pair on the left and of the pair on the
/// right); beyond the outermost it lies under the outermost chord. Infinite while some stretch
/// has no chord to bound it (fewer than three fits).
fn gain_left(tried: &[(f64, f64)], lower: f64, upper: f64) -> f64 {
    let mut points = tried.to_vec();
    points.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.1.total_cmp(&a.1)));
    // A shape tried twice is one point (its better fit): a chord needs two shapes.
    points.dedup_by(|later, first| later.0 == first.0);
    let n = points.len();
    // A score that is no number bounds nothing (f64::max would pass over it).
    if n < 2 || points.iter().any(|p| !p.1.is_finite()) {
        return f64::INFINITY;
    }
    let best = points.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
    // The chord from point i to point i + 1, as a line: its value at x.
    let chord = |i: usize| {
        let ((x0, s0), (x1, s1)) = (points[i], points[i + 1]);
        let slope = (s1 - s0) / (x1 - x0);
        move |x: f64| s0 + slope * (x - x0)
    };
    let mut top = f64::NEG_INFINITY;
    // Stretch i lies between shape i − 1 and shape i (stretch 0 from the lower end, stretch n
    // to the upper end).
    for i in 0..=n {
        let from = if i == 0 { lower } else { points[i - 1].0 };
        let to = if i == n { upper } else { points[i].0 };
        if to <= from {
            continue;
        }
        // The chord ending at the stretch's left shape, and the one starting at its right shape.
        let left = (i >= 2).then(|| chord(i - 2));
        let right = (i + 1 < n).then(|| chord(i));
        let under = |x: f64| match (&left, &right) {
            (Some(l), Some(r)) => l(x).min(r(x)),
            (Some(l), None) => l(x),
            (None, Some(r)) => r(x),
            (None, None) => f64::INFINITY,
        };
        let mut peak = under(from).max(under(to));
        // Where both chords bound it, their crossing within the stretch is the highest point.
        if let (Some(l), Some(r)) = (&left, &right) {
            let (l0, l1, r0, r1) = (l(from), l(to), r(from), r(to));
            let (dl, dr) = (l1 - l0, r1 - r0);
            if dl != dr {
                let u = (r0 - l0) / (dl - dr);
                if (0.0..=1.0).contains(&u) {
                    peak = peak.max(l0 + u * dl);
                }
            }
        }
        top = top.max(peak);
    }
    (top - best).max(0.0)
}

#[cfg(test)]
mod tests {
    use std::cell::{Cell, RefCell};

    use super::*;

    /// A score peaked at 5.213 as a strong law's is about its harmonic k within a quarter cell:
    /// a parabola that falls by 3240 nats across the half-width searched. A fit is its shape.
    fn score(x: &f64) -> f64 {
        -1e7 * (x - 5.213).powi(2)
    }

    /// A weak law's: the same peak, falling by 0.32 nats across the half-width.
    fn flat_score(x: &f64) -> f64 {
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
    fn where_the_score_is_flat_the_search_stops_within_its_tolerance_of_the_peak() {
        let count = |score: fn(&f64) -> f64| {
            let made = Cell::new(0);
            let best = best_of(5.211, 0.018, Some(5.211), score, |x, _| {
                made.set(made.get() + 1);
                Some(x)
            })
            .unwrap();
            (best, made.get())
        };
        let (best, flat_fits) = count(flat_score);
        let (_, steep_fits) = count(score);
        eprintln!("flat: {best:.6} after {flat_fits} fits; steep: {steep_fits} fits");
        assert!(
            -flat_score(&best) < SCORE_TOLERANCE,
            "{}",
            flat_score(&best)
        );
        assert!(flat_fits < steep_fits, "{flat_fits} against {steep_fits}");
    }

    #[test]
    fn the_gain_left_bounds_what_a_concave_score_can_still_gain() {
        // Parabolas and cusps (concave, not smooth) peaked anywhere in [0, 1], tried at 3-7
        // shapes spread by a fixed sequence: the bound is never below the gain that is left.
        let shapes = |n: usize, seed: f64| -> Vec<f64> {
            (1..=n)
                .map(|i| (seed * i as f64 * 0.618_034).fract())
                .collect()
        };
        for case in 0..200 {
            let peak = (case as f64 * 0.377_1).fract();
            let f = |x: f64| {
                if case % 2 == 0 {
                    -40.0 * (x - peak).powi(2)
                } else {
                    -3.0 * (x - peak).abs()
                }
            };
            let tried: Vec<(f64, f64)> = shapes(3 + case % 5, 1.0 + case as f64 * 0.1)
                .into_iter()
                .map(|x| (x, f(x)))
                .collect();
            let best = tried.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
            let left = gain_left(&tried, 0.0, 1.0);
            assert!(
                left >= f(peak) - best - 1e-12,
                "case {case}: {left} < {}",
                f(peak) - best
            );
        }
        // And it is finite once three shapes are tried, zero where the peak is an end's.
        assert!(gain_left(&[(0.5, 0.0)], 0.0, 1.0).is_infinite());
        assert!(gain_left(&[(0.0, 0.0), (0.5, f64::NAN), (1.0, -2.0)], 0.0, 1.0).is_infinite());
        assert_eq!(
            gain_left(&[(0.0, 0.0), (0.5, -1.0), (1.0, -2.0)], 0.0, 1.0),
            0.0
        );
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
