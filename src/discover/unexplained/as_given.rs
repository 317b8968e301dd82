//! The model as given, scored once per diagnosis: every verdict compares with it. Its laws —
//! its state and drift fingerprints (functions chosen by evidence against the model without
//! terms; a sensitivity solve per law block) — are scored against what the selected terms
//! gained, and fitted through the ODE in place of the selected terms
//! (`named::fit_named_terms`), because a law whose effect is large is underestimated by its
//! first-order gain (its sensitivities are taken at zero coefficients) and could otherwise lose
//! to a library term standing in for it (a supply sagging with the charge taken as three
//! library terms) without ever being fitted. Its fingerprints and generic alternatives (the
//! oscillation search the dearest of them) are the bar after a selection, and the verdict on
//! the model as given itself (`unexplained_as_given`).

use crate::error::Error;
use crate::study::Problem;

use super::super::candidate::Candidate;
use super::super::settings::EVIDENCE_THRESHOLD;
use super::{Context, Evidence, Fingerprint, Scores, Unexplained, oscillation, scores, state};

pub struct AsGiven {
    laws: Vec<Evidence>,
    /// `None` where the verdict is not asked (no recording, or fewer than 20 samples).
    scores: Option<Scores>,
    /// Below this frequency (Hz) an oscillation on the record is a trend.
    lowest_frequency: f64,
    /// Its whitened residual (stacked channel after channel), for the figure of an
    /// alternative found on it.
    residual: Vec<f64>,
}

impl AsGiven {
    /// `none` (the model as given at its MAP), first record.
    pub fn of(problem: &Problem, none: &Candidate) -> Result<Self, Error> {
        let nothing = Self {
            laws: Vec::new(),
            scores: None,
            lowest_frequency: f64::INFINITY,
            residual: Vec::new(),
        };
        if problem.recordings.is_empty() {
            return Ok(nothing);
        }
        let ctx = Context::of(problem, none, 0)?;
        if ctx.n < 20 {
            return Ok(nothing);
        }
        Ok(Self {
            laws: state::fingerprints(none, &ctx, 0.0)?,
            scores: Some(scores(&ctx, 0.0)),
            lowest_frequency: oscillation::lowest_frequency(&ctx),
            residual: ctx.y.as_slice().to_vec(),
        })
    }

    /// Below this frequency (Hz) an oscillation on the record is a trend.
    pub fn lowest_frequency(&self) -> f64 {
        self.lowest_frequency
    }

    /// Its whitened residual, empty where the verdict is not asked.
    pub(super) fn residual(&self) -> &[f64] {
        &self.residual
    }

    /// The laws' fingerprints.
    pub fn fingerprints(&self) -> impl Iterator<Item = &Fingerprint> {
        self.laws.iter().map(|e| &e.fingerprint)
    }

    /// The laws, each scored against a bar raised by `shift` nats.
    pub(super) fn shifted(&self, shift: f64) -> impl Iterator<Item = Evidence> + '_ {
        self.laws.iter().map(move |e| Evidence {
            fingerprint: e.fingerprint.clone().shifted(shift),
            residual: e.residual.clone(),
            explained: e.explained.clone(),
        })
    }

    /// The fingerprints and generic alternatives on the model as given's residual, scored
    /// against a bar raised by `shift` nats.
    pub(super) fn scores(&self, shift: f64) -> Option<Scores> {
        self.scores.clone().map(|s| s.shifted(shift))
    }
}

