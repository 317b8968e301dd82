//! `motorcal design`: the input to record next. Within the drive's limits, a piecewise-constant
//! voltage of N segments — for a `current_driven` model a current command, for a
//! `position_loop` the speed of a reference position ([`Commanded`]) —
//! that either tells candidate explanations apart (the expected evidence gap of each candidate
//! as the truth over its best-fitting rival, [`separate`]) or pins named parameters (D-optimal
//! on the Fisher matrix of the forward sensitivities, [`pin`]); beside it the fixed experiments
//! `diagnose` tries for a tie ([`crate::discover::TIE_EXPERIMENTS`]) and for pinning the
//! constant input: at the model's U, or for a drive at the largest current or reference speed
//! within the limits ([`fixed_inputs`]).
//!
//! The files: `profile` (the input and its free coordinates), `limits`, `experiment` (the
//! candidates at their estimates, the sampling and σ), `fitted` (the candidates' estimates
//! when no diagnosis gives them), `separate` and `pin` (the objectives),
//! `search` (multi-start Nelder–Mead), `rivals` (the rest of the library on a separating
//! design's input, and the redesign with the rivals it finds). Nothing here reads or writes a file: `app::design` does.
//!
//! **Limits.** An input is judged on the noise-free predictions of every candidate at the
//! record's samples: one whose |I|, |ω| or a position loop's |q| or force passes its limit
//! there is refused (a position loop's speed is its position's difference between samples). The
//! search runs on the continuous switching times with the current, speed, travel and force
//! limits 2% tighter ([`MARGIN`]), a reference's speeds too, since the axis follows them; the
//! input written switches at the first sample at or after each switching time, and is
//! checked again against the limits themselves — an input that then passes one is an error,
//! never clipped. A drive is integrated at its samples with its input held over each sample
//! interval ([`crate::motor::SampledDrive`]): its search sees a switch at the first sample at or
//! after it already, so what it finds is what is written.

mod experiment;
mod fitted;
mod limits;
mod pin;
mod profile;
mod rivals;
mod search;
mod separate;

pub use experiment::{
    Candidate, Commanded, Experiment, default_noise_sd, design_problem, design_times, model_limits,
    parse_candidate,
};
pub use fitted::candidates_without_diagnosis;
pub use limits::Limits;
pub use pin::{Pinned, Target, fisher, pin_candidate, pin_values_from, pinned};
pub use profile::{Profile, held};
pub use rivals::{
    CheckedSeparation, RIVAL_ROUNDS, Rival, RivalCheck, RivalRound, check_rivals, library,
    separate_checked,
};
pub use search::SearchSettings;
pub use separate::{
    Evaluation, ExpectedGap, Lead, LeadCurves, expected_gaps, lead_curves, noise_free_leads,
    predictions,
};

use crate::error::Error;
use crate::motor::VoltageInput;
use crate::study::InputProfile;

/// The search keeps |I|, |ω|, |q| and a position loop's force this fraction inside their
/// limits (see the module's notes).
pub const MARGIN: f64 = 0.98;

/// Monte Carlo records per truth for a reported gap.
pub const DEFAULT_DRAWS: usize = 20;

/// What the search's cost is when an input passes the limits: above any feasible cost, and
/// smaller the less it passes them.
const INFEASIBLE: f64 = 1e6;

#[derive(Clone, Copy, Debug)]
pub struct DesignSettings {
    pub search: SearchSettings,
    pub limits: Limits,
    /// Monte Carlo records per truth for the reported gaps.
    pub draws: usize,
}

/// An input other than the designed one, with where it takes the motor.
#[derive(Clone, Debug, serde::Serialize)]
pub struct InputCheck {
    pub input: String,
    pub within_limits: bool,
    /// Peak |I| and |ω| (a position loop: |q| and the axis's |ω|) over the candidates.
    pub peaks: std::collections::BTreeMap<String, f64>,
    /// The level at each of the experiment's times (what a fixed experiment's file holds, so
    /// that it can be recorded too and its expected figures checked).
    #[serde(skip)]
    pub levels: Vec<f64>,
}

/// A fixed experiment's gaps, for comparison.
#[derive(Clone, Debug, serde::Serialize)]
pub struct FixedSeparation {
    #[serde(flatten)]
    pub check: InputCheck,
    /// The smallest expected gap over the truths.
    pub expected_gap_nats: f64,
    pub spread_nats: f64,
    pub gaps: Vec<ExpectedGap>,
}

