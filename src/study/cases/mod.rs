//! Concealed-physics cases, built the way `../shared/data/concealed-dev/README.md` describes its
//! own: the nominal motor of §2.1, a true R drawn from N(0.1, 0.005²), one hidden effect (or
//! none, or two) scaled so that the noise-free truth minus the best nominal model (R refitted
//! by weighted least squares) peaks at a chosen multiple of the noise σ, 501 samples over
//! 0.5 s with σ_I = 2 A and σ_ω = 10 rad/s. `--conceal` keeps that peak below 1.5σ and redraws a
//! case until the oracle ([`oracle`]) finds the effect identifiable on the noise-free truth and
//! the noisy record holding it (leading none); an
//! effect that is not identifiable on the asked input after [`REDRAWS`] draws moves to a richer
//! one (constant → step → reversal → square), recorded in `answer.json`.

pub mod oracle;

use std::collections::BTreeMap;

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::Serialize;

use crate::error::Error;
use crate::io::{ModelFile, Recording};
use crate::motor::{MotorParam, Term, VoltageInput};
use crate::ode::SolverSettings;
use crate::parameter::{ParamId, Support};
use crate::study::InputProfile;
use crate::study::Problem;
use crate::synthetic::sample_times;

use oracle::{NONE_MARGIN, RUNNER_UP_MARGIN, least_squares};

pub const NOISE_SD: [f64; 2] = [2.0, 10.0];
pub const SAMPLES: usize = 501;
pub const DURATION: f64 = 0.5;
/// The largest peak effect a concealed case may have, in noise σ.
pub const CONCEALED_MAX: f64 = 1.5;
/// Draws per input before a richer input is tried.
pub const REDRAWS: usize = 5;
/// Draws on the one input a tied case keeps.
pub const TIED_REDRAWS: usize = 20;

#[derive(Clone, Debug)]
pub struct CaseOptions {
    /// Effects to hide (`["none"]` for a null case).
    pub effects: Vec<String>,
    /// Target peak |effect| / σ; drawn from U(0.6, 1.5) when `None`.
    pub magnitude: Option<f64>,
    pub input: InputProfile,
    pub seed: u64,
    pub conceal: bool,
    /// With `conceal`: a case the oracle cannot tell from its runner-up on the input asked — a
    /// tie, the case `motorcal design` is for. The input is kept (never fallen back from) and a
    /// draw is redrawn until it ties (lead over the runner-up below [`RUNNER_UP_MARGIN`]) while
    /// still standing out from no effect at all (by [`NONE_MARGIN`]).
    pub tied: bool,
}

/// A concealed-physics case: the noisy recording, the nominal model a user would believe (the
/// paper's motor with its defaults), and the answer.
#[derive(Clone, Debug)]
pub struct Case {
    pub recording: Recording,
    pub nominal: ModelFile,
    pub answer: Answer,
}

#[derive(Clone, Debug, Serialize)]
pub struct Answer {
    pub effect: String,
    pub effects: Vec<String>,
    pub params: BTreeMap<String, f64>,
    /// The development set's type: A for a constant 24 V (no U column), B for a held profile.
    #[serde(rename = "type")]
    pub kind: String,
    pub input: InputProfile,
    pub input_fallback: bool,
    pub noise: BTreeMap<String, f64>,
    pub seed: u64,
    pub target_magnitude: f64,
    pub max_abs_effect_over_sigma: BTreeMap<String, f64>,
    pub r_of_refitted_nominal: f64,
    /// The oracle's expected score lead of the truth over the best alternative model and over
    /// none (nats; absent for a null case).
    pub oracle_margin: Option<f64>,
    pub oracle_runner_up: Option<String>,
    pub oracle_margin_over_none: Option<f64>,
    /// The truth's lead over none on the noisy record (a concealed effect's; absent
    /// otherwise), its form refitted to it: a concealed case is made only where it clears
    /// [`NONE_MARGIN`].
    pub oracle_margin_over_none_realized: Option<f64>,
    pub attempts: usize,
}

fn nominal_problem(input: &VoltageInput, times: &[f64]) -> Problem {
    let voltage = input.held_values().map(<[f64]>::to_vec);
    Problem {
        label: "case".into(),
        recordings: vec![Recording {
            source: "case".into(),
            time: times.to_vec(),
            channels: vec![
                ("I".into(), vec![0.0; times.len()]),
                ("omega".into(), vec![0.0; times.len()]),
            ],
            voltage,
            inputs: Vec::new(),
        }],
        model: ModelFile::default(),
        reference: None,
    }
}

