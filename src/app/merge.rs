//! `motorcal merge`: the JSON of sweep shards read back and joined (`paper::sweep::merge`) into
//! what one unsharded sweep writes.

use std::path::{Path, PathBuf};

use super::AppError;
use super::sweep::{SweepOptions, SweepRecord, merge, print_and_write};
use crate::bayes::CoefficientPrior;
use crate::pipeline::RunSettings;

#[derive(clap::Args, Clone, Debug)]
pub struct MergeArgs {
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    #[arg(long, default_value = "out/sweep")]
    pub out: PathBuf,
    #[arg(long)]
    pub json: Option<PathBuf>,
}

/// The records of one shard's `sweep.json` (or `--json`).
pub fn read_shard(path: &Path) -> Result<Vec<SweepRecord>, AppError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| AppError::Usage(format!("{}: {e}", path.display())))?;
    serde_json::from_str(&text)
        .map_err(|e| AppError::Usage(format!("{}: line {}: {e}", path.display(), e.line())))
}

/// Reads every shard, joins them, and prints and writes the whole as `sweep` would.
pub fn run(args: &MergeArgs) -> Result<(), AppError> {
    let loaded = args
        .parts
        .iter()
        .map(|path| read_shard(path))
        .collect::<Result<Vec<_>, _>>()?;
    let records = merge(loaded)?;
    let options = SweepOptions {
        ks: Vec::new(),
        coefficient_prior: CoefficientPrior::default(),
        data_seeds: Vec::new(),
        shard: None,
        run: RunSettings::default(),
        out: args.out.clone(),
        json: args.json.clone(),
        figures_at: Vec::new(),
    };
    print_and_write(&records, &options)
}
