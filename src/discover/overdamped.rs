//! A coupling that rings not, and the reading it can stand in for.
//!
//! `compliant_coupling` is the load on a torsion spring and damper. With its damping ratio over
//! 1 its modes are real: nothing rings, and what the term holds on a record is the motor's side
//! running ahead of the load while the torque drives it, the speed measured on that side
//! leading the rigid motor's by about the torque over the damper's constant. A speed sensor
//! whose lead picks up the current's field reads the same: ω read as ω + κ·I (crosstalk). On
//! speed_crosstalk-780004 (papers/beyond-library.md, session 19) the coupling was selected at
//! ζ = 12.6 for that sensor, where the law `measured omega += κ·I` written by hand fits the
//! record better with two parameters fewer.
//!
//! The reading's dictionary does not offer I on ω (`unexplained::reading`: to first order a
//! lag of ω reads like it, and offered at first order it took a resonant sensor's place). Here
//! it is offered only as the overdamped coupling's alternative, fitted through the ODE in the
//! coupling's place, and the fits decide by the ranking's threshold.

use crate::parameter::ParamId;
use crate::study::Problem;

use super::candidate::{Candidate, fit_candidate_started};
use super::named::{named_term, starts_of};
use super::settings::EVIDENCE_THRESHOLD;
use super::unexplained::{Fingerprint, LawFunction};

const COUPLING: &str = "compliant_coupling";

/// The damping ratio above which a coupling's modes are real: it does not ring.
const CRITICAL_DAMPING: f64 = 1.0;

/// The speed's reading of the current, as the state fingerprint a law is named from, its
/// coefficient started at zero.
fn crosstalk() -> Fingerprint {
    let i = LawFunction {
        name: "I".into(),
        coefficient: 0.0,
        sd: 0.0,
    };
    Fingerprint::plain_state("measurement:omega", vec![i], 0.0)
}

/// Where `selected` holds a coupling damped past critical: the law reading the current in the
/// speed fitted in the coupling's place (the other selected terms kept), and a note of what was
/// tried and what it scored; the fit only where it beats `selected` by more than the threshold.
/// None where there is no such coupling, the model or its base takes no such law
/// (`named::named_term`), or the user's candidates (`allowed`) leave no law to add.
pub(super) fn reading_in_place(
    problem: &Problem,
    selected: &Candidate,
    allowed: Option<&[String]>,
) -> Option<(Option<Candidate>, String)> {
    if !selected.added.iter().any(|a| a == COUPLING)
        || allowed.is_some_and(|a| !a.iter().any(|c| c == "law"))
    {
        return None;
    }
    let zeta = *selected
        .theta
        .get(&ParamId::of_term(COUPLING, "zeta").to_string())?;
    if zeta <= CRITICAL_DAMPING {
        return None;
    }
    let named = named_term(problem, &crosstalk())?;
    let mut added: Vec<String> = (selected.added.iter())
        .filter(|a| *a != COUPLING)
        .cloned()
        .collect();
    added.push(named.term.name().into());
    let head = format!("{COUPLING}'s damping ratio is {zeta:.3}, over 1: it rings not");
    // A fit that fails is no candidate, as a named term's is not (`named::fit_named_terms`).
    let Ok(fit) = fit_candidate_started(problem, &added, Some(selected), &starts_of(&named)) else {
        return Some((
            None,
            format!(
                "{head}; a reading of the current in the speed's in its place could not be fitted"
            ),
        ));
    };
    let key = ParamId::of_term(named.term.name(), named.start[0].0).to_string();
    let gain = fit.score - selected.score;
    let taken = gain > EVIDENCE_THRESHOLD;
    let note = format!(
        "{head}, and what it holds is the motor's side running ahead of the load; a reading of \
         the current in the speed's (crosstalk: measured omega += {:.4e}·I) fitted in its place \
         scores {gain:+.2} nats against it, {}",
        fit.theta.get(&key).copied().unwrap_or(f64::NAN),
        if taken {
            "and is taken"
        } else {
            "under the threshold: the coupling stays"
        }
    );
    Some((taken.then_some(fit), note))
}
