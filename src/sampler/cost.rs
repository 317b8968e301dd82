//! What one phase of a run cost (the MAP, a chain's warm-up, its sampling): its time and the
//! evaluations it made. One type for every phase, so that a chain's and a run's costs are
//! summed, compared and reported the same way.

use std::iter::Sum;
use std::ops::Add;

use serde::Serialize;

use super::clock::Elapsed;
use crate::density::{Counted, LogDensity, SolveCount};

/// A phase's wall time, the CPU time of the thread that ran it, and its evaluations.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct PhaseCost {
    pub wall_seconds: f64,
    pub cpu_seconds: f64,
    pub density_evaluations: u64,
    pub gradient_evaluations: u64,
    /// Fisher metrics (or observed informations) evaluated: Fisher-MALA evaluates one per
    /// proposal, the MAP one for its Hessian.
    pub metric_evaluations: u64,
    /// The ODE solves behind those evaluations (fewer than evaluations where the density's
    /// cache served one).
    pub solves: SolveCount,
}

impl PhaseCost {
    /// A phase that took `time`, with every evaluation `density` has counted so far.
    pub fn counted<P: LogDensity>(time: Elapsed, density: &Counted<P>) -> Self {
        Self {
            wall_seconds: time.wall_seconds,
            cpu_seconds: time.cpu_seconds,
            density_evaluations: density.density_evaluations,
            gradient_evaluations: density.gradient_evaluations,
            metric_evaluations: density.metric_evaluations,
            solves: density.solves(),
        }
    }

    /// This phase without the evaluations of `earlier`, which the same counter counted first
    /// (a chain counts its warm-up and its sampling on one density); the time is this phase's.
    pub fn after(self, earlier: &PhaseCost) -> Self {
        Self {
            density_evaluations: self.density_evaluations - earlier.density_evaluations,
            gradient_evaluations: self.gradient_evaluations - earlier.gradient_evaluations,
            metric_evaluations: self.metric_evaluations - earlier.metric_evaluations,
            solves: self.solves - earlier.solves,
            ..self
        }
    }

    /// The phase's wall and CPU seconds.
    pub fn time(&self) -> Elapsed {
        Elapsed {
            wall_seconds: self.wall_seconds,
            cpu_seconds: self.cpu_seconds,
        }
    }
}

/// Two phases' costs together: wall time and CPU time alike are summed, so that the chains'
/// phases add up to their whole cost whatever the thread count.
impl Add for PhaseCost {
    type Output = Self;

    fn add(self, other: Self) -> Self {
        Self {
            wall_seconds: self.wall_seconds + other.wall_seconds,
            cpu_seconds: self.cpu_seconds + other.cpu_seconds,
            density_evaluations: self.density_evaluations + other.density_evaluations,
            gradient_evaluations: self.gradient_evaluations + other.gradient_evaluations,
            metric_evaluations: self.metric_evaluations + other.metric_evaluations,
            solves: self.solves + other.solves,
        }
    }
}

impl Sum for PhaseCost {
    fn sum<I: Iterator<Item = Self>>(iter: I) -> Self {
        iter.fold(Self::default(), Add::add)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_later_phase_counts_only_its_own_evaluations() {
        let mut density = Counted::new(crate::sampler::targets::Gaussian::correlated(2, 0.0, 1.0));
        density.gradient_evaluations = 7;
        density.metric_evaluations = 2;
        let time = |s| Elapsed {
            wall_seconds: s,
            cpu_seconds: s / 2.0,
        };
        let warmup = PhaseCost::counted(time(1.0), &density);
        density.density_evaluations = 3;
        density.gradient_evaluations = 10;
        let sampling = PhaseCost::counted(time(4.0), &density).after(&warmup);
        assert_eq!(
            sampling,
            PhaseCost {
                wall_seconds: 4.0,
                cpu_seconds: 2.0,
                density_evaluations: 3,
                gradient_evaluations: 3,
                metric_evaluations: 0,
                solves: SolveCount::default(),
            }
        );
        let both: PhaseCost = [warmup, sampling].into_iter().sum();
        assert_eq!(both.time(), time(5.0));
        assert_eq!(both.gradient_evaluations, 10);
    }
}
