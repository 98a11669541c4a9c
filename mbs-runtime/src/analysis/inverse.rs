//! Inverse dynamics along a motion: the generalised forces τ(t) = M qdd − h that make a model
//! follow a given q(t), qd(t), qdd(t) — e.g. the joint torques that drive an arm along a path.
//!
//! For a constrained model (`M qdd = h + Bᵀλ + S τ_a`, `Φ = 0`), only some coordinates are
//! actuated: [`inverse_dynamics_actuated_along`] solves `S τ_a + Bᵀλ = M qdd − h` for the
//! actuator efforts τ_a and the multipliers λ at each time, S selecting the actuated
//! coordinates. The system is square when #actuated + NC = NQ, and regular when B has full
//! rank and B over the unactuated coordinates is invertible (the actuators can drive the
//! mechanism there). Exact: one LU of [S Bᵀ] per time, no differences. The motion should be
//! consistent (Φ = 0, Φ̇ = 0, B qdd = γ); the largest violations are reported per time, not
//! refused.

use super::{AnalysisError, Computed, check, reduce};
use crate::error::Failure;
use crate::linalg::Lu;
use crate::model::Model;
use crate::trajectory::Trajectory;
use serde::Serialize;
use std::io::{self, Write};

/// Generalised forces along a motion: `tau` holds one row of NQ values per time.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Efforts {
    pub dof_names: Vec<String>,
    pub t: Vec<f64>,
    pub tau: Vec<f64>,
}

impl Efforts {
    /// τ at time index `i` (panics beyond `t.len()`, as a slice does).
    pub fn at(&self, i: usize) -> &[f64] {
        let n = self.dof_names.len();
        &self.tau[i * n..(i + 1) * n]
    }

    /// CSV: `t` then one column per coordinate.
    pub fn write_csv(&self, mut w: impl Write) -> io::Result<()> {
        writeln!(w, "t,{}", self.dof_names.join(","))?;
        for i in 0..self.t.len() {
            write!(w, "{:e}", self.t[i])?;
            for v in self.at(i) {
                write!(w, ",{v:e}")?;
            }
            writeln!(w)?;
        }
        Ok(())
    }
}

/// τ along the motion `path(t) → (q, qd, qdd)` sampled at `times`, with inputs `u`.
pub fn inverse_dynamics_along<M: Model>(
    model: &M,
    times: &[f64],
    u: &[f64],
    mut path: impl FnMut(f64) -> (Vec<f64>, Vec<f64>, Vec<f64>),
) -> Result<Efforts, AnalysisError> {
    fixed_inputs::<M>(u)?;
    let mut out = efforts(model, times.len());
    let mut row = vec![0.0; M::NQ];
    for (i, &t) in times.iter().enumerate() {
        let (q, qd, qdd) = path(t);
        if let Err(e) = tau_at(model, t, [&q, &qd, &qdd], u, &mut row) {
            return Err(stopped(i, t, e, Computed::Efforts(out)));
        }
        out.t.push(t);
        out.tau.extend_from_slice(&row);
    }
    Ok(out)
}

/// τ along a recorded trajectory (its t, q, qd, qdd), e.g. to check that a simulation needed
/// no actuation, or to drive a model along a measured motion. Each output is read in the
/// charts the run read it in ([`crate::charts::use_charts_of`], on a copy of `model`).
///
/// `u`: one value per input, the inputs at every output; or none (`&[]`), the inputs the
/// trajectory recorded at each output (a run records them: what its controllers and input
/// function gave at that time), so that τ is what the motion needed beyond them.
pub fn inverse_dynamics_of<M: Model + Clone>(
    model: &M,
    trajectory: &Trajectory,
    u: &[f64],
) -> Result<Efforts, AnalysisError> {
    fits(model, trajectory)?;
    let given = given_inputs::<M>(trajectory, u)?;
    let mut out = efforts(model, trajectory.len());
    let mut read = model.clone();
    let mut row = vec![0.0; M::NQ];
    for i in 0..trajectory.len() {
        crate::charts::use_charts_of(&mut read, trajectory, i);
        let t = trajectory.t[i];
        if let Err(e) = tau_at(&read, t, state(trajectory, i), given(i), &mut row) {
            return Err(stopped(i, t, e, Computed::Efforts(out)));
        }
        out.t.push(t);
        out.tau.extend_from_slice(&row);
    }
    Ok(out)
}

/// The failure `cause` at time `index` (t) of a motion, with the rows computed before it.
fn stopped(index: usize, t: f64, cause: AnalysisError, computed: Computed) -> AnalysisError {
    AnalysisError::AlongMotion {
        index,
        t,
        cause: Box::new(cause),
        computed: Box::new(computed),
    }
}

