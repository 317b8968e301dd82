//! The rest of the library on a designed input. A design separates the candidates it is given;
//! a library term it is not given can coincide with one of them on the input it found and take
//! the ranking of a record made on it (asymmetric friction, −k_a·ω·tanh(ω/ω_s), is viscous
//! friction with k_a = ∓Dd wherever ω keeps one sign). So after the search, each candidate as
//! the truth (its noise-free prediction on the designed input at its estimate) is fitted by
//! every other model `diagnose` ranks — the model as given (`none`) and each library term the
//! model lacks ([`candidate_names`]) — and a rival whose expected score comes within the
//! ranking's tie threshold of the truth's is reported; [`separate_checked`] then adds such
//! rivals to the candidates and designs again.
//!
//! **The score** is the design's own ([`super::separate`]): the rival refitted by weighted least
//! squares at the recording's σ to the truth's noise-free prediction, the truth's expected lead
//! ½·SS/σ² + ½·(d_rival − d_truth)·ln N, the Schwarz score `diagnose` ranks by, without a
//! record's noise. A rival starts at the truth's values of the parameters they share (R, …) and
//! at [`starting_values`] for its own (the model's values, a prior's median for one on its
//! bound: where `diagnose`'s search starts it). One start, where `diagnose` tries several and
//! starts its dynamic terms (a delay, a lag, a resonance) from estimates on the residual: a
//! rival whose valley that start misses is not found (the check can miss, it does not invent),
//! and one whose solve fails is listed as not fitted. A `load_step` whose switching time lands
//! on a step of the designed input is reported although `diagnose` would mark it as coinciding
//! with the input and never select it.

use rayon::prelude::*;
use serde::Serialize;

use crate::discover::{EVIDENCE_THRESHOLD, candidate_names};
use crate::error::Error;
use crate::motor::VoltageInput;
use crate::study::Problem;

use super::experiment::{Candidate, Experiment};
use super::fitted::starting_values;
use super::separate::{lead_over, predictions};
use super::{DesignSettings, SeparationDesign, held, no_limits, separate};

/// Redesigns after the first design when the check finds rivals: at most this many.
pub const RIVAL_ROUNDS: usize = 2;

/// A library model whose expected score on the designed input comes within the tie threshold
/// of a candidate's when that candidate is the truth.
#[derive(Clone, Debug, Serialize)]
pub struct Rival {
    pub truth: String,
    pub rival: String,
    /// The truth's expected score lead over the rival refitted to its noise-free prediction
    /// [nats]: at most [`EVIDENCE_THRESHOLD`].
    pub expected_gap_nats: f64,
}

/// What the check found on one input.
#[derive(Clone, Debug)]
pub struct RivalCheck {
    /// The models fitted against every truth: `none` and the library terms not among the
    /// candidates.
    pub library: Vec<String>,
    /// Every (truth, rival) whose expected lead is within the threshold, smallest lead first.
    pub rivals: Vec<Rival>,
    /// `rivals[i]`'s model at its fit to its truth's prediction: where it would sit if that
    /// truth made the record.
    pub fits: Vec<Candidate>,
    /// (truth, rival) pairs whose fit could not be completed (the solve failed).
    pub not_fitted: Vec<(String, String)>,
}

/// `none` and every library term `base` lacks that `diagnose` would rank, less the candidates.
pub fn library(base: &Problem, experiment: &Experiment) -> Result<Vec<String>, Error> {
    let mut names = vec!["none".to_string()];
    names.extend(candidate_names(base, None)?);
    names.retain(|n| !experiment.candidates.iter().any(|c| &c.name == n));
    Ok(names)
}

