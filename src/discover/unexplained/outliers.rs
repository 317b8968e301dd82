//! Isolated outliers: a few samples of one channel far off the model, following nothing (an
//! encoder's miscount, a spike on a sensor's line).
//!
//! Such samples hold no law of the state or of time, so no other alternative here holds them:
//! the polynomial and the autoregression spread them over the record, and a large one after a
//! quiet stretch reads as a ringing (encoder_glitch-790012, spikes of 14.9 σ taken for a
//! 350-Hz resonance). The alternative asked here is the noise itself: the channel's whitened
//! residual as a contaminated normal, (1 − ε)·N(0, a²) + ε·N(0, b²), against the single normal
//! the model assumes, both by maximum likelihood (two-component EM, the core's scale a the
//! channel's σ refitted, which the model has already). It spends two degrees of freedom, ε and
//! b, at ½·ln N each, as every alternative of the verdict does; under the model the
//! contaminated normal's gain over the normal stays near zero (its likelihood ratio is bounded
//! in probability, growing like log log n), far under ln N + the threshold.
//!
//! What it counts as an outlier must look like one:
//! - **isolated**: no two flagged samples adjacent. A run of large residuals is a shape in
//!   time (a transient the model misses), which the other alternatives are for;
//! - **away from the input's steps and the record's start**: the first samples after a step are
//!   where the model's fast dynamics decide the residual (a delay or an inductance misfit makes
//!   one large sample there), so they are left out of both likelihoods.
//!
//! Where the fit ends otherwise (the share at its cap, or flagged samples in a run), the residual
//! is still not one normal noise, and that is reported too, as a generic alternative of its own
//! ([`GenericKind::Tails`]): a noise of two scales, with the same two degrees of freedom and the
//! same bound under the model. emi_bursts-820009 (bursts of two samples at 4.8 σ every 57, 186
//! nats of noise-free miss) gave "nothing missing found": σ̂ widened by the bursts, the EM's best
//! share is at the cap, a tenth of the samples 3.0 times wider than the rest (a gain of 44.4
//! nats, 37.5 after its price).
//!
//! Sparse outliers cost the location of each: a spike of z σ is found only where ½z² pays for
//! where it is, about ln(n/q) nats for q of n samples. A noise-free miss of many nats spread
//! over spikes of 4 σ is therefore not found, and that is the information, not the detector.

use nalgebra::DVector;

use super::generic::GenericKind;
use super::regression::Explained;
use super::spans::{at_samples, listed};
use super::{Context, Scored, Span};

/// The largest share of samples that are outliers: beyond it the residual is a wider noise, or
/// a shape, not isolated samples.
const MAX_SHARE: f64 = 0.1;
/// A sample is a candidate outlier at the start only where it is this many of the core's sds off
/// (the EM then decides): under the model, 0.05% of samples.
const START_Z: f64 = 3.5;
/// The outliers' scale is at least this many times the core's: narrower, they are the noise.
const MIN_WIDTH: f64 = 2.0;
/// Samples after each input step (and the record's start) left out: the model's fast dynamics
/// act there.
const AFTER_STEP: usize = 3;
const EM_STEPS: usize = 200;

/// What the contaminated normal found on one channel: its score, and isolated outliers (the
/// samples flagged) or a noise of two scales.
pub(super) struct Outliers {
    pub scored: Scored,
    pub kind: GenericKind,
}

/// The contaminated normal's fit: its gain in log likelihood over the single normal, each
/// sample's probability of being in the wide part, its share and the two scales.
struct Mixture {
    gain: f64,
    r: Vec<f64>,
    share: f64,
    core: f64,
    wide: f64,
}

fn ln_normal(y: f64, s: f64) -> f64 {
    -0.5 * (y / s).powi(2) - s.ln() - 0.5 * (2.0 * std::f64::consts::PI).ln()
}

