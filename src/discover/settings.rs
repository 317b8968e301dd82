//! What a diagnosis is asked and the rules it keeps: the evidence threshold (see the module
//! doc of `discover`), how many terms at most, which fits are sampled and how.

use crate::error::Error;
use crate::motor::Term;
use crate::pipeline::RunSettings;
use crate::study::Problem;

/// A term is kept when it raises the score by more than this many nats (see the module's doc).
pub const EVIDENCE_THRESHOLD: f64 = 2.0;

/// At most this many terms are added: more than three missing effects at once on one short
/// recording is a model to rewrite, not to patch.
pub const MAX_TERMS: usize = 3;

/// The fewest samples a recording needs: BM2 at the default degree has 2·(K+1) coefficients and
/// the physics a few more per channel.
pub const MIN_SAMPLES: usize = 50;

/// How diagnose's sampled fits tune the NUTS metric unless told otherwise: candidate terms have
/// one-sided supports, where the Laplace approximation can be poor, so Stan's windows refine it.
pub const METRIC_ADAPTATION: crate::pipeline::MetricAdaptation =
    crate::pipeline::MetricAdaptation::Windows;

/// The discrepancy degree of the locating fit when none is given: the paper's choice for its
/// 501-sample records (§4.2).
pub const DEFAULT_K: usize = 9;

/// Records longer than this (samples summed over records) are fitted by the Laplace
/// approximation instead of NUTS: at 20 000–25 000 samples one gradient costs milliseconds, a
/// NUTS fit minutes per stage, and with that many samples the posterior of a handful of
/// parameters is Gaussian to well within its own width (Bernstein–von Mises).
pub const LAPLACE_ABOVE_SAMPLES: usize = 5000;

/// Draws taken from the Laplace approximation: enough for stable 95% intervals.
pub const LAPLACE_DRAWS: usize = 1000;

/// Whether `problem` is fitted by the Laplace approximation (see [`LAPLACE_ABOVE_SAMPLES`]).
pub fn uses_laplace(problem: &Problem) -> bool {
    problem
        .recordings
        .iter()
        .map(|r| r.n_samples())
        .sum::<usize>()
        > LAPLACE_ABOVE_SAMPLES
}

/// Smoothing window of the measured speed and input before differentiating [s]: 20 ms, short
/// against the mechanical time constants (0.5 s on EMPS, 1.7 s on HSM150) and long against
/// 1-ms sampling, whose quantised speed would otherwise make ω̇ pure noise.
pub const SMOOTHING_S: f64 = 0.02;

/// What [`super::discover`] is asked.
#[derive(Clone, Debug)]
pub struct DiscoverSettings {
    /// The discrepancy degree of the locating BM2 fits ([`DEFAULT_K`] when `None`).
    pub k: Option<usize>,
    /// Term names to consider; `None`: every term the model lacks that applies to its base.
    pub candidates: Option<Vec<String>>,
    /// The sampled fits' chains, seed and sampler (NUTS with [`METRIC_ADAPTATION`] by default).
    pub run: RunSettings,
    /// Stop after the ranking, the selection and the ties: no sampled fits.
    pub rank_only: bool,
    /// What `study::plausibility::check` found on the recordings, when the caller goes on
    /// regardless: no physics is then selected on top of a fit that cannot be this motor.
    pub implausible: Vec<crate::study::plausibility::Finding>,
}

impl Default for DiscoverSettings {
    fn default() -> Self {
        Self {
            k: None,
            candidates: None,
            run: RunSettings {
                sampler: crate::pipeline::SamplerKind::NutsDense,
                chain: crate::sampler::ChainSettings {
                    warmup: 500,
                    draws: 500,
                    keep: None,
                },
                metric_adaptation: METRIC_ADAPTATION,
                ..RunSettings::default()
            },
            rank_only: false,
            implausible: Vec::new(),
        }
    }
}

/// The four sampled fits of a diagnosis, in the order they run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum FitStage {
    /// BM1 of the model as given.
    Before,
    /// BM1 with the selected terms.
    After,
    /// BM2(K) of the model as given: where δ's band excludes zero.
    BeforeBm2,
    /// BM2(K) with the selected terms held at their estimates: what is still left.
    AfterBm2,
}

impl FitStage {
    pub const ALL: [FitStage; 4] = [
        FitStage::Before,
        FitStage::After,
        FitStage::BeforeBm2,
        FitStage::AfterBm2,
    ];

    /// The key in the report's `convergence` and in file names.
    pub fn name(&self) -> &'static str {
        match self {
            FitStage::Before => "before",
            FitStage::After => "after",
            FitStage::BeforeBm2 => "before_bm2",
            FitStage::AfterBm2 => "after_bm2",
        }
    }

    /// With the selected terms.
    pub fn is_after(&self) -> bool {
        matches!(self, FitStage::After | FitStage::AfterBm2)
    }

    /// BM2: δ's band in time.
    pub fn is_bm2(&self) -> bool {
        matches!(self, FitStage::BeforeBm2 | FitStage::AfterBm2)
    }
}

/// The candidates to rank: the given names (checked) or every term the model lacks.
pub fn candidate_names(problem: &Problem, given: Option<&[String]>) -> Result<Vec<String>, Error> {
    let present = |name: &str| problem.model.terms.iter().any(|t| t.term.name() == name);
    let base = problem.model.base;
    let several = problem.recordings.len() > 1;
    let applies = |name: &str| {
        Term::named(name).is_some_and(|t| base.accepts(&t) && !(several && t.record_time()))
    };
    match given {
        Some(names) => {
            for n in names {
                if !Term::NAMES.contains(&n.as_str()) {
                    return Err(Error::setting(
                        "candidates",
                        n,
                        format!("unknown effect (known: {})", Term::NAMES.join(", ")),
                    ));
                }
                if present(n) {
                    return Err(Error::setting("candidates", n, "the model already has it"));
                }
                if !applies(n) {
                    let why = if several && Term::named(n).is_some_and(|t| t.record_time()) {
                        "switches at a time within one record, and several records do not \
                         share a clock"
                            .to_string()
                    } else {
                        let term = Term::named(n).expect("a known name");
                        format!(
                            "{}, which a {} model does not have",
                            term.not_on_drives(),
                            base.name()
                        )
                    };
                    return Err(Error::setting("candidates", n, why));
                }
            }
            Ok(names.to_vec())
        }
        None => Ok(Term::NAMES
            .iter()
            .filter(|n| !present(n) && applies(n))
            .map(|n| n.to_string())
            .collect()),
    }
}
