//! The generator's identifiability oracle, independent of `diagnose`'s scoring: weighted least
//! squares with the noise σ known (no priors, no sampled σ), by projected Levenberg–Marquardt on
//! the forward model's sensitivities. Its score of a model is −½·SS/σ² at the best fit −
//! ½·d·ln N, the BIC's nats; a case is fair when the true form's score leads every other
//! one-effect model by [`RUNNER_UP_MARGIN`] and the nominal model by [`NONE_MARGIN`] (the
//! development set's BIC margins of 6 and 10, halved to nats).
//!
//! On the noise-free truth, and on the noisy record for the lead over none. The noise-free
//! margins ask whether the *effect* is identifiable on this input; the record's lead over none
//! asks whether this record holds it at all. A draw whose noise hides an effect the noise-free
//! truth shows is one no method can name (the oracle itself, knowing the truth's form, does not
//! find it there), and it is redrawn, as the development set's README redraws its own. The
//! README also asks the record's lead over the runner-up; this generator does not: a record on
//! which the truth ties with a look-alike is a case whose right answer is the tie (and the
//! experiment that separates it), the cases `motorcal design` is for.
use nalgebra::{DMatrix, DVector};

use crate::error::Error;
use crate::motor::Term;
use crate::ode::SolverSettings;
use crate::parameter::Support;
use crate::study::Problem;
use crate::study::frequency_grid::{frequency_search_cost, searched_frequencies};

use super::{DURATION, NOISE_SD, SAMPLES};

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
    least_squares_from(base, added, set, target, noise_sd, None)
}

