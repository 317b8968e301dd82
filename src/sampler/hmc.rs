//! Static HMC: a fixed integration time (jittered), then a Metropolis correction.

use rand::RngExt;
use serde::{Deserialize, Serialize};

use super::adapt::AdaptationState;
use super::hamiltonian::{Dynamics, HamiltonianKernel, PhasePoint, energy_after_leapfrog};
use super::{ChainRng, Info, Kernel, State, Transition};
use crate::density::LogDensity;

/// Settings of static HMC.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HmcSettings {
    /// Integration time T in the metric's units (a whitened target has unit scale); each
    /// transition takes ceil(T/ε) leapfrog steps.
    pub integration_time: f64,
    /// Draws each transition's integration time uniformly from T·[1 − jitter, 1 + jitter].
    pub jitter: f64,
    /// An energy error above this marks the transition divergent.
    pub max_energy_error: f64,
    /// A cap on leapfrog steps per transition, so that a collapsing step size slows a chain
    /// down instead of hanging it.
    pub max_steps: u32,
}

impl Default for HmcSettings {
    /// A quarter period of a unit-scale Gaussian, jittered by half: on a target the metric
    /// whitens, consecutive draws are nearly uncorrelated. (Stan's default 2π is a full
    /// period, which brings a Gaussian back where it started; the jitter breaks such
    /// resonances in the directions the metric does not whiten.)
    fn default() -> Self {
        Self {
            integration_time: std::f64::consts::FRAC_PI_2,
            jitter: 0.5,
            max_energy_error: 1000.0,
            max_steps: 1024,
        }
    }
}

impl HmcSettings {
    pub fn validate(&self) -> Result<(), String> {
        if !(self.integration_time > 0.0 && self.integration_time.is_finite()) {
            return Err(format!(
                "the integration time must be positive, got {}",
                self.integration_time
            ));
        }
        if !(0.0..1.0).contains(&self.jitter) {
            return Err(format!(
                "the integration-time jitter must be in [0, 1), got {}",
                self.jitter
            ));
        }
        if !(self.max_energy_error > 0.0) {
            return Err(format!(
                "the divergence threshold must be positive, got {}",
                self.max_energy_error
            ));
        }
        if self.max_steps == 0 {
            return Err("the leapfrog step cap must be at least 1".into());
        }
        Ok(())
    }
}
/// Static HMC with a Euclidean metric.
#[derive(Clone, Debug)]
pub struct Hmc {
    settings: HmcSettings,
    dynamics: Dynamics,
    start: PhasePoint,
    z: PhasePoint,
}

impl Hmc {
    /// A kernel whose step size is still unknown: Stan's heuristic searches one before the
    /// first transition, from ε = 1.
    pub fn new(
        metric: crate::sampler::metric::Metric,
        settings: HmcSettings,
    ) -> Result<Self, String> {
        settings.validate()?;
        let d = metric.dim();
        Ok(Self {
            settings,
            dynamics: Dynamics::new(metric),
            start: PhasePoint::new(d),
            z: PhasePoint::new(d),
        })
    }

    /// A kernel tuned earlier (e.g. reloaded with `--load-adaptation`): no search.
    pub fn from_adaptation(state: &AdaptationState, settings: HmcSettings) -> Result<Self, String> {
        let mut kernel = Self::new(state.metric.clone(), settings)?;
        kernel.dynamics = Dynamics::tuned(state);
        Ok(kernel)
    }

    pub fn settings(&self) -> &HmcSettings {
        &self.settings
    }
}

impl HamiltonianKernel for Hmc {
    fn dynamics(&self) -> &Dynamics {
        &self.dynamics
    }
    fn dynamics_mut(&mut self) -> &mut Dynamics {
        &mut self.dynamics
    }
}

impl<P: LogDensity> Kernel<P> for Hmc {
    fn name(&self) -> String {
        format!("hmc-{}", self.metric().kind().suffix())
    }

    fn uses_gradient(&self) -> bool {
        true
    }

    fn step(&mut self, density: &mut P, state: &mut State, rng: &mut ChainRng) -> Transition {
        self.dynamics.prepare(density, state, rng, &mut self.z)?;
        let eps = self.dynamics.step_size;
        let metric = &self.dynamics.metric;
        let s = &self.settings;
        let time = s.integration_time * (1.0 + s.jitter * (2.0 * rng.random::<f64>() - 1.0));
        let n_steps = ((time / eps).ceil().max(1.0)).min(s.max_steps as f64) as u32;

        self.start.load_state(state);
        self.start.refresh_momentum(metric, rng);
        let h0 = self.start.energy();
        self.z.copy_from(&self.start);
        let mut h = h0;
        let mut taken = 0;
        while taken < n_steps {
            h = energy_after_leapfrog(density, metric, &mut self.z, eps)?;
            taken += 1;
            if h - h0 > s.max_energy_error {
                break;
            }
        }
        let divergent = !(h - h0 <= s.max_energy_error);
        let accept_stat = if divergent {
            0.0
        } else {
            (h0 - h).exp().min(1.0)
        };
        let accepted = !divergent && rng.random::<f64>() < accept_stat;
        if accepted {
            self.z.store_state(state);
        }
        Ok(Info {
            accept_stat,
            accepted,
            divergent,
            step_size: eps,
            tree_depth: 0,
            n_steps: taken,
            energy: if accepted { h } else { h0 },
            block_accepted: Vec::new(),
        })
    }
}
