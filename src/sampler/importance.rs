//! Importance sampling from the Laplace approximation: independent draws from a
//! [`LaplaceProposal`], weighted by π/q, the weights Pareto-smoothed (PSIS), then resampled to
//! equal weights so that every summary, file and figure downstream reads the result like a
//! sampled run. k̂ says whether the weights, and so the draws, can be trusted (Vehtari et al.
//! 2024); the smoothed weights' effective sample size says how many independent draws they are
//! worth — the resampled draws look independent and would overstate it.
//!
//! The MAP is the joint posterior's mode, not its mean: with many coefficients beside them the
//! noise scales' marginal sits above their joint mode (at K = 20 on the paper's data `motorcal
//! bench --k 20 --samplers laplace-is` finds 1408 effective draws with the recentring and 618
//! with `--warmup 0`), and a proposal off centre
//! by δ in whitened units loses about a factor e^{-|δ|²} of its effective draws. So the
//! warm-up recentres the proposal in rounds: each round's draws are weighed, the weighted mean
//! is taken in whitened coordinates, and only the coordinates whose shift exceeds twice its
//! Monte Carlo standard error move (in 45 dimensions, moving every coordinate by its noise costs
//! more than the shift gains). The scale matrix stays the Laplace one: a covariance estimated
//! from a few hundred effective draws in 45 dimensions is mostly noise (Marchenko–Pastur).
//! Nothing is thrown away: every round's draws are weighed against the mixture of all rounds'
//! proposals (the balance heuristic of multiple importance sampling, Veach & Guibas 1995; Owen
//! & Zhou 2000), and all of them enter the smoothing and the resampling. Half of every round
//! after the first still comes from the MAP's proposal (defensive importance sampling), so that
//! a centre moved the wrong way — towards the mean of a skewed marginal, away from its mode —
//! cannot make the weights' tail much heavier than the MAP's proposal alone would.
//!
//! The proposals are made in `chains` parallel blocks, each on its chain's random stream, so the
//! draws do not depend on the thread count; the weights are smoothed together, and the
//! resampling (systematic, then shuffled and dealt back into `chains` blocks) runs on a stream
//! of its own.
//!
//! `collapsed-is` runs the same machinery with the proposal over θ only: each proposal's other
//! coordinates are drawn from the density's conditionals given θ ([`super::collapsed`]), their
//! log density is subtracted from the weight, and the mixture and the recentring see θ alone.

use nalgebra::DVector;
use rand::RngExt;
use rayon::prelude::*;

use super::clock::Stopwatch;
use super::driver::chain_rng;
use super::proposal::LaplaceProposal;
use super::{ChainOutput, DrawRecord, PhaseCost, proposal_log_density};
use crate::density::{Counted, DensityError, LogDensity};
use crate::diagnostics::{KHAT_UNRELIABLE, Psis, psis};

/// The sampler's name in files and tables.
pub const NAME: &str = "laplace-is";

/// What importance sampling produced.
#[derive(Clone, Debug)]
pub struct ImportanceRun {
    /// The resampled, equal-weight draws in `chains` blocks; each record's `weight` is the
    /// smoothed normalised weight of the proposal it copies.
    pub chains: Vec<ChainOutput>,
    /// The smoothed weights of all proposals, warm-up rounds' included, in proposal order
    /// (round by round, chain by chain within a round).
    pub psis: Psis,
    /// The final proposal's centre: the MAP moved by the recentring rounds.
    pub centre: Vec<f64>,
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

/// One block of proposals: the points, their log densities, and its cost.
struct Block {
    x: Vec<Vec<f64>>,
    log_density: Vec<f64>,
    /// log q of the coordinates drawn from the density's conditionals (`collapsed-is`; 0
    /// where the proposal drew every coordinate).
    log_completion: Vec<f64>,
    cost: PhaseCost,
}

/// What the Laplace proposal draws: every coordinate (`laplace-is`), or θ only, with the noise
/// scales and linear coefficients drawn from the density's conditionals given θ
/// ([`super::collapsed`], `collapsed-is`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Proposed {
    Everything,
    Leading,
}

