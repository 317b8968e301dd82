//! The integrator against the exact solution of the linear motor ODE (constant voltage).

use motorcal::forward::ForwardModel;
use motorcal::motor::closed_form::constant_voltage_solution;
use motorcal::motor::{MotorModel, MotorParam, MotorParameters, VoltageInput};
use motorcal::ode::{OdeError, SolverSettings};
use nalgebra::DMatrix;
use num_dual::Dual64;

fn paper_times() -> Vec<f64> {
    (1..=501).map(|i| i as f64 * 0.5 / 501.0).collect()
}

fn exact(params: &[f64], times: &[f64]) -> Vec<[f64; 2]> {
    times
        .iter()
        .map(|&t| constant_voltage_solution(params, 0.0, t).unwrap())
        .collect()
}

fn forward(params: MotorParameters, input: VoltageInput, solver: SolverSettings) -> ForwardModel {
    ForwardModel::new(
        MotorModel::new(params, input),
        paper_times(),
        &["R"],
        solver,
    )
    .unwrap()
}

#[test]
fn dopri5_matches_the_closed_form_to_1e_8_of_the_signal() {
    for params in [
        MotorParameters::default(),
        MotorParameters::paper_simulation_model(),
    ] {
        let fm = forward(
            params.clone(),
            VoltageInput::Constant,
            SolverSettings::for_data_generation(),
        );
        let m = fm.n_samples();
        let mut out = vec![0.0; fm.n_outputs()];
        fm.simulate(&[params.resistance], &mut out).unwrap();
        let p: Vec<f64> = MotorParam::ALL.iter().map(|&k| params.get(k)).collect();
        let truth = exact(&p, fm.times());
        for c in 0..2 {
            let max_abs = truth.iter().map(|x| x[c].abs()).fold(0.0, f64::max);
            let max_err = (0..m)
                .map(|i| (out[c * m + i] - truth[i][c]).abs())
                .fold(0.0, f64::max);
            assert!(
                max_err <= 1e-8 * max_abs,
                "channel {c}: error {max_err:e} vs scale {max_abs}"
            );
        }
    }
}

#[test]
fn dual_number_sensitivity_in_r_matches_the_closed_form_and_finite_differences() {
    let params = MotorParameters::paper_simulation_model();
    let fm = forward(
        params.clone(),
        VoltageInput::Constant,
        SolverSettings::for_data_generation(),
    );
    let m = fm.n_samples();
    let r = 0.097;
    let mut out = vec![0.0; fm.n_outputs()];
    let mut jac = DMatrix::zeros(fm.n_outputs(), 1);
    fm.simulate_with_sensitivities(&[r], &mut out, &mut jac)
        .unwrap();

    let mut p: Vec<Dual64> = MotorParam::ALL
        .iter()
        .map(|&k| Dual64::from(params.get(k)))
        .collect();
    p[MotorParam::Resistance as usize] = Dual64::new(r, 1.0);
    let h = 1e-6;
    let (mut plus, mut minus) = (vec![0.0; fm.n_outputs()], vec![0.0; fm.n_outputs()]);
    fm.simulate(&[r + h], &mut plus).unwrap();
    fm.simulate(&[r - h], &mut minus).unwrap();
    for c in 0..2 {
        let exact: Vec<f64> = fm
            .times()
            .iter()
            .map(|&t| constant_voltage_solution(&p, Dual64::from(0.0), t).unwrap()[c].eps)
            .collect();
        let scale = exact.iter().map(|v| v.abs()).fold(0.0, f64::max);
        for i in 0..m {
            let dual = jac[(c * m + i, 0)];
            assert!(
                (dual - exact[i]).abs() <= 1e-6 * scale,
                "closed form, channel {c} sample {i}: {dual} vs {}",
                exact[i]
            );
            let fd = (plus[c * m + i] - minus[c * m + i]) / (2.0 * h);
            assert!(
                (dual - fd).abs() <= 1e-4 * scale,
                "finite difference, channel {c} sample {i}: {dual} vs {fd}"
            );
        }
    }
}

#[test]
fn several_calibrated_parameters_give_one_column_each() {
    let params = MotorParameters::paper_simulation_model();
    let names = ["R", "c_g", "J", "d", "c_m"];
    let fm = ForwardModel::new(
        MotorModel::new(params.clone(), VoltageInput::Constant),
        paper_times(),
        &names,
        SolverSettings::for_data_generation(),
    )
    .unwrap();
    let theta: Vec<f64> = names
        .iter()
        .map(|n| params.get(MotorParam::from_key(n).unwrap()))
        .collect();
    let mut out = vec![0.0; fm.n_outputs()];
    let mut jac = DMatrix::zeros(fm.n_outputs(), names.len());
    fm.simulate_with_sensitivities(&theta, &mut out, &mut jac)
        .unwrap();
    for (k, name) in names.iter().enumerate() {
        let mut p: Vec<Dual64> = MotorParam::ALL
            .iter()
            .map(|&q| Dual64::from(params.get(q)))
            .collect();
        let slot = MotorParam::from_key(name).unwrap() as usize;
        p[slot] = Dual64::new(p[slot].re, 1.0);
        let exact: Vec<[f64; 2]> = fm
            .times()
            .iter()
            .map(|&t| {
                let x = constant_voltage_solution(&p, Dual64::from(0.0), t).unwrap();
                [x[0].eps, x[1].eps]
            })
            .collect();
        let m = fm.n_samples();
        for c in 0..2 {
            let scale = exact.iter().map(|v| v[c].abs()).fold(0.0, f64::max);
            let worst = (0..m)
                .map(|i| (jac[(c * m + i, k)] - exact[i][c]).abs())
                .fold(0.0, f64::max);
            assert!(
                worst <= 1e-6 * scale,
                "∂/∂{name}, channel {c}: error {worst:e} vs scale {scale:e}"
            );
        }
    }
}

