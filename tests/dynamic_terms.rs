//! The three dynamic terms: at their absent values each is the motor without it (undelayed,
//! unfiltered, rigid), to within the integrator's tolerance; at other values each does what its
//! name claims — the response arrives τ late, the measured channel is its true value through a
//! first-order filter of time constant τ, the speed rings at the set resonance — and the
//! sensitivities hold where the ramps and the absent values make them delicate.

use motorcal::forward::ForwardModel;
use motorcal::io::read_model_file;
use motorcal::motor::{ActiveTerm, MotorModel, MotorParameters, Term, VoltageInput};
use motorcal::ode::SolverSettings;
use nalgebra::DMatrix;

/// Sample times every `step` up to `end`, from `step`.
fn grid(step: f64, end: f64) -> Vec<f64> {
    let n = (end / step).round() as usize;
    (1..=n).map(|i| i as f64 * step).collect()
}

/// 24 V, 8 V from 0.1 s, −24 V from 0.3 s, held on the record's own 1-ms grid.
fn reversal() -> VoltageInput {
    let times = grid(1e-3, 0.5);
    let values = times
        .iter()
        .map(|&t| match t {
            t if t < 0.1 => 24.0,
            t if t < 0.3 => 8.0,
            _ => -24.0,
        })
        .collect();
    VoltageInput::Held { times, values }
}

fn active(name: &str, settings: Option<&[f64]>, values: &[f64]) -> ActiveTerm {
    let term = match settings {
        Some(s) => Term::from_name(name, s).unwrap().unwrap(),
        None => Term::named(name).unwrap(),
    };
    ActiveTerm {
        term,
        values: values.to_vec(),
    }
}

/// The noise-free channels, channel-major, at tight tolerances.
fn simulate(terms: Vec<ActiveTerm>, input: &VoltageInput, times: &[f64]) -> Vec<f64> {
    simulate_at(terms, input, times, SolverSettings::for_data_generation()).0
}

/// The noise-free channels at `solver`'s tolerances, and the steps the solve took.
fn simulate_at(
    terms: Vec<ActiveTerm>,
    input: &VoltageInput,
    times: &[f64],
    solver: SolverSettings,
) -> (Vec<f64>, usize) {
    let model = MotorModel::with_terms(MotorParameters::default(), input.clone(), terms).unwrap();
    let fm = ForwardModel::new(model, times.to_vec(), &[] as &[&str], solver).unwrap();
    let mut out = vec![0.0; fm.n_outputs()];
    let stats = fm.simulate(&[], &mut out).unwrap();
    (out, stats.accepted_steps + stats.rejected_steps)
}

fn peak(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |a, x| a.max(x.abs()))
}

#[test]
fn each_dynamic_term_at_its_absent_values_is_the_motor_without_it() {
    let times = grid(1e-3, 0.5);
    for input in [VoltageInput::Constant, reversal()] {
        let plain = simulate(Vec::new(), &input, &times);
        for name in ["input_delay", "sensor_lag", "compliant_coupling"] {
            let with = simulate(
                vec![ActiveTerm::with_defaults(Term::named(name).unwrap())],
                &input,
                &times,
            );
            let m = times.len();
            for c in 0..2 {
                let scale = peak(&plain[c * m..(c + 1) * m]);
                let worst = (0..m)
                    .map(|i| (with[c * m + i] - plain[c * m + i]).abs())
                    .fold(0.0, f64::max);
                assert!(
                    worst <= 1e-7 * scale,
                    "{name}, channel {c}: absent differs by {worst:.3e} (scale {scale:.1})"
                );
            }
        }
    }
}

#[test]
fn the_delayed_motor_responds_tau_later_to_every_step() {
    let times = grid(2e-4, 0.5);
    let m = times.len();
    // A delay longer than the ramp (width 10 µs) and one shorter than half the default ramp
    // (1 ms), where the ramp spans [c, c + 2τ] instead.
    for (tau, width, tolerance) in [(5e-3, 1e-5, 2e-3), (3e-4, 1e-3, 2e-2)] {
        for input in [VoltageInput::Constant, reversal()] {
            let delayed = simulate(
                vec![active("input_delay", Some(&[width]), &[tau])],
                &input,
                &times,
            );
            let late: Vec<f64> = times.iter().map(|t| t - tau).filter(|&t| t > 0.0).collect();
            let shifted = simulate(Vec::new(), &input, &late);
            let (k, first) = (late.len(), m - late.len());
            for c in 0..2 {
                let scale = peak(&shifted[c * k..(c + 1) * k]);
                let worst = (0..k)
                    .map(|i| (delayed[c * m + first + i] - shifted[c * k + i]).abs())
                    .fold(0.0, f64::max);
                assert!(
                    worst <= tolerance * scale,
                    "τ = {tau}, channel {c}: the delayed response misses the shifted one by \
                     {worst:.3e} (scale {scale:.1})"
                );
                // And it is not the undelayed response.
                let undelayed = simulate(Vec::new(), &input, &times);
                let moved = (0..m)
                    .map(|i| (delayed[c * m + i] - undelayed[c * m + i]).abs())
                    .fold(0.0, f64::max);
                assert!(
                    moved > 10.0 * worst,
                    "τ = {tau}, channel {c}: no delay seen"
                );
            }
            // Before τ the supply has not switched on: nothing moves.
            if let (VoltageInput::Constant, true) = (&input, tau > width) {
                let before = times.iter().take_while(|&&t| t < tau - width).count();
                assert!(before > 0);
                assert!((0..before).all(|i| delayed[i] == 0.0 && delayed[m + i] == 0.0));
            }
        }
    }
}