/// Fits every model of `library` to each candidate's noise-free prediction under `input` and
/// keeps those within the threshold (see the module's notes). The model as given (`none`) is
/// not checked as a truth: the ranking names it unless a term beats it by more than the
/// threshold, and a term fitted to its noise-free prediction at best reproduces it and pays
/// ½·ln N per parameter. The fits run in parallel, one model each, and are gathered in
/// `library`'s order: the result is the same whatever the thread count.
pub fn check_rivals(
    base: &Problem,
    experiment: &Experiment,
    input: &VoltageInput,
    library: &[String],
) -> Result<RivalCheck, Error> {
    let (predicted, _) = predictions(experiment, input, &no_limits())?;
    let truths: Vec<(&Candidate, &Vec<f64>)> = experiment
        .candidates
        .iter()
        .zip(&predicted)
        .filter(|(c, _)| !c.added.is_empty())
        .collect();
    type Fits = Vec<Result<(f64, Candidate), Error>>;
    let per_model: Vec<Fits> = library
        .par_iter()
        .map(|name| -> Result<Fits, Error> {
            let added = super::parse_candidate(name)?;
            let start = starting_values(base, &added)?;
            Ok(truths
                .iter()
                .map(|(truth, target)| {
                    let mut values = start.clone();
                    for (key, v) in truth.calibrated.iter().zip(&truth.theta) {
                        if let Some(slot) = values.get_mut(key) {
                            *slot = *v;
                        }
                    }
                    let rival = Candidate::new(base, name, &values)?;
                    let (gap, theta) = lead_over(experiment, input, target, truth, &rival, true)?;
                    let at = rival.calibrated.iter().cloned().zip(theta).collect();
                    Ok((gap, Candidate::new(base, name, &at)?))
                })
                .collect())
        })
        .collect::<Result<_, _>>()?;
    let mut found = Vec::new();
    let mut not_fitted = Vec::new();
    for (name, fits) in library.iter().zip(per_model) {
        for ((truth, _), fit) in truths.iter().zip(fits) {
            let (gap, at) = match fit {
                Ok(fit) => fit,
                Err(Error::Numerical(_)) => {
                    not_fitted.push((truth.name.clone(), name.clone()));
                    continue;
                }
                Err(e) => return Err(e),
            };
            // `diagnose` reports a runner-up whose score is within EVIDENCE_THRESHOLD of the
            // selected term's as a tie, and selects a term only where it leads the model as
            // given by more: a rival expected within it of the truth would, on a typical
            // record, be tied with the truth or selected in its place (`none`: the truth not
            // selected at all), so the design has not separated them.
            if gap <= EVIDENCE_THRESHOLD {
                let rival = Rival {
                    truth: truth.name.clone(),
                    rival: name.clone(),
                    expected_gap_nats: gap,
                };
                found.push((rival, at));
            }
        }
    }
    // Stable: equal leads keep the library's order.
    found.sort_by(|a, b| a.0.expected_gap_nats.total_cmp(&b.0.expected_gap_nats));
    let (rivals, fits) = found.into_iter().unzip();
    Ok(RivalCheck {
        library: library.to_vec(),
        rivals,
        fits,
        not_fitted,
    })
}

/// The rivals a redesign adds to the candidates, each once at its fit to the truth it comes
/// closest to. Where the model as given is among a truth's rivals, the truth is barely seen on
/// this input and the terms that tie with it mostly do so by vanishing too: for that truth only
/// `none` is added (separating the truth from it makes the effect seen; a term that still
/// coincides with it is found in the next round). A rival with more parameters than its truth
/// is reported, not added: within the threshold it pays ½·ln N per extra parameter, so it can
/// only be there on a record of fewer than e⁴ ≈ 55 values, and there it is mostly the truth
/// with parameters to spare, which no input separates from the truth.
fn to_add(experiment: &Experiment, check: &RivalCheck) -> Vec<Candidate> {
    let size = |name: &str| {
        experiment
            .candidates
            .iter()
            .find(|c| c.name == name)
            .map_or(0, |c| c.theta.len())
    };
    let unseen: Vec<&str> = check
        .rivals
        .iter()
        .filter(|r| r.rival == "none")
        .map(|r| r.truth.as_str())
        .collect();
    let mut out: Vec<Candidate> = Vec::new();
    for (rival, fit) in check.rivals.iter().zip(&check.fits) {
        let kept = rival.rival == "none" || !unseen.contains(&rival.truth.as_str());
        let larger = fit.theta.len() > size(&rival.truth);
        if kept && !larger && !out.iter().any(|c| c.name == rival.rival) {
            out.push(fit.clone());
        }
    }
    out
}