/// The designed separating input.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SeparationDesign {
    pub profile: Profile,
    pub times: Vec<f64>,
    /// The level at each sample time: the voltage, a current command, or a reference's speed
    /// (`input.csv` holds what the drive is played: [`Commanded::played`]).
    pub values: Vec<f64>,
    pub check: InputCheck,
    /// The smallest expected gap over the truths (the design's guarantee), its truth's sd.
    pub expected_gap_nats: f64,
    pub spread_nats: f64,
    pub gaps: Vec<ExpectedGap>,
    pub fixed_experiments: Vec<FixedSeparation>,
}

/// The designed pinning input.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PinDesign {
    pub profile: Profile,
    pub times: Vec<f64>,
    pub values: Vec<f64>,
    pub check: InputCheck,
    pub pinned: Pinned,
    pub fixed_experiments: Vec<(InputCheck, Pinned)>,
}

fn no_limits() -> Limits {
    Limits::open()
}

fn check(
    experiment: &Experiment,
    name: &str,
    input: &VoltageInput,
    limits: &Limits,
) -> Result<InputCheck, Error> {
    let mut peaks = std::collections::BTreeMap::new();
    let mut within = true;
    for c in &experiment.candidates {
        let forward = c.forward(input, &experiment.times)?;
        let mut y = vec![0.0; forward.n_outputs()];
        forward
            .simulate(&c.theta, &mut y)
            .map_err(|e| Error::Numerical(e.to_string()))?;
        within &= limits.excess(forward.channels(), &y, &experiment.times) == 0.0;
        for (channel, peak) in limits.peaks(forward.channels(), &y, &experiment.times) {
            let slot = peaks.entry(channel).or_insert(0.0f64);
            *slot = slot.max(peak);
        }
    }
    if let VoltageInput::Held { values, .. } = input {
        let bound = experiment.commanded().level_limit(limits)?;
        within &= values.iter().all(|u| u.abs() <= bound);
    }
    let held_at = experiment
        .candidates
        .first()
        .map_or(0.0, |c| c.problem.model.motor.voltage);
    let levels = experiment
        .times
        .iter()
        .map(|&t| input.value_at(t).unwrap_or(held_at))
        .collect();
    Ok(InputCheck {
        input: name.into(),
        within_limits: within,
        peaks,
        levels,
    })
}

/// Refuses a σ per channel that does not match the candidates' channels, and limits that no
/// useful input can meet: a constant 1% of the level limit (the voltage, or a current command)
/// already drives a candidate past the current or speed limit.
fn check_possible(experiment: &Experiment, limits: &Limits) -> Result<(), Error> {
    let channels = experiment.channels();
    if experiment.noise_sd.len() != channels.len()
        || experiment
            .noise_sd
            .iter()
            .any(|s| !(*s > 0.0 && s.is_finite()))
    {
        return Err(Error::setting(
            "noise-sd",
            format!("{:?}", experiment.noise_sd),
            format!(
                "give one positive σ per channel the model measures ({})",
                channels.join(", ")
            ),
        ));
    }
    let commanded = experiment.commanded();
    let u = 0.01 * commanded.level_limit(limits)?;
    let input = held(&experiment.times, vec![u; experiment.times.len()]);
    let c = check(experiment, "probe", &input, limits)?;
    if !c.within_limits {
        let peaks: Vec<String> = c
            .peaks
            .iter()
            .map(|(k, v)| format!("|{k}| {v:.3}"))
            .collect();
        return Err(Error::setting(
            "limits",
            limits,
            format!(
                "no input can meet these limits: a constant {u} {} (1% of the {} limit) \
                 already reaches {}",
                commanded.level().1,
                commanded.level().0,
                peaks.join(", ")
            ),
        ));
    }
    Ok(())
}

/// `settings` with the limits the candidates' model keeps ([`model_limits`]: a position loop's
/// force under its saturation unless given).
fn with_model_limits(experiment: &Experiment, settings: &DesignSettings) -> DesignSettings {
    let limits = match experiment.candidates.first() {
        Some(c) => model_limits(&c.problem.model, settings.limits),
        None => settings.limits,
    };
    DesignSettings {
        limits,
        ..*settings
    }
}

fn tightened(limits: &Limits) -> Limits {
    Limits {
        current: limits.current * MARGIN,
        speed: limits.speed * MARGIN,
        position: limits.position * MARGIN,
        force: limits.force * MARGIN,
        ..*limits
    }
}