#[test]
fn the_lagging_sensor_reports_its_channel_through_a_first_order_filter_of_time_constant_tau() {
    let h = 1e-4;
    let times = grid(h, 0.5);
    let m = times.len();
    let input = reversal();
    let truth = simulate(Vec::new(), &input, &times);
    for (channel, tau) in [(1usize, 8e-3), (0, 5e-4)] {
        let lagged = simulate(
            vec![active("sensor_lag", Some(&[channel as f64]), &[tau])],
            &input,
            &times,
        );
        let other = 1 - channel;
        let unchanged = (other * m..(other + 1) * m)
            .map(|i| (lagged[i] - truth[i]).abs())
            .fold(0.0, f64::max);
        assert!(
            unchanged <= 1e-7 * peak(&truth[other * m..(other + 1) * m]),
            "channel {other} is measured as it is, not off by {unchanged:.3e}"
        );
        let x = &truth[channel * m..(channel + 1) * m];
        let y = &lagged[channel * m..(channel + 1) * m];
        let scale = peak(x);
        // τ·dy/dt + y = x, dy/dt by central differences, away from the input's steps.
        let mut worst = 0.0f64;
        for i in 1..m - 1 {
            let near_step = [0.0, 0.1, 0.3].iter().any(|s| (times[i] - s).abs() < 3e-3);
            if near_step {
                continue;
            }
            let dy = (y[i + 1] - y[i - 1]) / (2.0 * h);
            worst = worst.max((tau * dy + y[i] - x[i]).abs());
        }
        assert!(
            worst <= 1e-3 * scale,
            "channel {channel}: τ·dy/dt + y − x reaches {worst:.3e} (scale {scale:.1})"
        );
        // A filter that lags: after the reversal the measured value trails the true one.
        let i = times.iter().position(|&t| t > 0.3 + tau).unwrap();
        assert!(
            (y[i] - x[i]).abs() > 0.05 * scale,
            "channel {channel}: no lag seen"
        );
    }
}

#[test]
fn the_coupled_speed_rings_at_the_set_resonance() {
    let h = 2e-5;
    let times = grid(h, 0.2);
    let m = times.len();
    let (f_r, zeta) = (80.0, 0.02);
    let rigid = simulate(Vec::new(), &VoltageInput::Constant, &times);
    for share in [0.1, 0.3] {
        let coupled = simulate(
            vec![active("compliant_coupling", None, &[share, f_r, zeta])],
            &VoltageInput::Constant,
            &times,
        );
        // The ringing is the coupled speed minus the rigid one; its successive maxima are one
        // damped period apart.
        let ring: Vec<f64> = (0..m).map(|i| coupled[m + i] - rigid[m + i]).collect();
        let maxima: Vec<f64> = (1..m - 1)
            .filter(|&i| ring[i] > ring[i - 1] && ring[i] >= ring[i + 1] && times[i] > 2e-3)
            .map(|i| times[i])
            .take(8)
            .collect();
        assert!(maxima.len() == 8, "share {share}: {} maxima", maxima.len());
        let period = (maxima[7] - maxima[0]) / 7.0;
        let expected = f_r * (1.0 - zeta * zeta).sqrt();
        let seen = 1.0 / period;
        assert!(
            (seen / expected - 1.0).abs() < 0.03,
            "share {share}: rings at {seen:.2} Hz, set {expected:.2} Hz"
        );
        println!("share {share}: rings at {seen:.3} Hz, set {expected:.3} Hz");
    }
}

/// ∂G/∂θ of one parameter by dual numbers against a finite difference (central, or forward
/// from a bound).
fn check_column(model: MotorModel, name: &str, theta: f64, step: f64, central: bool) {
    let times = grid(1e-3, 0.5);
    let fm =
        ForwardModel::new(model, times, &[name], SolverSettings::for_data_generation()).unwrap();
    let n = fm.n_outputs();
    let (mut out, mut jac) = (vec![0.0; n], DMatrix::zeros(n, 1));
    fm.simulate_with_sensitivities(&[theta], &mut out, &mut jac)
        .unwrap();
    let (mut plus, mut minus) = (vec![0.0; n], vec![0.0; n]);
    fm.simulate(&[theta + step], &mut plus).unwrap();
    let lower = if central { theta - step } else { theta };
    fm.simulate(&[lower], &mut minus).unwrap();
    let scale = peak(jac.as_slice());
    assert!(scale > 0.0, "{name}: the outputs do not depend on it");
    for i in 0..n {
        let fd = (plus[i] - minus[i]) / (theta + step - lower);
        assert!(
            (fd - jac[(i, 0)]).abs() <= 1e-3 * scale,
            "{name} at {theta}, output {i}: dual {} vs finite difference {fd} (scale {scale})",
            jac[(i, 0)]
        );
    }
}

