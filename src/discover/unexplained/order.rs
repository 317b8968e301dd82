//! The angle's order search: a ripple at a number of periods per revolution between the whole
//! numbers of the state fingerprint's grid.
//!
//! A rolling bearing's defect strikes at a ball-pass order, not a whole number of times per
//! revolution (3.39 or 2.46 on the generator's `bearing_defect` cases): on the grid's nearest
//! k its sine drifts off the record's by a whole period every 1/|Δk| revolutions, and the law
//! fitted there was in the wrong functions, with 7.6 to 12.3 nats left. Engineers find such
//! orders by order analysis, a spectrum of the signal in the shaft's angle rather than in time;
//! this is that search, on the residual. Its gain at order k is the residual's regression, per
//! channel, on sin(k·θ) and cos(k·θ) (θ the predicted speed's integral, as the law's own state
//! is), without the dynamics between a torque and what is read: a ripple passes through them
//! at its own order, so the peak is where it is, and the fingerprint's columns (`state`, solved
//! through the ODE at the order found) give the gain that counts.
//!
//! The orders searched run from two periods over the record's angle (k ≥ 2/R, R the
//! revolutions the record spans, as a frequency needs two periods over the record) to the most
//! the record samples (`state::sampled_ripple`), at four points per 1/R (the angle's Fourier
//! spacing, as the frequency grid has four per 1/T). Below once per revolution is a load
//! behind a gearbox that ripples once per turn of its slower shaft: on a record of one speed it
//! is a slow oscillation in time, which the oscillation search also finds, but through a
//! spin-up its period in time stretches and only the angle holds it (gear_ripple cases of
//! `beyond_library_cases`: with the search starting at one, 2 of 8 ended with a library term
//! alone and one took 487 s in fits of the wrong laws). The
//! order is a setting found by a search, so a column at it pays ln G of that grid, as a
//! searched frequency does (`study::frequency_grid`).

use nalgebra::{DMatrix, DVector};

use super::Context;
use super::regression::{gain_from_normal_equations, grid_peak};

/// Grid points per 1/R, the Fourier spacing in the angle: four, as the frequency grid's.
const OVERSAMPLING: f64 = 4.0;

/// Periods an order must make over the record's angle to be told from a trend: two, as a
/// frequency needs two periods over the record. The lowest order searched makes that many, and
/// a record that spans fewer revolutions is not searched.
const MIN_REVOLUTIONS: f64 = 2.0;

/// The order found, and what a column at it pays for the search (ln G).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Order {
    pub k: f64,
    pub price: f64,
    /// The angle's Fourier spacing 1/R: orders closer than this are one.
    pub cell: f64,
}

/// The best order in [2/R, `k_max`] of the residual left, refined between its neighbours; none
/// where the record spans too few revolutions or samples no order in that range.
pub(super) fn search(ctx: &Context, k_max: f64) -> Option<Order> {
    let theta = ctx.angle()?;
    let n = ctx.n;
    let residuals: Vec<&[f64]> = (0..ctx.channels.len())
        .map(|c| &ctx.y_perp.as_slice()[c * n..(c + 1) * n])
        .collect();
    search_in(&theta, &residuals, k_max)
}

/// [`search`] on the angle at each sample and each channel's residual.
fn search_in(theta: &[f64], residuals: &[&[f64]], k_max: f64) -> Option<Order> {
    let (lo, hi) = theta
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &t| {
            (a.min(t), b.max(t))
        });
    let revolutions = (hi - lo) / (2.0 * std::f64::consts::PI);
    let k_min = MIN_REVOLUTIONS / revolutions;
    if !(revolutions >= MIN_REVOLUTIONS) || k_max <= k_min {
        return None;
    }
    let step = 1.0 / (OVERSAMPLING * revolutions);
    let gain = |k: f64| -> f64 { residuals.iter().map(|y| order_gain(theta, y, k)).sum() };
    let (k, points) = grid_peak(k_min, k_max, step, gain)?;
    Some(Order {
        k,
        price: (points as f64).ln(),
        cell: 1.0 / revolutions,
    })
}

