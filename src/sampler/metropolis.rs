//! The paper's sampler: Metropolis-within-Gibbs with a Gaussian random walk per block, tuned
//! as PyMC3 (3.x, 2018) tuned `pm.Metropolis`.
//!
//! PyMC3 gives every free variable its own Metropolis step (`default_blocked = False`), so one
//! sweep proposes R, log σ_I, log σ_ω, the coefficient vector a_I and a_ω in turn, each with an
//! isotropic normal of standard deviation `scaling[b]` (S = ones, initial scaling 1). Its tuning
//! multiplies the scaling by a fixed factor every 100 steps from the acceptance rate of those
//! steps. This is kept deliberately faithful, weaknesses included, so that the paper's results
//! can be reproduced and compared against better samplers.

use std::ops::Range;

use rand_distr::{Distribution, StandardNormal};

use super::{
    Adaptation, ChainRng, Info, Kernel, State, Transition, proposal_log_density,
    random_walk_decision,
};
use crate::density::{DensityError, LogDensity};

/// Variable-at-a-time Gaussian random-walk Metropolis over the density's blocks.
#[derive(Clone, Debug)]
pub struct Metropolis {
    blocks: Vec<Range<usize>>,
    scaling: Vec<f64>,
    /// Always equal to the state between blocks, so a block proposal touches only its own
    /// coordinates and a rejection restores only those.
    proposal: Vec<f64>,
}

impl Metropolis {
    /// One block per group of `density.blocks()`, each with PyMC3's initial scaling 1.
    pub fn for_density<P: LogDensity>(density: &P) -> Self {
        Self::with_blocks(density.blocks())
    }

    /// The given blocks, each with PyMC3's initial scaling 1.
    pub fn with_blocks(blocks: Vec<Range<usize>>) -> Self {
        let scaling = vec![1.0; blocks.len()];
        Self {
            blocks,
            scaling,
            proposal: Vec::new(),
        }
    }

    /// Sets every block's proposal standard deviation (e.g. reloaded from a tuned run).
    pub fn with_scaling(mut self, scaling: Vec<f64>) -> Result<Self, String> {
        if scaling.len() != self.blocks.len() {
            return Err(format!(
                "{} scalings for {} blocks",
                scaling.len(),
                self.blocks.len()
            ));
        }
        if let Some(s) = scaling.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
            return Err(format!(
                "a proposal scaling must be positive and finite, got {s}"
            ));
        }
        self.scaling = scaling;
        Ok(self)
    }

    pub fn blocks(&self) -> &[Range<usize>] {
        &self.blocks
    }

    /// Proposal standard deviation per block.
    pub fn scaling(&self) -> &[f64] {
        &self.scaling
    }

    fn check_blocks(&self, dim: usize) -> Result<(), DensityError> {
        if self.blocks.is_empty() {
            return Err(DensityError::fatal(
                "the Metropolis sampler has no blocks to update",
            ));
        }
        for b in &self.blocks {
            if b.is_empty() || b.end > dim {
                return Err(DensityError::fatal(format!(
                    "block {}..{} does not fit a density of dimension {dim}",
                    b.start, b.end
                )));
            }
        }
        Ok(())
    }
}

impl<P: LogDensity> Kernel<P> for Metropolis {
    fn name(&self) -> String {
        "metropolis".into()
    }

    fn uses_gradient(&self) -> bool {
        false
    }

    fn init_state(&mut self, density: &mut P, x: &[f64]) -> Result<State, DensityError> {
        self.check_blocks(x.len())?;
        if x.len() != density.dim() {
            return Err(DensityError::fatal(format!(
                "initial point of dimension {} for a density of dimension {}",
                x.len(),
                density.dim()
            )));
        }
        Ok(State {
            x: x.to_vec(),
            log_density: density.log_density(x)?,
            gradient: Vec::new(),
        })
    }

    fn step(&mut self, density: &mut P, state: &mut State, rng: &mut ChainRng) -> Transition {
        self.check_blocks(state.x.len())?;
        self.proposal.clear();
        self.proposal.extend_from_slice(&state.x);
        let mut block_accepted = Vec::with_capacity(self.blocks.len());
        let mut accept_sum = 0.0;
        for (block, &scale) in self.blocks.iter().zip(&self.scaling) {
            for v in &mut self.proposal[block.clone()] {
                let z: f64 = StandardNormal.sample(rng);
                *v += scale * z;
            }
            let proposed = proposal_log_density(density, &self.proposal)?;
            let (accept_prob, accepted) = random_walk_decision(proposed, state.log_density, rng);
            if accepted {
                state.x[block.clone()].copy_from_slice(&self.proposal[block.clone()]);
                state.log_density = proposed;
            } else {
                self.proposal[block.clone()].copy_from_slice(&state.x[block.clone()]);
            }
            accept_sum += accept_prob;
            block_accepted.push(accepted);
        }
        Ok(Info {
            accept_stat: accept_sum / self.blocks.len() as f64,
            accepted: block_accepted.iter().any(|&a| a),
            divergent: false,
            step_size: self.scaling[0],
            tree_depth: 0,
            n_steps: self.blocks.len() as u32,
            energy: -state.log_density,
            block_accepted,
        })
    }
}