/// The fingerprint of the model as given, of what it lacks beyond the library.
///
/// The verdict on the model as given leads with what explains most of its residual. Where that
/// is a state or drift law and a single library term, fitted through the ODE on the same
/// record, scores as much (within the threshold), the law is the library's term by another
/// name: a supply dipping periodically loses on average a share of its voltage, which a law
/// in ω and the term speed_gain hold alike, and the dips' frequency, which no term holds, is
/// hidden behind the law. Where the verdict after the library's selection (`after`, before any
/// law is taken) then leads with a kind no law is — an oscillation, a delay, a lag — that
/// leads here, its figure with it, and the law heads the alternatives: what the model lacks
/// beyond the library. The evidence stays the model as given's.
/// Two exceptions, each for a reason: a law after the selection names nothing the law as given
/// did not; and a law's score here is its first-order gain, which understates a large effect
/// (its sensitivities are taken at zero coefficients), so where the law fitted through the ODE
/// alone was selected (`law_alone`, its score over the model as given) and beats the library's
/// best term by more than the threshold, the law is beyond the library and keeps its lead.
/// Nothing else changes: the law is still offered to the fits (`AsGiven::fingerprints`), and
/// the verdict after the selection is the report's own. `library_best` is the best single
/// library term and its score over the model as given (nats).
pub fn beyond_the_library(
    as_given: Option<Unexplained>,
    after: Option<&Unexplained>,
    library_best: Option<(&str, f64)>,
    law_alone: Option<f64>,
) -> Option<Unexplained> {
    let mut verdict = as_given?;
    let is_law =
        |f: &Fingerprint| matches!(f, Fingerprint::State { .. } | Fingerprint::Drift { .. });
    let named = |f: &Fingerprint| {
        matches!(
            f,
            Fingerprint::Oscillation { .. } | Fingerprint::Delay { .. } | Fingerprint::Lag { .. }
        )
    };
    let (Some((term, best)), Some(after)) = (library_best, after) else {
        return Some(verdict);
    };
    let held = best >= verdict.fingerprint.score() - EVIDENCE_THRESHOLD
        && law_alone.is_none_or(|law| law <= best + EVIDENCE_THRESHOLD);
    if !is_law(&verdict.fingerprint) || !named(&after.fingerprint) || !held {
        return Some(verdict);
    }
    let law = std::mem::replace(&mut verdict.fingerprint, after.fingerprint.clone());
    verdict
        .alternatives
        .retain(|f| f.identity() != verdict.fingerprint.identity());
    verdict.alternatives.insert(0, law.clone());
    verdict.suggestion = format!(
        "{}; on the model as given a law leads ({:+.1} nats), but the library's {term} holds as \
         much ({best:+.1}): named here is what is left beyond the library",
        after.suggestion,
        law.score()
    );
    verdict.figure = after.figure.clone();
    Some(verdict)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::discover::unexplained::{LawFunction, UnexplainedFigure};

    fn verdict(fingerprint: Fingerprint) -> Unexplained {
        Unexplained {
            evidence: fingerprint.score(),
            channels: vec!["I".into(), "omega".into()],
            spans: Vec::new(),
            fingerprint: fingerprint.clone(),
            alternatives: Vec::new(),
            considered: vec![fingerprint],
            suggestion: String::new(),
            figure: UnexplainedFigure::default(),
        }
    }

    fn law(score: f64) -> Fingerprint {
        let f = LawFunction {
            name: "omega*|omega|".into(),
            coefficient: -1.2e-6,
            sd: 1e-7,
        };
        Fingerprint::plain_state("measurement:omega", vec![f], score)
    }

    fn dips(score: f64) -> Fingerprint {
        Fingerprint::Oscillation {
            frequency_hz: 28.5,
            frequency_sd: 0.1,
            damping_ratio: None,
            channel: "I".into(),
            ringing: false,
            sensor: false,
            score,
            frequencies: 100,
        }
    }

    #[test]
    fn a_law_a_library_term_holds_as_well_gives_the_lead_to_what_is_left_after_the_selection() {
        let after = verdict(dips(23.3));
        let given = beyond_the_library(
            Some(verdict(law(62.3))),
            Some(&after),
            Some(("speed_gain", 61.0)),
            None,
        )
        .expect("a verdict");
        assert_eq!(given.fingerprint.identity(), "oscillation/I/false/false");
        assert_eq!(given.alternatives[0].identity(), "state/measurement:omega");
        assert_eq!(
            given.evidence, 62.3,
            "the evidence is still the model as given's"
        );
        assert!(
            given.suggestion.contains("speed_gain"),
            "{}",
            given.suggestion
        );
    }

    #[test]
    fn a_law_no_library_term_holds_keeps_the_lead() {
        // The best term short of the law by more than the threshold: the law is beyond it.
        let after = verdict(dips(23.3));
        let given = beyond_the_library(
            Some(verdict(law(62.3))),
            Some(&after),
            Some(("speed_gain", 62.3 - EVIDENCE_THRESHOLD - 0.1)),
            None,
        )
        .expect("a verdict");
        assert_eq!(given.fingerprint.identity(), "state/measurement:omega");
        assert!(given.alternatives.is_empty());
    }

    #[test]
    fn with_nothing_left_after_the_selection_the_law_keeps_the_lead() {
        let given = beyond_the_library(
            Some(verdict(law(62.3))),
            None,
            Some(("speed_gain", 75.0)),
            None,
        )
        .expect("a verdict");
        assert_eq!(given.fingerprint.identity(), "state/measurement:omega");
    }

    #[test]
    fn a_law_fitted_through_the_ode_beyond_the_library_keeps_the_lead() {
        // Its first-order score within the threshold of the term's, its fit well above it.
        let after = verdict(dips(23.3));
        let given = beyond_the_library(
            Some(verdict(law(62.3))),
            Some(&after),
            Some(("sensor_lag", 63.0)),
            Some(63.0 + EVIDENCE_THRESHOLD + 0.1),
        )
        .expect("a verdict");
        assert_eq!(given.fingerprint.identity(), "state/measurement:omega");
    }

    #[test]
    fn only_a_law_gives_up_its_lead_and_only_to_a_kind_no_law_is() {
        let best = Some(("speed_gain", 75.0));
        let given = beyond_the_library(
            Some(verdict(dips(30.0))),
            Some(&verdict(law(10.0))),
            best,
            None,
        )
        .expect("a verdict");
        assert_eq!(given.fingerprint.identity(), "oscillation/I/false/false");
        let mut other = law(10.0);
        if let Fingerprint::State { balance, .. } = &mut other {
            *balance = "torque".into();
        }
        let given = beyond_the_library(Some(verdict(law(62.3))), Some(&verdict(other)), best, None)
            .expect("a verdict");
        assert_eq!(given.fingerprint.identity(), "state/measurement:omega");
        assert!(beyond_the_library(None, Some(&verdict(dips(30.0))), best, None).is_none());
    }
}
