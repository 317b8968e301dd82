//! The sampling check of the Laplace evidence that `diagnose` runs for doubtful leaders: where
//! the posterior is close to Gaussian the importance-sampling estimate equals the Laplace value
//! within its Monte Carlo error; where a parameter piles against its bound it stays finite and
//! its weights usable.

use motorcal::discover::{fit_candidate, importance_evidence};
use motorcal::study::Problem;

#[test]
fn importance_sampling_agrees_with_laplace_where_the_posterior_is_gaussian() {
    let problem = Problem::paper(20180823).unwrap();
    // The paper's data were made with c_g = 0.01 and the model says 0.009: the torque-constant
    // term is strongly identified, its posterior nearly Gaussian.
    let fit = fit_candidate(&problem, &["torque_constant".to_string()]).unwrap();
    let c = importance_evidence(&fit, 7).unwrap();
    eprintln!("{c:?}");
    assert!(c.effective_draws > 500.0, "{c:?}");
    let gap = c.log_evidence - c.log_evidence_laplace;
    assert!(
        gap.abs() < 0.1 + 4.0 * c.standard_error,
        "importance sampling {:.3} ± {:.3}, Laplace {:.3}",
        c.log_evidence,
        c.standard_error,
        c.log_evidence_laplace
    );
}

#[test]
fn a_parameter_at_its_bound_is_flagged_and_still_estimated() {
    let mut problem = Problem::paper(20180823).unwrap();
    // The model as the data were made (c_g = 0.01): nothing is missing, and a Coulomb friction
    // T_c ≥ 0 piles against 0.
    problem.model.motor.torque_constant = 0.01;
    let fit = fit_candidate(&problem, &["coulomb_friction".to_string()]).unwrap();
    eprintln!("at bound: {:?}", fit.at_bound);
    assert_eq!(fit.at_bound, vec!["coulomb_friction.T_c".to_string()]);
    let c = importance_evidence(&fit, 7).unwrap();
    eprintln!("{c:?}");
    assert!(
        c.log_evidence.is_finite() && c.effective_draws > 50.0,
        "{c:?}"
    );
}
