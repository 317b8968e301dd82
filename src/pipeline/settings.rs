//! What a run is asked to do: which sampler, how its warm-up tunes the metric, how many chains
//! of what length from which seed, and the defaults the commands share.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize};

use serde::{Deserialize, Serialize};

use crate::error::Error;
use crate::sampler::ChainSettings;

/// The samplers a user can pick.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SamplerKind {
    /// The paper's Metropolis: one random-walk step per variable in turn, tuned as PyMC3 did.
    Metropolis,
    /// Adaptive Metropolis (Haario et al. 2001): joint proposal from the warm-up covariance.
    AdaptiveMetropolis,
    /// Preconditioned MALA; the preconditioner starts at the inverse MAP Hessian.
    Mala,
    /// Static HMC, diagonal metric: the Laplace variances (or Stan's windows).
    HmcDiag,
    /// Static HMC, dense metric: the inverse MAP Hessian (or Stan's windows from it).
    HmcDense,
    /// NUTS, diagonal metric: the Laplace variances (or Stan's windows).
    NutsDiag,
    /// NUTS, dense metric: the inverse MAP Hessian (or Stan's windows from it).
    NutsDense,
    /// Simplified manifold MALA with the Gauss–Newton (Fisher) metric.
    FisherMala,
    /// Independence Metropolis–Hastings from a Student-t at the MAP with the Laplace
    /// covariance; no gradients. Falls back to NUTS when k̂ of its warm-up's proposals > 0.5.
    Independence,
    /// Importance sampling from the same Student-t, Pareto-smoothed, resampled to equal
    /// weights; falls back to NUTS when k̂ > 0.7.
    LaplaceIs,
    /// Importance sampling with θ from the Student-t's marginal and the noise scales and
    /// discrepancy coefficients from their conditionals given θ; NUTS when k̂ > 0.7.
    CollapsedIs,
}

impl SamplerKind {
    pub fn name(&self) -> &'static str {
        match self {
            SamplerKind::Metropolis => "metropolis",
            SamplerKind::AdaptiveMetropolis => "adaptive-metropolis",
            SamplerKind::Mala => "mala",
            SamplerKind::HmcDiag => "hmc-diag",
            SamplerKind::HmcDense => "hmc-dense",
            SamplerKind::NutsDiag => "nuts-diag",
            SamplerKind::NutsDense => "nuts-dense",
            SamplerKind::FisherMala => "fisher-mala",
            SamplerKind::Independence => "independence",
            SamplerKind::LaplaceIs => "laplace-is",
            SamplerKind::CollapsedIs => "collapsed-is",
        }
    }

    pub fn uses_gradient(&self) -> bool {
        !matches!(
            self,
            SamplerKind::Metropolis
                | SamplerKind::AdaptiveMetropolis
                | SamplerKind::Independence
                | SamplerKind::LaplaceIs
                | SamplerKind::CollapsedIs
        )
    }

    /// HMC and NUTS, whose metric [`MetricAdaptation`] tunes.
    pub fn is_hamiltonian(&self) -> bool {
        matches!(
            self,
            SamplerKind::HmcDiag
                | SamplerKind::HmcDense
                | SamplerKind::NutsDiag
                | SamplerKind::NutsDense
        )
    }

    pub const ALL: [SamplerKind; 11] = [
        SamplerKind::Metropolis,
        SamplerKind::AdaptiveMetropolis,
        SamplerKind::Mala,
        SamplerKind::HmcDiag,
        SamplerKind::HmcDense,
        SamplerKind::NutsDiag,
        SamplerKind::NutsDense,
        SamplerKind::FisherMala,
        SamplerKind::Independence,
        SamplerKind::LaplaceIs,
        SamplerKind::CollapsedIs,
    ];
}

/// A sampler by its [`SamplerKind::name`].
impl std::str::FromStr for SamplerKind {
    type Err = Error;

    fn from_str(text: &str) -> Result<Self, Error> {
        crate::error::parse_name("sampler", text, &Self::ALL, Self::name)
    }
}

/// How HMC and NUTS tune their metric in warm-up. Both start from the Laplace covariance (the
/// inverse MAP Hessian, or its diagonal).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MetricAdaptation {
    /// Keep the Laplace covariance; warm-up tunes the step size alone. The calibration
    /// posteriors are close to Gaussian in the unconstrained coordinates, so the Hessian is a
    /// better metric than any estimate from a few hundred correlated draws (papers/john2018,
    /// "The warm-up"), and warm-up shrinks to what dual averaging needs.
    #[default]
    Laplace,
    /// Stan's windows: re-estimate the metric from the chain's own warm-up draws, shrunk toward
    /// the one in use. For posteriors far from Gaussian; it needs a long warm-up (≥ 1000).
    Windows,
}

