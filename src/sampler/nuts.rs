//! The No-U-Turn sampler as in Stan ≥ 2.18 (Betancourt 2017, "A conceptual introduction to
//! Hamiltonian Monte Carlo", appendix A): the trajectory doubles in a random direction until
//! it makes a U-turn, the draw is taken multinomially along it (biased towards the newest
//! subtree across doublings, uniform-progressive within one), and the generalized U-turn
//! criterion is also checked across the two halves of every merged subtree, which catches the
//! U-turns that the endpoints alone miss on near-Gaussian targets.
//!
//! All vectors live in a workspace allocated with the kernel: one scratch frame per tree
//! depth, so the recursion allocates nothing per leapfrog step.

use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use super::adapt::AdaptationState;
use super::hamiltonian::{Dynamics, HamiltonianKernel, PhasePoint, energy_after_leapfrog};
use super::metric::Metric;
use super::{ChainRng, Info, Kernel, State, Transition};
use crate::density::{DensityError, LogDensity};

/// Depths beyond this would take over a billion leapfrog steps per draw.
const DEEPEST: u32 = 30;

/// Settings of NUTS.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NutsSettings {
    /// At most 2^max_depth − 1 leapfrog steps per transition.
    pub max_depth: u32,
    /// An energy error above this marks the transition divergent.
    pub max_energy_error: f64,
}

impl Default for NutsSettings {
    fn default() -> Self {
        Self {
            max_depth: 10,
            max_energy_error: 1000.0,
        }
    }
}

impl NutsSettings {
    pub fn validate(&self) -> Result<(), String> {
        if !(1..=DEEPEST).contains(&self.max_depth) {
            return Err(format!(
                "the maximum tree depth must be in 1..={DEEPEST}, got {}",
                self.max_depth
            ));
        }
        if !(self.max_energy_error > 0.0) {
            return Err(format!(
                "the divergence threshold must be positive, got {}",
                self.max_energy_error
            ));
        }
        Ok(())
    }
}

/// NUTS with a Euclidean metric.
#[derive(Clone, Debug)]
pub struct Nuts {
    settings: NutsSettings,
    dynamics: Dynamics,
    work: Workspace,
}

impl Nuts {
    /// A kernel whose step size is still unknown: Stan's heuristic searches one before the
    /// first transition, from ε = 1.
    pub fn new(metric: Metric, settings: NutsSettings) -> Result<Self, String> {
        settings.validate()?;
        let work = Workspace::new(metric.dim(), settings.max_depth as usize);
        Ok(Self {
            settings,
            dynamics: Dynamics::new(metric),
            work,
        })
    }

    /// A kernel tuned earlier (e.g. reloaded with `--load-adaptation`): no search.
    pub fn from_adaptation(
        state: &AdaptationState,
        settings: NutsSettings,
    ) -> Result<Self, String> {
        let mut kernel = Self::new(state.metric.clone(), settings)?;
        kernel.dynamics = Dynamics::tuned(state);
        Ok(kernel)
    }

    pub fn settings(&self) -> &NutsSettings {
        &self.settings
    }
}

impl HamiltonianKernel for Nuts {
    fn dynamics(&self) -> &Dynamics {
        &self.dynamics
    }
    fn dynamics_mut(&mut self) -> &mut Dynamics {
        &mut self.dynamics
    }
}

/// One end of the trajectory as it grows in one direction of time: the phase point at its
/// tip, the momentum and velocity (M⁻¹p, "sharp") at its outer end and at the end that touches
/// the other side, and Σp over it.
#[derive(Clone, Debug)]
struct Side {
    z: PhasePoint,
    p_outer: Vec<f64>,
    sharp_outer: Vec<f64>,
    p_inner: Vec<f64>,
    sharp_inner: Vec<f64>,
    rho: Vec<f64>,
}

