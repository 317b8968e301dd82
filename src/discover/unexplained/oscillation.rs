//! Oscillations the model does not hold: a sinusoid that runs through the record (a periodic
//! load, an eccentric) and a damped sinusoid that rings after each input step (a resonance).
//! Both are searched on a grid of frequencies (and decay rates), refined, and scored by the
//! exact linearised gain of `regression`; the search's look-elsewhere cost is the logarithm of
//! the number of grid points, so that the best of many null periodogram ordinates (each ½χ²₂,
//! i.e. exponential with mean 1) clears the threshold as rarely as one fixed alternative would.

use std::f64::consts::PI;

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

#[cfg(test)]
use super::regression::gain;
use super::regression::{explain, gain_from_normal_equations, golden_max};
use super::{Context, Fingerprint, Scored};
use crate::study::frequency_grid::grid_over;
pub use crate::study::frequency_grid::{frequency_search_cost, lowest_frequency_over};

/// Decay times searched, in periods of the oscillation: ζ from about 0.3 to 0.005.
const DECAY_PERIODS: [f64; 7] = [0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0];
/// Golden-section steps of a refinement.
const REFINE_STEPS: usize = 40;

/// A fitted oscillation in one channel.
#[derive(Clone, Debug)]
pub struct Oscillation {
    pub frequency_hz: f64,
    pub frequency_sd: f64,
    /// The decay rate λ [1/s] of a ringing oscillation (none for one that runs on).
    pub decay: Option<f64>,
    pub scored: Scored,
    /// The frequencies its search ran over (it pays ln of every point tried, decay times
    /// included): a term started at its frequency pays ln of this in place of its frequency's
    /// ½·ln N (`frequency_search_cost`) — the term's damping is a parameter its score pays
    /// for already.
    pub frequencies: usize,
}

impl Oscillation {
    pub fn ringing(&self) -> bool {
        self.decay.is_some()
    }

    /// The fingerprint it gives on `channel`, scored against a bar raised by `shift` nats.
    pub fn fingerprint(&self, channel: &str, shift: f64) -> Fingerprint {
        Fingerprint::Oscillation {
            frequency_hz: self.frequency_hz,
            frequency_sd: self.frequency_sd,
            damping_ratio: self.damping_ratio(),
            channel: channel.to_string(),
            ringing: self.ringing(),
            sensor: false,
            score: self.scored.score - shift,
            frequencies: self.frequencies,
        }
    }

    /// ζ of a ringing oscillation: λ = ζ·ω_n, ω_d = ω_n·√(1 − ζ²).
    pub fn damping_ratio(&self) -> Option<f64> {
        let w = 2.0 * PI * self.frequency_hz;
        self.decay.map(|l| l / (l * l + w * w).sqrt())
    }
}

/// The columns of a sinusoid at f (decaying at λ after each step when given), in channel c's
/// rows of the stacked output.
fn columns(ctx: &Context, c: usize, f: f64, decay: Option<f64>) -> DMatrix<f64> {
    let one = channel_columns(&ctx.times, &ctx.steps, f, decay);
    let mut b = DMatrix::zeros(ctx.m(), one.ncols());
    b.rows_mut(c * ctx.n, ctx.n).copy_from(&one);
    b
}

/// The columns of a sinusoid at f over `times` alone: cos and sin, or for a ringing one
/// (decaying at λ) a pair after each of `steps`, zero before it and once its envelope is below
/// 10⁻⁴.
fn channel_columns(times: &[f64], steps: &[f64], f: f64, decay: Option<f64>) -> DMatrix<f64> {
    let windows = windows(times, steps, f, decay);
    let mut b = DMatrix::zeros(times.len(), 2 * windows.len());
    for (k, (start, values)) in windows.iter().enumerate() {
        for (i, &(co, s)) in values.iter().enumerate() {
            b[(start + i, 2 * k)] = co;
            b[(start + i, 2 * k + 1)] = s;
        }
    }
    b
}

