//! Constrained systems `M qdd = h + Bᵀλ`, `Φ(q, t) = 0`, `B = ∂Φ/∂q`: the pieces every
//! constraint method shares, on buffers allocated once.
//!
//! - **Index-1 accelerations** (KKT): with M = L Lᵀ (Cholesky), Y = L⁻¹Bᵀ and the Schur
//!   complement S = B M⁻¹ Bᵀ = YᵀY (positive definite while B has full rank),
//!   λ = S⁻¹(γ − Yᵀ L⁻¹h) and qdd = L⁻ᵀ(L⁻¹h + Yλ), so that B qdd = γ and M qdd = h + Bᵀλ.
//!   Baumgarte replaces γ by γ − 2αΦ̇ − β²Φ.
//! - **Projection** in the metric of M: q ← q − M⁻¹Bᵀ S⁻¹ Φ(q) (Newton, B re-evaluated,
//!   M frozen) until |Φ_i| ≤ tolerance, then qd ← qd − M⁻¹Bᵀ S⁻¹ (B qd + Φ_t): the nearest
//!   consistent state in kinetic-energy distance.
//! - **Coordinate partitioning** (Wehage & Haug 1982): q = (dependent d, independent i); for
//!   given independent q_i, qd_i, Newton on Φ(q) = 0 over q_d with B_d (nc × nc), then
//!   B_d qd_d = −Φ_t − B_i qd_i. The dependent set is the one complete pivoting on B picks;
//!   it is chosen again when the condition of B_d falls ten times below that of the best set.
//! - **Assembly** ([`assemble`]): Newton on Φ(q₀) = 0 moving only the coordinates not marked
//!   `independent` (minimal correction in the metric of M, halved until |Φ| decreases), with
//!   a branch check: the sign of det B over a square set of dependent coordinates must not
//!   change, since two assembly branches are separated by singular configurations; then the
//!   velocity projection with the marked velocities kept. The residuals before and after are
//!   reported in [`Assembly`].

use super::State;
use super::at::At;
use crate::erased::ErasedModel;
use crate::error::{Failure, LoopMatrix};
use crate::linalg::{Lu, Singular, backward, cholesky, cholesky_solve, forward, norm1};
use crate::options::ConstraintOptions;
use crate::stats::Stats;
use serde::Serialize;
use std::fmt;

/// How a run treats the constraints (the resolved [`crate::ConstraintMethod`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Mode {
    Index3,
    /// stabilized index 2 (Gear–Gupta–Leimkuhler), solved by the scheme itself
    Index2,
    Baumgarte {
        alpha: f64,
        beta: f64,
    },
    Projection,
    Partitioning,
}

impl Mode {
    /// The scheme integrates the ODE qdd = f(t, q, qd) of the index-1 form (all but index 3).
    pub fn is_ode(&self) -> bool {
        !matches!(self, Mode::Index3 | Mode::Index2)
    }
}

pub(crate) struct Constrained {
    pub mode: Mode,
    n: usize,
    pub nc: usize,
    names: Vec<String>,
    dof_labels: Vec<String>,
    pub tol: f64,
    /// index 3: scale the constraint rows of the iteration matrix
    pub scaling: bool,
    drift_tol: f64,
    max_iterations: usize,
    pub phi: Vec<f64>,
    /// B (nc × n, column-major)
    pub b: Vec<f64>,
    pub phi_t: Vec<f64>,
    pub gamma: Vec<f64>,
    /// λ of the last index-1 solve
    pub lambda: Vec<f64>,
    /// Y = L⁻¹Bᵀ (n × nc) and the Cholesky factor of S = YᵀY (nc × nc)
    y: Vec<f64>,
    s: Vec<f64>,
    w: Vec<f64>,
    r: Vec<f64>,
    /// partitioning: dependent and independent coordinates, B_d's LU, completed q and qd
    pub dep: Vec<usize>,
    pub ind: Vec<usize>,
    lu_d: Lu<f64>,
    pivot: Vec<f64>,
    used: Vec<bool>,
    /// the rows complete pivoting has taken (one flag per constraint)
    rows_used: Vec<bool>,
    best: Vec<usize>,
    pub qc: Vec<f64>,
    pub vc: Vec<f64>,
    /// scratch of `rate_jacobian`: q perturbed, B v + Φ_t at q, Φ_t at q perturbed
    qp: Vec<f64>,
    rate0: Vec<f64>,
    phi_tp: Vec<f64>,
    /// the watch of the loops' conditioning (`Options::singularity_tol`, 0: none, until the
    /// start is made): the Cholesky pivots of S at the start, against which every index-1
    /// solve's are judged, and those of B Bᵀ (in `bbt`), against which the states after the
    /// steps of index-3 and index-2 forms are judged
    watch_tol: f64,
    /// the ratio of the watch's last judgement (the pivot that fell most against its start
    /// value; 1 before any), about (σ/σ₀)² for B's smallest singular value σ: rounding errors
    /// in Φ and Φ̇ grow as its inverse square root in the coordinates that solve them, and as
    /// its inverse in λ
    pub fallen: f64,
    start_s: Vec<f64>,
    start_bbt: Vec<f64>,
    bbt: Vec<f64>,
}

/// What a completion that does not close names ([`Failure::ClosureFailed`]).
pub(crate) const PARTITION_CLOSURE: &str = "the dependent coordinates (partitioning)";
/// The matrix a singular partition names ([`Failure::SingularMatrix`]).
pub(crate) const PARTITION_MATRIX: &str = "B over the dependent coordinates (partitioning)";

impl Constrained {
    pub fn new(model: &dyn ErasedModel, mode: Mode, o: &ConstraintOptions) -> Constrained {
        let (n, nc) = (model.nq(), model.nc());
        let info = model.info();
        let z = |k: usize| vec![0.0; k];
        Constrained {
            mode,
            n,
            nc,
            names: info.constraints.iter().map(|s| s.to_string()).collect(),
            dof_labels: (0..n).map(|i| info.dof_label(i)).collect(),
            tol: o.tolerance,
            scaling: o.scaling,
            drift_tol: o.drift_tol,
            max_iterations: o.max_iterations,
            phi: z(nc),
            b: z(nc * n),
            phi_t: z(nc),
            gamma: z(nc),
            lambda: z(nc),
            y: z(n * nc),
            s: z(nc * nc),
            w: z(n),
            r: z(nc),
            dep: Vec::with_capacity(nc),
            ind: Vec::with_capacity(n),
            lu_d: Lu::new(nc),
            pivot: z(nc * n),
            used: vec![false; n],
            rows_used: vec![false; nc],
            best: Vec::with_capacity(nc),
            qc: z(n),
            vc: z(n),
            qp: z(n),
            rate0: z(nc),
            phi_tp: z(nc),
            watch_tol: 0.0,
            fallen: 1.0,
            start_s: z(nc),
            start_bbt: z(nc),
            bbt: z(nc * nc),
        }
    }