impl Side {
    fn new(d: usize) -> Self {
        Self {
            z: PhasePoint::new(d),
            p_outer: vec![0.0; d],
            sharp_outer: vec![0.0; d],
            p_inner: vec![0.0; d],
            sharp_inner: vec![0.0; d],
            rho: vec![0.0; d],
        }
    }

    /// Both ends at the side's tip: the trajectory is still the single point it starts at.
    fn collapse(&mut self) {
        for buffer in [&mut self.p_outer, &mut self.p_inner] {
            buffer.copy_from_slice(&self.z.p);
        }
        for buffer in [&mut self.sharp_outer, &mut self.sharp_inner] {
            buffer.copy_from_slice(&self.z.velocity);
        }
    }
}

const FORWARD: usize = 0;
const BACKWARD: usize = 1;

/// Scratch space of one transition: the forward and backward sides, the draw and the
/// proposal, Σp over the whole trajectory, and the frames of the recursion.
#[derive(Clone, Debug)]
struct Workspace {
    sides: [Side; 2],
    z_sample: PhasePoint,
    z_propose: PhasePoint,
    rho: Vec<f64>,
    /// `frames[k]` serves a subtree of depth k + 1 (the deepest, max_depth − 1, is the last
    /// doubling); the two halves it merges are built one after the other with `frames[..k]`,
    /// so frames never alias.
    frames: Vec<Frame>,
}

/// What a subtree of depth ≥ 1 keeps while building its halves, the "initial" half (nearer
/// the start of the trajectory) and the "final" half.
#[derive(Clone, Debug)]
struct Frame {
    rho_init: Vec<f64>,
    rho_final: Vec<f64>,
    p_init_end: Vec<f64>,
    sharp_init_end: Vec<f64>,
    p_final_beg: Vec<f64>,
    sharp_final_beg: Vec<f64>,
    propose_final: PhasePoint,
}

impl Workspace {
    fn new(d: usize, max_depth: usize) -> Self {
        let v = || vec![0.0; d];
        Self {
            sides: [Side::new(d), Side::new(d)],
            z_sample: PhasePoint::new(d),
            z_propose: PhasePoint::new(d),
            rho: v(),
            frames: (1..max_depth)
                .map(|_| Frame {
                    rho_init: v(),
                    rho_final: v(),
                    p_init_end: v(),
                    sharp_init_end: v(),
                    p_final_beg: v(),
                    sharp_final_beg: v(),
                    propose_final: PhasePoint::new(d),
                })
                .collect(),
        }
    }
}

/// Where `build_tree` writes what its caller keeps of a subtree, in whichever buffers the
/// caller holds them.
struct Subtree<'a> {
    /// The multinomial draw from the subtree.
    propose: &'a mut PhasePoint,
    /// Momentum and velocity at the end nearer the trajectory's start…
    p_beg: &'a mut [f64],
    sharp_beg: &'a mut [f64],
    /// …and at the far end.
    p_end: &'a mut [f64],
    sharp_end: &'a mut [f64],
    /// Σp over the subtree.
    rho: &'a mut [f64],
    /// log Σ exp(H0 − H) over the subtree.
    log_weight: &'a mut f64,
}

/// What stays fixed, or accumulates over the whole trajectory, while subtrees are built.
struct Trajectory<'a, P> {
    density: &'a mut P,
    metric: &'a Metric,
    rng: &'a mut ChaCha8Rng,
    /// Signed step: negative when growing backwards in time.
    step: f64,
    h0: f64,
    max_energy_error: f64,
    n_leapfrog: u32,
    /// Σ min(1, exp(H0 − H)) over every leapfrog step, rejected subtrees included (Stan's
    /// accept_stat, which dual averaging tunes).
    sum_metro_prob: f64,
    divergent: bool,
}

