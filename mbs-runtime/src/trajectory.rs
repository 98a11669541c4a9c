//! The sampled motion: t, q, qd, qdd (and energy, body poses on request) at the output times,
//! with CSV and JSON writers, and observers that see every output as it is produced.

use crate::model::{Energy, Pose, RotationJoint};
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
    /// input names (`u[k]` or the DSL's), as the model names them; empty for a model without
    /// inputs and for a motion that records none (a measured one)
    #[serde(default)]
    pub input_names: Vec<String>,
    /// the inputs u in force at each output, `input_names.len()` per output: the time
    /// function's value there plus what the sampled controllers hold (at a sample instant,
    /// what they wrote there), so that a run's qdd and λ are those of its q, qd and u
    #[serde(default)]
    pub u_data: Vec<f64>,
    /// the rotation joints (`Tball`, `Tfree`), each named by the frame it moves
    #[serde(default)]
    pub joint_names: Vec<String>,
    /// per output, per rotation joint: its rotation relative to the frame before it, a unit
    /// quaternion `[x, y, z, w]` whose sign is continuous from one output to the next (the
    /// orientation without charts: its angles among q jump where the chart is re-centred)
    #[serde(default)]
    pub orientation_data: Vec<f64>,
    /// per output, per rotation joint: the number of the chart its angles are read in, an
    /// index into `charts[joint]` (0 is the model's chart at the start)
    #[serde(default)]
    pub chart_data: Vec<u32>,
    /// per rotation joint, every chart it has used, in order, as quaternions `[x, y, z, w]`
    #[serde(default)]
    pub charts: Vec<Vec<[f64; 4]>>,
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

/// The length of a measured state ([`Trajectory::measured_states`]) of a model with `nq`
/// coordinates and `joints` rotation joints (`Tball`, `Tfree`): q then qd, each joint's
/// angles as the 9 entries of its rotation and its rates as its angular velocity in its own
/// axes, in place of its first angle and first rate.
pub fn state_size(nq: usize, joints: usize) -> usize {
    2 * nq + 6 * joints
}

impl Trajectory {
    /// The state a run is measured by at every output (work–precision studies, global error
    /// control): (q, qd), each rotation joint's three angles replaced by the nine entries of
    /// its rotation (row-major) and its three rates by its angular velocity in its own axes,
    /// which do not depend on the chart the angles are read in ([`state_size`] numbers).
    /// `joints` beyond the trajectory's own rotation joints are Euler angles read with the
    /// identity chart.
    pub fn measured_states(&self, joints: &[RotationJoint]) -> Vec<Vec<f64>> {
        (0..self.len())
            .map(|i| {
                let (q, qd) = (self.q(i), self.qd(i));
                if joints.is_empty() {
                    return q.iter().chain(qd).copied().collect();
                }
                let mut y = Vec::with_capacity(state_size(q.len(), joints.len()));
                let angle = |k: usize| joints.iter().position(|j| j.angles.contains(&k));
                for k in 0..q.len() {
                    match angle(k) {
                        Some(j) if joints[j].angles[0] == k => {
                            // Euler angles of a model without charts: the identity
                            let chart = if j < self.joint_names.len() {
                                self.chart(i, j)
                            } else {
                                crate::IDENTITY3
                            };
                            let r = crate::charts::joint_rotation(&chart, &joints[j], q);
                            let m = r.to_rotation_matrix();
                            y.extend((0..9).map(|e| m[(e / 3, e % 3)]));
                        }
                        Some(_) => {}
                        None => y.push(q[k]),
                    }
                }
                for k in 0..q.len() {
                    match angle(k) {
                        Some(j) if joints[j].angles[0] == k => {
                            let [a, b, c] = joints[j].angles;
                            y.extend(crate::charts::body_rates(
                                [q[a], q[b], q[c]],
                                [qd[a], qd[b], qd[c]],
                            ));
                        }
                        Some(_) => {}
                        None => y.push(qd[k]),
                    }
                }
                y
            })
            .collect()
    }

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