/// Whether `trajectory`'s data fit `model` ([`Trajectory::check_fits`]).
fn fits<M: Model>(model: &M, trajectory: &Trajectory) -> Result<(), AnalysisError> {
    let joints = model.info().rotation_joints.len();
    Ok(trajectory.check_fits(M::NQ, joints)?)
}

/// The inputs at each output of `trajectory`: `u` when it gives one value per input, the
/// trajectory's own when it gives none and the trajectory recorded the model's inputs.
fn given_inputs<'a, M: Model>(
    trajectory: &'a Trajectory,
    u: &'a [f64],
) -> Result<impl Fn(usize) -> &'a [f64], AnalysisError> {
    let recorded = u.is_empty() && M::NU > 0;
    if recorded && trajectory.input_names.len() != M::NU {
        return Err(Failure::InvalidOption {
            name: "u",
            value: format!(
                "none, and the trajectory records {} inputs for a model of {}",
                trajectory.input_names.len(),
                M::NU
            ),
            reason: "give the inputs, one value per input of the model, or a trajectory that records them (a run's)",
        }
        .into());
    }
    if !recorded {
        fixed_inputs::<M>(u)?;
    }
    Ok(move |i: usize| if recorded { trajectory.u(i) } else { u })
}

/// Output `i` of `trajectory`: [q, qd, qdd].
fn state(trajectory: &Trajectory, i: usize) -> [&[f64]; 3] {
    [trajectory.q(i), trajectory.qd(i), trajectory.qdd(i)]
}

/// Inputs `u` given for every time: one value per input of the model.
fn fixed_inputs<M: Model>(u: &[f64]) -> Result<(), AnalysisError> {
    if u.len() != M::NU {
        return Err(Failure::InvalidOption {
            name: "u",
            value: u.len().to_string(),
            reason: "must have one value per input",
        }
        .into());
    }
    Ok(())
}

/// No efforts yet, room for `times` times.
fn efforts<M: Model>(model: &M, times: usize) -> Efforts {
    let n = M::NQ;
    let info = model.info();
    Efforts {
        dof_names: (0..n).map(|i| info.dof_label(i)).collect(),
        t: Vec::with_capacity(times),
        tau: Vec::with_capacity(n * times),
    }
}

/// τ at one time of a motion into `row`, the state and τ checked.
fn tau_at<M: Model>(
    model: &M,
    t: f64,
    state: [&[f64]; 3],
    u: &[f64],
    row: &mut [f64],
) -> Result<(), AnalysisError> {
    check_state::<M>(model, t, state)?;
    let [q, qd, qdd] = state;
    model.inverse_dynamics(t, q, qd, qdd, u, row);
    check(model, "τ", row)
}

/// One value per coordinate in q, qd and qdd, all finite.
fn check_state<M: Model>(model: &M, t: f64, state: [&[f64]; 3]) -> Result<(), AnalysisError> {
    if state.iter().any(|v| v.len() != M::NQ) {
        return Err(Failure::InvalidOption {
            name: "path",
            value: t.to_string(),
            reason: "must give q, qd and qdd with one value per coordinate",
        }
        .into());
    }
    for (name, v) in ["path's q", "path's qd", "path's qdd"]
        .into_iter()
        .zip(state)
    {
        check(model, name, v)?;
    }
    Ok(())
}

/// Actuator efforts and constraint reactions along a motion of a constrained model
/// ([`inverse_dynamics_actuated_along`]): per time, τ_a (one per actuated coordinate) and λ
/// (one per constraint) with `S τ_a + Bᵀλ = M qdd − h`.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[non_exhaustive]
pub struct ActuatedEfforts {
    /// labels of the actuated coordinates, and their indices in q
    pub actuated: Vec<String>,
    pub actuated_indices: Vec<usize>,
    /// constraint names (`pin.x`, …)
    pub constraint_names: Vec<String>,
    pub t: Vec<f64>,
    /// τ_a, one row of `actuated.len()` values per time (N or N·m: generalised forces)
    pub tau: Vec<f64>,
    /// λ, one row of `constraint_names.len()` values per time (for `coincide(a, b, along =
    /// [x])` the force along x the closure applies to b)
    pub lambda: Vec<f64>,
    /// largest |Φ_i|, |Φ̇_i| = |B qd + ∂Φ/∂t| and |B qdd − γ| per time: how consistent the
    /// given motion is
    pub phi: Vec<f64>,
    pub phi_dot: Vec<f64>,
    pub phi_ddot: Vec<f64>,
}

impl ActuatedEfforts {
    /// τ_a at time index `i` (panics beyond `t.len()`, as a slice does).
    pub fn tau_at(&self, i: usize) -> &[f64] {
        let n = self.actuated.len();
        &self.tau[i * n..(i + 1) * n]
    }

