//! `motorcal diagnose`: where the model and the recordings disagree (BM2's discrepancy band),
//! which left-out physics explains it (candidate terms ranked by evidence), whether the
//! recording can tell the leaders apart (ties, and the experiment that would), and the fit with
//! the selected terms against the fit without.
//!
//! **The threshold** ([`EVIDENCE_THRESHOLD`], 2 nats, fixed before the development cases were
//! run): a term is selected, or added in the greedy forward selection, when its score beats the
//! model without it by more than this. Under the null every one-parameter candidate's gain in
//! log likelihood is ½χ²₁; with the ½·ln N penalty at N = 1002 observations, a false alarm
//! among twelve candidates needs χ²₁ > 2·(3.45 + 2) = 10.9 for one of them, probability
//! 12 × 0.1% ≈ 1% (thirteen since `asymmetric_friction` joined: still about 1%). A case that is fair to ask (a BIC margin ≥ 10 over `none`, i.e. a 5-nat
//! score lead) clears it with 3 nats to spare. Kass and Raftery call 2 nats (a Bayes factor of
//! 7.4) positive evidence; the multiplicity of twelve candidates is why it is not 1.

//!
//! The stages, each a file that takes the [`Candidate`] type and imports only the files listed
//! before it: `settings` (the rules and what is asked), `coincide` (a recorded input's steps and
//! a switching time fitted at one), `candidate` (a candidate's problem, posterior, MAP and
//! score), `confirm` (importance sampling of a doubtful leader), `screen` (collinear
//! sensitivities), `ties` (the simulated experiment that separates two candidates), `state`
//! (the missing torque against speed), `selection` (ranking and forward selection), `fits` (the
//! sampled fits, Ljung–Box, δ's band), `diagnosis` (the report as data). Nothing here reads or
//! writes a file or prints: the command (`app::diagnose`) does.
//!
//! ```
//! use motorcal::discover::{DiscoverSettings, discover};
//! use motorcal::study::cases::{CaseOptions, make_case};
//! use motorcal::study::{InputProfile, Problem};
//!
//! // A start-up with Coulomb friction three noise σ strong, simulated in memory.
//! let case = make_case(&CaseOptions {
//!     effects: vec!["coulomb_friction".into()],
//!     magnitude: Some(3.0),
//!     input: InputProfile::Constant,
//!     seed: 2026,
//!     conceal: false,
//!     tied: false,
//! })?;
//! let problem = Problem {
//!     label: "in memory".into(),
//!     recordings: vec![case.recording],
//!     model: case.nominal,
//!     reference: None,
//! };
//! let mut settings = DiscoverSettings { rank_only: true, ..DiscoverSettings::default() };
//! settings.run.quiet = true;
//! let diagnosis = discover(&problem, &settings)?;
//! assert_eq!(diagnosis.selected, "coulomb_friction");
//! # Ok::<(), motorcal::error::Error>(())
//! ```

mod candidate;
mod coincide;
mod confirm;
mod diagnosis;
mod discovered;
mod fits;
mod named;
mod overdamped;
mod prune;
mod screen;
mod selection;
mod settings;
mod shape_search;
mod state;
mod ties;
mod unexplained;

use std::time::Instant;

pub use candidate::{Candidate, Confirmation, answer_params, fit_candidate, fit_candidate_from};
pub use coincide::{InputCoincidence, InputStep, input_steps};
pub use confirm::importance_evidence;
pub use diagnosis::{Diagnosis, PassedOver, RankEntry, StageFit};
pub use discovered::{Discovered, DiscoveredBalance, DiscoveredFunction, discovered};
pub use fits::{FitSummary, Mismatch, SampledFit, Whiteness, ljung_box};
pub use named::{NamedTerm, named_term, named_terms};
pub use selection::{Selection, forward_selection, rank};
pub use settings::{
    DEFAULT_K, DiscoverSettings, EVIDENCE_THRESHOLD, FitStage, LAPLACE_ABOVE_SAMPLES,
    LAPLACE_DRAWS, MAX_TERMS, METRIC_ADAPTATION, MIN_SAMPLES, candidate_names, uses_laplace,
};
pub use state::{StateFingerprint, records_reverse};
pub use ties::TIE_EXPERIMENTS;
pub use unexplained::{FOLDED_BINS, Fingerprint, Folded, Span, Unexplained, UnexplainedFigure};

use crate::bayes::ModelSettings;
use crate::error::Error;
use crate::study::Problem;
use unexplained::{AsGiven, dynamic_starts};

/// The stages of a diagnosis, as [`discover_with`] reports them to its caller.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Progress {
    /// Ranking `n` candidates one at a time.
    Ranking { candidates: usize },
    /// The forward selection.
    Selecting,
    /// Ties, notes and the state fingerprint.
    Reporting,
    /// A sampled fit starts.
    Sampling(FitStage),
}

/// The whole diagnosis of `problem`: where the model and the recordings disagree, which
/// left-out physics explains it, the ties and the experiments that would separate them, and the
/// fit before and after. No file is read or written.
pub fn discover(problem: &Problem, settings: &DiscoverSettings) -> Result<Diagnosis, Error> {
    discover_with(problem, settings, |_| {})
}

/// As [`discover`], telling `progress` each stage as it starts.
pub fn discover_with(
    problem: &Problem,
    settings: &DiscoverSettings,
    progress: impl Fn(Progress),
) -> Result<Diagnosis, Error> {
    let started = Instant::now();
    settings.run.validate()?;
    for r in &problem.recordings {
        if r.n_samples() < MIN_SAMPLES {
            return Err(Error::invalid(format!(
                "{}: {} samples is too short to diagnose (need at least {MIN_SAMPLES})",
                r.source,
                r.n_samples()
            )));
        }
    }
    let k = settings.k.unwrap_or(DEFAULT_K);
    ModelSettings::bm2(k)
        .validate()
        .map_err(|e| Error::setting("k", k, e))?;
    // A recording that cannot be this motor gets no candidate: whatever scored best would be
    // physics named on top of a wrong file.
    let candidates = if settings.implausible.is_empty() {
        candidate_names(problem, settings.candidates.as_deref())?
    } else {
        Vec::new()
    };
    progress(Progress::Ranking {
        candidates: candidates.len(),
    });
    // The model as given and the verdict on its residual come first: they say where the
    // dynamic terms start.
    let none = fit_candidate(problem, &[])?;
    let as_given = AsGiven::of(problem, &none)?;
    let starts = dynamic_starts(problem, &as_given, &candidates);
    let (ranking, not_ranked) = rank(problem, none, &candidates, &starts)?;
    let ranking_s = started.elapsed().as_secs_f64();
    progress(Progress::Selecting);
    let selection = forward_selection(problem, &ranking, &candidates, &starts)?;
    let selection_s = started.elapsed().as_secs_f64();
    progress(Progress::Reporting);
    diagnosis::assemble(
        problem,
        settings,
        k,
        &candidates,
        ranking,
        selection,
        as_given,
        not_ranked,
        started,
        [ranking_s, selection_s],
        &progress,
    )
}