#[test]
fn sensitivities_hold_across_the_delay_s_ramps_and_at_the_coupling_s_absent_share() {
    for tau in [2e-4, 2e-3] {
        let model = MotorModel::with_terms(
            MotorParameters::default(),
            reversal(),
            vec![active("input_delay", None, &[tau])],
        )
        .unwrap();
        check_column(model, "input_delay.tau", tau, 1e-5 * tau, true);
    }
    // At s = 0 (rigid) the derivative in s is finite and right: forward differences from the
    // bound.
    let model = MotorModel::with_terms(
        MotorParameters::default(),
        VoltageInput::Constant,
        vec![active("compliant_coupling", None, &[0.0, 60.0, 0.1])],
    )
    .unwrap();
    check_column(model, "compliant_coupling.s", 0.0, 1e-6, false);
}

#[test]
fn a_sensor_lag_names_its_channel_and_a_bad_one_is_one_error() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("motorcal-lag-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("model.toml");
    let read = |text: &str| {
        std::fs::write(&path, text).unwrap();
        read_model_file(&path)
    };
    let file = read("schema = 2\n[terms.sensor_lag]\nchannel = \"I\"\ntau = 1e-3\n").unwrap();
    assert_eq!(file.terms[0].term.settings(), vec![0.0]);
    let written = motorcal::io::to_toml_string(&file);
    assert!(written.contains("channel = \"I\""), "{written}");
    for bad in ["\"q\"", "1", "\"omega \""] {
        let e = read(&format!(
            "schema = 2\n[terms.sensor_lag]\nchannel = {bad}\n"
        ))
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("terms.sensor_lag.channel") && e.contains("must be one of \"I\", \"omega\""),
            "{bad}: {e}"
        );
    }
}

/// A filter of a few µs would hold an explicit integrator to steps of a few µs (tens of
/// thousands per 0.5-s solve, the cap at 50 000); advanced in closed form it costs the solve
/// no step, and it reads its channel as a first-order lag does: τ late, to O(τ²·ẍ).
/// (Integrated as a state, to 4ab57c1, the 5-µs lag on I took 30 362 steps per solve here.)
#[test]
fn a_lag_of_microseconds_costs_the_solve_no_step_and_reads_its_channel_tau_late() {
    let times = grid(1e-3, 0.5);
    let input = reversal();
    let (truth, plain_steps) = simulate_at(Vec::new(), &input, &times, SolverSettings::default());
    let m = times.len();
    for (channel, tau) in [(0usize, 5e-6), (1, 5e-6), (0, 3e-5)] {
        let (lagged, steps) = simulate_at(
            vec![active("sensor_lag", Some(&[channel as f64]), &[tau])],
            &input,
            &times,
            SolverSettings::default(),
        );
        println!("τ = {tau} on channel {channel}: {steps} steps, {plain_steps} without the lag");
        assert!(
            steps <= plain_steps + plain_steps / 4,
            "τ = {tau} on channel {channel}: {steps} steps against {plain_steps} without the lag"
        );
        // x(t − τ) from the motor without the lag, sampled τ earlier.
        let earlier: Vec<f64> = times.iter().map(|t| t - tau).collect();
        let (late, _) = simulate_at(Vec::new(), &input, &earlier, SolverSettings::default());
        let x = &truth[channel * m..(channel + 1) * m];
        let y = &lagged[channel * m..(channel + 1) * m];
        let x_late = &late[channel * m..(channel + 1) * m];
        let scale = peak(x);
        let mut worst = 0.0f64;
        let mut shift = 0.0f64;
        for i in 0..m {
            // Within a few electrical time constants of a step ẍ is large and the lag is not a
            // pure shift there.
            if [0.0, 0.1, 0.3].iter().any(|s| (times[i] - s).abs() < 5e-3) {
                continue;
            }
            worst = worst.max((y[i] - x_late[i]).abs());
            shift = shift.max((x[i] - x_late[i]).abs());
        }
        // A lag and a delay part at τ²·ẍ/2: within a tenth of the shift itself here.
        assert!(
            shift > 1e-6 * scale && worst <= 1e-6 * scale + 0.1 * shift,
            "τ = {tau} on channel {channel}: y − x(t − τ) reaches {worst:.3e} (x − x(t − τ) {shift:.3e})"
        );
    }
}

/// ∂G/∂τ of the lag from a few µs (where the closed form's series and recurrence branches meet
/// within a step) to a slow filter, on either channel.
#[test]
fn the_lag_s_sensitivity_holds_from_microseconds_to_a_slow_filter() {
    for channel in [0.0, 1.0] {
        for tau in [5e-6, 4e-4, 3e-2] {
            let model = MotorModel::with_terms(
                MotorParameters::default(),
                reversal(),
                vec![active("sensor_lag", Some(&[channel]), &[tau])],
            )
            .unwrap();
            check_column(model, "sensor_lag.tau", tau, 1e-5 * tau, true);
        }
    }
}
