//! What `unexplained.png` shows: each channel's whitened residual with the part the leading
//! fingerprint explains, each channel's spectrum of gains (the sinusoid's log-likelihood gain
//! at each searched frequency), and where the fingerprint is a law of what is read, periodic
//! in a variable of the state — the angle's harmonic k·θ (a tachogenerator's ripple), the
//! reading's own value in steps of q — that channel's residual folded onto one period of it:
//! there a ripple or a sawtooth that looks like noise in time is a shape. (A torque's or a
//! voltage's ripple reaches the channels through the motor's dynamics, filtered and delayed,
//! and its fold is no longer its shape: none is drawn for those balances.)

use std::f64::consts::PI;

use super::{Context, Fingerprint};

#[derive(Clone, Debug, Default)]
pub struct UnexplainedFigure {
    pub times: Vec<f64>,
    pub channels: Vec<String>,
    /// Stacked channel after channel, in noise σ.
    pub residual: Vec<f64>,
    pub explained: Vec<f64>,
    /// Per channel: (frequencies [Hz], gains [nats]).
    pub spectrum: Vec<(Vec<f64>, Vec<f64>)>,
    /// The residual of the channel read, folded onto the fingerprint's period.
    pub folded: Option<Folded>,
}

/// One channel's residual against the fraction of a period of the fingerprint's variable,
/// sorted by that fraction, with its mean over each of [`FOLDED_BINS`] equal parts of the period.
#[derive(Clone, Debug, Default)]
pub struct Folded {
    pub channel: String,
    /// What a period is, for the axis: "k·θ/2π" or "ω/q".
    pub variable: String,
    /// Fractions of a period, in [0, 1), ascending.
    pub phase: Vec<f64>,
    /// In noise σ, at `phase`.
    pub residual: Vec<f64>,
    /// The mean of `residual` over the part of the period each sample falls in.
    pub binned: Vec<f64>,
}

/// Parts of a period the folded residual is averaged over: a ripple's fundamental is drawn by
/// a dozen points a half-period, and with a few hundred samples each part still holds tens.
pub const FOLDED_BINS: usize = 24;

/// The folded residual of `residual` (whitened, stacked per channel as `ctx` stacks it) where
/// `fingerprint` is a law of what is read, periodic in the angle or in steps.
pub(super) fn folded(ctx: &Context, fingerprint: &Fingerprint, residual: &[f64]) -> Option<Folded> {
    let Fingerprint::State {
        balance,
        harmonic,
        step,
        spot,
        ..
    } = fingerprint
    else {
        return None;
    };
    let n = ctx.n;
    let read = balance.strip_prefix("measurement:")?;
    let c = ctx.channels.iter().position(|c| c == read)?;
    // A spot turns once a revolution.
    let harmonic = harmonic.or(spot.map(|_| 1.0));
    let (periods, variable): (Vec<f64>, String) = match (step, harmonic) {
        (Some(q), _) => {
            let periods = ctx.times.iter().map(|&t| ctx.fine.at(c, t) / q).collect();
            (periods, format!("predicted {}/q", ctx.channels[c]))
        }
        (None, Some(k)) => {
            let theta = ctx.angle()?;
            let periods = theta.iter().map(|a| k * a / (2.0 * PI)).collect();
            let k = if k.fract() == 0.0 {
                format!("{k:.0}")
            } else {
                format!("{k:.3}")
            };
            (periods, format!("{k}·θ/2π"))
        }
        (None, None) => return None,
    };
    let fraction: Vec<f64> = periods.iter().map(|p: &f64| p.rem_euclid(1.0)).collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| fraction[a].total_cmp(&fraction[b]));
    let residual: Vec<f64> = order.iter().map(|&i| residual[c * n + i]).collect();
    let phase: Vec<f64> = order.iter().map(|&i| fraction[i]).collect();
    let bin = |p: f64| ((p * FOLDED_BINS as f64) as usize).min(FOLDED_BINS - 1);
    let (mut sum, mut count) = ([0.0; FOLDED_BINS], [0usize; FOLDED_BINS]);
    for (&p, &r) in phase.iter().zip(&residual) {
        sum[bin(p)] += r;
        count[bin(p)] += 1;
    }
    let binned = phase
        .iter()
        .map(|&p| sum[bin(p)] / count[bin(p)] as f64)
        .collect();
    Some(Folded {
        channel: ctx.channels[c].clone(),
        variable,
        phase,
        residual,
        binned,
    })
}
