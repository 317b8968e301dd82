//! A noise that follows the slope: the residual's spread grows where the channels change fast.
//!
//! A sample read at an instant off by δ reads y(t + δ) ≈ y + δ·dy/dt. Where δ is a fresh draw
//! each sample (a converter's clock shared with a busy processor, a logger that stamps a sample
//! when it gets to it), that is no shift in the mean any term or law could hold: the residual
//! stays white, but its variance is σ² + s²·(dŷ/dt)², largest on the steep flanks after the
//! input's steps and near zero where the record is still. The alternative asked here is that
//! noise, against the single normal the model assumes, by maximum likelihood on the whitened
//! residual at the model's scales: one degree of freedom, the jitter's sd s [s], paid at ½·ln N
//! as every alternative of the verdict is. Under the model its likelihood ratio is that of one variance parameter on the boundary,
//! about ½χ²₁, far under ½·ln N and the generic's threshold.
//!
//! The same δ moves every channel sampled at that instant, so the fit is tried with one δ shared
//! by all channels (their deviations correlated as their slopes are) and on each channel alone
//! (a sensor with a clock of its own); the best of them is kept.
//!
//! A shift that is the same on every sample (a delay, a lag) is a mean the timing fingerprints
//! fit exactly, and on one sample of u σ a fitted mean gains ½u² where a variance gains only
//! ½(u² − 1 − ln u²): those lead wherever the slope's residual has a sign.

use nalgebra::DVector;

use super::generic::GenericKind;
use super::regression::{Explained, golden_max};
use super::spans::{Span, runs};
use super::{Context, Scored};

/// The jitter's sd searched, as shares of the sampling interval Δ: from a thousandth (under any
/// noise a record shows) to a quarter. Two neighbours swap places when their δs differ by more
/// than Δ, with probability Φ(−Δ/(√2·s)): 0.2% at s = Δ/4, 8% at Δ/2, 24% at Δ. A clock that
/// puts one pair in twelve out of order is no jitter but broken time stamps, and there
/// y + δ·dy/dt no longer holds (the current's flank after a step relaxes within about one Δ).
/// (Set after a backlash's ringing, on the 118, was taken for a jitter of 0.55·Δ.)
const S_RANGE: (f64, f64) = (1e-3, 0.25);
const GRID: usize = 61;

/// What the noise that follows the slope found: its score, the channels it acts on and the
/// jitter's sd [s].
pub(super) struct SlopeNoise {
    pub scored: Scored,
    pub channel: usize,
    pub kind: GenericKind,
}

/// Channel c's whitened slope at each sample as a jittered read sees it: a δ drawn either side
/// of the instant reads the slope on that side, so its spread is the root mean square of the
/// slopes just before and just after (on the fine grid), with the central difference's sign.
/// At an input's step the two differ (the current's slope jumps); a central difference there
/// would halve it.
fn slopes(ctx: &Context, c: usize) -> Vec<f64> {
    let y = &ctx.fine.channels[c];
    let h = ctx.fine.step();
    ctx.times
        .iter()
        .map(|&t| {
            let k = ctx.fine.interior_index(t);
            let (before, after) = ((y[k] - y[k - 1]) / h, (y[k + 1] - y[k]) / h);
            let rms = (0.5 * (before * before + after * after)).sqrt();
            rms.copysign(before + after) / ctx.sigma[c]
        })
        .collect()
}

/// The log likelihood of the whitened residuals `y` (one row per channel, at the model's unit
/// scales) under covariance 1 + s²·d dᵀ per sample (d the whitened slopes), by Sherman–Morrison.
fn ln_likelihood(y: &[&[f64]], d: &[&[f64]], s: f64) -> f64 {
    let n = y[0].len();
    let mut total = 0.0;
    for i in 0..n {
        let (mut ee, mut ez, mut zz) = (0.0, 0.0, 0.0);
        for k in 0..y.len() {
            let e = s * d[k][i];
            ee += e * e;
            ez += e * y[k][i];
            zz += y[k][i] * y[k][i];
        }
        total -= 0.5 * (zz - ez * ez / (1.0 + ee) + (1.0 + ee).ln());
    }
    total
}

