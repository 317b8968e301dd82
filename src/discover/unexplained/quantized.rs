//! A reading in steps: what is read of a channel rounded to a step q (an encoder's counts per
//! sample period read as a speed, an ADC's least significant bit).
//!
//! The error a step adds, round(y/q)·q − y, is a sawtooth in the true value y of period q: on
//! a record whose value sweeps many steps it looks like more noise, white in time, and a
//! record with its σ estimated takes it as that (speed_quantization-650053: a step of 2.5 σ,
//! 126 nats of noise-free miss, "nothing missing found"). But it is a function of the value,
//! not of time, and that is what this search looks for: the channel's residual regressed on
//! sin(2π·ŷ/q) and cos(2π·ŷ/q), ŷ the model's prediction of the channel, the sawtooth's
//! fundamental (6/π² of its power), over a grid of 1/q at four points per 1/span (the value's
//! Fourier spacing, as the angle's order search has four per revolution spanned). The period
//! is a setting found by a search, so the pair pays ln G of that grid beside its two
//! coefficients' ½·ln N each.
//!
//! The steps searched: at most a sixteenth of the span the record sweeps (a sensor of four
//! bits over the range recorded; a coarser one is a shape of the value the state fingerprint's
//! smooth functions hold), and at least the step whose fundamental, fitted perfectly, would
//! pay its two coefficients: n·(q/π)²/(4σ²) = ln N, q = 2πσ·√(ln N/n). The grid is cut from
//! the coarse end at [`MAX_POINTS`], and at [`MAX_EVALUATIONS`] / n points on a record longer
//! than 512 samples, so that a long record's search costs what a short one's does (it then
//! searches the coarser steps only).
//!
//! No law term holds a sawtooth, so the fingerprint names none: the verdict says what is read
//! follows its own value in steps, and the step found.

use nalgebra::DMatrix;

use super::fingerprint::LawFunction;
use super::order::order_gain;
use super::regression::{coefficient_sds, grid_peak};
use super::{Context, Evidence, Fingerprint};

/// Grid points per 1/span, the value's Fourier spacing: four, as the order and frequency grids.
const OVERSAMPLING: f64 = 4.0;

/// Levels a quantizer has at least over the span recorded: four bits.
const MIN_LEVELS: f64 = 16.0;

/// The most points the grid of 1/q takes.
const MAX_POINTS: usize = 4096;

/// The most (grid point, sample) pairs the search evaluates: [`MAX_POINTS`] on 512 samples.
const MAX_EVALUATIONS: usize = MAX_POINTS * 512;

/// The evidence that what is read of channel `c` is rounded to a step, on the model `ctx` is
/// the residual of; none where the channel's span leaves no step to search.
pub(super) fn evidence(ctx: &Context, c: usize, shift: f64) -> Option<Evidence> {
    let n = ctx.n;
    let value: Vec<f64> = ctx.times.iter().map(|&t| ctx.fine.at(c, t)).collect();
    let residual = &ctx.y_perp.as_slice()[c * n..(c + 1) * n];
    let (lo, hi) = value
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let span = hi - lo;
    let q_min = 2.0 * std::f64::consts::PI * ctx.sigma[c] * (ctx.ln_n / n as f64).sqrt();
    let (nu_min, spacing) = (MIN_LEVELS / span, 1.0 / (OVERSAMPLING * span));
    let points = MAX_POINTS.min(MAX_EVALUATIONS / n);
    let nu_max = (1.0 / q_min).min(nu_min + points as f64 * spacing);
    if !(span > 0.0 && nu_max > nu_min) {
        return None;
    }
    let phase: Vec<f64> = value
        .iter()
        .map(|v| 2.0 * std::f64::consts::PI * v)
        .collect();
    let (nu, points) = grid_peak(nu_min, nu_max, spacing, |nu| {
        order_gain(&phase, residual, nu)
    })?;
    // The pair in the channel's rows, whitened as the residual is: coefficients in its unit.
    let columns = DMatrix::from_fn(n, 2, |i, j| {
        let (s, co) = (nu * phase[i]).sin_cos();
        (if j == 0 { s } else { co }) / ctx.sigma[c]
    });
    let b_perp = ctx.projector.residualize(&ctx.in_channel(c, &columns));
    let scored = ctx.score_residualized(&b_perp, (points as f64).ln());
    let sds = coefficient_sds(&b_perp);
    let channel = &ctx.channels[c];
    let functions = ["sin", "cos"]
        .iter()
        .enumerate()
        .map(|(j, f)| LawFunction {
            name: format!("{f}(2*pi*{channel}/q)"),
            coefficient: scored.explained.coefficients[j],
            sd: sds[j],
        })
        .collect();
    Some(Evidence {
        fingerprint: Fingerprint::State {
            balance: format!("measurement:{channel}"),
            functions,
            omega_s: None,
            harmonic: None,
            current_limit: None,
            speed_limit: None,
            spot: None,
            fade: None,
            instant: None,
            step: Some(1.0 / nu),
            harmonic_price: 0.0,
            harmonic_width: 0.0,
            score: scored.score - shift,
        },
        residual: ctx.y.as_slice().to_vec(),
        explained: scored.explained.fitted.as_slice().to_vec(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sawtooth's fundamental carries 6/π² of its power: the gain of the residual of a
    /// reading rounded to q, regressed at 1/q, is that share of the sawtooth's ½·Σe²/σ².
    #[test]
    fn a_rounded_reading_s_error_is_found_at_its_step() {
        let q = 25.0;
        let value: Vec<f64> = (0..501).map(|i| -2400.0 + 9.6 * i as f64).collect();
        let error: Vec<f64> = value.iter().map(|v| (v / q).round() * q - v).collect();
        let phase: Vec<f64> = value
            .iter()
            .map(|v| 2.0 * std::f64::consts::PI * v)
            .collect();
        let whole = 0.5 * error.iter().map(|e| e * e).sum::<f64>();
        let at_step = order_gain(&phase, &error, 1.0 / q);
        let share = at_step / whole;
        assert!(
            (share - 6.0 / std::f64::consts::PI.powi(2)).abs() < 0.02,
            "{share}"
        );
        // Off the step by a few of the value's Fourier spacings, the pair finds little.
        let off = order_gain(&phase, &error, 1.0 / q + 3.0 / 4800.0);
        assert!(off < 0.1 * at_step, "{off} vs {at_step}");
    }
}
