//! Session 14's probe (papers/beyond-library.md): ∂G/∂θ of a term at its absent value beside a
//! 14-ms lag on ω, by dual numbers against central differences, at the fits' tolerances
//! (`tight` false) or the generator's. Copy into tests/ of a checkout and run
//! `cargo test --release --test probe_sensitivities -- --nocapture`; its output on 4ab57c1 and
//! on this session's build is probe_sensitivities.txt.
use motorcal::forward::ForwardModel;
use motorcal::motor::{ActiveTerm, MotorModel, MotorParameters, Term, VoltageInput};
use motorcal::ode::SolverSettings;
use nalgebra::DMatrix;

fn grid(step: f64, end: f64) -> Vec<f64> {
    let n = (end / step).round() as usize;
    (1..=n).map(|i| i as f64 * step).collect()
}

#[test]
fn probe() {
    let times = grid(1e-3, 0.5);
    let values = times.iter().map(|&t| if t < 0.1 { 24.0 } else if t < 0.3 { 8.0 } else { -24.0 }).collect();
    let input = VoltageInput::Held { times: times.clone(), values };
    for (name, with_lag, tight) in [
        ("armature_reaction", true, false),
        ("resistance_heating", true, false),
        ("armature_reaction", false, false),
        ("armature_reaction", true, true),
    ] {
        let t = Term::named(name).unwrap();
        let n_p = t.params().len();
        let lag = ActiveTerm { term: Term::from_name("sensor_lag", &[1.0]).unwrap().unwrap(), values: vec![0.0142] };
        let other = ActiveTerm { term: t.clone(), values: t.params().iter().map(|p| p.default).collect() };
        let key = format!("{name}.{}", t.params()[0].key);
        let model = MotorModel::with_terms(MotorParameters::default(), input.clone(), if with_lag { vec![lag, other] } else { vec![other] }).unwrap();
        let fm = ForwardModel::new(model, times.clone(), &[key.as_str()], if tight { SolverSettings::for_data_generation() } else { SolverSettings::default() }).unwrap();
        let n = fm.n_outputs();
        let theta0 = 0.0;
        let (mut out, mut jac) = (vec![0.0; n], DMatrix::zeros(n, 1));
        fm.simulate_with_sensitivities(&[theta0], &mut out, &mut jac).unwrap();
        let step = 1e-6;
        let (mut plus, mut minus) = (vec![0.0; n], vec![0.0; n]);
        fm.simulate(&[theta0 + step], &mut plus).unwrap();
        fm.simulate(&[theta0 - step], &mut minus).unwrap();
        let m = n / 2;
        let peak = |r: std::ops::Range<usize>, f: &dyn Fn(usize) -> f64| r.map(|i| f(i).abs()).fold(0.0f64, f64::max);
        println!("{key} lag {with_lag} tight {tight} ({n_p} params): dual peak I {:.4e} ω {:.4e}; fd peak I {:.4e} ω {:.4e}",
            peak(0..m, &|i| jac[(i, 0)]), peak(m..n, &|i| jac[(i, 0)]),
            peak(0..m, &|i| (plus[i] - minus[i]) / (2.0 * step)), peak(m..n, &|i| (plus[i] - minus[i]) / (2.0 * step)));
    }
}
