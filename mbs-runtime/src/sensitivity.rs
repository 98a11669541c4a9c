//! Forward sensitivities: dq(t)/dp and dqd(t)/dp integrated with the motion, for the
//! parameters a model marks `sensitive` (`param k = 1e4 sensitive;`).
//!
//! Differentiating M(q, p) qdd = h(q, qd, p) with respect to p along the motion gives, for
//! s = ∂q/∂p,
//!
//! ```text
//! M s̈ = −K_t s − C_t ṡ − ∂τ/∂p        (K_t = ∂τ/∂q, C_t = ∂τ/∂qd, τ = M qdd − h)
//! ```
//!
//! at the current (q, qd, qdd): the same mass matrix, the exact tangents (`option tangents;`)
//! and the generated ∂τ/∂p. [`Sensitivities`] wraps a model into one whose coordinates are
//! (q, s₁, …, s_NS), block-diagonal mass matrix diag(M, …, M) and forces (h, h₁, …, h_NS), so
//! every scheme integrates the motion and its sensitivities together, with its error control
//! over both (as CVODES's "full" error control: the error norm is the largest of the
//! motion's and each parameter's sensitivities' own, so adding sensitivities never loosens
//! the motion's control, which one RMS norm over them all did by √(1 + NS) where the
//! sensitivities' errors were small); its forward dynamics solves every block with
//! one Cholesky factorisation of M. Starts at s = ∂q₀/∂p, ṡ = ∂qd₀/∂p of the declared
//! start ([`Model::start_sensitivities`], zero where the start is free of the parameter; it
//! was zero always, and `dof x = x0;` with `param x0 sensitive` gave dx/dx0 = 0 throughout),
//! completed on closed loops (below). The inputs are taken as free of the parameters: u(t)
//! given as a function of time is, a sampled controller's is not (its feedback through the
//! state would be missing from dq/dp), and a simulation refuses controllers on a wrapper. The wrapped model's
//! iteration matrices come from finite differences (its tangents would need second
//! derivatives).
//!
//! **Rotation joints.** When the runtime re-centres a joint's chart, the sensitivities of its
//! angles and rates are mapped into the new chart, the new chart held fixed (it is a number
//! of the nominal motion): the same perturbation of the joint's orientation and angular
//! velocity ([`crate::charts::Recentring::map_sensitivity`]). A joint's sensitivities are
//! thus read in the chart of the output they belong to, as its angles are.
//!
//! **Closed loops** (M qdd = h + Bᵀλ, Φ(q, p) = 0). Differentiating both along the motion,
//! with μ = ∂λ/∂p and K_λ = ∂(Bᵀλ)/∂q:
//!
//! ```text
//! M s̈ − Bᵀμ = −(K_t − K_λ) s − C_t ṡ − ∂τ/∂p + ∂(Bᵀλ)/∂p
//! B s̈       = −∂Φ̈/∂q s − ∂Φ̈/∂qd ṡ − ∂Φ̈/∂p          (Φ̈ = B qdd − γ)
//! ```
//!
//! at the qdd and λ of the motion (the index-1 system of the wrapped model at (q, qd)). The
//! wrapper keeps the wrapped model's constraints on q, which the scheme enforces with the
//! chosen constraint method, and gives each sᵢ the forces M s̈ᵢ of this system: the
//! sensitivities follow Φ̈'s derivative (index 1), and B s + ∂Φ/∂p = 0 and its rate hold to
//! the accuracy of the integration (`Sensitivities::residuals` measures them). The start's
//! sensitivities are those of the assembly: the coordinates marked `independent` keep theirs
//! (0 unless a start says otherwise), the others take the least change, in the metric of M,
//! that satisfies B s + ∂Φ/∂p = 0 and B ṡ + ∂Φ̇/∂q s + ∂Φ̇/∂p = 0
//! ([`Model::complete_start`]). That is the derivative of the assembly when the coordinates
//! not marked number the constraints (the loop then closes in one way); with more of them,
//! the assembly's result also depends on Newton's path from the start and on M(p), which
//! this first-order choice does not follow.