    /// λ at time index `i` (panics beyond `t.len()`, as a slice does).
    pub fn lambda_at(&self, i: usize) -> &[f64] {
        let n = self.constraint_names.len();
        &self.lambda[i * n..(i + 1) * n]
    }

    /// λ of constraint `name` along the motion.
    pub fn lambda_of(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.constraint_names.iter().position(|n| n == name)?;
        Some((0..self.t.len()).map(|i| self.lambda_at(i)[k]).collect())
    }

    /// CSV: `t`, one column per actuated coordinate (its label), `NAME.lambda` per
    /// constraint, then `phi, phi_dot, phi_ddot` (the largest violations).
    pub fn write_csv(&self, mut w: impl Write) -> io::Result<()> {
        let mut header = vec!["t".to_string()];
        header.extend(self.actuated.iter().cloned());
        header.extend(self.constraint_names.iter().map(|n| format!("{n}.lambda")));
        header.extend(["phi".into(), "phi_dot".into(), "phi_ddot".into()]);
        writeln!(w, "{}", header.join(","))?;
        for i in 0..self.t.len() {
            write!(w, "{:e}", self.t[i])?;
            for v in self.tau_at(i).iter().chain(self.lambda_at(i)) {
                write!(w, ",{v:e}")?;
            }
            writeln!(
                w,
                ",{:e},{:e},{:e}",
                self.phi[i], self.phi_dot[i], self.phi_ddot[i]
            )?;
        }
        Ok(())
    }
}

/// Actuator efforts τ_a on the coordinates `actuated` (indices, NQ − NC of them) and the
/// constraint reactions λ along the motion `path(t) → (q, qd, qdd)` sampled at `times`, with
/// inputs `u`: `S τ_a + Bᵀλ = M qdd − h`. Without constraints, with every coordinate
/// actuated, it is [`inverse_dynamics_along`] in the order of `actuated`.
pub fn inverse_dynamics_actuated_along<M: Model>(
    model: &M,
    times: &[f64],
    u: &[f64],
    actuated: &[usize],
    mut path: impl FnMut(f64) -> (Vec<f64>, Vec<f64>, Vec<f64>),
) -> Result<ActuatedEfforts, AnalysisError> {
    fixed_inputs::<M>(u)?;
    let (mut solver, mut out) = Actuation::new(model, actuated, times.len())?;
    for (i, &t) in times.iter().enumerate() {
        let (q, qd, qdd) = path(t);
        if let Err(e) = solver.push(model, t, [&q, &qd, &qdd], u, &mut out) {
            return Err(stopped(i, t, e, Computed::Actuated(out)));
        }
    }
    Ok(out)
}

/// [`inverse_dynamics_actuated_along`] along a recorded trajectory (its t, q, qd, qdd), each
/// output read in the charts the run read it in (on a copy of `model`); `u` as in
/// [`inverse_dynamics_of`]: the inputs at every output, or none for the trajectory's own.
pub fn inverse_dynamics_actuated_of<M: Model + Clone>(
    model: &M,
    trajectory: &Trajectory,
    u: &[f64],
    actuated: &[usize],
) -> Result<ActuatedEfforts, AnalysisError> {
    fits(model, trajectory)?;
    let given = given_inputs::<M>(trajectory, u)?;
    let (mut solver, mut out) = Actuation::new(model, actuated, trajectory.len())?;
    let mut read = model.clone();
    for i in 0..trajectory.len() {
        crate::charts::use_charts_of(&mut read, trajectory, i);
        let t = trajectory.t[i];
        if let Err(e) = solver.push(&read, t, state(trajectory, i), given(i), &mut out) {
            return Err(stopped(i, t, e, Computed::Actuated(out)));
        }
    }
    Ok(out)
}

/// `S τ_a + Bᵀλ = M qdd − h` solved one time after another, with its work space.
struct Actuation<'a> {
    actuated: &'a [usize],
    unactuated: Vec<usize>,
    lu: Lu<f64>,
    tau: Vec<f64>,
    phi: Vec<f64>,
    phi_t: Vec<f64>,
    gamma: Vec<f64>,
}

