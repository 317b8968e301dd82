//! `motorcal design` on a `position_loop` model: the designed input is the reference's speed,
//! played as its integral (`input.csv` is `t,q_ref`, starting where the axis rests), within the
//! speed limit, the travel and the force limit that keeps the controller below its saturation;
//! on the tie a record that never reverses leaves (Coulomb friction against a load), it
//! separates the pair better than the fixed reversal and step, and the loop closes: each
//! candidate as the truth, simulated on the designed reference, is what `diagnose` names.

mod cli_support;
mod sensitivity_support;

use cli_support::{motorcal, one_error_line, scratch};
use sensitivity_support::assert_sensitivities_are_central_differences;

use std::path::{Path, PathBuf};

use motorcal::io::{ChannelMap, read_input_profile, read_recording_for};
use motorcal::motor::Base;

/// EMPS's cascade on a 95-kg axis, d = 205 N·s/m, c_g = 35.15 N/V; J and d calibrated.
fn model_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/design/position_loop.toml")
}

const LIMITS: &str = "q=±0.1,omega=±0.5,force=±300";
/// σ of q [m] and of the force [N]: EMPS's after its fit are about 2 µm and 3 N.
const NOISE: [&str; 2] = ["2e-6", "5"];

fn run(args: &[&str]) -> String {
    let o = motorcal(args);
    assert!(
        o.status.success(),
        "motorcal {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The fixture with `terms` (TOML tables) added and J, d set, as a truth file in `dir`.
fn truth_file(dir: &Path, name: &str, j: f64, d: f64, terms: &str) -> PathBuf {
    let text = std::fs::read_to_string(model_path())
        .unwrap()
        .replace("J = 95.2\n", &format!("J = {j}\n"))
        .replace("d = 205.0\n", &format!("d = {d}\n"))
        .replace("[drive]", &format!("{terms}\n[drive]"));
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// `simulate --truth truth --input input` into `out`, with `noise` σ (q, force).
fn simulate(truth: &Path, input: &Path, noise: [&str; 2], seed: &str, out: &Path) -> PathBuf {
    run(&[
        "simulate",
        "--truth",
        truth.to_str().unwrap(),
        "--nominal",
        model_path().to_str().unwrap(),
        "--input",
        input.to_str().unwrap(),
        "--noise-sd",
        noise[0],
        noise[1],
        "--seed",
        seed,
        "--out",
        out.to_str().unwrap(),
    ]);
    out.join("recording.csv")
}

/// `design --model model --limits limits REST --out out`.
fn design(model: &Path, limits: &str, rest: &[&str], out: &Path) -> std::process::Output {
    let mut args = vec![
        "design",
        "--model",
        model.to_str().unwrap(),
        "--limits",
        limits,
    ];
    args.extend_from_slice(rest);
    args.extend(["--out", out.to_str().unwrap()]);
    motorcal(&args)
}

/// `design` on the fixture, which must succeed.
fn design_fixture(rest: &[&str], out: &Path) {
    let o = design(&model_path(), LIMITS, rest, out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn diagnose(recording: &Path, report: &Path) -> serde_json::Value {
    run(&[
        "diagnose",
        "--data",
        recording.to_str().unwrap(),
        "--model",
        model_path().to_str().unwrap(),
        "--rank-only",
        "--json",
        report.to_str().unwrap(),
    ]);
    json(report)
}

#[test]
fn a_designed_reference_parts_coulomb_friction_from_a_load_and_the_loop_closes() {
    let dir = scratch("design-position", "loop");
    // A record that never reverses: the reference ramps at 0.1 m/s for a second, and the
    // truth's Coulomb friction (3 N, under the 5-N noise of the force) is a constant load there.
    let ramp = dir.join("ramp.csv");
    let rows: String = (1..=1000)
        .map(|i| format!("{},{}\n", i as f64 / 1000.0, 0.1 * i as f64 / 1000.0))
        .collect();
    std::fs::write(&ramp, format!("t,q_ref\n{rows}")).unwrap();
    let coulomb = "[terms.coulomb_friction]\nT_c = 3.0\nomega_s = 0.005\n";
    let truth = truth_file(&dir, "coulomb", 95.2, 205.0, coulomb);
    let recorded = simulate(&truth, &ramp, NOISE, "3", &dir.join("ramp"));
    let diagnosis = diagnose(&recorded, &dir.join("ramp.json"));
    assert_eq!(
        diagnosis["tied_pairs"],
        serde_json::json!([["coulomb_friction", "load_torque"]]),
        "{}",
        diagnosis["ranking"]
    );

    // Without a diagnosis, the candidates fitted to the record give σ, which a position loop
    // has no default for.
    let fitted = dir.join("fitted");
    design_fixture(
        &[
            "--data",
            recorded.to_str().unwrap(),
            "--separate",
            "coulomb_friction,load_torque",
            "--duration",
            "0.2",
            "--rate",
            "1000",
            "--starts",
            "1",
            "--draws",
            "2",
            "--no-rival-check",
        ],
        &fitted,
    );
    let sd = json(&fitted.join("design.json"))["noise_sd"].clone();
    let sd_q = sd["q"].as_f64().unwrap();
    let sd_force = sd["force"].as_f64().unwrap();
    assert!((sd_q / 2e-6 - 1.0).abs() < 0.2, "σ_q {sd_q}");
    assert!((sd_force / 5.0 - 1.0).abs() < 0.2, "σ_force {sd_force}");

    let out = dir.join("design");
    let diagnosis_path = dir.join("ramp.json");
    design_fixture(
        &[
            "--diagnosis",
            diagnosis_path.to_str().unwrap(),
            "--duration",
            "1",
            "--rate",
            "1000",
            "--noise-sd",
            NOISE[0],
            NOISE[1],
        ],
        &out,
    );
    let report = json(&out.join("design.json"));
    assert_eq!(
        report["candidates"],
        serde_json::json!(["coulomb_friction", "load_torque"])
    );
    assert_eq!(report["input"]["quantity"], "q_ref");
    assert_eq!(report["input"]["levels"]["quantity"], "reference speed");
    let gap = report["expected_gap_nats"].as_f64().unwrap();
    assert!(gap >= 10.0, "expected gap {gap}");
    for fixed in report["fixed_experiments"].as_array().unwrap() {
        let g = fixed["expected_gap_nats"].as_f64().unwrap();
        assert!(gap > g, "designed {gap} nats, {} {g}", fixed["input"]);
    }

    // The reference as written: from where the axis rests, at most the speed limit.
    let text = std::fs::read_to_string(out.join("input.csv")).unwrap();
    assert!(
        text.starts_with("t,q_ref\n"),
        "{}",
        &text[..20.min(text.len())]
    );
    let reference = read_input_profile(&out.join("input.csv"), "q_ref").unwrap();
    assert_eq!(reference.values[0], 0.0);
    let fastest = reference
        .values
        .windows(2)
        .zip(reference.times.windows(2))
        .map(|(q, t)| ((q[1] - q[0]) / (t[1] - t[0])).abs())
        .fold(0.0f64, f64::max);
    assert!(
        fastest <= 0.5 && fastest > 0.005,
        "reference speed {fastest}"
    );

    // Each candidate as the truth at the design's estimate (its smoothing speed the design's:
    // 1% of the speed limit), played the written reference by `simulate`, outside the design's
    // code: noise-free within the limits, and named by `diagnose` from a noisy record.
    let at = &report["candidates_at"]["values"];
    let value = |c: &str, k: &str| at[c][k].as_f64().unwrap();
    let truths = [
        (
            "coulomb_friction",
            format!(
                "[terms.coulomb_friction]\nT_c = {}\nomega_s = 0.005\n",
                value("coulomb_friction", "coulomb_friction.T_c")
            ),
        ),
        (
            "load_torque",
            format!(
                "[terms.load_torque]\nT_0 = {}\n",
                value("load_torque", "load_torque.T_0")
            ),
        ),
    ];
    let map = ChannelMap::default();
    for (name, terms) in &truths {
        let truth = truth_file(&dir, name, value(name, "J"), value(name, "d"), terms);
        let input = out.join("input.csv");
        let clean = simulate(
            &truth,
            &input,
            ["0", "0"],
            "1",
            &dir.join(format!("{name}-clean")),
        );
        let r = read_recording_for(&clean, &map, Base::PositionLoop).unwrap();
        let q = r.channel("q").unwrap();
        let force = r.channel("force").unwrap();
        let peak = |v: &[f64]| v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let speed = q
            .windows(2)
            .zip(r.time.windows(2))
            .map(|(q, t)| ((q[1] - q[0]) / (t[1] - t[0])).abs())
            .fold(0.0f64, f64::max);
        assert!(peak(q) <= 0.1, "{name}: |q| reaches {}", peak(q));
        assert!(speed <= 0.5, "{name}: the axis reaches {speed} m/s");
        assert!(
            peak(force) <= 300.0,
            "{name}: |force| reaches {}",
            peak(force)
        );
        assert!(speed > 0.01, "{name}: the axis hardly moves ({speed} m/s)");

        let noisy = simulate(&truth, &input, NOISE, "11", &dir.join(name));
        let named = diagnose(&noisy, &dir.join(format!("{name}.json")));
        assert_eq!(named["selected"], *name, "{}", named["ranking"]);
    }
}

#[test]
fn a_position_loop_design_needs_its_travel_and_speed_and_the_saturation() {
    let dir = scratch("design-position", "refused");
    let pin = ["--pin", "J", "--duration", "0.05", "--rate", "400"];
    let with_noise = [&pin[..], &["--noise-sd", NOISE[0], NOISE[1]]].concat();
    let out = dir.join("design");
    // A voltage's limits leave the travel out.
    let o = design(&model_path(), "U=±24,I=±300,omega=±3000", &with_noise, &out);
    one_error_line(
        &o,
        &[
            "--limits",
            "q (the travel) not limited",
            "position_loop",
            "q=±VALUE",
        ],
    );
    assert!(!out.exists());
    // Without the controller's saturation nothing bounds the force.
    let text = std::fs::read_to_string(model_path())
        .unwrap()
        .replace("input_limit = 10.0\n", "");
    let unsaturated = dir.join("unsaturated.toml");
    std::fs::write(&unsaturated, text).unwrap();
    let o = design(&unsaturated, LIMITS, &with_noise, &out);
    one_error_line(&o, &["drive.input_limit", "saturation"]);
    assert!(!out.exists());
    // Without σ for q and the force there is no default to fall back on.
    let o = design(&model_path(), LIMITS, &pin, &out);
    one_error_line(&o, &["--noise-sd", "'q'"]);
    assert!(!out.exists());
}

#[test]
fn a_library_design_keeps_a_position_loop_under_its_saturation_unless_told() {
    use motorcal::design::{self, DesignSettings, Experiment, SearchSettings, Target};
    let model = motorcal::io::read_model_file(&model_path()).unwrap();
    let times = design::design_times(0.2, 1000.0).unwrap();
    // No force limit given: a caller of the library gets the command's default, 2% under
    // the controller's saturation c_g·input_limit = 351.5 N.
    let limits: design::Limits = "q=±0.1,omega=±0.5".parse().unwrap();
    let base = design::design_problem(&model, &times, &limits).unwrap();
    let targets = [Target::parse("J"), Target::parse("d")];
    let candidate =
        design::pin_candidate(&base, &std::collections::BTreeMap::new(), &targets).unwrap();
    let experiment = Experiment {
        candidates: vec![candidate.clone()],
        times,
        noise_sd: vec![2e-6, 5.0],
    };
    let settings = DesignSettings {
        search: SearchSettings {
            segments: 4,
            starts: 1,
            ..SearchSettings::default()
        },
        limits,
        draws: 2,
    };
    let d = design::pin(&candidate, &experiment, &targets, &settings).unwrap();
    let force = d.check.peaks["force"];
    assert!(force <= design::MARGIN * 351.5, "|force| reaches {force} N");
    assert!(d.check.within_limits);
}

/// The fixture with the initial position's offset calibrated beside J and d, in `dir`.
fn with_initial_offset(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(model_path()).unwrap() + "q0_offset = {}\n";
    let path = dir.join("position_loop_q0.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// A reference ramping at 2 cm/s from rest, sampled at 1 kHz over 0.5 s, as `t,q_ref`.
fn ramp(dir: &Path) -> PathBuf {
    let mut text = String::from("t,q_ref\n");
    for k in 1..=500 {
        let t = k as f64 * 1e-3;
        text.push_str(&format!("{t},{}\n", 0.02 * (t - 1e-3)));
    }
    let path = dir.join("ramp.csv");
    std::fs::write(&path, text).unwrap();
    path
}

/// The axis's initial position is the first measured q, and that sample's noise moved J's
/// MAP with it (`papers/design.md`, "Over many records": J spread 1.2–1.6 times its posterior
/// sd over 50 records). The offset `q0_offset` takes it out. It is a parameter like any
/// other: its sensitivities are the derivatives of the sampled solve (central differences),
/// and calibrated on a record it puts the axis where it started (at rest, at the reference's
/// first value) to within three of its sds, sds under half a sample's noise.
#[test]
fn the_initial_position_offset_is_differentiated_and_calibrated_back_to_where_the_axis_started() {
    use motorcal::ode::SolverSettings;
    use motorcal::study::Problem;
    let dir = scratch("design-position", "initial-offset");
    let model = with_initial_offset(&dir);
    let recording = simulate(&model_path(), &ramp(&dir), NOISE, "31", &dir.join("rec"));
    let problem = Problem::from_files(std::slice::from_ref(&recording), &model).unwrap();
    let forward = problem.forward(SolverSettings::default()).unwrap();
    let names = forward.calibrated_names();
    let at = names
        .iter()
        .position(|n| n == "q0_offset")
        .expect("calibrated");
    let mut theta = forward.nominal_calibrated();
    theta[at] = 1.5e-6;
    let jacobian = assert_sensitivities_are_central_differences(&forward, &theta, |k| {
        if k == at { 1e-7 } else { 1e-6 * theta[k].abs() }
    });
    for (k, name) in names.iter().enumerate() {
        assert!(jacobian.column(k).amax() > 0.0, "{name}: no sensitivity");
    }
    let out = dir.join("fit");
    run(&[
        "fit",
        "--data",
        recording.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
        "--bm",
        "1",
        "--map-only",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    let fit = json(&out.join("fit.json"));
    let offset = fit["map"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "q0_offset")
        .expect("q0_offset in the MAP")
        .clone();
    let (value, sd) = (
        offset["value"].as_f64().unwrap(),
        offset["laplace_sd"].as_f64().unwrap(),
    );
    let first: f64 = std::fs::read_to_string(&recording)
        .unwrap()
        .lines()
        .nth(1)
        .unwrap()
        .split(',')
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    let started = first + value;
    eprintln!("first q {first:e}, offset {value:e} ± {sd:e}: start {started:e}");
    assert!(sd < 1e-6, "sd {sd:e} against σ_q 2e-6");
    assert!(
        started.abs() < 3.0 * sd,
        "started at {started:e} ± {sd:e}, not 0"
    );
}
