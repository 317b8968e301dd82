//! The false-alarm study of the plausibility check (papers/plausibility/README.md): fresh
//! concealed cases from seeds no test and no tuning used, made by `simulate --effect …
//! --conceal`'s generator (one-effect: each library term on alternating inputs; null; two-effect
//! on the reversal input), each checked as `fit`, `diagnose` and `predict` check a recording
//! before any physics. A finding on any of them is a false alarm. Writes `false_alarms.csv` and
//! prints one line per set.
//!
//! cargo run --release --example plausibility_study -- [--per-effect 5] [--null 40] [--two 20]
//!     [--seed-base 940000] [--out papers/plausibility]

use std::path::PathBuf;

use rayon::prelude::*;

use motorcal::motor::Term;
use motorcal::study::cases::{CaseOptions, make_case};
use motorcal::study::plausibility::check;
use motorcal::study::{InputProfile, Problem};

fn arg<T: std::str::FromStr>(args: &[String], name: &str, default: T) -> T {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

struct Row {
    set: &'static str,
    effects: String,
    seed: u64,
    input: String,
    findings: Vec<String>,
    check_s: f64,
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let per_effect: u64 = arg(&args, "--per-effect", 5);
    let n_null: u64 = arg(&args, "--null", 40);
    let n_two: u64 = arg(&args, "--two", 20);
    let seed_base: u64 = arg(&args, "--seed-base", 940_000);
    let out = PathBuf::from(arg(&args, "--out", "papers/plausibility".to_string()));

    let inputs = [InputProfile::Constant, InputProfile::Reversal];
    let names = Term::NAMES;
    let mut specs: Vec<(&'static str, Vec<String>, u64, InputProfile)> = Vec::new();
    let mut seed = seed_base;
    for round in 0..per_effect {
        for name in names {
            let input = inputs[round as usize % 2];
            specs.push(("one", vec![name.to_string()], seed, input));
            seed += 1;
        }
    }
    for i in 0..n_null {
        specs.push(("null", vec!["none".into()], seed, inputs[i as usize % 2]));
        seed += 1;
    }
    for _ in 0..n_two {
        // Two distinct terms drawn from the seed.
        let a = (seed.wrapping_mul(2654435761) >> 7) as usize % names.len();
        let mut b = (seed.wrapping_mul(40503) >> 3) as usize % names.len();
        if a == b {
            b = (b + 1) % names.len();
        }
        let effects = vec![names[a].to_string(), names[b].to_string()];
        specs.push(("two", effects, seed, InputProfile::Reversal));
        seed += 1;
    }

    let rows: Vec<Row> = specs
        .par_iter()
        .filter_map(|(set, effects, seed, input)| {
            let case = match make_case(&CaseOptions {
                effects: effects.clone(),
                magnitude: None,
                input: *input,
                seed: *seed,
                conceal: true,
                tied: false,
            }) {
                Ok(c) => c,
                Err(e) => {
                    eprintln!("{set} {effects:?} seed {seed}: not made: {e}");
                    return None;
                }
            };
            let problem = Problem {
                label: format!("{}-{seed}", effects.join("+")),
                recordings: vec![case.recording],
                model: case.nominal,
                reference: None,
            };
            let started = std::time::Instant::now();
            let found = check(&problem).expect("the check runs");
            let check_s = started.elapsed().as_secs_f64();
            for f in &found {
                eprintln!("{set} {effects:?} seed {seed}: FALSE ALARM {f}");
            }
            Some(Row {
                set,
                effects: effects.join("+"),
                seed: *seed,
                input: format!("{:?}", case.answer.input).to_lowercase(),
                findings: found.iter().map(|f| f.to_string()).collect(),
                check_s,
            })
        })
        .collect();

    std::fs::create_dir_all(&out).expect("the output folder");
    let path = out.join("false_alarms.csv");
    let mut w = csv::Writer::from_path(&path).expect("false_alarms.csv");
    w.write_record(["set", "effects", "seed", "input", "findings", "check_s"])
        .unwrap();
    for r in &rows {
        w.write_record([
            r.set.to_string(),
            r.effects.clone(),
            r.seed.to_string(),
            r.input.clone(),
            r.findings.join(" | "),
            format!("{:.4}", r.check_s),
        ])
        .unwrap();
    }
    w.flush().unwrap();
    for set in ["one", "two", "null"] {
        let of: Vec<&Row> = rows.iter().filter(|r| r.set == set).collect();
        let alarms = of.iter().filter(|r| !r.findings.is_empty()).count();
        let slowest = of.iter().map(|r| r.check_s).fold(0.0, f64::max);
        println!(
            "{set}: {alarms} false alarms of {} cases (slowest check {slowest:.3} s)",
            of.len()
        );
    }
    println!("wrote {}", path.display());
}
