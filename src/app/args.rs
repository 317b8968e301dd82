//! How the command line reads the library's enums. The library names its values
//! (`name()`, `ALL`, `FromStr`) and knows nothing of clap; the values' help, which `--help`
//! shows beside each, is the command line's and is written here.

use clap::ValueEnum;
use clap::builder::PossibleValue;

use crate::bayes::CoefficientFamily;
use crate::pipeline::{MetricAdaptation, SamplerKind};

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
        let unknown = "nuts".parse::<SamplerKind>().unwrap_err().to_string();
        assert!(
            unknown.starts_with("sampler = nuts: expected one of metropolis,"),
            "{unknown}"
        );
    }
}
