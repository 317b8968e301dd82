//! Every channel late by τ (the input acts late) against one channel filtered with time
//! constant τ (a sensor lag), fitted exactly rather than to first order: on a record whose
//! current rises in one sample interval, −τ·dŷ/dt is far from ŷ(t − τ) − ŷ(t).
//!
//! The model's prediction is solved once more on a grid ten times finer than the samples,
//! starting at t = 0 where the motor is at rest; the late prediction is read off it by linear
//! interpolation, and the filtered one by the exact first-order-hold discretisation of
//! τ·ẋ = u − x on that grid. τ is then found by golden section on the gain (the linearised
//! likelihood ratio of `regression`, the model's parameters refitted beside it), started from
//! the first-order estimate.

use nalgebra::DMatrix;

use crate::error::Error;
use crate::forward::ForwardModel;

use super::Context;
use super::regression::golden_max;

/// Fine-grid points per sample interval.
pub const FINE: usize = 10;

/// The model's prediction on the fine grid, per channel of the context (in its own unit).
pub struct FinePrediction {
    pub times: Vec<f64>,
    pub channels: Vec<Vec<f64>>,
}

impl FinePrediction {
    pub fn of(forward: &ForwardModel, theta: &[f64], names: &[String]) -> Result<Self, Error> {
        let t = forward.times();
        let end = t[t.len() - 1];
        let n = t.len() * FINE + 1;
        let times: Vec<f64> = (0..n).map(|k| end * k as f64 / (n - 1) as f64).collect();
        let fine = ForwardModel::new(
            forward.model().clone(),
            times.clone(),
            &forward.calibrated_names(),
            *forward.solver(),
        )
        .map_err(Error::Numerical)?;
        let mut out = vec![0.0; fine.n_outputs()];
        fine.simulate(theta, &mut out)
            .map_err(|e| Error::Numerical(format!("the fine prediction: {e}")))?;
        let channels = names
            .iter()
            .map(|name| {
                let k = fine.channels().iter().position(|c| c == name).unwrap_or(0);
                out[k * n..(k + 1) * n].to_vec()
            })
            .collect();
        Ok(Self { times, channels })
    }

    pub(super) fn at(&self, c: usize, t: f64) -> f64 {
        self.read(&self.channels[c], t)
    }

    /// The integral of channel c from t = 0 (the trapezoid rule on the fine grid) at each of
    /// `times`: the angle θ = ∫ω dt of the predicted speed.
    pub(super) fn integral_at(&self, c: usize, times: &[f64]) -> Vec<f64> {
        self.integral_of_at(c, |y| y, times)
    }

    /// `shares` of channel c's largest |value| on the fine grid (a limit's grid below the
    /// predicted peak); none where the channel stays at zero.
    pub(super) fn shares_of_peak(&self, c: usize, shares: &[f64]) -> Vec<f64> {
        let peak = self.channels[c].iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if peak > 0.0 {
            shares.iter().map(|s| s * peak).collect()
        } else {
            Vec::new()
        }
    }

    /// The fine grid's step [s].
    pub(super) fn step(&self) -> f64 {
        self.times[1] - self.times[0]
    }

    /// The fine grid's point nearest t, kept off the ends so that it has neighbours both sides.
    pub(super) fn interior_index(&self, t: f64) -> usize {
        ((t / self.step()).round() as usize).clamp(1, self.times.len() - 2)
    }

    /// Channel c's integral from t = 0 on the fine grid (trapezoids).
    pub(super) fn integral(&self, c: usize) -> Vec<f64> {
        self.integral_of(c, |y| y)
    }

    /// The integral from t = 0 of `f` of channel c, at each of `times`: the heat ∫R·I² dt of
    /// the predicted current with `f` = R·I².
    pub(super) fn integral_of_at(
        &self,
        c: usize,
        f: impl Fn(f64) -> f64,
        times: &[f64],
    ) -> Vec<f64> {
        let sum = self.integral_of(c, f);
        times.iter().map(|&t| self.read(&sum, t)).collect()
    }

    /// The integral from t = 0 of `f` of channel c on the fine grid (trapezoids).
    fn integral_of(&self, c: usize, f: impl Fn(f64) -> f64) -> Vec<f64> {
        let y: Vec<f64> = self.channels[c].iter().map(|&v| f(v)).collect();
        let h = self.step();
        let mut sum = vec![0.0; y.len()];
        for k in 1..y.len() {
            sum[k] = sum[k - 1] + 0.5 * h * (y[k - 1] + y[k]);
        }
        sum
    }

    /// `y`, a series on the fine grid, at time t (linear between grid points).
    fn read(&self, y: &[f64], t: f64) -> f64 {
        read_on_grid(y, self.step(), t)
    }

    /// Channel c through τ·ẋ = u − x, x(0) = u(0), on the fine grid.
    fn filtered(&self, c: usize, tau: f64) -> Vec<f64> {
        let u = &self.channels[c];
        let h = self.step();
        let a = (-h / tau).exp();
        let beta = tau / h * (1.0 - a);
        let mut x = vec![u[0]; u.len()];
        for k in 1..u.len() {
            x[k] = a * x[k - 1] + (1.0 - beta) * u[k] + (beta - a) * u[k - 1];
        }
        x
    }
}