/// Warm-up per chain when none is given. HMC and NUTS on the Laplace metric only tune a step
/// size: on the paper's data every length from 10 to 300 kept R-hat ≤ 1.01 and bulk ESS
/// ≥ 2000 at every K = 0…20, but at 10 the unsettled step size left 31 divergent transitions
/// in the 21 runs, from 20 on 1–3 (papers/john2018, "The warm-up"). 100 leaves dual averaging
/// (t₀ = 10) ten times its damping span to settle, for posteriors less Gaussian than the
/// paper's, at a tenth of 1000 draws. Everything else keeps Stan's 1000: the windows need it
/// to estimate a metric, and MALA's step-size search is noisier. The independence sampler
/// tries each of its proposal shapes for 40 transitions; importance sampling spends a quarter of
/// its default 1000 draws per chain recentring its proposal (`sampler::importance`; on BM2
/// only, see `pipeline::importance`), and those draws are weighed into the result, not
/// discarded.
pub fn default_warmup(sampler: SamplerKind, metric: MetricAdaptation) -> usize {
    match sampler {
        SamplerKind::Independence => crate::sampler::independence::INDEPENDENCE_WARMUP,
        SamplerKind::LaplaceIs | SamplerKind::CollapsedIs => crate::sampler::importance::IS_WARMUP,
        _ if sampler.is_hamiltonian() && metric == MetricAdaptation::Laplace => LAPLACE_WARMUP,
        _ => 1000,
    }
}

/// See [`default_warmup`].
pub const LAPLACE_WARMUP: usize = 100;

/// The mean acceptance statistic dual averaging aims at on the Laplace metric, above Stan's
/// 0.8. The whitened target is nearly isotropic, so the step size lands near the leapfrog's
/// stability limit; where the posterior's curvature grows away from the MAP (R traded against
/// δ at large K) 0.8 left 3–22 divergent transitions in 4000 at K = 19 on four chain seeds,
/// where Stan's windows, which settle on smaller steps, left 0–3. Raising the target is
/// Stan's own remedy for divergences: 0.85 left at most one per K from 17 to 20, at 13–47%
/// more gradients at K = 19 (papers/john2018, "The warm-up").
pub const LAPLACE_TARGET_ACCEPT: f64 = 0.85;

impl MetricAdaptation {
    pub fn name(&self) -> &'static str {
        match self {
            MetricAdaptation::Laplace => "laplace",
            MetricAdaptation::Windows => "windows",
        }
    }

    pub const ALL: [MetricAdaptation; 2] = [MetricAdaptation::Laplace, MetricAdaptation::Windows];
}

/// A metric adaptation by its [`MetricAdaptation::name`].
impl std::str::FromStr for MetricAdaptation {
    type Err = Error;

    fn from_str(text: &str) -> Result<Self, Error> {
        crate::error::parse_name("metric_adaptation", text, &Self::ALL, Self::name)
    }
}

