//! The sampled motion: t, q, qd, qdd (and energy, body poses on request) at the output times,
//! with CSV and JSON writers, and observers that see every output as it is produced.

use crate::model::{Energy, Pose};
use serde::{Deserialize, Serialize};
use std::io::{self, Write};

/// Outputs of a simulation. Per-output vectors are stored row after row: output `i` of `q` is
/// `q[i*nq..(i+1)*nq]` (see [`Trajectory::q`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Trajectory {
    /// coordinate names, as in the model (`q[3]` or the DSL name)
    pub dof_names: Vec<String>,
    /// body and frame names (poses are recorded only on request)
    pub frame_names: Vec<String>,
    /// constraint names (`pin.x`, …), one λ each
    #[serde(default)]
    pub constraint_names: Vec<String>,
    pub t: Vec<f64>,
    pub q_data: Vec<f64>,
    pub qd_data: Vec<f64>,
    pub qdd_data: Vec<f64>,
    /// Lagrange multipliers, `constraint_names.len()` per output: λ_i is the generalised
    /// force Bᵢᵀλ_i's magnitude; for `coincide(a, b, along = [x])` it is the force along x
    /// that the closure applies to b (−λ to a), for a scalar constraint the multiplier of
    /// its gradient
    #[serde(default)]
    pub lambda_data: Vec<f64>,
    /// energy at each output (empty when not recorded)
    pub energy: Vec<Energy>,
    /// poses of every frame at each output (empty when not recorded)
    pub poses: Vec<Pose>,
}

/// Sees every output as it is recorded (streaming: plots, files, controllers).
pub trait Observer {
    fn observe(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64]);
}

impl<F: FnMut(f64, &[f64], &[f64], &[f64])> Observer for F {
    fn observe(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64]) {
        self(t, q, qd, qdd)
    }
}

impl Trajectory {
    pub(crate) fn new(
        dof_names: Vec<String>,
        frame_names: Vec<String>,
        constraint_names: Vec<String>,
    ) -> Trajectory {
        Trajectory {
            dof_names,
            frame_names,
            constraint_names,
            ..Trajectory::default()
        }
    }

    /// Number of outputs.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Number of coordinates.
    pub fn nq(&self) -> usize {
        self.dof_names.len()
    }

    /// q at output `i` (nq values).
    pub fn q(&self, i: usize) -> &[f64] {
        let n = self.nq();
        &self.q_data[i * n..(i + 1) * n]
    }

    /// qd at output `i`.
    pub fn qd(&self, i: usize) -> &[f64] {
        let n = self.nq();
        &self.qd_data[i * n..(i + 1) * n]
    }

    /// qdd at output `i`.
    pub fn qdd(&self, i: usize) -> &[f64] {
        let n = self.nq();
        &self.qdd_data[i * n..(i + 1) * n]
    }

    /// λ at output `i` (one per constraint).
    pub fn lambda(&self, i: usize) -> &[f64] {
        let n = self.constraint_names.len();
        &self.lambda_data[i * n..(i + 1) * n]
    }

    /// The multiplier of the constraint named `name` at every output (`None` if no such
    /// constraint).
    pub fn constraint_force(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.constraint_names.iter().position(|c| c == name)?;
        Some((0..self.len()).map(|i| self.lambda(i)[k]).collect())
    }

    /// Poses of every frame at output `i` (empty unless recorded).
    pub fn poses_at(&self, i: usize) -> &[Pose] {
        let n = self.frame_names.len();
        if self.poses.len() < (i + 1) * n {
            &[]
        } else {
            &self.poses[i * n..(i + 1) * n]
        }
    }

    /// Reserves room for `outputs` more outputs.
    pub(crate) fn reserve(&mut self, outputs: usize, energy: bool, frames: bool) {
        let n = self.nq();
        self.t.reserve(outputs);
        self.q_data.reserve(outputs * n);
        self.qd_data.reserve(outputs * n);
        self.qdd_data.reserve(outputs * n);
        self.lambda_data
            .reserve(outputs * self.constraint_names.len());
        if energy {
            self.energy.reserve(outputs);
        }
        if frames {
            self.poses.reserve(outputs * self.frame_names.len());
        }
    }

