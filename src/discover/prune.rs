//! The discovered law pruned through the ODE: the fingerprint chose its functions at first
//! order, and each must pay its ½·ln N in the fit of the law itself, as every candidate's
//! parameters pay in the ranking.

use rayon::prelude::*;

use crate::error::Error;
use crate::motor::Term;
use crate::motor::dictionary::{self, N_FUNCTIONS, PHASE_PAIRS};
use crate::motor::terms::Law;
use crate::parameter::ParamId;

use super::candidate::{Candidate, fit_candidate_at};
use super::named::law_of;

/// `fit`'s law with the functions that do not pay for themselves through the ODE removed
/// (backward elimination by the ranking's own score, log L̂ − ½·d·ln N): each function — a
/// sine-and-cosine pair as one ([`PHASE_PAIRS`]: a phase the origin of θ or t sets is no
/// physics to prune half of) — is dropped in turn, the law refitted from `fit`'s estimates,
/// and the best of these kept while it scores above the law it came from. The fingerprint
/// chose the functions at first order, on the residual of the model without the law; through
/// the ODE a function that followed part of the effect there can be left with a coefficient
/// its sd cannot tell from zero, and pays ½·ln N for nothing. On cogging-660005
/// (papers/beyond-library.md, session 6) `I*|I|` beside the angle's ripple was such a
/// function; the posterior it left was far from the Laplace approximation, and the NUTS run
/// that replaced the weights took most of the diagnosis. A searched frequency's or harmonic's
/// price is kept whatever is dropped: the grid was searched. `None` where `fit` holds no law
/// of two or more such units, or none is dropped.
pub fn prune_law(fit: &Candidate) -> Result<Option<Candidate>, Error> {
    let mut best: Option<Candidate> = None;
    loop {
        let current = best.as_ref().unwrap_or(fit);
        let Some(units) = law_of(current).map(units_of).filter(|u| u.len() > 1) else {
            break;
        };
        let reduced: Vec<Candidate> = units
            .par_iter()
            .filter_map(|unit| without(current, unit).ok())
            .collect();
        match reduced
            .into_iter()
            .max_by(|a, b| a.score.total_cmp(&b.score))
        {
            Some(r) if r.score > current.score => best = Some(r),
            _ => break,
        }
    }
    Ok(best)
}

/// `law`'s functions as keys, a sine-and-cosine pair both of whose halves it holds as one unit.
fn units_of(law: &Law) -> Vec<Vec<usize>> {
    let mut units: Vec<Vec<usize>> = Vec::new();
    for &k in &law.active {
        let (b, f) = (k / N_FUNCTIONS, k % N_FUNCTIONS);
        let partner = PHASE_PAIRS
            .iter()
            .find(|p| p.contains(&f))
            .map(|p| b * N_FUNCTIONS + if p[0] == f { p[1] } else { p[0] })
            .filter(|q| law.active.contains(q));
        match partner {
            Some(q) if q < k => {}
            Some(q) => units.push(vec![k, q]),
            None => units.push(vec![k]),
        }
    }
    units
}

/// `fit` refitted with its law's functions `unit` removed, its terms as they were set (a lag's
/// channel, the law's shapes), every parameter started at `fit`'s estimate, paying the same
/// search price.
fn without(fit: &Candidate, unit: &[usize]) -> Result<Candidate, Error> {
    let dropped: Vec<ParamId> = unit
        .iter()
        .map(|&k| ParamId::of_term("law", dictionary::key(k)))
        .collect();
    let mut problem = fit.problem.clone();
    for active in &mut problem.model.terms {
        if let Term::Law(law) = &mut active.term {
            let kept = law
                .active
                .iter()
                .copied()
                .filter(|a| !unit.contains(a))
                .collect();
            *law = law.clone().with_active(kept);
        }
    }
    if let Some(calibrate) = &mut problem.model.calibrate {
        calibrate.retain(|e| !dropped.contains(&e.id));
    }
    let start = fit
        .theta
        .iter()
        .filter(|(name, _)| !dropped.contains(&ParamId::parse(name)))
        .map(|(name, v)| (name.clone(), *v))
        .collect();
    fit_candidate_at(problem, &fit.added, &start, fit.search_penalty)
}
