//! The K study on the paper's data: `sweep` writes one record per K with the paper's error
//! measures, and `select-k`'s σ rule sees that K = 0 has not stabilised (the discrepancy is
//! not yet captured, so the noise σ is overestimated, §4.2).

use motorcal::bayes::CoefficientPrior;
use motorcal::paper::sweep::select::{TOLERANCE, evidence, sigma_stabilisation, wasserstein_1};
use motorcal::paper::sweep::{SweepOptions, SweepRecord, merge, sweep};
use motorcal::pipeline::{RunSettings, SamplerKind};
use motorcal::sampler::ChainSettings;

fn options(ks: Vec<usize>, out: &str) -> SweepOptions {
    SweepOptions {
        ks,
        coefficient_prior: CoefficientPrior::default(),
        data_seeds: vec![motorcal::synthetic::DEFAULT_SEED],
        shard: None,
        run: RunSettings {
            sampler: SamplerKind::NutsDense,
            chains: 2,
            chain: ChainSettings {
                warmup: 300,
                draws: 300,
                keep: None,
            },
            quiet: true,
            ..RunSettings::default()
        },
        out: std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
            .join(format!("motorcal-sweep-{}-{out}", std::process::id())),
        json: None,
        figures_at: Vec::new(),
    }
}

#[test]
fn a_sweep_writes_the_papers_error_measures_and_k0_has_not_stabilised() {
    // The command as a user runs it (the records, their files and figures), with the
    // options' chains: `motorcal sweep` draws the figures and writes the files.
    let opts = options((0..=4).collect(), "small");
    let json = opts.out.join("sweep.json");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_motorcal"))
        .args(["sweep", "--k", "0..=4", "--figures-at", "4", "--quiet"])
        .args(["--data-seed", &opts.data_seeds[0].to_string()])
        .args(["--sampler", opts.run.sampler.name()])
        .args(["--chains", &opts.run.chains.to_string()])
        .args(["--warmup", &opts.run.chain.warmup.to_string()])
        .args(["--draws", &opts.run.chain.draws.to_string()])
        .args(["--seed", &opts.run.seed.to_string()])
        .arg("--out")
        .arg(&opts.out)
        .arg("--json")
        .arg(&json)
        .output()
        .expect("the binary runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let from_json: Vec<SweepRecord> =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    // The selection rules need the σ draws, which the files do not carry: the library's sweep
    // on the same options, which must be what the command wrote.
    let records = sweep(&opts).unwrap();
    assert_eq!(without_wall_times(&from_json), without_wall_times(&records));
    assert_eq!(
        records.iter().map(|r| r.k).collect::<Vec<_>>(),
        vec![0, 1, 2, 3, 4]
    );
    for r in &records {
        assert!((r.r.mse - (r.r.bias.powi(2) + r.r.variance)).abs() < 1e-18);
        assert!(r.delta_i.n_mse <= r.delta_i.n_mse_bound * (1.0 + 1e-12));
        assert!(r.delta_omega.n_mse <= r.delta_omega.n_mse_bound * (1.0 + 1e-12));
        assert!(r.max_rhat.is_finite() && r.min_ess_tail > 0.0);
    }
    let stdout = String::from_utf8_lossy(&o.stdout);
    let written: Vec<&str> = stdout
        .lines()
        .filter_map(|l| l.strip_prefix("wrote "))
        .collect();
    assert!(written.len() >= 2, "{stdout}");
    assert!(
        written.iter().all(|p| std::path::Path::new(p).exists()),
        "{written:?}"
    );
    for figure in ["fig13-delta-k4.png", "fig14-coefficients-k4.png"] {
        assert!(opts.out.join(figure).exists(), "{figure}");
    }
    let choice = sigma_stabilisation(&records);
    let d0 = choice.distances.iter().find(|d| d.k == 0).unwrap().distance;
    eprintln!("distances {:?}", choice.distances);
    assert!(d0 > TOLERANCE, "K = 0 looks stable: {d0}");
    // The data carry a discrepancy: a δ of degree 4 is far more probable than a constant one,
    // and at these small K the importance-sampling evidence stays near the Laplace value.
    let ev = evidence(&records);
    eprintln!("evidences {:?}", ev.evidences);
    let at = |k: usize| ev.evidences.iter().find(|e| e.k == k).unwrap();
    assert!(at(4).log_evidence > at(0).log_evidence + 100.0);
    for e in &ev.evidences {
        assert!(e.trusted, "{e:?}");
        assert!(
            (e.log_evidence - e.log_evidence_laplace).abs() < 1.0,
            "{e:?}"
        );
    }
    let _ = std::fs::remove_dir_all(&opts.out);
}

#[test]
fn wasserstein_distance_is_symmetric_and_sees_a_spread() {
    let a: Vec<f64> = (0..1000).map(|i| i as f64 / 999.0).collect();
    let b: Vec<f64> = a.iter().map(|x| 2.0 * x - 0.5).collect();
    let (ab, ba) = (wasserstein_1(&a, &b), wasserstein_1(&b, &a));
    assert!((ab - ba).abs() < 1e-12);
    // |2u − 0.5 − u| integrated over [0, 1] = ∫|u − 0.5| = 0.25
    assert!((ab - 0.25).abs() < 1e-3, "{ab}");
}

/// The JSON a run writes, with the times and the speeds per second (the fields a rerun cannot
/// repeat) zeroed.
fn without_wall_times(records: &[SweepRecord]) -> String {
    fn zero_times(v: &mut serde_json::Value) {
        if let Some(map) = v.as_object_mut() {
            for (key, value) in map.iter_mut() {
                if key.ends_with("_s") {
                    *value = serde_json::json!(0.0);
                } else {
                    zero_times(value);
                }
            }
        }
    }
    let mut v = serde_json::to_value(records).unwrap();
    for r in v.as_array_mut().unwrap() {
        zero_times(r);
    }
    serde_json::to_string_pretty(&v).unwrap()
}

#[test]
fn three_shards_merged_are_the_unsharded_sweep() {
    let mut opts = options(vec![0, 1, 2], "shards");
    opts.data_seeds = vec![5, 6];
    let whole = sweep(&opts).unwrap();
    let mut parts = Vec::new();
    for i in 1..=3 {
        let mut o = opts.clone();
        o.shard = Some((i, 3));
        let part = sweep(&o).unwrap();
        assert_eq!(
            part.len(),
            2,
            "shard {i}/3 holds two of the six grid points"
        );
        // Through JSON, as the files travel between machines.
        let text = serde_json::to_string(&part).unwrap();
        parts.push(serde_json::from_str(&text).unwrap());
    }
    let merged = merge(parts).unwrap();
    assert_eq!(without_wall_times(&merged), without_wall_times(&whole));
}