impl Proposed {
    /// The sampler's name in files and tables.
    pub fn name(&self) -> &'static str {
        match self {
            Proposed::Everything => NAME,
            Proposed::Leading => COLLAPSED_NAME,
        }
    }
}

/// The collapsed sampler's name in files and tables.
pub const COLLAPSED_NAME: &str = "collapsed-is";

/// Rounds the warm-up's proposals are spread over. The first moves the centre most of the way
/// from a sample weighed against the MAP's proposal; the second re-estimates it from draws
/// already near the new centre, whose weights are less uneven.
pub const RECENTRING_ROUNDS: usize = 2;

/// The share of every round after the first drawn from the MAP's proposal rather than the
/// recentred one (defensive importance sampling, Hesterberg 1995). The weighted mean is not the
/// mode: where the posterior is skewed (a term near its bound) a symmetric proposal moved to the
/// mean leaves the mode's side thin, and its few draws there carry huge weights. With the MAP's
/// proposal holding at least this share of the mixture, no draw weighs more than 1/share times
/// what the MAP's proposal alone would give it, so recentring can cost at most that factor in the
/// tail and gains wherever the shift is real.
pub const DEFENSIVE_SHARE: f64 = 0.5;

/// Proposals per chain spent recentring when no warm-up is given (see `default_warmup`): a
/// quarter of the default 1000.
pub const IS_WARMUP: usize = 250;

/// `chains × draws` proposals on the densities `make` builds (one per block, so caches are never
/// shared), all Pareto-smoothed together and resampled to as many equal-weight draws. The first
/// `warmup` of each chain's `draws` (at most a quarter of them, so that most proposals come from
/// the final centre; 0 keeps the MAP) are drawn in [`RECENTRING_ROUNDS`] recentring rounds: the
/// warm-up is part of the sample, not extra to it.
pub fn importance_sample<P, F>(
    proposal: &LaplaceProposal,
    chains: usize,
    warmup: usize,
    draws: usize,
    seed: u64,
    make: F,
) -> Result<ImportanceRun, DensityError>
where
    P: LogDensity,
    F: Fn(usize) -> Result<P, DensityError> + Sync,
{
    importance_sample_with(
        proposal,
        Proposed::Everything,
        chains,
        warmup,
        draws,
        seed,
        make,
    )
}