/// The truth's noise-free channels: the nominal model with the true R and the effects at
/// `values` (each effect's parameters in its declaration order).
fn truth_output(
    base: &Problem,
    r_true: f64,
    effects: &[(String, Vec<f64>)],
) -> Result<Vec<f64>, Error> {
    let names: Vec<String> = effects.iter().map(|(n, _)| n.clone()).collect();
    let mut problem = base.with_terms(&names)?;
    problem.model.motor.set(MotorParam::Resistance, r_true);
    for (name, values) in effects {
        if let Some(t) = problem
            .model
            .terms
            .iter_mut()
            .find(|t| t.term.name() == name)
        {
            t.values = values.clone();
        }
    }
    problem.model.calibrate = Some(Vec::new());
    let forward = problem.forward(SolverSettings::for_data_generation())?;
    let mut out = vec![0.0; forward.n_outputs()];
    forward
        .simulate(&[], &mut out)
        .map_err(|e| Error::Numerical(e.to_string()))?;
    Ok(out)
}

/// Peak |truth − best nominal| / σ per channel, and the refitted R.
fn peak_over_sigma(base: &Problem, truth: &[f64]) -> Result<([f64; 2], f64), Error> {
    let (_, theta) = least_squares(base, &[], truth, &NOISE_SD)?;
    let mut problem = base.with_terms(&[])?;
    problem.model.calibrate = Some(Vec::new());
    problem.model.motor.set(MotorParam::Resistance, theta[0]);
    let forward = problem.forward(SolverSettings::default())?;
    let mut out = vec![0.0; forward.n_outputs()];
    forward
        .simulate(&[], &mut out)
        .map_err(|e| Error::Numerical(e.to_string()))?;
    let m = SAMPLES;
    let mut peak = [0.0f64; 2];
    for c in 0..2 {
        for i in 0..m {
            peak[c] = peak[c].max((truth[c * m + i] - out[c * m + i]).abs() / NOISE_SD[c]);
        }
    }
    Ok((peak, theta[0]))
}

/// The effect's parameters with its size parameter (the first) at `size`; the other ones (a
/// switching time) as drawn.
fn with_size(drawn: &[f64], size: f64) -> Vec<f64> {
    let mut v = drawn.to_vec();
    v[0] = size;
    v
}