/// The contaminated normal's maximum-likelihood fit to `y` by EM, its share at most
/// [`MAX_SHARE`] and its wide scale at least [`MIN_WIDTH`] times the core's; none where no
/// sample is [`START_Z`] off.
fn contaminated_normal(y: &[f64]) -> Option<Mixture> {
    let n = y.len() as f64;
    let a0 = (y.iter().map(|v| v * v).sum::<f64>() / n).sqrt();
    if !(a0 > 0.0) {
        return None;
    }
    let single: f64 = y.iter().map(|&v| ln_normal(v, a0)).sum();
    let far: Vec<f64> = y
        .iter()
        .copied()
        .filter(|v| v.abs() > START_Z * a0)
        .collect();
    if far.is_empty() {
        return None;
    }
    let mut eps = far.len() as f64 / n;
    let mut b = (far.iter().map(|v| v * v).sum::<f64>() / far.len() as f64).sqrt();
    let mut a = a0;
    let mut r = vec![0.0; y.len()];
    let mut ln_l = f64::NEG_INFINITY;
    for _ in 0..EM_STEPS {
        let mut total = 0.0;
        for (ri, &v) in r.iter_mut().zip(y) {
            let (core, wide) = (
                (1.0 - eps).ln() + ln_normal(v, a),
                eps.ln() + ln_normal(v, b),
            );
            let top = core.max(wide);
            let sum = top + ((core - top).exp() + (wide - top).exp()).ln();
            *ri = (wide - sum).exp();
            total += sum;
        }
        let converged = (total - ln_l).abs() < 1e-9;
        ln_l = total;
        if converged {
            break;
        }
        let share: f64 = r.iter().sum();
        eps = (share / n).clamp(0.5 / n, MAX_SHARE);
        let moment = |w: &dyn Fn(f64) -> f64| {
            let (s, ww) = y.iter().zip(&r).fold((0.0, 0.0), |(s, ww), (&v, &ri)| {
                (s + w(ri) * v * v, ww + w(ri))
            });
            (s / ww.max(f64::MIN_POSITIVE)).sqrt()
        };
        a = moment(&|ri| 1.0 - ri);
        b = moment(&|ri| ri).max(MIN_WIDTH * a);
    }
    ln_l.is_finite().then_some(Mixture {
        gain: ln_l - single,
        r,
        share: eps,
        core: a,
        wide: b,
    })
}

impl Mixture {
    /// Isolated outliers: the share inside its cap, the wide part wider than the floor, and no
    /// two of the `flagged` samples (indices into the record, in order) side by side.
    fn isolated_outliers(&self, flagged: &[usize]) -> bool {
        self.share < MAX_SHARE
            && self.wide > MIN_WIDTH * self.core
            && !flagged.is_empty()
            && flagged.windows(2).all(|w| w[1] > w[0] + 1)
    }
}

/// The evidence of isolated outliers on channel `c` of the residual `ctx` holds; none where the
/// contaminated normal finds none that look like outliers.
pub(super) fn evidence(ctx: &Context, c: usize) -> Option<Outliers> {
    let n = ctx.n;
    let dt = (ctx.times[n - 1] - ctx.times[0]) / (n - 1) as f64;
    let near_step = |t: f64| {
        ctx.steps
            .iter()
            .any(|&s| t >= s - 0.5 * dt && t <= s + (AFTER_STEP as f64 + 0.5) * dt)
    };
    let kept: Vec<usize> = (0..n).filter(|&i| !near_step(ctx.times[i])).collect();
    let y: Vec<f64> = kept.iter().map(|&i| ctx.y[c * n + i]).collect();
    let mixture = contaminated_normal(&y)?;
    let samples: Vec<usize> = kept
        .iter()
        .zip(&mixture.r)
        .filter(|(_, ri)| **ri > 0.5)
        .map(|(&i, _)| i)
        .collect();
    let mut fitted = DVector::zeros(ctx.m());
    for &i in &samples {
        fitted[c * n + i] = ctx.y[c * n + i];
    }
    let kind = if mixture.isolated_outliers(&samples) {
        GenericKind::Outliers(samples)
    } else {
        GenericKind::Tails {
            samples,
            share: mixture.share,
            width: mixture.wide / mixture.core,
        }
    };
    let explained = Explained {
        gain: mixture.gain,
        rank: 2,
        coefficients: Vec::new(),
        fitted,
        fitted_sd: DVector::zeros(ctx.m()),
    };
    Some(Outliers {
        scored: Scored::new(explained, ctx.ln_n),
        kind,
    })
}

/// The verdict's `where` and its sentence where isolated outliers on channel `c` lead.
pub(super) fn reported(ctx: &Context, c: usize, samples: &[usize]) -> (Vec<Span>, String) {
    let at: Vec<f64> = samples.iter().map(|&i| ctx.times[i]).collect();
    (
        at_samples(ctx, c, samples),
        suggestion(&ctx.channels[c], &at),
    )
}