    pub(crate) fn push(&mut self, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], lambda: &[f64]) {
        self.t.push(t);
        self.q_data.extend_from_slice(q);
        self.qd_data.extend_from_slice(qd);
        self.qdd_data.extend_from_slice(qdd);
        self.lambda_data.extend_from_slice(lambda);
    }

    /// Largest |Φ_i(t, q)| of `model`'s constraints over the outputs (0 without constraints):
    /// the drift of a run, on the integrator's own states with `Output::Steps`, on
    /// interpolated ones between them otherwise.
    pub fn constraint_residual<M: crate::model::Model>(&self, model: &M) -> f64 {
        let mut phi = vec![0.0; M::NC];
        let mut worst = 0.0f64;
        for i in 0..self.len() {
            model.constraints(self.t[i], self.q(i), &mut phi);
            worst = phi.iter().fold(worst, |w, p| w.max(p.abs()));
        }
        worst
    }

    /// Energy drift: max |E(t) − E(t0)| over the outputs (`None` when energy was not recorded).
    pub fn energy_drift(&self) -> Option<f64> {
        let e0 = self.energy.first()?.total();
        Some(
            self.energy
                .iter()
                .map(|e| (e.total() - e0).abs())
                .fold(0.0, f64::max),
        )
    }

    /// CSV with a header of named columns: `t`, then `q[…]`, `qd[…]`, `qdd[…]` per coordinate,
    /// then `NAME.lambda` per constraint, then `kinetic, potential, total` when energy was
    /// recorded.
    pub fn write_csv(&self, mut w: impl Write) -> io::Result<()> {
        let mut header = vec!["t".to_string()];
        for prefix in ["", "d", "dd"] {
            for name in &self.dof_names {
                header.push(if prefix.is_empty() {
                    name.clone()
                } else {
                    format!("{name}.{prefix}")
                });
            }
        }
        for name in &self.constraint_names {
            header.push(format!("{name}.lambda"));
        }
        let with_energy = self.energy.len() == self.len() && !self.is_empty();
        if with_energy {
            header.extend(["kinetic", "potential", "total"].map(String::from));
        }
        writeln!(
            w,
            "{}",
            header
                .iter()
                .map(|h| csv_field(h))
                .collect::<Vec<_>>()
                .join(",")
        )?;
        for i in 0..self.len() {
            write!(w, "{:e}", self.t[i])?;
            for v in self
                .q(i)
                .iter()
                .chain(self.qd(i))
                .chain(self.qdd(i))
                .chain(self.lambda(i))
            {
                write!(w, ",{v:e}")?;
            }
            if with_energy {
                let e = self.energy[i];
                write!(w, ",{:e},{:e},{:e}", e.kinetic, e.potential, e.total())?;
            }
            writeln!(w)?;
        }
        Ok(())
    }

    /// The whole trajectory as JSON.
    pub fn write_json(&self, w: impl Write) -> io::Result<()> {
        serde_json::to_writer(w, self).map_err(io::Error::other)
    }
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_has_named_columns_and_one_row_per_output() {
        let mut t = Trajectory::new(
            vec!["q[0]".into(), "knee".into()],
            vec![],
            vec!["pin".into()],
        );
        t.push(0.0, &[1.0, 2.0], &[0.0, 0.5], &[0.1, 0.2], &[3.0]);
        t.push(0.5, &[1.5, 2.5], &[1.0, 0.5], &[0.1, 0.2], &[4.0]);
        t.energy = vec![
            Energy {
                kinetic: 1.0,
                potential: 2.0
            };
            2
        ];
        let mut out = Vec::new();
        t.write_csv(&mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[0],
            "t,q[0],knee,q[0].d,knee.d,q[0].dd,knee.dd,pin.lambda,kinetic,potential,total"
        );
        assert_eq!(lines.len(), 3);
        assert_eq!(lines[2].split(',').count(), 11);
        assert_eq!(t.constraint_force("pin"), Some(vec![3.0, 4.0]));
        let mut json = Vec::new();
        t.write_json(&mut json).unwrap();
        let back: Trajectory = serde_json::from_slice(&json).unwrap();
        assert_eq!(back, t);
        assert_eq!(t.energy_drift(), Some(0.0));
    }
}
