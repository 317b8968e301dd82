//! `motorcal select-k`: §3.2.3's guideline made automatic — the smallest K whose marginal
//! posteriors of σ_I and σ_ω stay within a tolerance of those at K + L for L = 1, 2, 3.
//!
//! **The distance** (fixed before any run of this rule): the Wasserstein-1 distance between the
//! two marginal posteriors of σ_c, divided by the posterior sd of σ_c at K + L, maximised over the
//! channels and L. W1 compares whole distributions in the quantity's own unit (for two
//! Gaussians of equal spread it is the shift of the means), and dividing by the sd makes it the
//! shift in posterior standard deviations: a number that means the same at every K and on both
//! channels. **The tolerance, 0.5**: a shift of half a posterior sd is where two posteriors of
//! equal spread stop being hard to tell apart (their overlap coefficient, 2Φ(−δ/2), falls to
//! 0.80). On the paper's data the distances once σ has settled (K = 8…17) were 0.04–0.12
//! (papers/john2018 §4): Monte Carlo noise and the last real drift together stay well below it.

use serde::Serialize;

use super::SweepRecord;

pub const TOLERANCE: f64 = 0.5;

/// The rules that choose K: §3.2.3's σ-stabilisation ([`sigma_stabilisation`]) or the largest
/// log evidence ([`evidence`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Rule {
    #[default]
    SigmaStabilisation,
    Evidence,
}

impl Rule {
    pub const ALL: [Rule; 2] = [Rule::SigmaStabilisation, Rule::Evidence];

    /// The rule's name, as the selections record it (`rule`).
    pub fn name(&self) -> &'static str {
        match self {
            Rule::SigmaStabilisation => "sigma-stabilisation",
            Rule::Evidence => "evidence",
        }
    }
}

/// A rule by its [`Rule::name`].
impl std::str::FromStr for Rule {
    type Err = crate::error::Error;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        crate::error::parse_name("rule", text, &Self::ALL, Self::name)
    }
}
/// L = 1, 2, 3, as §3.2.3 asks.
pub const LOOK_AHEAD: usize = 3;

#[derive(Clone, Debug, Serialize)]
pub struct KDistance {
    pub k: usize,
    /// max over channels and L of W1(π^K(σ_c), π^{K+L}(σ_c)) / sd^{K+L}(σ_c).
    pub distance: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Selection {
    /// The chosen K, or `None` if no K of the sweep stabilises.
    pub k: Option<usize>,
    pub rule: String,
    pub tolerance: f64,
    pub distances: Vec<KDistance>,
}

/// Wasserstein-1 distance between two samples: ∫|F⁻¹(u) − G⁻¹(u)| du on a grid of quantiles.
pub fn wasserstein_1(a: &[f64], b: &[f64]) -> f64 {
    let sorted = |v: &[f64]| {
        let mut s = v.to_vec();
        s.sort_by(f64::total_cmp);
        s
    };
    let (a, b) = (sorted(a), sorted(b));
    let quantile = |s: &[f64], u: f64| {
        let h = u * (s.len() - 1) as f64;
        let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
        s[lo] + (h - lo as f64) * (s[hi] - s[lo])
    };
    let n = a.len().max(b.len()).max(1000);
    (0..n)
        .map(|i| {
            let u = (i as f64 + 0.5) / n as f64;
            (quantile(&a, u) - quantile(&b, u)).abs()
        })
        .sum::<f64>()
        / n as f64
}

fn sd(v: &[f64]) -> f64 {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// The rule over a sweep's records (any order; consecutive degrees needed for each K judged).
pub fn sigma_stabilisation(records: &[SweepRecord]) -> Selection {
    let at = |k: usize| records.iter().find(|r| r.k == k);
    let mut ks: Vec<usize> = records.iter().map(|r| r.k).collect();
    ks.sort();
    let mut distances = Vec::new();
    for &k in &ks {
        let Some(base) = at(k) else { continue };
        let ahead: Vec<&SweepRecord> = (1..=LOOK_AHEAD).filter_map(|l| at(k + l)).collect();
        if ahead.len() < LOOK_AHEAD {
            continue;
        }
        let mut worst: f64 = 0.0;
        for other in ahead {
            for c in 0..2 {
                let d = wasserstein_1(&base.sigma_draws[c], &other.sigma_draws[c])
                    / sd(&other.sigma_draws[c]);
                worst = worst.max(d);
            }
        }
        distances.push(KDistance { k, distance: worst });
    }
    Selection {
        k: distances
            .iter()
            .find(|d| d.distance < TOLERANCE)
            .map(|d| d.k),
        rule: Rule::SigmaStabilisation.name().into(),
        tolerance: TOLERANCE,
        distances,
    }
}

/// Effective importance draws below which an evidence estimate is not trusted.
pub const MIN_EFFECTIVE_DRAWS: f64 = 100.0;

#[derive(Clone, Debug, Serialize)]
pub struct KEvidence {
    pub k: usize,
    pub log_evidence: f64,
    pub standard_error: f64,
    pub effective_draws: f64,
    pub log_evidence_laplace: f64,
    /// Whether the estimate has enough effective draws to be ranked.
    pub trusted: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct EvidenceSelection {
    pub k: Option<usize>,
    pub rule: String,
    pub evidences: Vec<KEvidence>,
}

/// The K of largest log evidence (importance sampling), among estimates with at least
/// [`MIN_EFFECTIVE_DRAWS`] effective draws.
pub fn evidence(records: &[SweepRecord]) -> EvidenceSelection {
    let mut evidences: Vec<KEvidence> = records
        .iter()
        .map(|r| KEvidence {
            k: r.k,
            log_evidence: r.evidence.log_evidence,
            standard_error: r.evidence.standard_error,
            effective_draws: r.evidence.effective_draws,
            log_evidence_laplace: r.evidence.log_evidence_laplace,
            trusted: r.evidence.effective_draws >= MIN_EFFECTIVE_DRAWS,
        })
        .collect();
    evidences.sort_by_key(|e| e.k);
    let k = evidences
        .iter()
        .filter(|e| e.trusted)
        .max_by(|a, b| a.log_evidence.total_cmp(&b.log_evidence))
        .map(|e| e.k);
    EvidenceSelection {
        k,
        rule: Rule::Evidence.name().into(),
        evidences,
    }
}

#[cfg(test)]
mod tests {
    use super::wasserstein_1;

    #[test]
    fn w1_of_a_shift_is_the_shift() {
        let a: Vec<f64> = (0..2000).map(|i| (i as f64 / 1999.0) * 3.0).collect();
        let b: Vec<f64> = a.iter().map(|x| x + 0.7).collect();
        assert!((wasserstein_1(&a, &b) - 0.7).abs() < 1e-9);
        assert!(wasserstein_1(&a, &a) < 1e-12);
    }
}