/// The search on `cost`, the profile it ends at, and that profile sampled and checked.
/// `extra` starts go beside the seeded ones ([`fixed_starts`]); with `judge`, the start whose
/// end it rates lowest wins, not the one `cost` rates lowest (see [`separate`]).
fn search_profile<F: Fn(&VoltageInput) -> f64 + Sync>(
    experiment: &Experiment,
    settings: &DesignSettings,
    extra: &[Profile],
    cost: F,
    judge: Option<&dyn Fn(&VoltageInput) -> f64>,
) -> Result<(Profile, Vec<f64>, VoltageInput, InputCheck), Error> {
    let duration = *experiment.times.last().unwrap_or(&0.0);
    let n = settings.search.segments;
    if n < 1 {
        return Err(Error::setting(
            "segments",
            n,
            "a design needs at least one segment",
        ));
    }
    // A reference's speeds keep the speed's margin: the axis follows them.
    let commanded = experiment.commanded();
    let u_max = match commanded {
        Commanded::Position => commanded.level_limit(&tightened(&settings.limits))?,
        _ => commanded.level_limit(&settings.limits)?,
    };
    let starts: Vec<Vec<f64>> = search::starts(&settings.search, duration, u_max)
        .iter()
        .chain(extra)
        .map(|p| p.to_free(u_max))
        .collect();
    let free = |z: &[f64]| cost(&Profile::from_free(z, n, duration, u_max).continuous());
    let ends = search::minimise_each(&starts, settings.search.iterations, &free);
    let rated: Vec<f64> = match judge {
        Some(judge) => ends
            .iter()
            .map(|(z, _)| judge(&Profile::from_free(z, n, duration, u_max).continuous()))
            .collect(),
        None => ends.iter().map(|(_, c)| *c).collect(),
    };
    // The first among equals: the same end whatever the thread count.
    let best = (1..ends.len()).fold(0, |b, i| if rated[i] < rated[b] { i } else { b });
    let profile = Profile::from_free(&ends[best].0, n, duration, u_max);
    let values = profile.sampled(&experiment.times);
    let input = held(&experiment.times, values.clone());
    let c = check(experiment, "designed", &input, &settings.limits)?;
    if !c.within_limits {
        return Err(Error::Numerical(format!(
            "the best input the search found passes the limits once sampled (peaks {:?}); it is \
             refused rather than clipped: try more segments or another seed",
            c.peaks
        )));
    }
    Ok((profile, values, input, c))
}

/// The fixed experiments: each profile at the model's U, or for a drive at the largest level
/// (current, or reference speed) within its limit at which every candidate stays within the
/// limits (the strongest such experiment the drive allows; a constant load can make that zero).
/// (name, input).
fn fixed_inputs(
    experiment: &Experiment,
    profiles: &[InputProfile],
    limits: &Limits,
) -> Result<Vec<(String, VoltageInput)>, Error> {
    let times = &experiment.times;
    let at = |p: &InputProfile, u: f64| match p.voltage(u, times) {
        VoltageInput::Constant => held(times, vec![u; times.len()]),
        held => held,
    };
    let mut out = Vec::new();
    for p in profiles {
        let u = match experiment.commanded() {
            Commanded::Voltage => experiment
                .candidates
                .first()
                .map_or(0.0, |c| c.problem.model.motor.voltage),
            commanded @ (Commanded::Current | Commanded::Position) => {
                let within = |u: f64| -> Result<bool, Error> {
                    Ok(check(experiment, p.name(), &at(p, u), limits)?.within_limits)
                };
                let mut high = commanded.level_limit(limits)?;
                let mut low = 0.0;
                if within(high)? {
                    low = high;
                } else {
                    // Bisection on the level: 20 halvings leave it within 1e-6 of the limit's
                    // bound, and `low` is within the limits at every step.
                    for _ in 0..20 {
                        let mid = 0.5 * (low + high);
                        if within(mid)? {
                            low = mid;
                        } else {
                            high = mid;
                        }
                    }
                }
                low
            }
        };
        out.push((p.name().to_string(), at(p, u)));
    }
    Ok(out)
}

/// For a drive's command, the fixed experiments as search starts, at the largest level within
/// the search's (tightened) limits: each is then a feasible start, and the designed input's
/// noise-free objective is at least theirs (the search keeps its best point). Run at the
/// limits, they are strong: the seeded starts alone were seen to end far below the reversal
/// (HSM150's model, Coulomb friction against a load: 268 nats against 1842). None for a
/// voltage: its fixed experiments run at the model's U, often past the limits.
fn fixed_starts(
    experiment: &Experiment,
    profiles: &[InputProfile],
    search_limits: &Limits,
    segments: usize,
) -> Result<Vec<Profile>, Error> {
    if !experiment.commanded().is_sampled() {
        return Ok(Vec::new());
    }
    let duration = *experiment.times.last().unwrap_or(&0.0);
    Ok(fixed_inputs(experiment, profiles, search_limits)?
        .into_iter()
        .filter_map(|(_, input)| match input {
            VoltageInput::Held { times, values } => {
                Profile::from_held(&times, &values, segments, duration)
            }
            VoltageInput::Constant => None,
        })
        .collect())
}