    /// Watches the loops' conditioning from now on (`tolerance` > 0), against S's factor
    /// (in `s`, of the index-1 solve just made at the start) and B Bᵀ at the B just
    /// evaluated there. A change point (a parallelogram four-bar folding flat, an isosceles
    /// slider-crank's slider reaching the crank's pivot) makes B lose rank; near it λ grows
    /// as 1/σ and a scheme's small steps can leave the branch the motion was on, silently.
    pub fn watch_from_start(&mut self, tolerance: f64) {
        let nc = self.nc;
        for i in 0..nc {
            self.start_s[i] = self.s[i + nc * i].powi(2);
        }
        if self.gram().is_ok() {
            for i in 0..nc {
                self.start_bbt[i] = self.bbt[i + nc * i].powi(2);
            }
            self.watch_tol = tolerance;
        }
    }

    /// The watch's last ratio when within [`NearChangePoint::NEAR`] times its threshold;
    /// none without the watch.
    pub fn near_change_point(&self) -> Option<crate::error::NearChangePoint> {
        use crate::error::NearChangePoint;
        (self.watch_tol > 0.0 && self.fallen < NearChangePoint::NEAR * self.watch_tol).then_some(
            NearChangePoint {
                ratio: self.fallen,
                tolerance: self.watch_tol,
            },
        )
    }

    /// The Cholesky factor of B Bᵀ (of `self.b`) into `bbt`.
    fn gram(&mut self) -> Result<(), Singular> {
        let (n, nc) = (self.n, self.nc);
        for i in 0..nc {
            for j in 0..=i {
                let x = (0..n)
                    .map(|k| self.b[i + nc * k] * self.b[j + nc * k])
                    .sum();
                self.bbt[i + nc * j] = x;
                self.bbt[j + nc * i] = x;
            }
        }
        cholesky(&mut self.bbt, nc)
    }

    /// The pivot of a Cholesky factor (nc × nc) that fell most against its start value.
    fn fallen(factor: &[f64], start: &[f64], nc: usize) -> f64 {
        (0..nc).fold(f64::INFINITY, |m, i| {
            m.min(factor[i + nc * i].powi(2) / start[i])
        })
    }

    /// Judges the factor of `matrix` (S just made by an index-1 solve at (t, q), or B Bᵀ by
    /// [`Constrained::judge_gram`]) against the start's.
    fn judge(
        &mut self,
        m: &dyn ErasedModel,
        st: &mut Stats,
        at: (f64, &[f64]),
        matrix: LoopMatrix,
    ) -> Result<(), Failure> {
        let (factor, start) = match matrix {
            LoopMatrix::Schur => (&self.s, &self.start_s),
            LoopMatrix::Gram => (&self.bbt, &self.start_bbt),
        };
        let ratio = Self::fallen(factor, start, self.nc);
        self.fallen = ratio;
        if ratio < self.watch_tol {
            return Err(self.singular_loop(m, st, at.0, at.1, matrix, ratio));
        }
        Ok(())
    }

    /// Judges B Bᵀ at the state (t, q) a step of an index-3 or index-2 form accepted.
    fn judge_gram(
        &mut self,
        m: &dyn ErasedModel,
        st: &mut Stats,
        t: f64,
        q: &[f64],
    ) -> Result<(), Failure> {
        self.eval_b(m, st, t, q);
        st.loop_checks += 1;
        if self.gram().is_err() {
            return Err(self.rank_failure(m, st, t, q));
        }
        self.judge(m, st, (t, q), LoopMatrix::Gram)
    }

    /// What a singular loop at (t, q) is (a failure path: allocates, evaluates B 2n + 1
    /// more times): the coordinate with the largest |∂ log det (B Bᵀ)/∂q_j| (central
    /// differences), the one whose value makes B lose rank, and the constraints of B's
    /// smallest singular value.
    fn singular_loop(
        &mut self,
        m: &dyn ErasedModel,
        st: &mut Stats,
        t: f64,
        q: &[f64],
        matrix: LoopMatrix,
        ratio: f64,
    ) -> Failure {
        let (n, nc) = (self.n, self.nc);
        self.eval_b(m, st, t, q);
        let (_, _, involved) = rank_of(&self.b, nc, n);
        let mut log_det = |c: &mut Self, q: &[f64]| -> Option<f64> {
            c.eval_b(m, st, t, q);
            c.gram().ok()?;
            Some((0..nc).map(|i| c.bbt[i + nc * i].powi(2).ln()).sum())
        };
        let mut qp = q.to_vec();
        let mut best = (0, 0.0f64);
        for j in 0..n {
            let dj = 1e-6 * q[j].abs().max(1.0);
            qp[j] = q[j] + dj;
            let up = log_det(self, &qp);
            qp[j] = q[j] - dj;
            let down = log_det(self, &qp);
            qp[j] = q[j];
            if let (Some(a), Some(b)) = (up, down) {
                let g = ((a - b) / (2.0 * dj)).abs();
                if g > best.1 {
                    best = (j, g);
                }
            }
        }
        self.eval_b(m, st, t, q);
        Failure::SingularLoop {
            coordinate: self.dof_labels[best.0].clone(),
            value: q[best.0],
            constraints: involved.iter().map(|&i| self.name(i)).collect(),
            matrix,
            ratio,
            tolerance: self.watch_tol,
        }
    }

    /// Name of constraint `i`.
    pub fn name(&self, i: usize) -> String {
        self.names
            .get(i)
            .cloned()
            .unwrap_or_else(|| format!("#{i}"))
    }

    pub fn eval_phi(&mut self, m: &dyn ErasedModel, st: &mut Stats, t: f64, q: &[f64]) {
        m.constraints(t, q, &mut self.phi);
        st.constraints += 1;
    }

