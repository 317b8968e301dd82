//! What `motorcal design` prints: the designed input's gaps or sds beside the fixed
//! experiments', and the rival check's rounds.

use std::path::Path;

use serde_json::Value;

/// The rival check: each round's candidates, gap and unseparated rivals, then what is left.
fn print_rivals(report: &Value) {
    let check = &report["rival_check"];
    if check.is_null() {
        println!("rest of the library: not checked (--no-rival-check)");
        return;
    }
    let threshold = check["threshold_nats"].as_f64().unwrap_or(f64::NAN);
    let rounds = check["rounds"].as_array().map_or(&[][..], Vec::as_slice);
    for (i, round) in rounds.iter().enumerate() {
        let names: Vec<&str> = round["candidates"]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(Value::as_str)
            .collect();
        let rivals: Vec<String> = round["unseparated_rivals"]
            .as_array()
            .into_iter()
            .flatten()
            .map(|r| {
                format!(
                    "{} on {} ({:.2})",
                    r["rival"].as_str().unwrap_or(""),
                    r["truth"].as_str().unwrap_or(""),
                    r["expected_gap_nats"].as_f64().unwrap_or(f64::NAN)
                )
            })
            .collect();
        println!(
            "  round {}: {} → expected gap {:.2} nats; rivals within {threshold} nats: {}",
            i + 1,
            names.join(", "),
            round["expected_gap_nats"].as_f64().unwrap_or(f64::NAN),
            if rivals.is_empty() {
                "none".into()
            } else {
                rivals.join(", ")
            }
        );
        if let Some(note) = round["note"].as_str() {
            println!("    {note}");
        }
    }
    let rivals = report["unseparated_rivals"]
        .as_array()
        .map_or(&[][..], Vec::as_slice);
    if rivals.is_empty() {
        println!("rest of the library: no rival within {threshold} nats of any candidate");
    } else {
        println!("unseparated rivals (the design leaves them within {threshold} nats):");
        println!("  {:<24} {:<24} {:>16}", "truth", "rival", "expected gap");
        for r in rivals {
            println!(
                "  {:<24} {:<24} {:>16.2}",
                r["truth"].as_str().unwrap_or(""),
                r["rival"].as_str().unwrap_or(""),
                r["expected_gap_nats"].as_f64().unwrap_or(f64::NAN)
            );
        }
    }
}

pub(super) fn print_summary(report: &Value, out: &Path) {
    let f = |v: &Value| v.as_f64().map_or("—".to_string(), |x| format!("{x:.2}"));
    if report["objective"] == "separate" {
        println!(
            "designed input: expected gap {} ± {} nats (worst truth)",
            f(&report["expected_gap_nats"]),
            f(&report["expected_gap_sd_nats"])
        );
        for g in report["gaps"].as_array().into_iter().flatten() {
            println!(
                "  {} as truth over {}: {} ± {} nats, σ estimated (at the σ given {}; \
                 noise-free {})",
                g["truth"].as_str().unwrap_or(""),
                g["rival"].as_str().unwrap_or(""),
                f(&g["expected_gap_nats"]),
                f(&g["sd_nats"]),
                f(&g["known_sigma_gap_nats"]),
                f(&g["noise_free_gap_nats"])
            );
        }
        print_rivals(report);
        for e in report["fixed_experiments"].as_array().into_iter().flatten() {
            println!(
                "{:>9} input: expected gap {} ± {} nats{}",
                e["input"].as_str().unwrap_or(""),
                f(&e["expected_gap_nats"]),
                f(&e["expected_gap_sd_nats"]),
                if e["within_limits"] == true {
                    ""
                } else {
                    " (passes the limits)"
                }
            );
        }
    } else {
        println!("designed input: expected sd {}", report["expected_sd"]);
        for e in report["fixed_experiments"].as_array().into_iter().flatten() {
            println!(
                "{:>9} input: expected sd {}{}",
                e["input"].as_str().unwrap_or(""),
                e["expected_sd"],
                if e["within_limits"] == true {
                    ""
                } else {
                    " (passes the limits)"
                }
            );
        }
    }
    println!(
        "wrote {} (input.csv, design.json, design.png) in {:.1} s",
        out.display(),
        report["runtime_s"].as_f64().unwrap_or(0.0)
    );
}
