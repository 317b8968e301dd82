//! `independence`: independence Metropolis–Hastings from the Student-t at the MAP, judged by the
//! Pareto k̂ of its warm-up's importance weights before any chain draws, and NUTS on the same
//! problem when k̂ says the Laplace approximation cannot be trusted — laplace-is's check and
//! fallback, on the proposals the chains make anyway.
//!
//! The check comes after warm-up, not after the draws: warm-up's proposals are independent draws
//! from the shapes it tries, as good a sample of π/q as the sampling's, and on a proposal that
//! misses the posterior the draws are what costs — on BM2(K = 3) a noise scale drawn far in its
//! prior's tail left a chain stuck at a minimum bulk ESS of 1.4 in 819 200 draws
//! (papers/laplace-samplers/README.md), which a check after the draws would have paid for first.
//! The warm-ups of all chains are pooled, as laplace-is pools its blocks: one k̂ per run, from
//! chains × warm-up proposals (1280 by default), where one chain's 320 would give a noisier one.

use std::time::Instant;

use crate::diagnostics::KHAT_GOOD;

use super::fallback::{falls_back, nuts_instead};
use super::{
    Error, Fittable, PhaseCost, RunOutput, RunSettings, SamplerKind, finish_run, in_pool,
    progress_bars, run_control,
};
use crate::density::DensityError;
use crate::optimize::MapEstimate;
use crate::sampler::independence::{Independence, IndependenceTuning, warmup_khat};
use crate::sampler::proposal::LaplaceProposal;
use crate::sampler::{ChainOutput, sample_chains, warm_up_chains};

/// The independence chain's own bound on k̂, below laplace-is's 0.7: a chain stays at a point of
/// weight w for about w / E_q[w] transitions, so its mean stay under π is E_q[w²] / E_q[w]²,
/// finite only where the weights have a finite variance, k < ½. Above it the chain sticks
/// (BM2(K = 3) SBC replication 118, k̂ 0.69, needed 25 600 draws for a bulk ESS of 100) where
/// importance sampling, which weighs every draw instead of staying, still estimates well.
const KHAT_CHAIN: f64 = KHAT_GOOD;

/// What the chains did once their warm-ups were judged.
enum Judged {
    /// Trusted (or too short a warm-up to judge, `khat` then `None`): the chains drew.
    Sampled {
        chains: Vec<ChainOutput>,
        khat: Option<f64>,
    },
    /// k̂ said the approximation cannot be trusted: the chains stopped after warm-up, which
    /// cost `warmup` over all of them.
    Untrusted { khat: f64, warmup: PhaseCost },
}

/// The independence sampler on `posterior` from `inits`: every chain's warm-up, then k̂ of all
/// their proposals' weights; when k̂ > the lower of `settings.fallback_above` and ½
/// ([`KHAT_CHAIN`]; or cannot be fitted) and
/// `settings.fallback`, no chain draws and NUTS runs instead, as for laplace-is
/// ([`nuts_instead`]); otherwise the chains draw and the record keeps k̂.
pub(super) fn independence<P: Fittable>(
    posterior: &P,
    map: &MapEstimate,
    map_cost: PhaseCost,
    inits: &[Vec<f64>],
    settings: &RunSettings,
    label: &str,
    started: Instant,
) -> Result<RunOutput, Error> {
    let bars = progress_bars(inits.len(), label, settings.quiet);
    let make = |_| {
        let proposal = LaplaceProposal::new(&map.x, &map.hessian).map_err(DensityError::fatal)?;
        let mut kernel = Independence::new(proposal);
        IndependenceTuning::start(&mut kernel);
        Ok((posterior.clone(), kernel, IndependenceTuning::default()))
    };
    let work = || -> Result<Judged, DensityError> {
        let progress = bars.as_ref().map(|(_, b)| b.as_slice());
        let control = run_control(settings);
        let warm = warm_up_chains(
            inits,
            &settings.chain,
            settings.seed,
            make,
            progress,
            control,
        )?;
        let khat = warmup_khat(warm.iter().map(|w| w.kernel()));
        if let Some(khat) = khat.filter(|&k| falls_back(k, settings, KHAT_CHAIN)) {
            let warmup = warm.iter().map(|w| w.warmup()).sum();
            return Ok(Judged::Untrusted { khat, warmup });
        }
        let chains = sample_chains(warm)?.into_iter().map(|(o, _)| o).collect();
        Ok(Judged::Sampled { chains, khat })
    };
    match in_pool(settings.threads, work)?? {
        Judged::Sampled { chains, khat } => Ok(RunOutput {
            map: map_cost,
            khat,
            ..finish_run(SamplerKind::Independence.name(), chains, map, started)
        }),
        Judged::Untrusted { khat, warmup } => {
            if let Some((_, bars)) = &bars {
                for bar in bars {
                    bar.abandon_with_message(format!("k̂ {khat:.2}: NUTS instead"));
                }
            }
            nuts_instead(
                posterior, settings, label, khat, map_cost, warmup, started, None,
            )
        }
    }
}
