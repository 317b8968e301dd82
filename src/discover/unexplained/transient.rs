//! A transient after each input step that does not ring: what a hidden first-order state leaves
//! (a shorted turn's or a frame's eddy currents in the current, a second mass on a damper in
//! the speed), and the rival a ringing oscillation must beat to claim its frequency.
//!
//! The ringing alternative (`oscillation`) gives every step a pair of columns, e^(−λτ)·cos ωτ
//! and e^(−λτ)·sin ωτ, τ the time since the step. Damped hard (its search reaches ζ ≈ 0.5),
//! that pair is a transient of two shapes that barely swings; so is a pair of decaying
//! exponentials, e^(−τ/τ₁) and e^(−τ/τ₂), with the same two amplitudes per step and no
//! frequency. **The rule**, fixed before any case was scored: a ringing oscillation is offered
//! as a fingerprint only where it scores above this transient, each paying ½·ln N per amplitude
//! and the logarithm of its own search's grid. Where it does not, its frequency is not what the
//! record shows: the transient is kept as a generic alternative (`unknown`: a hidden state
//! relaxing after each step, which no term names), and it leads only as a generic one does, by
//! beating every specific fingerprint by the threshold.

use nalgebra::DMatrix;

use super::oscillation::pair_windows_gain;
use super::regression::{explain, golden_max};
use super::{Context, Scored};

/// The time constants tried, in sample intervals: from half an interval (a transient within one
/// sample) to a quarter of a 1000-sample record.
const TAU_INTERVALS: [f64; 10] = [0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0, 256.0];
/// Golden-section steps of each time constant's refinement.
const REFINE_STEPS: usize = 30;

/// The best transient of channel c: its two time constants [s] and its score.
#[derive(Clone, Debug)]
pub struct Transient {
    pub taus: [f64; 2],
    pub scored: Scored,
}

/// Channel c's columns over the record's samples: after each step, e^(−τ/τ₁) and e^(−τ/τ₂),
/// zero before the step and once below 10⁻⁴.
fn channel_columns(times: &[f64], steps: &[f64], taus: [f64; 2]) -> DMatrix<f64> {
    let windows = windows(times, steps, taus);
    let mut b = DMatrix::zeros(times.len(), 2 * windows.len());
    for (k, (start, values)) in windows.iter().enumerate() {
        for (i, &(fast, slow)) in values.iter().enumerate() {
            b[(start + i, 2 * k)] = fast;
            b[(start + i, 2 * k + 1)] = slow;
        }
    }
    b
}

/// [`channel_columns`]' pairs where they are nonzero, as `oscillation`'s ringing gives its own:
/// each step's first row and the pair's values from there, until both are below 10⁻⁴.
fn windows(times: &[f64], steps: &[f64], taus: [f64; 2]) -> Vec<(usize, Vec<(f64, f64)>)> {
    let cut = |v: f64| if v < 1e-4 { 0.0 } else { v };
    steps
        .iter()
        .map(|&ts| {
            let start = times.partition_point(|&t| t < ts);
            let values = times[start..]
                .iter()
                .map(|&t| {
                    (
                        cut((-(t - ts) / taus[0]).exp()),
                        cut((-(t - ts) / taus[1]).exp()),
                    )
                })
                .take_while(|&(a, b)| a > 0.0 || b > 0.0)
                .collect();
            (start, values)
        })
        .collect()
}

/// The best transient in channel c, searched over pairs of [`TAU_INTERVALS`] and refined; none
/// on a record too short for it or without a step.
pub fn search(ctx: &Context, c: usize) -> Option<Transient> {
    let n = ctx.n;
    if ctx.steps.is_empty() || n < 20 {
        return None;
    }
    let interval = (ctx.times[n - 1] - ctx.times[0]) / (n - 1) as f64;
    // The search's quick gain, as the ringing's: the projected residual on the unprojected
    // columns, summed where they are nonzero (the exact score is computed once, at the end).
    let y = &ctx.y_perp.as_slice()[c * n..(c + 1) * n];
    let quick = |taus: [f64; 2]| pair_windows_gain(&windows(&ctx.times, &ctx.steps, taus), y);
    let grid: Vec<f64> = TAU_INTERVALS.iter().map(|k| k * interval).collect();
    let pairs: Vec<[f64; 2]> = (0..grid.len())
        .flat_map(|a| ((a + 1)..grid.len()).map(move |b| (a, b)))
        .map(|(a, b)| [grid[a], grid[b]])
        .collect();
    let mut best = (f64::NEG_INFINITY, pairs[0]);
    for &p in &pairs {
        let g = quick(p);
        if g > best.0 {
            best = (g, p);
        }
    }
    let mut taus = best.1;
    for q in 0..2 {
        let at = |l: f64| {
            let mut t = taus;
            t[q] = l.exp();
            quick(t)
        };
        let l = golden_max((taus[q] / 2.0).ln(), (taus[q] * 2.0).ln(), REFINE_STEPS, at);
        let mut refined = taus;
        refined[q] = l.exp();
        if quick(refined) > quick(taus) {
            taus = refined;
        }
    }
    let mut b = DMatrix::zeros(ctx.m(), 2 * ctx.steps.len());
    b.rows_mut(c * n, n)
        .copy_from(&channel_columns(&ctx.times, &ctx.steps, taus));
    let e = explain(&ctx.y, &ctx.projector.residualize(&b));
    let penalty = 0.5 * e.rank as f64 * ctx.ln_n + (pairs.len() as f64).ln();
    taus.sort_by(f64::total_cmp);
    Some(Transient {
        taus,
        scored: Scored::new(e, penalty),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_step_s_columns_start_at_it_and_decay_with_their_own_time_constant() {
        let times: Vec<f64> = (0..100).map(|i| i as f64 * 1e-3).collect();
        let b = channel_columns(&times, &[0.0, 0.05], [2e-3, 10e-3]);
        assert_eq!(b.ncols(), 4);
        // Before the second step its columns are zero; at it they are one.
        assert_eq!(b[(49, 2)], 0.0);
        assert_eq!(b[(50, 2)], 1.0);
        assert!((b[(52, 2)] - (-1.0f64).exp()).abs() < 1e-12);
        assert!((b[(60, 3)] - (-1.0f64).exp()).abs() < 1e-12);
        // The fast one is cut once below 10⁻⁴ (τ = 2 ms: after 18.4 ms).
        assert_eq!(b[(20, 0)], 0.0);
        assert!(b[(18, 0)] > 0.0);
    }

    #[test]
    fn the_windowed_gain_is_the_dense_regressions() {
        use super::super::regression::gain;
        use nalgebra::DVector;
        let times: Vec<f64> = (0..600).map(|i| i as f64 * 1e-3).collect();
        let steps = [0.0, 0.2, 0.23, 0.45];
        let y: Vec<f64> = times
            .iter()
            .map(|t| (-t / 4e-3).exp() + 0.3 * (17.0 * t).sin())
            .collect();
        for taus in [[5e-4, 2e-3], [2e-3, 3e-2], [1e-2, 0.2]] {
            let dense = gain(
                &DVector::from_column_slice(&y),
                &channel_columns(&times, &steps, taus),
            );
            let windowed = pair_windows_gain(&windows(&times, &steps, taus), &y);
            assert!(
                (dense - windowed).abs() <= 1e-9 * dense.abs().max(1.0),
                "{taus:?}: dense {dense} windowed {windowed}"
            );
        }
    }
}