    /// Z = ∂(B v + Φ_t)/∂q at (t, q, v) (nc × n, column-major) into `z`, by forward
    /// differences: n + 1 evaluations of Φ_t and n of B. `b` is B(q), which `self.b` holds
    /// again afterwards. The Φ̇ rows of the stabilized index-2 iteration matrices need it
    /// (the Newmark family's and Radau's).
    #[allow(clippy::too_many_arguments)]
    pub fn rate_jacobian(
        &mut self,
        m: &dyn ErasedModel,
        st: &mut Stats,
        t: f64,
        q: &[f64],
        v: &[f64],
        b: &[f64],
        z: &mut [f64],
    ) {
        let (n, nc) = (self.n, self.nc);
        let rate = |b: &[f64], phi_t: &[f64], k: usize| {
            phi_t[k] + (0..n).map(|j| b[k + nc * j] * v[j]).sum::<f64>()
        };
        m.constraint_rate(t, q, &mut self.phi_tp);
        st.constraints += 1;
        for k in 0..nc {
            self.rate0[k] = rate(b, &self.phi_tp, k);
        }
        self.qp.copy_from_slice(q);
        for j in 0..n {
            let d = f64::EPSILON.sqrt() * q[j].abs().max(1.0);
            self.qp[j] = q[j] + d;
            m.constraint_jacobian(t, &self.qp, &mut self.b);
            m.constraint_rate(t, &self.qp, &mut self.phi_tp);
            st.constraints += 2;
            for k in 0..nc {
                z[k + nc * j] = (rate(&self.b, &self.phi_tp, k) - self.rate0[k]) / d;
            }
            self.qp[j] = q[j];
        }
        self.b.copy_from_slice(b);
    }

    pub fn eval_b(&mut self, m: &dyn ErasedModel, st: &mut Stats, t: f64, q: &[f64]) {
        m.constraint_jacobian(t, q, &mut self.b);
        st.constraints += 1;
    }

    fn eval_phi_t(&mut self, m: &dyn ErasedModel, st: &mut Stats, t: f64, q: &[f64]) {
        m.constraint_rate(t, q, &mut self.phi_t);
        st.constraints += 1;
    }

    /// Largest |Φ_i| of `self.phi`, and i.
    pub fn worst(&self) -> (f64, usize) {
        worst(&self.phi)
    }

    /// Y = L⁻¹Bᵀ and the Cholesky factor of S = YᵀY, with L the Cholesky factor of M.
    fn schur(&mut self, l: &[f64], st: &mut Stats) -> Result<(), Singular> {
        let (n, nc) = (self.n, self.nc);
        for i in 0..nc {
            let yi = &mut self.y[i * n..(i + 1) * n];
            for j in 0..n {
                yi[j] = self.b[i + nc * j];
            }
            forward(l, n, yi);
        }
        for i in 0..nc {
            for j in 0..=i {
                let mut x = 0.0;
                for k in 0..n {
                    x += self.y[k + n * i] * self.y[k + n * j];
                }
                self.s[i + nc * j] = x;
                self.s[j + nc * i] = x;
            }
        }
        st.factorizations += 1;
        cholesky(&mut self.s, nc)
    }

    /// x = M⁻¹Bᵀ S⁻¹ r after [`Constrained::schur`]; `self.r` holds r on entry.
    fn correction(&mut self, l: &[f64], st: &mut Stats, x: &mut [f64]) {
        let (n, nc) = (self.n, self.nc);
        cholesky_solve(&self.s, nc, &mut self.r);
        for k in 0..n {
            x[k] = (0..nc).map(|i| self.y[k + n * i] * self.r[i]).sum();
        }
        backward(l, n, x);
        st.solves += 1;
    }

    /// The failure for a singular S at (t, q): rank, smallest singular value and the
    /// constraints involved, from the SVD of B (the run stops: allocating is fine).
    pub fn rank_failure(
        &mut self,
        m: &dyn ErasedModel,
        st: &mut Stats,
        t: f64,
        q: &[f64],
    ) -> Failure {
        self.eval_b(m, st, t, q);
        let labels = &self.dof_labels;
        rank_failure(&self.b, self.nc, self.n, &self.names, |j| labels[j].clone())
    }

    /// qdd and λ of the index-1 equations at (t, q, qd), with L the Cholesky factor of M(q)
    /// and `h` = h(q, qd); Baumgarte's terms when the mode has them.
    pub fn kkt(
        &mut self,
        m: &dyn ErasedModel,
        st: &mut Stats,
        l: &[f64],
        at: At,
        h: &[f64],
        qdd: &mut [f64],
    ) -> Result<(), Failure> {
        let At { t, q, qd } = at;
        let (n, nc) = (self.n, self.nc);
        self.eval_b(m, st, t, q);
        m.constraint_bias(t, q, qd, &mut self.gamma);
        st.constraints += 1;
        if let Mode::Baumgarte { alpha, beta } = self.mode {
            if alpha != 0.0 || beta != 0.0 {
                self.eval_phi(m, st, t, q);
                self.eval_phi_t(m, st, t, q);
                for i in 0..nc {
                    let rate =
                        self.phi_t[i] + (0..n).map(|j| self.b[i + nc * j] * qd[j]).sum::<f64>();
                    self.gamma[i] -= 2.0 * alpha * rate + beta * beta * self.phi[i];
                }
            }
        }
        if self.schur(l, st).is_err() {
            return Err(self.rank_failure(m, st, t, q));
        }
        if self.watch_tol > 0.0 {
            self.judge(m, st, (t, q), LoopMatrix::Schur)?;
        }
        self.w.copy_from_slice(h);
        forward(l, n, &mut self.w);
        for i in 0..nc {
            let yz: f64 = (0..n).map(|k| self.y[k + n * i] * self.w[k]).sum();
            self.lambda[i] = self.gamma[i] - yz;
        }
        cholesky_solve(&self.s, nc, &mut self.lambda);
        for k in 0..n {
            qdd[k] = self.w[k]
                + (0..nc)
                    .map(|i| self.y[k + n * i] * self.lambda[i])
                    .sum::<f64>();
        }
        backward(l, n, qdd);
        st.solves += 2;
        Ok(())
    }

