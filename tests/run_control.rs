//! What a caller controls of a run beside its settings (`RunControl`, which the Python bindings
//! use): the stop flag ends the chains with `STOPPED`, a work budget ends a chain that
//! spent it with `BUDGET_SPENT`, and keeping the warm-up's draws changes no draw.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use motorcal::density::DensityError;
use motorcal::sampler::adapt::{DualAveragingSettings, StepSizeAdaptation};
use motorcal::sampler::metric::{Metric, MetricKind};
use motorcal::sampler::nuts::{Nuts, NutsSettings};
use motorcal::sampler::targets::Gaussian;
use motorcal::sampler::{
    BUDGET_SPENT, ChainOutput, ChainSettings, RunControl, STOPPED, run_chains_until,
};

const WARMUP: usize = 40;

fn nuts(control: RunControl<'_>) -> Result<Vec<ChainOutput>, DensityError> {
    let target = Gaussian::correlated(4, 0.5, 10.0);
    let settings = ChainSettings {
        warmup: WARMUP,
        draws: 60,
        keep: None,
    };
    let inits = vec![vec![0.5; 4], vec![-0.5; 4]];
    let runs = run_chains_until(
        &inits,
        &settings,
        7,
        |_| {
            let kernel = Nuts::new(
                Metric::identity(4, MetricKind::Diagonal),
                NutsSettings::default(),
            )
            .map_err(DensityError::fatal)?;
            let adaptation = StepSizeAdaptation::new(DualAveragingSettings::default())
                .map_err(DensityError::fatal)?;
            Ok((target.clone(), kernel, adaptation))
        },
        None,
        control,
    )?;
    Ok(runs.into_iter().map(|(o, _)| o).collect())
}

#[test]
fn a_set_stop_flag_ends_the_run() {
    let stop = AtomicBool::new(true);
    let err = nuts(RunControl {
        stop: Some(&stop),
        ..RunControl::default()
    })
    .unwrap_err();
    assert_eq!(err.message, STOPPED);
    assert!(!err.recoverable);
}

#[test]
fn keeping_the_warmup_changes_no_draw() {
    let unset = AtomicBool::new(false);
    let plain = nuts(RunControl::default()).unwrap();
    let transitions = AtomicUsize::new(0);
    let kept = nuts(RunControl {
        stop: Some(&unset),
        save_warmup: true,
        transitions: Some(&transitions),
        work_budget: None,
    })
    .unwrap();
    // Every chain's every transition counted, for a caller's progress display.
    assert_eq!(
        transitions.load(Ordering::Relaxed),
        kept.len() * (WARMUP + kept[0].draws.len())
    );
    for (a, b) in plain.iter().zip(&kept) {
        assert_eq!(a.draws, b.draws);
        assert_eq!(a.records, b.records);
        assert!(a.warmup_draws.is_empty());
        assert_eq!(b.warmup_draws.len(), WARMUP);
        assert_eq!(b.warmup_records.len(), WARMUP);
        // Dual averaging moves the step size during warm-up.
        let first = b.warmup_records[0].step_size;
        assert!(b.warmup_records.iter().any(|r| r.step_size != first));
    }
}

#[test]
fn a_chain_past_its_work_budget_ends_the_run_and_one_within_it_draws_as_without() {
    let plain = nuts(RunControl::default()).unwrap();
    // On a closed-form target a chain's work is its gradients.
    let spent = |o: &ChainOutput| o.warmup.gradient_evaluations + o.sampling.gradient_evaluations;
    let most = plain.iter().map(spent).max().unwrap();
    let least = plain.iter().map(spent).min().unwrap();
    // A budget every chain stays within moves no draw.
    let within = nuts(RunControl {
        work_budget: Some(most + 1),
        ..RunControl::default()
    })
    .unwrap();
    for (a, b) in plain.iter().zip(&within) {
        assert_eq!(a.draws, b.draws);
    }
    // Half of what the thriftiest chain spent ends the run, as a fatal error.
    let err = nuts(RunControl {
        work_budget: Some(least / 2),
        ..RunControl::default()
    })
    .unwrap_err();
    assert_eq!(err.message, BUDGET_SPENT);
    assert!(!err.recoverable);
}
