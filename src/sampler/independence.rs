//! Independence Metropolis–Hastings: every proposal a fresh draw from the Laplace approximation
//! as a multivariate Student-t ([`LaplaceProposal`]), accepted with probability
//! min(1, π(x′)q(x)/(π(x)q(x′))). Where the posterior is close to its Laplace approximation
//! nearly every proposal is accepted and the draws are nearly independent, each for one plain
//! density evaluation and no gradient (Tierney 1994, §2.3.3; Robert & Casella, §7.4).
//!
//! Warm-up tunes the proposal's degrees of freedom and scale by the acceptance rate: it tries
//! each pair of [`CANDIDATES`] for an equal share of the warm-up and keeps the one whose
//! transitions had the highest mean acceptance probability.
//!
//! Warm-up also weighs its proposals — independent draws from the mixture of the shapes it
//! tried — by π/q, the importance weights importance sampling smooths
//! ([`mixture_log_weights`]), and their Pareto k̂ ([`warmup_khat`]) says whether the t covers
//! the posterior. That is what independence MH needs: it is uniformly ergodic when π/q is
//! bounded and not even geometrically ergodic when it is not (Mengersen & Tweedie 1996); a
//! proposal that misses where π has mass leaves the chain on its draw of largest weight until it
//! proposes there again. The acceptance rate cannot tell that from a proposal only somewhat too
//! wide: both accept little.

use super::importance::mixture_log_weights;
use super::proposal::LaplaceProposal;
use super::{
    Adaptation, ChainRng, Info, Kernel, State, Transition, proposal_log_density,
    random_walk_decision,
};
use crate::density::LogDensity;
use crate::diagnostics::psis;

/// (degrees of freedom, scale) pairs warm-up chooses from, the first the kernel starts with:
/// heavy to light tails, at the Laplace scale and widened. Heavier tails and a wider scale
/// cost acceptance where the approximation is good and save the chain from sticking in a
/// tail the Gaussian underweights where it is not.
pub const CANDIDATES: [(f64, f64); 8] = [
    (5.0, 1.0),
    (5.0, 1.2),
    (10.0, 1.0),
    (10.0, 1.2),
    (30.0, 1.0),
    (30.0, 1.2),
    (100.0, 1.0),
    (100.0, 1.2),
];

/// Warm-up transitions when none is given: 40 per candidate.
pub const INDEPENDENCE_WARMUP: usize = 40 * CANDIDATES.len();

/// Independence Metropolis–Hastings with a [`LaplaceProposal`].
#[derive(Clone, Debug)]
pub struct Independence {
    proposal: LaplaceProposal,
    /// The last transition's proposal and its log density, for warm-up to weigh.
    last: Option<(Vec<f64>, f64)>,
    /// The importance log weights of warm-up's proposals, left here by [`IndependenceTuning`]
    /// with the shape it chose, so that the run can judge the proposal before drawing.
    warmup_log_weights: Vec<f64>,
}

impl Independence {
    /// Proposes from `proposal` (its shape as given; [`IndependenceTuning`] resets it).
    pub fn new(proposal: LaplaceProposal) -> Self {
        Self {
            proposal,
            last: None,
            warmup_log_weights: Vec::new(),
        }
    }

    pub fn proposal(&self) -> &LaplaceProposal {
        &self.proposal
    }

    /// log π − log q of every warm-up proposal, q the mixture of the shapes warm-up drew from
    /// (empty without [`IndependenceTuning`] or without a warm-up).
    pub fn warmup_log_weights(&self) -> &[f64] {
        &self.warmup_log_weights
    }
}

/// Fewer warm-up proposals than this, over all chains, are not judged: the generalized Pareto
/// fit behind k̂ takes the largest fifth of the weights, and on fewer than 20 of them its k̂ is
/// mostly its prior (k = 0.5, worth 10 observations).
pub const MIN_JUDGED_PROPOSALS: usize = 100;