impl<P: LogDensity> Trajectory<'_, P> {
    /// Grows a subtree of 2^depth leapfrog steps from `z` (left at the subtree's far end) and
    /// fills `out`. Returns whether the subtree is valid: no divergence and no U-turn inside.
    fn build_tree(
        &mut self,
        frames: &mut [Frame],
        z: &mut PhasePoint,
        depth: usize,
        out: Subtree<'_>,
    ) -> Result<bool, DensityError> {
        if depth == 0 {
            let h = energy_after_leapfrog(self.density, self.metric, z, self.step)?;
            self.n_leapfrog += 1;
            if !(h - self.h0 <= self.max_energy_error) {
                self.divergent = true;
            }
            *out.log_weight = self.h0 - h;
            self.sum_metro_prob += (self.h0 - h).exp().min(1.0);
            out.propose.copy_from(z);
            out.rho.copy_from_slice(&z.p);
            out.p_beg.copy_from_slice(&z.p);
            out.p_end.copy_from_slice(&z.p);
            out.sharp_beg.copy_from_slice(&z.velocity);
            out.sharp_end.copy_from_slice(&z.velocity);
            return Ok(!self.divergent);
        }

        let (lower, this) = frames.split_at_mut(depth - 1);
        let Frame {
            rho_init,
            rho_final,
            p_init_end,
            sharp_init_end,
            p_final_beg,
            sharp_final_beg,
            propose_final,
        } = &mut this[0];

        let mut log_weight_init = f64::NEG_INFINITY;
        let init = Subtree {
            propose: &mut *out.propose,
            p_beg: &mut *out.p_beg,
            sharp_beg: &mut *out.sharp_beg,
            p_end: p_init_end,
            sharp_end: sharp_init_end,
            rho: rho_init,
            log_weight: &mut log_weight_init,
        };
        if !self.build_tree(lower, z, depth - 1, init)? {
            return Ok(false);
        }

        let mut log_weight_final = f64::NEG_INFINITY;
        let last = Subtree {
            propose: propose_final,
            p_beg: p_final_beg,
            sharp_beg: sharp_final_beg,
            p_end: &mut *out.p_end,
            sharp_end: &mut *out.sharp_end,
            rho: rho_final,
            log_weight: &mut log_weight_final,
        };
        if !self.build_tree(lower, z, depth - 1, last)? {
            return Ok(false);
        }

        // Within a subtree the proposal is uniform-progressive: the final half wins in
        // proportion to its weight.
        *out.log_weight = log_sum_exp(log_weight_init, log_weight_final);
        if self.rng.random::<f64>() < (log_weight_final - *out.log_weight).exp() {
            out.propose.copy_from(propose_final);
        }
        for ((r, a), b) in out
            .rho
            .iter_mut()
            .zip(rho_init.iter())
            .zip(rho_final.iter())
        {
            *r = a + b;
        }
        Ok(no_u_turn(out.sharp_beg, out.sharp_end, rho_init, rho_final)
            && no_u_turn(out.sharp_beg, sharp_final_beg, rho_init, p_final_beg)
            && no_u_turn(sharp_init_end, out.sharp_end, rho_final, p_init_end))
    }
}

/// The generalized U-turn criterion over a stretch of trajectory whose summed momentum is
/// `rho_a + rho_b`: both end velocities still point along it.
fn no_u_turn(sharp_minus: &[f64], sharp_plus: &[f64], rho_a: &[f64], rho_b: &[f64]) -> bool {
    let (mut minus, mut plus) = (0.0, 0.0);
    for i in 0..rho_a.len() {
        let rho = rho_a[i] + rho_b[i];
        minus += sharp_minus[i] * rho;
        plus += sharp_plus[i] * rho;
    }
    minus > 0.0 && plus > 0.0
}

fn log_sum_exp(a: f64, b: f64) -> f64 {
    let m = a.max(b);
    if m == f64::NEG_INFINITY {
        m
    } else if m == f64::INFINITY {
        f64::INFINITY
    } else {
        m + ((a - m).exp() + (b - m).exp()).ln()
    }
}

impl<P: LogDensity> Kernel<P> for Nuts {
    fn name(&self) -> String {
        format!("nuts-{}", self.metric().kind().suffix())
    }

    fn uses_gradient(&self) -> bool {
        true
    }

