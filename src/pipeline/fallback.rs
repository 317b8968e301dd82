//! NUTS in place of a sampler that draws from the Laplace approximation, when the Pareto k̂ of
//! its importance weights says the approximation cannot be trusted: laplace-is's and the
//! independence sampler's one way out, so that both fall back alike and record it alike.

use std::time::Instant;

use crate::diagnostics::KHAT_UNRELIABLE;

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
pub(super) fn nuts_instead<P: Fittable>(
    posterior: &P,
    settings: &RunSettings,
    label: &str,
    khat: f64,
    map: PhaseCost,
    spent: PhaseCost,
    started: Instant,
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
    let nuts = RunSettings {
        sampler: SamplerKind::NutsDense,
        chain: crate::sampler::ChainSettings {
            warmup: super::default_warmup(SamplerKind::NutsDense, metric_adaptation),
            ..settings.chain.clone()
        },
        metric_adaptation,
        ..settings.clone()
    };
    let mut posterior = posterior.clone();
    let fallback = super::run_sampler(&mut posterior, &nuts, &format!("{label} fallback"))?;
    Ok(RunOutput {
        khat: Some(khat),
        fell_back: true,
        map: map + fallback.map,
        warmup: spent + fallback.warmup,
        wall_seconds: started.elapsed().as_secs_f64(),
        ..fallback
    })
}
