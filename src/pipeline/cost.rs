//! What a run cost, counted whole: every speed figure per second (or evaluation) of the
//! sampling phase alone and per second (or evaluation) of everything before the draws too — the
//! MAP, the initial points, the warm-up. The report of `bench` and `sweep`.

use serde::{Deserialize, Serialize};

use super::RunOutput;
use crate::density::SolveCount;
use crate::sampler::clock::Elapsed;

/// The cost of one run and min bulk-ESS per unit of it. Seconds are wall time or CPU time of
/// the threads that did the work; the chains' phases are summed over chains.
///
/// Written flat (`wall_s`, `map_wall_s`, `map_cpu_s`, …, `min_ess_per_s`): bench.json and
/// sweep.json are read by scripts and by later runs, so they go through a flat mirror,
/// `CostRecord`, that keeps their keys.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(from = "CostRecord", into = "CostRecord")]
pub struct RunCost {
    /// Wall time of the whole run a user waits for: MAP, initial points, warm-up, sampling.
    pub wall_s: f64,
    /// The MAP search and the initial points.
    pub map: Elapsed,
    pub warmup: Elapsed,
    pub sampling: Elapsed,
    /// The three phases' CPU seconds together.
    pub total_cpu_s: f64,
    /// `gradient` for gradient samplers, `density` for the random walks.
    pub eval_kind: String,
    /// Evaluations of `eval_kind` in the sampling phase.
    pub evaluations: u64,
    /// Every evaluation: the MAP's (densities too for the random walks), the initial points',
    /// the warm-up's and the sampling's, with each Fisher or observed-information metric
    /// (the MAP's Hessian, Fisher-MALA's one per proposal) counted as one gradient: each
    /// needs the same sensitivities.
    pub all_evaluations: u64,
    /// min bulk-ESS per CPU second of the sampling phase.
    pub min_ess_per_s: f64,
    /// min bulk-ESS per CPU second of the whole cost (`total_cpu_s`).
    pub min_ess_per_total_s: f64,
    /// min bulk-ESS per second of the whole run's wall time (`wall_s`).
    pub min_ess_per_wall_s: f64,
    /// min bulk-ESS per evaluation of the sampling phase, and per one of all of them.
    pub min_ess_per_eval: f64,
    pub min_ess_per_all_evals: f64,
    /// Every ODE solve of the run (MAP, initial points, warm-up, sampling): plain f64 solves,
    /// dual-number solves and the derivative directions those carried.
    pub solves: SolveCount,
    /// min bulk-ESS per solve-equivalent of the whole cost ([`SolveCount::equivalents`]).
    pub min_ess_per_solve: f64,
}

impl RunCost {
    pub fn of(run: &RunOutput, uses_gradient: bool) -> Self {
        let (map, warmup, sampling) = (&run.map, &run.warmup, &run.sampling);
        let metrics =
            map.metric_evaluations + warmup.metric_evaluations + sampling.metric_evaluations;
        let (evaluations, all_evaluations, eval_kind) = if uses_gradient {
            (
                sampling.gradient_evaluations,
                map.gradient_evaluations
                    + warmup.gradient_evaluations
                    + sampling.gradient_evaluations
                    + metrics,
                "gradient",
            )
        } else {
            (
                sampling.density_evaluations,
                map.density_evaluations
                    + map.gradient_evaluations
                    + warmup.density_evaluations
                    + sampling.density_evaluations
                    + metrics,
                "density",
            )
        };
        let total_cpu_s = map.cpu_seconds + warmup.cpu_seconds + sampling.cpu_seconds;
        let ess = run.min_ess_bulk;
        let solves = map.solves + warmup.solves + sampling.solves;
        Self {
            wall_s: run.wall_seconds,
            map: map.time(),
            warmup: warmup.time(),
            sampling: sampling.time(),
            total_cpu_s,
            eval_kind: eval_kind.into(),
            evaluations,
            all_evaluations,
            min_ess_per_s: ess / sampling.cpu_seconds,
            min_ess_per_total_s: ess / total_cpu_s,
            min_ess_per_wall_s: ess / run.wall_seconds,
            min_ess_per_eval: ess / evaluations.max(1) as f64,
            min_ess_per_all_evals: ess / all_evaluations.max(1) as f64,
            solves,
            min_ess_per_solve: ess / solves.equivalents().max(1) as f64,
        }
    }
}