    fn step(&mut self, density: &mut P, state: &mut State, rng: &mut ChainRng) -> Transition {
        let w = &mut self.work;
        let start = &mut w.sides[FORWARD].z;
        self.dynamics.prepare(density, state, rng, start)?;
        let eps = self.dynamics.step_size;
        let metric = &self.dynamics.metric;

        start.load_state(state);
        start.refresh_momentum(metric, rng);
        let h0 = start.energy();
        w.z_sample.copy_from(start);
        w.rho.copy_from_slice(&start.p);
        let [forward, backward] = &mut w.sides;
        backward.z.copy_from(&forward.z);
        forward.collapse();
        backward.collapse();

        let mut trajectory = Trajectory {
            density,
            metric,
            rng,
            step: eps,
            h0,
            max_energy_error: self.settings.max_energy_error,
            n_leapfrog: 0,
            sum_metro_prob: 0.0,
            divergent: false,
        };
        // The initial point has weight exp(H0 − H0) = 1.
        let mut log_sum_weight = 0.0;
        let mut depth = 0;
        let mut moved = false;
        while depth < self.settings.max_depth {
            let mut log_weight_subtree = f64::NEG_INFINITY;
            let direction = if trajectory.rng.random::<f64>() > 0.5 {
                FORWARD
            } else {
                BACKWARD
            };
            // The old trajectory becomes the other side; the end of it that faces the
            // growing side is where the new subtree starts.
            let [forward, backward] = &mut w.sides;
            let (grow, other) = if direction == FORWARD {
                (forward, backward)
            } else {
                (backward, forward)
            };
            other.rho.copy_from_slice(&w.rho);
            other.p_inner.copy_from_slice(&grow.p_outer);
            other.sharp_inner.copy_from_slice(&grow.sharp_outer);
            trajectory.step = if direction == FORWARD { eps } else { -eps };
            let out = Subtree {
                propose: &mut w.z_propose,
                p_beg: &mut grow.p_inner,
                sharp_beg: &mut grow.sharp_inner,
                p_end: &mut grow.p_outer,
                sharp_end: &mut grow.sharp_outer,
                rho: &mut grow.rho,
                log_weight: &mut log_weight_subtree,
            };
            let valid = trajectory.build_tree(&mut w.frames, &mut grow.z, depth as usize, out)?;
            if !valid {
                break;
            }
            depth += 1;

            // Across doublings the proposal is biased towards the new subtree, which moves
            // the draw away from the start more often than uniform sampling would.
            if log_weight_subtree > log_sum_weight
                || trajectory.rng.random::<f64>() < (log_weight_subtree - log_sum_weight).exp()
            {
                w.z_sample.copy_from(&w.z_propose);
                moved = true;
            }
            log_sum_weight = log_sum_exp(log_sum_weight, log_weight_subtree);

            let (fwd, bck) = (&w.sides[FORWARD], &w.sides[BACKWARD]);
            for ((r, b), f) in w.rho.iter_mut().zip(&bck.rho).zip(&fwd.rho) {
                *r = b + f;
            }
            // The whole trajectory, and each side merged with the first point of the other.
            let persists = no_u_turn(&bck.sharp_outer, &fwd.sharp_outer, &bck.rho, &fwd.rho)
                && no_u_turn(&bck.sharp_outer, &fwd.sharp_inner, &bck.rho, &fwd.p_inner)
                && no_u_turn(&bck.sharp_inner, &fwd.sharp_outer, &fwd.rho, &bck.p_inner);
            if !persists {
                break;
            }
        }

        w.z_sample.store_state(state);
        Ok(Info {
            accept_stat: trajectory.sum_metro_prob / trajectory.n_leapfrog as f64,
            accepted: moved,
            divergent: trajectory.divergent,
            step_size: eps,
            tree_depth: depth,
            n_steps: trajectory.n_leapfrog,
            energy: w.z_sample.energy(),
            block_accepted: Vec::new(),
        })
    }
}