    /// Projects the state's q onto Φ(q, t) = 0 and qd onto Φ̇ = 0 in the metric of M (L its
    /// Cholesky factor at the unprojected q).
    pub fn project(
        &mut self,
        m: &dyn ErasedModel,
        st: &mut Stats,
        l: &[f64],
        s: &mut State,
        dx: &mut [f64],
    ) -> Result<(), Failure> {
        let (t, q, qd) = (s.t, &mut s.q[..], &mut s.qd[..]);
        let (n, nc) = (self.n, self.nc);
        st.projections += 1;
        let mut it = 0;
        // what rounding leaves of Φ, from B at the iterate before (none at the first)
        let mut floor = 0.0f64;
        loop {
            self.eval_phi(m, st, t, q);
            let (worst, at) = self.worst();
            if worst <= self.tol.max(floor) {
                break;
            }
            if it == self.max_iterations || !worst.is_finite() {
                return Err(Failure::ClosureFailed {
                    what: "all coordinates (projection)",
                    constraint: self.name(at),
                    residual: worst,
                    iterations: it,
                });
            }
            self.eval_b(m, st, t, q);
            floor = closure_floor(&self.b, nc, q);
            if self.schur(l, st).is_err() {
                return Err(self.rank_failure(m, st, t, q));
            }
            self.r.copy_from_slice(&self.phi);
            self.correction(l, st, dx);
            for k in 0..n {
                q[k] -= dx[k];
            }
            it += 1;
        }
        self.eval_b(m, st, t, q);
        self.eval_phi_t(m, st, t, q);
        if self.schur(l, st).is_err() {
            return Err(self.rank_failure(m, st, t, q));
        }
        for i in 0..nc {
            self.r[i] = self.phi_t[i] + (0..n).map(|j| self.b[i + nc * j] * qd[j]).sum::<f64>();
        }
        self.correction(l, st, dx);
        for k in 0..n {
            qd[k] -= dx[k];
        }
        Ok(())
    }

    /// e ← e − M⁻¹Bᵀ S⁻¹ B e: the part of e tangent to the constraints in the metric of M
    /// (L its Cholesky factor, B evaluated), which removes any M⁻¹Bᵀx component.
    pub fn tangent_part(
        &mut self,
        st: &mut Stats,
        l: &[f64],
        e: &mut [f64],
        dx: &mut [f64],
    ) -> Result<(), Singular> {
        let (n, nc) = (self.n, self.nc);
        self.schur(l, st)?;
        for i in 0..nc {
            self.r[i] = (0..n).map(|j| self.b[i + nc * j] * e[j]).sum();
        }
        self.correction(l, st, dx);
        for k in 0..n {
            e[k] -= dx[k];
        }
        Ok(())
    }

    /// Partitioning: q_d and qd_d completed from q_i, qd_i (starting from the given q_d)
    /// into `self.qc`, `self.vc`.
    pub fn complete(
        &mut self,
        m: &dyn ErasedModel,
        st: &mut Stats,
        t: f64,
        q: &[f64],
        qd: &[f64],
    ) -> Result<(), Failure> {
        let nc = self.nc;
        st.projections += 1;
        let mut qc = std::mem::take(&mut self.qc);
        qc.copy_from_slice(q);
        let mut it = 0;
        let result = loop {
            self.eval_phi(m, st, t, &qc);
            let (worst, at) = self.worst();
            self.eval_b(m, st, t, &qc);
            if let Err(e) = self.factor_dependent(st) {
                break Err(self.singular_partition(e));
            }
            let converged = worst <= self.tol.max(closure_floor(&self.b, nc, &qc));
            if it == self.max_iterations && !converged || !worst.is_finite() {
                break Err(Failure::ClosureFailed {
                    what: PARTITION_CLOSURE,
                    constraint: self.name(at),
                    residual: worst,
                    iterations: it,
                });
            }
            self.r.copy_from_slice(&self.phi);
            self.lu_d.solve(&mut self.r);
            st.solves += 1;
            for (k, &d) in self.dep.iter().enumerate() {
                qc[d] -= self.r[k];
            }
            if converged {
                // the last correction too: with an ill-conditioned B_d, |Φ| ≤ tolerance alone
                // leaves q_d off by cond·tolerance; then B at the final q for the velocities
                self.eval_b(m, st, t, &qc);
                break self
                    .factor_dependent(st)
                    .map_err(|e| self.singular_partition(e));
            }
            it += 1;
        };
        self.qc = qc;
        result?;
        // B_d qd_d = −Φ_t − B_i qd_i with B at the closed q
        let qc = std::mem::take(&mut self.qc);
        self.eval_phi_t(m, st, t, &qc);
        self.qc = qc;
        self.vc.copy_from_slice(qd);
        for i in 0..nc {
            self.r[i] = -self.phi_t[i]
                - self
                    .ind
                    .iter()
                    .map(|&j| self.b[i + nc * j] * qd[j])
                    .sum::<f64>();
        }
        self.lu_d.solve(&mut self.r);
        st.solves += 1;
        for (k, &d) in self.dep.iter().enumerate() {
            self.vc[d] = self.r[k];
        }
        Ok(())
    }

    /// LU of B_d = B[:, dep].
    fn factor_dependent(&mut self, st: &mut Stats) -> Result<(), Singular> {
        let nc = self.nc;
        let a = self.lu_d.matrix_mut();
        for (k, &d) in self.dep.iter().enumerate() {
            a[k * nc..(k + 1) * nc].copy_from_slice(&self.b[d * nc..(d + 1) * nc]);
        }
        st.factorizations += 1;
        self.lu_d.factor()
    }

    fn singular_partition(&self, e: Singular) -> Failure {
        Failure::SingularMatrix {
            matrix: PARTITION_MATRIX,
            rcond: e.rcond,
            coordinates: vec![self.dof_labels[self.dep[e.column.min(self.dep.len() - 1)]].clone()],
            cause: String::new(),
        }
    }

    /// Reciprocal condition (1-norm estimate) of B over `cols`, with B evaluated.
    fn rcond_of(&mut self, cols: &[usize], st: &mut Stats) -> f64 {
        let nc = self.nc;
        let a = self.lu_d.matrix_mut();
        for (k, &d) in cols.iter().enumerate() {
            a[k * nc..(k + 1) * nc].copy_from_slice(&self.b[d * nc..(d + 1) * nc]);
        }
        let anorm = norm1(a, nc);
        st.factorizations += 1;
        if self.lu_d.factor().is_err() || anorm == 0.0 {
            return 0.0;
        }
        let (inv, _) = self.lu_d.inverse_norm_estimate();
        if inv > 0.0 { 1.0 / (anorm * inv) } else { 0.0 }
    }

