//! Where the dynamic terms start when they are ranked: the verdict's own estimates on the
//! residual of the model as given, whatever their evidence. A delay's τ, a lag's τ and the
//! channel it is on, a ringing resonance's frequency and damping ratio are what a MAP search
//! from the terms' defaults (τ = 0 on its bound, a resonance at 100 Hz) cannot find by itself:
//! the likelihood in a frequency has a valley per harmonic, and at τ = 0 the gradient of a lag
//! on one channel is no guide to which channel.
//!
//! And whether the compliant coupling is ranked at all: only where that residual rings after
//! the input's steps by more than the threshold. A coupling's three parameters (the load's
//! share, f_r, ζ) make it the library's most flexible term: with f_r far below or above what
//! the record resolves it is a slow, state-dependent torque that absorbs part of any effect,
//! and on two-effect records it led the ranking by tens of nats with no resonance to be seen
//! (torque constant with quadratic drag: a "coupling" at 0.9 Hz; a voltage drop with a load
//! step: one the backward step later dropped). A resonance is what the term is; a record that
//! shows none gives no evidence for it that a generic alternative would not take.

use crate::motor::Term;
use crate::parameter::ParamId;

use super::super::candidate::Starts;
use super::super::settings::EVIDENCE_THRESHOLD;
use super::{AsGiven, Fingerprint};

/// The dynamic terms the starts are for.
pub const DYNAMIC: [&str; 3] = ["input_delay", "sensor_lag", "compliant_coupling"];

/// Starts for the dynamic terms among `candidates`, estimated on the model as given's residual
/// (first record); empty when there are none to start.
pub fn dynamic_starts(as_given: &AsGiven, candidates: &[String]) -> Starts {
    let mut starts = Starts::default();
    if !candidates.iter().any(|c| DYNAMIC.contains(&c.as_str())) {
        return starts;
    }
    let Some(found) = as_given.scores(0.0).map(|s| s.fingerprints) else {
        return starts;
    };
    let best = |kind: &dyn Fn(&Fingerprint) -> bool| {
        found
            .iter()
            .map(|e| &e.fingerprint)
            .filter(|f| kind(f))
            .max_by(|a, b| a.score().total_cmp(&b.score()))
            .cloned()
    };
    let key = |term: &str, p: &str| ParamId::of_term(term, p).to_string();
    if let Some(Fingerprint::Delay { seconds, .. }) =
        best(&|f| matches!(f, Fingerprint::Delay { .. }))
    {
        starts.values.insert(key("input_delay", "tau"), seconds);
    }
    if let Some(Fingerprint::Lag {
        channel, seconds, ..
    }) = best(&|f| matches!(f, Fingerprint::Lag { .. }))
        && let Some(index) = ["I", "omega"].iter().position(|c| *c == channel)
        && let Some(Ok(term)) = Term::from_name("sensor_lag", &[index as f64])
    {
        starts.values.insert(key("sensor_lag", "tau"), seconds);
        starts.terms.push(term);
    }
    if let Some(Fingerprint::Oscillation {
        frequency_hz,
        damping_ratio,
        grid_points,
        ..
    }) = best(&|f| match f {
        Fingerprint::Oscillation {
            ringing: true,
            frequency_hz,
            ..
        } => *frequency_hz >= as_given.lowest_frequency(),
        _ => false,
    }) {
        starts
            .values
            .insert(key("compliant_coupling", "f_r"), frequency_hz);
        starts.values.insert(
            key("compliant_coupling", "zeta"),
            damping_ratio.unwrap_or(0.1).clamp(1e-3, 1.0),
        );
        starts.search_penalty.insert(
            "compliant_coupling".into(),
            (grid_points.max(1) as f64).ln(),
        );
    }
    starts
}

/// The candidates to rank: `candidates` less the compliant coupling where the model as given's
/// residual does not ring by more than the threshold (see the module's note), unless the user
/// named it (`asked`). Returns the note saying so where it was left out.
pub fn offered(
    candidates: Vec<String>,
    asked: bool,
    as_given: &AsGiven,
) -> (Vec<String>, Option<String>) {
    const COUPLING: &str = "compliant_coupling";
    if asked || !candidates.iter().any(|c| c == COUPLING) {
        return (candidates, None);
    }
    let evidence = as_given.ringing_evidence().unwrap_or(f64::NEG_INFINITY);
    if evidence > EVIDENCE_THRESHOLD {
        return (candidates, None);
    }
    let shown = if evidence.is_finite() {
        format!("{evidence:.1} nats")
    } else {
        "none".to_string()
    };
    let note = format!(
        "{COUPLING} was not ranked: the residual of the model as given does not ring after the \
         input's steps, two periods or more over the record (evidence {shown}, threshold \
         {EVIDENCE_THRESHOLD} nats), and a coupling \
         without a resonance to show is a slow torque any effect can hide in; name it with \
         --candidates to rank it anyway"
    );
    (
        candidates.into_iter().filter(|c| c != COUPLING).collect(),
        Some(note),
    )
}
