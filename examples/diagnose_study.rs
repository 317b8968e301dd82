//! The diagnose study of `papers/diagnose.md`: fresh concealed cases from seeds no test and no
//! tuning used (one-effect, null, two-effect), each made by `simulate --effect … --conceal`'s
//! generator and diagnosed (ranking and selection; `--full` adds the sampled fits), and the
//! development set with the full command. Writes `study.csv` and `study.json` and prints the
//! confusion tables.
//!
//! cargo run --release --example diagnose_study -- [--per-effect 5] [--null 20] [--two 20]
//!     [--seed-base 900000] [--out papers/diagnose] [--full] [--effects a,b] [--no-dev]
//!
//! `--effects` restricts the one-effect cases to the named terms (seeds are then given to those
//! only, in the library's order); `--no-dev` skips the development set.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use serde::Serialize;

use motorcal::discover::{DiscoverSettings, discover};
use motorcal::motor::Term;
use motorcal::pipeline::{RunSettings, SamplerKind};
use motorcal::sampler::ChainSettings;
use motorcal::study::cases::{Case, CaseOptions, make_case};
use motorcal::study::{InputProfile, Problem};

#[derive(Clone, Debug, Serialize)]
struct Row {
    set: String,
    case: String,
    truth: Vec<String>,
    seed: u64,
    input: String,
    input_fallback: bool,
    peak_over_sigma: f64,
    oracle_margin: Option<f64>,
    selected: String,
    selected_set: Vec<String>,
    ties: Vec<String>,
    right: bool,
    /// The third verdict's fingerprint kind, when the selected model leaves structure.
    unexplained: Option<String>,
    runtime_s: f64,
}

