//! Mechanics driven by a drive that closes the electrical loop itself: the recorded current (or
//! force command) is the input of J dω/dt = c_g·u − d·ω + Σ torque, and the electrical equation
//! is not observable. Two bases use it:
//!
//! - `current_driven`: u is a recorded current, held between samples; the model measures ω.
//! - `position_loop`: u is the output of a sampled cascade controller acting on the simulated
//!   position (a P position loop feeding a P velocity loop, as the EMPS benchmark documents:
//!   u_k = k_p·k_v·(q_ref,k − q_k) − k_v·v_k with v_k the backward difference of the two-sample
//!   mean of q, saturated at ±`input_limit`, plus an optional recorded disturbance added after
//!   the saturation, applied `delay_samples` later). The model measures q and the force
//!   c_g·u_k. The loop tracks so well that position hides the model error at the µm level; the
//!   controller output is where it shows.
//!
//! Both are integrated with fixed steps aligned to the samples ([`crate::ode::solve_sampled`]):
//! the input changes at every sample of a 1 kHz record.

use serde::{Deserialize, Serialize};

use super::balance::{Coefficients, Site, torque_balance};
use super::{Base, MotorModel, MotorParam, Scalar};
use crate::ode::{HeldInputSystem, OdeError, SolverStats, solve_sampled};

/// The `[drive]` table of a model file: how the drive turns its input into torque.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DriveSettings {
    /// The largest input the drive passes (A for a current, V for a controller output): the
    /// controller's saturation, and with c_g the torque scale the default priors are drawn to.
    /// `None`: the largest recorded input.
    pub input_limit: Option<f64>,
    /// k_p of the position loop [1/s] (`position_loop` only).
    pub position_gain: f64,
    /// k_v of the velocity loop [input per unit speed] (`position_loop` only).
    pub velocity_gain: f64,
    /// Samples between the controller computing an output and the drive applying it.
    pub delay_samples: usize,
    /// Fourth-order steps per sample interval.
    pub substeps: usize,
}

impl Default for DriveSettings {
    fn default() -> Self {
        Self {
            input_limit: None,
            position_gain: 0.0,
            velocity_gain: 0.0,
            delay_samples: 0,
            substeps: 1,
        }
    }
}

impl DriveSettings {
    pub fn validate(&self, base: Base) -> Result<(), String> {
        if let Some(limit) = self.input_limit
            && !(limit > 0.0 && limit.is_finite())
        {
            return Err(format!(
                "drive.input_limit = {limit} must be a positive number"
            ));
        }
        if !(1..=64).contains(&self.substeps) {
            return Err(format!(
                "drive.substeps = {} must be between 1 and 64",
                self.substeps
            ));
        }
        if base == Base::PositionLoop {
            for (key, v) in [
                ("position_gain", self.position_gain),
                ("velocity_gain", self.velocity_gain),
            ] {
                if !(v > 0.0 && v.is_finite()) {
                    return Err(format!(
                        "drive.{key} = {v} must be a positive number for a position_loop base"
                    ));
                }
            }
        }
        Ok(())
    }
}

/// What a record gives the drive: its sample times, the input series (the current for
/// `current_driven`, the reference position for `position_loop`), a disturbance added after
/// the saturation (zeros when not recorded), where the axis starts, and its speed scale.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct SampledDrive {
    pub times: Vec<f64>,
    pub input: Vec<f64>,
    pub disturbance: Vec<f64>,
    pub initial_position: f64,
    /// The largest speed of the record (measured, or of the reference): what "fast" means.
    pub speed_scale: f64,
    pub settings: DriveSettings,
}

impl SampledDrive {
    /// The input limit: declared, or the largest recorded input.
    pub fn input_scale(&self) -> f64 {
        self.settings.input_limit.unwrap_or_else(|| {
            self.input
                .iter()
                .fold(0.0f64, |a, v| a.max(v.abs()))
                .max(f64::MIN_POSITIVE)
        })
    }
}

