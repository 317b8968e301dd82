//! Instruction counts (under callgrind) of the criterion benches' measured operations, for A/B
//! between commits (`IMPORTS` is filled in by run.sh: the problem and MAP as each commit
//! exported them): `valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*measured*'`.
use std::hint::black_box;

use nalgebra::DMatrix;

use motorcal::bayes::{CalibrationPosterior, ModelSettings};
use motorcal::density::{FisherMetric, LogDensity};
use motorcal::sampler::driver::chain_rng;
use motorcal::sampler::metric::{Metric, MetricKind};
use motorcal::sampler::nuts::{Nuts, NutsSettings};
use motorcal::sampler::{ChainSettings, run_chain};
use motorcal::synthetic::DEFAULT_SEED;
IMPORTS

#[inline(never)]
fn measured_density(p: &mut CalibrationPosterior, points: &[Vec<f64>; 3], what: &str, n: usize) {
    let d = p.dim();
    let mut grad = vec![0.0; d];
    let mut metric = DMatrix::zeros(d, d);
    let forward = p.forward(0).clone();
    let mut out = vec![0.0; forward.n_outputs()];
    for i in 0..n {
        let x = &points[i % 3];
        match what {
            "f64_solve" => {
                black_box(forward.simulate(black_box(&x[..1]), &mut out).unwrap());
            }
            "log_density" => {
                black_box(p.log_density(black_box(x)).unwrap());
            }
            "log_density_gradient" => {
                black_box(p.log_density_and_gradient(black_box(x), &mut grad).unwrap());
            }
            "fisher_metric" => {
                p.fisher_metric(black_box(x), &mut metric).unwrap();
                black_box(&metric);
            }
            _ => panic!("{what}"),
        }
    }
}

#[inline(never)]
fn measured_nuts(p: &CalibrationPosterior, x: &[f64], hessian: &DMatrix<f64>) -> f64 {
    let metric = Metric::from_precision(hessian, MetricKind::Dense).unwrap();
    let kernel = Nuts::new(metric, NutsSettings::default()).unwrap();
    let adaptation = motorcal::sampler::adapt::WindowedAdaptation::default();
    let settings = ChainSettings { warmup: 200, draws: 100, keep: None };
    let mut rng = chain_rng(DEFAULT_SEED, 0);
    let (out, _) = run_chain(p.clone(), kernel, adaptation, x, &settings, &mut rng, 0, None).unwrap();
    out.unconstrained.iter().map(|v| v[0]).sum()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let k: usize = args[1].parse().unwrap();
    let what = args[2].as_str();
    let n: usize = args.get(3).map(|s| s.parse().unwrap()).unwrap_or(30);
    let problem = Problem::paper(DEFAULT_SEED).unwrap();
    let mut posterior = problem.posterior(&ModelSettings::bm2(k)).unwrap();
    let map = map_estimate(&mut posterior).unwrap();
    if what == "nuts" {
        println!("{}", measured_nuts(&posterior, &map.x, &map.hessian));
        return;
    }
    let x = map.x.clone();
    let mut up = x.clone();
    up[0] *= 1.0 + 1e-3;
    let mut down = x.clone();
    down[0] *= 1.0 - 1e-3;
    measured_density(&mut posterior, &[x, up, down], what, n);
}
