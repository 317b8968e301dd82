//! Importance sampling from the Laplace approximation: independent draws from a
//! [`LaplaceProposal`], weighted by π/q, the weights Pareto-smoothed (PSIS), then resampled to
//! equal weights so that every summary, file and figure downstream reads the result like a
//! sampled run. k̂ says whether the weights, and so the draws, can be trusted (Vehtari et al.
//! 2024); the smoothed weights' effective sample size says how many independent draws they are
//! worth — the resampled draws look independent and would overstate it.
//!
//! The proposals are made in `chains` parallel blocks, each on its chain's random stream, so the
//! draws do not depend on the thread count; the weights are smoothed together, and the
//! resampling (systematic, then shuffled and dealt back into `chains` blocks) runs on a stream
//! of its own.

use rand::RngExt;
use rayon::prelude::*;

use super::clock::Stopwatch;
use super::driver::chain_rng;
use super::proposal::LaplaceProposal;
use super::{ChainOutput, DrawRecord, PhaseCost, proposal_log_density};
use crate::density::{Counted, DensityError, LogDensity};
use crate::diagnostics::{Psis, psis};

/// The sampler's name in files and tables.
pub const NAME: &str = "laplace-is";

/// What importance sampling produced.
#[derive(Clone, Debug)]
pub struct ImportanceRun {
    /// The resampled, equal-weight draws in `chains` blocks; each record's `weight` is the
    /// smoothed normalised weight of the proposal it copies.
    pub chains: Vec<ChainOutput>,
    /// The smoothed weights of all proposals, in proposal order (chain by chain).
    pub psis: Psis,
}

impl ImportanceRun {
    pub fn khat(&self) -> f64 {
        self.psis.khat
    }

    /// The effective sample size of the smoothed weights.
    pub fn weights_ess(&self) -> f64 {
        self.psis.ess()
    }
}

/// One block of proposals: the points, their log densities and log weights, and its cost.
struct Block {
    x: Vec<Vec<f64>>,
    log_density: Vec<f64>,
    log_weights: Vec<f64>,
    cost: PhaseCost,
}

/// `chains × draws` proposals from `proposal` on the densities `make` builds (one per block,
/// so caches are never shared), Pareto-smoothed and resampled.
pub fn importance_sample<P, F>(
    proposal: &LaplaceProposal,
    chains: usize,
    draws: usize,
    seed: u64,
    make: F,
) -> Result<ImportanceRun, DensityError>
where
    P: LogDensity,
    F: Fn(usize) -> Result<P, DensityError> + Sync,
{
    if chains == 0 || draws == 0 {
        return Err(DensityError::fatal("importance sampling needs draws"));
    }
    let blocks: Vec<Block> = (0..chains)
        .into_par_iter()
        .map(|c| propose(proposal, make(c)?, draws, &mut chain_rng(seed, c)))
        .collect::<Result<_, _>>()?;
    let watch = Stopwatch::start();
    let log_weights: Vec<f64> = blocks.iter().flat_map(|b| b.log_weights.clone()).collect();
    let smoothed = psis(&log_weights);
    let picks = resample(&smoothed.weights(), &mut chain_rng(seed, chains));
    let density = make(0)?;
    let names = density.output_names();
    let mut outputs = picks
        .chunks(draws)
        .enumerate()
        .map(|(c, picks)| {
            let mut out = ChainOutput {
                chain: c,
                sampler: NAME.into(),
                names: names.clone(),
                draws: Vec::with_capacity(draws),
                unconstrained: Vec::with_capacity(draws),
                records: Vec::with_capacity(draws),
                warmup: PhaseCost::default(),
                sampling: blocks[c].cost,
                uses_gradient: false,
                divergences: 0,
                mean_accept_stat: 1.0,
                final_step_size: proposal.scale(),
                warmup_draws: Vec::new(),
                warmup_records: Vec::new(),
            };
            let mut constrained = Vec::new();
            for &i in picks {
                let (b, j) = (i / draws, i % draws);
                let x = &blocks[b].x[j];
                density.constrain(x, &mut constrained);
                out.draws.push(constrained.clone());
                out.unconstrained.push(x.clone());
                let lp = blocks[b].log_density[j];
                out.records.push(DrawRecord {
                    lp,
                    accept_stat: 1.0,
                    step_size: proposal.scale(),
                    tree_depth: 0,
                    n_steps: 1,
                    divergent: false,
                    energy: -lp,
                    weight: Some(smoothed.log_weights[i].exp()),
                });
            }
            out
        })
        .collect::<Vec<_>>();
    // Smoothing and resampling ran on this thread after the blocks: chain 1's to carry.
    let time = watch.elapsed();
    outputs[0].sampling.wall_seconds += time.wall_seconds;
    outputs[0].sampling.cpu_seconds += time.cpu_seconds;
    Ok(ImportanceRun {
        chains: outputs,
        psis: smoothed,
    })
}

