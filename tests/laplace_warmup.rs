//! HMC and NUTS on the Laplace metric (the default): warm-up tunes the step size and nothing
//! else, the draws do not depend on the thread count, and the short default warm-up keeps
//! R-hat and ESS on BM2 where Stan's windows needed 1000 iterations.

use motorcal::bayes::ModelSettings;
use motorcal::pipeline::{
    MetricAdaptation, RunSettings, SamplerKind, default_warmup, map_estimate, run_sampler,
};
use motorcal::sampler::ChainSettings;
use motorcal::sampler::adapt::AdaptationState;
use motorcal::sampler::metric::{Metric, MetricKind};
use motorcal::study::Problem;

fn settings(sampler: SamplerKind, warmup: usize, draws: usize) -> RunSettings {
    RunSettings {
        sampler,
        chains: 4,
        chain: ChainSettings {
            warmup,
            draws,
            keep: None,
        },
        quiet: true,
        ..RunSettings::default()
    }
}

fn motorcal(args: &[&str]) -> std::process::Output {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_motorcal"))
        .args(args)
        .output()
        .expect("the binary runs");
    assert!(
        o.status.success(),
        "motorcal {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// What a user gets without `--warmup`: the command line takes `default_warmup` for the sampler
/// and the metric adaptation (the Laplace metric unless told otherwise), which is short on the
/// Laplace metric and Stan's 1000 in the windows; the fit records the warm-up it ran and, on the
/// Laplace metric, ends with the metric it started from.
#[test]
fn a_fit_without_warmup_runs_the_short_default_and_keeps_the_laplace_metric() {
    assert_eq!(
        RunSettings::default().metric_adaptation,
        MetricAdaptation::Laplace
    );
    let short = default_warmup(SamplerKind::NutsDense, MetricAdaptation::Laplace);
    let stan = default_warmup(SamplerKind::NutsDense, MetricAdaptation::Windows);
    assert!(short < stan, "Laplace warm-up {short}, windows {stan}");
    assert_eq!(stan, 1000);
    // Samplers without the Laplace metric's step-size-only warm-up keep Stan's length.
    assert_eq!(
        default_warmup(SamplerKind::Mala, MetricAdaptation::Laplace),
        stan
    );

    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("motorcal-default-warmup-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let path = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    motorcal(&[
        "simulate",
        "--out",
        &path(""),
        "--seed",
        "3",
        "--input",
        "reversal",
    ]);
    for (adaptation, expected) in [
        (MetricAdaptation::Laplace, short),
        (MetricAdaptation::Windows, stan),
    ] {
        let name = adaptation.name();
        let out = path(name);
        let saved = path(&format!("{name}.toml"));
        motorcal(&[
            "fit",
            "--data",
            &path("recording.csv"),
            "--model",
            &path("motor.toml"),
            "--bm",
            "1",
            "--sampler",
            "nuts-dense",
            "--metric-adaptation",
            name,
            "--chains",
            "1",
            "--draws",
            "20",
            "--save-adaptation",
            &saved,
            "--quiet",
            "--out",
            &out,
        ]);
        let report: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join(name).join("fit.json")).unwrap())
                .unwrap();
        let warmup = &report["run_settings"]["chain"]["warmup"];
        assert_eq!(warmup.as_u64(), Some(expected as u64), "{name}: {warmup}");

        // The metric the warm-up ended with against the Laplace metric at the fit's MAP.
        let problem =
            Problem::from_files(&[dir.join("recording.csv")], &dir.join("motor.toml")).unwrap();
        let mut posterior = problem
            .posterior(&problem.model_settings(Some(1), None))
            .unwrap();
        let laplace = Metric::from_precision(
            &map_estimate(&mut posterior).unwrap().hessian,
            MetricKind::Dense,
        )
        .unwrap();
        let tuned = AdaptationState::from_toml(&std::fs::read_to_string(&saved).unwrap()).unwrap();
        match adaptation {
            MetricAdaptation::Laplace => assert!(tuned.metric == laplace, "the metric moved"),
            MetricAdaptation::Windows => assert!(tuned.metric != laplace, "the windows kept it"),
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn warmup_on_the_laplace_metric_tunes_the_step_size_alone() {
    let problem = Problem::paper(motorcal::synthetic::DEFAULT_SEED).unwrap();
    let mut posterior = problem.posterior(&ModelSettings::bm2(3)).unwrap();
    let laplace = Metric::from_precision(
        &map_estimate(&mut posterior.clone()).unwrap().hessian,
        MetricKind::Dense,
    )
    .unwrap();
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("motorcal-laplace-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for metric_adaptation in [MetricAdaptation::Laplace, MetricAdaptation::Windows] {
        let saved = dir.join(format!("{}.toml", metric_adaptation.name()));
        let run_settings = RunSettings {
            metric_adaptation,
            save_adaptation: Some(saved.clone()),
            threads: Some(1),
            ..settings(SamplerKind::HmcDense, 200, 50)
        };
        run_sampler(&mut posterior, &run_settings, "laplace").unwrap();
        let tuned = AdaptationState::from_toml(&std::fs::read_to_string(&saved).unwrap()).unwrap();
        let kept = tuned.metric == laplace;
        match metric_adaptation {
            MetricAdaptation::Laplace => assert!(kept, "the Laplace metric was changed"),
            // The control: the same check sees Stan's windows move the metric.
            MetricAdaptation::Windows => assert!(!kept, "the windows left the metric alone"),
        }
        assert!(
            tuned.step_size > 0.05 && tuned.step_size < 5.0,
            "{}",
            tuned.step_size
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn laplace_metric_draws_do_not_depend_on_the_thread_count() {
    let problem = Problem::paper(motorcal::synthetic::DEFAULT_SEED).unwrap();
    let posterior = problem.posterior(&ModelSettings::bm2(3)).unwrap();
    let draws = |threads| {
        let run_settings = RunSettings {
            threads: Some(threads),
            ..settings(SamplerKind::NutsDense, 50, 50)
        };
        let run = run_sampler(&mut posterior.clone(), &run_settings, "threads").unwrap();
        run.chains.into_iter().map(|c| c.draws).collect::<Vec<_>>()
    };
    let one = draws(1);
    assert!(one == draws(2), "draws depend on the thread count");
    assert!(one[0] != one[1], "chains share a random stream");
}

/// The claim behind the default: at `default_warmup` on the Laplace metric every K keeps R-hat ≤ 1.01 and bulk ESS
/// ≥ 400 (4 chains × 1000 draws). In CI at the paper's K = 9 and the largest K = 20; the whole
/// K = 0…20 with `--ignored`.
fn converges_at_the_default_warmup(ks: &[usize], sampler: SamplerKind) {
    let problem = Problem::paper(motorcal::synthetic::DEFAULT_SEED).unwrap();
    for &k in ks {
        let mut posterior = problem.posterior(&ModelSettings::bm2(k)).unwrap();
        let warmup = default_warmup(sampler, MetricAdaptation::Laplace);
        let run = run_sampler(&mut posterior, &settings(sampler, warmup, 1000), "warmup").unwrap();
        eprintln!(
            "{} K = {k}: R-hat {:.4}, bulk ESS {:.0}",
            sampler.name(),
            run.max_rhat,
            run.min_ess_bulk
        );
        assert!(run.max_rhat <= 1.01, "K = {k}: R-hat {}", run.max_rhat);
        assert!(
            run.min_ess_bulk >= 400.0,
            "K = {k}: ESS {}",
            run.min_ess_bulk
        );
    }
}

#[test]
fn nuts_and_hmc_converge_at_the_default_warmup_at_k9_and_k20() {
    converges_at_the_default_warmup(&[9, 20], SamplerKind::NutsDense);
    converges_at_the_default_warmup(&[9, 20], SamplerKind::HmcDense);
}

#[test]
#[ignore = "every K = 0..20 for NUTS and HMC, about a minute; run before changing the default"]
fn nuts_and_hmc_converge_at_the_default_warmup_at_every_k() {
    let ks: Vec<usize> = (0..=20).collect();
    converges_at_the_default_warmup(&ks, SamplerKind::NutsDense);
    converges_at_the_default_warmup(&ks, SamplerKind::HmcDense);
}
