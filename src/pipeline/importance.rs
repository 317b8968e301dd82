//! `laplace-is`: importance sampling from the Laplace approximation, Pareto-smoothed, and NUTS
//! on the same problem when k̂ says the approximation cannot be trusted.

use std::time::Instant;

use super::SamplerKind;
use super::fallback::{falls_back, nuts_instead};
use super::{Error, Fittable, PhaseCost, RunOutput, RunSettings, finish_run};
use crate::density::DensityError;
use crate::optimize::MapEstimate;
use crate::sampler::importance::{Proposed, importance_sample_with};
use crate::sampler::proposal::LaplaceProposal;

/// The proposal's degrees of freedom and scale. Importance sampling has no acceptance rate to
/// tune them by, so they are fixed: tails heavier than the Gaussian's keep the weights bounded
/// where the posterior's tails are Gaussian, and ν = 30 keeps the t's radial spread close to
/// the Gaussian's, which in 10–50 dimensions decides how much of the sample carries weight.
pub const IS_SHAPE: (f64, f64) = (30.0, 1.0);

/// The second proposal's degrees of freedom and scale ([`RunSettings::defensive_proposal`]):
/// tails of a t with 5 degrees of freedom, 1.5 times the Laplace scale. A k̂ above the line
/// says the posterior reaches where the first proposal puts too little mass — a skewed
/// marginal, a second mode, a curved ridge — and a wider proposal with polynomial tails covers
/// those at the price of weights spread thinner (in many dimensions, much thinner: which is
/// why it is the second proposal, not the first). Over the 184 independent-integrator cases of
/// papers/beyond-library.md (session 6) four of diagnose's fits fell back to NUTS, BM1 and
/// BM2 alike; the second proposal keeps all four, and the NUTS run that made two of those
/// diagnoses 27 and 42 s is not needed. The t's heavier tails are defensive importance
/// sampling (Hesterberg 1995) in its simplest form: a proposal whose tails dominate the
/// target's.
pub const DEFENSIVE_SHAPE: (f64, f64) = (5.0, 1.5);

/// What the second proposal's seed differs by, so that its draws are not the first's rescaled.
const DEFENSIVE_SEED: u64 = 0xdef5_e1f0;

/// Importance sampling of `posterior` from the Student-t at `map`: `chains × draws` proposals,
/// resampled. Its `min_ess_bulk` is the smaller of the smoothed weights' ESS and the resampled
/// draws' bulk ESS. With `collapsed-is` the Student-t is the Laplace approximation's marginal in
/// θ and the rest is drawn from the posterior's conditionals given θ. When k̂ >
/// `settings.fallback_above` (0.7 by default; or cannot be fitted) and `settings.fallback`, NUTS
/// with a dense metric runs instead (`fallback::nuts_instead`); its record keeps k̂, says
/// `fell_back`, and counts the importance sampling it replaced in its warm-up.
pub(super) fn laplace_is<P: Fittable>(
    posterior: &P,
    map: &MapEstimate,
    map_cost: PhaseCost,
    settings: &RunSettings,
    label: &str,
    started: Instant,
) -> Result<RunOutput, Error> {
    let proposed = if settings.sampler == SamplerKind::CollapsedIs {
        Proposed::Leading
    } else {
        Proposed::Everything
    };
    let laplace = if proposed == Proposed::Leading {
        let leading = posterior.conditioned_on().ok_or_else(|| {
            Error::invalid(
                "collapsed-is needs a posterior whose noise scales (and coefficients) have conditionals given θ",
            )
        })?;
        marginal_proposal(map, leading)
    } else {
        LaplaceProposal::new(&map.x, &map.hessian)
    }
    .map_err(Error::Numerical)?;
    // The recentring corrects the offset of the scales' marginal from the joint mode under
    // many linear coefficients (BM2). Without them (BM1) the marginals that are off their mode
    // are skewed ones — a term near its bound — where a symmetric proposal moved to the mean
    // thins the mode's side: 1000 SBC replications on BM1 put k̂ above 0.5 in 43 with it
    // against 8 without, and dev case 03's after-fit from 0.52–0.68 to 0.65–0.79 (six seeds).
    let recentring = if posterior.has_linear_coefficients() {
        settings.chain.warmup
    } else {
        0
    };
    let attempts: &[((f64, f64), u64)] = if settings.defensive_proposal {
        &[(IS_SHAPE, 0), (DEFENSIVE_SHAPE, DEFENSIVE_SEED)]
    } else {
        &[(IS_SHAPE, 0)]
    };
    let mut spent = PhaseCost::default();
    let mut first_khat = None;
    let mut refused = None;
    let mut map_cost = map_cost;
    for &((df, scale), seed) in attempts {
        let proposal = laplace
            .clone()
            .with_shape(df, scale)
            .map_err(Error::Numerical)?;
        let work = || {
            importance_sample_with(
                &proposal,
                proposed,
                settings.chains,
                recentring,
                settings.chain.draws,
                settings.seed ^ seed,
                |_| Ok::<_, DensityError>(posterior.clone()),
            )
        };
        let run = super::in_pool(settings.threads, work)??;
        let khat = run.khat();
        let weights_ess = run.weights_ess();
        let mut output = RunOutput {
            map: map_cost,
            khat: Some(khat),
            ..finish_run(settings.sampler.name(), run.chains, map, started)
        };
        output.min_ess_bulk = output.min_ess_bulk.min(weights_ess);
        // A proposal refused before is counted in the warm-up of the one kept.
        let own = output.warmup + output.sampling;
        output.warmup = spent + output.warmup;
        if !falls_back(khat, settings, f64::INFINITY) {
            return Ok(output);
        }
        spent = spent + own;
        first_khat.get_or_insert(khat);
        map_cost = output.map;
        // The refused sample with the lower k̂ is what stands if the fallback stops at its
        // budget (a k̂ that could not be fitted, NaN, ranks last).
        let rank = |k: Option<f64>| k.filter(|k| !k.is_nan()).unwrap_or(f64::INFINITY);
        if refused
            .as_ref()
            .is_none_or(|r: &RunOutput| rank(output.khat) < rank(r.khat))
        {
            refused = Some(output);
        }
    }
    let khat = first_khat.unwrap_or(f64::NAN);
    let refused = refused.map(|r| (r, map.x.as_slice()));
    nuts_instead(
        posterior, settings, label, khat, map_cost, spent, started, refused,
    )
}

/// The Laplace approximation's marginal in the first `leading` coordinates: N(x̂_θ, (H⁻¹)_θθ).
fn marginal_proposal(map: &MapEstimate, leading: usize) -> Result<LaplaceProposal, String> {
    let covariance = map
        .hessian
        .clone()
        .try_inverse()
        .ok_or("the Hessian at the MAP is singular")?;
    let block = covariance.view((0, 0), (leading, leading)).into_owned();
    let precision = block
        .try_inverse()
        .ok_or("the marginal covariance of θ is singular")?;
    LaplaceProposal::new(&map.x[..leading], &precision)
}
