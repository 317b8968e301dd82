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

/// NUTS with a dense metric on `posterior` (tuned in Stan's windows where k̂ > 0.7, the Laplace one below), from the settings' chains,
/// draws and seed. Its record keeps `khat`, says `fell_back`, adds `map` (the Laplace sampler's
/// MAP) to its own, and counts `spent` (all the Laplace sampler drew) in its warm-up.
///
/// With `settings.fallback_budget` and a `refused` sample to return to, each chain may spend
/// that many gradients per transition on average, each at the integrator's work of a gradient
/// at the `mode`; where one spends more, the fallback ends and `refused` stands, marked
/// [`RunOutput::fallback_stopped`].
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
    // Where k̂ > 0.7 (or none could be fitted) the Laplace covariance is no metric to trust
    // either: NUTS re-estimates it in Stan's windows, with their warm-up. Between a stricter
    // line and 0.7 (the independence chain falls back above 0.5, diagnose's fits above
    // min(1 − 1/log₁₀ S, 0.7)) the approximation was refused for weighing draws, whose error
    // converges slowly there, not as a shape: NUTS keeps it as its metric, tunes only the step
    // size, and its own R-hat and ESS judge the result.
    let metric_adaptation = if khat <= KHAT_UNRELIABLE {
        MetricAdaptation::Laplace
    } else {
        MetricAdaptation::Windows
    };
    let warmup = super::default_warmup(SamplerKind::NutsDense, metric_adaptation);
    let transitions = (warmup + settings.chain.draws) as u64;
    let (refused, mode) = refused.unzip();
    let work_budget = match (settings.fallback_budget, mode) {
        (Some(per_transition), Some(mode)) => {
            Some(per_transition * transitions * gradient_work(posterior, mode)?)
        }
        _ => None,
    };
    let nuts = RunSettings {
        sampler: SamplerKind::NutsDense,
        chain: crate::sampler::ChainSettings {
            warmup,
            ..settings.chain.clone()
        },
        metric_adaptation,
        work_budget,
        // NUTS itself does not fall back.
        fallback_budget: None,
        ..settings.clone()
    };
    let mut posterior = posterior.clone();
    let fallback = match super::run_sampler(&mut posterior, &nuts, &format!("{label} fallback")) {
        Ok(run) => run,
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
    Ok(RunOutput {
        khat: Some(khat),
        fell_back: true,
        map: map + fallback.map,
        warmup: spent + fallback.warmup,
        wall_seconds: started.elapsed().as_secs_f64(),
        ..fallback
    })
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
