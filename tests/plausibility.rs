//! Recordings that cannot be this motor are named as such, with the likely mistake, before any
//! physics is asked of them; recordings that can be pass untouched.

use std::path::Path;

use motorcal::io::Recording;
use motorcal::study::Problem;
use motorcal::study::plausibility::{Finding, check};

fn paper() -> Problem {
    Problem::paper(motorcal::synthetic::DEFAULT_SEED).unwrap()
}

/// The paper's recording with `alter` applied to it.
fn altered(mut alter: impl FnMut(&mut Recording)) -> Problem {
    let mut problem = paper();
    alter(&mut problem.recordings[0]);
    problem
}

fn channel<'a>(r: &'a mut Recording, name: &str) -> &'a mut Vec<f64> {
    &mut r.channels.iter_mut().find(|(n, _)| n == name).unwrap().1
}

fn findings(problem: &Problem) -> Vec<Finding> {
    let started = std::time::Instant::now();
    let found = check(problem).unwrap();
    for f in &found {
        eprintln!("{f}");
    }
    eprintln!("checked in {:.3} s", started.elapsed().as_secs_f64());
    found
}

fn assert_named(found: &[Finding], channel: &str, cause: &str) {
    assert!(
        found.iter().any(|f| f.channel == channel
            && (f.likely_cause.contains(cause) || f.finding.contains(cause))),
        "expected {channel}: …{cause}…, found {found:#?}"
    );
}

#[test]
fn the_papers_recording_is_plausible() {
    assert!(findings(&paper()).is_empty());
}

#[test]
fn all_channels_zero_is_a_dead_recording() {
    let found = findings(&altered(|r| {
        for (_, v) in r.channels.iter_mut() {
            v.iter_mut().for_each(|x| *x = 0.0);
        }
    }));
    assert_named(&found, "I", "was the drive running");
    assert_named(&found, "omega", "was the drive running");
    assert!(
        found
            .iter()
            .any(|f| f.finding.contains("omega is 0 throughout"))
    );
}

#[test]
fn a_constant_speed_channel_is_named() {
    let found = findings(&altered(|r| {
        channel(r, "omega").iter_mut().for_each(|x| *x = 1234.5)
    }));
    assert_named(&found, "omega", "was the drive running");
    assert!(found.iter().all(|f| f.channel != "I"), "{found:#?}");
}

#[test]
fn swapped_current_and_speed_are_named() {
    let found = findings(&altered(|r| {
        let i = channel(r, "I").clone();
        let w = channel(r, "omega").clone();
        *channel(r, "I") = w;
        *channel(r, "omega") = i;
    }));
    assert_named(&found, "I/omega", "swapped");
}

#[test]
fn the_current_in_a_wrong_unit_is_named() {
    let scaled =
        |factor: f64| altered(move |r| channel(r, "I").iter_mut().for_each(|x| *x *= factor));
    assert_named(&findings(&scaled(1e3)), "I", "mA");
    // No factor we know: named as a scale the file does not state, by its order of magnitude.
    assert_named(&findings(&scaled(1e12)), "I", "about 1e12");
    assert_named(&findings(&scaled(-2.5e4)), "I", "about −1e4");
}

#[test]
fn the_speed_in_rpm_is_named() {
    let found = findings(&altered(|r| {
        let f = 60.0 / (2.0 * std::f64::consts::PI);
        channel(r, "omega").iter_mut().for_each(|x| *x *= f)
    }));
    assert_named(&found, "omega", "rpm");
}

#[test]
fn a_sign_flipped_current_is_named() {
    let found = findings(&altered(|r| {
        channel(r, "I").iter_mut().for_each(|x| *x = -*x)
    }));
    assert_named(&found, "I", "wrong sign");
}

#[test]
fn time_in_milliseconds_is_named() {
    let found = findings(&altered(|r| r.time.iter_mut().for_each(|t| *t *= 1e3)));
    assert_named(&found, "t", "ms");
}

#[test]
fn a_recording_of_pure_noise_is_named() {
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let found = findings(&altered(|r| {
        for (_, v) in r.channels.iter_mut() {
            v.iter_mut()
                .for_each(|x| *x = Normal::new(0.0, 5.0).unwrap().sample(&mut rng));
        }
    }));
    assert_named(&found, "I", "does not follow");
    assert_named(&found, "omega", "does not follow");
}

