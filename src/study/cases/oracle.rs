//! The generator's identifiability oracle, independent of `diagnose`'s scoring: weighted least
//! squares with the noise σ known (no priors, no sampled σ), by projected Levenberg–Marquardt on
//! the forward model's sensitivities, on the *noise-free* truth. Its expected score of a model is
//! −½·SS/σ² at the best fit − ½·d·ln N, the BIC's nats; a case is fair when the true form's
//! expected score leads every other one-effect model by [`RUNNER_UP_MARGIN`] and the nominal
//! model by [`NONE_MARGIN`] (the development set's BIC margins of 6 and 10, halved to nats).
//! Judging on the noise-free truth asks whether the *effect* is identifiable on this input, not
//! whether this noise draw happens to cooperate, so a case the tool then gets wrong still counts.

use nalgebra::{DMatrix, DVector};

use crate::error::Error;
use crate::motor::Term;
use crate::ode::SolverSettings;
use crate::parameter::Support;
use crate::study::Problem;

// The starts across a switching time's range are diagnose's: a list of fractions, no scoring.
use crate::study::BOUNDED_STARTS;

pub const RUNNER_UP_MARGIN: f64 = 3.0;
pub const NONE_MARGIN: f64 = 5.0;
/// Starts of a time constant that ended at zero, as multiples of its first start.
const POSITIVE_DECADES: [f64; 3] = [0.1, 0.01, 0.001];

/// The best weighted fit of `base` with `added` switched on to `target` (channel-major, as the
/// forward model writes it): SS/σ² at the optimum and the fitted values.
pub fn least_squares(
    base: &Problem,
    added: &[String],
    target: &[f64],
    noise_sd: &[f64],
) -> Result<(f64, Vec<f64>), Error> {
    least_squares_set(base, added, &[], target, noise_sd)
}

/// As [`least_squares`], the added terms named in `set` taking its settings (a lag on I rather
/// than the default ω).
pub fn least_squares_set(
    base: &Problem,
    added: &[String],
    set: &[Term],
    target: &[f64],
    noise_sd: &[f64],
) -> Result<(f64, Vec<f64>), Error> {
    let mut problem = base.with_terms(added)?;
    for active in &mut problem.model.terms {
        if let Some(t) = set.iter().find(|t| t.name() == active.term.name()) {
            active.term = t.clone();
        }
    }
    let forward = problem.forward(SolverSettings::default())?;
    let specs = forward.calibrated_specs();
    let m = forward.times().len();
    let weights: Vec<f64> = (0..forward.n_outputs())
        .map(|row| 1.0 / noise_sd[row / m])
        .collect();
    let mut start = forward.nominal_calibrated();
    for (i, s) in specs.iter().enumerate() {
        // Absent effects start a little inside their support: a zero is a stationary point of
        // several terms (tanh, |I|) and an LM step from there may not move.
        if let Support::Positive = s.support
            && start[i] <= 0.0
        {
            start[i] = match s.default_prior {
                crate::parameter::Prior::HalfNormal { scale } => 0.1 * scale,
                _ => 1e-6,
            };
        }
    }
    let mut starts = vec![start.clone()];
    for (i, s) in specs.iter().enumerate() {
        if let Support::Bounded { lower, upper } = s.support {
            starts = starts
                .iter()
                .flat_map(|st| {
                    BOUNDED_STARTS.iter().map(move |f| {
                        let mut v = st.clone();
                        v[i] = lower + f * (upper - lower);
                        v
                    })
                })
                .collect();
        }
    }
    let mut best = (f64::INFINITY, start);
    let fit_from = |starts: &[Vec<f64>], best: &mut (f64, Vec<f64>)| {
        for s in starts {
            if let Ok((ss, theta)) =
                levenberg_marquardt(&forward, &specs, target, &weights, s.clone())
                && ss < best.0
            {
                *best = (ss, theta);
            }
        }
    };
    fit_from(&starts, &mut best);
    // A time constant (a filter's, a delay's) switches its term off at zero, where its
    // sensitivity vanishes: a projected step that overshoots to zero ends there, and its start
    // (a tenth of the prior's scale) can lie decades above the value that fits. A lag of 15 µs
    // on I, started at milliseconds, ended at zero and left the oracle claiming a delay 9.9
    // nats clear of it (its answer.json), where the lag fits within about a nat (a temporary
    // print; the test below holds the fit). A fit that ends with a time constant at
    // zero is therefore tried again from a decade, two and three below its start.
    let dead: Vec<usize> = specs
        .iter()
        .enumerate()
        .filter(|(i, s)| {
            matches!(s.support, Support::Positive)
                && s.id.term().is_some()
                && s.unit == "s"
                && best.1.get(*i) == Some(&0.0)
        })
        .map(|(i, _)| i)
        .collect();
    if !dead.is_empty() {
        let again: Vec<Vec<f64>> = starts
            .iter()
            .flat_map(|st| {
                POSITIVE_DECADES.iter().map(|f| {
                    let mut v = st.clone();
                    for &i in &dead {
                        v[i] *= f;
                    }
                    v
                })
            })
            .collect();
        fit_from(&again, &mut best);
    }
    if !best.0.is_finite() {
        return Err(Error::Numerical(format!(
            "no least-squares fit of {added:?} converged"
        )));
    }
    Ok(best)
}

