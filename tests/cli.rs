//! The command line as a user meets it: the README's commands work, and bad input gets one
//! clear error line, a non-zero exit and no output.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn motorcal(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_motorcal"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("motorcal-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn assert_clean_failure(o: &Output, needles: &[&str]) {
    assert!(
        !o.status.success(),
        "expected failure, got success: {}",
        String::from_utf8_lossy(&o.stdout)
    );
    let err = stderr(o);
    let lines: Vec<&str> = err.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "expected one error line, got: {err}");
    assert!(!err.contains("panicked"), "{err}");
    for needle in needles {
        assert!(
            err.contains(needle),
            "error '{err}' does not mention '{needle}'"
        );
    }
}

fn simulate_into(dir: &Path) {
    let o = motorcal(&[
        "simulate",
        "--out",
        dir.to_str().unwrap(),
        "--seed",
        "3",
        "--input",
        "reversal",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn simulate_then_fit_map_writes_a_report() {
    let dir = scratch("fit");
    simulate_into(&dir);
    for f in ["recording.csv", "motor.toml", "truth.toml"] {
        assert!(dir.join(f).exists(), "{f} missing");
    }
    let out = dir.join("out");
    let o = motorcal(&[
        "fit",
        "--data",
        dir.join("recording.csv").to_str().unwrap(),
        "--model",
        dir.join("motor.toml").to_str().unwrap(),
        "--map-only",
        "--k",
        "5",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("fit.json")).unwrap()).unwrap();
    let r = report["map"][0]["value"].as_f64().unwrap();
    assert!((r - 0.1).abs() < 0.01, "MAP of R = {r}");
}

#[test]
fn a_fit_with_a_sampler_writes_draws_that_summarize_reads_back() {
    let dir = scratch("sample");
    simulate_into(&dir);
    let out = dir.join("out");
    let o = motorcal(&[
        "fit",
        "--data",
        dir.join("recording.csv").to_str().unwrap(),
        "--model",
        dir.join("motor.toml").to_str().unwrap(),
        "--bm",
        "1",
        "--sampler",
        "adaptive-metropolis",
        "--chains",
        "2",
        "--warmup",
        "300",
        "--draws",
        "300",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    for f in ["predictive.csv", "predictive.png", "traces.png", "fit.json"] {
        assert!(out.join(f).exists(), "{f} missing");
    }
    let draws: Vec<String> = (1..=2)
        .map(|c| {
            out.join(format!("fit-adaptive-metropolis-chain{c}.csv"))
                .display()
                .to_string()
        })
        .collect();
    let mut args = vec!["summarize"];
    args.extend(draws.iter().map(|s| s.as_str()));
    let o = motorcal(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("2 chains × 300 draws") && text.contains("sigma_omega"),
        "{text}"
    );
}

#[test]
fn an_unknown_key_in_the_model_file_names_file_line_and_field() {
    let dir = scratch("badtoml");
    simulate_into(&dir);
    let model = dir.join("bad.toml");
    std::fs::write(&model, "[motor]\nR = 0.1\nc_q = 3\n").unwrap();
    let out = dir.join("out");
    let o = motorcal(&[
        "fit",
        "--data",
        dir.join("recording.csv").to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
        "--map-only",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_clean_failure(&o, &["bad.toml", ":3", "c_q"]);
    assert!(!out.exists(), "a failed run wrote output");
}

#[test]
fn a_non_positive_inductance_is_refused() {
    let dir = scratch("badl");
    simulate_into(&dir);
    let model = dir.join("bad.toml");
    std::fs::write(&model, "[motor]\nL = -1e-4\n").unwrap();
    let o = motorcal(&[
        "fit",
        "--data",
        dir.join("recording.csv").to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
        "--map-only",
    ]);
    assert_clean_failure(&o, &["bad.toml", "L"]);
}

#[test]
fn time_going_backwards_in_a_recording_names_the_line() {
    let dir = scratch("badcsv");
    simulate_into(&dir);
    let csv = dir.join("bad.csv");
    std::fs::write(&csv, "t,I,omega\n0.1,1,2\n0.2,1,2\n0.15,1,2\n0.3,1,2\n").unwrap();
    let o = motorcal(&[
        "fit",
        "--data",
        csv.to_str().unwrap(),
        "--model",
        dir.join("motor.toml").to_str().unwrap(),
        "--map-only",
    ]);
    assert_clean_failure(&o, &["bad.csv", ":4", "t"]);
}

#[test]
fn a_nan_cell_names_its_column() {
    let dir = scratch("nan");
    simulate_into(&dir);
    let csv = dir.join("nan.csv");
    std::fs::write(&csv, "t,I,omega\n0.1,1,2\n0.2,NaN,2\n").unwrap();
    let o = motorcal(&[
        "fit",
        "--data",
        csv.to_str().unwrap(),
        "--model",
        dir.join("motor.toml").to_str().unwrap(),
        "--map-only",
    ]);
    assert_clean_failure(&o, &["nan.csv", ":3", "I"]);
}

#[test]
fn impossible_options_are_refused_before_any_work() {
    let dir = scratch("opts");
    simulate_into(&dir);
    let data = dir.join("recording.csv");
    let model = dir.join("motor.toml");
    let base = [
        "fit",
        "--data",
        data.to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
    ];
    let run = |extra: &[&str]| {
        let mut args: Vec<&str> = base.to_vec();
        args.extend_from_slice(extra);
        motorcal(&args)
    };
    assert_clean_failure(&run(&["--k", "41"]), &["--k 41"]);
    assert_clean_failure(&run(&["--chains", "0"]), &["--chains 0"]);
    assert_clean_failure(&run(&["--draws", "100", "--keep", "200"]), &["keep 200"]);
    assert_clean_failure(&run(&["--threads", "0"]), &["--threads 0"]);
    // A budget for a fallback that will not happen.
    assert_clean_failure(
        &run(&["--sampler", "nuts-dense", "--fallback-budget", "16"]),
        &["--fallback-budget 16", "laplace-is"],
    );
    assert_clean_failure(
        &run(&[
            "--sampler",
            "laplace-is",
            "--no-fallback",
            "--fallback-budget",
            "16",
        ]),
        &["--fallback-budget 16", "off"],
    );
}

#[test]
fn a_bad_schema_2_model_file_is_one_error_line_and_nothing_written() {
    let dir = scratch("schema2");
    simulate_into(&dir);
    let data = dir.join("recording.csv");
    let out = dir.join("out");
    for (text, needles) in [
        (
            "schema = 2\n[terms.colomb_friction]\nT_c = 0.1\n",
            &["bad.toml", ":2", "terms.colomb_friction", "unknown term"][..],
        ),
        (
            "schema = 2\n[calibrate]\n\"coulomb_friction.T_c\" = { prior = \"gamma\" }\n",
            &["bad.toml", ":3", "calibrate.coulomb_friction.T_c.prior"][..],
        ),
        (
            "schema = 2\n[calibrate]\nR = { prior = \"uniform\", lower = 0.05 }\n",
            &["bad.toml", ":3", "calibrate.R.upper"][..],
        ),
    ] {
        let model = dir.join("bad.toml");
        std::fs::write(&model, text).unwrap();
        let o = motorcal(&[
            "fit",
            "--data",
            data.to_str().unwrap(),
            "--model",
            model.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--map-only",
        ]);
        assert_clean_failure(&o, needles);
        assert!(!out.join("fit.json").exists());
    }
}

#[test]
fn fit_takes_several_recordings_and_a_schema_2_model() {
    let dir = scratch("several");
    simulate_into(&dir);
    let second = dir.join("second");
    std::fs::create_dir_all(&second).unwrap();
    let o = motorcal(&["simulate", "--out", second.to_str().unwrap(), "--seed", "4"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let model = dir.join("model.toml");
    std::fs::write(
        &model,
        "schema = 2\n[motor]\nc_g = 0.009\n[calibrate]\nR = {}\n\"torque_constant.k\" = {}\n\
         [discrepancy]\nbasis = \"none\"\n",
    )
    .unwrap();
    let out = dir.join("out");
    let o = motorcal(&[
        "fit",
        "--data",
        dir.join("recording.csv").to_str().unwrap(),
        "--data",
        second.join("recording.csv").to_str().unwrap(),
        "--model",
        model.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--map-only",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("fit.json")).unwrap()).unwrap();
    assert_eq!(
        report["calibrated"],
        serde_json::json!(["R", "torque_constant.k"])
    );
    assert_eq!(report["data"].as_array().unwrap().len(), 2);
    assert_eq!(
        report["fit"].as_array().unwrap().len(),
        4,
        "two channels × two records"
    );
    assert!(
        report["settings"]["discrepancy_degree"].is_null(),
        "basis none is BM1"
    );
}

#[test]
fn simulate_takes_a_schema_2_truth_with_terms() {
    let dir = scratch("truth2");
    let truth = dir.join("truth-in.toml");
    std::fs::write(
        &truth,
        "schema = 2\n[terms.coulomb_friction]\nT_c = 0.2\n[terms.current_offset]\nb_I = 5.0\n",
    )
    .unwrap();
    let run = |out: &Path, truth: Option<&Path>| {
        let mut args = vec!["simulate", "--out", out.to_str().unwrap(), "--seed", "5"];
        if let Some(t) = truth {
            args.extend(["--truth", t.to_str().unwrap()]);
        }
        let o = motorcal(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        std::fs::read_to_string(out.join("recording.csv")).unwrap()
    };
    let with = run(&dir.join("with"), Some(&truth));
    let plain = dir.join("plain.toml");
    std::fs::write(&plain, "schema = 2\n").unwrap();
    let without = run(&dir.join("without"), Some(&plain));
    assert_ne!(with, without, "the terms change the recording");
    // The truth is written back with its terms.
    let back = std::fs::read_to_string(dir.join("with/truth.toml")).unwrap();
    assert!(back.contains("[terms.coulomb_friction]") && back.contains("T_c = 0.2"));
}

#[test]
fn diagnose_refuses_bad_input_with_one_line_and_writes_nothing() {
    let dir = scratch("diagnose-bad");
    simulate_into(&dir);
    let data = dir.join("recording.csv");
    let model = dir.join("motor.toml");
    let json = dir.join("report.json");
    let out = dir.join("out");
    let run = |data: &Path, extra: &[&str]| {
        let mut args = vec![
            "diagnose",
            "--data",
            data.to_str().unwrap(),
            "--model",
            model.to_str().unwrap(),
            "--json",
            json.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        motorcal(&args)
    };
    assert_clean_failure(
        &run(&data, &["--candidates", "coulomb_friction,magic"]),
        &["--candidates", "magic", "coulomb_friction"],
    );
    assert_clean_failure(&run(&data, &["--k", "41"]), &["--k 41"]);
    assert_clean_failure(&run(&data, &["--chains", "0"]), &["--chains 0"]);
    let short = scratch("diagnose-short");
    let o = motorcal(&[
        "simulate",
        "--out",
        short.to_str().unwrap(),
        "--samples",
        "20",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_clean_failure(
        &run(&short.join("recording.csv"), &[]),
        &["recording.csv", "too short"],
    );
    assert!(!json.exists() && !out.exists());
}

#[test]
fn simulate_effect_makes_a_concealed_fair_case() {
    let dir = scratch("effect");
    let o = motorcal(&[
        "simulate",
        "--effect",
        "load_step",
        "--conceal",
        "--seed",
        "5",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let answer: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("answer.json")).unwrap()).unwrap();
    assert_eq!(answer["effect"], "load_step");
    let peak = ["I", "omega"]
        .iter()
        .map(|c| answer["max_abs_effect_over_sigma"][c].as_f64().unwrap())
        .fold(0.0, f64::max);
    assert!(peak < 1.5 && peak > 0.1, "peak {peak}");
    assert!(answer["oracle_margin"].as_f64().unwrap() >= 3.0);
    assert!(answer["oracle_margin_over_none"].as_f64().unwrap() >= 5.0);
    // And the noisy record it wrote holds the effect.
    assert!(answer["oracle_margin_over_none_realized"].as_f64().unwrap() >= 5.0);
    for f in ["recording.csv", "motor.toml"] {
        assert!(dir.join(f).exists(), "{f}");
    }
}

/// `--tied` keeps the input asked and redraws until the truth ties with its look-alike: a
/// concealed Coulomb friction on a constant input (which never reverses) is a constant torque
/// the oracle cannot tell from a load torque, yet stands out from no effect.
#[test]
fn simulate_tied_makes_a_concealed_tie_on_the_input_asked() {
    let dir = scratch("tied");
    let o = motorcal(&[
        "simulate",
        "--effect",
        "coulomb_friction",
        "--conceal",
        "--tied",
        "--input",
        "constant",
        "--seed",
        "2",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let answer: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("answer.json")).unwrap()).unwrap();
    assert_eq!(answer["input"], "constant");
    assert_eq!(answer["input_fallback"], false);
    assert_eq!(answer["oracle_runner_up"], "load_torque");
    assert!(answer["oracle_margin"].as_f64().unwrap() < 3.0);
    assert!(answer["oracle_margin_over_none"].as_f64().unwrap() >= 5.0);
    assert!(String::from_utf8_lossy(&o.stdout).contains("tied with load_torque"));
}

#[test]
fn simulate_effect_refuses_what_it_cannot_make() {
    let dir = scratch("effect-bad");
    let out = dir.join("case");
    let run = |extra: &[&str]| {
        let mut args = vec!["simulate", "--out", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        motorcal(&args)
    };
    assert_clean_failure(
        &run(&["--effect", "gremlins"]),
        &["gremlins", "coulomb_friction"],
    );
    assert_clean_failure(
        &run(&["--effect", "coulomb_friction", "--magnitude", "-1"]),
        &["--magnitude -1"],
    );
    assert_clean_failure(
        &run(&[
            "--effect",
            "coulomb_friction",
            "--magnitude",
            "2",
            "--conceal",
        ]),
        &["--magnitude 2", "1.5"],
    );
    // A tie is a concealed effect's: --tied alone is refused.
    assert_clean_failure(
        &run(&["--effect", "coulomb_friction", "--tied"]),
        &["--tied", "--conceal"],
    );
    assert!(!out.exists());
}

#[test]
fn sweep_refuses_impossible_degrees_with_one_line() {
    let dir = scratch("sweep-bad");
    let out = dir.join("out");
    let run = |k: &str| motorcal(&["sweep", "--k", k, "--out", out.to_str().unwrap()]);
    assert_clean_failure(&run("5..2"), &["5..2", "empty"]);
    assert_clean_failure(&run("0,x"), &["0,x"]);
    assert_clean_failure(&run("3,41"), &["--k 41"]);
    assert!(!out.exists());
}

#[test]
fn sweep_shard_rule_and_merge_mistakes_are_one_line() {
    let dir = scratch("merge-bad");
    let out = dir.join("out");
    let o = out.to_str().unwrap();
    assert_clean_failure(
        &motorcal(&["sweep", "--k", "0", "--shard", "0/3", "--out", o]),
        &["--shard 0/3"],
    );
    assert_clean_failure(
        &motorcal(&["select-k", "--rule", "coin-toss", "--out", o]),
        &["--rule coin-toss", "evidence"],
    );
    assert_clean_failure(
        &motorcal(&["select-k", "--shard", "1/2", "--out", o]),
        &["--shard"],
    );
    let part = dir.join("part.json");
    std::fs::write(&part, "[\n  {\"k\": 3,\n   \"bogus\": 1}\n]\n").unwrap();
    assert_clean_failure(
        &motorcal(&["merge", part.to_str().unwrap(), "--out", o]),
        &["part.json", "line"],
    );
    assert!(!out.exists());
}
