//! Our diagnostics against ArviZ 0.23.4 on the peers' NumPyro draws (BM2, K = 9, 4 × 1000).
//!
//! The reference JSON was produced by `az.ess(method="bulk" | "tail")`, `az.rhat()` and
//! `az.mcse(method="mean")` on exactly these draws; we require agreement to 1e-6 relative for
//! every parameter and statistic. The full data live outside the crate, so that test skips
//! (rather than fails) when they are absent; the crate's own fixture, a subset of the same draws
//! (3 chains × 200 draws of 5 parameters, `tests/fixtures/arviz_small_*`, made by
//! `tests/fixtures/make_arviz_fixture.py` with ArviZ 0.23.4), is checked in every clone at the
//! same tolerance.

use std::collections::BTreeMap;
use std::path::Path;

use motorcal::diagnostics::{ess_bulk, ess_tail, mcse_mean, rhat, summarize};

const DATA_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/peers/data/");
const FIXTURE_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/");
const TOLERANCE: f64 = 1e-6;

/// Parameter name → chains × draws, read from the long-format CSV `chain,draw,<params>`.
fn read_draws(path: &Path) -> BTreeMap<String, Vec<Vec<f64>>> {
    let mut reader = csv::Reader::from_path(path).expect("open draws CSV");
    let headers = reader.headers().expect("CSV header").clone();
    let chain_col = headers
        .iter()
        .position(|h| h == "chain")
        .expect("chain column");
    let draw_col = headers
        .iter()
        .position(|h| h == "draw")
        .expect("draw column");
    let mut draws: BTreeMap<String, Vec<Vec<f64>>> = BTreeMap::new();
    for record in reader.records() {
        let record = record.expect("CSV record");
        let chain: usize = record[chain_col].parse().expect("chain index");
        let draw: usize = record[draw_col].parse().expect("draw index");
        for (col, name) in headers.iter().enumerate() {
            if col == chain_col || col == draw_col {
                continue;
            }
            let value: f64 = record[col].parse().expect("numeric draw");
            let chains = draws.entry(name.to_owned()).or_default();
            if chains.len() <= chain {
                chains.resize(chain + 1, Vec::new());
            }
            // Rows are in draw order within each chain; check rather than assume it.
            assert_eq!(chains[chain].len(), draw, "draws out of order for {name}");
            chains[chain].push(value);
        }
    }
    draws
}

#[test]
fn matches_arviz_on_numpyro_draws() {
    let dir = Path::new(DATA_DIR);
    let csv_path = dir.join("numpyro_k9_draws.csv");
    let json_path = dir.join("numpyro_k9_arviz_ess.json");
    if !csv_path.is_file() || !json_path.is_file() {
        eprintln!(
            "diagnostics_arviz: reference data not found in {}; test skipped",
            dir.display()
        );
        return;
    }
    compare_with_arviz(&csv_path, &json_path, 4, 1000);
}

/// The crate's own fixture: needs nothing outside the crate, so it always runs. The subset keeps
/// a poorly mixed parameter (R: R-hat 1.04, bulk ESS 83 in 600 draws) beside well mixed ones.
#[test]
fn matches_arviz_on_the_fixture_subset() {
    let dir = Path::new(FIXTURE_DIR);
    compare_with_arviz(
        &dir.join("arviz_small_draws.csv"),
        &dir.join("arviz_small_reference.json"),
        3,
        200,
    );
}

/// Every statistic of every parameter in the reference JSON against ours on the draws of
/// `csv_path`, which must hold `n_chains` chains of `n_draws` draws each.
fn compare_with_arviz(csv_path: &Path, json_path: &Path, n_chains: usize, n_draws: usize) {
    let draws = read_draws(csv_path);
    let reference: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(json_path).expect("read JSON"))
            .expect("parse JSON");

    type Statistic = fn(&[Vec<f64>]) -> f64;
    let statistics: [(&str, Statistic); 4] = [
        ("ess_bulk", |c| ess_bulk(c)),
        ("ess_tail", |c| ess_tail(c)),
        ("rhat", |c| rhat(c)),
        ("mcse_mean", |c| mcse_mean(c)),
    ];

    let mut failures = Vec::new();
    let mut compared = 0;
    for (key, statistic) in statistics {
        let Some(expected) = reference.get(key).and_then(|v| v.as_object()) else {
            eprintln!("diagnostics_arviz: no `{key}` in the reference JSON; not compared");
            continue;
        };
        assert_eq!(expected.len(), draws.len(), "{key}: parameter sets differ");
        let mut worst = (0.0_f64, String::new());
        for (name, want) in expected {
            let want = want.as_f64().expect("numeric reference value");
            let chains = draws
                .get(name)
                .unwrap_or_else(|| panic!("{name} missing in draws"));
            assert_eq!(chains.len(), n_chains);
            assert!(chains.iter().all(|c| c.len() == n_draws));
            let got = statistic(chains);
            // A NaN on either side must fail, so count it as an infinite deviation.
            let rel = ((got - want) / want).abs();
            let rel = if rel.is_nan() { f64::INFINITY } else { rel };
            if rel > TOLERANCE {
                failures.push(format!(
                    "{key}[{name}]: ours {got:.12} ArviZ {want:.12} rel {rel:.2e}"
                ));
            }
            if rel > worst.0 {
                worst = (rel, name.clone());
            }
            compared += 1;
        }
        eprintln!(
            "diagnostics_arviz: {key}: max relative deviation {:.3e} ({})",
            worst.0, worst.1
        );
    }
    assert!(compared > 0, "nothing compared");
    assert!(
        failures.is_empty(),
        "deviations from ArviZ:\n{}",
        failures.join("\n")
    );

    // The summary must carry the same numbers as the individual functions.
    for (name, chains) in &draws {
        let s = summarize(name.as_str(), chains);
        assert_eq!(s.ess_bulk, ess_bulk(chains));
        assert_eq!(s.ess_tail, ess_tail(chains));
        assert_eq!(s.rhat, rhat(chains));
        assert_eq!(s.mcse_mean, mcse_mean(chains));
        assert!(s.q05 <= s.q50 && s.q50 <= s.q95);
    }
}