    /// The dependent set complete pivoting on B picks (into `self.best`), B evaluated.
    fn pivot_choice(&mut self) {
        let (n, nc) = (self.n, self.nc);
        self.pivot.copy_from_slice(&self.b);
        self.used.fill(false);
        self.rows_used.fill(false);
        self.best.clear();
        for _ in 0..nc {
            let (mut bi, mut bj, mut bv) = (usize::MAX, usize::MAX, -1.0);
            for j in 0..n {
                if self.used[j] {
                    continue;
                }
                for i in 0..nc {
                    if self.rows_used[i] {
                        continue;
                    }
                    let v = self.pivot[i + nc * j].abs();
                    if v > bv {
                        (bi, bj, bv) = (i, j, v);
                    }
                }
            }
            if bj == usize::MAX {
                break;
            }
            self.used[bj] = true;
            self.best.push(bj);
            self.rows_used[bi] = true;
            let p = self.pivot[bi + nc * bj];
            if p == 0.0 {
                continue;
            }
            for i in 0..nc {
                if self.rows_used[i] {
                    continue;
                }
                let f = self.pivot[i + nc * bj] / p;
                for j in 0..n {
                    self.pivot[i + nc * j] -= f * self.pivot[bi + nc * j];
                }
            }
        }
        self.best.sort_unstable();
    }

    /// Sets the partition: `preferred` independent coordinates when B over the others is
    /// not ten times worse conditioned than the pivoting choice, else that choice. B must be
    /// evaluated. Returns whether the dependent set changed.
    pub fn choose_partition(&mut self, preferred: Option<&[bool]>, st: &mut Stats) -> bool {
        let (n, nc) = (self.n, self.nc);
        self.pivot_choice();
        let best = std::mem::take(&mut self.best);
        let r_best = self.rcond_of(&best, st);
        let mut cand: Vec<usize> = Vec::new();
        if let Some(p) = preferred {
            cand.extend((0..n).filter(|&j| !p[j]));
        } else {
            cand.extend_from_slice(&self.dep);
        }
        let keep = cand.len() == nc && self.rcond_of(&cand, st) >= 0.1 * r_best;
        let chosen = if keep { cand } else { best.clone() };
        self.best = best;
        let changed = chosen != self.dep;
        self.dep.clear();
        self.dep.extend_from_slice(&chosen);
        self.ind.clear();
        self.ind.extend((0..n).filter(|j| !self.dep.contains(j)));
        changed
    }

    /// After an accepted step with partitioning (B evaluated at the completed q): a new
    /// partition when the current one has become ill-conditioned.
    pub fn check_partition(&mut self, st: &mut Stats) {
        let r_cur = {
            let dep = std::mem::take(&mut self.dep);
            let r = self.rcond_of(&dep, st);
            self.dep = dep;
            r
        };
        self.pivot_choice();
        let best = std::mem::take(&mut self.best);
        let r_best = self.rcond_of(&best, st);
        if best != self.dep && r_cur < 0.1 * r_best {
            self.dep.clear();
            self.dep.extend_from_slice(&best);
            self.ind.clear();
            let n = self.n;
            self.ind.extend((0..n).filter(|j| !best.contains(j)));
            st.repartitions += 1;
        }
        self.best = best;
    }

    /// The independent coordinates' labels.
    pub fn independent_labels(&self) -> Vec<String> {
        self.ind
            .iter()
            .map(|&j| self.dof_labels[j].clone())
            .collect()
    }

    /// `ConstraintDrift` when some |Φ_i(t, q)| exceeds the drift tolerance.
    pub fn check_drift(
        &mut self,
        m: &dyn ErasedModel,
        st: &mut Stats,
        t: f64,
        q: &[f64],
    ) -> Result<(), Failure> {
        self.eval_phi(m, st, t, q);
        let (worst, at) = self.worst();
        // not below ten times what rounding leaves of Φ (from the last B evaluated, none
        // before the first): the four-bar 10⁷ times larger, its Φ sums of 10⁶ m and that
        // floor just under 1e-6 m, ended Radau's index-3 steps of 6 s at |Φ| = 1.46e-6 m,
        // which the absolute drift_tol of 1e-6 called a drift
        let tolerance = self
            .drift_tol
            .max(10.0 * closure_floor(&self.b, self.nc, q));
        if worst > tolerance || !worst.is_finite() {
            return Err(Failure::ConstraintDrift {
                constraint: self.name(at),
                value: worst,
                tolerance,
                closed_by_scheme: matches!(self.mode, Mode::Index3 | Mode::Index2),
            });
        }
        if self.watch_tol > 0.0 && !self.mode.is_ode() {
            self.judge_gram(m, st, t, q)?;
        }
        Ok(())
    }
}

/// What rounding leaves of the constraints Φ at q, B = ∂Φ/∂q there (nc × n, column-major):
/// 100 ε of the largest |B_ij| max(|q_j|, 1), the size of the terms Φ is a sum of (a length
/// times a rotation's sine or cosine, a coordinate). Newton closes the constraints to the
/// tolerance asked or to this, whichever is larger: a four-bar 10⁶ times larger (links of
/// 100 to 400 km, or a 0.4 m one in micrometres) stalls at |Φ| ≈ 1e-10, where the tolerance
/// of 1e-11 cannot be met, and its runs stopped at their first projection.
pub(crate) fn closure_floor(b: &[f64], nc: usize, q: &[f64]) -> f64 {
    let size = (0..q.len())
        .map(|j| {
            let column = b[nc * j..nc * (j + 1)]
                .iter()
                .fold(0.0f64, |m, x| m.max(x.abs()));
            column * q[j].abs().max(1.0)
        })
        .fold(0.0f64, f64::max);
    rounding_of(size)
}

/// What rounding leaves of a sum whose largest term is `size`: 100 ε of it, 0 when it is not
/// finite (a state that is not finite is refused elsewhere, and must not raise a tolerance).
fn rounding_of(size: f64) -> f64 {
    if size.is_finite() {
        100.0 * f64::EPSILON * size
    } else {
        0.0
    }
}

/// What rounding leaves of the constraints' rates Φ̇ = B v + Φ_t at (q, v): 100 ε of the
/// largest term, |B_ij v_j| or |Φ_t,i|, as [`closure_floor`] is of Φ's. A rate closed to an
/// absolute tolerance below it cannot be met (the four-bar × 10⁸, whose rates are sums of
/// terms of 10⁴ m/s, stopped in Newton at index 2 under Radau at h_min).
pub(crate) fn rate_floor(b: &[f64], nc: usize, v: &[f64], phi_t: &[f64]) -> f64 {
    let terms = (0..v.len()).map(|j| {
        let column = b[nc * j..nc * (j + 1)]
            .iter()
            .fold(0.0f64, |m, x| m.max(x.abs()));
        column * v[j].abs()
    });
    rounding_of(
        terms
            .chain(phi_t.iter().map(|x| x.abs()))
            .fold(0.0f64, f64::max),
    )
}

