//! The check a forward model's sensitivities share across the tests: every column of the
//! Jacobian against central differences of `simulate`.

use motorcal::forward::ForwardModel;
use nalgebra::DMatrix;

/// The sensitivities at `theta`, each column asserted within 1e-5 of its largest entry of the
/// central difference with step `step(k)` for parameter k; the Jacobian, for further checks.
pub fn assert_sensitivities_are_central_differences(
    forward: &ForwardModel,
    theta: &[f64],
    step: impl Fn(usize) -> f64,
) -> DMatrix<f64> {
    let n = forward.n_outputs();
    let mut values = vec![0.0; n];
    let mut jacobian = DMatrix::zeros(n, theta.len());
    forward
        .simulate_with_sensitivities(theta, &mut values, &mut jacobian)
        .unwrap();
    let names = forward.calibrated_names();
    for k in 0..theta.len() {
        let h = step(k);
        let (mut up, mut down) = (theta.to_vec(), theta.to_vec());
        up[k] += h;
        down[k] -= h;
        let (mut vu, mut vd) = (vec![0.0; n], vec![0.0; n]);
        forward.simulate(&up, &mut vu).unwrap();
        forward.simulate(&down, &mut vd).unwrap();
        let scale = jacobian.column(k).amax().max(1e-12);
        for row in 0..n {
            let fd = (vu[row] - vd[row]) / (2.0 * h);
            assert!(
                (fd - jacobian[(row, k)]).abs() < 1e-5 * scale,
                "{}, output {row}: {fd} vs {}",
                names[k],
                jacobian[(row, k)]
            );
        }
    }
    jacobian
}
