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
/// then hidden behind the law. What the model lacks beyond the library is what is left after
/// the library's selection: that verdict's leader, where it has one, leads here, and the law
/// heads the alternatives. Nothing else changes: the law is still offered to the fits
/// (`AsGiven::fingerprints`), and the verdict after the selection is the report's own.
/// `library_best` is the best single library term's score over the model as given (nats);
/// `after` the verdict after the selection, before any law is taken.
pub fn beyond_the_library(
    as_given: Option<Unexplained>,
    after: Option<&Unexplained>,
    library_best: Option<(&str, f64)>,
) -> Option<Unexplained> {
    let mut verdict = as_given?;
    let law = matches!(
        verdict.fingerprint,
        Fingerprint::State { .. } | Fingerprint::Drift { .. }
    );
    let (Some((term, best)), Some(after)) = (library_best, after) else {
        return Some(verdict);
    };
    if !law || best < verdict.fingerprint.score() - EVIDENCE_THRESHOLD {
        return Some(verdict);
    }
    let law = std::mem::replace(&mut verdict.fingerprint, after.fingerprint.clone());
    verdict
        .alternatives
        .retain(|f| f.identity() != verdict.fingerprint.identity());
    verdict.alternatives.insert(0, law.clone());
    verdict.suggestion = format!(
        "{}; on the model as given a law leads ({:+.1} nats), which the library's {term} holds \
         as well ({best:+.1}): what is left beyond the library is named",
        after.suggestion,
        law.score()
    );
    verdict.figure = after.figure.clone();
    Some(verdict)
}