/// σ = `block` / max|B_ij|, at least 1: about what a multiplier λ moves per unit of Φ's
/// residual ((B M⁻¹ Bᵀ)⁻¹ B, `block` the largest entry of M or of the iteration matrix'
/// dynamics block), which scales the rounding floor of λ's Newton corrections at index 3 and
/// 2. A four-bar written in millimetres has σ 10⁵–10⁶ times its size in metres: with the
/// floor taken at σ = 1, Newton asked λ for digits below rounding and failed at h_min. Not
/// below 1, the floor it had, which every model in SI units was measured with.
pub(crate) fn multiplier_scale(block: f64, b: &[f64]) -> f64 {
    let ratio = block / b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if ratio.is_finite() && ratio > 1.0 {
        ratio
    } else {
        1.0
    }
}

/// Largest |x_i| and i (infinite at the first non-finite x_i).
pub(crate) fn worst(x: &[f64]) -> (f64, usize) {
    let mut best = (0.0, 0);
    for (i, v) in x.iter().enumerate() {
        if !(v.abs() <= best.0) {
            best = (v.abs(), i);
            if !v.is_finite() {
                return (f64::INFINITY, i);
            }
        }
    }
    best
}

/// Rank, smallest singular value and the constraints involved in B's deficiency.
fn rank_failure(
    b: &[f64],
    nc: usize,
    n: usize,
    names: &[String],
    label: impl Fn(usize) -> String,
) -> Failure {
    // a B that is not finite has no rank: its own failure, naming the constraint and the
    // coordinate (√(x² + y²) − l at x = y = 0 gives 0/0)
    if let Some(i) = b.iter().position(|x| !x.is_finite()) {
        return Failure::NonFinite {
            quantity: "B = ∂Φ/∂q",
            coordinate: format!("{} in constraint `{}`", label(i / nc), names[i % nc]),
            cause: String::new(),
        };
    }
    let (rank, sigma_min, involved) = rank_of(b, nc, n);
    Failure::RankDeficientConstraints {
        rank,
        nc,
        sigma_min,
        constraints: involved.iter().map(|&i| names[i].clone()).collect(),
    }
}

/// Numerical rank of B (nc × n, column-major; σ ≤ 1e-10·σ_max counts as zero), its smallest
/// singular value, and the constraints with large components in the left singular vectors
/// of the vanishing singular values (the equations that repeat or cancel each other).
/// A B with entries that are not finite has rank 0 here, σ_min NaN and every constraint
/// involved: nalgebra's SVD does not return on such a matrix.
pub(crate) fn rank_of(b: &[f64], nc: usize, n: usize) -> (usize, f64, Vec<usize>) {
    if b.iter().any(|x| !x.is_finite()) {
        return (0, f64::NAN, (0..nc).collect());
    }
    // B padded with zero columns to at least nc × nc, so that U is square
    let cols = n.max(nc);
    let mat = nalgebra::DMatrix::from_fn(nc, cols, |i, j| if j < n { b[i + nc * j] } else { 0.0 });
    let svd = mat.svd(true, false);
    let u = svd.u.expect("U requested");
    let sigma = &svd.singular_values;
    let smax = sigma.iter().fold(0.0f64, |a, &v| a.max(v));
    let mut order: Vec<usize> = (0..sigma.len()).collect();
    order.sort_by(|&i, &j| sigma[i].total_cmp(&sigma[j]));
    let rank = (0..sigma.len())
        .filter(|&i| sigma[i] > 1e-10 * smax)
        .count()
        .min(nc);
    let sigma_min = sigma[order[0]];
    let mut involved = Vec::new();
    // the left singular vectors of the vanishing singular values (or of the smallest one)
    for &k in order.iter().take((nc - rank).max(1)) {
        let uk = u.column(k);
        let umax = uk.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        for i in 0..nc {
            if uk[i].abs() >= 0.3 * umax && !involved.contains(&i) {
                involved.push(i);
            }
        }
    }
    involved.sort_unstable();
    (rank, sigma_min, involved)
}

/// Largest move of a coordinate in one assembly step (rad or m).
const MAX_MOVE: f64 = 0.5;

/// The consistent start of a constrained model, as found by [`assemble`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Assembly {
    /// largest |Φ_i| at the given q₀, and after assembly
    pub residual_before: f64,
    pub residual_after: f64,
    /// largest |Φ̇_i| at the given qd₀, and after the velocity projection
    pub rate_residual_before: f64,
    pub rate_residual_after: f64,
    /// Newton iterations on the positions
    pub iterations: usize,
    /// the coordinate that moved most, and by how much (positions)
    pub largest_change: (String, f64),
    /// the coordinates kept as given (marked `independent`)
    pub kept: Vec<String>,
}

impl fmt::Display for Assembly {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "assembly: max |Φ| {:.2e} → {:.2e} in {} iterations (largest change {} by {:.3e}), max |Φ̇| {:.2e} → {:.2e}; kept {}",
            self.residual_before,
            self.residual_after,
            self.iterations,
            self.largest_change.0,
            self.largest_change.1,
            self.rate_residual_before,
            self.rate_residual_after,
            if self.kept.is_empty() {
                "none".to_string()
            } else {
                self.kept.join(", ")
            }
        )
    }
}

/// The change of the coordinates `free` (the others kept) that B (NC × NQ) maps to `r`, the
/// least in the metric of M (NQ × NQ): W⁻¹B_fᵀ(B_f W⁻¹B_fᵀ)⁻¹r with W = M_ff; subtracted, it
/// removes a residual r of Φ (or Φ̇) to first order. None when W or B_f W⁻¹B_fᵀ is singular.
pub(crate) fn least_correction(
    b: &[f64],
    mm: &[f64],
    free: &[usize],
    r: &[f64],
) -> Option<nalgebra::DVector<f64>> {
    use nalgebra::{DMatrix, DVector};
    let (nc, nf) = (r.len(), free.len());
    let n = b.len() / nc.max(1);
    let bf = DMatrix::from_fn(nc, nf, |i, k| b[i + nc * free[k]]);
    let w = DMatrix::from_fn(nf, nf, |a, c| mm[free[a] + n * free[c]]);
    let winv_bt = w.cholesky()?.solve(&bf.transpose());
    let s = &bf * &winv_bt;
    let x = s.cholesky()?.solve(&DVector::from_column_slice(r));
    Some(winv_bt * x)
}