/// The development set's fourteen cases pass untouched (skipped without ../shared).
#[test]
fn the_development_set_is_plausible() {
    let dev = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/concealed-dev");
    if !dev.is_dir() {
        eprintln!("skipped: {} is absent", dev.display());
        return;
    }
    for i in 1..=14 {
        let dir = dev.join(format!("case{i:02}"));
        let problem =
            Problem::from_files(&[dir.join("recording.csv")], &dir.join("motor.toml")).unwrap();
        assert!(findings(&problem).is_empty(), "case{i:02}");
    }
}

/// The crate's own concealed cases pass untouched (no ../shared needed).
#[test]
fn the_fixture_cases_are_plausible() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/cases");
    for case in ["coulomb_friction", "torque_constant"] {
        let dir = root.join(case);
        let problem =
            Problem::from_files(&[dir.join("recording.csv")], &dir.join("motor.toml")).unwrap();
        assert!(findings(&problem).is_empty(), "{case}");
    }
}

/// The real EMPS and HSM150 records with the examples' drive models pass untouched (skipped
/// without ../shared).
#[test]
fn the_real_records_are_plausible() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let real = root.join("../shared/data/real");
    if !real.is_dir() {
        eprintln!("skipped: {} is absent", real.display());
        return;
    }
    let emps = Problem::from_files(
        &[real.join("emps/emps_estimation.csv")],
        &root.join("examples/emps/model.toml"),
    )
    .unwrap();
    assert!(findings(&emps).is_empty(), "EMPS");
    for name in [
        "idf_pos_0.06_1",
        "idf_neg_0.04_1",
        "idf_pos_0.06_2",
        "idf_neg_0.04_3",
    ] {
        let hsm = Problem::from_files(
            &[real.join(format!("hsm150/{name}.csv"))],
            &root.join("examples/hsm150/model.toml"),
        )
        .unwrap();
        assert!(findings(&hsm).is_empty(), "HSM150 {name}");
    }
}

/// The commands refuse such a recording with one line per finding and write nothing; with
/// `--force` diagnose goes on, reports the findings and selects no physics, and fit keeps them in
/// fit.json.
#[test]
fn diagnose_refuses_a_dead_recording_unless_forced() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("motorcal-plaus-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let case = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/cases/torque_constant");
    let text = std::fs::read_to_string(case.join("recording.csv")).unwrap();
    let mut zeroed = String::new();
    for (i, line) in text.lines().enumerate() {
        if i == 0 || line.starts_with('#') {
            zeroed.push_str(line);
        } else {
            let t = line.split(',').next().unwrap();
            zeroed.push_str(&format!("{t},0,0"));
        }
        zeroed.push('\n');
    }
    assert!(text.lines().next().unwrap().starts_with("t,I,omega"));
    let data = dir.join("zeros.csv");
    std::fs::write(&data, zeroed).unwrap();
    let json = dir.join("report.json");
    let run = |extra: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_motorcal"))
            .args(["diagnose", "--quiet", "--rank-only", "--data"])
            .arg(&data)
            .arg("--model")
            .arg(case.join("motor.toml"))
            .arg("--json")
            .arg(&json)
            .args(extra)
            .output()
            .unwrap()
    };
    let refused = run(&[]);
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success());
    assert!(
        stderr.contains("zeros.csv") && stderr.contains("omega is 0 throughout"),
        "{stderr}"
    );
    assert!(!json.exists(), "nothing written");
    let forced = run(&["--force"]);
    assert!(
        forced.status.success(),
        "{}",
        String::from_utf8_lossy(&forced.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(report["selected"], "none");
    assert!(!report["implausible"].as_array().unwrap().is_empty());

    // fit: the same refusal, and with --force the findings go into fit.json.
    let fit = |extra: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_motorcal"))
            .args(["fit", "--map-only", "--bm", "1", "--data"])
            .arg(&data)
            .arg("--model")
            .arg(case.join("motor.toml"))
            .arg("--out")
            .arg(dir.join("fit"))
            .args(extra)
            .output()
            .unwrap()
    };
    let refused = fit(&[]);
    assert!(!refused.status.success());
    assert!(!dir.join("fit/fit.json").exists(), "nothing written");
    let forced = fit(&["--force"]);
    let stdout = String::from_utf8_lossy(&forced.stdout);
    assert!(
        forced.status.success(),
        "{}",
        String::from_utf8_lossy(&forced.stderr)
    );
    assert!(
        stdout.contains("implausible (went on with --force)"),
        "{stdout}"
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("fit/fit.json")).unwrap()).unwrap();
    assert!(report["implausible"][0]["finding"].is_string(), "{report}");
    std::fs::remove_dir_all(&dir).unwrap();
}
