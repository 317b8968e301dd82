//! A switching time that coincides with a step of a recorded input.
//!
//! A term that switches at a time within the record (`load_step`) adds a torque step. Where
//! the recorded input (the voltage U, a drive's current, force or reference, its disturbance)
//! itself steps at that time, the data cannot tell a load that changed then from the input
//! acting differently than the model says: a gain error on the increment, a friction map that
//! is not affine in ω (the new operating point sits on another slope of it), the drive's own
//! response to the new set-point. All of these change the torque balance exactly when the
//! input steps, and a load step there absorbs them. Such a fit is kept in the ranking, marked
//! with the input step it coincides with, and never selected.
//!
//! **When they coincide.** The switching time's own uncertainty decides, not a window fixed in
//! seconds: |t_s − t_k| ≤ 2·√(s_t² + s_k²) + Δt, with
//! - s_t the Laplace sd of t_s, scaled by √τ, τ the integrated autocorrelation time of the
//!   fit's residuals (samples per effectively independent one, N/ESS). A Laplace sd assumes
//!   independent errors; residuals correlated over τ samples carry the information of N/τ, so
//!   the sd grows by √τ. A fit whose model is right leaves white residuals (τ ≈ 1) and keeps
//!   its Laplace sd of a few ms; a model that misses how the input acts leaves residuals
//!   correlated over the response time, and its switching time is known only to that scale.
//! - s_k the input step's own timing uncertainty: exact for a noise-free held input, and for a
//!   level change Δ in noise of sd σ √26·(σ/Δ)² samples (the least-squares change point's
//!   error tends to the argmax of a two-sided Brownian motion with drift −|s|/2, whose
//!   variance is 26 in units of (σ/Δ)² samples; Yao 1987, checked here by simulation).
//! - Δt one sample: a held input's step is only located to the sample it happens in.
//!
//! **The record's start** is a step of every input that starts away from zero: the records
//! begin with the input applied to a motor at rest. A load step there is a constant load,
//! the library's `load_torque`, and on a record that never reverses the same torque as Coulomb
//! friction (both together trade freely; see `forward_selection`).

use serde::Serialize;

use crate::bayes::CalibrationPosterior;
use crate::diagnostics::ess_mean;
use crate::error::Error;
use crate::io::Recording;
use crate::optimize::MapEstimate;
use crate::parameter::Support;
use crate::study::Problem;

use super::settings::{EVIDENCE_THRESHOLD, SMOOTHING_S};

/// √26: the sd of a least-squares change point in units of (σ/Δ)² samples.
const CHANGE_POINT_SD: f64 = 5.0990195135927845;

/// A step of a recorded input: when, by how much, and how precisely its time is known.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InputStep {
    /// The input's column in the recording.
    pub input: String,
    pub time: f64,
    /// The change of level (the input's unit).
    pub size: f64,
    /// The sd of the step's time [s] (0 for a noise-free held input).
    pub time_sd: f64,
    /// The record's start, where the input is applied to the motor at rest.
    pub record_start: bool,
}

/// A fitted switching time that coincides with an input step.
#[derive(Clone, Debug, Serialize)]
pub struct InputCoincidence {
    /// The switching-time parameter (`load_step.t_s`) and its MAP.
    pub parameter: String,
    pub switching_time: f64,
    /// The step it coincides with.
    pub input_step: InputStep,
    /// The distance within which the two coincide, 2·√(s_t² + s_k²) + Δt [s].
    pub resolution: f64,
    /// s_t: the Laplace sd of the switching time scaled by √τ.
    pub switching_time_sd: f64,
    /// τ: the residuals' integrated autocorrelation time, in samples.
    pub residual_autocorrelation: f64,
}

/// The steps of a recording's inputs: the recorded voltage, and a drive's inputs.
pub fn input_steps(problem: &Problem, recording: &Recording) -> Vec<InputStep> {
    let mut series: Vec<(&str, &[f64])> = Vec::new();
    if let Some(u) = &recording.voltage {
        series.push(("U", u));
    }
    for (name, values) in &recording.inputs {
        series.push((name, values));
    }
    let mut steps = Vec::new();
    let n = recording.n_samples();
    let dt = (recording.last_time() - recording.time[0]) / (n.max(2) - 1) as f64;
    let min_level = ((SMOOTHING_S / dt).round() as usize).max(1);
    for (name, values) in series {
        let column = problem.model.channels.column(name).to_string();
        let Some((first_level, found)) = steps_of(values, min_level) else {
            continue;
        };
        if first_level != 0.0 {
            steps.push(InputStep {
                input: column.clone(),
                time: recording.time[0],
                size: first_level,
                time_sd: 0.0,
                record_start: true,
            });
        }
        for (i, size, samples_sd) in found {
            steps.push(InputStep {
                input: column.clone(),
                time: recording.time[i],
                size,
                time_sd: samples_sd * dt,
                record_start: false,
            });
        }
    }
    steps.sort_by(|a, b| a.time.total_cmp(&b.time));
    steps
}