/// Makes (q, qd) consistent with Φ(q, t) = 0 and Φ̇ = 0: Newton on the coordinates not
/// marked `independent` (minimal correction in the metric of M, no coordinate moved by more
/// than 0.5 per step, step halved until max |Φ| decreases), refusing a result on another
/// assembly branch; then the velocities of those
/// coordinates from B qd = −Φ_t. Typed errors: redundant constraints (rank of B), too many
/// coordinates marked independent, no convergence, a change of branch; on any of them `q`
/// and `qd` are left as they were given.
pub fn assemble<M: crate::model::Model + 'static>(
    model: &M,
    t: f64,
    q: &mut [f64],
    qd: &mut [f64],
    o: &ConstraintOptions,
) -> Result<Assembly, Failure> {
    o.validate()?;
    for (name, v) in [("q", &*q), ("qd", &*qd)] {
        if v.len() != M::NQ {
            return Err(Failure::InvalidOption {
                name,
                value: format!("{} values (the model has {} coordinates)", v.len(), M::NQ),
                reason: "must have one value per coordinate",
            });
        }
    }
    if !t.is_finite() {
        return Err(Failure::InvalidOption {
            name: "t",
            value: t.to_string(),
            reason: "must be finite",
        });
    }
    let (q0, qd0) = (q.to_vec(), qd.to_vec());
    let result = assemble_erased(model, t, q, qd, o);
    if result.is_err() {
        // the last Newton iterate is no start: the caller keeps the one it gave
        q.copy_from_slice(&q0);
        qd.copy_from_slice(&qd0);
    }
    result
}

/// [`assemble`] on the model behind the schemes.
pub(crate) fn assemble_erased(
    model: &dyn ErasedModel,
    t: f64,
    q: &mut [f64],
    qd: &mut [f64],
    o: &ConstraintOptions,
) -> Result<Assembly, Failure> {
    use nalgebra::DMatrix;
    let (n, nc) = (model.nq(), model.nc());
    let info = model.info();
    let names: Vec<String> = info.constraints.iter().map(|s| s.to_string()).collect();
    let label = |i: usize| info.dof_label(i);
    let kept: Vec<usize> = (0..n)
        .filter(|&i| info.independent.get(i) == Some(&true))
        .collect();
    let free: Vec<usize> = (0..n).filter(|i| !kept.contains(i)).collect();
    let mut phi = vec![0.0; nc];
    let mut b = vec![0.0; nc * n];
    let mut mm = vec![0.0; n * n];
    let eval = |q: &[f64], phi: &mut [f64]| {
        model.constraints(t, q, phi);
        worst(phi)
    };
    let (before, at0) = eval(q, &mut phi);
    let fail = |reason: String, phi: &[f64], it: usize| {
        let (r, at) = worst(phi);
        Failure::InconsistentStart {
            reason,
            constraint: names.get(at).cloned().unwrap_or_default(),
            residual: r,
            iterations: it,
        }
    };
    if !before.is_finite() {
        return Err(fail(
            format!("Φ is not finite at q₀ (constraint `{}`)", names[at0]),
            &phi,
            0,
        ));
    }
    if free.len() < nc {
        // redundant equations first: no marking would close them
        model.constraint_jacobian(t, q, &mut b);
        if rank_of(&b, nc, n).0 < nc {
            return Err(rank_failure(&b, nc, n, &names, label));
        }
        return Err(fail(
            format!(
                "{} marked independent, so only {} left to close {}: mark at most {}",
                counted(kept.len(), "coordinate is", "coordinates are"),
                counted(free.len(), "is", "are"),
                counted(nc, "constraint", "constraints"),
                n.saturating_sub(nc)
            ),
            &phi,
            0,
        ));
    }
    // B over the free coordinates
    let restricted = |b: &[f64]| DMatrix::from_fn(nc, free.len(), |i, k| b[i + nc * free[k]]);
    let deficient = |b: &[f64], phi: &[f64], it: usize| -> Failure {
        let (rank, _, _) = rank_of(b, nc, n);
        if rank < nc {
            rank_failure(b, nc, n, &names, label)
        } else {
            fail(
                format!(
                    "the coordinates marked independent ({}) leave B over the others rank-deficient: the loop cannot close by moving {}; mark other coordinates",
                    kept.iter()
                        .map(|&i| label(i))
                        .collect::<Vec<_>>()
                        .join(", "),
                    free.iter()
                        .map(|&i| label(i))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
                phi,
                it,
            )
        }
    };
    model.constraint_jacobian(t, q, &mut b);
    // a square set of free coordinates for the branch check (complete pivoting)
    let square: Vec<usize> = {
        let bf = restricted(&b);
        let mut piv = bf;
        let mut cols = Vec::new();
        let mut rows: Vec<usize> = (0..nc).collect();
        for _ in 0..nc {
            let mut best = (0.0, 0, 0);
            for &i in &rows {
                for k in 0..free.len() {
                    if !cols.contains(&k) && piv[(i, k)].abs() > best.0 {
                        best = (piv[(i, k)].abs(), i, k);
                    }
                }
            }
            let (v, bi, bk) = best;
            if v == 0.0 {
                break;
            }
            cols.push(bk);
            rows.retain(|&i| i != bi);
            for &i in &rows {
                let f = piv[(i, bk)] / piv[(bi, bk)];
                for k in 0..free.len() {
                    let x = piv[(bi, k)];
                    piv[(i, k)] -= f * x;
                }
            }
        }
        cols.sort_unstable();
        cols
    };
    let det_sign = |b: &[f64]| -> f64 {
        if square.len() < nc {
            return 0.0;
        }
        DMatrix::from_fn(nc, nc, |i, k| b[i + nc * free[square[k]]])
            .determinant()
            .signum()
    };
    let sign0 = det_sign(&b);
    let q_start = q.to_vec();
    // Newton's direction at q: B, what rounding leaves of Φ there, and the least correction
    // (None: B over the free coordinates is rank-deficient)
    let direction = |q: &[f64], phi: &[f64], b: &mut [f64], mm: &mut [f64]| {
        model.constraint_jacobian(t, q, b);
        model.mass_matrix(t, q, mm);
        (closure_floor(b, nc, q), least_correction(b, mm, &free, phi))
    };
    // q less `step` times the correction, and its Φ and largest |Φ|
    let (mut trial, mut phi_trial) = (q.to_vec(), vec![0.0; nc]);
    let try_step = |q: &[f64], dx: &[f64], step: f64, trial: &mut [f64], phi: &mut [f64]| {
        for (k, &j) in free.iter().enumerate() {
            trial[j] = q[j] - step * dx[k];
        }
        eval(trial, phi).0
    };
    let mut it = 0;
    let mut res = before;
    // what rounding leaves of Φ, from B at the iterate before (none at the first)
    let mut floor = 0.0f64;
    while res > o.tolerance.max(floor) {
        if it == o.max_iterations {
            return Err(fail(
                "Newton on the positions did not converge".into(),
                &phi,
                it,
            ));
        }
        let (f, dx) = direction(q, &phi, &mut b, &mut mm);
        floor = f;
        let Some(dx) = dx else {
            return Err(deficient(&b, &phi, it));
        };
        // at most MAX_MOVE per coordinate and step, so that a far start does not wander off
        // by whole turns
        let biggest = dx.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let mut step = (MAX_MOVE / biggest).min(1.0);
        loop {
            let r = try_step(q, dx.as_slice(), step, &mut trial, &mut phi_trial);
            if r < res || step < 1e-4 {
                res = r;
                break;
            }
            step *= 0.5;
        }
        if !res.is_finite() {
            return Err(fail(
                "Φ became non-finite during Newton".into(),
                &phi_trial,
                it + 1,
            ));
        }
        q.copy_from_slice(&trial);
        phi.copy_from_slice(&phi_trial);
        it += 1;
    }
    // then to what rounding leaves of Φ, while full steps still shrink it (a few more
    // iterations, once): an absolute tolerance is loose for a small mechanism (1e-11 m is
    // 1e-4 of a 0.1 µm crank), and a start closed only to it made Radau3 at index 2 fail in
    // Newton at t = 0, closing in its first step what the start had left
    for _ in 0..3 {
        if res <= floor {
            break;
        }
        let (f, dx) = direction(q, &phi, &mut b, &mut mm);
        floor = f;
        let Some(dx) = dx else {
            break;
        };
        let r = try_step(q, dx.as_slice(), 1.0, &mut trial, &mut phi_trial);
        if !(r < 0.5 * res) {
            break;
        }
        res = r;
        q.copy_from_slice(&trial);
        phi.copy_from_slice(&phi_trial);
        it += 1;
    }
    model.constraint_jacobian(t, q, &mut b);
    let (rank, _, _) = rank_of(&b, nc, n);
    if rank < nc {
        return Err(rank_failure(&b, nc, n, &names, label));
    }
    let sign1 = det_sign(&b);
    if sign0 != 0.0 && sign1 != sign0 {
        q.copy_from_slice(&q_start);
        return Err(fail(
            "Newton closed the loop on another assembly branch (det B over the dependent coordinates changed sign): start closer to the intended configuration".into(),
            &phi,
            it,
        ));
    }
    // velocities: B qd = −Φ_t with the kept velocities unchanged
    let mut phi_t = vec![0.0; nc];
    model.constraint_rate(t, q, &mut phi_t);
    let rate = |qd: &[f64]| -> Vec<f64> {
        (0..nc)
            .map(|i| phi_t[i] + (0..n).map(|j| b[i + nc * j] * qd[j]).sum::<f64>())
            .collect()
    };
    let r0 = rate(qd);
    let (rate_before, _) = worst(&r0);
    model.mass_matrix(t, q, &mut mm);
    let Some(dv) = least_correction(&b, &mm, &free, &r0) else {
        return Err(deficient(&b, &phi, it));
    };
    for (k, &j) in free.iter().enumerate() {
        qd[j] -= dv[k];
    }
    // the correction solves through B W⁻¹ Bᵀ, whose condition is B's squared: a second one
    // takes what rounding left, and what is left then is refused
    let scale = (0..nc)
        .map(|i| phi_t[i].abs() + (0..n).map(|j| (b[i + nc * j] * qd[j]).abs()).sum::<f64>())
        .fold(0.0f64, f64::max);
    let allowed = |r: f64| r <= 1e-9 * scale + o.tolerance;
    let (mut rate_after, mut at) = worst(&rate(qd));
    if !allowed(rate_after) && rate_after.is_finite() {
        let r1 = rate(qd);
        if let Some(dv) = least_correction(&b, &mm, &free, &r1) {
            for (k, &j) in free.iter().enumerate() {
                qd[j] -= dv[k];
            }
        }
        (rate_after, at) = worst(&rate(qd));
    }
    if !allowed(rate_after) {
        return Err(fail(
            format!(
                "the velocities do not satisfy constraint `{}`'s rate (|Φ̇| = {rate_after:.3e} after the correction{}): B over the coordinates not marked independent is ill-conditioned here, or the start's velocities are not finite; start elsewhere or mark other coordinates",
                names[at],
                if rate_before.is_finite() {
                    ""
                } else {
                    ", not finite before it"
                }
            ),
            &phi,
            it,
        ));
    }
    let (change, moved) = (0..n)
        .map(|j| ((q[j] - q_start[j]).abs(), j))
        .fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a });
    Ok(Assembly {
        residual_before: before,
        residual_after: res,
        rate_residual_before: rate_before,
        rate_residual_after: rate_after,
        iterations: it,
        largest_change: (label(moved), change),
        kept: kept.iter().map(|&i| label(i)).collect(),
    })
}