fn worst(gaps: &[ExpectedGap]) -> (f64, f64) {
    gaps.iter()
        .map(|g| (g.expected_gap_nats, g.sd_nats))
        .fold((f64::INFINITY, 0.0), |a, b| if b.0 < a.0 { b } else { a })
}

/// Designs the input that separates the experiment's candidates (at least two).
pub fn separate(
    experiment: &Experiment,
    settings: &DesignSettings,
) -> Result<SeparationDesign, Error> {
    if experiment.candidates.len() < 2 {
        return Err(Error::setting(
            "separate",
            experiment.candidates.len(),
            "separating needs at least two candidates",
        ));
    }
    let settings = &with_model_limits(experiment, settings);
    check_possible(experiment, &settings.limits)?;
    let search_limits = tightened(&settings.limits);
    let cost =
        |input: &VoltageInput| match noise_free_leads(experiment, input, &search_limits, false) {
            Ok(Evaluation::Infeasible { excess }) => INFEASIBLE * (1.0 + excess),
            Ok(e) => -e.worst(),
            Err(_) => INFEASIBLE * 1e3,
        };
    let profiles = crate::discover::TIE_EXPERIMENTS;
    let n = settings.search.segments;
    let extra = fixed_starts(experiment, &profiles, &search_limits, n)?;
    // The search's rival fits are a few Gauss–Newton steps: an input where they stop short
    // looks separating and is not. With the fixed experiments among the starts the ends are
    // rated by fits to convergence, so that the design is not chosen below a start it left.
    let polished =
        |input: &VoltageInput| match noise_free_leads(experiment, input, &search_limits, true) {
            Ok(Evaluation::Infeasible { excess }) => INFEASIBLE * (1.0 + excess),
            Ok(e) => -e.worst(),
            Err(_) => INFEASIBLE * 1e3,
        };
    let judge: Option<&dyn Fn(&VoltageInput) -> f64> = if extra.is_empty() {
        None
    } else {
        Some(&polished)
    };
    let (profile, values, input, check) =
        search_profile(experiment, settings, &extra, cost, judge)?;
    let seed = settings.search.seed;
    let gaps = expected_gaps(experiment, &input, &settings.limits, settings.draws, seed)?;
    let (expected_gap_nats, spread_nats) = worst(&gaps);
    let mut fixed_experiments = Vec::new();
    for (name, fixed) in fixed_inputs(experiment, &profiles, &settings.limits)? {
        let check = self::check(experiment, &name, &fixed, &settings.limits)?;
        let gaps = expected_gaps(experiment, &fixed, &no_limits(), settings.draws, seed)?;
        let (g, s) = worst(&gaps);
        fixed_experiments.push(FixedSeparation {
            check,
            expected_gap_nats: g,
            spread_nats: s,
            gaps,
        });
    }
    Ok(SeparationDesign {
        profile,
        times: experiment.times.clone(),
        values,
        check,
        expected_gap_nats,
        spread_nats,
        gaps,
        fixed_experiments,
    })
}

/// Designs the input that pins `targets` of `candidate` (the experiment's candidates are only
/// used for the limits check: pass the candidate itself).
pub fn pin(
    candidate: &Candidate,
    experiment: &Experiment,
    targets: &[Target],
    settings: &DesignSettings,
) -> Result<PinDesign, Error> {
    let settings = &with_model_limits(experiment, settings);
    check_possible(experiment, &settings.limits)?;
    let search_limits = tightened(&settings.limits);
    let cost = |input: &VoltageInput| match pin::pin_cost(
        candidate,
        experiment,
        targets,
        input,
        &search_limits,
    ) {
        Ok(Ok(log_det)) if log_det.is_finite() => log_det,
        Ok(Ok(_)) => INFEASIBLE,
        Ok(Err(excess)) => INFEASIBLE * (1.0 + excess),
        Err(_) => INFEASIBLE * 1e3,
    };
    let profiles = [
        InputProfile::Constant,
        crate::discover::TIE_EXPERIMENTS[0],
        crate::discover::TIE_EXPERIMENTS[1],
    ];
    let n = settings.search.segments;
    let extra = fixed_starts(experiment, &profiles, &search_limits, n)?;
    let (profile, values, input, check) = search_profile(experiment, settings, &extra, cost, None)?;
    let pinned = pinned(candidate, experiment, targets, &input)?;
    let mut fixed_experiments = Vec::new();
    for (name, fixed) in fixed_inputs(experiment, &profiles, &settings.limits)? {
        let check = self::check(experiment, &name, &fixed, &settings.limits)?;
        fixed_experiments.push((check, self::pinned(candidate, experiment, targets, &fixed)?));
    }
    Ok(PinDesign {
        profile,
        times: experiment.times.clone(),
        values,
        check,
        pinned,
        fixed_experiments,
    })
}
