//! The independent-integrator cases the beyond-library tests share
//! (`tests/fixtures/beyond/`, made by `examples/beyond_library_cases.rs`): a case's recording
//! and nominal model as a problem, its answer, and the truth's parameters read from it.

use std::path::{Path, PathBuf};

use motorcal::discover::{Diagnosis, DiscoverSettings, discover};
use motorcal::study::Problem;

/// The case `name`: its problem (recording and nominal model) and its `answer.json`.
pub fn fixture(name: &str) -> (Problem, serde_json::Value) {
    let dir: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/beyond")
        .join(name);
    let problem =
        Problem::from_files(&[dir.join("recording.csv")], &dir.join("motor.toml")).unwrap();
    let answer =
        serde_json::from_str(&std::fs::read_to_string(dir.join("answer.json")).unwrap()).unwrap();
    (problem, answer)
}

/// A number of the truth's debug text, e.g. `mu` of `LoadFriction { mu: 0.00016 }`.
pub fn truth_value(answer: &serde_json::Value, key: &str) -> f64 {
    truth_field(answer, key).parse().unwrap()
}

/// A whole number of the truth's debug text, read exactly (a 64-bit salt does not survive f64).
#[allow(dead_code)] // each test binary compiles this module; not every one reads an integer
pub fn truth_integer(answer: &serde_json::Value, key: &str) -> u64 {
    truth_field(answer, key).parse().unwrap()
}

fn truth_field<'a>(answer: &'a serde_json::Value, key: &str) -> &'a str {
    let text = answer["truth"].as_str().unwrap();
    let at = text.find(&format!("{key}: ")).unwrap() + key.len() + 2;
    text[at..].split([',', ' ', '}']).next().unwrap()
}

/// The diagnosis with the whole library, the dynamic terms included, as `diagnose` runs by
/// default, ranked only and quiet (the verdicts are made before any fit is sampled).
#[allow(dead_code)] // each test binary compiles this module; not every one diagnoses
pub fn whole_library(problem: &Problem) -> Diagnosis {
    let mut settings = DiscoverSettings {
        rank_only: true,
        candidates: None,
        ..DiscoverSettings::default()
    };
    settings.run.quiet = true;
    discover(problem, &settings).unwrap()
}
