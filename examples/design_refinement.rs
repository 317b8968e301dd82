//! Whether a finer input beats `motorcal design`'s: the designed profile of a `design.json`
//! resampled on M equal segments, each level free, and climbed by finite-difference gradient
//! ascent (normalised steps, backtracking) on a soft minimum (temperature ½ nat) of the
//! truths' noise-free leads over viscous friction, quadratic drag and asymmetric friction at
//! the design's `candidates_at`; then the worst lead with the rivals' fits polished, and the
//! expected gaps over 20 noisy records as `design` reports them (papers/design.md, viscous
//! seed 1).
//!
//!     cargo run --release --example design_refinement -- CASE_DIR M ITERATIONS DESIGN_JSON
use motorcal::design::{self, Candidate, Evaluation, Experiment, Limits, Profile};
use rayon::prelude::*;
use std::collections::BTreeMap;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dir = &args[1];
    let m: usize = args[2].parse().unwrap();
    let iters: usize = args[3].parse().unwrap();
    let model =
        motorcal::io::read_model_file(std::path::Path::new(&format!("{dir}/motor.toml"))).unwrap();
    let times = design::design_times(0.5, 1000.0).unwrap();
    let base = design::design_problem(&model, &times, &"U=±24,I=±300,omega=±3000".parse().unwrap())
        .unwrap();
    let d: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&args[4]).unwrap()).unwrap();
    let vals = d["candidates_at"]["values"].as_object().unwrap();
    let mut cands = Vec::new();
    for name in ["viscous_friction", "quadratic_drag", "asymmetric_friction"] {
        let v: BTreeMap<String, f64> = vals[name]
            .as_object()
            .unwrap()
            .iter()
            .map(|(k, x)| (k.clone(), x.as_f64().unwrap()))
            .collect();
        cands.push(Candidate::new(&base, name, &v).unwrap());
    }
    let exp = Experiment {
        candidates: cands,
        times: times.clone(),
        noise_sd: vec![2.0, 10.0],
    };
    let limits: Limits = "U=±24,I=±300,omega=±3000".parse().unwrap();
    let tight = Limits {
        current: 300.0 * 0.98,
        speed: 3000.0 * 0.98,
        ..limits
    };
    let p = &d["profile"];
    let lev: Vec<f64> = p["levels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let sw: Vec<f64> = p["switches"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let start = Profile {
        levels: lev,
        switches: sw,
        duration: 0.5,
    };
    // fine grid: m equal segments, level = start's level at the segment's middle
    let fine_sw: Vec<f64> = (1..m).map(|j| 0.5 * j as f64 / m as f64).collect();
    let mut z: Vec<f64> = (0..m)
        .map(|j| {
            (start.level_at(0.5 * (j as f64 + 0.5) / m as f64) / 24.0)
                .clamp(-0.995, 0.995)
                .atanh()
        })
        .collect();
    let eval = |z: &[f64], polish: bool| -> f64 {
        let prof = Profile {
            levels: z.iter().map(|x| 24.0 * x.tanh()).collect(),
            switches: fine_sw.clone(),
            duration: 0.5,
        };
        match design::noise_free_leads(&exp, &prof.continuous(), &tight, polish) {
            Ok(Evaluation::Feasible { leads, .. }) => {
                // soft-min over the truths' leads (temperature 0.5 nat)
                let t = 0.5;
                let mn = leads.iter().map(|l| l.gap).fold(f64::INFINITY, f64::min);
                mn - t * leads
                    .iter()
                    .map(|l| (-(l.gap - mn) / t).exp())
                    .sum::<f64>()
                    .ln()
            }
            Ok(Evaluation::Infeasible { excess }) => -1e3 * (1.0 + excess),
            Err(_) => -1e9,
        }
    };
    let mut f = eval(&z, false);
    eprintln!("start: {f:.3} (polished {:.3})", eval(&z, true));
    let mut step = 0.3;
    let h = 1e-3;
    for it in 0..iters {
        let g: Vec<f64> = (0..m)
            .into_par_iter()
            .map(|i| {
                let mut zz = z.clone();
                zz[i] += h;
                (eval(&zz, false) - f) / h
            })
            .collect();
        let gn = g.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-12);
        // backtracking on a normalised step
        loop {
            let zz: Vec<f64> = z.iter().zip(&g).map(|(a, b)| a + step * b / gn).collect();
            let ff = eval(&zz, false);
            if ff > f {
                z = zz;
                f = ff;
                step *= 1.3;
                break;
            }
            step *= 0.5;
            if step < 1e-4 {
                break;
            }
        }
        if it % 5 == 0 {
            eprintln!("it {it}: {f:.3} step {step:.3e}");
        }
        if step < 1e-4 {
            break;
        }
    }
    let prof = Profile {
        levels: z.iter().map(|x| 24.0 * x.tanh()).collect(),
        switches: fine_sw.clone(),
        duration: 0.5,
    };
    eprintln!(
        "end: {f:.3}, polished worst {:.3}",
        design::noise_free_leads(&exp, &prof.continuous(), &tight, true)
            .unwrap()
            .worst()
    );
    println!("{}", serde_json::to_string(&prof.levels).unwrap());
    let input = design::held(&times, prof.sampled(&times));
    let gaps = design::expected_gaps(&exp, &input, &limits, 20, 2026).unwrap();
    for g in gaps {
        eprintln!(
            "{} over {}: nf {:.2} exp {:.2} ± {:.2}",
            g.truth, g.rival, g.noise_free_gap_nats, g.expected_gap_nats, g.sd_nats
        );
    }
}