/// Scales one effect's size parameter (keeping its sign) so that its peak is `target` σ:
/// doubling to bracket, then bisection in log size.
fn scale_effect(
    base: &Problem,
    r_true: f64,
    name: &str,
    drawn: &[f64],
    sign: f64,
    target: f64,
) -> Result<f64, Error> {
    let peak = |size: f64| -> Result<f64, Error> {
        let truth = truth_output(
            base,
            r_true,
            &[(name.into(), with_size(drawn, sign * size))],
        )?;
        let (p, _) = peak_over_sigma(base, &truth)?;
        Ok(p[0].max(p[1]))
    };
    // A size too small for the integrator to resolve (a lag of nanoseconds, stiff) is below
    // any target: the bracket goes on doubling past it.
    let peak_or_zero = |size: f64| -> Result<f64, Error> {
        match peak(size) {
            Err(Error::Numerical(_)) => Ok(0.0),
            other => other,
        }
    };
    // A bounded size (a share) stops short of its bound: the effect is then as large as it gets.
    let ceiling = match Term::named(name).map(|t| t.params()[0].support) {
        Some(support) => {
            match support(&base.model_for(&base.recordings[0])?.magnitudes(DURATION)) {
                Support::Bounded { upper, .. } => 0.95 * upper,
                _ => f64::INFINITY,
            }
        }
        None => f64::INFINITY,
    };
    let mut lo = 1e-9;
    let mut hi = 1e-9;
    for _ in 0..80 {
        if peak_or_zero(hi)? >= target {
            break;
        }
        lo = hi;
        hi *= 2.0;
        if hi >= ceiling {
            hi = ceiling;
            break;
        }
    }
    for _ in 0..40 {
        let mid = (lo * hi).sqrt();
        if peak_or_zero(mid)? < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(sign * (lo * hi).sqrt())
}

pub fn make_case(options: &CaseOptions) -> Result<Case, Error> {
    let effects: Vec<String> = options
        .effects
        .iter()
        .filter(|e| e.as_str() != "none")
        .cloned()
        .collect();
    for e in &effects {
        if Term::named(e).is_none() {
            return Err(Error::setting(
                "effect",
                "",
                format!(
                    "unknown effect '{e}' (known: none, {})",
                    Term::NAMES.join(", ")
                ),
            ));
        }
    }
    if effects.len() > 2 {
        return Err(Error::setting("effect", "", "at most two effects"));
    }
    if let Some(m) = options.magnitude
        && !(m > 0.0 && m.is_finite())
    {
        return Err(Error::setting(
            "magnitude",
            m,
            "must be a positive multiple of the noise σ",
        ));
    }
    if options.conceal
        && let Some(m) = options.magnitude
        && m >= CONCEALED_MAX
    {
        return Err(Error::setting(
            "magnitude",
            m,
            format!("a concealed effect stays below {CONCEALED_MAX} σ"),
        ));
    }
    if options.tied && (!options.conceal || effects.is_empty()) {
        return Err(Error::setting(
            "tied",
            "true",
            "a tied case is a concealed effect: needs conceal and an effect",
        ));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let times = sample_times(DURATION, SAMPLES);
    let ladder = InputProfile::ALL;
    let first = ladder.iter().position(|i| *i == options.input).unwrap_or(0);
    // A tie is a property of the input asked: another input would be another case.
    let last = if options.tied {
        first + 1
    } else {
        ladder.len()
    };
    // The noise is the seed's alone, the same on every draw of the effect.
    let noise = noise_draw(options.seed);
    let mut attempts = 0;
    for (rung, &input) in ladder.iter().enumerate().take(last).skip(first) {
        let voltage = input.voltage(24.0, &times);
        let base = nominal_problem(&voltage, &times);
        let tries = if options.tied {
            TIED_REDRAWS
        } else if options.conceal && !effects.is_empty() {
            REDRAWS
        } else {
            1
        };
        for _ in 0..tries {
            attempts += 1;
            let r_true = 0.1 + 0.005 * Normal::<f64>::new(0.0, 1.0).unwrap().sample(&mut rng);
            let target = options
                .magnitude
                .unwrap_or_else(|| rng.random_range(0.6..CONCEALED_MAX));
            let mut hidden: Vec<(String, Vec<f64>)> = Vec::new();
            for name in &effects {
                let term = Term::named(name).expect("checked");
                let drawn: Vec<f64> = term
                    .params()
                    .iter()
                    .map(|p| match (name.as_str(), p.key) {
                        (_, "t_s") => rng.random_range(0.2..0.8) * DURATION,
                        // A resonance the record resolves (ten samples a period at the most),
                        // lightly damped: it rings for a few periods after each step.
                        ("compliant_coupling", "f_r") => rng.random_range(30.0..100.0),
                        ("compliant_coupling", "zeta") => rng.random_range(0.05..0.2),
                        _ => p.default,
                    })
                    .collect();
                let magnitudes = base.model_for(&base.recordings[0])?.magnitudes(DURATION);
                let sign = match (term.params()[0].support)(&magnitudes) {
                    Support::Real if rng.random_bool(0.5) => -1.0,
                    _ => 1.0,
                };
                let size = scale_effect(&base, r_true, name, &drawn, sign, target)?;
                hidden.push((name.clone(), with_size(&drawn, size)));
            }
            let truth = truth_output(&base, r_true, &hidden)?;
            let (peak, r_refit) = peak_over_sigma(&base, &truth)?;
            // Two effects are each concealed (each alone peaks at the target); together they may
            // show more, or less where they cancel: the answer records the combined peak. Both
            // hidden below 1.5σ *together* and each told apart from its look-alikes is rarely
            // possible on 501 samples (the oracle refuses most such draws).
            if options.conceal && effects.len() == 1 && peak[0].max(peak[1]) >= CONCEALED_MAX {
                continue;
            }
            let expected = if effects.is_empty() {
                None
            } else {
                Some(oracle::margins(&base, &truth, &effects)?)
            };
            let fair = match &expected {
                Some(m) if options.tied => m.lead < RUNNER_UP_MARGIN && m.over_none >= NONE_MARGIN,
                Some(m) => m.fair(),
                None => true,
            };
            if options.conceal && !fair {
                continue;
            }
            let measured = with_noise(&truth, &noise);
            // The record must hold the effect: its own lead over none (the truth's form refitted
            // to it) by the margin. Not its lead over a look-alike: a record on which the truth
            // ties with one is a fair case whose right answer is the tie and the experiment that
            // separates it (issue 20's cases), where a record that holds no effect has no right
            // answer at all. A tie asked for keeps the noise-free tie alone.
            let realized = match &expected {
                Some(m) if options.conceal && !options.tied => Some(oracle::lead_over_none(
                    &base,
                    &measured.concat(),
                    &effects,
                    &m.own_fit,
                )?),
                _ => None,
            };
            if realized.is_some_and(|r| r < NONE_MARGIN) {
                continue;
            }
            return Ok(assemble_case(
                options,
                &voltage,
                r_true,
                &hidden,
                measured,
                peak,
                r_refit,
                target,
                input,
                rung != first,
                expected,
                realized,
                attempts,
            ));
        }
    }
    let why = if options.tied {
        format!(
            "no tie on the {} input after {attempts} draws (the effect either stood out from \
             its runner-up by {RUNNER_UP_MARGIN} nats or from no effect by less than \
             {NONE_MARGIN})",
            options.input.name()
        )
    } else {
        format!("not identifiable on any input after {attempts} draws")
    };
    Err(Error::setting("effect", options.effects.join(","), why))
}

/// The seed's noise on each channel: σ_I then σ_ω, a sample at a time.
fn noise_draw(seed: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x6e6f_6973_6500);
    (0..2)
        .map(|c| {
            let normal = Normal::new(0.0, NOISE_SD[c]).expect("σ > 0");
            (0..SAMPLES).map(|_| normal.sample(&mut rng)).collect()
        })
        .collect()
}

/// The channels measured: the noise-free truth (channel-major) plus the noise.
fn with_noise(truth: &[f64], noise: &[Vec<f64>]) -> Vec<Vec<f64>> {
    noise
        .iter()
        .enumerate()
        .map(|(c, n)| {
            (0..SAMPLES)
                .map(|i| truth[c * SAMPLES + i] + n[i])
                .collect()
        })
        .collect()
}

/// The recording of the measured channels, and the answer.
#[allow(clippy::too_many_arguments)]
fn assemble_case(
    options: &CaseOptions,
    voltage: &VoltageInput,
    r_true: f64,
    hidden: &[(String, Vec<f64>)],
    measured: Vec<Vec<f64>>,
    peak: [f64; 2],
    r_refit: f64,
    target: f64,
    input: InputProfile,
    input_fallback: bool,
    expected: Option<oracle::Margins>,
    realized: Option<f64>,
    attempts: usize,
) -> Case {
    let times = sample_times(DURATION, SAMPLES);
    let recording = Recording {
        source: "motorcal simulate --effect".into(),
        time: times,
        channels: vec![
            ("I".into(), measured[0].clone()),
            ("omega".into(), measured[1].clone()),
        ],
        voltage: voltage.held_values().map(<[f64]>::to_vec),
        inputs: Vec::new(),
    };
    let mut params = BTreeMap::new();
    params.insert("R".to_string(), r_true);
    let qualify = hidden.len() > 1;
    for (name, values) in hidden {
        let term = Term::named(name).expect("checked");
        for (p, v) in term.params().iter().zip(values) {
            let key = if qualify {
                ParamId::of_term(name, p.key).to_string()
            } else {
                p.key.to_string()
            };
            params.insert(key, *v);
        }
    }
    let label = if hidden.is_empty() {
        "none".to_string()
    } else {
        hidden
            .iter()
            .map(|(n, _)| n.clone())
            .collect::<Vec<_>>()
            .join(",")
    };
    let answer = Answer {
        effect: label,
        effects: hidden.iter().map(|(n, _)| n.clone()).collect(),
        params,
        kind: if input == InputProfile::Constant {
            "A"
        } else {
            "B"
        }
        .into(),
        input,
        input_fallback,
        noise: BTreeMap::from([
            ("sigma_I".into(), NOISE_SD[0]),
            ("sigma_omega".into(), NOISE_SD[1]),
        ]),
        seed: options.seed,
        target_magnitude: target,
        max_abs_effect_over_sigma: BTreeMap::from([
            ("I".into(), peak[0]),
            ("omega".into(), peak[1]),
        ]),
        r_of_refitted_nominal: r_refit,
        oracle_margin: expected.as_ref().map(|m| m.lead),
        oracle_runner_up: expected.as_ref().map(|m| m.runner_up.clone()),
        oracle_margin_over_none: expected.as_ref().map(|m| m.over_none),
        oracle_margin_over_none_realized: realized,
        attempts,
    };
    Case {
        recording,
        nominal: ModelFile::default(),
        answer,
    }
}
