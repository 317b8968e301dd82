//! The forward model G(θ): the motor's channels at a recording's sample times, and their
//! sensitivities ∂G/∂θ to the calibrated ODE parameters θ by forward-mode dual numbers.

use nalgebra::DMatrix;
use num_dual::{Dual64, DualNum, DualSVec64};

use crate::motor::{MotorModel, Segments};
use crate::ode::{self, OdeError, SolverSettings, SolverStats};
use crate::parameter::{ParamId, ParameterSpec};

/// G(θ) for one recording: which parameters are free, at which times the channels are sampled.
#[derive(Clone, Debug)]
pub struct ForwardModel {
    model: MotorModel,
    times: Vec<f64>,
    segments: Segments,
    calibrated: Vec<usize>,
    nominal: Vec<f64>,
    solver: SolverSettings,
}

/// The integration starts at t = 0 (the motor at rest, or at its declared initial state).
const T0: f64 = 0.0;

impl ForwardModel {
    /// `calibrated` names the free parameters (keys of the model's parameter vector, e.g. "R"
    /// or "coulomb_friction.T_c").
    pub fn new<S: AsRef<str>>(
        model: MotorModel,
        times: Vec<f64>,
        calibrated: &[S],
        solver: SolverSettings,
    ) -> Result<Self, String> {
        if times.is_empty() {
            return Err("no sample times".into());
        }
        if times[0] < T0 || times.windows(2).any(|w| !(w[1] > w[0])) {
            return Err("sample times must be non-negative and strictly increasing".into());
        }
        let ids = model.parameter_ids();
        let names = model.parameter_names();
        let calibrated = calibrated
            .iter()
            .map(|name| {
                let id = ParamId::parse(name.as_ref());
                let index = ids.iter().position(|p| *p == id).ok_or_else(|| {
                    format!("unknown parameter '{id}' (known: {})", names.join(", "))
                })?;
                model.check_calibrated(&id)?;
                Ok(index)
            })
            .collect::<Result<Vec<_>, String>>()?;
        for (k, i) in calibrated.iter().enumerate() {
            if calibrated[..k].contains(i) {
                return Err(format!("parameter '{}' is calibrated twice", names[*i]));
            }
        }
        let segments = model.segments(T0);
        let nominal = model.parameter_values();
        Ok(Self {
            model,
            times,
            segments,
            calibrated,
            nominal,
            solver,
        })
    }

    pub fn model(&self) -> &MotorModel {
        &self.model
    }

    pub fn times(&self) -> &[f64] {
        &self.times
    }