fn residual_ss(out: &[f64], target: &[f64], weights: &[f64]) -> f64 {
    out.iter()
        .zip(target)
        .zip(weights)
        .map(|((g, y), w)| ((y - g) * w).powi(2))
        .sum()
}

/// Projected Levenberg–Marquardt from `theta` on the weighted residual `(target − G(θ))·w`:
/// the weighted sum of squares where it stops, and the estimate there.
pub fn levenberg_marquardt(
    forward: &crate::forward::ForwardModel,
    specs: &[crate::parameter::ParameterSpec],
    target: &[f64],
    weights: &[f64],
    mut theta: Vec<f64>,
) -> Result<(f64, Vec<f64>), Error> {
    let n = forward.n_outputs();
    let d = theta.len();
    let numerical = |e: crate::ode::OdeError| Error::Numerical(e.to_string());
    let mut out = vec![0.0; n];
    let mut jac = DMatrix::zeros(n, d);
    forward
        .simulate_with_sensitivities(&theta, &mut out, &mut jac)
        .map_err(numerical)?;
    let mut ss = residual_ss(&out, target, weights);
    let mut lambda = 1e-3;
    for _ in 0..100 {
        let r = DVector::from_iterator(n, (0..n).map(|i| (target[i] - out[i]) * weights[i]));
        let mut jw = jac.clone();
        for i in 0..n {
            for j in 0..d {
                jw[(i, j)] *= weights[i];
            }
        }
        let jtj = jw.transpose() * &jw;
        let jtr = jw.transpose() * r;
        let mut improved = false;
        for _ in 0..20 {
            let mut a = jtj.clone();
            for j in 0..d {
                a[(j, j)] += lambda * jtj[(j, j)].max(1e-300);
            }
            let Some(step) = a.cholesky().map(|c| c.solve(&jtr)) else {
                lambda *= 10.0;
                continue;
            };
            let trial: Vec<f64> = theta
                .iter()
                .zip(step.iter())
                .zip(specs)
                .map(|((t, s), spec)| project(&spec.support, t + s))
                .collect();
            let mut trial_out = vec![0.0; n];
            let trial_ss = match forward.simulate(&trial, &mut trial_out) {
                Ok(_) => residual_ss(&trial_out, target, weights),
                Err(_) => f64::INFINITY,
            };
            if trial_ss < ss {
                let converged = (ss - trial_ss) <= 1e-10 * ss.max(1.0);
                theta = trial;
                ss = trial_ss;
                lambda = (lambda * 0.3).max(1e-12);
                improved = true;
                forward
                    .simulate_with_sensitivities(&theta, &mut out, &mut jac)
                    .map_err(numerical)?;
                if converged {
                    return Ok((ss, theta));
                }
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
    Ok((ss, theta))
}

/// Back into the support: positive parameters at 0 at the least, bounded ones inside.
fn project(support: &Support, x: f64) -> f64 {
    match *support {
        Support::Positive => x.max(0.0),
        Support::Bounded { lower, upper } => x.clamp(lower, upper),
        Support::Real => x,
    }
}

#[cfg(test)]
mod tests {
    use super::super::{
        DURATION, NOISE_SD, SAMPLES, choice_variants, nominal_problem, truth_output,
    };
    use super::*;
    use crate::study::InputProfile;
    use crate::synthetic::sample_times;

    /// The generator's draw that made a delay of 14 µs a case 9.9 nats clear of every rival:
    /// a lag on I of about the same τ fits it within a nat or two, and the oracle's least
    /// squares must find that lag, not stop with τ at zero (no lag at all).
    #[test]
    fn a_lag_of_microseconds_is_fitted_not_left_at_zero() {
        let times = sample_times(DURATION, SAMPLES);
        let base = nominal_problem(&InputProfile::Reversal.voltage(24.0, &times), &times);
        let truth = truth_output(
            &base,
            0.09159537366795094,
            &[("input_delay".into(), vec![1.3842165865263777e-5])],
        )
        .unwrap();
        let lag = "sensor_lag".to_string();
        let on_current = choice_variants(std::slice::from_ref(&lag));
        let (ss_none, _) = least_squares(&base, &[], &truth, &NOISE_SD).unwrap();
        let (ss_lag, theta) = least_squares_set(
            &base,
            std::slice::from_ref(&lag),
            &on_current,
            &truth,
            &NOISE_SD,
        )
        .unwrap();
        let tau = *theta.last().unwrap();
        assert!(tau > 0.0, "τ = {tau}");
        assert!(
            ss_lag < 0.25 * ss_none,
            "SS/σ²: lag {ss_lag}, none {ss_none}"
        );
    }
}
