//! Inverse dynamics along a motion: the generalised forces τ(t) = M qdd − h that make a model
//! follow a given q(t), qd(t), qdd(t) — e.g. the joint torques that drive an arm along a path.

use super::AnalysisError;
use super::statics::check;
use crate::error::Failure;
use crate::model::Model;
use crate::trajectory::Trajectory;
use serde::Serialize;
use std::io::{self, Write};

/// Generalised forces along a motion: `tau` holds one row of NQ values per time.
#[derive(Clone, Debug, Serialize)]
pub struct Efforts {
    pub dof_names: Vec<String>,
    pub t: Vec<f64>,
    pub tau: Vec<f64>,
}

impl Efforts {
    /// τ at time index `i`.
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
    let n = M::NQ;
    if u.len() != M::NU {
        return Err(Failure::InvalidOption {
            name: "u",
            value: u.len().to_string(),
            reason: "must have one value per input",
        }
        .into());
    }
    let info = model.info();
    let mut tau = Vec::with_capacity(n * times.len());
    let mut row = vec![0.0; n];
    for &t in times {
        let (q, qd, qdd) = path(t);
        if q.len() != n || qd.len() != n || qdd.len() != n {
            return Err(Failure::InvalidOption {
                name: "path",
                value: t.to_string(),
                reason: "must give q, qd and qdd with one value per coordinate",
            }
            .into());
        }
        for v in [&q, &qd, &qdd] {
            check(model, "path", v)?;
        }
        model.inverse_dynamics(t, &q, &qd, &qdd, u, &mut row);
        check(model, "τ", &row)?;
        tau.extend_from_slice(&row);
    }
    Ok(Efforts {
        dof_names: (0..n).map(|i| info.dof_label(i)).collect(),
        t: times.to_vec(),
        tau,
    })
}

/// τ along a recorded trajectory (its t, q, qd, qdd), e.g. to check that a simulation needed
/// no actuation, or to drive a model along a measured motion.
pub fn inverse_dynamics_of<M: Model>(
    model: &M,
    trajectory: &Trajectory,
    u: &[f64],
) -> Result<Efforts, AnalysisError> {
    let mut i = 0;
    inverse_dynamics_along(model, &trajectory.t, u, |_| {
        let s = (
            trajectory.q(i).to_vec(),
            trajectory.qd(i).to_vec(),
            trajectory.qdd(i).to_vec(),
        );
        i += 1;
        s
    })
}
