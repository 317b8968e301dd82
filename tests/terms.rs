//! Physics terms: each term's sensitivities (its extra state included) are the derivatives of
//! the numerical solution, and all of them together still simulate and fit.

use motorcal::forward::ForwardModel;
use motorcal::motor::{ActiveTerm, MotorModel, MotorParameters, Term, VoltageInput};
use motorcal::ode::SolverSettings;
use nalgebra::DMatrix;

fn times() -> Vec<f64> {
    (1..=501).map(|i| i as f64 * 0.5 / 501.0).collect()
}

/// 24 V, a third of it from 20%, −24 V from 60%: speed and current change sign, so every
/// term acts (Coulomb friction and the voltage drop included).
fn reversal() -> VoltageInput {
    let t = times();
    let values = t
        .iter()
        .map(|&s| {
            if s < 0.1 {
                24.0
            } else if s < 0.3 {
                8.0
            } else {
                -24.0
            }
        })
        .collect();
    VoltageInput::Held { times: t, values }
}

/// A value of each term's parameters at which its effect is clearly visible.
pub fn visible_values(name: &str) -> Vec<f64> {
    match name {
        "torque_constant" => vec![0.1],
        "back_emf_constant" => vec![-0.05],
        "viscous_friction" => vec![3e-5],
        "coulomb_friction" => vec![0.05],
        "quadratic_drag" => vec![2e-8],
        "load_torque" => vec![0.05],
        "load_step" => vec![0.08, 0.15],
        "voltage_drop" => vec![0.8],
        "resistance_heating" => vec![1e-3],
        "armature_reaction" => vec![5e-4],
        "current_offset" => vec![6.0],
        "speed_gain" => vec![0.04],
        "asymmetric_friction" => vec![-2e-5],
        "input_delay" => vec![2e-4],
        "sensor_lag" => vec![3e-3],
        "compliant_coupling" => vec![0.2, 60.0, 0.1],
        other => panic!("no values for {other}"),
    }
}

fn term(name: &str) -> ActiveTerm {
    ActiveTerm {
        term: Term::named(name).unwrap(),
        values: visible_values(name),
    }
}

/// Checks every column of ∂G/∂θ against central differences of G, at the data generator's
/// tolerances.
fn assert_sensitivities_match_finite_differences(model: MotorModel, names: &[String]) {
    assert_sensitivities_match_at(model, names, SolverSettings::for_data_generation(), 2e-4);
}

/// The same at `solver`'s tolerances, each column within `share` of its own peak.
fn assert_sensitivities_match_at(
    model: MotorModel,
    names: &[String],
    solver: SolverSettings,
    share: f64,
) {
    let fm = ForwardModel::new(model, times(), names, solver).unwrap();
    let theta = fm.nominal_calibrated();
    let n = fm.n_outputs();
    let mut out = vec![0.0; n];
    let mut jac = DMatrix::zeros(n, names.len());
    fm.simulate_with_sensitivities(&theta, &mut out, &mut jac)
        .unwrap();
    let mut plain = vec![0.0; n];
    fm.simulate(&theta, &mut plain).unwrap();
    for (a, b) in plain.iter().zip(&out) {
        assert!(
            (a - b).abs() <= 10.0 * solver.rtol * (1.0 + a.abs()),
            "the dual solve's values are the f64 solve's: {a} vs {b}"
        );
    }
    for (k, name) in names.iter().enumerate() {
        // Every value checked here is non-zero: a relative step suits each parameter's scale.
        let h = 1e-5 * theta[k].abs();
        let (mut plus, mut minus) = (theta.clone(), theta.clone());
        plus[k] += h;
        minus[k] -= h;
        let (mut gp, mut gm) = (vec![0.0; n], vec![0.0; n]);
        fm.simulate(&plus, &mut gp).unwrap();
        fm.simulate(&minus, &mut gm).unwrap();
        let column: Vec<f64> = (0..n).map(|i| jac[(i, k)]).collect();
        let scale = column.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        assert!(scale > 0.0, "{name}: the outputs do not depend on it");
        for i in 0..n {
            let fd = (gp[i] - gm[i]) / (2.0 * h);
            assert!(
                (fd - column[i]).abs() <= share * scale,
                "{name}, output {i}: dual {} vs finite difference {fd} (scale {scale})",
                column[i]
            );
        }
    }
}

fn calibrated(model: &MotorModel) -> Vec<String> {
    let mut names = vec!["R".to_string()];
    for t in model.terms() {
        for p in t.term.params() {
            names.push(format!("{}.{}", t.term.name(), p.key));
        }
    }
    names
}

/// Each term alone on the reversal record, then all of them together, with their calibrated
/// names.
fn each_term_then_all() -> Vec<(MotorModel, Vec<String>)> {
    let with = |terms: Vec<ActiveTerm>| {
        let model = MotorModel::with_terms(MotorParameters::default(), reversal(), terms).unwrap();
        let names = calibrated(&model);
        (model, names)
    };
    let mut models: Vec<_> = Term::NAMES.iter().map(|n| with(vec![term(n)])).collect();
    models.push(with(Term::NAMES.iter().map(|n| term(n)).collect()));
    models
}

