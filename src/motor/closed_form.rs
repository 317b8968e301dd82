//! The exact solution of the motor ODE for a constant voltage: the equations are linear,
//! x' = A x + b, and A has two real eigenvalues for any motor with a well-damped electrical pole.
//! Written generic over the number type, so differentiating it gives exact sensitivities: the
//! reference the integrator is tested against.

use num_dual::DualNum;

use super::MotorParam;

/// (I(t), ω(t)) for constant U from the base parameter vector `p` (ordered as
/// [`MotorParam::ALL`]) and a constant load torque, or `None` when A has complex or repeated
/// eigenvalues.
pub fn constant_voltage_solution<D: DualNum<Primitive = f64> + Copy>(
    p: &[D],
    load_torque: D,
    t: f64,
) -> Option<[D; 2]> {
    use MotorParam::*;
    let g = |k: MotorParam| p[k as usize];
    let (l, j) = (g(Inductance), g(Inertia));
    let a = [
        [-g(Resistance) / l, -g(BackEmfConstant) / l],
        [g(TorqueConstant) / j, -g(ViscousFriction) / j],
    ];
    let b = [g(Voltage) / l, -load_torque / j];
    let x0 = [g(InitialCurrent), g(InitialSpeed)];
    let trace = a[0][0] + a[1][1];
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    let disc = trace * trace - det * 4.0;
    if disc.re() <= 0.0 {
        return None;
    }
    let root = disc.sqrt();
    let (l1, l2) = ((trace + root) * 0.5, (trace - root) * 0.5);
    // Equilibrium x* = −A⁻¹ b.
    let x_star = [
        -(a[1][1] * b[0] - a[0][1] * b[1]) / det,
        -(-a[1][0] * b[0] + a[0][0] * b[1]) / det,
    ];
    let z = [x0[0] - x_star[0], x0[1] - x_star[1]];
    // Sylvester's formula: exp(At) = e^{λ1 t}(A − λ2)/(λ1 − λ2) + e^{λ2 t}(A − λ1)/(λ2 − λ1).
    let e1 = (l1 * t).exp() / (l1 - l2);
    let e2 = (l2 * t).exp() / (l2 - l1);
    let apply = |row: usize| {
        let m1 = [
            a[row][0] - if row == 0 { l2 } else { D::from(0.0) },
            a[row][1] - if row == 1 { l2 } else { D::from(0.0) },
        ];
        let m2 = [
            a[row][0] - if row == 0 { l1 } else { D::from(0.0) },
            a[row][1] - if row == 1 { l1 } else { D::from(0.0) },
        ];
        e1 * (m1[0] * z[0] + m1[1] * z[1]) + e2 * (m2[0] * z[0] + m2[1] * z[1])
    };
    Some([x_star[0] + apply(0), x_star[1] + apply(1)])
}