/// The maximum-likelihood fit to the whitened residuals `y` with slopes `d` (rows channels),
/// the jitter's sd searched from S_RANGE of the sampling interval `dt`: its gain over the
/// single normal, and s. The channels' scales stay the model's (1 in whitened units), as every
/// other alternative of the verdict takes them: a scale refitted here would be a gain the
/// alternatives it is ranked against do not get (a lag's deterministic residual, which a
/// variance that follows the slope holds in part, would then lose to it).
fn fit(y: &[&[f64]], d: &[&[f64]], dt: f64) -> (f64, f64) {
    let single = ln_likelihood(y, d, 0.0);
    let (lo, hi) = ((S_RANGE.0 * dt).ln(), (S_RANGE.1 * dt).ln());
    let at = |u: f64| ln_likelihood(y, d, u.exp());
    let step = (hi - lo) / (GRID - 1) as f64;
    let on_grid = (0..GRID)
        .map(|k| lo + step * k as f64)
        .max_by(|&u, &v| at(u).total_cmp(&at(v)))
        .unwrap_or(lo);
    let s = golden_max((on_grid - step).max(lo), (on_grid + step).min(hi), 40, at).exp();
    (ln_likelihood(y, d, s) - single, s)
}

/// The evidence of a noise that follows the slope on the residual `ctx` holds: the best of one
/// jitter shared by every channel and of each channel's own.
pub(super) fn evidence(ctx: &Context) -> Option<SlopeNoise> {
    let n = ctx.n;
    let channels = ctx.channels.len();
    let dt = (ctx.times[n - 1] - ctx.times[0]) / (n - 1) as f64;
    if !(dt > 0.0) {
        return None;
    }
    let d: Vec<Vec<f64>> = (0..channels).map(|c| slopes(ctx, c)).collect();
    let mut sets: Vec<Vec<usize>> = (0..channels).map(|c| vec![c]).collect();
    if channels > 1 {
        sets.push((0..channels).collect());
    }
    let (gain, s, cs) = sets
        .into_iter()
        .map(|cs| {
            let ys: Vec<&[f64]> = cs
                .iter()
                .map(|&c| &ctx.y.as_slice()[c * n..(c + 1) * n])
                .collect();
            let ds: Vec<&[f64]> = cs.iter().map(|&c| d[c].as_slice()).collect();
            let (gain, s) = fit(&ys, &ds, dt);
            (gain, s, cs)
        })
        .max_by(|x, y| x.0.total_cmp(&y.0))?;
    if !gain.is_finite() {
        return None;
    }
    // For the figure: each sample's expected jitter part, s·d·E[δ/s | y], with e = s·d:
    // E[δ/s | y] = eᵀy / (1 + eᵀe).
    let mut fitted = DVector::zeros(ctx.m());
    for i in 0..n {
        let (mut ee, mut ez) = (0.0, 0.0);
        for &c in &cs {
            let e = s * d[c][i];
            ee += e * e;
            ez += e * ctx.y[c * n + i];
        }
        for &c in &cs {
            fitted[c * n + i] = s * d[c][i] * ez / (1.0 + ee);
        }
    }
    let lead = *cs
        .iter()
        .max_by(|&&x, &&y| {
            let w = |c: usize| d[c].iter().map(|v| v * v).sum::<f64>();
            w(x).total_cmp(&w(y))
        })
        .unwrap_or(&0);
    let explained = Explained {
        gain,
        rank: 1,
        coefficients: vec![s],
        fitted,
        fitted_sd: DVector::zeros(ctx.m()),
    };
    Some(SlopeNoise {
        scored: Scored::new(explained, 0.5 * ctx.ln_n),
        channel: lead,
        kind: GenericKind::SlopeNoise {
            seconds: s,
            channels: cs,
        },
    })
}