#[test]
fn every_terms_sensitivities_match_finite_differences() {
    for (model, names) in each_term_then_all().into_iter().take(Term::NAMES.len()) {
        assert_sensitivities_match_finite_differences(model, &names);
    }
}

/// Each term alone and all of them together, at the tolerances every fit runs at (rtol 1e-8):
/// the dual parts follow the steps the real parts chose, so they are checked there too.
#[test]
fn every_terms_sensitivities_hold_at_the_fits_tolerances() {
    for (model, names) in each_term_then_all() {
        assert_sensitivities_match_at(model, &names, SolverSettings::default(), 1e-3);
    }
}

/// Beside a lag on the speed, at the tolerances every fit runs at: the derivatives a
/// diagnosis's step screen, L-BFGS and Laplace evidence use. While the lag's state was
/// integrated with the others (to 2026-12-01) this failed, on coulomb_friction.T_c first (0.1%
/// of its column's scale off), where every term passes without the lag; at the armature
/// reaction's absent κ the current's sensitivity came out 64× its finite difference (1.7e6
/// against 2.65e4), and the step screen beside a lag saw no gain where the fit then found 19
/// nats (bearing_defect-690003).
#[test]
fn beside_a_lag_every_terms_sensitivities_hold_at_the_fits_tolerances() {
    for name in Term::NAMES.iter().filter(|&&n| n != "sensor_lag") {
        let lag = ActiveTerm {
            term: Term::from_name("sensor_lag", &[1.0]).unwrap().unwrap(),
            values: vec![0.0142],
        };
        let model = MotorModel::with_terms(
            MotorParameters::default(),
            reversal(),
            vec![lag, term(name)],
        )
        .unwrap();
        let names = calibrated(&model);
        assert_sensitivities_match_at(model, &names, SolverSettings::default(), 1e-3);
    }
}

#[test]
fn all_terms_together_have_exact_sensitivities_simulate_and_fit() {
    let terms: Vec<ActiveTerm> = Term::NAMES.iter().map(|n| term(n)).collect();
    let model = MotorModel::with_terms(MotorParameters::default(), reversal(), terms).unwrap();
    let names = calibrated(&model);
    assert_eq!(
        names.len(),
        20,
        "R and nineteen term parameters (load_step has two, compliant_coupling three)"
    );
    assert_eq!(
        model.n_states(),
        6,
        "I, ω, the heating's energy, the coupling's twist and load speed, the lagged sensor"
    );
    assert_sensitivities_match_finite_differences(model, &names);
}

#[test]
fn terms_take_their_place_in_the_parameter_vector_whatever_the_order_given() {
    let a = MotorModel::with_terms(
        MotorParameters::default(),
        VoltageInput::Constant,
        vec![term("speed_gain"), term("coulomb_friction")],
    )
    .unwrap();
    let b = MotorModel::with_terms(
        MotorParameters::default(),
        VoltageInput::Constant,
        vec![term("coulomb_friction"), term("speed_gain")],
    )
    .unwrap();
    assert_eq!(a.parameter_names(), b.parameter_names());
    let names = a.parameter_names();
    assert_eq!(
        names[names.len() - 2..],
        ["coulomb_friction.T_c", "speed_gain.g"]
    );
    let twice = MotorModel::with_terms(
        MotorParameters::default(),
        VoltageInput::Constant,
        vec![term("speed_gain"), term("speed_gain")],
    );
    assert!(twice.unwrap_err().contains("twice"));
}

#[test]
fn a_schema_1_load_torque_is_the_load_torque_term() {
    let with_tl = MotorModel::new(
        MotorParameters {
            load_torque: 0.05,
            ..MotorParameters::default()
        },
        VoltageInput::Constant,
    );
    let as_term = MotorModel::with_terms(
        MotorParameters::default(),
        VoltageInput::Constant,
        vec![term("load_torque")],
    )
    .unwrap();
    assert_eq!(with_tl.parameter_names(), as_term.parameter_names());
    assert_eq!(with_tl.parameter_values(), as_term.parameter_values());
    // And the closed form with the same load agrees with the integrator.
    let fm = ForwardModel::new(
        as_term,
        times(),
        &[] as &[&str],
        SolverSettings::for_data_generation(),
    )
    .unwrap();
    let mut out = vec![0.0; fm.n_outputs()];
    fm.simulate(&[], &mut out).unwrap();
    let p: Vec<f64> = with_tl.parameter_values()[..9].to_vec();
    let m = fm.n_samples();
    for (i, &t) in fm.times().iter().enumerate() {
        let exact = motorcal::motor::closed_form::constant_voltage_solution(&p, 0.05, t).unwrap();
        assert!((out[i] - exact[0]).abs() < 1e-6 * 240.0);
        assert!((out[m + i] - exact[1]).abs() < 1e-6 * 2400.0);
    }
}