/// The first level of one held input and its steps as (index of the first sample at the new
/// level, size, sd of the index in samples); `None` for an input that is not held at levels.
///
/// Three kinds of input: held exactly (most consecutive samples equal, as a written
/// zero-order-hold profile: every change is a step); levels in noise (the measured current of
/// a current-controlled drive: first differences of independent noise have lag-one
/// autocorrelation −½); and a sampled smooth signal (a position reference: its differences are
/// a velocity, autocorrelation near +1), which has no steps. In noise a level must hold for
/// `min_level` samples: shorter excursions are ripple and spikes, which the mechanics (time
/// constants of hundreds of samples) do not see.
type Steps = Vec<(usize, f64, f64)>;
fn steps_of(x: &[f64], min_level: usize) -> Option<(f64, Steps)> {
    let n = x.len();
    if n < 4 || x.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let d: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
    let held = d.iter().filter(|v| **v == 0.0).count();
    if 2 * held >= d.len() {
        let steps = d
            .iter()
            .enumerate()
            .filter(|(_, v)| **v != 0.0)
            .map(|(i, v)| (i + 1, *v, 0.0))
            .collect();
        return Some((x[0], steps));
    }
    if lag_one_autocorrelation(&d) >= 0.0 {
        return None;
    }
    // The noise sd from the differences (robust: median absolute deviation), which a few
    // steps do not move.
    let mut abs: Vec<f64> = d.iter().map(|v| v.abs()).collect();
    abs.sort_by(f64::total_cmp);
    let sigma = 1.4826 * abs[abs.len() / 2] / std::f64::consts::SQRT_2;
    if sigma <= 0.0 {
        return None;
    }
    let mut prefix = vec![0.0; n + 1];
    for (i, v) in x.iter().enumerate() {
        prefix[i + 1] = prefix[i] + v;
    }
    let mut steps = Vec::new();
    segment(&prefix, 0, n, sigma, min_level.max(1), &mut steps);
    steps.sort_by_key(|s| s.0);
    let first_end = steps.first().map_or(n, |s| s.0);
    Some((prefix[first_end] / first_end as f64, steps))
}

fn lag_one_autocorrelation(d: &[f64]) -> f64 {
    let m = d.iter().sum::<f64>() / d.len() as f64;
    let c0: f64 = d.iter().map(|v| (v - m).powi(2)).sum();
    let c1: f64 = d.windows(2).map(|w| (w[0] - m) * (w[1] - m)).sum();
    if c0 > 0.0 { c1 / c0 } else { 0.0 }
}

/// Binary segmentation of x[a..b) by the change in mean. A change is kept by the ranking's own
/// rule: its gain in log likelihood, z²/2 for the CUSUM statistic z in noise of sd σ, beats its
/// two parameters' penalty (the new level and the time, ½·2·ln N) by more than the threshold.
fn segment(prefix: &[f64], a: usize, b: usize, sigma: f64, min_level: usize, out: &mut Steps) {
    if b - a < 2 * min_level {
        return;
    }
    let n_all = (prefix.len() - 1) as f64;
    let total = prefix[b] - prefix[a];
    let len = (b - a) as f64;
    let mut best: Option<(usize, f64, f64)> = None;
    for k in a + min_level..=b - min_level {
        let (n1, n2) = ((k - a) as f64, (b - k) as f64);
        let m1 = (prefix[k] - prefix[a]) / n1;
        let m2 = (total - (prefix[k] - prefix[a])) / n2;
        let z = (m2 - m1).abs() * (n1 * n2 / len).sqrt() / sigma;
        if best.is_none_or(|b| z > b.1) {
            best = Some((k, z, m2 - m1));
        }
    }
    let Some((k, z, size)) = best else { return };
    if 0.5 * z * z - n_all.ln() <= EVIDENCE_THRESHOLD {
        return;
    }
    out.push((k, size, CHANGE_POINT_SD * (sigma / size).powi(2)));
    segment(prefix, a, k, sigma, min_level, out);
    segment(prefix, k, b, sigma, min_level, out);
}

