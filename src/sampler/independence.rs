//! Independence Metropolis–Hastings: every proposal a fresh draw from the Laplace approximation
//! as a multivariate Student-t ([`LaplaceProposal`]), accepted with probability
//! min(1, π(x′)q(x)/(π(x)q(x′))). Where the posterior is close to its Laplace approximation
//! nearly every proposal is accepted and the draws are nearly independent, each for one plain
//! density evaluation and no gradient (Tierney 1994, §2.3.3; Robert & Casella, §7.4).
//!
//! Warm-up tunes the proposal's degrees of freedom and scale by the acceptance rate: it tries
//! each pair of [`CANDIDATES`] for an equal share of the warm-up and keeps the one whose
//! transitions had the highest mean acceptance probability.

use super::proposal::LaplaceProposal;
use super::{
    Adaptation, ChainRng, Info, Kernel, State, Transition, proposal_log_density,
    random_walk_decision,
};
use crate::density::LogDensity;

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
}

impl Independence {
    /// Proposes from `proposal` (its shape as given; [`IndependenceTuning`] resets it).
    pub fn new(proposal: LaplaceProposal) -> Self {
        Self { proposal }
    }

    pub fn proposal(&self) -> &LaplaceProposal {
        &self.proposal
    }
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
            state.x = x;
            state.log_density = proposed;
        }
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
#[derive(Clone, Debug, Default)]
pub struct IndependenceTuning {
    accept_sums: Vec<f64>,
    counts: Vec<usize>,
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
        let mut chains = Vec::new();
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
        }
        check_gaussian_moments(&chains, &target, 4.0).unwrap();
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
