//! `motorcal select-k`: one whole sweep (`app::sweep`), then the choice of K by the rule asked
//! for (`paper::sweep::select`), printed and, with `--json`, written.

use std::path::Path;

use super::AppError;
use super::sweep::{SweepArgs, run_options, select};

/// The sweep, its table and files, then the rule's reading of it and the chosen K.
pub fn run(args: &SweepArgs) -> Result<(), AppError> {
    let options = args.options(true)?;
    if options.shard.is_some() || options.data_seeds.len() > 1 {
        return Err(AppError::Usage(
            "select-k judges one whole sweep: no --shard, one --data-seed".into(),
        ));
    }
    let rule = args.rule()?;
    let records = run_options(&options)?;
    match rule {
        select::Rule::Evidence => {
            let choice = select::evidence(&records);
            for e in &choice.evidences {
                println!(
                    "K = {:>2}: log evidence {:.2} ± {:.2} ({:.0} effective draws{}), Laplace {:.2}",
                    e.k,
                    e.log_evidence,
                    e.standard_error,
                    e.effective_draws,
                    if e.trusted { "" } else { ", not trusted" },
                    e.log_evidence_laplace
                );
            }
            match choice.k {
                Some(k) => println!("chosen K = {k} (largest evidence)"),
                None => println!("no evidence estimate has enough effective draws"),
            }
            write_choice(args.json.as_deref(), &choice)
        }
        select::Rule::SigmaStabilisation => {
            let choice = select::sigma_stabilisation(&records);
            for d in &choice.distances {
                println!("K = {:>2}: distance {:.3}", d.k, d.distance);
            }
            match choice.k {
                Some(k) => println!(
                    "chosen K = {k} (σ posteriors within {} sd for K + 1..3)",
                    choice.tolerance
                ),
                None => println!("no K of the sweep stabilises within {}", choice.tolerance),
            }
            write_choice(args.json.as_deref(), &choice)
        }
    }
}

fn write_choice<T: serde::Serialize>(path: Option<&Path>, choice: &T) -> Result<(), AppError> {
    if let Some(path) = path {
        let text =
            serde_json::to_string_pretty(choice).map_err(|e| AppError::Output(e.to_string()))?;
        crate::io::write_atomically(path, text.as_bytes())?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