/// The verdict's `where` and its sentence where a noise of two scales on channel `c` leads: a
/// share of the samples spread `width` times wider than the rest.
pub(super) fn tails_reported(
    ctx: &Context,
    c: usize,
    samples: &[usize],
    share: f64,
    width: f64,
) -> (Vec<Span>, String) {
    let channel = &ctx.channels[c];
    let sentence = format!(
        "{channel}'s residual is not one normal noise: {} of its samples lie in a part about \
         {width:.1} times wider than the rest (a share of {:.1}%{}) — interference in bursts, \
         a sensor's intermittent contact, or a load that kicks now and then, rather than a law \
         of the state; look at the samples where the residual is large in the recording",
        samples.len(),
        100.0 * share,
        if share >= MAX_SHARE {
            ", the most the fit allows"
        } else {
            ""
        },
    );
    (at_samples(ctx, c, samples), sentence)
}

/// The sentence: how many, where, and what to do.
fn suggestion(channel: &str, times: &[f64]) -> String {
    format!(
        "{channel} has {} isolated sample{} far off the model that follow{} nothing (t = {} \
         s): a sensor's miscount or a spike on its line rather than the motor's physics; look \
         at those samples in the recording, and drop or repair them before calibrating",
        times.len(),
        if times.len() == 1 { "" } else { "s" },
        if times.len() == 1 { "s" } else { "" },
        listed(times)
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    fn noise(seed: u64, n: usize) -> Vec<f64> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let normal = Normal::new(0.0, 1.0).unwrap();
        (0..n).map(|_| normal.sample(&mut rng)).collect()
    }

    /// Under the model the contaminated normal gains far less than the two degrees of freedom
    /// it pays (ln 1002 ≈ 6.9 nats on a 501-sample, two-channel record) plus the threshold.
    #[test]
    fn on_white_noise_the_contaminated_normal_gains_less_than_it_pays() {
        let pays = (1002f64).ln() + 2.0;
        let mut worst = 0.0f64;
        for seed in 0..400 {
            // Whatever the fit ends as: outliers, or a noise of two scales.
            if let Some(m) = contaminated_normal(&noise(seed, 497)) {
                worst = worst.max(m.gain);
            }
        }
        assert!(
            worst < pays,
            "largest gain on 400 white records {worst:.2} nats"
        );
    }

    /// Bursts of two samples at 4.8 σ every 57 (emi_bursts-820009), the residual whitened by
    /// its own RMS as a σ̂ that the bursts widened whitens it: the fit is no set of isolated
    /// outliers (its share at the cap, or its samples in pairs), and it gains far more than the
    /// two degrees of freedom and the threshold it pays — a noise of two scales.
    #[test]
    fn bursts_of_two_samples_are_a_noise_of_two_scales() {
        let mut y = noise(11, 497);
        for (i, v) in y.iter_mut().enumerate() {
            if i % 57 < 2 {
                *v += if (i / 57) % 3 == 0 { -4.8 } else { 4.8 };
            }
        }
        let rms = (y.iter().map(|v| v * v).sum::<f64>() / y.len() as f64).sqrt();
        let y: Vec<f64> = y.iter().map(|v| v / rms).collect();
        let m = contaminated_normal(&y).expect("a contaminated normal");
        let flagged: Vec<usize> = (0..y.len()).filter(|&i| m.r[i] > 0.5).collect();
        assert!(!m.isolated_outliers(&flagged), "{flagged:?}");
        assert!(m.gain > (1002f64).ln() + 2.0 + 20.0, "gain {:.1}", m.gain);
    }

    /// Five spikes of 12 σ among 497 samples are found, each of them, and nothing else.
    #[test]
    fn spikes_of_twelve_sigma_are_found_where_they_are() {
        let mut y = noise(7, 497);
        let at = [40, 133, 250, 301, 460];
        for (k, &i) in at.iter().enumerate() {
            y[i] += if k % 2 == 0 { 12.0 } else { -12.0 };
        }
        let m = contaminated_normal(&y).expect("a contaminated normal");
        let flagged: Vec<usize> = (0..y.len()).filter(|&i| m.r[i] > 0.5).collect();
        assert!(m.isolated_outliers(&flagged));
        let gain = m.gain;
        assert_eq!(flagged, at);
        assert!(gain > 100.0, "gain {gain:.1}");
    }
}
