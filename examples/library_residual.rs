//! What the library's best single term leaves of a beyond-library case's miss: on the
//! noise-free truth (`truth.csv`, written by `beyond_library_cases`), the nominal model and
//! the nominal model with each library term are fitted by the generator's oracle (weighted
//! least squares, σ known, R and the term's parameters free), and the miss left, ½·SS/σ² in
//! nats, is printed. An effect a library term holds to within what the record can show leaves
//! a few nats; one it stands in for leaves what the verdict should still find.
//!
//! With `--report NAME`, a column more: the miss left by the library terms a `diagnose --json`
//! report (`CASE_DIR/NAME`) selected, fitted together (a `law` among them is left out), which
//! says whether a selection of several terms holds what no single term does.
//!
//! cargo run --release --example library_residual -- [--report r.json] CASE_DIR…

use std::path::Path;

use motorcal::error::Error;
use motorcal::motor::Term;
use motorcal::study::Problem;
use motorcal::study::cases::NOISE_SD;
use motorcal::study::cases::oracle::least_squares;

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let report = args.iter().position(|a| a == "--report").map(|i| {
        let name = args.get(i + 1).cloned().unwrap_or_default();
        args.drain(i..(i + 2).min(args.len()));
        name
    });
    let dirs = args;
    if dirs.is_empty() {
        eprintln!("usage: library_residual [--report NAME] CASE_DIR…");
        std::process::exit(2);
    }
    let (extra, rule) = if report.is_some() {
        (
            " the report's library terms | the miss they leave |",
            "---|---|",
        )
    } else {
        ("", "")
    };
    println!(
        "| case | miss of the nominal model (nats) | best library term | miss it leaves (nats) | runner-up | its miss |{extra}"
    );
    println!("|---|---|---|---|---|---|{rule}");
    let mut failed = 0;
    for dir in dirs {
        let dir = Path::new(&dir);
        match library_residual(dir, report.as_deref()) {
            Ok(row) => println!("{row}"),
            Err(e) => {
                eprintln!("{}: {e}", dir.display());
                failed += 1;
            }
        }
    }
    if failed > 0 {
        std::process::exit(1);
    }
}

/// The table row of one case folder.
fn library_residual(dir: &Path, report: Option<&str>) -> Result<String, Error> {
    let problem = Problem::from_files(&[dir.join("truth.csv")], &dir.join("motor.toml"))?;
    let record = &problem.recordings[0];
    let mut target = Vec::new();
    for c in ["I", "omega"] {
        let values = record.channel(c).ok_or_else(|| {
            Error::invalid(format!(
                "{}: no channel {c}",
                dir.join("truth.csv").display()
            ))
        })?;
        target.extend_from_slice(values);
    }
    let miss = |added: &[String]| {
        least_squares(&problem, added, &target, &NOISE_SD).map(|(ss, _)| 0.5 * ss)
    };
    let none = miss(&[])?;
    let mut fits: Vec<(String, f64)> = Term::NAMES
        .iter()
        .filter_map(|t| miss(&[t.to_string()]).ok().map(|m| (t.to_string(), m)))
        .collect();
    fits.sort_by(|a, b| a.1.total_cmp(&b.1));
    let [best, runner_up, ..] = fits.as_slice() else {
        return Err(Error::invalid(
            "fewer than two library terms could be fitted",
        ));
    };
    let name = dir.file_name().unwrap_or_default().to_string_lossy();
    let mut row = format!(
        "| {name} | {none:.1} | {} | {:.1} | {} | {:.1} |",
        best.0, best.1, runner_up.0, runner_up.1
    );
    if let Some(report) = report {
        let path = dir.join(report);
        let text = std::fs::read_to_string(&path)
            .map_err(|e| Error::invalid(format!("{}: {e}", path.display())))?;
        let json: serde_json::Value = serde_json::from_str(&text)
            .map_err(|e| Error::invalid(format!("{}: {e}", path.display())))?;
        let selected: Vec<String> = json["selected_set"]
            .as_array()
            .map(|a| {
                a.iter()
                    .filter_map(|v| v.as_str())
                    .map(String::from)
                    .collect()
            })
            .unwrap_or_default();
        let library: Vec<String> = selected.into_iter().filter(|t| t != "law").collect();
        let left = miss(&library)?;
        row.push_str(&format!(" {} | {left:.1} |", library.join(" + ")));
    }
    Ok(row)
}