use crate::error::{Failure, ModelError, ParamError};
use crate::linalg::{Lu, cholesky, cholesky_solve};
use crate::model::{ConstraintTangents, Energy, Kinematics, Model, ModelInfo, Pose};
use crate::trajectory::Trajectory;
use std::any::TypeId;
use std::cell::RefCell;
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

/// A model and the sensitivities of its motion to its `sensitive` parameters, as one model
/// with NQ·(1 + NS) coordinates: q, then ∂q/∂p₁, …, ∂q/∂p_NS (named `∂q[i]/∂p`).
pub struct Sensitivities<M: Model> {
    pub model: M,
    info: &'static ModelInfo,
    scratch: RefCell<Scratch>,
}

struct Scratch {
    m: Vec<f64>,
    l: Vec<f64>,
    h: Vec<f64>,
    qdd: Vec<f64>,
    k: Vec<f64>,
    c: Vec<f64>,
    dtau: Vec<f64>,
    zero: Vec<f64>,
    haug: Vec<f64>,
    /// closed loops only (empty otherwise)
    loops: Loops,
}

/// What a closed loop adds: B, γ, the index-1 system [M −Bᵀ; B 0] factorised, λ, K_λ, the
/// constraints' derivatives and a right-hand side.
struct Loops {
    b: Vec<f64>,
    gamma: Vec<f64>,
    kkt: Lu<f64>,
    lambda: Vec<f64>,
    k_lambda: Vec<f64>,
    tangents: ConstraintTangents,
    rhs: Vec<f64>,
}

impl Loops {
    fn new<M: Model>() -> Loops {
        let (n, nc) = (M::NQ, M::NC);
        Loops {
            b: vec![0.0; nc * n],
            gamma: vec![0.0; nc],
            kkt: Lu::new(n + nc),
            lambda: vec![0.0; nc],
            k_lambda: vec![0.0; n * n],
            tangents: ConstraintTangents::new::<M>(),
            rhs: vec![0.0; n + nc],
        }
    }

    /// Factorises [M −Bᵀ; B 0] from `m` and `self.b`; whether it is regular.
    fn factor(&mut self, m: &[f64], n: usize) -> bool {
        let nc = self.gamma.len();
        let na = n + nc;
        let a = self.kkt.matrix_mut();
        a.fill(0.0);
        for c in 0..n {
            for r in 0..n {
                a[r + na * c] = m[r + n * c];
            }
            for i in 0..nc {
                let bij = self.b[i + nc * c];
                a[(n + i) + na * c] = bij;
                a[c + na * (n + i)] = -bij;
            }
        }
        self.kkt.factor().is_ok()
    }
}

