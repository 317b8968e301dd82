//! A resonant sensor: one measured channel through a second-order filter,
//! ẍ + 2ζω_n·ẋ + ω_n²·x = ω_n²·u, the model after the first-order lag when the sensor (or the
//! shaft to its encoder) has a mass on a spring of its own. At low frequencies it is the lag
//! with τ = 2ζ/ω_n; what the lag cannot hold is the ringing after each step. A lightly damped
//! sensor read as a lag leaves that ringing in the residual, and the report would name a lag
//! where the physics is a resonance.
//!
//! Fitted like the lag (`timing`): the filter is run exactly on the model's fine-grid
//! prediction (classical Runge–Kutta, the input linear between fine points), and (ω_n, ζ)
//! maximise the linearised gain with the model's parameters refitted beside them. The search
//! starts from the lag's τ: for each damping ratio of a grid, ω_n = 2ζ/τ gives the same
//! low-frequency delay, and a golden section in ln ω_n about it (to within 1%) finds the
//! ringing; the best is then refined in ζ and once more in ω_n (to within 0.1%). A new sensor
//! is looked for only where the lag pays for its own parameter: a resonance the record resolves
//! is that lag at low frequencies (a lightly damped one whose lag is too small to pay rings
//! after the steps, and the damped sinusoid of `oscillation` is there for it). Two parameters, each paid ½·ln N like every other.

use super::regression::golden_max;
use super::timing::{FinePrediction, gain, in_channel_change};
use super::{Context, Evidence, Fingerprint};
use crate::error::Error;
use crate::forward::ForwardModel;
use crate::parameter::ParamId;

/// The damping ratios the search starts from (a resonance rings visibly below ζ ≈ 0.7).
const DAMPING_GRID: [f64; 7] = [0.03, 0.06, 0.12, 0.2, 0.3, 0.45, 0.65];

/// Above this damping ratio the filter's magnitude response has no resonant peak: the sensor
/// is a (second-order) lag, not a resonance, and is left to the lag's fingerprint.
pub const RINGS_BELOW: f64 = std::f64::consts::FRAC_1_SQRT_2;

/// A fitted second-order sensor on one channel.
pub struct Resonance {
    pub zeta: f64,
    /// The ringing (damped) frequency [Hz] and its sd from the gain's curvature.
    pub frequency_hz: f64,
    pub frequency_sd: f64,
    pub gain: f64,
    /// What it changes in the stacked whitened output, the model's parameters refitted.
    pub change: Vec<f64>,
}

/// Channel `c` of the fine prediction through the filter, from rest at its first value.
fn filtered(fine: &FinePrediction, c: usize, omega_n: f64, zeta: f64) -> Vec<f64> {
    let u = &fine.channels[c];
    let h = fine.step();
    // Sub-steps keep ω_n·h within classical Runge–Kutta's accurate range.
    let sub = ((omega_n * h / 0.3).ceil() as usize).max(1);
    let dt = h / sub as f64;
    let (w2, d) = (omega_n * omega_n, 2.0 * zeta * omega_n);
    let rhs = |x: f64, v: f64, u: f64| (v, w2 * (u - x) - d * v);
    let mut out = vec![u[0]; u.len()];
    let (mut x, mut v) = (u[0], 0.0);
    for k in 1..u.len() {
        for s in 0..sub {
            let at = |f: f64| u[k - 1] + (u[k] - u[k - 1]) * (s as f64 + f) / sub as f64;
            let (u0, um, u1) = (at(0.0), at(0.5), at(1.0));
            let (a1, b1) = rhs(x, v, u0);
            let (a2, b2) = rhs(x + 0.5 * dt * a1, v + 0.5 * dt * b1, um);
            let (a3, b3) = rhs(x + 0.5 * dt * a2, v + 0.5 * dt * b2, um);
            let (a4, b4) = rhs(x + dt * a3, v + dt * b3, u1);
            x += dt / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
            v += dt / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4);
        }
        out[k] = x;
    }
    out
}

/// The maximiser of `f` on [lo, hi] and its value there.
fn golden(lo: f64, hi: f64, steps: usize, f: impl Fn(f64) -> f64) -> (f64, f64) {
    let x = golden_max(lo, hi, steps, &f);
    (x, f(x))
}