/// How to run a sampler.
#[derive(Clone, Debug, Serialize)]
pub struct RunSettings {
    pub sampler: SamplerKind,
    pub chains: usize,
    pub chain: ChainSettings,
    pub seed: u64,
    /// Worker threads (all cores when `None`); the draws do not depend on it.
    pub threads: Option<usize>,
    /// Initial points are the MAP plus draws from the Laplace approximation with its standard
    /// deviations inflated by this factor, so that R-hat can detect chains that do not mix.
    pub init_dispersion: f64,
    pub quiet: bool,
    /// HMC/NUTS: write the adapted step size and metric (of chain 1) here.
    pub save_adaptation: Option<PathBuf>,
    /// HMC/NUTS: start every chain from this adaptation and skip adapting.
    pub load_adaptation: Option<PathBuf>,
    /// HMC/NUTS: how warm-up tunes the metric.
    pub metric_adaptation: MetricAdaptation,
    /// Set from outside (a user's interrupt) to end the chains between transitions with the
    /// fatal error [`crate::sampler::STOPPED`]; `None` runs to the end.
    #[serde(skip)]
    pub stop: Option<Arc<AtomicBool>>,
    /// Keep every warm-up draw in the chains' output too (the draws are the same either way).
    #[serde(skip)]
    pub save_warmup: bool,
    /// Counts every chain's transitions for a caller's progress display; changes no draw.
    #[serde(skip)]
    pub transitions: Option<Arc<AtomicUsize>>,
    /// laplace-is, independence: run NUTS (dense) on the same problem instead when k̂ says the
    /// Laplace approximation cannot be trusted.
    pub fallback: bool,
    /// laplace-is, independence: the k̂ above which they fall back (0.7, where PSIS stops being
    /// reliable, by default; a diagnosis's fits ask for min(1 − 1/log₁₀ S, 0.7), the line for
    /// their S proposals; the independence chain never goes above 0.5, where its mean stay at
    /// a point becomes infinite).
    pub fallback_above: f64,
    /// laplace-is: where the first proposal's k̂ falls back, importance sampling is tried once
    /// more, from a wider Student-t with heavier tails ([`super::importance::DEFENSIVE_SHAPE`]),
    /// before NUTS; its own k̂ judges it by the same line.
    pub defensive_proposal: bool,
    /// laplace-is: the gradients per transition that its NUTS fallback may spend on average,
    /// per chain (warm-up and draws), each at the cost of a gradient at the MAP in the
    /// integrator's work ([`crate::density::Counted::work`]); a chain past it ends the
    /// fallback, and the importance sample with the lower k̂ stands, its record saying so
    /// ([`super::RunOutput::fallback_stopped`]). `None` lets the fallback run to its end.
    pub fallback_budget: Option<u64>,
    /// The work each chain may spend in all, warm-up and sampling
    /// ([`crate::sampler::RunControl::work_budget`]); a chain past it ends the run with
    /// [`crate::sampler::BUDGET_SPENT`]. `None`: no limit.
    pub work_budget: Option<u64>,
    /// The MAP search the run starts from.
    #[serde(skip)]
    pub map_search: MapSearch,
}

/// Which MAP search a run starts from (`optimize::MapSettings`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MapSearch {
    /// To a whitened gradient of 10⁻⁷: the pinned draws of the paper's tables start from it.
    #[default]
    Precise,
    /// A diagnosis's: to 10⁻², then Newton steps to the log density's rounding. Its fits start
    /// at a candidate's MAP already, and on a law in the angle the solver's rounding leaves
    /// the gradient above 10⁻⁷ for good: the precise search ran its L-BFGS 1 097 iterations,
    /// 92.6 s, on load_ripple-570009's fit after the law, where this one stops at the same
    /// mode to the rounding of its Newton steps.
    Ranking,
}

impl MapSearch {
    pub fn settings(self) -> crate::optimize::MapSettings {
        match self {
            MapSearch::Precise => crate::optimize::MapSettings::default(),
            MapSearch::Ranking => crate::optimize::MapSettings::ranking(),
        }
    }
}

impl Default for RunSettings {
    fn default() -> Self {
        Self {
            sampler: SamplerKind::AdaptiveMetropolis,
            chains: 4,
            chain: ChainSettings::default(),
            seed: crate::synthetic::DEFAULT_SEED,
            threads: None,
            init_dispersion: 3.0,
            quiet: false,
            save_adaptation: None,
            load_adaptation: None,
            metric_adaptation: MetricAdaptation::default(),
            stop: None,
            save_warmup: false,
            transitions: None,
            fallback: true,
            fallback_above: crate::diagnostics::KHAT_UNRELIABLE,
            defensive_proposal: false,
            fallback_budget: None,
            work_budget: None,
            map_search: MapSearch::Precise,
        }
    }
}

impl RunSettings {
    pub fn validate(&self) -> Result<(), Error> {
        if self.chains == 0 {
            return Err(Error::setting("chains", 0, "need at least one chain"));
        }
        if self.threads == Some(0) {
            return Err(Error::setting("threads", 0, "need at least one thread"));
        }
        if let Some(budget) = self.fallback_budget {
            let why = if budget == 0 {
                Some("a fallback needs at least one gradient per transition")
            } else if !matches!(
                self.sampler,
                SamplerKind::LaplaceIs | SamplerKind::CollapsedIs
            ) {
                Some("only laplace-is and collapsed-is fall back within a budget")
            } else if !self.fallback {
                Some("the fallback is off")
            } else {
                None
            };
            if let Some(why) = why {
                return Err(Error::setting("fallback_budget", budget, why));
            }
        }
        self.chain.validate().map_err(|e| {
            Error::Settings(crate::error::SettingError {
                name: "keep/draws".into(),
                value: None,
                message: e.to_string(),
            })
        })?;
        Ok(())
    }
}