impl<M: Model + 'static> Sensitivities<M> {
    /// Wraps `model`; refused without sensitive parameters or without tangents.
    pub fn new(model: M) -> Result<Sensitivities<M>, ModelError> {
        let info = model.info();
        if M::SENSITIVE.is_empty() {
            return Err(ModelError::NoSensitiveParameters { model: info.name });
        }
        if !info.has_tangents {
            return Err(ModelError::TangentsNotGenerated { model: info.name });
        }
        let n = M::NQ;
        // generated with `has_tangents`; a model written by hand may say it has them and
        // lack one, which `evaluate` would then read as zeros: asked once here
        {
            let (z, u) = (vec![0.0; n], vec![0.0; M::NU]);
            let (mut k, mut c) = (vec![0.0; n * n], vec![0.0; n * n]);
            model.tangents(0.0, &z, &z, &z, &u, &mut k, &mut c)?;
            let mut dtau = vec![0.0; n * M::SENSITIVE.len()];
            model.parameter_tangents(0.0, &z, &z, &z, &u, &mut dtau)?;
        }
        if M::NC > 0 {
            // generated for models with constraints and sensitive parameters; a model written
            // by hand may lack it
            let z = vec![0.0; n.max(M::NC)];
            model.constraint_parameter_tangents(
                0.0,
                &z[..n],
                &z[..n],
                &z[..n],
                &z[..M::NC],
                &mut ConstraintTangents::new::<M>(),
            )?;
        }
        let z = |len: usize| vec![0.0; len];
        Ok(Sensitivities {
            info: extended_info::<M>(info),
            scratch: RefCell::new(Scratch {
                m: z(n * n),
                l: z(n * n),
                h: z(n),
                qdd: z(n),
                k: z(n * n),
                c: z(n * n),
                dtau: z(n * M::SENSITIVE.len()),
                zero: z(n * (1 + M::SENSITIVE.len())),
                haug: z(n * (1 + M::SENSITIVE.len())),
                loops: Loops::new::<M>(),
            }),
            model,
        })
    }

    /// ∂q/∂p (NQ values) of parameter `p` (an index into `M::SENSITIVE`) at output `i` of a
    /// trajectory of this model. Panics, as slice indexing does, when `p` or `i` is out of
    /// range or `tr` is not a trajectory of this wrapper (whose coordinates hold the
    /// sensitivities).
    pub fn dq_dp(tr: &Trajectory, i: usize, p: usize) -> &[f64] {
        let n = M::NQ;
        &tr.q(i)[n * (1 + p)..n * (2 + p)]
    }

    /// ∂qd/∂p at output `i` (panics as [`Sensitivities::dq_dp`] does).
    pub fn dqd_dp(tr: &Trajectory, i: usize, p: usize) -> &[f64] {
        let n = M::NQ;
        &tr.qd(i)[n * (1 + p)..n * (2 + p)]
    }

    /// M, the wrapped h (the first NQ), and the sensitivities' forces into `s.haug`; whether
    /// M was factorised (its Cholesky factor in `s.l`).
    fn evaluate(&self, s: &mut Scratch, t: f64, x: &[f64], xd: &[f64], u: &[f64]) -> bool {
        let n = M::NQ;
        let (q, qd) = (&x[..n], &xd[..n]);
        self.model.dynamics(t, q, qd, u, &mut s.m, &mut s.h);
        s.l.copy_from_slice(&s.m);
        let factorised = cholesky(&mut s.l, n).is_ok();
        // qdd of an open loop from the factor; a closed loop's from its index-1 system
        let closed = M::NC > 0 && self.closed_loop_state(s, t, q, qd);
        if M::NC == 0 {
            s.qdd.copy_from_slice(&s.h);
            if factorised {
                cholesky_solve(&s.l, n, &mut s.qdd);
            } else {
                // the runtime's checks of the pivots and of the accelerations report it
                s.qdd.fill(f64::NAN);
            }
        }
        // checked at construction (`new`): both answer for this model
        let _ = self.model.tangents(t, q, qd, &s.qdd, u, &mut s.k, &mut s.c);
        let _ = self
            .model
            .parameter_tangents(t, q, qd, &s.qdd, u, &mut s.dtau);
        s.haug[..n].copy_from_slice(&s.h);
        for j in 0..M::SENSITIVE.len() {
            let (sq, sv) = (&x[n * (1 + j)..n * (2 + j)], &xd[n * (1 + j)..n * (2 + j)]);
            let out = &mut s.haug[n * (1 + j)..n * (2 + j)];
            for i in 0..n {
                let mut f = -s.dtau[i + n * j];
                for k in 0..n {
                    f -= s.k[i + n * k] * sq[k] + s.c[i + n * k] * sv[k];
                }
                out[i] = f;
            }
            if M::NC > 0 {
                Self::closed_loop_forces(&mut s.loops, &s.m, closed, j, sq, sv, out);
            }
        }
        factorised
    }

    /// qdd and λ of the wrapped closed loop at (q, qd) into `s.qdd` and `s.loops.lambda` (the
    /// index-1 system), then K_λ and the constraints' derivatives there; whether the system
    /// was regular (NaN accelerations otherwise, which the runtime's checks report).
    fn closed_loop_state(&self, s: &mut Scratch, t: f64, q: &[f64], qd: &[f64]) -> bool {
        let (n, nc) = (M::NQ, M::NC);
        let l = &mut s.loops;
        self.model.constraint_jacobian(t, q, &mut l.b);
        self.model.constraint_bias(t, q, qd, &mut l.gamma);
        let regular = l.factor(&s.m, n);
        l.rhs[..n].copy_from_slice(&s.h);
        l.rhs[n..].copy_from_slice(&l.gamma);
        if regular {
            l.kkt.solve(&mut l.rhs);
        } else {
            l.rhs.fill(f64::NAN);
        }
        s.qdd.copy_from_slice(&l.rhs[..n]);
        l.lambda.copy_from_slice(&l.rhs[n..n + nc]);
        self.model
            .constraint_tangent(t, q, &l.lambda, &mut l.k_lambda);
        // checked at construction: it answers for this model
        let _ =
            self.model
                .constraint_parameter_tangents(t, q, qd, &s.qdd, &l.lambda, &mut l.tangents);
        regular
    }

    /// Block j's forces M s̈ⱼ of a closed loop from `f` = −K_t s − C_t ṡ − ∂τ/∂p (in `out`):
    /// adds K_λ s + ∂(Bᵀλ)/∂p, solves the index-1 system with B s̈ = −∂Φ̈/∂q s − ∂Φ̈/∂qd ṡ −
    /// ∂Φ̈/∂p, and writes M s̈ = f + Bᵀμ.
    fn closed_loop_forces(
        l: &mut Loops,
        m: &[f64],
        regular: bool,
        j: usize,
        sq: &[f64],
        sv: &[f64],
        out: &mut [f64],
    ) {
        let (n, nc) = (M::NQ, M::NC);
        let ct = &l.tangents;
        for i in 0..n {
            let mut f = out[i] + ct.dforce_dp[i + n * j];
            for k in 0..n {
                f += l.k_lambda[i + n * k] * sq[k];
            }
            l.rhs[i] = f;
        }
        for i in 0..nc {
            let mut g = -ct.dacc_dp[i + nc * j];
            for k in 0..n {
                g -= ct.dacc_dq[i + nc * k] * sq[k] + ct.dacc_dqd[i + nc * k] * sv[k];
            }
            l.rhs[n + i] = g;
        }
        if !regular {
            out.fill(f64::NAN);
            return;
        }
        l.kkt.solve(&mut l.rhs);
        for (i, o) in out.iter_mut().enumerate() {
            *o = (0..n).map(|k| m[i + n * k] * l.rhs[k]).sum();
        }
    }

    /// The largest |B sⱼ + ∂Φ/∂pⱼ| and |B ṡⱼ + ∂Φ̇/∂q sⱼ + ∂Φ̇/∂pⱼ| at output `i` of a
    /// trajectory of this model: how far its sensitivities have drifted from the constraints'
    /// derivatives (zero for models without constraints). Reads the output in its charts (and
    /// leaves the wrapper in them); None when `tr` has no output `i` of this model's size.
    pub fn residuals(&mut self, tr: &Trajectory, i: usize) -> Option<(f64, f64)> {
        let (n, nc) = (M::NQ, M::NC);
        let joints = self.model.info().rotation_joints.len();
        if i >= tr.len() || tr.check_fits(<Self as Model>::NQ, joints).is_err() {
            return None;
        }
        if nc == 0 {
            return Some((0.0, 0.0));
        }
        crate::charts::use_charts_of(&mut self.model, tr, i);
        let (t, x, xd) = (tr.t[i], tr.q(i), tr.qd(i));
        let mut b = vec![0.0; nc * n];
        let mut ct = ConstraintTangents::new::<M>();
        self.model.constraint_jacobian(t, &x[..n], &mut b);
        let zero = vec![0.0; n.max(nc)];
        let _ = self.model.constraint_parameter_tangents(
            t,
            &x[..n],
            &xd[..n],
            &zero[..n],
            &zero[..nc],
            &mut ct,
        );
        let mut worst = (0.0f64, 0.0f64);
        for j in 0..M::SENSITIVE.len() {
            let (sq, sv) = (&x[n * (1 + j)..n * (2 + j)], &xd[n * (1 + j)..n * (2 + j)]);
            for r in 0..nc {
                let (mut p, mut v) = (ct.dphi_dp[r + nc * j], ct.drate_dp[r + nc * j]);
                for k in 0..n {
                    p += b[r + nc * k] * sq[k];
                    v += b[r + nc * k] * sv[k] + ct.drate_dq[r + nc * k] * sq[k];
                }
                worst = (worst.0.max(p.abs()), worst.1.max(v.abs()));
            }
        }
        Some(worst)
    }

    /// diag(M, …, M) from `s.m`.
    fn block_diagonal(s: &Scratch, out: &mut [f64]) {
        let n = M::NQ;
        let na = n * (1 + M::SENSITIVE.len());
        out.fill(0.0);
        for b in 0..=M::SENSITIVE.len() {
            for c in 0..n {
                for r in 0..n {
                    out[(b * n + r) + na * (b * n + c)] = s.m[r + n * c];
                }
            }
        }
    }
}