/// [`importance_sample`] with what the proposal draws chosen: with [`Proposed::Leading`],
/// `proposal` is over θ (the density's leading coordinates) and the rest is drawn from the
/// density's conditionals given θ, so every weight varies with θ alone (`collapsed-is`).
pub fn importance_sample_with<P, F>(
    proposal: &LaplaceProposal,
    proposed: Proposed,
    chains: usize,
    warmup: usize,
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
    let mut rngs: Vec<_> = (0..chains).map(|c| chain_rng(seed, c)).collect();
    let recentring = warmup.min(draws / 4);
    let per_round = if recentring >= RECENTRING_ROUNDS {
        vec![recentring / RECENTRING_ROUNDS; RECENTRING_ROUNDS]
    } else {
        Vec::new()
    };
    let last = draws - per_round.iter().sum::<usize>();
    // components[0] is the MAP's proposal, kept in every round (see `DEFENSIVE_SHARE`).
    let mut components: Vec<(LaplaceProposal, usize)> = vec![(proposal.clone(), 0)];
    let mut rounds: Vec<Vec<Block>> = Vec::new();
    let mut current = proposal.clone();
    for n in per_round.iter().copied().chain([last]) {
        let defensive = if rounds.is_empty() {
            n
        } else {
            (n as f64 * DEFENSIVE_SHARE).round() as usize
        };
        let parts = [(proposal, defensive), (&current, n - defensive)];
        let blocks: Vec<Block> = rngs
            .par_iter_mut()
            .enumerate()
            .map(|(c, rng)| propose(&parts, proposed, make(c)?, rng))
            .collect::<Result<_, _>>()?;
        components[0].1 += defensive * chains;
        if n > defensive {
            add_component(&mut components, &current, (n - defensive) * chains);
        }
        rounds.push(blocks);
        if rounds.len() <= per_round.len() {
            let smoothed = psis(&log_weights(&rounds, &components));
            current = recentre(&current, &rounds, &smoothed);
        }
    }
    let watch = Stopwatch::start();
    let smoothed = psis(&log_weights(&rounds, &components));
    let pool: Vec<(&Vec<f64>, f64)> = rounds
        .iter()
        .flatten()
        .flat_map(|b| b.x.iter().zip(b.log_density.iter().copied()))
        .collect();
    let picks = resample(
        &smoothed.weights(),
        chains * draws,
        &mut chain_rng(seed, chains),
    );
    let density = make(0)?;
    let names = density.output_names();
    let finals = rounds.last().expect("the final round");
    let mut outputs = picks
        .chunks(draws)
        .enumerate()
        .map(|(c, picks)| {
            let mut out = ChainOutput {
                chain: c,
                sampler: proposed.name().into(),
                names: names.clone(),
                draws: Vec::with_capacity(draws),
                unconstrained: Vec::with_capacity(draws),
                records: Vec::with_capacity(draws),
                warmup: rounds[..rounds.len() - 1].iter().map(|r| r[c].cost).sum(),
                sampling: finals[c].cost,
                uses_gradient: false,
                divergences: 0,
                mean_accept_stat: 1.0,
                final_step_size: proposal.scale(),
                warmup_draws: Vec::new(),
                warmup_records: Vec::new(),
            };
            let mut constrained = Vec::new();
            for &i in picks {
                let (x, lp) = pool[i];
                density.constrain(x, &mut constrained);
                out.draws.push(constrained.clone());
                out.unconstrained.push(x.clone());
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
        centre: current.mean().to_vec(),
    })
}

/// `n` more proposals from `q` in the mixture, counted with an equal component where there is
/// one (a round whose centre did not move; the rounds share the Laplace scale matrix, so their
/// centres tell them apart): the mixture holds each distinct proposal once, and a recentring
/// that moves nothing weighs every draw exactly as no recentring would.
fn add_component(components: &mut Vec<(LaplaceProposal, usize)>, q: &LaplaceProposal, n: usize) {
    match components.iter_mut().find(|(c, _)| c.mean() == q.mean()) {
        Some((_, count)) => *count += n,
        None => components.push((q.clone(), n)),
    }
}

/// log π(x) − log Σᵣ (nᵣ/N) qᵣ(x) for every proposal so far: each weighed against the mixture of
/// all rounds' proposals (with one round, exactly log π − log q).
fn log_weights(rounds: &[Vec<Block>], components: &[(LaplaceProposal, usize)]) -> Vec<f64> {
    let d = components[0].0.dim();
    let points = rounds.iter().flatten().flat_map(|b| {
        b.x.iter().map(move |x| &x[..d]).zip(
            b.log_density
                .iter()
                .zip(&b.log_completion)
                .map(|(lp, lc)| lp - lc),
        )
    });
    mixture_log_weights(points, components)
}

/// The importance log weights log π(x) − log Σᵣ (nᵣ/N) qᵣ(x) of proposals `(x, log π(x))` drawn
/// nᵣ from each of the `components` (qᵣ, nᵣ): every draw weighed against the mixture of all of
/// them (the balance heuristic; with one component, exactly log π − log q). Importance sampling
/// weighs its rounds' draws so, and the independence sampler its warm-up's, drawn from each of
/// the proposal shapes it tries.
pub fn mixture_log_weights<'a>(
    points: impl Iterator<Item = (&'a [f64], f64)>,
    components: &[(LaplaceProposal, usize)],
) -> Vec<f64> {
    let total: usize = components.iter().map(|c| c.1).sum();
    let log_shares: Vec<f64> = components
        .iter()
        .map(|(_, n)| (*n as f64).ln() - (total as f64).ln())
        .collect();
    points
        .map(|(x, lp)| {
            if lp == f64::NEG_INFINITY {
                // Outside the support, or its solve failed: it weighs nothing.
                return lp;
            }
            let terms: Vec<f64> = components
                .iter()
                .zip(&log_shares)
                .map(|((q, _), share)| share + q.log_density(x))
                .collect();
            let top = terms.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let log_mixture = if terms.len() == 1 {
                terms[0]
            } else {
                top + terms.iter().map(|t| (t - top).exp()).sum::<f64>().ln()
            };
            lp - log_mixture
        })
        .collect()
}

/// The centre moved to the weighted mean of every proposal so far, in the coordinates that the
/// Laplace scale matrix whitens, where that shift exceeds twice its Monte Carlo standard error
/// (√(weighted variance / the weights' ESS)); elsewhere it stays.
fn recentre(current: &LaplaceProposal, rounds: &[Vec<Block>], smoothed: &Psis) -> LaplaceProposal {
    let weights = smoothed.weights();
    let ess = smoothed.ess();
    let whitened: Vec<DVector<f64>> = rounds
        .iter()
        .flatten()
        .flat_map(|b| b.x.iter())
        .map(|x| current.whiten(&x[..current.dim()]))
        .collect();
    let d = current.dim();
    let mut mean = DVector::zeros(d);
    for (z, w) in whitened.iter().zip(&weights) {
        if *w > 0.0 {
            mean += z * *w;
        }
    }
    let mut variance = DVector::<f64>::zeros(d);
    for (z, w) in whitened.iter().zip(&weights) {
        if *w > 0.0 {
            let r = z - &mean;
            variance += r.component_mul(&r) * *w;
        }
    }
    // Beyond k̂ = 0.7 no PSIS estimate is trusted (Vehtari et al. 2024), the weighted mean's
    // included: a move would follow the noise of a few heavy draws, so the centre stays.
    if !(smoothed.khat < KHAT_UNRELIABLE) || !(ess > 1.0) || !mean.iter().all(|m| m.is_finite()) {
        return current.clone();
    }
    let shift = DVector::from_iterator(
        d,
        mean.iter().zip(variance.iter()).map(|(m, v)| {
            if m.abs() > 2.0 * (v / ess).sqrt() {
                *m
            } else {
                0.0
            }
        }),
    );
    current.recentred(&current.unwhiten(&shift))
}

/// One chain's block of a round: `n` draws from each `(proposal, n)` part in turn, completed
/// from the density's conditionals where only θ is `proposed`.
fn propose<P: LogDensity>(
    parts: &[(&LaplaceProposal, usize)],
    proposed: Proposed,
    density: P,
    rng: &mut super::ChainRng,
) -> Result<Block, DensityError> {
    let watch = Stopwatch::start();
    let mut density = Counted::new(density);
    let draws = parts.iter().map(|p| p.1).sum();
    let mut block = Block {
        x: Vec::with_capacity(draws),
        log_density: Vec::with_capacity(draws),
        log_completion: Vec::with_capacity(draws),
        cost: PhaseCost::default(),
    };
    let each = parts.iter().flat_map(|&(q, n)| std::iter::repeat_n(q, n));
    for proposal in each {
        let lead = proposal.draw(rng);
        let (x, lp, lc) = match proposed {
            Proposed::Everything => {
                let lp = proposal_log_density(&mut density, &lead)?;
                (lead, lp, 0.0)
            }
            Proposed::Leading => match super::collapsed::complete(&mut density, &lead, rng)? {
                Some((x, lc)) => {
                    let lp = proposal_log_density(&mut density, &x)?;
                    (x, lp, lc)
                }
                // Nothing to condition on at θ: it weighs nothing.
                None => {
                    let mut x = lead;
                    x.resize(density.dim(), 0.0);
                    (x, f64::NEG_INFINITY, 0.0)
                }
            },
        };
        block.x.push(x);
        block.log_density.push(lp);
        block.log_completion.push(lc);
    }
    block.cost = PhaseCost::counted(watch.elapsed(), &density);
    Ok(block)
}

/// Systematic resampling of `n` picks (one uniform, n evenly spaced points through the weights'
/// cumulative sum), then a Fisher–Yates shuffle so that consecutive draws are not sorted by
/// proposal.
fn resample(weights: &[f64], n: usize, rng: &mut super::ChainRng) -> Vec<usize> {
    let total: f64 = weights.iter().sum();
    let u: f64 = rng.random::<f64>();
    let mut picks = Vec::with_capacity(n);
    let mut cumulative = 0.0;
    let mut i = 0;
    for k in 0..n {
        let point = (u + k as f64) / n as f64 * total;
        while i + 1 < weights.len() && cumulative + weights[i] <= point {
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
        let picks = resample(&weights, weights.len(), &mut chain_rng(1, 0));
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
        let run = importance_sample(&proposal, 4, 0, 1000, 17, |_| Ok(target.clone())).unwrap();
        assert!(run.khat() < 0.5, "k̂ = {}", run.khat());
        assert!(run.weights_ess() > 2000.0, "ESS {}", run.weights_ess());
        assert_eq!(run.chains.len(), 4);
        assert!(run.chains.iter().all(|c| c.draws.len() == 1000));
        assert_eq!(run.chains[0].sampling.density_evaluations, 1000);
        check_gaussian_moments(&run.chains, &target, 4.0).unwrap();
    }

    #[test]
    fn recentring_moves_an_off_centre_proposal_onto_the_mean_and_keeps_every_draw() {
        // The proposal's centre 0.8 standard deviations off in two of eight coordinates, as the
        // joint mode sits off the noise scales' marginal at K = 20.
        let target = Gaussian::correlated(8, 0.3, 1.0);
        let precision = target.covariance.clone().try_inverse().unwrap();
        let mut mode: Vec<f64> = target.mean.iter().copied().collect();
        mode[0] -= 0.8 * target.covariance[(0, 0)].sqrt();
        mode[5] += 0.8 * target.covariance[(5, 5)].sqrt();
        let proposal = LaplaceProposal::new(&mode, &precision)
            .unwrap()
            .with_shape(30.0, 1.0)
            .unwrap();
        let fixed = importance_sample(&proposal, 4, 0, 1000, 21, |_| Ok(target.clone())).unwrap();
        let moved = importance_sample(&proposal, 4, 250, 1000, 21, |_| Ok(target.clone())).unwrap();
        let miss = |c: &[f64]| {
            let z = proposal.recentred(target.mean.as_slice()).whiten(c);
            z.norm()
        };
        assert!(miss(&fixed.centre) > 1.0, "{}", miss(&fixed.centre));
        assert!(miss(&moved.centre) < 0.3, "{}", miss(&moved.centre));
        // The warm-up's proposals are a quarter of the draws: 4000 weighed, 4000 resampled.
        assert_eq!(moved.psis.log_weights.len(), 4000);
        assert!(moved.chains.iter().all(|c| c.draws.len() == 1000));
        assert_eq!(moved.chains[0].warmup.density_evaluations, 250);
        assert!(
            moved.weights_ess() > 1.3 * fixed.weights_ess(),
            "ESS {} recentred vs {} at the mode",
            moved.weights_ess(),
            fixed.weights_ess()
        );
        check_gaussian_moments(&moved.chains, &target, 4.0).unwrap();
    }

    #[test]
    fn a_proposal_too_narrow_is_flagged_by_khat() {
        let target = Gaussian::new(vec![0.0, 0.0], DMatrix::identity(2, 2));
        let proposal = LaplaceProposal::new(&[0.0, 0.0], &(DMatrix::identity(2, 2) * 9.0)).unwrap();
        let run = importance_sample(&proposal, 2, 0, 2000, 3, |_| Ok(target.clone())).unwrap();
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
            let run = importance_sample(&proposal, 4, 0, 1000, 5, |_| Ok(target.clone())).unwrap();
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
                .install(|| importance_sample(&proposal, 3, 0, 200, 9, |_| Ok(target.clone())))
                .unwrap()
        };
        let (one, two) = (run(1), run(2));
        for (a, b) in one.chains.iter().zip(&two.chains) {
            assert_eq!(a.draws, b.draws);
        }
        assert_eq!(one.psis, two.psis);
    }
}