/// The Pareto k̂ of the warm-up proposals' importance weights, pooled over `kernels` (the
/// chains of one run, whose warm-ups drew from the same shapes in the same proportions):
/// `None` when they made fewer than [`MIN_JUDGED_PROPOSALS`]. NaN when no proposal had a
/// positive density.
pub fn warmup_khat<'a>(kernels: impl Iterator<Item = &'a Independence>) -> Option<f64> {
    let pooled: Vec<f64> = kernels
        .flat_map(|k| k.warmup_log_weights.iter().copied())
        .collect();
    (pooled.len() >= MIN_JUDGED_PROPOSALS).then(|| psis(&pooled).khat)
}

impl<P: LogDensity> Kernel<P> for Independence {
    fn name(&self) -> String {
        "independence".into()
    }

    fn uses_gradient(&self) -> bool {
        false
    }

    fn step(&mut self, density: &mut P, state: &mut State, rng: &mut ChainRng) -> Transition {
        let x = self.proposal.draw(rng);
        let proposed = proposal_log_density(density, &x)?;
        // The log importance ratios log π − log q at the proposal and at the current state.
        let current = state.log_density - self.proposal.log_density(&state.x);
        let candidate = proposed - self.proposal.log_density(&x);
        let (accept_prob, accepted) = random_walk_decision(candidate, current, rng);
        if accepted {
            state.x.clone_from(&x);
            state.log_density = proposed;
        }
        self.last = Some((x, proposed));
        Ok(Info::single_proposal(
            accept_prob,
            accepted,
            false,
            self.proposal.scale(),
            state.log_density,
        ))
    }
}

/// Warm-up's choice of the proposal's shape among [`CANDIDATES`] by the mean acceptance
/// probability. The kernel must start with the first candidate's shape (see
/// [`IndependenceTuning::start`]); a warm-up too short to try every candidate twice keeps it.
/// It also keeps every warm-up proposal, and leaves their importance weights on the kernel.
#[derive(Clone, Debug, Default)]
pub struct IndependenceTuning {
    accept_sums: Vec<f64>,
    counts: Vec<usize>,
    /// Every warm-up proposal, its log density, and the (ν, s) it was drawn with.
    proposals: Vec<(Vec<f64>, f64, (f64, f64))>,
}

impl IndependenceTuning {
    /// Sets the kernel to the first candidate, as warm-up's first transitions assume.
    pub fn start(kernel: &mut Independence) {
        let (df, scale) = CANDIDATES[0];
        kernel
            .proposal
            .set_shape(df, scale)
            .expect("a valid candidate");
    }

    fn candidate(iteration: usize, n_warmup: usize) -> usize {
        iteration * CANDIDATES.len() / n_warmup
    }

    /// The mean acceptance probability each candidate had in warm-up (NaN for one not tried).
    pub fn acceptance(&self) -> Vec<f64> {
        self.accept_sums
            .iter()
            .zip(&self.counts)
            .map(|(s, &n)| if n == 0 { f64::NAN } else { s / n as f64 })
            .collect()
    }

    /// log π − log q of the proposals, q the mixture of the shapes they were drawn from in the
    /// proportions they were drawn in (a fixed schedule, so the same in every chain). The
    /// mixture, not the shape warm-up then keeps: the draws came from it, so these are valid
    /// importance weights, and they leave out no draw. Its heaviest tails (ν = 5, 1.2 times the
    /// Laplace scale) make them lighter-tailed than the kept shape's would be, so k̂ errs on
    /// the side of trusting the chain (`tests/laplace_samplers.rs`, the friction term).
    fn log_weights(&self, proposal: &LaplaceProposal) -> Vec<f64> {
        let mut components: Vec<(LaplaceProposal, usize)> = Vec::new();
        for &(_, _, (df, scale)) in &self.proposals {
            match components
                .iter_mut()
                .find(|(q, _)| q.df() == df && q.scale() == scale)
            {
                Some((_, n)) => *n += 1,
                None => components.push((
                    proposal
                        .clone()
                        .with_shape(df, scale)
                        .expect("a shape the kernel drew with"),
                    1,
                )),
            }
        }
        let points = self.proposals.iter().map(|(x, lp, _)| (x.as_slice(), *lp));
        mixture_log_weights(points, &components)
    }
}