/// q' = ω and J ω' = c_g·u − d·ω + Σ torque, with the model's terms.
struct Mechanics<'a, D> {
    model: &'a MotorModel,
    p: &'a [D],
    coefficients: Coefficients<D>,
}

impl<D: Scalar> HeldInputSystem<D> for Mechanics<'_, D> {
    fn n_states(&self) -> usize {
        self.model.n_states()
    }

    fn rhs(&self, t: f64, y: &[D], input: D, dy: &mut [D]) {
        let model = self.model;
        let c = &self.coefficients;
        let speed = y[1];
        let site = |k: usize| Site {
            t,
            segment_start: t,
            current: input,
            speed,
            voltage: D::from(0.0),
            coefficients: c,
            params: &self.p[model.param_offsets[k]..model.param_offsets[k + 1]],
            states: &y[model.state_offsets[k]..model.state_offsets[k + 1]],
        };
        let balance = model.balance(c, &site);
        dy[0] = speed;
        dy[1] = torque_balance(c, Some(&balance), input, speed) * c.inverse_inertia;
        model.term_derivatives(&site, &balance, dy);
    }
}

/// The channels of a drive-base model at the record's samples, channel-major (`out[c·M + i]`).
pub(super) fn simulate<D: Scalar>(
    model: &MotorModel,
    drive: &SampledDrive,
    p: &[D],
    out: &mut [D],
) -> Result<SolverStats, OdeError> {
    let system = Mechanics {
        model,
        p,
        coefficients: model.coefficients(p),
    };
    let m = drive.times.len();
    let mut y0 = vec![D::from(0.0); model.n_states()];
    model.initial_state(p, &mut y0);
    // The first measured position carries its sample's noise; the offset, when calibrated,
    // takes it back out.
    y0[0] = D::from(drive.initial_position) + p[MotorParam::InitialPositionOffset as usize];
    let substeps = drive.settings.substeps;
    match model.base {
        Base::PositionLoop => {
            let delay = drive.settings.delay_samples;
            let gain = p[MotorParam::TorqueConstant as usize];
            let (positions, forces) = out.split_at_mut(m);
            let limit = drive.input_scale();
            // The last three positions the controller saw, and its last `delay + 1` outputs.
            let mut seen = [y0[0]; 3];
            let mut pending = vec![D::from(0.0); delay + 1];
            solve_sampled(&system, &y0, &drive.times, substeps, |k, y| {
                seen = [y[0], seen[0], seen[1]];
                if k == 0 {
                    seen = [y[0]; 3];
                }
                let output = controller_output(drive, limit, &seen, k);
                positions[k] = y[0];
                forces[k] = output * gain;
                // Before the first output has come through the delay, the first is held.
                if k == 0 {
                    pending.fill(output);
                }
                pending.rotate_right(1);
                pending[0] = output;
                pending[delay]
            })
        }
        _ => solve_sampled(&system, &y0, &drive.times, substeps, |k, y| {
            out[k] = y[1];
            D::from(drive.input[k])
        }),
    }
}

/// The cascade's output at sample k from the last three positions seen (q_k, q_{k−1}, q_{k−2}):
/// the velocity estimate is the backward difference of the two-sample mean, (q_k − q_{k−2}) / 2h;
/// the output saturates (no derivative there) and the recorded disturbance adds after the
/// saturation.
fn controller_output<D: Scalar>(drive: &SampledDrive, limit: f64, seen: &[D; 3], k: usize) -> D {
    let s = &drive.settings;
    let h = if k == 0 {
        drive.times.get(1).map_or(1.0, |t1| t1 - drive.times[0])
    } else {
        drive.times[k] - drive.times[k - 1]
    };
    let speed = (seen[0] - seen[2]) / (2.0 * h);
    let raw =
        (-seen[0] + drive.input[k]) * (s.position_gain * s.velocity_gain) - speed * s.velocity_gain;
    let saturated = if raw.re().abs() > limit {
        D::from(limit.copysign(raw.re()))
    } else {
        raw
    };
    saturated + drive.disturbance[k]
}