/// The gain of the residual `y` regressed on sin(k·θ) and cos(k·θ), from the two columns'
/// normal equations, accumulated without forming the columns.
pub(super) fn order_gain(theta: &[f64], y: &[f64], k: f64) -> f64 {
    let mut h = DVector::zeros(2);
    let mut g = DMatrix::zeros(2, 2);
    for (&t, &v) in theta.iter().zip(y) {
        let (s, c) = (k * t).sin_cos();
        h[0] += s * v;
        h[1] += c * v;
        g[(0, 0)] += s * s;
        g[(0, 1)] += s * c;
        g[(1, 1)] += c * c;
    }
    g[(1, 0)] = g[(0, 1)];
    gain_from_normal_equations(&h, g)
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    use super::*;

    /// A whitened residual: a ripple 0.5·sin(k·θ + φ) in unit noise.
    fn ripple_in_noise(theta: &[f64], k: f64, phase: f64, rng: &mut ChaCha8Rng) -> Vec<f64> {
        let noise = Normal::new(0.0, 1.0).unwrap();
        theta
            .iter()
            .map(|th| 0.5 * (k * th + phase).sin() + noise.sample(rng))
            .collect()
    }

    fn revolutions(theta: &[f64]) -> f64 {
        (theta[theta.len() - 1] - theta[0]) / (2.0 * std::f64::consts::PI)
    }

    /// The order the search finds in `y`, asserted within a quarter of the angle's Fourier
    /// spacing 1/R of `k`.
    fn found_near(theta: &[f64], y: &[f64], k: f64) -> Order {
        let found = search_in(theta, &[y], 12.0).expect("enough revolutions");
        assert!(
            (found.k - k).abs() < 0.25 / revolutions(theta),
            "{} vs {k}",
            found.k
        );
        found
    }

    #[test]
    fn an_order_between_whole_numbers_is_found_where_the_residual_has_it() {
        // A record spinning at a steady 200 rad/s for 0.5 s (about 16 revolutions) whose
        // residual holds a ripple at 3.39 periods per revolution: the grid's 3 and 4 miss it
        // by several of the angle's Fourier spacings (1/R), the search finds it within a
        // quarter of one.
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let times: Vec<f64> = (1..=501).map(|i| i as f64 * 1e-3).collect();
        let theta: Vec<f64> = times.iter().map(|t| 200.0 * t).collect();
        let y = ripple_in_noise(&theta, 3.39, 0.7, &mut rng);
        let found = found_near(&theta, &y, 3.39);
        let r = revolutions(&theta);
        // The price is ln of the grid's points: four per 1/R over [2/R, 12].
        let points = ((12.0 - 2.0 / r) * 4.0 * r).floor() + 1.0;
        assert!((found.price - points.ln()).abs() < 0.01, "{}", found.price);
        // Pure noise has its best order somewhere, but no gain near the ripple's.
        let noise = Normal::new(0.0, 1.0).unwrap();
        let white: Vec<f64> = (0..501).map(|_| noise.sample(&mut rng)).collect();
        let ripple = order_gain(&theta, &y, found.k);
        let chance = order_gain(
            &theta,
            &white,
            search_in(&theta, &[&white], 12.0).unwrap().k,
        );
        assert!(ripple > 2.0 * chance, "{ripple} vs {chance}");
        // Too few revolutions, or nothing sampled above two periods over the record: no search.
        let slow: Vec<f64> = times.iter().map(|t| 10.0 * t).collect();
        assert_eq!(search_in(&slow, &[&y], 12.0), None);
        assert_eq!(search_in(&theta, &[&y], 2.0 / r), None);
    }

    #[test]
    fn an_order_below_once_per_revolution_is_found_through_a_spin_up() {
        // A spin-up from rest (ω rising as 1 − e^(−t/τ) to 600 rad/s, τ = 0.1 s, about 40
        // revolutions in 0.5 s) whose residual holds a ripple once per turn of a shaft geared
        // down 2.7 times (k = 0.37): its period in time stretches through the spin-up, so no
        // frequency holds it; in the angle the search finds it within a quarter of 1/R.
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let tau = 0.1;
        let theta: Vec<f64> = (1..=501)
            .map(|i| {
                let t = i as f64 * 1e-3;
                600.0 * (t - tau * (1.0 - (-t / tau).exp()))
            })
            .collect();
        let y = ripple_in_noise(&theta, 0.37, 2.0, &mut rng);
        found_near(&theta, &y, 0.37);
    }
}