/// [`RunCost`] as the files hold it: one key per phase and clock (`*_wall_s`, `*_cpu_s`), in
/// the order they have always been written. Reading older files, `map_s` is `map_wall_s` and
/// `warmup_s` is `warmup_wall_s` (then the maximum over chains, not yet the sum); keys a file
/// lacks read as zero.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(default)]
struct CostRecord {
    wall_s: f64,
    #[serde(alias = "map_s")]
    map_wall_s: f64,
    map_cpu_s: f64,
    #[serde(alias = "warmup_s")]
    warmup_wall_s: f64,
    warmup_cpu_s: f64,
    sampling_wall_s: f64,
    sampling_cpu_s: f64,
    total_cpu_s: f64,
    eval_kind: String,
    evaluations: u64,
    all_evaluations: u64,
    min_ess_per_s: f64,
    min_ess_per_total_s: f64,
    min_ess_per_wall_s: f64,
    min_ess_per_eval: f64,
    min_ess_per_all_evals: f64,
    plain_solves: u64,
    dual_solves: u64,
    solve_directions: u64,
    solve_equivalents: u64,
    min_ess_per_solve: f64,
}

impl From<RunCost> for CostRecord {
    fn from(c: RunCost) -> Self {
        Self {
            wall_s: c.wall_s,
            map_wall_s: c.map.wall_seconds,
            map_cpu_s: c.map.cpu_seconds,
            warmup_wall_s: c.warmup.wall_seconds,
            warmup_cpu_s: c.warmup.cpu_seconds,
            sampling_wall_s: c.sampling.wall_seconds,
            sampling_cpu_s: c.sampling.cpu_seconds,
            total_cpu_s: c.total_cpu_s,
            eval_kind: c.eval_kind,
            evaluations: c.evaluations,
            all_evaluations: c.all_evaluations,
            min_ess_per_s: c.min_ess_per_s,
            min_ess_per_total_s: c.min_ess_per_total_s,
            min_ess_per_wall_s: c.min_ess_per_wall_s,
            min_ess_per_eval: c.min_ess_per_eval,
            min_ess_per_all_evals: c.min_ess_per_all_evals,
            plain_solves: c.solves.plain,
            dual_solves: c.solves.dual,
            solve_directions: c.solves.directions,
            solve_equivalents: c.solves.equivalents(),
            min_ess_per_solve: c.min_ess_per_solve,
        }
    }
}

impl From<CostRecord> for RunCost {
    fn from(r: CostRecord) -> Self {
        let phase = |wall_seconds, cpu_seconds| Elapsed {
            wall_seconds,
            cpu_seconds,
        };
        Self {
            wall_s: r.wall_s,
            map: phase(r.map_wall_s, r.map_cpu_s),
            warmup: phase(r.warmup_wall_s, r.warmup_cpu_s),
            sampling: phase(r.sampling_wall_s, r.sampling_cpu_s),
            total_cpu_s: r.total_cpu_s,
            eval_kind: r.eval_kind,
            evaluations: r.evaluations,
            all_evaluations: r.all_evaluations,
            min_ess_per_s: r.min_ess_per_s,
            min_ess_per_total_s: r.min_ess_per_total_s,
            min_ess_per_wall_s: r.min_ess_per_wall_s,
            min_ess_per_eval: r.min_ess_per_eval,
            min_ess_per_all_evals: r.min_ess_per_all_evals,
            solves: SolveCount {
                plain: r.plain_solves,
                dual: r.dual_solves,
                directions: r.solve_directions,
                ..SolveCount::default()
            },
            min_ess_per_solve: r.min_ess_per_solve,
        }
    }
}