/// [`channel_columns`]' column pairs where they are nonzero: each pair's first row and its
/// (cos, sin) values from there.
fn windows(
    times: &[f64],
    steps: &[f64],
    f: f64,
    decay: Option<f64>,
) -> Vec<(usize, Vec<(f64, f64)>)> {
    let w = 2.0 * PI * f;
    match decay {
        None => vec![(
            0,
            times
                .iter()
                .map(|&t| (w * t).sin_cos())
                .map(|(s, co)| (co, s))
                .collect(),
        )],
        Some(l) => steps
            .iter()
            .map(|&ts| {
                let start = times.partition_point(|&t| t < ts);
                let values = times[start..]
                    .iter()
                    .map(|&t| {
                        let tau = t - ts;
                        ((-l * tau).exp(), tau)
                    })
                    .take_while(|&(envelope, _)| envelope >= 1e-4)
                    .map(|(envelope, tau)| {
                        let (s, co) = (w * tau).sin_cos();
                        (envelope * co, envelope * s)
                    })
                    .collect();
                (start, values)
            })
            .collect(),
    }
}

/// The quick gain used by the search: channel c's projected residual regressed on the
/// unprojected columns (the exact score is computed once, at the end). The same regression as
/// [`gain`] on `columns`' rows of channel c, summed over where each column is nonzero only: a
/// ringing column vanishes before its step and after its envelope falls below 10⁻⁴, and on a
/// long record the dense B̃ᵀB̃ over every row was most of a diagnosis's time.
fn quick_gain(ctx: &Context, c: usize, f: f64, decay: Option<f64>) -> f64 {
    let n = ctx.n;
    let y = &ctx.y_perp.as_slice()[c * n..(c + 1) * n];
    windowed_gain(&ctx.times, &ctx.steps, y, f, decay)
}

/// [`gain`] of y on [`channel_columns`], summed over each column's nonzero window only.
fn windowed_gain(times: &[f64], steps: &[f64], y: &[f64], f: f64, decay: Option<f64>) -> f64 {
    pair_windows_gain(&windows(times, steps, f, decay), y)
}

/// [`gain`] of y on column pairs given where they are nonzero (each pair's first row and its
/// values from there), the normal equations summed over the windows' overlaps only: the
/// ringing's pairs here, a transient's (`transient`) too.
pub(super) fn pair_windows_gain(windows: &[(usize, Vec<(f64, f64)>)], y: &[f64]) -> f64 {
    let k = 2 * windows.len();
    let mut h = DVector::zeros(k);
    let mut g = DMatrix::zeros(k, k);
    for (a, (start_a, va)) in windows.iter().enumerate() {
        for (i, &(co, s)) in va.iter().enumerate() {
            h[2 * a] += co * y[start_a + i];
            h[2 * a + 1] += s * y[start_a + i];
        }
        for (b, (start_b, vb)) in windows.iter().enumerate().skip(a) {
            let from = (*start_a).max(*start_b);
            let to = (start_a + va.len()).min(start_b + vb.len());
            let mut block = [[0.0; 2]; 2];
            for i in from..to.max(from) {
                let (ca, sa) = va[i - start_a];
                let (cb, sb) = vb[i - start_b];
                block[0][0] += ca * cb;
                block[0][1] += ca * sb;
                block[1][0] += sa * cb;
                block[1][1] += sa * sb;
            }
            for (r, row) in block.iter().enumerate() {
                for (q, v) in row.iter().enumerate() {
                    g[(2 * a + r, 2 * b + q)] = *v;
                    g[(2 * b + q, 2 * a + r)] = *v;
                }
            }
        }
    }
    gain_from_normal_equations(&h, g)
}

fn golden(lo: f64, hi: f64, g: impl FnMut(f64) -> f64) -> f64 {
    golden_max(lo, hi, REFINE_STEPS, g)
}

/// The lowest frequency an oscillation is told from a trend at: below two periods over the
/// record it is one (the polynomial's).
pub fn lowest_frequency(ctx: &Context) -> f64 {
    lowest_frequency_over(ctx.times[ctx.n - 1] - ctx.times[0])
}

/// The searched frequencies and their spacing.
fn frequency_grid(ctx: &Context) -> (Vec<f64>, f64, f64) {
    grid_over(ctx.times[ctx.n - 1] - ctx.times[0], ctx.n)
}

/// The gain of a sinusoid running through the record at each searched frequency (channel c).
pub fn spectrum(ctx: &Context, c: usize) -> (Vec<f64>, Vec<f64>) {
    let (grid, _, _) = frequency_grid(ctx);
    let gains = grid
        .par_iter()
        .map(|&f| quick_gain(ctx, c, f, None))
        .collect();
    (grid, gains)
}