/// PyMC3's `tune()`: the factor applied to a block's scaling after a tuning interval with this
/// acceptance rate. The comparisons run in PyMC3's order, the three "too low" tests first, then
/// "too high" from the most extreme down, so each rate falls into exactly one band.
pub fn pymc3_tuning_factor(acceptance_rate: f64) -> f64 {
    if acceptance_rate < 0.001 {
        0.1
    } else if acceptance_rate < 0.05 {
        0.5
    } else if acceptance_rate < 0.2 {
        0.9
    } else if acceptance_rate > 0.95 {
        10.0
    } else if acceptance_rate > 0.75 {
        2.0
    } else if acceptance_rate > 0.5 {
        1.1
    } else {
        1.0
    }
}

/// PyMC3's tuning of [`Metropolis`]: every `interval` warm-up sweeps, each block's scaling is
/// multiplied by [`pymc3_tuning_factor`] of that block's acceptance rate over the interval.
///
/// PyMC3 tunes at the start of a step once `interval` steps have passed, and switches tuning off
/// before the first draw; so with 500 tuning steps it tunes 4 times (before steps 100…400), not
/// after step 500. The same happens here: no tuning on the last warm-up iteration.
#[derive(Clone, Debug)]
pub struct PyMc3Tuning {
    interval: usize,
    accepted: Vec<u32>,
    steps: usize,
}

impl Default for PyMc3Tuning {
    fn default() -> Self {
        Self {
            interval: 100,
            accepted: Vec::new(),
            steps: 0,
        }
    }
}

impl PyMc3Tuning {
    /// PyMC3's default `tune_interval = 100`.
    pub fn new() -> Self {
        Self::default()
    }

    pub fn with_interval(interval: usize) -> Result<Self, String> {
        if interval == 0 {
            return Err("the tuning interval must be at least 1".into());
        }
        Ok(Self {
            interval,
            ..Self::default()
        })
    }

    pub fn interval(&self) -> usize {
        self.interval
    }
}

impl Adaptation<Metropolis> for PyMc3Tuning {
    fn observe(
        &mut self,
        kernel: &mut Metropolis,
        _: &State,
        info: &Info,
        iteration: usize,
        n_warmup: usize,
    ) {
        let n_blocks = kernel.blocks.len();
        if self.accepted.len() != n_blocks {
            self.accepted = vec![0; n_blocks];
            self.steps = 0;
        }
        for (count, &a) in self.accepted.iter_mut().zip(&info.block_accepted) {
            *count += a as u32;
        }
        self.steps += 1;
        if self.steps < self.interval {
            return;
        }
        if iteration + 1 < n_warmup {
            for (scale, count) in kernel.scaling.iter_mut().zip(&self.accepted) {
                *scale *= pymc3_tuning_factor(*count as f64 / self.interval as f64);
            }
        }
        self.accepted.fill(0);
        self.steps = 0;
    }

    fn finish(&mut self, _: &mut Metropolis) {
        self.accepted.fill(0);
        self.steps = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tuning_table_is_pymc3s_with_its_comparison_order() {
        let cases = [
            (0.0, 0.1),
            (0.0009, 0.1),
            (0.001, 0.5),
            (0.049, 0.5),
            (0.05, 0.9),
            (0.199, 0.9),
            (0.2, 1.0),
            (0.35, 1.0),
            (0.5, 1.0),
            (0.51, 1.1),
            (0.75, 1.1),
            (0.76, 2.0),
            (0.95, 2.0),
            (0.96, 10.0),
            (1.0, 10.0),
        ];
        for (rate, factor) in cases {
            assert_eq!(pymc3_tuning_factor(rate), factor, "acceptance rate {rate}");
        }
    }

    fn info(block_accepted: Vec<bool>) -> Info {
        Info {
            block_accepted,
            ..Info::default()
        }
    }

    #[test]
    fn each_block_is_tuned_from_its_own_acceptance_over_the_interval() {
        let mut kernel = Metropolis::with_blocks(vec![0..1, 1..3, 3..4]);
        let mut tuning = PyMc3Tuning::new();
        let state = State {
            x: vec![0.0; 4],
            log_density: 0.0,
            gradient: Vec::new(),
        };
        // Block 0 never moves, block 1 moves 30 times in 100, block 2 always.
        for i in 0..100 {
            tuning.observe(
                &mut kernel,
                &state,
                &info(vec![false, i % 10 < 3, true]),
                i,
                500,
            );
        }
        assert_eq!(kernel.scaling(), &[0.1, 1.0, 10.0]);
        // Nothing changes in the middle of an interval.
        for i in 100..150 {
            tuning.observe(&mut kernel, &state, &info(vec![true, true, true]), i, 500);
        }
        assert_eq!(kernel.scaling(), &[0.1, 1.0, 10.0]);
    }

    #[test]
    fn as_in_pymc3_500_tuning_steps_tune_four_times() {
        let mut kernel = Metropolis::with_blocks(vec![0..1, 1..2]);
        let mut tuning = PyMc3Tuning::new();
        let state = State {
            x: vec![0.0; 2],
            log_density: 0.0,
            gradient: Vec::new(),
        };
        for i in 0..500 {
            tuning.observe(&mut kernel, &state, &info(vec![false, true]), i, 500);
        }
        tuning.finish(&mut kernel);
        // Before steps 100, 200, 300 and 400; the fifth interval ends with the warm-up.
        assert!(
            (kernel.scaling()[0] / 1e-4 - 1.0).abs() < 1e-12,
            "{}",
            kernel.scaling()[0]
        );
        assert!(
            (kernel.scaling()[1] / 1e4 - 1.0).abs() < 1e-12,
            "{}",
            kernel.scaling()[1]
        );
    }
}
