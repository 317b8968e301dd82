//! What a small torque added to the motor does to its measured channels: the voltage-driven
//! base's two balances at a fit's MAP, linear in (I, ω), stepped exactly on the fine grid.
//!
//! A ripple in the torque balance does not reach the record as itself. The speed integrates it
//! through the inertia (a ripple at order k and speed ω shows in ω about 1/(J·k·ω) as large,
//! a quarter period late) and the current follows the speed through the back-EMF; where the
//! speed changes (a spin-up, a reversal) the ripple's image in the channels swells and fades
//! with 1/ω while the torque's own amplitude stays. A search that regresses the residual on
//! sin(k·θ) and cos(k·θ) themselves scores that image with the wrong weights, and a slow
//! structure of the residual can then outscore the ripple (gear_ripple-720004 of
//! `beyond_library_cases`: the residual's own order spectrum peaks at k = 0.057, while the
//! law fitted through the ODE gains 46.6 nats at the true 0.533 and 14.0 at 0.057, from
//! `fit --map-only` of each law). The columns below are what the regression should see: the
//! torque's image through the balances.
//!
//! The same map steps a small voltage added to the voltage balance (a supply that drops for a
//! moment, `knocks`), its input vector (1/L, 0) in place of the torque's (0, 1/J).
//!
//! Only the base's balances: a term's own dynamics (a coupling, a lag) and its dependence on
//! the state are left out. The search needs where the peak is; the fingerprint then solves the
//! law's columns through the whole ODE at the order found and scores those.

use nalgebra::{Matrix2, Matrix3, Vector2};

use crate::forward::ForwardModel;
use crate::motor::{Base, MotorParam};

/// The linear balances' exact one-step map on a grid of step h:
/// x ← A_h·x + b_h·τ, with x = (I, ω) and τ (a torque, or a voltage: [`Added`]) held over the
/// step.
#[derive(Clone, Debug)]
pub struct TorqueResponse {
    a_h: Matrix2<f64>,
    b_h: Vector2<f64>,
}

/// Which balance the small input is added to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Added {
    Torque,
    Voltage,
}

impl TorqueResponse {
    /// The base's balances L·dI/dt = −R·I − c_m·ω and J·dω/dt = c_g·I − d·ω + τ at the values
    /// `theta` gives the calibrated parameters (the others at the model's), on a grid of step
    /// `h`. None for a drive base, whose balances are the drive's, or where L or J is not
    /// positive.
    pub fn of(forward: &ForwardModel, theta: &[f64], h: f64) -> Option<Self> {
        Self::of_added(forward, theta, h, Added::Torque)
    }

    /// The same balances with the small input added to `added`'s balance: τ/J to dω/dt, or
    /// v/L to dI/dt.
    pub fn of_added(forward: &ForwardModel, theta: &[f64], h: f64, added: Added) -> Option<Self> {
        let model = forward.model();
        if model.base != Base::VoltageDriven || model.drive.is_some() {
            return None;
        }
        let calibrated = forward.calibrated_names();
        let value = |p: MotorParam| {
            calibrated
                .iter()
                .position(|n| n == p.key())
                .map_or(model.nominal.get(p), |i| theta[i])
        };
        let (r, l, j) = (
            value(MotorParam::Resistance),
            value(MotorParam::Inductance),
            value(MotorParam::Inertia),
        );
        let (c_m, c_g, d) = (
            value(MotorParam::BackEmfConstant),
            value(MotorParam::TorqueConstant),
            value(MotorParam::ViscousFriction),
        );
        if !(l > 0.0 && j > 0.0 && h > 0.0) {
            return None;
        }
        let b = match added {
            Added::Torque => Vector2::new(0.0, 1.0 / j),
            Added::Voltage => Vector2::new(1.0 / l, 0.0),
        };
        Some(Self::of_balances(
            Matrix2::new(-r / l, -c_m / l, c_g / j, -d / j),
            b,
            h,
        ))
    }