    pub fn channels(&self) -> &'static [&'static str] {
        self.model.channels()
    }

    pub fn n_samples(&self) -> usize {
        self.times.len()
    }

    /// Length of the output vector: channels × samples, channel-major.
    pub fn n_outputs(&self) -> usize {
        self.channels().len() * self.times.len()
    }

    pub fn n_calibrated(&self) -> usize {
        self.calibrated.len()
    }

    pub fn calibrated_names(&self) -> Vec<String> {
        let names = self.model.parameter_names();
        self.calibrated.iter().map(|&i| names[i].clone()).collect()
    }

    /// The calibrated parameters as the model declares them, default priors scaled to this
    /// model and this recording's length.
    pub fn calibrated_specs(&self) -> Vec<ParameterSpec> {
        let duration = self.times.last().copied().unwrap_or(0.0) - T0;
        let specs = self.model.parameter_specs(&self.model.magnitudes(duration));
        self.calibrated.iter().map(|&i| specs[i].clone()).collect()
    }

    /// Nominal values of the calibrated parameters.
    pub fn nominal_calibrated(&self) -> Vec<f64> {
        self.calibrated.iter().map(|&i| self.nominal[i]).collect()
    }

    pub fn solver(&self) -> &SolverSettings {
        &self.solver
    }

    /// G(θ), channel-major: `out[c * M + i]` is channel c at sample i.
    pub fn simulate(&self, theta: &[f64], out: &mut [f64]) -> Result<SolverStats, OdeError> {
        let mut p = self.nominal.clone();
        for (k, &slot) in self.calibrated.iter().enumerate() {
            p[slot] = theta[k];
        }
        self.run(&p, out)
    }

    /// G(θ) and the sensitivity matrix ∂G/∂θ (outputs × calibrated parameters).
    ///
    /// One dual-number solve carries up to four directions at once (`DualSVec64`); a fifth
    /// parameter starts another pass. All passes take the same steps, since step control sees
    /// real parts only, so the columns are derivatives of one numerical solution.
    pub fn simulate_with_sensitivities(
        &self,
        theta: &[f64],
        out: &mut [f64],
        jacobian: &mut DMatrix<f64>,
    ) -> Result<SolverStats, OdeError> {
        let n_par = self.calibrated.len();
        assert_eq!(jacobian.nrows(), self.n_outputs());
        assert_eq!(jacobian.ncols(), n_par);
        match n_par {
            0 => self.simulate(theta, out),
            1 => self.sensitivity_pass::<Dual64>(theta, 0, 1, out, jacobian),
            2 => self.sensitivity_pass::<DualSVec64<2>>(theta, 0, 2, out, jacobian),
            3 => self.sensitivity_pass::<DualSVec64<3>>(theta, 0, 3, out, jacobian),
            _ => {
                let mut stats = SolverStats::default();
                for start in (0..n_par).step_by(4) {
                    let width = (n_par - start).min(4);
                    let s =
                        self.sensitivity_pass::<DualSVec64<4>>(theta, start, width, out, jacobian)?;
                    stats.accepted_steps += s.accepted_steps;
                    stats.rejected_steps += s.rejected_steps;
                    stats.rhs_evaluations += s.rhs_evaluations;
                }
                Ok(stats)
            }
        }
    }

    fn sensitivity_pass<D: Seedable>(
        &self,
        theta: &[f64],
        start: usize,
        width: usize,
        out: &mut [f64],
        jacobian: &mut DMatrix<f64>,
    ) -> Result<SolverStats, OdeError> {
        let mut p: Vec<D> = self.nominal.iter().map(|&v| D::from(v)).collect();
        for (k, &slot) in self.calibrated.iter().enumerate() {
            p[slot] = if (start..start + width).contains(&k) {
                D::seeded(theta[k], k - start)
            } else {
                D::from(theta[k])
            };
        }
        let mut values = vec![D::from(0.0); self.n_outputs()];
        let stats = self.run(&p, &mut values)?;
        for (row, v) in values.iter().enumerate() {
            out[row] = v.re();
            for k in 0..width {
                jacobian[(row, start + k)] = v.derivative(k);
            }
        }
        Ok(stats)
    }

    fn run<D: DualNum<Primitive = f64> + Copy>(
        &self,
        p: &[D],
        out: &mut [D],
    ) -> Result<SolverStats, OdeError> {
        let n = self.model.n_states();
        let m = self.times.len();
        let n_channels = self.channels().len();
        if self.model.drive.is_some() {
            return self.model.simulate_drive(p, &mut out[..n_channels * m]);
        }
        let mut y0 = vec![D::from(0.0); n];
        self.model.initial_state(p, &mut y0);
        let mut states = vec![D::from(0.0); n * m];
        let system = self.model.system(p, &self.segments);
        let stats = match system.plain() {
            Ok(plain) => ode::solve(&plain, T0, &y0, &self.times, &self.solver, &mut states)?,
            Err(system) => ode::solve(&system, T0, &y0, &self.times, &self.solver, &mut states)?,
        };
        self.model
            .measure(&self.times, &states, p, &mut out[..n_channels * m]);
        Ok(stats)
    }
}

/// A dual number that can carry the derivative in one of its directions.
trait Seedable: DualNum<Primitive = f64> + Copy {
    fn seeded(value: f64, direction: usize) -> Self;
    fn derivative(&self, direction: usize) -> f64;
}

impl Seedable for Dual64 {
    fn seeded(value: f64, _direction: usize) -> Self {
        Dual64::new(value, 1.0)
    }
    fn derivative(&self, _direction: usize) -> f64 {
        self.eps
    }
}

impl<const N: usize> Seedable for DualSVec64<N> {
    fn seeded(value: f64, direction: usize) -> Self {
        DualSVec64::from_re(value).derivative(direction)
    }
    fn derivative(&self, direction: usize) -> f64 {
        self.eps.0.as_ref().map_or(0.0, |e| e[direction])
    }
}
