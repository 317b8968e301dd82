//! Fixed Runge–Kutta steps aligned to a record's samples, for systems whose input is held
//! between samples and changes at nearly every one (a measured current at 1 kHz, a sampled
//! controller's output).
//!
//! Why not the adaptive Dormand–Prince of [`super::solve`] with a breakpoint per sample: every
//! breakpoint restarts it (a fresh first step, its error estimate thrown away), so 25 000 samples
//! cost 25 000 restarts and a step count set by the restarts, not by accuracy. The held input
//! already fixes the natural step, one sample; what is integrated inside it is smooth, so the
//! classical fourth-order method over `substeps` equal steps per sample is accurate to O(h⁴)
//! with h ≤ 1 ms against mechanical time constants of tens of milliseconds and more. The steps
//! are the same for every parameter value, so the dual parts are the exact derivatives of this
//! discrete solution (no step control to differentiate through).

use num_dual::DualNum;

use super::{OdeError, SolverStats};

/// y' = f(t, y, u) with an input u held over each sample interval.
pub trait HeldInputSystem<D> {
    fn n_states(&self) -> usize;
    fn rhs(&self, t: f64, y: &[D], input: D, dy: &mut [D]);
}

/// Integrates from `times[0]` with `y0`. At every sample k, `sample(k, y_k)` sees the state
/// (to record what the model measures there) and returns the input held on [t_k, t_{k+1}): a
/// recorded series, or a controller acting on the sampled state (the last sample's return value
/// is not used). Nothing is stored per sample here: a 25 000-sample record of dual numbers
/// would be megabytes allocated and freed at every density evaluation.
pub fn solve_sampled<D, S, F>(
    system: &S,
    y0: &[D],
    times: &[f64],
    substeps: usize,
    mut sample: F,
) -> Result<SolverStats, OdeError>
where
    D: DualNum<Primitive = f64> + Copy,
    S: HeldInputSystem<D>,
    F: FnMut(usize, &[D]) -> D,
{
    let n = system.n_states();
    let m = times.len();
    if y0.len() != n || m == 0 || substeps == 0 {
        return Err(OdeError::BadOutputTimes(format!(
            "{} initial values for {n} states, {m} samples, {substeps} substeps",
            y0.len(),
        )));
    }
    let zero = D::from(0.0);
    let mut y = y0.to_vec();
    let (mut k1, mut k2, mut k3, mut k4, mut stage) = (
        vec![zero; n],
        vec![zero; n],
        vec![zero; n],
        vec![zero; n],
        vec![zero; n],
    );
    let mut stats = SolverStats::default();
    for k in 0..m {
        if y.iter().any(|v| !v.re().is_finite()) {
            return Err(OdeError::NonFinite { t: times[k] });
        }
        let u = sample(k, &y);
        if k + 1 == m {
            break;
        }
        let h = (times[k + 1] - times[k]) / substeps as f64;
        for s in 0..substeps {
            let t = times[k] + s as f64 * h;
            system.rhs(t, &y, u, &mut k1);
            for i in 0..n {
                stage[i] = y[i] + k1[i] * (0.5 * h);
            }
            system.rhs(t + 0.5 * h, &stage, u, &mut k2);
            for i in 0..n {
                stage[i] = y[i] + k2[i] * (0.5 * h);
            }
            system.rhs(t + 0.5 * h, &stage, u, &mut k3);
            for i in 0..n {
                stage[i] = y[i] + k3[i] * h;
            }
            system.rhs(t + h, &stage, u, &mut k4);
            for i in 0..n {
                y[i] += (k1[i] + (k2[i] + k3[i]) * 2.0 + k4[i]) * (h / 6.0);
            }
        }
        stats.accepted_steps += substeps;
        stats.rhs_evaluations += 4 * substeps;
    }
    Ok(stats)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ẏ = −a·y + u with u held: each interval has the closed form
    /// y(t_k + h) = u/a + (y_k − u/a)·e^(−a·h).
    struct FirstOrder {
        a: f64,
    }

    impl HeldInputSystem<f64> for FirstOrder {
        fn n_states(&self) -> usize {
            1
        }
        fn rhs(&self, _t: f64, y: &[f64], u: f64, dy: &mut [f64]) {
            dy[0] = -self.a * y[0] + u;
        }
    }

    #[test]
    fn a_held_input_is_integrated_to_fourth_order() {
        let a = 30.0;
        let times: Vec<f64> = (0..200).map(|i| i as f64 * 1e-3).collect();
        let inputs: Vec<f64> = (0..200).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
        let mut exact = vec![0.0; 200];
        let mut y = 0.5;
        for k in 0..200 {
            exact[k] = y;
            let target = inputs[k] / a;
            y = target + (y - target) * (-a * 1e-3f64).exp();
        }
        let error = |substeps: usize| {
            let mut out = vec![0.0; 200];
            solve_sampled(&FirstOrder { a }, &[0.5], &times, substeps, |k, y| {
                out[k] = y[0];
                inputs[k]
            })
            .unwrap();
            out.iter()
                .zip(&exact)
                .map(|(o, e)| (o - e).abs())
                .fold(0.0, f64::max)
        };
        let (one, two) = (error(1), error(2));
        assert!(one < 1e-7, "one step per sample: {one}");
        // Halving h divides a fourth-order method's global error by about 16.
        assert!(one / two > 12.0 && one / two < 20.0, "{one} / {two}");
    }

    #[test]
    fn the_input_sees_the_state_at_its_sample() {
        // A proportional controller u = −g·y on ẏ = u: y_{k+1} = (1 − g·h)·y_k exactly, since
        // the right-hand side is constant over each sample.
        struct Integrator;
        impl HeldInputSystem<f64> for Integrator {
            fn n_states(&self) -> usize {
                1
            }
            fn rhs(&self, _t: f64, _y: &[f64], u: f64, dy: &mut [f64]) {
                dy[0] = u;
            }
        }
        let times: Vec<f64> = (0..10).map(|i| i as f64 * 0.01).collect();
        let mut out = [0.0; 10];
        solve_sampled(&Integrator, &[1.0], &times, 1, |k, y| {
            out[k] = y[0];
            -5.0 * y[0]
        })
        .unwrap();
        for (k, v) in out.iter().enumerate() {
            assert!((v - 0.95f64.powi(k as i32)).abs() < 1e-12, "{k}: {v}");
        }
    }
}
