//! `motorcal design`: every designed input stays within the limits under every candidate, bad
//! options get one clear error and write nothing, and a small design runs end to end.

mod cli_support;

use cli_support::{motorcal, one_error_line, scratch};

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use motorcal::design::{
    self, Candidate, DesignSettings, Experiment, Limits, SearchSettings, design_problem,
    design_times,
};
use motorcal::discover::EVIDENCE_THRESHOLD;
use motorcal::io::{read_model_file, read_voltage_profile};
use motorcal::motor::VoltageInput;
use motorcal::study::{Problem, recording_from};
use motorcal::synthetic::generate;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/design")
        .join(name)
}

/// The fixture's drive: 24 V, 300 A, 3000 rad/s.
/// `motorcal design ARGS` as a quick design: 0.05 s at 400 Hz within the paper's limits, three
/// segments from one start, written to `out`.
fn quick_design(args: &[&str], out: &Path) -> std::process::Output {
    let mut all = vec!["design"];
    all.extend_from_slice(args);
    all.extend([
        "--duration",
        "0.05",
        "--rate",
        "400",
        "--limits",
        "U=±24,I=±300,omega=±3000",
        "--segments",
        "3",
        "--starts",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    motorcal(&all)
}

/// The design.json a design wrote to `out`.
fn design_json(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("design.json")).unwrap()).unwrap()
}

fn limits() -> Limits {
    "U=±24,I=±300,omega=±3000".parse().unwrap()
}

/// The two tied candidates of the fixture at the diagnosis's estimates, on a short record.
fn tied_pair(duration: f64, rate: f64) -> Experiment {
    let model = read_model_file(&fixture("motor.toml")).unwrap();
    let times = design_times(duration, rate).unwrap();
    let base = design_problem(&model, &times, &limits()).unwrap();
    let at = |pairs: &[(&str, f64)]| -> BTreeMap<String, f64> {
        pairs.iter().map(|(k, v)| (k.to_string(), *v)).collect()
    };
    let candidates = vec![
        Candidate::new(
            &base,
            "load_torque",
            &at(&[("R", 0.10557), ("load_torque.T_0", 0.02452)]),
        )
        .unwrap(),
        Candidate::new(
            &base,
            "coulomb_friction",
            &at(&[("R", 0.10557), ("coulomb_friction.T_c", 0.02453)]),
        )
        .unwrap(),
    ];
    Experiment {
        candidates,
        times,
        noise_sd: vec![2.0, 10.0],
    }
}

#[test]
fn designed_inputs_stay_within_the_limits() {
    let experiment = tied_pair(0.1, 500.0);
    // Limits that bind: 24 V would drive the current to 240 A.
    for (seed, limits) in [
        (1, "U=±24,I=±120,omega=±3000"),
        (2, "U=±12,I=±300,omega=±400"),
    ] {
        let limits: Limits = limits.parse().unwrap();
        let settings = DesignSettings {
            search: SearchSettings {
                segments: 4,
                starts: 2,
                iterations: 60,
                seed,
            },
            limits,
            draws: 2,
        };
        let d = design::separate(&experiment, &settings).unwrap();
        assert!(d.values.iter().all(|u| u.abs() <= limits.voltage));
        let input = design::held(&d.times, d.values.clone());
        let (predictions, excess) = design::predictions(&experiment, &input, &limits).unwrap();
        assert_eq!(excess, 0.0);
        let m = d.times.len();
        for y in &predictions {
            assert!(y[..m].iter().all(|i| i.abs() <= limits.current));
            assert!(y[m..].iter().all(|w| w.abs() <= limits.speed));
        }
        // The design uses what the limits allow: it is not the motor at rest.
        assert!(d.values.iter().any(|u| u.abs() > 0.1 * limits.voltage));
        assert!(d.expected_gap_nats.is_finite());
    }
}

#[test]
fn the_same_seed_gives_the_same_design_whatever_the_thread_count() {
    let experiment = tied_pair(0.05, 400.0);
    let settings = DesignSettings {
        search: SearchSettings {
            segments: 3,
            starts: 2,
            iterations: 40,
            seed: 9,
        },
        limits: "U=±24,I=±300,omega=±3000".parse().unwrap(),
        draws: 3,
    };
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| design::separate(&experiment, &settings).unwrap())
    };
    let (a, b) = (on(1), on(3));
    assert_eq!(a.values, b.values);
    assert_eq!(a.expected_gap_nats.to_bits(), b.expected_gap_nats.to_bits());
}

