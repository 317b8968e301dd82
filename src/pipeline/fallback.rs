//! NUTS in place of a sampler that draws from the Laplace approximation, when the Pareto k̂ of
//! its importance weights says the approximation cannot be trusted: laplace-is's and the
//! independence sampler's one way out, so that both fall back alike and record it alike.

use std::time::Instant;

use crate::density::{Counted, LogDensity};
use crate::diagnostics::KHAT_UNRELIABLE;
use crate::sampler::BUDGET_SPENT;

use super::{Error, Fittable, MetricAdaptation, PhaseCost, RunOutput, RunSettings, SamplerKind};

/// Whether a run whose proposals gave `khat` falls back: k̂ above `settings.fallback_above` or
/// above the sampler's own `ceiling` (the lower of the two), or none could be fitted (NaN),
/// unless `settings.fallback` is off.
pub(super) fn falls_back(khat: f64, settings: &RunSettings, ceiling: f64) -> bool {
    settings.fallback && !(khat <= settings.fallback_above.min(ceiling))
}

/// NUTS with a dense metric on `posterior` from the settings' chains, draws and seed: on the
/// Laplace metric first (its short warm-up, step size tuned only), and where k̂ > 0.7 and that
/// run fails its own diagnostics ([`converged_alone`]), again with the metric tuned in Stan's
/// windows. Its record keeps `khat`, says `fell_back`, adds `map` (the Laplace sampler's MAP)
/// to its own, and counts `spent` (all the Laplace sampler drew, and a Laplace-metric run
/// refused) in its warm-up.
///
/// With `settings.fallback_budget` and a `refused` sample to return to, each chain may spend
/// that many gradients per transition on average, each at the integrator's work of a gradient
/// at the `mode`; where one spends more in the last run, the fallback ends and `refused`
/// stands, marked [`RunOutput::fallback_stopped`] (a Laplace-metric run past its budget hands
/// over to the windows' run instead).
#[allow(clippy::too_many_arguments)]
pub(super) fn nuts_instead<P: Fittable>(
    posterior: &P,
    settings: &RunSettings,
    label: &str,
    khat: f64,
    map: PhaseCost,
    spent: PhaseCost,
    started: Instant,
    refused: Option<(RunOutput, &[f64])>,
) -> Result<RunOutput, Error> {
    // Between a stricter line and 0.7 (the independence chain falls back above 0.5,
    // diagnose's fits above min(1 − 1/log₁₀ S, 0.7)) the approximation was refused for
    // weighing draws, whose error converges slowly there, not as a shape: NUTS keeps it as its
    // metric. Above 0.7 it may be no metric to trust either (a banana's arms), but k̂ alone
    // cannot tell that from a Gaussian shape a little too narrow in one direction, which
    // thins importance weights in some twenty dimensions past use and costs NUTS nothing but
    // a few leapfrog steps (the BM2 fit after a cogging law: R's posterior wider than the
    // Laplace approximation's, k̂ 0.96, and on the Laplace metric NUTS passes its own
    // diagnostics in about a third of the windows' time; papers/beyond-library.md, session
    // 12). So the Laplace metric is tried first everywhere, and the run's own R-hat, ESS and
    // divergences decide whether Stan's windows, with their 1000-transition warm-up, are
    // needed.
    let metrics: &[MetricAdaptation] = if khat <= KHAT_UNRELIABLE {
        &[MetricAdaptation::Laplace]
    } else {
        &[MetricAdaptation::Laplace, MetricAdaptation::Windows]
    };
    let (refused, mode) = refused.unzip();
    let gradient_work = match (settings.fallback_budget, mode) {
        (Some(_), Some(mode)) => Some(gradient_work(posterior, mode)?),
        _ => None,
    };
    let mut spent = spent;
    for (i, &metric_adaptation) in metrics.iter().enumerate() {
        let last = i + 1 == metrics.len();
        let warmup = super::default_warmup(SamplerKind::NutsDense, metric_adaptation);
        let transitions = (warmup + settings.chain.draws) as u64;
        let nuts = RunSettings {
            sampler: SamplerKind::NutsDense,
            chain: crate::sampler::ChainSettings {
                warmup,
                ..settings.chain.clone()
            },
            metric_adaptation,
            work_budget: settings
                .fallback_budget
                .zip(gradient_work)
                .map(|(per_transition, work)| per_transition * transitions * work),
            // NUTS itself does not fall back.
            fallback_budget: None,
            ..settings.clone()
        };
        let mut posterior = posterior.clone();
        let fallback = match super::run_sampler(&mut posterior, &nuts, &format!("{label} fallback"))
        {
            Ok(run) => run,
            Err(Error::Numerical(message)) if message == BUDGET_SPENT && !last => continue,
            Err(Error::Numerical(message)) if message == BUDGET_SPENT => {
                let refused = refused.expect("a budget is set only with a sample to return to");
                return Ok(RunOutput {
                    fallback_stopped: true,
                    wall_seconds: started.elapsed().as_secs_f64(),
                    ..refused
                });
            }
            Err(e) => return Err(e),
        };
        if !last && !converged_alone(&fallback, settings.chains) {
            spent = spent + fallback.warmup + fallback.sampling;
            continue;
        }
        return Ok(RunOutput {
            khat: Some(khat),
            fell_back: true,
            map: map + fallback.map,
            warmup: spent + fallback.warmup,
            wall_seconds: started.elapsed().as_secs_f64(),
            ..fallback
        });
    }
    unreachable!("the last metric's run returns")
}

/// R-hat at most this, as Vehtari et al. (2021) recommend.
const RHAT_CONVERGED: f64 = 1.01;

/// Bulk ESS per chain at least this (Vehtari et al. 2021: 100 per chain, so that R-hat and the
/// ESS themselves are reliable).
const ESS_PER_CHAIN: f64 = 100.0;

/// Whether a NUTS run stands on its own diagnostics: R-hat and bulk ESS as recommended, and no
/// divergent transition (where a divergence shows, the step size did not fit the curvature
/// somewhere, and Stan's remedy is the adaptation the windows give).
fn converged_alone(run: &RunOutput, chains: usize) -> bool {
    run.max_rhat <= RHAT_CONVERGED
        && run.min_ess_bulk >= ESS_PER_CHAIN * chains as f64
        && run.divergences == 0
}

/// The integrator's work of one gradient of `posterior` at `x` ([`Counted::work`]). A clone
/// keeps its original's cached solves, which may hold `x`: the probe goes one representable
/// number above it in every coordinate, where the solve takes the same steps and no cache
/// serves it.
fn gradient_work<P: Fittable>(posterior: &P, x: &[f64]) -> Result<u64, Error> {
    let mut probe = Counted::new(posterior.clone());
    let beside: Vec<f64> = x.iter().map(|v| v.next_up()).collect();
    let mut gradient = vec![0.0; x.len()];
    probe.log_density_and_gradient(&beside, &mut gradient)?;
    Ok(probe.work())
}