/// Whether a fitted switching time of `posterior` at `map` coincides with a step of the
/// recorded inputs (one record: a switching time is a candidate only then).
pub fn coincidence(
    problem: &Problem,
    posterior: &mut CalibrationPosterior,
    map: &MapEstimate,
) -> Result<Option<InputCoincidence>, Error> {
    if problem.recordings.len() != 1 {
        return Ok(None);
    }
    let switching: Vec<(usize, String)> = posterior
        .calibrated()
        .iter()
        .enumerate()
        .filter(|(_, c)| {
            matches!(c.support, Support::Bounded { .. })
                && c.id
                    .term()
                    .and_then(crate::motor::Term::named)
                    .is_some_and(|t| t.record_time())
        })
        .map(|(i, c)| (i, c.name.clone()))
        .collect();
    if switching.is_empty() {
        return Ok(None);
    }
    let recording = &problem.recordings[0];
    let steps = input_steps(problem, recording);
    if steps.is_empty() {
        return Ok(None);
    }
    let residuals = posterior
        .residuals(&map.x, 0)
        .map_err(|e| Error::Numerical(e.to_string()))?;
    let tau = residuals
        .iter()
        .map(|r| {
            let ess = ess_mean(&[r.as_slice()]);
            if ess.is_finite() && ess > 0.0 {
                (r.len() as f64 / ess).max(1.0)
            } else {
                1.0
            }
        })
        .fold(1.0f64, f64::max);
    let laplace_sd = map.laplace_sd();
    let theta = posterior.theta_of(&map.x);
    let dt = (recording.last_time() - recording.time[0]) / (recording.n_samples() - 1) as f64;
    for (i, name) in switching {
        let c = &posterior.calibrated()[i];
        let slope = c.transform.map(map.x[i]).dx.abs();
        let sd = laplace_sd[i] * slope * tau.sqrt();
        let t_s = theta[i];
        let nearest = steps
            .iter()
            .min_by(|a, b| (a.time - t_s).abs().total_cmp(&(b.time - t_s).abs()));
        if let Some(step) = nearest {
            // A NaN sd (a singular Hessian) says the time is not resolved at all.
            let sd = if sd.is_finite() { sd } else { f64::INFINITY };
            let resolution = 2.0 * sd.hypot(step.time_sd) + dt;
            if (step.time - t_s).abs() <= resolution {
                return Ok(Some(InputCoincidence {
                    parameter: name,
                    switching_time: t_s,
                    input_step: step.clone(),
                    resolution,
                    switching_time_sd: sd,
                    residual_autocorrelation: tau,
                }));
            }
        }
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_written_profile_steps_where_it_changes() {
        let x = [24.0, 24.0, 24.0, 12.0, 12.0, 12.0, -24.0, -24.0];
        let (first, steps) = steps_of(&x, 1).unwrap();
        assert_eq!(first, 24.0);
        assert_eq!(steps, vec![(3, -12.0, 0.0), (6, -36.0, 0.0)]);
    }

    #[test]
    fn a_smooth_reference_has_no_steps() {
        let x: Vec<f64> = (0..2000).map(|i| (i as f64 * 0.003).sin()).collect();
        assert!(steps_of(&x, 20).is_none());
    }

    #[test]
    fn a_level_change_in_noise_is_found_and_noise_alone_is_not() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let noise = Normal::new(0.0, 0.5).unwrap();
        let flat: Vec<f64> = (0..20_000).map(|_| 1.0 + noise.sample(&mut rng)).collect();
        let (level, steps) = steps_of(&flat, 20).unwrap();
        assert!(steps.is_empty(), "{steps:?}");
        assert!((level - 1.0).abs() < 0.02, "{level}");
        let stepped: Vec<f64> = flat
            .iter()
            .enumerate()
            .map(|(i, v)| if i >= 10_000 { v + 0.1 } else { *v })
            .collect();
        let (_, steps) = steps_of(&stepped, 20).unwrap();
        assert_eq!(steps.len(), 1, "{steps:?}");
        let (k, size, sd) = steps[0];
        assert!(
            (k as f64 - 10_000.0).abs() < 5.0 * sd + 5.0,
            "{k} (sd {sd})"
        );
        assert!((size - 0.1).abs() < 0.03, "{size}");
    }
}