fn arg<T: std::str::FromStr>(args: &[String], name: &str, default: T) -> T {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

fn run_settings() -> RunSettings {
    RunSettings {
        sampler: SamplerKind::NutsDense,
        chains: 4,
        chain: ChainSettings {
            warmup: 500,
            draws: 500,
            keep: None,
        },
        quiet: true,
        metric_adaptation: motorcal::discover::METRIC_ADAPTATION,
        ..RunSettings::default()
    }
}

/// The case diagnosed in memory, as `diagnose` would from its files.
fn diagnose_case(name: &str, case: &Case, rank_only: bool) -> motorcal::discover::Diagnosis {
    let problem = Problem {
        label: name.to_string(),
        recordings: vec![case.recording.clone()],
        model: case.nominal.clone(),
        reference: None,
    };
    let settings = DiscoverSettings {
        run: run_settings(),
        rank_only,
        ..DiscoverSettings::default()
    };
    discover(&problem, &settings).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Right: one effect named (or tied); none for a null case; both of two in the selected set.
fn judge(truth: &[String], d: &motorcal::discover::Diagnosis) -> bool {
    match truth.len() {
        0 => d.selected == "none",
        1 => d.selected == truth[0] || d.ties.contains(&truth[0]),
        _ => truth.iter().all(|t| d.selected_set.contains(t)),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let per_effect: usize = arg(&args, "--per-effect", 5);
    let n_null: usize = arg(&args, "--null", 20);
    let n_two: usize = arg(&args, "--two", 20);
    let seed_base: u64 = arg(&args, "--seed-base", 900_000);
    let out = PathBuf::from(arg(&args, "--out", "papers/diagnose".to_string()));
    let full = args.iter().any(|a| a == "--full");
    let no_dev = args.iter().any(|a| a == "--no-dev");
    let only: Option<Vec<String>> = args
        .iter()
        .position(|a| a == "--effects")
        .and_then(|i| args.get(i + 1))
        .map(|list| list.split(',').map(str::to_string).collect());
    if let Some(names) = &only
        && let Some(unknown) = names.iter().find(|n| !Term::NAMES.contains(&n.as_str()))
    {
        panic!("--effects: unknown term {unknown}");
    }

    // Case specifications: (set, effects, seed, first input).
    let mut specs: Vec<(String, Vec<String>, u64, InputProfile)> = Vec::new();
    let inputs = [InputProfile::Constant, InputProfile::Reversal];
    let mut seed = seed_base;
    for round in 0..per_effect {
        for name in Term::NAMES
            .iter()
            .filter(|n| only.as_ref().is_none_or(|o| o.iter().any(|e| e == *n)))
        {
            specs.push((
                "one".into(),
                vec![name.to_string()],
                seed,
                inputs[round % 2],
            ));
            seed += 1;
        }
    }
    for i in 0..n_null {
        specs.push(("null".into(), vec!["none".into()], seed, inputs[i % 2]));
        seed += 1;
    }
    // Pairs drawn by the seed; a pair the generator cannot make fair is replaced by the next.
    let names = Term::NAMES;
    let mut pair_seed = seed;
    let mut pairs = Vec::new();
    while pairs.len() < n_two * 3 {
        let a = (pair_seed.wrapping_mul(2654435761) >> 7) as usize % names.len();
        let b = (pair_seed.wrapping_mul(40503) >> 3) as usize % names.len();
        if a != b {
            pairs.push((names[a.min(b)], names[a.max(b)], pair_seed));
        }
        pair_seed += 1;
    }

    let make = |effects: &[String], seed: u64, input: InputProfile| {
        let name = format!("{}-{seed}", effects.join("+"));
        let case = make_case(&CaseOptions {
            effects: effects.to_vec(),
            magnitude: None,
            input,
            seed,
            conceal: true,
            tied: false,
        });
        (name, case)
    };
    let evaluate = |set: &str, name: &str, case: &Case| {
        let d = diagnose_case(name, case, !full);
        let answer = &case.answer;
        let truth = answer.effects.clone();
        let row = Row {
            set: set.into(),
            case: name.to_string(),
            right: judge(&truth, &d),
            truth,
            seed: answer.seed,
            input: format!("{:?}", answer.input).to_lowercase(),
            input_fallback: answer.input_fallback,
            peak_over_sigma: answer.max_abs_effect_over_sigma["I"]
                .max(answer.max_abs_effect_over_sigma["omega"]),
            oracle_margin: answer.oracle_margin,
            selected: d.selected.clone(),
            selected_set: d.selected_set.clone(),
            ties: d.ties.clone(),
            unexplained: d.unexplained.as_ref().map(|u| {
                serde_json::to_value(&u.fingerprint).unwrap()["kind"]
                    .as_str()
                    .unwrap_or("?")
                    .to_string()
            }),
            runtime_s: d.runtime_s,
        };
        eprintln!(
            "{} {:?} → {} {:?} ties {:?} {} unexplained {:?} ({:.1} s)",
            row.set,
            row.truth,
            row.selected,
            row.selected_set,
            row.ties,
            if row.right { "right" } else { "WRONG" },
            row.unexplained,
            row.runtime_s
        );
        row
    };

    let mut rows: Vec<Row> = specs
        .par_iter()
        .filter_map(|(set, effects, seed, input)| {
            let (name, case) = make(effects, *seed, *input);
            match case {
                Ok(c) => Some(evaluate(set, &name, &c)),
                Err(e) => {
                    eprintln!("{set} {effects:?} seed {seed}: not made: {e}");
                    None
                }
            }
        })
        .collect();
    let mut two_rows = Vec::new();
    for chunk in pairs.chunks(4) {
        if two_rows.len() >= n_two {
            break;
        }
        let made: Vec<Row> = chunk
            .par_iter()
            .filter_map(|(a, b, seed)| {
                let effects = vec![a.to_string(), b.to_string()];
                let (name, case) = make(&effects, *seed, InputProfile::Reversal);
                match case {
                    Ok(c) => Some(evaluate("two", &name, &c)),
                    Err(e) => {
                        eprintln!("two {effects:?} seed {seed}: not made: {e}");
                        None
                    }
                }
            })
            .collect();
        two_rows.extend(made);
    }
    two_rows.truncate(n_two);
    rows.extend(two_rows);

    let dev = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/concealed-dev");
    if dev.is_dir() && !no_dev && !args.iter().any(|a| a == "--skip-dev") {
        for i in 1..=14 {
            let dir = dev.join(format!("case{i:02}"));
            let answer: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(dir.join("answer.json")).unwrap())
                    .unwrap();
            let effect = answer["effect"].as_str().unwrap().to_string();
            let truth = if effect == "none" {
                vec![]
            } else {
                vec![effect]
            };
            let problem =
                Problem::from_files(&[dir.join("recording.csv")], &dir.join("motor.toml"))
                    .unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
            let settings = DiscoverSettings {
                run: run_settings(),
                ..DiscoverSettings::default()
            };
            let d =
                discover(&problem, &settings).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
            let row = Row {
                set: "dev".into(),
                case: format!("case{i:02}"),
                right: judge(&truth, &d),
                truth,
                seed: answer["noise"]["seed"].as_u64().unwrap_or(0),
                input: answer["type"].as_str().unwrap_or("").into(),
                input_fallback: false,
                peak_over_sigma: 0.0,
                oracle_margin: answer["oracle_bic_margin"].as_f64().map(|b| b / 2.0),
                selected: d.selected.clone(),
                selected_set: d.selected_set.clone(),
                ties: d.ties.clone(),
                unexplained: d.unexplained.as_ref().map(|u| {
                    serde_json::to_value(&u.fingerprint).unwrap()["kind"]
                        .as_str()
                        .unwrap_or("?")
                        .to_string()
                }),
                runtime_s: d.runtime_s,
            };
            eprintln!(
                "dev {} {:?} → {} unexplained {:?} ({:.1} s)",
                row.case, row.truth, row.selected, row.unexplained, row.runtime_s
            );
            rows.push(row);
        }
    }

    std::fs::create_dir_all(&out).unwrap();
    let mut csv = String::from(
        "set,case,truth,seed,input,input_fallback,peak_over_sigma,oracle_margin,selected,selected_set,ties,right,unexplained,runtime_s\n",
    );
    for r in &rows {
        csv.push_str(&format!(
            "{},{},{},{},{},{},{:.3},{},{},{},{},{},{},{:.2}\n",
            r.set,
            r.case,
            r.truth.join("+"),
            r.seed,
            r.input,
            r.input_fallback,
            r.peak_over_sigma,
            r.oracle_margin
                .map(|m| format!("{m:.2}"))
                .unwrap_or_default(),
            r.selected,
            r.selected_set.join("+"),
            r.ties.join("+"),
            r.right,
            r.unexplained.clone().unwrap_or_default(),
            r.runtime_s
        ));
    }
    std::fs::write(out.join("study.csv"), csv).unwrap();
    std::fs::write(
        out.join("study.json"),
        serde_json::to_string_pretty(&rows).unwrap(),
    )
    .unwrap();

    for set in ["dev", "one", "null", "two"] {
        let of: Vec<&Row> = rows.iter().filter(|r| r.set == set).collect();
        if of.is_empty() {
            continue;
        }
        let right = of.iter().filter(|r| r.right).count();
        let mut times: Vec<f64> = of.iter().map(|r| r.runtime_s).collect();
        times.sort_by(f64::total_cmp);
        let unexplained = of.iter().filter(|r| r.unexplained.is_some()).count();
        println!(
            "\n{set}: {right}/{} right ({:.0}%); unexplained {unexplained}; runtime median {:.1} s, max {:.1} s",
            of.len(),
            100.0 * right as f64 / of.len() as f64,
            times[times.len() / 2],
            times[times.len() - 1]
        );
        if set == "two" {
            for r in &of {
                println!(
                    "  {:<40} → {:<40} {}",
                    r.truth.join("+"),
                    r.selected_set.join("+"),
                    if r.right { "" } else { "✗" }
                );
            }
            continue;
        }
        // truth × selected
        let mut table: BTreeMap<String, BTreeMap<String, usize>> = BTreeMap::new();
        for r in &of {
            let truth = r.truth.first().cloned().unwrap_or_else(|| "none".into());
            let shown = if r.right {
                truth.clone()
            } else {
                r.selected.clone()
            };
            *table.entry(truth).or_default().entry(shown).or_default() += 1;
        }
        println!(
            "  {:<20} {:>5}  selected (wrong ones named)",
            "truth", "right"
        );
        for (truth, row) in &table {
            let right = row.get(truth).copied().unwrap_or(0);
            let wrong: Vec<String> = row
                .iter()
                .filter(|(s, _)| *s != truth)
                .map(|(s, n)| format!("{s} ×{n}"))
                .collect();
            println!(
                "  {:<20} {:>2}/{:<2}  {}",
                truth,
                right,
                row.values().sum::<usize>(),
                wrong.join(", ")
            );
        }
    }
}