/// The verdict's `where` and its sentence where the noise that follows the slope leads: the
/// stretches where the jitter's part of the spread exceeds the noise's, and what to do.
pub(super) fn reported(ctx: &Context, seconds: f64, cs: &[usize]) -> (Vec<Span>, String) {
    let spans = cs
        .iter()
        .flat_map(|&c| {
            let d = slopes(ctx, c);
            runs(ctx, c, 0.0, |i| (seconds * d[i]).abs() > 1.0)
        })
        .collect();
    let names: Vec<&str> = cs.iter().map(|&c| ctx.channels[c].as_str()).collect();
    let sentence = format!(
        "the residual's spread on {} grows where the channel{} change{} fast, as if each \
         sample were read at an instant off by about {:.1} µs (sd), drawn afresh each time: \
         the sampling clock jitters (a converter triggered by a busy processor, a logger that \
         stamps a sample when it gets to it) rather than a law of the motor; record with a \
         hardware-timed trigger, or with each sample's own time stamp",
        names.join(" and "),
        if cs.len() == 1 { "" } else { "s" },
        if cs.len() == 1 { "s" } else { "" },
        seconds * 1e6
    );
    (spans, sentence)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    fn normal(seed: u64, n: usize) -> Vec<f64> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let z = Normal::new(0.0, 1.0).unwrap();
        (0..n).map(|_| z.sample(&mut rng)).collect()
    }

    /// Slopes of a stepped record at 1 kHz, whitened: a current that jumps after each of twenty
    /// steps and relaxes in 2 ms, a speed that follows in 20 ms [1/s]. About three samples
    /// after each step are steep, sixty in all: s is then known to about a tenth.
    fn slopes(n: usize) -> [Vec<f64>; 2] {
        let current = (0..n)
            .map(|i| 2e4 * (-((i % 25) as f64) / 2.0).exp())
            .collect();
        let speed = (0..n)
            .map(|i| 2e3 * (-((i % 25) as f64) / 20.0).exp())
            .collect();
        [current, speed]
    }

    /// Under the model (white noise of unit scale, whatever the slopes) the noise that follows
    /// the slope gains far less than the one degree of freedom (½·ln 1002 ≈ 3.5 nats) and the
    /// generic's threshold (2) it must pay, on 200 records.
    #[test]
    fn on_white_noise_a_noise_that_follows_the_slope_gains_less_than_it_pays() {
        let n = 501;
        let d = slopes(n);
        let mut worst = 0.0f64;
        for seed in 0..200 {
            let (i, w) = (normal(2 * seed, n), normal(2 * seed + 1, n));
            let (gain, _) = fit(&[&i, &w], &[&d[0], &d[1]], 1e-3);
            worst = worst.max(gain);
        }
        assert!(
            worst < 0.5 * 1002f64.ln() + 2.0,
            "largest gain {worst:.2} nats"
        );
    }

    /// Samples read 0.15 ms off their instants (sd), one draw per sample for both channels: the
    /// fit finds the jitter's sd within a quarter (about two and a half of its sds) and gains far
    /// more than it pays.
    #[test]
    fn a_jittered_sampling_clock_is_a_noise_that_follows_the_slope_at_its_sd() {
        let n = 501;
        let d = slopes(n);
        let delta: Vec<f64> = normal(7, n).iter().map(|z| 1.5e-4 * z).collect();
        let (mut i, mut w) = (normal(8, n), normal(9, n));
        for k in 0..n {
            i[k] += delta[k] * d[0][k];
            w[k] += delta[k] * d[1][k];
        }
        let (gain, s) = fit(&[&i, &w], &[&d[0], &d[1]], 1e-3);
        assert!((s / 1.5e-4 - 1.0).abs() < 0.25, "s {s:.3e}");
        assert!(gain > 0.5 * 1002f64.ln() + 2.0 + 20.0, "gain {gain:.1}");
    }
}