/// "1 coordinate is", "3 coordinates are": a count with the words that agree with it.
fn counted(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

#[cfg(test)]
mod tests {
    use super::rank_of;

    /// B (nc × n) from rows.
    fn cols(rows: &[&[f64]]) -> Vec<f64> {
        let (nc, n) = (rows.len(), rows[0].len());
        (0..nc * n).map(|k| rows[k % nc][k / nc]).collect()
    }

    #[test]
    fn rank_finds_zero_and_repeated_rows() {
        // full rank
        let b = cols(&[&[1.0, 0.0, 2.0], &[0.0, 1.0, -1.0]]);
        assert_eq!(rank_of(&b, 2, 3).0, 2);
        // a vanishing row (an out-of-plane equation of a planar loop): that row is named
        let b = cols(&[&[1.0, 0.0, 2.0], &[0.0, 0.0, 0.0], &[0.0, 1.0, -1.0]]);
        let (rank, smin, involved) = rank_of(&b, 3, 3);
        assert_eq!((rank, involved), (2, vec![1]));
        assert!(smin < 1e-12);
        // the same equation twice, scaled: both are named
        let b = cols(&[&[1.0, 2.0, 0.0], &[0.0, 0.0, 1.0], &[-2.0, -4.0, 0.0]]);
        let (rank, _, involved) = rank_of(&b, 3, 3);
        assert_eq!((rank, involved), (2, vec![0, 2]));
        // more equations than coordinates
        let b = cols(&[&[1.0], &[2.0]]);
        assert_eq!(rank_of(&b, 2, 1).0, 1);
    }
}