/// The best oscillation of each kind (running on, ringing) in channel c.
pub fn search(ctx: &Context, c: usize) -> Vec<Oscillation> {
    let (grid, step, f_min) = frequency_grid(ctx);
    if grid.is_empty() {
        return Vec::new();
    }
    let mut out = Vec::new();
    let kinds: Vec<Option<f64>> = if ctx.steps.is_empty() {
        vec![None]
    } else {
        std::iter::once(None)
            .chain(DECAY_PERIODS.iter().map(|&p| Some(p)))
            .collect()
    };
    // Running on: one search over f. Ringing: over f and the decay time in periods.
    for ringing in [false, true] {
        let mut best = (f64::NEG_INFINITY, grid[0], None);
        let tried: Vec<(f64, Option<f64>)> = grid
            .iter()
            .flat_map(|&f| {
                kinds
                    .iter()
                    .filter(|k| k.is_some() == ringing)
                    .map(move |periods| (f, periods.map(|p| f / p)))
            })
            .collect();
        let points = tried.len();
        // Evaluated in parallel, compared in grid order: the same pick whatever the threads.
        let gains: Vec<f64> = tried
            .par_iter()
            .map(|&(f, decay)| quick_gain(ctx, c, f, decay))
            .collect();
        for (&(f, decay), &g) in tried.iter().zip(&gains) {
            if g > best.0 {
                best = (g, f, decay);
            }
        }
        if points == 0 {
            continue;
        }
        let (_, mut f, mut decay) = best;
        f = golden((f - step).max(f_min / 2.0), f + step, |x| {
            quick_gain(ctx, c, x, decay)
        });
        if let Some(l) = decay {
            let periods = f / l;
            let p = golden((periods / 2.0).ln(), (periods * 2.0).ln(), |lp| {
                quick_gain(ctx, c, f, Some(f / lp.exp()))
            })
            .exp();
            decay = Some(f / p);
        }
        // The frequency's sd from the curvature of the gain (the log likelihood) at its peak.
        let h = step / 20.0;
        let curvature = (quick_gain(ctx, c, f + h, decay) - 2.0 * quick_gain(ctx, c, f, decay)
            + quick_gain(ctx, c, f - h, decay))
            / (h * h);
        let frequency_sd = if curvature < 0.0 {
            1.0 / (-curvature).sqrt()
        } else {
            f64::NAN
        };
        let b = ctx.projector.residualize(&columns(ctx, c, f, decay));
        let e = explain(&ctx.y, &b);
        // Amplitude and phase per column pair count ½·ln N each; the frequency (and decay)
        // searched on a grid count the logarithm of the grid's points.
        let penalty = 0.5 * e.rank as f64 * ctx.ln_n + (points as f64).ln();
        out.push(Oscillation {
            frequency_hz: f,
            frequency_sd,
            decay,
            scored: Scored::new(e, penalty),
            frequencies: grid.len(),
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_windowed_gain_is_the_dense_regressions() {
        // 1-ms samples with a gap, steps at the start and inside the record, a decay that ends the
        // windows early and one that runs past the end, and a frequency between grid points.
        let times: Vec<f64> = (0..3000)
            .map(|i| i as f64 * 1e-3 + if i > 1500 { 0.01 } else { 0.0 })
            .collect();
        let steps = [0.0, 0.7, 1.2, 1.6];
        let y: Vec<f64> = times
            .iter()
            .map(|t| (37.0 * t).sin() * (-t).exp() + 0.3 * (5.0 * t * t).cos())
            .collect();
        let dense_y = DVector::from_column_slice(&y);
        for (f, decay) in [
            (12.3, None),
            (12.3, Some(12.3 / 2.0)),
            (3.1, Some(0.05)),
            (250.0, Some(900.0)),
        ] {
            let dense = gain(&dense_y, &channel_columns(&times, &steps, f, decay));
            let windowed = windowed_gain(&times, &steps, &y, f, decay);
            assert!(
                (dense - windowed).abs() <= 1e-9 * dense.abs().max(1.0),
                "f {f} decay {decay:?}: dense {dense} windowed {windowed}"
            );
        }
    }
}
