//! The dynamic term a fingerprint names, fitted from the fingerprint's estimate: a delay names
//! `input_delay` (τ), a lag names `sensor_lag` on its channel (τ), a resonance that rings after
//! the input steps names `compliant_coupling` (f_r and ζ; the load's share from several
//! starts). These terms are not screened with the library (`PhysicsTerm::SCREENED`):
//! from a flat start their MAP search rarely finds the valley, from the fingerprint's it does.
//!
//! Each is tried beside the selected terms and alone (a library term selected for a delay
//! absorbs part of it, and beside the delay is then dead weight), scored as every candidate is
//! (log L̂ − ½·d·ln N), and taken when the better of the two beats the selected model by more
//! than [`EVIDENCE_THRESHOLD`]: the ranking's rule, for the ranking's reason.

use rayon::prelude::*;

use crate::error::Error;
use crate::motor::Term;
use crate::parameter::ParamId;
use crate::study::Problem;

use super::candidate::{Candidate, Starts, fit_candidate_started};
use super::settings::EVIDENCE_THRESHOLD;
use super::unexplained::{Fingerprint, Unexplained};

/// The term a fingerprint names, with its settings and the parameter values it starts at.
#[derive(Clone, Debug, PartialEq)]
pub struct NamedTerm {
    pub term: Term,
    pub start: Vec<(&'static str, f64)>,
    /// ln of the grid its start was the best of (a frequency), paid by its score.
    pub search_penalty: f64,
}

/// The term `fingerprint` names on `problem`'s base, if one does.
pub fn named_term(problem: &Problem, fingerprint: &Fingerprint) -> Option<NamedTerm> {
    let mut search_penalty = 0.0;
    let (term, start) = match fingerprint {
        Fingerprint::Delay { seconds, .. } => {
            (Term::named("input_delay")?, vec![("tau", *seconds)])
        }
        Fingerprint::Lag {
            channel, seconds, ..
        } => {
            let index = ["I", "omega"].iter().position(|c| c == channel)?;
            let term = Term::from_name("sensor_lag", &[index as f64])?.ok()?;
            (term, vec![("tau", *seconds)])
        }
        Fingerprint::Oscillation {
            frequency_hz,
            damping_ratio,
            ringing: true,
            grid_points,
            ..
        } => {
            search_penalty = (*grid_points.max(&1) as f64).ln();
            (
                Term::named("compliant_coupling")?,
                vec![
                    ("f_r", *frequency_hz),
                    ("zeta", damping_ratio.unwrap_or(0.1).clamp(1e-3, 1.0)),
                ],
            )
        }
        _ => return None,
    };
    let present = problem
        .model
        .terms
        .iter()
        .any(|t| t.term.name() == term.name());
    (problem.model.base.accepts(&term) && !present).then_some(NamedTerm {
        term,
        start,
        search_penalty,
    })
}

/// `named` fitted beside `with` (the selected terms, or none), started at `with`'s estimates
/// and the fingerprint's; a frequency found by a grid search pays the grid's multiplicity, as
/// in the ranking.
fn fit_named(problem: &Problem, with: &Candidate, named: &NamedTerm) -> Result<Candidate, Error> {
    let search_penalty = named.search_penalty;
    let name = named.term.name().to_string();
    let mut added = with.added.clone();
    added.push(name.clone());
    let mut starts = Starts {
        terms: vec![named.term.clone()],
        ..Starts::default()
    };
    for &(key, value) in &named.start {
        starts
            .values
            .insert(ParamId::of_term(&name, key).to_string(), value);
    }
    if search_penalty > 0.0 {
        starts.search_penalty.insert(name, search_penalty);
    }
    fit_candidate_started(problem, &added, Some(with), &starts)
}

/// The best fit of a term the verdict's fingerprints name (every kind that cleared the
/// threshold on its own, not only the leader: the fits, not the linearised scores, decide), when it beats `selected` by more than the threshold. Where the user named
/// the candidates (`allowed`), only those may be added: the list says what the diagnosis may
/// add to the model, whichever way it finds them.
pub fn fit_named_terms(
    problem: &Problem,
    left: &Unexplained,
    selected: &Candidate,
    none: &Candidate,
    allowed: Option<&[String]>,
) -> Result<Option<Candidate>, Error> {
    let mut named: Vec<NamedTerm> = Vec::new();
    for f in std::iter::once(&left.fingerprint).chain(&left.considered) {
        if let Some(n) = named_term(problem, f)
            && !named.iter().any(|m| m.term.name() == n.term.name())
            && allowed.is_none_or(|a| a.iter().any(|c| c == n.term.name()))
        {
            named.push(n);
        }
    }
    let mut bases = vec![selected];
    if !selected.added.is_empty() {
        bases.push(none);
    }
    let jobs: Vec<(&Candidate, &NamedTerm)> = named
        .iter()
        .flat_map(|n| bases.iter().map(move |b| (*b, n)))
        .collect();
    // A fit that fails (a stiff resonance far from the data) is no candidate, not an error of
    // the diagnosis.
    let fits: Vec<Candidate> = jobs
        .par_iter()
        .filter_map(|(with, n)| fit_named(problem, with, n).ok())
        .collect();
    Ok(fits
        .into_iter()
        .filter(|f| f.score - selected.score > EVIDENCE_THRESHOLD)
        .max_by(|a, b| a.score.total_cmp(&b.score)))
}