/// As [`least_squares_set`], started also from `extra` where given.
pub fn least_squares_from(
    base: &Problem,
    added: &[String],
    set: &[Term],
    target: &[f64],
    noise_sd: &[f64],
    extra: Option<&[f64]>,
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
    if let Some(e) = extra.filter(|e| e.len() == start.len()) {
        starts.push(e.to_vec());
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

/// The oracle's score of `base` with `added` switched on (`set` giving their settings) against
/// `target`, started also from `extra` where given, and the fit: −½·SS/σ² − ½·d·ln N, less a
/// coupling's frequency search.
fn score(
    base: &Problem,
    target: &[f64],
    added: &[String],
    set: &[Term],
    extra: Option<&[f64]>,
) -> Result<(f64, Vec<f64>), Error> {
    let n = (2 * SAMPLES) as f64;
    let d = base.with_terms(added)?.calibrated_names()?.len() as f64 - 1.0;
    let (ss, theta) = least_squares_from(base, added, set, target, &NOISE_SD, extra)?;
    // A resonance's frequency no one knows is searched for: `diagnose` starts the coupling at
    // the best of G frequencies and charges it ln G in place of its ½·ln N, and so does the
    // oracle, so that a case it makes is one `diagnose`'s own score can find.
    let search = if added.iter().any(|a| a == "compliant_coupling") {
        frequency_search_cost(searched_frequencies(DURATION, SAMPLES), 2 * SAMPLES)
    } else {
        0.0
    };
    Ok((-0.5 * ss - 0.5 * d * n.ln() - search, theta))
}

/// The truth's score lead over none on `target` (the noisy record), its form started also from
/// `own_start` (its fit to the noise-free truth), so that its fit to a noisy record is not lost
/// to a far valley of a frequency or a switching time.
pub fn lead_over_none(
    base: &Problem,
    target: &[f64],
    effects: &[String],
    own_start: &[f64],
) -> Result<f64, Error> {
    let (own, _) = score(base, target, effects, &[], Some(own_start))?;
    let (none, _) = score(base, target, &[], &[], None)?;
    Ok(own - none)
}

/// The oracle's score margins of a truth with `effects` on the noise-free `truth`: its lead
/// over the best alternative, that alternative's name, its lead over none, and the truth's form
/// fitted. The alternatives of one effect are every other one-effect model and none; of two
/// effects, each of the two alone and every pair that swaps one of them for another term.
pub fn margins(base: &Problem, truth: &[f64], effects: &[String]) -> Result<Margins, Error> {
    let score_of = |added: &[String]| score(base, truth, added, &[], None).map(|(s, _)| s);
    let (own, own_fit) = score(base, truth, effects, &[], None)?;
    let none = score_of(&[])?;
    let mut alternatives: Vec<Vec<String>> = Vec::new();
    let others: Vec<String> = Term::NAMES
        .iter()
        .filter(|t| !effects.iter().any(|e| e == *t))
        .map(|t| t.to_string())
        .collect();
    if effects.len() == 1 {
        alternatives.extend(others.iter().map(|o| vec![o.clone()]));
    } else {
        for (i, kept) in effects.iter().enumerate() {
            alternatives.push(vec![kept.clone()]);
            for o in &others {
                let mut pair = effects.to_vec();
                pair[1 - i] = o.clone();
                alternatives.push(pair);
            }
        }
    }
    let mut runner_up = ("none".to_string(), none);
    for alt in alternatives {
        let s = score_of(&alt)?;
        if s > runner_up.1 {
            runner_up = (alt.join("+"), s);
        }
        // A term with a choice among channels is an alternative on each of them: `diagnose`
        // fits a lag on whichever channel the residual points to.
        for set in choice_variants(&alt) {
            let (s, _) = score(base, truth, &alt, std::slice::from_ref(&set), None)?;
            if s > runner_up.1 {
                runner_up = (format!("{} ({:?})", alt.join("+"), set), s);
            }
        }
    }
    Ok(Margins {
        lead: own - runner_up.1,
        runner_up: runner_up.0,
        over_none: own - none,
        own_fit,
    })
}

/// What [`margins`] finds.
#[derive(Clone, Debug)]
pub struct Margins {
    /// The truth's score lead over the best alternative (nats).
    pub lead: f64,
    pub runner_up: String,
    /// The truth's score lead over the nominal model (nats).
    pub over_none: f64,
    /// The truth's own form fitted to the target.
    pub own_fit: Vec<f64>,
}

impl Margins {
    /// Whether the truth stands out by the development set's margins.
    pub fn fair(&self) -> bool {
        self.lead >= RUNNER_UP_MARGIN && self.over_none >= NONE_MARGIN
    }
}

/// The terms among `names` with a setting that chooses (a channel), at each choice other than
/// the default.
fn choice_variants(names: &[String]) -> Vec<Term> {
    let mut out = Vec::new();
    for name in names {
        let (Some((_, settings)), Some(term)) = (Term::declarations(name), Term::named(name))
        else {
            continue;
        };
        let defaults = term.settings();
        for (k, s) in settings.iter().enumerate() {
            for index in 0..s.choices.len() {
                if index as f64 == defaults[k] {
                    continue;
                }
                let mut values = defaults.clone();
                values[k] = index as f64;
                if let Some(Ok(t)) = Term::from_name(name, &values) {
                    out.push(t);
                }
            }
        }
    }
    out
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
    use super::super::{CaseOptions, make_case, nominal_problem, truth_output};
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

    /// A concealed case's record holds its effect. A coupling of seed 1300024 on the constant
    /// input led no effect by 6.6 nats on the noise-free truth, and the generator made it when
    /// it judged that alone; on its noisy record the oracle's own fit of the truth's form led
    /// by 1.8 (`diagnose` ranked it at +1.4, under its 2 nats). Such a draw is now redrawn:
    /// the case made leads none on its own record, recomputed here from the recording.
    #[test]
    fn a_concealed_case_is_one_whose_own_record_holds_the_effect() {
        let effects = vec!["compliant_coupling".to_string()];
        let case = make_case(&CaseOptions {
            effects: effects.clone(),
            magnitude: None,
            input: InputProfile::Constant,
            seed: 1_300_024,
            conceal: true,
            tied: false,
        })
        .unwrap();
        let times = sample_times(DURATION, SAMPLES);
        let base = nominal_problem(&InputProfile::Constant.voltage(24.0, &times), &times);
        let record: Vec<f64> = case
            .recording
            .channels
            .iter()
            .flat_map(|(_, v)| v.iter().copied())
            .collect();
        let (_, start) = least_squares(&base, &effects, &record, &NOISE_SD).unwrap();
        let on_record = lead_over_none(&base, &record, &effects, &start).unwrap();
        assert!(on_record >= NONE_MARGIN, "{on_record}");
        let said = case.answer.oracle_margin_over_none_realized.unwrap();
        assert!((said - on_record).abs() < 0.5, "{said} vs {on_record}");
        assert!(case.answer.oracle_margin.unwrap() >= RUNNER_UP_MARGIN);
    }
}