/// What a timing hypothesis with this τ changes in the stacked whitened output.
fn change(ctx: &Context, fine: &FinePrediction, channel: Option<usize>, tau: f64) -> DMatrix<f64> {
    let n = ctx.n;
    let mut d = DMatrix::zeros(ctx.m(), 1);
    for c in 0..ctx.channels.len() {
        match channel {
            // Late by τ: ŷ(t − τ) − ŷ(t).
            None => {
                for (i, &t) in ctx.times.iter().enumerate() {
                    d[(c * n + i, 0)] = (fine.at(c, t - tau) - fine.at(c, t)) / ctx.sigma[c];
                }
            }
            Some(l) if l == c => return in_channel_change(ctx, fine, c, &fine.filtered(c, tau)),
            Some(_) => {}
        }
    }
    d
}

/// What replacing channel `c`'s fine prediction by `x` (the channel through a sensor's filter,
/// `x` on the same fine grid) changes in the stacked whitened output.
pub(super) fn in_channel_change(
    ctx: &Context,
    fine: &FinePrediction,
    c: usize,
    x: &[f64],
) -> DMatrix<f64> {
    let n = ctx.n;
    let mut d = DMatrix::zeros(ctx.m(), 1);
    for (i, &t) in ctx.times.iter().enumerate() {
        d[(c * n + i, 0)] = (fine.read(x, t) - fine.at(c, t)) / ctx.sigma[c];
    }
    d
}

/// ½(‖y⊥‖² − ‖y⊥ − d⊥‖²): the gain of the hypothesis at this τ, its size fixed by τ itself.
pub(super) fn gain(ctx: &Context, d: &DMatrix<f64>) -> f64 {
    let d_perp = ctx.projector.residualize(d);
    let mut g = 0.0;
    for i in 0..ctx.m() {
        let y = ctx.y_perp[i];
        g += y * y - (y - d_perp[(i, 0)]).powi(2);
    }
    0.5 * g
}

/// A fitted timing hypothesis.
pub struct Timing {
    pub tau: f64,
    /// What it changes in the stacked whitened output, the model's parameters refitted.
    pub change: Vec<f64>,
    /// From the curvature of the gain (the log likelihood) at τ.
    pub sd: f64,
    pub gain: f64,
}

/// The best τ of a delay (`channel` None) or of a lag on `channel`, from the first-order
/// estimate `start`; `None` when no positive τ gains.
pub fn fit(
    ctx: &Context,
    fine: &FinePrediction,
    channel: Option<usize>,
    start: f64,
) -> Option<Timing> {
    let dt = ctx.times[ctx.n - 1] / ctx.n as f64;
    let hi = 4.0 * start.max(dt / FINE as f64);
    let g = |tau: f64| gain(ctx, &change(ctx, fine, channel, tau));
    let tau = golden_max(0.0, hi, 30, g);
    let best = g(tau);
    let h = (tau * 0.01).max(1e-9);
    let curvature = (g(tau + h) - 2.0 * best + g((tau - h).max(0.0))) / (h * h);
    let sd = if curvature < 0.0 {
        1.0 / (-curvature).sqrt()
    } else {
        f64::NAN
    };
    let change = ctx
        .projector
        .residualize(&change(ctx, fine, channel, tau))
        .as_slice()
        .to_vec();
    (best > 0.0).then_some(Timing {
        tau,
        change,
        sd,
        gain: best,
    })
}

/// `y`, a series on a grid of step `h` from t = 0, at time t (linear between grid points).
pub(super) fn read_on_grid(y: &[f64], h: f64, t: f64) -> f64 {
    let u = (t / h).clamp(0.0, (y.len() - 1) as f64);
    let k = (u.floor() as usize).min(y.len() - 2);
    let w = u - k as f64;
    y[k] * (1.0 - w) + y[k + 1] * w
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The angle of a speed that rises linearly, ω = a + b·t, is a·t + b·t²/2. The trapezoid
    /// rule is exact on a line, so on the fine grid the angle is the closed form to rounding,
    /// and between its points (read linearly) within the chord's b·h²/8.
    #[test]
    fn the_angle_is_the_speed_s_integral_from_the_start() {
        let (a, b) = (120.0, 800.0);
        let times: Vec<f64> = (0..=5000).map(|k| k as f64 * 1e-4).collect();
        let fine = FinePrediction {
            channels: vec![times.iter().map(|t| a + b * t).collect()],
            times,
        };
        let samples = [0.0, 0.00123, 0.25, 0.37777, 0.5];
        for (t, theta) in samples.iter().zip(fine.integral_at(0, &samples)) {
            let exact = a * t + b * t * t / 2.0;
            let chord = b * 1e-4 * 1e-4 / 8.0;
            assert!(
                (theta - exact).abs() <= chord + 1e-12,
                "{t}: {theta} vs {exact}"
            );
        }
    }
}
