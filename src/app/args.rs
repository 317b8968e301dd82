//! What the commands share on the command line: the chains' options ([`ChainArgs`]), lists of
//! degrees ([`parse_ks`]), and how clap reads the library's enums. The library names its values
//! (`name()`, `ALL`, `FromStr`) and knows nothing of clap; the values' help, which `--help`
//! shows beside each, is the command line's and is written here.

use clap::ValueEnum;
use clap::builder::PossibleValue;

use crate::bayes::{CoefficientFamily, CoefficientPrior};
use crate::paper::sweep::select::Rule;
use crate::pipeline::{MetricAdaptation, RunSettings, SamplerKind, default_warmup};
use crate::sampler::ChainSettings;

/// What every command that runs chains takes: how many, from which seed, shown or not.
#[derive(clap::Args, Clone, Debug)]
pub struct ChainArgs {
    /// Chains per run (default 4; `reproduce table1`: 3, as the paper ran).
    #[arg(long)]
    pub chains: Option<usize>,
    /// Seed of the chains (and of the paper's synthetic noise).
    #[arg(long, default_value_t = crate::synthetic::DEFAULT_SEED)]
    pub seed: u64,
    /// No progress bars.
    #[arg(long)]
    pub quiet: bool,
    /// HMC/NUTS warm-up: keep the Laplace metric and tune the step size (laplace; the default,
    /// but windows for `reproduce table1`), or re-estimate the metric in Stan's windows.
    #[arg(long, value_enum)]
    pub metric_adaptation: Option<MetricAdaptation>,
}

impl ChainArgs {
    pub fn chains_or(&self, default: usize) -> usize {
        self.chains.unwrap_or(default)
    }

    /// A run of `sampler` with these chains (default 4), seed and quietness; a warm-up not
    /// given is the sampler's default for the metric adaptation (see
    /// [`default_warmup`]).
    pub fn run(&self, sampler: SamplerKind, warmup: Option<usize>, draws: usize) -> RunSettings {
        self.run_adapting(sampler, warmup, draws, MetricAdaptation::default())
    }

    /// As [`ChainArgs::run`], with a command's own default metric adaptation.
    pub fn run_adapting(
        &self,
        sampler: SamplerKind,
        warmup: Option<usize>,
        draws: usize,
        default_metric: MetricAdaptation,
    ) -> RunSettings {
        let metric_adaptation = self.metric_adaptation.unwrap_or(default_metric);
        RunSettings {
            sampler,
            chains: self.chains_or(4),
            chain: ChainSettings {
                warmup: warmup.unwrap_or_else(|| default_warmup(sampler, metric_adaptation)),
                draws,
                keep: None,
            },
            seed: self.seed,
            quiet: self.quiet,
            metric_adaptation,
            ..RunSettings::default()
        }
    }
}

/// The coefficient prior of `--prior-family` and `--prior-decay`.
pub fn coefficient_prior(family: CoefficientFamily, decay_power: f64) -> CoefficientPrior {
    CoefficientPrior {
        family,
        decay_power,
        ..CoefficientPrior::default()
    }
}

/// Discrepancy degrees as a range (`0..=20`, `3..10`) or a comma list (`0,3,9`).
pub fn parse_ks(text: &str) -> Result<Vec<usize>, String> {
    let bad = |e: &dyn std::fmt::Display| format!("'{text}': {e}");
    if let Some((a, b)) = text.split_once("..") {
        let (inclusive, b) = match b.strip_prefix('=') {
            Some(b) => (true, b),
            None => (false, b),
        };
        let a: usize = a.trim().parse().map_err(|e| bad(&e))?;
        let b: usize = b.trim().parse().map_err(|e| bad(&e))?;
        let end = if inclusive { b + 1 } else { b };
        if end <= a {
            return Err(format!("'{text}': an empty range"));
        }
        return Ok((a..end).collect());
    }
    text.split(',')
        .map(|v| v.trim().parse::<usize>().map_err(|e| bad(&e)))
        .collect()
}