/// A ratio to two significant figures ("28×", "0.54×", "7100×"): reruns move speed ratios by
/// ~20%, so a third figure would be noise.
pub fn ratio_2sf(x: f64) -> String {
    if !x.is_finite() || x <= 0.0 {
        return format!("{x}");
    }
    let digits = 1 - x.log10().floor() as i32;
    let rounded = {
        let scale = 10f64.powi(digits);
        (x * scale).round() / scale
    };
    // Rounding can carry into a new leading digit (9.96 → 10): then one decimal fewer.
    let digits = 1 - rounded.log10().floor() as i32;
    format!("{rounded:.*}", digits.max(0) as usize)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::sampler::PhaseCost;

    /// Four chains: MAP 0.5 s CPU (60 gradients, 10 metrics, 40 densities); each chain
    /// 0.25 s of warm-up (700 gradients, 300 metrics) and 2 s of sampling (2000 gradients,
    /// 1000 metrics), summed over chains.
    pub(crate) fn run(min_ess: f64) -> RunOutput {
        RunOutput {
            sampler: "x".into(),
            chains: Vec::new(),
            summaries: Vec::new(),
            max_rhat: 1.0,
            min_ess_bulk: min_ess,
            wall_seconds: 6.0,
            map: PhaseCost {
                wall_seconds: 0.6,
                cpu_seconds: 0.5,
                density_evaluations: 40,
                gradient_evaluations: 60,
                metric_evaluations: 10,
                ..PhaseCost::default()
            },
            warmup: PhaseCost {
                wall_seconds: 1.2,
                cpu_seconds: 1.0,
                density_evaluations: 4 * 500,
                gradient_evaluations: 4 * 700,
                metric_evaluations: 4 * 300,
                ..PhaseCost::default()
            },
            sampling: PhaseCost {
                wall_seconds: 9.0,
                cpu_seconds: 8.0,
                density_evaluations: 4 * 3000,
                gradient_evaluations: 4 * 2000,
                metric_evaluations: 4 * 1000,
                ..PhaseCost::default()
            },
            divergences: 0,
            map_log_density: 0.0,
            log_evidence_laplace: 0.0,
            khat: None,
            fell_back: false,
            fallback_stopped: false,
        }
    }

    #[test]
    fn speed_is_counted_over_the_sampling_phase_and_over_the_whole_cost() {
        let cost = RunCost::of(&run(850.0), true);
        assert_eq!(cost.total_cpu_s, 0.5 + 1.0 + 8.0);
        assert_eq!(cost.min_ess_per_s, 850.0 / 8.0);
        assert_eq!(cost.min_ess_per_total_s, 850.0 / 9.5);
        assert_eq!(cost.min_ess_per_wall_s, 850.0 / 6.0);
        assert_eq!(cost.eval_kind, "gradient");
        assert_eq!(cost.evaluations, 8000);
        assert_eq!(cost.min_ess_per_eval, 850.0 / 8000.0);
        // Fisher metrics of every phase count as gradients: 60 + 2800 + 8000 + (10 + 1200 + 4000).
        assert_eq!(cost.all_evaluations, 16070);
        assert_eq!(cost.min_ess_per_all_evals, 850.0 / 16070.0);
        assert_eq!(cost.warmup.wall_seconds, 1.2);
        assert_eq!(cost.sampling.wall_seconds, 9.0);
    }

    #[test]
    fn random_walks_count_densities_and_the_maps_gradients_and_metrics() {
        let cost = RunCost::of(&run(850.0), false);
        assert_eq!(cost.eval_kind, "density");
        assert_eq!(cost.evaluations, 12000);
        assert_eq!(
            cost.all_evaluations,
            40 + 60 + 2000 + 12000 + (10 + 1200 + 4000)
        );
    }

    #[test]
    fn solves_are_counted_over_the_whole_cost_a_dual_solve_with_its_directions() {
        let mut r = run(600.0);
        r.map.solves = SolveCount {
            plain: 10,
            dual: 20,
            directions: 20,
            ..SolveCount::default()
        };
        r.sampling.solves = SolveCount {
            plain: 500,
            dual: 0,
            directions: 0,
            ..SolveCount::default()
        };
        let cost = RunCost::of(&r, false);
        assert_eq!(cost.solves.equivalents(), 10 + 20 * 2 + 500);
        assert_eq!(cost.min_ess_per_solve, 600.0 / 550.0);
    }

    #[test]
    fn the_cost_is_written_flat_with_the_keys_it_always_had() {
        let cost = RunCost::of(&run(850.0), true);
        let text = serde_json::to_string(&cost).unwrap();
        let keys: Vec<&str> = text
            .trim_matches(['{', '}'])
            .split(',')
            .map(|pair| pair.split(':').next().unwrap().trim_matches('"'))
            .collect();
        assert_eq!(
            keys,
            [
                "wall_s",
                "map_wall_s",
                "map_cpu_s",
                "warmup_wall_s",
                "warmup_cpu_s",
                "sampling_wall_s",
                "sampling_cpu_s",
                "total_cpu_s",
                "eval_kind",
                "evaluations",
                "all_evaluations",
                "min_ess_per_s",
                "min_ess_per_total_s",
                "min_ess_per_wall_s",
                "min_ess_per_eval",
                "min_ess_per_all_evals",
                // Added with the solve count; older files read them as zero.
                "plain_solves",
                "dual_solves",
                "solve_directions",
                "solve_equivalents",
                "min_ess_per_solve",
            ]
        );
        assert!(text.contains(r#""map_cpu_s":0.5,"#), "{text}");
        let back: RunCost = serde_json::from_str(&text).unwrap();
        assert_eq!(back, cost);
    }

    #[test]
    fn older_files_read_with_their_field_names() {
        let cost: RunCost =
            serde_json::from_str(r#"{"wall_s": 3.0, "map_s": 0.25, "warmup_s": 1.5}"#).unwrap();
        assert_eq!(
            (cost.wall_s, cost.map.wall_seconds, cost.warmup.wall_seconds),
            (3.0, 0.25, 1.5)
        );
        assert_eq!(cost.total_cpu_s, 0.0);
    }

    #[test]
    fn ratios_keep_two_significant_figures() {
        assert_eq!(ratio_2sf(28.46), "28");
        assert_eq!(ratio_2sf(7125.8), "7100");
        assert_eq!(ratio_2sf(3.249), "3.2");
        assert_eq!(ratio_2sf(0.5432), "0.54");
        assert_eq!(ratio_2sf(9.96), "10");
        assert_eq!(ratio_2sf(99.7), "100");
        assert_eq!(ratio_2sf(20.0), "20");
    }
}