/// The best underdamped second-order sensor on channel `c` of `fine` (the model's prediction,
/// or the one without its lag), scored against the model's prediction, started from the lag
/// `tau` found there; `None` when the best damping ratio leaves no resonant peak or nothing is
/// gained.
pub fn fit(ctx: &Context, fine: &FinePrediction, c: usize, tau: f64) -> Option<Resonance> {
    if !(tau > 0.0) {
        return None;
    }
    let dt = ctx.times[ctx.n - 1] / (ctx.n - 1) as f64;
    // A resonance above the sampling's Nyquist frequency would alias: not one the record shows.
    let nyquist = std::f64::consts::PI / dt;
    let g = |omega_n: f64, zeta: f64| {
        let x = filtered(fine, c, omega_n, zeta);
        gain(ctx, &in_channel_change(ctx, &ctx.fine, c, &x))
    };
    let mut best = (f64::NEG_INFINITY, 0.0, 0.0);
    for zeta in DAMPING_GRID {
        let centre = (2.0 * zeta / tau).min(nyquist).ln();
        let hi = (centre + 4f64.ln()).min(nyquist.ln());
        let (ln_w, v) = golden(centre - 4f64.ln(), hi, 12, |l| g(l.exp(), zeta));
        if v > best.0 {
            best = (v, ln_w.exp(), zeta);
        }
    }
    let (_, omega_n, zeta0) = best;
    let (zeta, _) = golden(0.5 * zeta0, (2.0 * zeta0).min(1.0), 14, |z| g(omega_n, z));
    let (ln_w, value) = golden(
        omega_n.ln() - 0.3,
        (omega_n.ln() + 0.3).min(nyquist.ln()),
        14,
        |l| g(l.exp(), zeta),
    );
    let omega_n = ln_w.exp();
    if !(value > 0.0) || zeta >= RINGS_BELOW {
        return None;
    }
    let damped = |w: f64| w * (1.0 - zeta * zeta).sqrt() / (2.0 * std::f64::consts::PI);
    // The frequency's sd from the curvature of the log likelihood in ω_n, ζ held.
    let h = omega_n * 1e-3;
    let curvature = (g(omega_n + h, zeta) - 2.0 * value + g(omega_n - h, zeta)) / (h * h);
    let frequency_sd = if curvature < 0.0 {
        damped(1.0 / (-curvature).sqrt())
    } else {
        f64::NAN
    };
    let x = filtered(fine, c, omega_n, zeta);
    let change = ctx
        .projector
        .residualize(&in_channel_change(ctx, &ctx.fine, c, &x))
        .as_slice()
        .to_vec();
    Some(Resonance {
        zeta,
        frequency_hz: damped(omega_n),
        frequency_sd,
        gain: value,
        change,
    })
}

/// Where the model holds a sensor lag with τ > 0: the channel's index among `names`, τ, and the
/// fine prediction with the lag switched off.
pub(super) fn unlagged(
    forward: &ForwardModel,
    theta: &[f64],
    names: &[String],
) -> Result<Option<(usize, f64, FinePrediction)>, Error> {
    let Some(term) = forward
        .model()
        .terms()
        .iter()
        .find(|t| t.term.name() == "sensor_lag")
    else {
        return Ok(None);
    };
    let channel = ["I", "omega"][term.term.settings()[0] as usize];
    let key = ParamId::of_term("sensor_lag", "tau").to_string();
    let (Some(c), Some(k)) = (
        names.iter().position(|n| n == channel),
        forward.calibrated_names().iter().position(|n| *n == key),
    ) else {
        return Ok(None);
    };
    if !(theta[k] > 0.0) {
        return Ok(None);
    }
    let mut off = theta.to_vec();
    off[k] = 0.0;
    Ok(Some((
        c,
        theta[k],
        FinePrediction::of(forward, &off, names)?,
    )))
}

/// The resonant sensor on channel `c` as a fingerprint (an oscillation in the sensor, ringing),
/// from the `lag` found on it, scored against a bar raised by `shift` nats; `None` when none
/// rings. Where the model already
/// holds a lag on `c`, the resonance is fitted in its place (on the prediction without it,
/// started from its τ, one parameter more than it): a filter on top of the lag would be a
/// third-order sensor whose frequency is not the sensor's.
pub(super) fn evidence(ctx: &Context, c: usize, lag: Option<f64>, shift: f64) -> Option<Evidence> {
    let (r, extra) = match &ctx.lagged {
        Some((l, tau, raw)) if *l == c => (fit(ctx, raw, c, *tau)?, 0.5 * ctx.ln_n),
        _ => (fit(ctx, &ctx.fine, c, lag?)?, ctx.ln_n),
    };
    Some(Evidence {
        fingerprint: Fingerprint::Oscillation {
            frequency_hz: r.frequency_hz,
            frequency_sd: r.frequency_sd,
            damping_ratio: Some(r.zeta),
            channel: ctx.channels[c].clone(),
            ringing: true,
            sensor: true,
            score: r.gain - extra - shift,
            // Found by a local search from the lag, not the best of a grid: ½·ln N each for
            // ω_n and ζ (in `extra`, the lag's own one already paid where the model holds it).
            frequencies: 1,
        },
        residual: ctx.y.as_slice().to_vec(),
        explained: r.change,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The filter's step response overshoots by exp(−πζ/√(1−ζ²)) at the first peak, a
    /// half-period π/ω_d after the step.
    #[test]
    fn the_filter_rings_as_a_second_order_system_does() {
        let h = 1e-5;
        let times: Vec<f64> = (0..4000).map(|k| k as f64 * h).collect();
        let step = times
            .iter()
            .map(|&t| if t > 0.0 { 1.0 } else { 0.0 })
            .collect();
        let fine = FinePrediction {
            times: times.clone(),
            channels: vec![step],
        };
        let (omega_n, zeta) = (2.0 * std::f64::consts::PI * 200.0, 0.2);
        let x = filtered(&fine, 0, omega_n, zeta);
        let omega_d = omega_n * (1.0 - zeta * zeta).sqrt();
        let peak = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let expected = 1.0 + (-std::f64::consts::PI * zeta / (1.0 - zeta * zeta).sqrt()).exp();
        assert!((peak - expected).abs() < 2e-3, "{peak} vs {expected}");
        let at_peak = times[x.iter().position(|&v| v == peak).unwrap()];
        let half_period = std::f64::consts::PI / omega_d;
        assert!((at_peak - half_period).abs() < 2.0 * h + 1e-3 * half_period);
    }
}