impl ValueEnum for SamplerKind {
    fn value_variants<'a>() -> &'a [Self] {
        &Self::ALL
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        let help = match self {
            SamplerKind::Metropolis => {
                "The paper's Metropolis: one random-walk step per variable in turn, tuned as PyMC3 did"
            }
            SamplerKind::AdaptiveMetropolis => {
                "Adaptive Metropolis (Haario et al. 2001): joint proposal from the warm-up covariance"
            }
            SamplerKind::Mala => {
                "Preconditioned MALA; the preconditioner starts at the inverse MAP Hessian"
            }
            SamplerKind::HmcDiag => {
                "Static HMC, diagonal metric: the Laplace variances (or Stan's windows)"
            }
            SamplerKind::HmcDense => {
                "Static HMC, dense metric: the inverse MAP Hessian (or Stan's windows from it)"
            }
            SamplerKind::NutsDiag => {
                "NUTS, diagonal metric: the Laplace variances (or Stan's windows)"
            }
            SamplerKind::NutsDense => {
                "NUTS, dense metric: the inverse MAP Hessian (or Stan's windows from it)"
            }
            SamplerKind::FisherMala => {
                "Simplified manifold MALA with the Gauss–Newton (Fisher) metric"
            }
            SamplerKind::Independence => {
                "Independence Metropolis–Hastings from a Student-t at the MAP with the Laplace covariance; NUTS when k̂ of its warm-up > 0.5"
            }
            SamplerKind::LaplaceIs => {
                "Importance sampling from that Student-t, Pareto-smoothed; NUTS when k̂ > 0.7"
            }
            SamplerKind::CollapsedIs => {
                "Importance sampling with θ from that Student-t's marginal, σ and the discrepancy coefficients from their conditionals given θ; NUTS when k̂ > 0.7"
            }
        };
        Some(PossibleValue::new(self.name()).help(help))
    }
}

impl ValueEnum for MetricAdaptation {
    fn value_variants<'a>() -> &'a [Self] {
        &Self::ALL
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        let help = match self {
            MetricAdaptation::Laplace => concat!(
                "Keep the Laplace covariance; warm-up tunes the step size alone. The calibration ",
                "posteriors are close to Gaussian in the unconstrained coordinates, so the Hessian ",
                "is a better metric than any estimate from a few hundred correlated draws ",
                "(papers/john2018, \"The warm-up\"), and warm-up shrinks to what dual averaging needs"
            ),
            MetricAdaptation::Windows => concat!(
                "Stan's windows: re-estimate the metric from the chain's own warm-up draws, shrunk ",
                "toward the one in use. For posteriors far from Gaussian; it needs a long warm-up ",
                "(≥ 1000)"
            ),
        };
        Some(PossibleValue::new(self.name()).help(help))
    }
}

/// Without help per value: `--help` lists the families on one line.
impl ValueEnum for CoefficientFamily {
    fn value_variants<'a>() -> &'a [Self] {
        &Self::ALL
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        Some(PossibleValue::new(self.name()))
    }
}

impl ValueEnum for Rule {
    fn value_variants<'a>() -> &'a [Self] {
        &Self::ALL
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        Some(PossibleValue::new(self.name()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The command line and the library (files, labels, `FromStr`) spell every value alike.
    #[test]
    fn the_command_line_reads_the_names_the_library_writes() {
        for kind in SamplerKind::ALL {
            assert_eq!(
                <SamplerKind as ValueEnum>::from_str(kind.name(), false),
                Ok(kind)
            );
            assert_eq!(kind.name().parse::<SamplerKind>(), Ok(kind));
        }
        for metric in MetricAdaptation::ALL {
            assert_eq!(
                <MetricAdaptation as ValueEnum>::from_str(metric.name(), false),
                Ok(metric)
            );
            assert_eq!(metric.name().parse::<MetricAdaptation>(), Ok(metric));
        }
        for family in CoefficientFamily::ALL {
            assert_eq!(
                <CoefficientFamily as ValueEnum>::from_str(family.name(), false),
                Ok(family)
            );
            assert_eq!(family.name().parse::<CoefficientFamily>(), Ok(family));
        }
        for rule in Rule::ALL {
            assert_eq!(<Rule as ValueEnum>::from_str(rule.name(), false), Ok(rule));
            assert_eq!(rule.name().parse::<Rule>(), Ok(rule));
        }
        assert_eq!(parse_ks("0..=2"), Ok(vec![0, 1, 2]));
        assert_eq!(parse_ks("3..5"), Ok(vec![3, 4]));
        assert_eq!(parse_ks("0, 3,9"), Ok(vec![0, 3, 9]));
        assert!(parse_ks("5..2").unwrap_err().contains("empty"));
        let unknown = "nuts".parse::<SamplerKind>().unwrap_err().to_string();
        assert!(
            unknown.starts_with("sampler = nuts: expected one of metropolis,"),
            "{unknown}"
        );
    }
}