fn propose<P: LogDensity>(
    proposal: &LaplaceProposal,
    density: P,
    draws: usize,
    rng: &mut super::ChainRng,
) -> Result<Block, DensityError> {
    let watch = Stopwatch::start();
    let mut density = Counted::new(density);
    let mut block = Block {
        x: Vec::with_capacity(draws),
        log_density: Vec::with_capacity(draws),
        log_weights: Vec::with_capacity(draws),
        cost: PhaseCost::default(),
    };
    for _ in 0..draws {
        let x = proposal.draw(rng);
        let lp = proposal_log_density(&mut density, &x)?;
        // A proposal outside the support (or whose solve failed) weighs nothing.
        let lw = if lp == f64::NEG_INFINITY {
            lp
        } else {
            lp - proposal.log_density(&x)
        };
        block.x.push(x);
        block.log_density.push(lp);
        block.log_weights.push(lw);
    }
    block.cost = PhaseCost::counted(watch.elapsed(), &density);
    Ok(block)
}

/// Systematic resampling (one uniform, n evenly spaced points through the weights' cumulative
/// sum), then a Fisher–Yates shuffle so that consecutive draws are not sorted by proposal.
fn resample(weights: &[f64], rng: &mut super::ChainRng) -> Vec<usize> {
    let n = weights.len();
    let total: f64 = weights.iter().sum();
    let u: f64 = rng.random::<f64>();
    let mut picks = Vec::with_capacity(n);
    let mut cumulative = 0.0;
    let mut i = 0;
    for k in 0..n {
        let point = (u + k as f64) / n as f64 * total;
        while i + 1 < n && cumulative + weights[i] <= point {
            cumulative += weights[i];
            i += 1;
        }
        picks.push(i);
    }
    for k in (1..n).rev() {
        let j = rng.random_range(0..=k);
        picks.swap(k, j);
    }
    picks
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::targets::{Gaussian, check_gaussian_moments};
    use nalgebra::DMatrix;

    #[test]
    fn systematic_resampling_copies_each_draw_in_proportion_to_its_weight() {
        let weights = [0.5, 0.25, 0.125, 0.125, 0.0];
        let picks = resample(&weights, &mut chain_rng(1, 0));
        let count = |i| picks.iter().filter(|&&p| p == i).count() as f64;
        // Systematic resampling keeps every count within one of n·wᵢ.
        for (i, w) in weights.iter().enumerate() {
            assert!((count(i) - 5.0 * w).abs() < 1.0, "{i}: {picks:?}");
        }
    }

    #[test]
    fn a_correlated_gaussian_is_recovered_with_a_small_khat() {
        let target = Gaussian::correlated(6, 0.9, 1e3);
        let precision = target.covariance.clone().try_inverse().unwrap();
        let mean: Vec<f64> = target.mean.iter().copied().collect();
        let proposal = LaplaceProposal::new(&mean, &precision)
            .unwrap()
            .with_shape(10.0, 1.2)
            .unwrap();
        let run = importance_sample(&proposal, 4, 1000, 17, |_| Ok(target.clone())).unwrap();
        assert!(run.khat() < 0.5, "k̂ = {}", run.khat());
        assert!(run.weights_ess() > 2000.0, "ESS {}", run.weights_ess());
        assert_eq!(run.chains.len(), 4);
        assert!(run.chains.iter().all(|c| c.draws.len() == 1000));
        assert_eq!(run.chains[0].sampling.density_evaluations, 1000);
        check_gaussian_moments(&run.chains, &target, 4.0).unwrap();
    }

    #[test]
    fn a_proposal_too_narrow_is_flagged_by_khat() {
        let target = Gaussian::new(vec![0.0, 0.0], DMatrix::identity(2, 2));
        let proposal = LaplaceProposal::new(&[0.0, 0.0], &(DMatrix::identity(2, 2) * 9.0)).unwrap();
        let run = importance_sample(&proposal, 2, 2000, 3, |_| Ok(target.clone())).unwrap();
        assert!(run.khat() > 0.7, "k̂ = {}", run.khat());
    }

    #[test]
    fn a_banana_is_flagged_by_khat_from_its_laplace_approximation() {
        use crate::sampler::targets::Banana;
        for (bend, flagged) in [(0.0, false), (2.0, true)] {
            let target = Banana { bend, width: 0.3 };
            // The mode (0, −b) and the Hessian there, diag(1, 1/s²).
            let precision =
                DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![1.0, 1.0 / 0.09]));
            let proposal = LaplaceProposal::new(&[0.0, -bend], &precision)
                .unwrap()
                .with_shape(30.0, 1.0)
                .unwrap();
            let run = importance_sample(&proposal, 4, 1000, 5, |_| Ok(target.clone())).unwrap();
            assert_eq!(run.khat() > 0.7, flagged, "b = {bend}: k̂ = {}", run.khat());
        }
    }

    #[test]
    fn the_draws_do_not_depend_on_the_thread_count() {
        let target = Gaussian::correlated(3, 0.5, 10.0);
        let precision = target.covariance.clone().try_inverse().unwrap();
        let mean: Vec<f64> = target.mean.iter().copied().collect();
        let proposal = LaplaceProposal::new(&mean, &precision).unwrap();
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| importance_sample(&proposal, 3, 200, 9, |_| Ok(target.clone())))
                .unwrap()
        };
        let (one, two) = (run(1), run(2));
        for (a, b) in one.chains.iter().zip(&two.chains) {
            assert_eq!(a.draws, b.draws);
        }
        assert_eq!(one.psis, two.psis);
    }
}
