//! What the library's best single term leaves of a beyond-library case's miss: on the
//! noise-free truth (`truth.csv`, written by `beyond_library_cases`), the nominal model and
//! the nominal model with each library term are fitted by the generator's oracle (weighted
//! least squares, σ known, R and the term's parameters free), and the miss left, ½·SS/σ² in
//! nats, is printed. An effect a library term holds to within what the record can show leaves
//! a few nats; one it stands in for leaves what the verdict should still find.
//!
//! cargo run --release --example library_residual -- CASE_DIR…

use std::path::Path;

use motorcal::motor::Term;
use motorcal::study::Problem;
use motorcal::study::cases::NOISE_SD;
use motorcal::study::cases::oracle::least_squares;

fn main() {
    let dirs: Vec<String> = std::env::args().skip(1).collect();
    if dirs.is_empty() {
        eprintln!("usage: library_residual CASE_DIR…");
        std::process::exit(2);
    }
    println!(
        "| case | miss of the nominal model (nats) | best library term | miss it leaves (nats) | runner-up | its miss |"
    );
    println!("|---|---|---|---|---|---|");
    for dir in dirs {
        let dir = Path::new(&dir);
        let problem = match Problem::from_files(&[dir.join("truth.csv")], &dir.join("motor.toml")) {
            Ok(p) => p,
            Err(e) => {
                eprintln!("{}: {e}", dir.display());
                continue;
            }
        };
        let record = &problem.recordings[0];
        let target: Vec<f64> = ["I", "omega"]
            .iter()
            .flat_map(|c| record.channel(c).expect("the channel").to_vec())
            .collect();
        let miss = |added: &[String]| {
            least_squares(&problem, added, &target, &NOISE_SD).map(|(ss, _)| 0.5 * ss)
        };
        let none = miss(&[]).unwrap_or(f64::NAN);
        let mut fits: Vec<(String, f64)> = Term::NAMES
            .iter()
            .filter_map(|t| miss(&[t.to_string()]).ok().map(|m| (t.to_string(), m)))
            .collect();
        fits.sort_by(|a, b| a.1.total_cmp(&b.1));
        let name = dir.file_name().unwrap().to_string_lossy();
        println!(
            "| {name} | {none:.1} | {} | {:.1} | {} | {:.1} |",
            fits[0].0, fits[0].1, fits[1].0, fits[1].1
        );
    }
}