impl Adaptation<Independence> for IndependenceTuning {
    fn observe(
        &mut self,
        kernel: &mut Independence,
        _: &State,
        info: &Info,
        iteration: usize,
        n_warmup: usize,
    ) {
        if let Some((x, lp)) = kernel.last.take() {
            let shape = (kernel.proposal.df(), kernel.proposal.scale());
            self.proposals.push((x, lp, shape));
        }
        if n_warmup < 2 * CANDIDATES.len() {
            return;
        }
        if self.counts.is_empty() {
            self.accept_sums = vec![0.0; CANDIDATES.len()];
            self.counts = vec![0; CANDIDATES.len()];
        }
        let c = Self::candidate(iteration, n_warmup);
        self.accept_sums[c] += info.accept_stat;
        self.counts[c] += 1;
        if iteration + 1 < n_warmup {
            let (df, scale) = CANDIDATES[Self::candidate(iteration + 1, n_warmup)];
            kernel
                .proposal
                .set_shape(df, scale)
                .expect("a valid candidate");
        }
    }

    fn finish(&mut self, kernel: &mut Independence) {
        kernel.warmup_log_weights = self.log_weights(&kernel.proposal);
        let acceptance = self.acceptance();
        // The first of the best, so that ties resolve the same way on every platform.
        let best = (0..acceptance.len()).fold(None, |best: Option<usize>, i| match best {
            Some(b) if !(acceptance[i] > acceptance[b]) => Some(b),
            _ if acceptance[i].is_nan() => best,
            _ => Some(i),
        });
        let (df, scale) = CANDIDATES[best.unwrap_or(0)];
        kernel
            .proposal
            .set_shape(df, scale)
            .expect("a valid candidate");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnostics::{KHAT_GOOD, KHAT_UNRELIABLE};
    use crate::sampler::driver::{chain_rng, run_chain};
    use crate::sampler::targets::{Gaussian, check_gaussian_moments};
    use crate::sampler::{ChainSettings, NoAdaptation};
    use nalgebra::DMatrix;

    fn kernel_for(target: &Gaussian, shift: f64) -> Independence {
        let precision = target.covariance.clone().try_inverse().unwrap();
        let mean: Vec<f64> = target.mean.iter().map(|m| m + shift).collect();
        Independence::new(LaplaceProposal::new(&mean, &precision).unwrap())
    }

    #[test]
    fn a_correlated_gaussian_is_sampled_with_its_moments_and_nearly_always_accepted() {
        let target = Gaussian::correlated(6, 0.9, 1e3);
        let settings = ChainSettings {
            warmup: INDEPENDENCE_WARMUP,
            draws: 4000,
            keep: None,
        };
        let (mut chains, mut kernels) = (Vec::new(), Vec::new());
        for c in 0..2 {
            let mut kernel = kernel_for(&target, 0.0);
            IndependenceTuning::start(&mut kernel);
            let init: Vec<f64> = target.mean.iter().copied().collect();
            let (out, kernel) = run_chain(
                target.clone(),
                kernel,
                IndependenceTuning::default(),
                &init,
                &settings,
                &mut chain_rng(11, c),
                c,
                None,
            )
            .unwrap();
            // On the exact Gaussian, t proposals accept more the lighter their tails and the
            // closer their scale to the target's.
            let shape = (kernel.proposal().df(), kernel.proposal().scale());
            assert!(shape.0 >= 30.0 && shape.1 == 1.0, "chain {c}: {shape:?}");
            assert!(out.mean_accept_stat > 0.9, "{}", out.mean_accept_stat);
            assert_eq!(out.sampling.gradient_evaluations, 0);
            assert_eq!(out.sampling.density_evaluations, 4000);
            chains.push(out);
            kernels.push(kernel);
        }
        check_gaussian_moments(&chains, &target, 4.0).unwrap();
        // The proposal covers the target: the warm-up's weights are light-tailed.
        let khat = warmup_khat(kernels.iter()).unwrap();
        assert!(khat < KHAT_GOOD, "k̂ = {khat}");
    }

    /// The banana of `importance`'s tests, from its Laplace approximation at the mode: bent,
    /// the t misses the arms and k̂ of the warm-up's weights says so; straight (a Gaussian), it
    /// does not.
    #[test]
    fn warm_up_weighs_every_proposal_and_its_khat_flags_a_bent_banana_only() {
        use crate::sampler::targets::Banana;
        for (bend, flagged) in [(0.0, false), (2.0, true)] {
            let target = Banana { bend, width: 0.3 };
            let precision =
                DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![1.0, 1.0 / 0.09]));
            let settings = ChainSettings {
                warmup: INDEPENDENCE_WARMUP,
                draws: 1,
                keep: None,
            };
            let kernels: Vec<Independence> = (0..4)
                .map(|c| {
                    let proposal = LaplaceProposal::new(&[0.0, -bend], &precision).unwrap();
                    let mut kernel = Independence::new(proposal);
                    IndependenceTuning::start(&mut kernel);
                    let tuning = IndependenceTuning::default();
                    let mut rng = chain_rng(5, c);
                    let init = [0.0, -bend];
                    run_chain(
                        target.clone(),
                        kernel,
                        tuning,
                        &init,
                        &settings,
                        &mut rng,
                        c,
                        None,
                    )
                    .unwrap()
                    .1
                })
                .collect();
            for kernel in &kernels {
                assert_eq!(kernel.warmup_log_weights().len(), INDEPENDENCE_WARMUP);
            }
            let khat = warmup_khat(kernels.iter()).unwrap();
            assert_eq!(khat > KHAT_UNRELIABLE, flagged, "b = {bend}: k̂ = {khat}");
        }
    }

    #[test]
    fn a_warm_up_too_short_to_judge_gives_no_khat() {
        let target = Gaussian::correlated(2, 0.5, 1.0);
        let settings = ChainSettings {
            warmup: MIN_JUDGED_PROPOSALS - 1,
            draws: 10,
            keep: None,
        };
        let mut kernel = kernel_for(&target, 0.0);
        IndependenceTuning::start(&mut kernel);
        let (_, kernel) = run_chain(
            target.clone(),
            kernel,
            IndependenceTuning::default(),
            &[0.0, 0.0],
            &settings,
            &mut chain_rng(2, 0),
            0,
            None,
        )
        .unwrap();
        assert_eq!(kernel.warmup_log_weights().len(), MIN_JUDGED_PROPOSALS - 1);
        assert_eq!(warmup_khat([&kernel].into_iter()), None);
        assert!(warmup_khat([&kernel, &kernel].into_iter()).is_some());
    }

    #[test]
    fn a_misplaced_proposal_still_targets_the_posterior() {
        // Centred one sd off and half as wide: the acceptance step must correct both.
        let target = Gaussian::new(
            vec![0.0, 0.0],
            DMatrix::from_row_slice(2, 2, &[1.0, 0.5, 0.5, 1.0]),
        );
        let precision = target.covariance.clone().try_inverse().unwrap() * 4.0;
        let proposal = LaplaceProposal::new(&[1.0, 0.0], &precision)
            .unwrap()
            .with_shape(3.0, 1.0)
            .unwrap();
        let settings = ChainSettings {
            warmup: 0,
            draws: 20_000,
            keep: None,
        };
        let (out, _) = run_chain(
            target.clone(),
            Independence::new(proposal),
            NoAdaptation,
            &[0.0, 0.0],
            &settings,
            &mut chain_rng(5, 0),
            0,
            None,
        )
        .unwrap();
        assert!(out.mean_accept_stat < 0.9, "{}", out.mean_accept_stat);
        check_gaussian_moments(&[out], &target, 4.0).unwrap();
    }

    #[test]
    fn the_same_seed_gives_the_same_draws() {
        let target = Gaussian::correlated(3, 0.5, 10.0);
        let run = || {
            let mut kernel = kernel_for(&target, 0.1);
            IndependenceTuning::start(&mut kernel);
            let settings = ChainSettings {
                warmup: INDEPENDENCE_WARMUP,
                draws: 100,
                keep: None,
            };
            let init: Vec<f64> = target.mean.iter().copied().collect();
            let (out, _) = run_chain(
                target.clone(),
                kernel,
                IndependenceTuning::default(),
                &init,
                &settings,
                &mut chain_rng(3, 1),
                1,
                None,
            )
            .unwrap();
            out.draws
        };
        assert_eq!(run(), run());
    }
}