impl<'a> Actuation<'a> {
    /// Checks `actuated` against `model`; the solver and the efforts, none yet (room for
    /// `times` times).
    fn new<M: Model>(
        model: &M,
        actuated: &'a [usize],
        times: usize,
    ) -> Result<(Actuation<'a>, ActuatedEfforts), AnalysisError> {
        let (n, nc) = (M::NQ, M::NC);
        let info = model.info();
        let invalid = |name: &'static str, value: String, reason: &'static str| {
            AnalysisError::from(Failure::InvalidOption {
                name,
                value,
                reason,
            })
        };
        if let Some(&i) = actuated.iter().find(|&&i| i >= n) {
            return Err(invalid(
                "actuated",
                i.to_string(),
                "is not a coordinate index",
            ));
        }
        if (1..actuated.len()).any(|k| actuated[..k].contains(&actuated[k])) {
            return Err(invalid(
                "actuated",
                format!("{actuated:?}"),
                "names a coordinate twice",
            ));
        }
        if actuated.len() + nc != n {
            return Err(invalid(
                "actuated",
                format!(
                    "{} coordinates ({} constraints, {} coordinates)",
                    actuated.len(),
                    nc,
                    n
                ),
                "the actuated coordinates and the constraints must number NQ together: actuate NQ − NC coordinates (one per degree of freedom)",
            ));
        }
        let na = actuated.len();
        let out = ActuatedEfforts {
            actuated: actuated.iter().map(|&i| info.dof_label(i)).collect(),
            actuated_indices: actuated.to_vec(),
            constraint_names: info.constraints.iter().map(|s| s.to_string()).collect(),
            t: Vec::with_capacity(times),
            tau: Vec::with_capacity(na * times),
            lambda: Vec::with_capacity(nc * times),
            phi: Vec::with_capacity(times),
            phi_dot: Vec::with_capacity(times),
            phi_ddot: Vec::with_capacity(times),
        };
        let solver = Actuation {
            actuated,
            unactuated: (0..n).filter(|i| !actuated.contains(i)).collect(),
            lu: Lu::<f64>::new(n),
            tau: vec![0.0; n],
            phi: vec![0.0; nc],
            phi_t: vec![0.0; nc],
            gamma: vec![0.0; nc],
        };
        Ok((solver, out))
    }

    /// τ_a, λ and the motion's consistency at one time, appended to `out`.
    fn push<M: Model>(
        &mut self,
        model: &M,
        t: f64,
        state: [&[f64]; 3],
        u: &[f64],
        out: &mut ActuatedEfforts,
    ) -> Result<(), AnalysisError> {
        let (n, nc, na) = (M::NQ, M::NC, self.actuated.len());
        let info = model.info();
        let names = info.constraints;
        check_state::<M>(model, t, state)?;
        let [q, qd, qdd] = state;
        model.inverse_dynamics(t, q, qd, qdd, u, &mut self.tau);
        check(model, "τ", &self.tau)?;
        let b = if nc > 0 {
            reduce::jacobian(model, t, q)?
        } else {
            nalgebra::DMatrix::zeros(0, n)
        };
        // [S Bᵀ] (n × n): column k < na is e_actuated[k], column na + i is row i of B
        let a = self.lu.matrix_mut();
        a.fill(0.0);
        for (k, &j) in self.actuated.iter().enumerate() {
            a[j + n * k] = 1.0;
        }
        for i in 0..nc {
            for j in 0..n {
                a[j + n * (na + i)] = b[(i, j)];
            }
        }
        if let Err(s) = self.lu.factor() {
            reduce::rank_check(&b, names)?;
            return Err(Failure::SingularMatrix {
                matrix: "[S Bᵀ]: B over the unactuated coordinates (the actuated coordinates cannot drive the mechanism here)",
                rcond: s.rcond,
                coordinates: self.unactuated.iter().map(|&i| info.dof_label(i)).collect(),
                cause: String::new(),
            }
            .into());
        }
        let mut x = self.tau.clone();
        self.lu.solve(&mut x);
        check(model, "[τ_a, λ]", &x)?;
        out.t.push(t);
        out.tau.extend_from_slice(&x[..na]);
        out.lambda.extend_from_slice(&x[na..]);
        // how consistent the motion is
        let (phi, phi_t, gamma) = (&mut self.phi, &mut self.phi_t, &mut self.gamma);
        if nc > 0 {
            model.constraints(t, q, phi);
            model.constraint_rate(t, q, phi_t);
            model.constraint_bias(t, q, qd, gamma);
        }
        // Φ̇ = B qd + ∂Φ/∂t and Φ̈ = B qdd − γ in place; `reduce::worst` takes a non-finite
        // violation for an infinite one (f64::max would drop a NaN and report 0)
        let row = |i: usize, v: &[f64]| (0..n).map(|j| b[(i, j)] * v[j]).sum::<f64>();
        for i in 0..nc {
            phi_t[i] += row(i, qd);
            gamma[i] = row(i, qdd) - gamma[i];
        }
        out.phi.push(reduce::worst(phi).0);
        out.phi_dot.push(reduce::worst(phi_t).0);
        out.phi_ddot.push(reduce::worst(gamma).0);
        Ok(())
    }
}