#[test]
fn a_held_voltage_is_integrated_piecewise_exactly() {
    // 24 V, then 8 V from t = 0.1, then −24 V from t = 0.3: each piece is again linear, so the
    // exact solution restarts the closed form at each switch.
    let times = paper_times();
    let values: Vec<f64> = times
        .iter()
        .map(|&t| {
            if t < 0.1 {
                24.0
            } else if t < 0.3 {
                8.0
            } else {
                -24.0
            }
        })
        .collect();
    let params = MotorParameters::default();
    let fm = ForwardModel::new(
        MotorModel::new(
            params.clone(),
            VoltageInput::Held {
                times: times.clone(),
                values: values.clone(),
            },
        ),
        times.clone(),
        &["R"],
        SolverSettings::for_data_generation(),
    )
    .unwrap();
    let mut out = vec![0.0; fm.n_outputs()];
    fm.simulate(&[params.resistance], &mut out).unwrap();

    let switches: Vec<f64> = (1..times.len())
        .filter(|&i| values[i] != values[i - 1])
        .map(|i| times[i])
        .collect();
    let mut start = 0.0;
    let mut state = [0.0, 0.0];
    let mut p: Vec<f64> = MotorParam::ALL.iter().map(|&k| params.get(k)).collect();
    let m = times.len();
    let mut worst = [0.0f64; 2];
    let mut scale = [0.0f64; 2];
    for (i, &t) in times.iter().enumerate() {
        while let Some(&s) = switches.iter().find(|&&s| s > start && s <= t) {
            p[MotorParam::InitialCurrent as usize] = state[0];
            p[MotorParam::InitialSpeed as usize] = state[1];
            p[MotorParam::Voltage as usize] =
                values[times.partition_point(|&x| x <= start).saturating_sub(1)];
            let x = constant_voltage_solution(&p, 0.0, s - start).unwrap();
            state = x;
            start = s;
        }
        p[MotorParam::InitialCurrent as usize] = state[0];
        p[MotorParam::InitialSpeed as usize] = state[1];
        let u_index = times.partition_point(|&x| x <= start).saturating_sub(1);
        p[MotorParam::Voltage as usize] = values[u_index];
        let x = constant_voltage_solution(&p, 0.0, t - start).unwrap();
        for c in 0..2 {
            worst[c] = worst[c].max((out[c * m + i] - x[c]).abs());
            scale[c] = scale[c].max(x[c].abs());
        }
    }
    for c in 0..2 {
        assert!(
            worst[c] <= 1e-8 * scale[c],
            "channel {c}: error {:e} vs scale {:e}",
            worst[c],
            scale[c]
        );
    }
}

#[test]
fn the_step_cap_and_a_blow_up_are_recoverable_errors_not_hangs() {
    let capped = SolverSettings {
        max_steps: 5,
        ..SolverSettings::default()
    };
    let fm = forward(MotorParameters::default(), VoltageInput::Constant, capped);
    let mut out = vec![0.0; fm.n_outputs()];
    assert!(matches!(
        fm.simulate(&[0.1], &mut out),
        Err(OdeError::TooManySteps { .. })
    ));

    // A negative resistance makes the electrical pole unstable with a rate of 10⁷/s.
    let fm = forward(
        MotorParameters::default(),
        VoltageInput::Constant,
        SolverSettings::default(),
    );
    assert!(fm.simulate(&[-1000.0], &mut out).is_err());
}

#[test]
fn solver_statistics_stay_where_they_were_measured() {
    // A cheap guard against silent slow-downs (the step count of the paper's start-up at the
    // default tolerance; a changed controller shows here first).
    let fm = forward(
        MotorParameters::paper_simulation_model(),
        VoltageInput::Constant,
        SolverSettings::default(),
    );
    let mut out = vec![0.0; fm.n_outputs()];
    let stats = fm.simulate(&[0.1], &mut out).unwrap();
    eprintln!("{stats:?}");
    assert!((150..=300).contains(&stats.accepted_steps), "{stats:?}");
    assert!(stats.rejected_steps <= 20, "{stats:?}");
}