    /// ẋ = A·x + b·τ stepped exactly with τ held over a step of h: exp of the augmented
    /// matrix [[A, b], [0, 0]]·h holds A_h and b_h = ∫₀ʰ exp(A·s) ds·b.
    pub(super) fn of_balances(a: Matrix2<f64>, b: Vector2<f64>, h: f64) -> Self {
        let mut augmented = Matrix3::zeros();
        augmented.fixed_view_mut::<2, 2>(0, 0).copy_from(&(a * h));
        augmented.fixed_view_mut::<2, 1>(0, 2).copy_from(&(b * h));
        let e = augmented.exp();
        Self {
            a_h: e.fixed_view::<2, 2>(0, 0).into_owned(),
            b_h: e.fixed_view::<2, 1>(0, 2).into_owned(),
        }
    }

    /// The current's and the speed's responses, from rest, to the torque series `tau` on the
    /// grid (held over each step at the mean of its two ends).
    pub fn respond(&self, tau: &[f64]) -> [Vec<f64>; 2] {
        let mut x = Vector2::zeros();
        let mut current = Vec::with_capacity(tau.len());
        let mut speed = Vec::with_capacity(tau.len());
        current.push(0.0);
        speed.push(0.0);
        for w in tau.windows(2) {
            x = self.a_h * x + self.b_h * (0.5 * (w[0] + w[1]));
            current.push(x[0]);
            speed.push(x[1]);
        }
        [current, speed]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_held_torque_brings_the_speed_to_the_balances_steady_state() {
        // The paper's motor (R 0.1 Ω, L 0.1 mH, c 0.01, d 1e-6, J 5e-5) with a torque τ held:
        // at rest the balances give I = −c_m·ω/R and (c_g·c_m/R + d)·ω = τ; after 0.5 s (ten
        // mechanical time constants J·R/(c_g·c_m) = 50 ms) the stepped response is there.
        let (r, l, c, d, j) = (0.1, 1e-4, 0.01, 1e-6, 5e-5);
        let response = TorqueResponse::of_balances(
            Matrix2::new(-r / l, -c / l, c / j, -d / j),
            Vector2::new(0.0, 1.0 / j),
            1e-4,
        );
        let tau = vec![1e-3; 5001];
        let [current, speed] = response.respond(&tau);
        let omega = 1e-3 / (c * c / r + d);
        // e^(−10) of the step is left to go: within 1e-4.
        assert!(
            (speed[5000] - omega).abs() < 1e-4 * omega,
            "{}",
            speed[5000]
        );
        assert!((current[5000] + c * omega / r).abs() < 1e-4 * c * omega / r);
        // Early on the inertia alone holds the torque: ω ≈ τ·t/J over the first few steps,
        // while the current has barely moved.
        assert!((speed[3] - 1e-3 * 3e-4 / j).abs() < 0.01 * speed[3]);
    }

    #[test]
    fn a_held_voltage_brings_the_balances_to_the_motors_own_steady_state() {
        // A voltage v added to the voltage balance is the supply's own: at rest R·I + c_m·ω = v
        // and c_g·I = d·ω, the paper's no-load speed per volt; over the first step the winding
        // alone answers, I = v/R·(1 − e^(−R·h/L)), while the speed has barely moved.
        let (r, l, c, d, j) = (0.1, 1e-4, 0.01, 1e-6, 5e-5);
        let response = TorqueResponse::of_balances(
            Matrix2::new(-r / l, -c / l, c / j, -d / j),
            Vector2::new(1.0 / l, 0.0),
            1e-4,
        );
        let [current, speed] = response.respond(&vec![1.0; 5001]);
        let omega = c / (r * d + c * c);
        assert!(
            (speed[5000] - omega).abs() < 1e-4 * omega,
            "{}",
            speed[5000]
        );
        // The current's e^(−10) left is of its start-up's v/R, not of the small d·ω/c_g.
        assert!((current[5000] - d * omega / c).abs() < 1e-4 / r);
        let first = (1.0 - (-r * 1e-4 / l).exp()) / r;
        assert!((current[1] - first).abs() < 1e-3 * first, "{}", current[1]);
        assert!(speed[1] < 1e-3 * omega);
    }
}