/// One leaked `ModelInfo` per model type: its coordinates followed by `∂q[i]/∂p` for each
/// sensitive parameter.
fn extended_info<M: Model + 'static>(inner: &'static ModelInfo) -> &'static ModelInfo {
    static CACHE: OnceLock<Mutex<HashMap<TypeId, &'static ModelInfo>>> = OnceLock::new();
    let mut cache = CACHE
        .get_or_init(|| Mutex::new(HashMap::new()))
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    cache.entry(TypeId::of::<M>()).or_insert_with(|| {
        let mut dofs: Vec<&'static str> = inner.dofs.to_vec();
        for p in M::SENSITIVE {
            for d in inner.dofs {
                dofs.push(String::leak(format!("∂{d}/∂{p}")));
            }
        }
        let mut independent = inner.independent.to_vec();
        independent.resize(dofs.len(), true);
        Box::leak(Box::new(ModelInfo {
            dofs: Vec::leak(dofs),
            independent: Vec::leak(independent),
            has_tangents: false,
            ..*inner
        }))
    })
}

impl<M: Model + 'static> Model for Sensitivities<M> {
    type Params = M::Params;
    const NQ: usize = M::NQ * (1 + M::SENSITIVE.len());
    const NU: usize = M::NU;
    const NFRAMES: usize = M::NFRAMES;
    const NPOINTS: usize = M::NPOINTS;
    const NC: usize = M::NC;
    /// block by block with one Cholesky factorisation of the wrapped M
    const FORWARD_DYNAMICS_GENERATED: bool = true;
    const SENSITIVITY_BLOCKS: usize = M::SENSITIVE.len();

    fn info(&self) -> &'static ModelInfo {
        self.info
    }

    fn params(&self) -> &Self::Params {
        self.model.params()
    }

    fn set_params(&mut self, params: Self::Params) -> Result<(), ParamError> {
        self.model.set_params(params)
    }

    /// The wrapped model's start, then its sensitivities ∂q₀/∂p and ∂qd₀/∂p
    /// ([`Model::start_sensitivities`]).
    fn initial_state(&self, q: &mut [f64], qd: &mut [f64]) {
        let n = M::NQ;
        let (q, sq) = q.split_at_mut(n);
        let (qd, sqd) = qd.split_at_mut(n);
        self.model.initial_state(q, qd);
        self.model.start_sensitivities(sq, sqd);
    }

    /// qdd of every block with one factorisation of M (NQ × NQ of the wrapped model); the
    /// pivots are its Cholesky pivots L_jj², repeated for each block (0 where M is not
    /// positive definite).
    fn forward_dynamics(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        u: &[f64],
        qdd: &mut [f64],
        pivots: &mut [f64],
    ) {
        let s = &mut *self.scratch.borrow_mut();
        let ok = self.evaluate(s, t, q, qd, u);
        let n = M::NQ;
        for b in 0..=M::SENSITIVE.len() {
            let block = &mut qdd[b * n..(b + 1) * n];
            block.copy_from_slice(&s.haug[b * n..(b + 1) * n]);
            crate::linalg::solve_with_pivots(&s.l, n, ok, block, &mut pivots[b * n..(b + 1) * n]);
        }
    }

    fn mass_matrix(&self, t: f64, q: &[f64], m: &mut [f64]) {
        let s = &mut *self.scratch.borrow_mut();
        self.model.mass_matrix(t, &q[..M::NQ], &mut s.m);
        Self::block_diagonal(s, m);
    }

    fn dynamics(&self, t: f64, q: &[f64], qd: &[f64], u: &[f64], m: &mut [f64], h: &mut [f64]) {
        let s = &mut *self.scratch.borrow_mut();
        self.evaluate(s, t, q, qd, u);
        Self::block_diagonal(s, m);
        h.copy_from_slice(&s.haug);
    }

    fn inverse_dynamics(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        u: &[f64],
        tau: &mut [f64],
    ) {
        let s = &mut *self.scratch.borrow_mut();
        self.evaluate(s, t, q, qd, u);
        let n = M::NQ;
        for b in 0..=M::SENSITIVE.len() {
            for i in 0..n {
                let mut f = -s.haug[b * n + i];
                for k in 0..n {
                    f += s.m[i + n * k] * qdd[b * n + k];
                }
                tau[b * n + i] = f;
            }
        }
    }

    fn tangents(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        u: &[f64],
        k: &mut [f64],
        c: &mut [f64],
    ) -> Result<(), ModelError> {
        let _ = (t, q, qd, qdd, u, k, c);
        Err(ModelError::TangentsNotGenerated {
            model: self.info.name,
        })
    }

    fn static_forces(&self, t: f64, q: &[f64], u: &[f64], h: &mut [f64]) {
        let s = &mut *self.scratch.borrow_mut();
        let zero = std::mem::take(&mut s.zero);
        self.evaluate(s, t, q, &zero, u);
        s.zero = zero;
        h.copy_from_slice(&s.haug);
    }

    /// The wrapped model's ∂h/∂u in the first NQ rows; the sensitivities' rows are zero.
    fn input_matrix(&self, t: f64, q: &[f64], qd: &[f64], u: &[f64], b: &mut [f64]) {
        let (n, na) = (M::NQ, Self::NQ);
        b.fill(0.0);
        // (linearisation only, never inside a step)
        let mut inner = vec![0.0; n * M::NU];
        self.model.input_matrix(t, &q[..n], &qd[..n], u, &mut inner);
        for c in 0..M::NU {
            b[na * c..na * c + n].copy_from_slice(&inner[n * c..n * (c + 1)]);
        }
    }

    fn energy(&self, t: f64, q: &[f64], qd: &[f64]) -> Energy {
        self.model.energy(t, &q[..M::NQ], &qd[..M::NQ])
    }

    fn power(&self, t: f64, q: &[f64], qd: &[f64], u: &[f64]) -> f64 {
        self.model.power(t, &q[..M::NQ], &qd[..M::NQ], u)
    }

    // the wrapped model's constraints on q; the sensitivities follow them through their forces
    fn constraints(&self, t: f64, q: &[f64], phi: &mut [f64]) {
        self.model.constraints(t, &q[..M::NQ], phi)
    }

    /// B of the wrapped model in the first NQ columns, zero over the sensitivities
    fn constraint_jacobian(&self, t: f64, q: &[f64], b: &mut [f64]) {
        b.fill(0.0);
        self.model
            .constraint_jacobian(t, &q[..M::NQ], &mut b[..M::NC * M::NQ]);
    }

    fn constraint_rate(&self, t: f64, q: &[f64], phi_t: &mut [f64]) {
        self.model.constraint_rate(t, &q[..M::NQ], phi_t)
    }

    fn constraint_bias(&self, t: f64, q: &[f64], qd: &[f64], gamma: &mut [f64]) {
        self.model
            .constraint_bias(t, &q[..M::NQ], &qd[..M::NQ], gamma)
    }

    /// the wrapped model's ∂(Bᵀλ)/∂q in the top-left block
    fn constraint_tangent(&self, t: f64, q: &[f64], lambda: &[f64], k: &mut [f64]) {
        let (n, na) = (M::NQ, Self::NQ);
        k.fill(0.0);
        if n == 0 || M::NC == 0 {
            return;
        }
        let s = &mut *self.scratch.borrow_mut();
        self.model.constraint_tangent(t, &q[..n], lambda, &mut s.k);
        for c in 0..n {
            k[na * c..na * c + n].copy_from_slice(&s.k[n * c..n * (c + 1)]);
        }
    }

    /// The sensitivities of the assembled start (see the module's documentation).
    fn complete_start(&self, t: f64, q: &mut [f64], qd: &mut [f64]) -> Result<(), Failure> {
        let (n, nc) = (M::NQ, M::NC);
        if nc == 0 {
            return Ok(());
        }
        let inner = self.model.info();
        let free: Vec<usize> = (0..n)
            .filter(|&i| inner.independent.get(i) != Some(&true))
            .collect();
        let (mut b, mut mm) = (vec![0.0; nc * n], vec![0.0; n * n]);
        let mut ct = ConstraintTangents::new::<M>();
        self.model.constraint_jacobian(t, &q[..n], &mut b);
        self.model.mass_matrix(t, &q[..n], &mut mm);
        let zero = vec![0.0; n.max(nc)];
        self.model
            .constraint_parameter_tangents(t, &q[..n], &qd[..n], &zero[..n], &zero[..nc], &mut ct)
            .map_err(|e| Failure::InvalidOption {
                name: "model",
                value: inner.name.to_string(),
                reason: crate::integrators::model_error_reason(&e),
            })?;
        let singular = || {
            Failure::InconsistentStart {
            reason: "the sensitivities of the start cannot be made consistent: B over the coordinates not marked independent is rank-deficient".into(),
            constraint: String::new(),
            residual: f64::NAN,
            iterations: 0,
        }
        };
        let mut r = vec![0.0; nc];
        for j in 0..M::SENSITIVE.len() {
            let block = n * (1 + j)..n * (2 + j);
            // positions: B s + ∂Φ/∂p = 0
            for (i, ri) in r.iter_mut().enumerate() {
                *ri = ct.dphi_dp[i + nc * j]
                    + (0..n)
                        .map(|k| b[i + nc * k] * q[block.start + k])
                        .sum::<f64>();
            }
            let dx =
                crate::integrators::least_correction(&b, &mm, &free, &r).ok_or_else(singular)?;
            for (a, &k) in free.iter().enumerate() {
                q[block.start + k] -= dx[a];
            }
            // velocities: B ṡ + ∂Φ̇/∂q s + ∂Φ̇/∂p = 0
            let sq = &q[block.clone()];
            for (i, ri) in r.iter_mut().enumerate() {
                *ri = ct.drate_dp[i + nc * j]
                    + (0..n)
                        .map(|k| {
                            b[i + nc * k] * qd[block.start + k] + ct.drate_dq[i + nc * k] * sq[k]
                        })
                        .sum::<f64>();
            }
            let dv =
                crate::integrators::least_correction(&b, &mm, &free, &r).ok_or_else(singular)?;
            for (a, &k) in free.iter().enumerate() {
                qd[block.start + k] -= dv[a];
            }
        }
        Ok(())
    }

    fn chart(&self, joint: usize) -> [[f64; 3]; 3] {
        self.model.chart(joint)
    }

    fn set_chart(&mut self, joint: usize, r: [[f64; 3]; 3]) {
        self.model.set_chart(joint, r)
    }

    /// Maps each sensitivity block as the re-centred charts ask (the new charts held fixed:
    /// the same perturbation of each joint's orientation and angular velocity), then asks for
    /// the accelerations again, which the sensitivities' need at the mapped state.
    fn recentred(
        &self,
        moved: &[crate::charts::Recentring],
        q: &mut [f64],
        qd: &mut [f64],
    ) -> bool {
        let n = M::NQ;
        for j in 0..M::SENSITIVE.len() {
            let block = n * (1 + j)..n * (2 + j);
            for r in moved {
                r.map_sensitivity(&mut q[block.clone()], &mut qd[block.clone()]);
            }
        }
        true
    }

    fn frames(&self, t: f64, q: &[f64], out: &mut [Pose]) {
        self.model.frames(t, &q[..M::NQ], out)
    }

    fn kinematics(&self, t: f64, q: &[f64], qd: &[f64], out: &mut Kinematics) {
        self.model.kinematics(t, &q[..M::NQ], &qd[..M::NQ], out)
    }
}
