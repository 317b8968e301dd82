//! The K study over noise seeds (the paper ran one realisation): for each data seed, the K = 0..20
//! sweep, K chosen by both rules, the bias of R for BM1 and for BM2 at each chosen K, and
//! whether the 95% interval of R holds R₀ = 0.1.
//!
//! cargo run --release --example k_seeds -- [--seeds 20] [--first 1] [--warmup 500] [--draws 500]
//!     [--out papers/john2018/k-seeds] [--metric-adaptation laplace|windows]

use std::path::PathBuf;

use serde::Serialize;

use motorcal::bayes::{CoefficientPrior, ModelSettings};
use motorcal::paper::sweep::select::{evidence, sigma_stabilisation};
use motorcal::paper::sweep::{SweepOptions, SweepRecord, run_k};
use motorcal::pipeline::{MetricAdaptation, RunSettings, SamplerKind, run_sampler};
use motorcal::sampler::ChainSettings;
use motorcal::study::Problem;

#[derive(Serialize)]
struct SeedRow {
    data_seed: u64,
    k_sigma: Option<usize>,
    k_evidence: Option<usize>,
    bm1_r_mean: f64,
    bm1_r_q025: f64,
    bm1_r_q975: f64,
    bm2_sigma_r_mean: Option<f64>,
    bm2_sigma_covers: Option<bool>,
    bm2_evidence_r_mean: Option<f64>,
    bm2_evidence_covers: Option<bool>,
    max_rhat: f64,
    wall_s: f64,
}

fn arg<T: std::str::FromStr>(args: &[String], name: &str, default: T) -> T {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let seeds: u64 = arg(&args, "--seeds", 20);
    let first: u64 = arg(&args, "--first", 1);
    let warmup: usize = arg(&args, "--warmup", 500);
    let draws: usize = arg(&args, "--draws", 500);
    let out = PathBuf::from(arg(&args, "--out", "papers/john2018/k-seeds".to_string()));
    let metric_adaptation: MetricAdaptation =
        match arg(&args, "--metric-adaptation", "laplace".to_string()).parse() {
            Ok(m) => m,
            Err(e) => {
                eprintln!("--metric-adaptation: {e}");
                std::process::exit(2);
            }
        };
    let run = RunSettings {
        sampler: SamplerKind::NutsDense,
        chains: 4,
        chain: ChainSettings {
            warmup,
            draws,
            keep: None,
        },
        quiet: true,
        metric_adaptation,
        ..RunSettings::default()
    };
    let r0 = 0.1;
    let mut rows = Vec::new();
    for data_seed in first..first + seeds {
        let started = std::time::Instant::now();
        let options = SweepOptions {
            ks: (0..=20).collect(),
            coefficient_prior: CoefficientPrior::default(),
            data_seeds: vec![data_seed],
            shard: None,
            run: run.clone(),
            out: out.clone(),
            json: None,
            figures_at: Vec::new(),
        };
        let problem = Problem::paper(data_seed).expect("the paper's data");
        let records: Vec<SweepRecord> = options
            .ks
            .iter()
            .map(|&k| {
                run_k(&problem, data_seed, k, &options, &mut |_| {
                    Ok::<_, motorcal::error::Error>(())
                })
                .expect("a K runs")
            })
            .collect();
        let k_sigma = sigma_stabilisation(&records).k;
        let k_evidence = evidence(&records).k;
        let mut bm1 = problem.posterior(&ModelSettings::bm1()).unwrap();
        let bm1_run = run_sampler(&mut bm1, &run, "BM1").unwrap();
        let r1 = bm1_run.summary("R").unwrap().clone();
        let at = |k: Option<usize>| k.and_then(|k| records.iter().find(|r| r.k == k));
        let covers = |r: &SweepRecord| r.r.q025 <= r0 && r0 <= r.r.q975;
        let row = SeedRow {
            data_seed,
            k_sigma,
            k_evidence,
            bm1_r_mean: r1.mean,
            bm1_r_q025: r1.q025,
            bm1_r_q975: r1.q975,
            bm2_sigma_r_mean: at(k_sigma).map(|r| r.r.mean),
            bm2_sigma_covers: at(k_sigma).map(covers),
            bm2_evidence_r_mean: at(k_evidence).map(|r| r.r.mean),
            bm2_evidence_covers: at(k_evidence).map(covers),
            max_rhat: records
                .iter()
                .map(|r| r.max_rhat)
                .fold(bm1_run.max_rhat, f64::max),
            wall_s: started.elapsed().as_secs_f64(),
        };
        eprintln!(
            "seed {data_seed}: K σ-rule {:?}, evidence {:?}; R BM1 {:.5}, BM2(σ) {:?} covers {:?}; {:.0} s",
            row.k_sigma,
            row.k_evidence,
            row.bm1_r_mean,
            row.bm2_sigma_r_mean,
            row.bm2_sigma_covers,
            row.wall_s
        );
        rows.push(row);
    }
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(
        out.join("k-seeds.json"),
        serde_json::to_string_pretty(&rows).unwrap(),
    )
    .unwrap();
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        if v.is_empty() {
            f64::NAN
        } else {
            v[v.len() / 2]
        }
    };
    let ks = |f: &dyn Fn(&SeedRow) -> Option<usize>| {
        rows.iter()
            .map(|r| f(r).map_or("-".to_string(), |k| k.to_string()))
            .collect::<Vec<_>>()
            .join(" ")
    };
    println!("seeds {first}..{}", first + seeds - 1);
    println!("K by σ rule:    {}", ks(&|r| r.k_sigma));
    println!("K by evidence:  {}", ks(&|r| r.k_evidence));
    println!(
        "median K: σ rule {}, evidence {}",
        median(
            rows.iter()
                .filter_map(|r| r.k_sigma.map(|k| k as f64))
                .collect()
        ),
        median(
            rows.iter()
                .filter_map(|r| r.k_evidence.map(|k| k as f64))
                .collect()
        )
    );
    let mean = |v: Vec<f64>| v.iter().sum::<f64>() / v.len() as f64;
    println!(
        "bias of R (mean over seeds of posterior mean − 0.1): BM1 {:.2e}, BM2 at σ-rule K {:.2e}, at evidence K {:.2e}",
        mean(rows.iter().map(|r| r.bm1_r_mean - r0).collect()),
        mean(
            rows.iter()
                .filter_map(|r| r.bm2_sigma_r_mean.map(|m| m - r0))
                .collect()
        ),
        mean(
            rows.iter()
                .filter_map(|r| r.bm2_evidence_r_mean.map(|m| m - r0))
                .collect()
        )
    );
    let count = |f: &dyn Fn(&SeedRow) -> Option<bool>| {
        let v: Vec<bool> = rows.iter().filter_map(f).collect();
        format!("{}/{}", v.iter().filter(|b| **b).count(), v.len())
    };
    println!(
        "95% interval of R holds 0.1: BM1 {}, BM2 at σ-rule K {}, at evidence K {}",
        count(&|r| Some(r.bm1_r_q025 <= r0 && r0 <= r.bm1_r_q975)),
        count(&|r| r.bm2_sigma_covers),
        count(&|r| r.bm2_evidence_covers)
    );
    println!(
        "max R-hat over all runs {:.4}; wall time per seed median {:.0} s",
        rows.iter().map(|r| r.max_rhat).fold(0.0, f64::max),
        median(rows.iter().map(|r| r.wall_s).collect())
    );
}