#[test]
fn a_small_design_runs_end_to_end() {
    let dir = scratch("design", "e2e");
    let out = dir.join("design");
    let o = quick_design(
        &[
            "--model",
            fixture("motor.toml").to_str().unwrap(),
            "--diagnosis",
            fixture("diagnosis.json").to_str().unwrap(),
            "--draws",
            "2",
        ],
        &out,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let input = read_voltage_profile(&out.join("input.csv")).unwrap();
    assert_eq!(input.times.len(), 20);
    assert!(input.values.iter().all(|u| u.abs() <= 24.0));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("design.json")).unwrap()).unwrap();
    assert!(json["expected_gap_nats"].is_f64());
    assert!(json["expected_gap_sd_nats"].is_f64());
    let fixed: Vec<&str> = json["fixed_experiments"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["input"].as_str().unwrap())
        .collect();
    assert_eq!(fixed, ["reversal", "step"]);
    // Each fixed experiment is written beside the design, to be recorded as it was scored:
    // the same times, within the voltage limit, the reversal's voltage reversed.
    for e in json["fixed_experiments"].as_array().unwrap() {
        let file = e["file"].as_str().unwrap();
        assert_eq!(file, format!("fixed-{}.csv", e["input"].as_str().unwrap()));
        let played = read_voltage_profile(&out.join(file)).unwrap();
        assert_eq!(played.times, input.times);
        assert!(played.values.iter().all(|u| u.abs() <= 24.0), "{file}");
    }
    let reversal = read_voltage_profile(&out.join("fixed-reversal.csv")).unwrap();
    assert!(reversal.values.first().unwrap() * reversal.values.last().unwrap() < 0.0);
    assert_eq!(json["seed"], 2026);
    assert_eq!(
        json["candidates"],
        serde_json::json!(["load_torque", "coulomb_friction"])
    );
    assert!(json["peaks"]["I"].as_f64().unwrap() <= 300.0);
    assert!(out.join("design.png").exists());
    // The rest of the library was checked on the designed input.
    assert!(json["unseparated_rivals"].is_array());
    let rounds = json["rival_check"]["rounds"].as_array().unwrap();
    assert!((1..=1 + design::RIVAL_ROUNDS).contains(&rounds.len()));
    assert_eq!(json["rival_check"]["threshold_nats"], EVIDENCE_THRESHOLD);

    // The loop closes: simulate takes the designed input.
    let sim = dir.join("sim");
    let o = motorcal(&[
        "simulate",
        "--input",
        out.join("input.csv").to_str().unwrap(),
        "--out",
        sim.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn bad_options_get_one_clear_error_and_write_nothing() {
    let dir = scratch("design", "bad");
    let out = dir.join("design");
    let model = fixture("motor.toml");
    let diagnosis = fixture("diagnosis.json");
    // A quick design of `model` (with the fixture's diagnosis unless `diagnosed` is false).
    let run_on = |model: &Path, diagnosed: bool, extra: &[&str]| {
        let mut args = vec!["design", "--model", model.to_str().unwrap()];
        if diagnosed {
            args.extend(["--diagnosis", diagnosis.to_str().unwrap()]);
        }
        args.extend([
            "--rate",
            "400",
            "--segments",
            "3",
            "--starts",
            "1",
            "--draws",
            "2",
            "--out",
            out.to_str().unwrap(),
        ]);
        args.extend_from_slice(extra);
        motorcal(&args)
    };
    let run = |extra: &[&str]| run_on(&model, true, extra);
    let limits = "U=±24,I=±300,omega=±3000";
    let o = run(&["--duration", "0.02", "--limits", limits]);
    one_error_line(&o, &["--duration", "8 samples", "ten"]);
    let o = run(&[
        "--duration",
        "0.05",
        "--limits",
        limits,
        "--separate",
        "load_torque,coulomb_fricton",
    ]);
    one_error_line(&o, &["coulomb_fricton", "unknown candidate"]);
    let o = run(&[
        "--duration",
        "0.05",
        "--limits",
        "U=±24,I=±0.001,omega=±3000",
    ]);
    one_error_line(&o, &["--limits", "no input can meet"]);
    let o = run(&["--duration", "0.05", "--limits", "U=±24,I=±300"]);
    one_error_line(&o, &["--limits", "speed"]);
    // The voltage is this model's input: its limit cannot be left out.
    let o = run(&["--duration", "0.05", "--limits", "I=±300,omega=±3000"]);
    one_error_line(&o, &["--limits", "U=±VALUE"]);
    // Neither candidates nor a diagnosis to take them from.
    let o = run_on(&model, false, &["--duration", "0.05", "--limits", limits]);
    one_error_line(&o, &["--separate", "--diagnosis"]);
    assert!(!out.exists());
}

/// A noisy record of the fixture's model with Coulomb friction of `t_c` N·m at 24 V.
fn coulomb_record(t_c: f64, times: &[f64]) -> Problem {
    let model = read_model_file(&fixture("motor.toml")).unwrap();
    let base = design_problem(&model, times, &limits()).unwrap();
    let values = BTreeMap::from([("coulomb_friction.T_c".to_string(), t_c)]);
    let truth = Candidate::new(&base, "coulomb_friction", &values).unwrap();
    let motor = truth.problem.model.model(VoltageInput::Constant).unwrap();
    let data = generate(&motor, times, &[2.0, 10.0], 11).unwrap();
    Problem {
        label: "recorded".into(),
        recordings: vec![recording_from(&data, "recorded", None)],
        model,
        reference: None,
    }
}

#[test]
fn without_a_diagnosis_the_candidates_sit_at_their_map_on_the_recording() {
    let times = design_times(0.2, 1000.0).unwrap();
    let recorded = coulomb_record(0.05, &times);
    let base = design_problem(&recorded.model, &times, &limits()).unwrap();
    let names = ["load_torque".to_string(), "coulomb_friction".to_string()];
    let (candidates, sd) =
        design::candidates_without_diagnosis(&base, &names, Some(&recorded)).unwrap();
    let value = |c: &Candidate, p: &str| c.theta[c.calibrated.iter().position(|n| n == p).unwrap()];
    // On a record that never reverses both explain the same torque: each finds it.
    for (c, p) in candidates
        .iter()
        .zip(["load_torque.T_0", "coulomb_friction.T_c"])
    {
        let v = value(c, p);
        assert!((v - 0.05).abs() < 0.01, "{p} = {v}");
        assert!((value(c, "R") - 0.1).abs() < 0.005);
    }
    let sd = sd.expect("a fitted recording gives its noise");
    assert!(
        (sd[0] / 2.0 - 1.0).abs() < 0.15 && (sd[1] / 10.0 - 1.0).abs() < 0.15,
        "{sd:?}"
    );
}

#[test]
fn without_a_recording_the_candidates_sit_at_the_model_values_and_a_zero_term_at_its_prior_median()
{
    let model = read_model_file(&fixture("motor.toml")).unwrap();
    let times = design_times(0.05, 400.0).unwrap();
    let base = design_problem(&model, &times, &limits()).unwrap();
    let names = ["none".to_string(), "coulomb_friction".to_string()];
    let (candidates, sd) = design::candidates_without_diagnosis(&base, &names, None).unwrap();
    assert!(sd.is_none());
    assert_eq!(candidates[0].theta, [0.1]);
    let c = &candidates[1];
    let t_c = c.theta[c
        .calibrated
        .iter()
        .position(|n| n == "coulomb_friction.T_c")
        .unwrap()];
    // T_c's default, zero, would make the candidate the model itself.
    assert!(t_c > 0.0 && t_c.is_finite());
}

#[test]
fn design_fits_the_named_candidates_to_a_recording_when_no_diagnosis_is_given() {
    let dir = scratch("design", "fitted");
    let sim = dir.join("sim");
    let o = motorcal(&[
        "simulate",
        "--effect",
        "coulomb_friction",
        "--magnitude",
        "3",
        "--input",
        "constant",
        "--seed",
        "4",
        "--samples",
        "200",
        "--t-end",
        "0.2",
        "--out",
        sim.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = dir.join("design");
    let o = quick_design(
        &[
            "--model",
            sim.join("motor.toml").to_str().unwrap(),
            "--data",
            sim.join("recording.csv").to_str().unwrap(),
            "--separate",
            "load_torque,coulomb_friction",
            "--draws",
            "2",
        ],
        &out,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json = design_json(&out);
    assert_eq!(
        json["candidates_at"]["source"],
        "their MAP on the recordings"
    );
    let t_c = json["candidates_at"]["values"]["coulomb_friction"]["coulomb_friction.T_c"]
        .as_f64()
        .unwrap();
    assert!(t_c > 0.0);
    // The noise is the recording's, not the paper's 2 A and 10 rad/s to the digit.
    assert_ne!(json["noise_sd"]["I"], 2.0);
    assert!(json["expected_gap_nats"].is_f64());
}

/// Dd of the test's viscous friction [N·m·s/rad]: strong enough to be seen on 50 samples.
const DD: f64 = 2e-4;

/// Viscous friction against quadratic drag (as strong at 2000 rad/s) on the fixture's motor.
fn friction_pair(times: &[f64]) -> (Problem, Experiment) {
    let model = read_model_file(&fixture("motor.toml")).unwrap();
    let base = design_problem(&model, times, &limits()).unwrap();
    let at = |pairs: &[(&str, f64)]| -> BTreeMap<String, f64> {
        pairs.iter().map(|(k, v)| (k.to_string(), *v)).collect()
    };
    let candidates = vec![
        Candidate::new(
            &base,
            "viscous_friction",
            &at(&[("R", 0.1), ("viscous_friction.Dd", DD)]),
        )
        .unwrap(),
        Candidate::new(
            &base,
            "quadratic_drag",
            &at(&[("R", 0.1), ("quadratic_drag.k_q", DD / 2000.0)]),
        )
        .unwrap(),
    ];
    let experiment = Experiment {
        candidates,
        times: times.to_vec(),
        noise_sd: vec![2.0, 10.0],
    };
    (base, experiment)
}

#[test]
fn a_library_term_that_coincides_with_a_candidate_on_the_designed_input_is_found_and_separated() {
    let times = design_times(0.1, 500.0).unwrap();
    let (base, experiment) = friction_pair(&times);
    let settings = DesignSettings {
        search: SearchSettings {
            segments: 4,
            starts: 2,
            iterations: 60,
            seed: 3,
        },
        limits: "U=±24,I=±300,omega=±3000".parse().unwrap(),
        draws: 2,
    };
    let is_asymmetric_on_viscous = |r: &design::Rival| {
        r.truth == "viscous_friction"
            && r.rival == "asymmetric_friction"
            && r.expected_gap_nats <= EVIDENCE_THRESHOLD
    };
    // Checked but not redesigned: the pair's design leaves asymmetric friction (viscous
    // friction wherever ω keeps one sign) within the threshold of viscous friction.
    let once = design::separate_checked(&base, &experiment, &settings, 0).unwrap();
    assert_eq!(once.rounds.len(), 1);
    assert!(
        once.unseparated_rivals()
            .iter()
            .any(is_asymmetric_on_viscous),
        "{:?}",
        once.rounds
    );
    assert!(once.added().is_empty());

    let checked =
        design::separate_checked(&base, &experiment, &settings, design::RIVAL_ROUNDS).unwrap();
    let first = &checked.rounds[0];
    assert!(
        first
            .unseparated_rivals
            .iter()
            .any(is_asymmetric_on_viscous),
        "{:?}",
        checked.rounds
    );
    // The rival joined the candidates, the input was designed again, and nothing is left.
    assert_eq!(checked.added(), ["asymmetric_friction"]);
    assert_eq!(checked.rounds.len(), 2, "{:?}", checked.rounds);
    assert!(
        checked.unseparated_rivals().is_empty(),
        "{:?}",
        checked.rounds
    );
    for g in &checked.design.gaps {
        assert!(g.noise_free_gap_nats > EVIDENCE_THRESHOLD, "{g:?}");
    }
    // On the final input the pair's own check finds asymmetric friction beyond the threshold:
    // the speed reverses there.
    let input = design::held(&times, checked.design.values.clone());
    let again =
        design::check_rivals(&base, &experiment, &input, &["asymmetric_friction".into()]).unwrap();
    assert!(again.rivals.is_empty(), "{:?}", again.rivals);
    let viscous = &experiment.candidates[0];
    let forward = viscous.forward(&input, &times).unwrap();
    let mut y = vec![0.0; forward.n_outputs()];
    forward.simulate(&viscous.theta, &mut y).unwrap();
    let omega = &y[times.len()..];
    assert!(omega.iter().any(|w| *w > 10.0) && omega.iter().any(|w| *w < -10.0));
}

/// `--pin` with `--data` designs where the recording puts the motor, not where the model file
/// guessed: on a record of the paper's motor (c_g = 0.01) with the nominal model (c_g = 0.009),
/// the design sits at the fit's c_g/J, 11% from the file's, and takes σ from that fit.
#[test]
fn a_pin_design_on_a_recording_sits_at_the_recording_s_estimates() {
    let dir = scratch("design", "pin-data");
    let sim = dir.join("sim");
    let o = motorcal(&["simulate", "--seed", "5", "--out", sim.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = dir.join("design");
    let o = quick_design(
        &[
            "--model",
            sim.join("motor.toml").to_str().unwrap(),
            "--data",
            sim.join("recording.csv").to_str().unwrap(),
            "--pin",
            "c_g/J",
        ],
        &out,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json = design_json(&out);
    assert_eq!(
        json["pinned_at"]["source"],
        "the model's MAP on the recordings"
    );
    let at = &json["pinned_at"]["values"];
    let ratio = at["c_g"].as_f64().unwrap() / at["J"].as_f64().unwrap();
    assert!(
        (ratio / (0.01 / 5e-5) - 1.0).abs() < 0.03,
        "c_g/J {ratio} against the truth's 200 (the file's 180)"
    );
    let sd = [&json["noise_sd"]["I"], &json["noise_sd"]["omega"]].map(|s| s.as_f64().unwrap());
    assert!(
        (sd[0] / 2.0 - 1.0).abs() < 0.2 && (sd[1] / 10.0 - 1.0).abs() < 0.2,
        "σ {sd:?} against the record's 2 and 10"
    );
}

/// `--pin` with `--diagnosis` sits at the diagnosis's selected model at its MAP, so that a
/// parameter of the term it found (the load torque of the fixture's diagnosis) can be pinned;
/// the model as given alone has no such parameter and the same pin is one error.
#[test]
fn a_pin_design_on_a_diagnosis_pins_the_selected_term_s_parameter() {
    let dir = scratch("design", "pin-diagnosis");
    let (model, diagnosis) = (fixture("motor.toml"), fixture("diagnosis.json"));
    let run = |out: &Path, diagnosed: bool| {
        let mut args = vec!["--model", model.to_str().unwrap()];
        if diagnosed {
            args.extend(["--diagnosis", diagnosis.to_str().unwrap()]);
        }
        args.extend(["--pin", "R,load_torque.T_0"]);
        quick_design(&args, out)
    };
    let out = dir.join("diagnosed");
    let o = run(&out, true);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let json = design_json(&out);
    let diagnosis: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&diagnosis).unwrap()).unwrap();
    for key in ["R", "load_torque.T_0"] {
        assert_eq!(
            json["pinned_at"]["values"][key], diagnosis["selected_params"][key],
            "{key}"
        );
        assert!(json["expected_sd"][key].as_f64().unwrap() > 0.0, "{key}");
    }
    let bare = dir.join("bare");
    let o = run(&bare, false);
    one_error_line(&o, &["load_torque.T_0"]);
    assert!(!bare.exists());
}

#[test]
fn a_pin_design_on_a_diagnosis_that_selected_a_law_is_refused_with_where_the_law_lives() {
    // A law's functions are written into the amended model.toml, not into the report's term
    // names, so a design from the report alone could not rebuild the selected model.
    let dir = scratch("design", "pin-diagnosis-law");
    let mut diagnosis: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(fixture("diagnosis.json")).unwrap()).unwrap();
    diagnosis["selected_set"] = serde_json::json!(["law"]);
    let report = dir.join("law-diagnosis.json");
    std::fs::write(&report, diagnosis.to_string()).unwrap();
    let out = dir.join("out");
    let model = fixture("motor.toml");
    let o = quick_design(
        &[
            "--model",
            model.to_str().unwrap(),
            "--diagnosis",
            report.to_str().unwrap(),
            "--pin",
            "R",
        ],
        &out,
    );
    one_error_line(&o, &["discovered law", "amended model.toml", "--model"]);
    assert!(!out.exists());
}
