//! Pareto-smoothed importance sampling against ArviZ 0.23.4's `az.psislw` (reff = 1) on the
//! cases `tests/fixtures/make_psis_fixture.py` made: wider and narrower normal proposals for a
//! normal, a normal proposal for a Student-t, a multivariate t proposal for a 5-d normal, and
//! short samples (a tail at n/5, and one too short to fit). k̂ and every smoothed log weight
//! must agree to 1e-9 (absolute, on log weights normalised to sum to one), and the weights'
//! ESS to 1e-9 relative.

use motorcal::diagnostics::{KHAT_GOOD, KHAT_UNRELIABLE, psis};
use serde_json::Value;

const FIXTURE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/fixtures/psis_reference.json"
);
const TOLERANCE: f64 = 1e-9;

fn floats(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("an array")
        .iter()
        .map(|x| x.as_f64().expect("a number"))
        .collect()
}

#[test]
fn khat_and_smoothed_weights_match_arviz() {
    let text = std::fs::read_to_string(FIXTURE).expect("read the PSIS fixture");
    let reference: Value = serde_json::from_str(&text).expect("parse the PSIS fixture");
    let cases = reference["cases"].as_array().expect("cases");
    assert_eq!(cases.len(), 6);
    for case in cases {
        let name = case["name"].as_str().unwrap();
        let ours = psis(&floats(&case["log_weights"]));
        match case["khat"].as_f64() {
            Some(k) => assert!(
                (ours.khat - k).abs() < TOLERANCE,
                "{name}: k̂ {} vs ArviZ {k}",
                ours.khat
            ),
            None => assert_eq!(ours.khat, f64::INFINITY, "{name}"),
        }
        let smoothed = floats(&case["smoothed"]);
        assert_eq!(smoothed.len(), ours.log_weights.len());
        for (i, (a, b)) in ours.log_weights.iter().zip(&smoothed).enumerate() {
            assert!((a - b).abs() < TOLERANCE, "{name}[{i}]: {a} vs ArviZ {b}");
        }
        let ess = case["ess"].as_f64().unwrap();
        assert!(
            (ours.ess() / ess - 1.0).abs() < TOLERANCE,
            "{name}: ESS {} vs {ess}",
            ours.ess()
        );
        eprintln!("{name:9} k̂ = {:8.4}  ESS = {:7.1}", ours.khat, ours.ess());
    }
    // The fixture's cases span the thresholds, so the comparison above covers both sides.
    let khat = |name: &str| {
        let case = cases.iter().find(|c| c["name"] == name).unwrap();
        psis(&floats(&case["log_weights"])).khat
    };
    assert!(khat("wide") < KHAT_GOOD && khat("gauss_5d") < KHAT_GOOD);
    assert!(khat("narrow") > KHAT_UNRELIABLE && khat("t_from_n") > KHAT_UNRELIABLE);
}