    /// Checks that the data fit a model of `nq` coordinates and `joints` rotation joints
    /// before they are read as its motion (a trajectory built by hand from measurements, or
    /// read from a file): `nq` names, q, qd and qdd one value per coordinate per output, and
    /// the charts of at most `joints` rotation joints (none: each output is read in the
    /// model's charts), each output's chart numbers among them.
    pub fn check_fits(&self, nq: usize, joints: usize) -> Result<(), crate::error::Failure> {
        use crate::error::Failure::InvalidOption;
        let outputs = self.len();
        if self.nq() != nq {
            return Err(InvalidOption {
                name: "trajectory.dof_names",
                value: format!("{} names for a model of {nq} coordinates", self.nq()),
                reason: "must name every coordinate of the model, in its order",
            });
        }
        for (name, data) in [
            ("trajectory.q_data", &self.q_data),
            ("trajectory.qd_data", &self.qd_data),
            ("trajectory.qdd_data", &self.qdd_data),
        ] {
            if data.len() != outputs * nq {
                return Err(InvalidOption {
                    name,
                    value: format!(
                        "{} values for {outputs} outputs (t) of {nq} coordinates",
                        data.len()
                    ),
                    reason: "must hold one value per coordinate per output, output after output",
                });
            }
        }
        let tj = self.joint_names.len();
        if tj > joints {
            return Err(InvalidOption {
                name: "trajectory.joint_names",
                value: format!("{tj} rotation joints for a model of {joints}"),
                reason: "must name at most the model's rotation joints (none: the model's charts)",
            });
        }
        let nu = self.input_names.len();
        if self.u_data.len() != outputs * nu {
            return Err(InvalidOption {
                name: "trajectory.u_data",
                value: format!(
                    "{} values for {outputs} outputs of {nu} inputs",
                    self.u_data.len()
                ),
                reason: "must hold one value per input named in `input_names` per output (none when it names none)",
            });
        }
        if self.charts.len() != tj || self.chart_data.len() != outputs * tj {
            return Err(InvalidOption {
                name: "trajectory.chart_data",
                value: format!(
                    "{} chart lists and {} chart numbers for {tj} joints over {outputs} outputs",
                    self.charts.len(),
                    self.chart_data.len()
                ),
                reason: "must hold one chart list per joint and one chart number per joint per output",
            });
        }
        let out_of_range = self
            .chart_data
            .iter()
            .enumerate()
            .any(|(k, &c)| c as usize >= self.charts[k % tj].len());
        if out_of_range {
            return Err(InvalidOption {
                name: "trajectory.chart_data",
                value: "a chart number beyond its joint's list".into(),
                reason: "each chart number must index its joint's list in `charts`",
            });
        }
        Ok(())
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

    /// The inputs u at output `i` (one per name of `input_names`: none when the motion
    /// records no inputs).
    pub fn u(&self, i: usize) -> &[f64] {
        let n = self.input_names.len();
        &self.u_data[i * n..(i + 1) * n]
    }

    /// The multiplier of the constraint named `name` at every output (`None` if no such
    /// constraint).
    pub fn constraint_force(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.constraint_names.iter().position(|c| c == name)?;
        Some((0..self.len()).map(|i| self.lambda(i)[k]).collect())
    }

    /// The rotation of every rotation joint at output `i`, 4 numbers `[x, y, z, w]` each.
    pub fn orientation(&self, i: usize) -> &[f64] {
        let n = 4 * self.joint_names.len();
        &self.orientation_data[i * n..(i + 1) * n]
    }

    /// The chart of rotation joint `joint` at output `i` as a rotation matrix (rows): the
    /// rotation its angles are measured from, `R = chart · Rz(a) · Ry(b) · Rx(c)`.
    pub fn chart(&self, i: usize, joint: usize) -> [[f64; 3]; 3] {
        let k = self.chart_data[i * self.joint_names.len() + joint] as usize;
        crate::charts::matrix_of(self.charts[joint][k])
    }

    /// The chart numbers of every rotation joint at output `i` (indices into `charts`).
    pub fn chart_numbers(&self, i: usize) -> &[u32] {
        let n = self.joint_names.len();
        &self.chart_data[i * n..(i + 1) * n]
    }

    /// Records the rotation joints of the output just pushed: their orientations (4 numbers
    /// each) and chart numbers.
    pub(crate) fn push_joints(&mut self, orientation: &[f64], charts: &[u32]) {
        self.orientation_data.extend_from_slice(orientation);
        self.chart_data.extend_from_slice(charts);
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

    /// The bytes one output takes (t, q, q̇, q̈, λ, u, the rotation joints' orientations and
    /// charts, and energy and poses when recorded).
    pub(crate) fn bytes_per_output(&self, energy: bool, frames: bool) -> usize {
        let (n, nc, nu, joints) = (
            self.nq(),
            self.constraint_names.len(),
            self.input_names.len(),
            self.joint_names.len(),
        );
        let f64s = 1 + 3 * n + nc + nu + 4 * joints;
        let mut bytes = 8 * f64s + 4 * joints;
        if energy {
            bytes += std::mem::size_of::<Energy>();
        }
        if frames {
            bytes += self.frame_names.len() * std::mem::size_of::<Pose>();
        }
        bytes
    }

    /// Reserves room for `outputs` more outputs; an error when the memory they need cannot
    /// be had (nothing is reserved then beyond what was).
    pub(crate) fn reserve(
        &mut self,
        outputs: usize,
        energy: bool,
        frames: bool,
    ) -> Result<(), std::collections::TryReserveError> {
        let n = self.nq();
        let joints = self.joint_names.len();
        let times = |k: usize| outputs.saturating_mul(k);
        self.t.try_reserve(outputs)?;
        self.q_data.try_reserve(times(n))?;
        self.qd_data.try_reserve(times(n))?;
        self.qdd_data.try_reserve(times(n))?;
        self.lambda_data
            .try_reserve(times(self.constraint_names.len()))?;
        self.u_data.try_reserve(times(self.input_names.len()))?;
        self.orientation_data.try_reserve(times(4 * joints))?;
        self.chart_data.try_reserve(times(joints))?;
        for charts in self.charts.iter_mut() {
            // re-centrings are rare: room for 16 before the list grows
            charts.try_reserve(16)?;
        }
        if energy {
            self.energy.try_reserve(outputs)?;
        }
        if frames {
            self.poses.try_reserve(times(self.frame_names.len()))?;
        }
        Ok(())
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
    /// interpolated ones between them otherwise; each output read in the charts the run read
    /// it in (on a copy of `model`).
    pub fn constraint_residual<M: crate::model::Model + Clone>(&self, model: &M) -> f64 {
        let mut phi = vec![0.0; M::NC];
        let mut worst = 0.0f64;
        let mut model = model.clone();
        for i in 0..self.len() {
            crate::charts::use_charts_of(&mut model, self, i);
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

    /// [`Trajectory::energy_drift`] relative to max(|E(t0)|, max kinetic energy), the scale of
    /// the motion's energies (`None` when energy was not recorded).
    pub fn relative_energy_drift(&self) -> Option<f64> {
        let drift = self.energy_drift()?;
        let scale = self
            .energy
            .iter()
            .map(|e| e.kinetic.abs())
            .fold(self.energy.first()?.total().abs(), f64::max);
        Some(if scale > 0.0 { drift / scale } else { drift })
    }

    /// CSV with a header of named columns: `t`, then per coordinate its name (`q[0]`, or the
    /// DSL name such as `knee`), then `qd[…]` and `qdd[…]` per coordinate as the DSL writes
    /// them (`qd[0]`, `qd[knee]`), then `NAME.lambda` per constraint, then the inputs by
    /// their names (`u[0]`, or the DSL's) when the run recorded them, then per rotation joint
    /// `FRAME.qx, FRAME.qy, FRAME.qz, FRAME.qw` (its rotation, a quaternion continuous
    /// across re-centrings) and `FRAME.chart` (the chart number), then `kinetic, potential,
    /// total` when energy was recorded. [`CsvWriter`] writes the same file as outputs come.
    pub fn write_csv(&self, w: impl Write) -> io::Result<()> {
        let mut csv = CsvWriter::new(w);
        csv.write(self)?;
        csv.finish(self).map(|_| ())
    }

    /// Forgets every output, keeping the names (and the memory reserved for outputs).
    pub fn clear_outputs(&mut self) {
        self.t.clear();
        self.q_data.clear();
        self.qd_data.clear();
        self.qdd_data.clear();
        self.lambda_data.clear();
        self.u_data.clear();
        self.orientation_data.clear();
        self.chart_data.clear();
        self.energy.clear();
        self.poses.clear();
    }

    /// Appends output `i` of `from` (a trajectory of the same model): t, q, qd, qdd, λ, u, and
    /// energy and poses when `from` recorded them.
    pub fn push_output(&mut self, from: &Trajectory, i: usize) {
        self.push(
            from.t[i],
            from.q(i),
            from.qd(i),
            from.qdd(i),
            from.lambda(i),
        );
        self.u_data.extend_from_slice(from.u(i));
        if !from.joint_names.is_empty() {
            self.push_joints(from.orientation(i), from.chart_numbers(i));
            // the charts the output's numbers index: `from`'s, when it has more joints or
            // more charts of a joint (a chart added since the last output pushed)
            let fewer = self.charts.len() < from.charts.len()
                || (self.charts.iter())
                    .zip(&from.charts)
                    .any(|(mine, theirs)| mine.len() < theirs.len());
            if fewer {
                self.charts = from.charts.clone();
            }
        }
        if from.energy.len() == from.len() {
            self.energy.push(from.energy[i]);
        }
        let poses = from.poses_at(i);
        if !poses.is_empty() {
            self.poses.extend_from_slice(poses);
        }
    }

    /// The whole trajectory as JSON.
    pub fn write_json(&self, w: impl Write) -> io::Result<()> {
        serde_json::to_writer(w, self).map_err(io::Error::other)
    }
}

/// Writes a trajectory's CSV ([`Trajectory::write_csv`]'s columns) as its outputs come: give
/// it the outputs recorded so far, forget them, give it the next ones. The header is written
/// with the first outputs; energy columns are there when those outputs carry energy.
pub struct CsvWriter<W: Write> {
    w: W,
    /// whether the header is written, and with energy columns
    header: Option<bool>,
    rows: usize,
}

impl<W: Write> CsvWriter<W> {
    pub fn new(w: W) -> CsvWriter<W> {
        CsvWriter {
            w,
            header: None,
            rows: 0,
        }
    }

    /// Rows written so far.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Writes every output of `tr` (the header first, on the first call).
    pub fn write(&mut self, tr: &Trajectory) -> io::Result<()> {
        let with_energy = match self.header {
            Some(e) => e,
            // the columns are known with the first outputs
            None if tr.is_empty() => return Ok(()),
            None => {
                let e = tr.energy.len() == tr.len();
                self.write_header(tr, e)?;
                e
            }
        };
        let w = &mut self.w;
        for i in 0..tr.len() {
            write!(w, "{:e}", tr.t[i])?;
            for v in tr
                .q(i)
                .iter()
                .chain(tr.qd(i))
                .chain(tr.qdd(i))
                .chain(tr.lambda(i))
                .chain(tr.u(i))
            {
                write!(w, ",{v:e}")?;
            }
            for (o, c) in tr.orientation(i).chunks(4).zip(tr.chart_numbers(i)) {
                write!(w, ",{:e},{:e},{:e},{:e},{c}", o[0], o[1], o[2], o[3])?;
            }
            if with_energy {
                let e = tr.energy.get(i).copied().unwrap_or(Energy {
                    kinetic: f64::NAN,
                    potential: f64::NAN,
                });
                write!(w, ",{:e},{:e},{:e}", e.kinetic, e.potential, e.total())?;
            }
            writeln!(w)?;
        }
        self.rows += tr.len();
        Ok(())
    }

    /// Flushes the file (writing the header alone if no output came; `names` gives the
    /// columns) and hands back the writer.
    pub fn finish(mut self, names: &Trajectory) -> io::Result<W> {
        if self.header.is_none() {
            self.write_header(names, false)?;
        }
        self.w.flush()?;
        Ok(self.w)
    }

    fn write_header(&mut self, tr: &Trajectory, with_energy: bool) -> io::Result<()> {
        let mut header = vec!["t".to_string()];
        header.extend(tr.dof_names.iter().cloned());
        for prefix in ["qd", "qdd"] {
            for name in &tr.dof_names {
                // `q[0]` → `qd[0]`, `knee` → `qd[knee]`: as the DSL writes them
                let index = name
                    .strip_prefix("q[")
                    .and_then(|r| r.strip_suffix(']'))
                    .unwrap_or(name);
                header.push(format!("{prefix}[{index}]"));
            }
        }
        for name in &tr.constraint_names {
            header.push(format!("{name}.lambda"));
        }
        header.extend(tr.input_names.iter().cloned());
        for name in &tr.joint_names {
            for c in ["qx", "qy", "qz", "qw", "chart"] {
                header.push(format!("{name}.{c}"));
            }
        }
        if with_energy {
            header.extend(["kinetic", "potential", "total"].map(String::from));
        }
        let line: Vec<String> = header.iter().map(|h| csv_field(h)).collect();
        writeln!(self.w, "{}", line.join(","))?;
        self.header = Some(with_energy);
        Ok(())
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
            "t,q[0],knee,qd[0],qd[knee],qdd[0],qdd[knee],pin.lambda,kinetic,potential,total"
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

    #[test]
    fn csv_written_as_outputs_come_is_the_whole_file() {
        let mut whole = Trajectory::new(vec!["q[0]".into()], vec![], vec![]);
        let mut csv = CsvWriter::new(Vec::new());
        let mut chunk = whole.clone();
        // nothing yet: the header waits for the first outputs
        csv.write(&chunk).unwrap();
        for k in 0..5 {
            let t = k as f64 * 0.1;
            let e = Energy {
                kinetic: t,
                potential: 1.0,
            };
            for tr in [&mut whole, &mut chunk] {
                tr.push(t, &[t], &[1.0], &[0.0], &[]);
                tr.energy.push(e);
            }
            if k % 2 == 1 {
                csv.write(&chunk).unwrap();
                chunk.clear_outputs();
            }
        }
        csv.write(&chunk).unwrap();
        assert_eq!(csv.rows(), 5);
        let streamed = csv.finish(&whole).unwrap();
        let mut at_once = Vec::new();
        whole.write_csv(&mut at_once).unwrap();
        assert_eq!(
            String::from_utf8(streamed).unwrap(),
            String::from_utf8(at_once).unwrap()
        );
        // a trajectory without outputs still has its header
        let mut empty = Vec::new();
        Trajectory::new(vec!["q[0]".into()], vec![], vec![])
            .write_csv(&mut empty)
            .unwrap();
        assert_eq!(String::from_utf8(empty).unwrap(), "t,q[0],qd[0],qdd[0]\n");
    }
}