/// One design and its check.
#[derive(Clone, Debug, Serialize)]
pub struct RivalRound {
    /// The candidates this round designed for.
    pub candidates: Vec<String>,
    /// Its designed input's expected gap (worst truth) and that truth's sd.
    pub expected_gap_nats: f64,
    pub spread_nats: f64,
    pub unseparated_rivals: Vec<Rival>,
    /// (truth, rival) pairs whose fit could not be completed.
    pub not_fitted: Vec<(String, String)>,
    /// Why rivals were left without a redesign, where they were.
    pub note: Option<String>,
}

/// The design after the rival check: the last round's design, the candidates it separates (the
/// given ones, then the rivals added), and every round.
#[derive(Clone, Debug)]
pub struct CheckedSeparation {
    pub design: SeparationDesign,
    pub experiment: Experiment,
    pub rounds: Vec<RivalRound>,
    /// The models checked in the last round.
    pub library: Vec<String>,
}

impl CheckedSeparation {
    /// The rivals the final design leaves within the threshold.
    pub fn unseparated_rivals(&self) -> &[Rival] {
        self.rounds
            .last()
            .map_or(&[], |r| r.unseparated_rivals.as_slice())
    }

    /// The candidates the check added, in the order it added them.
    pub fn added(&self) -> Vec<String> {
        let given = self.rounds.first().map_or(0, |r| r.candidates.len());
        self.experiment.candidates[given..]
            .iter()
            .map(|c| c.name.clone())
            .collect()
    }
}

/// [`separate`], then the check of the rest of the library on the designed input; while it
/// finds rivals and at most `extra_rounds` times, the rivals join the candidates ([`to_add`])
/// and the input is designed again. No redesign where the design does not separate its own
/// candidates by more than the threshold (noise-free): the search maximises the smallest lead
/// over the truths' rivals, and more candidates can only lower it, so they could not be
/// separated either; the rivals are then reported as they are. `base` is the user's model on
/// the design's sampling ([`super::design_problem`]).
pub fn separate_checked(
    base: &Problem,
    experiment: &Experiment,
    settings: &DesignSettings,
    extra_rounds: usize,
) -> Result<CheckedSeparation, Error> {
    let mut experiment = experiment.clone();
    let mut rounds: Vec<RivalRound> = Vec::new();
    loop {
        let design = separate(&experiment, settings)?;
        let input = held(&design.times, design.values.clone());
        let library = library(base, &experiment)?;
        let check = check_rivals(base, &experiment, &input, &library)?;
        let own = design
            .gaps
            .iter()
            .map(|g| g.noise_free_gap_nats)
            .fold(f64::INFINITY, f64::min);
        let note = if check.rivals.is_empty() {
            None
        } else if own <= EVIDENCE_THRESHOLD {
            Some(format!(
                "not redesigned: the design leads its own candidates by {own:.2} nats at worst \
                 (noise-free), within the {EVIDENCE_THRESHOLD}-nat threshold; more candidates \
                 cannot be separated either"
            ))
        } else if rounds.len() >= extra_rounds {
            Some(format!("not redesigned: {extra_rounds} redesigns done"))
        } else {
            None
        };
        let added = to_add(&experiment, &check);
        let note = note.or_else(|| {
            (!check.rivals.is_empty() && added.is_empty()).then(|| {
                "not redesigned: every rival has more parameters than its truth (see to_add)"
                    .to_string()
            })
        });
        let done = check.rivals.is_empty() || note.is_some();
        rounds.push(RivalRound {
            candidates: experiment
                .candidates
                .iter()
                .map(|c| c.name.clone())
                .collect(),
            expected_gap_nats: design.expected_gap_nats,
            spread_nats: design.spread_nats,
            unseparated_rivals: check.rivals,
            not_fitted: check.not_fitted,
            note,
        });
        if done {
            return Ok(CheckedSeparation {
                design,
                experiment,
                rounds,
                library,
            });
        }
        experiment.candidates.extend(added);
    }
}
