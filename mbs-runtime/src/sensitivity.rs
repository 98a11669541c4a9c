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
//! over both (as CVODES's "full" error control); its forward dynamics solves every block with
//! one Cholesky factorisation of M. Starts at s = ṡ = 0 (initial conditions that
//! do not depend on the parameters). Open-loop models without rotation joints; the wrapped
//! model's iteration matrices come from finite differences (its tangents would need second
//! derivatives).

use crate::error::{ModelError, ParamError};
use crate::linalg::{cholesky, cholesky_solve};
use crate::model::{Energy, Kinematics, Model, ModelInfo, Pose};
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
}

impl<M: Model + 'static> Sensitivities<M> {
    /// Wraps `model`; refused without sensitive parameters, without tangents, with
    /// constraints or rotation joints.
    pub fn new(model: M) -> Result<Sensitivities<M>, ModelError> {
        let info = model.info();
        let unsupported = |reason: &'static str| ModelError::SensitivitiesUnsupported {
            model: info.name,
            reason,
        };
        if M::SENSITIVE.is_empty() {
            return Err(ModelError::NoSensitiveParameters { model: info.name });
        }
        if !info.has_tangents {
            return Err(ModelError::TangentsNotGenerated { model: info.name });
        }
        if M::NC > 0 {
            return Err(unsupported(
                "it has constraints (∂Φ/∂p and the multipliers' sensitivities are not generated yet)",
            ));
        }
        if !info.rotation_joints.is_empty() {
            return Err(unsupported(
                "it has rotation joints (a re-centred chart would need its sensitivities mapped too)",
            ));
        }
        let n = M::NQ;
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
            }),
            model,
        })
    }

    /// ∂q/∂p (NQ values) of parameter `p` (an index into `M::SENSITIVE`) at output `i` of a
    /// trajectory of this model.
    pub fn dq_dp(tr: &Trajectory, i: usize, p: usize) -> &[f64] {
        let n = M::NQ;
        &tr.q(i)[n * (1 + p)..n * (2 + p)]
    }

    /// ∂qd/∂p at output `i`.
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
        s.qdd.copy_from_slice(&s.h);
        let factorised = cholesky(&mut s.l, n).is_ok();
        if factorised {
            cholesky_solve(&s.l, n, &mut s.qdd);
        } else {
            // the runtime's checks of the pivots and of the accelerations report it
            s.qdd.fill(f64::NAN);
        }
        // checked at construction: both are generated
        let _ = self.model.tangents(t, q, qd, &s.qdd, u, &mut s.k, &mut s.c);
        let _ = self
            .model
            .parameter_tangents(t, q, qd, &s.qdd, u, &mut s.dtau);
        s.haug[..n].copy_from_slice(&s.h);
        for j in 0..M::SENSITIVE.len() {
            let (sq, sv) = (&x[n * (1 + j)..n * (2 + j)], &xd[n * (1 + j)..n * (2 + j)]);
            for i in 0..n {
                let mut f = -s.dtau[i + n * j];
                for k in 0..n {
                    f -= s.k[i + n * k] * sq[k] + s.c[i + n * k] * sv[k];
                }
                s.haug[n * (1 + j) + i] = f;
            }
        }
        factorised
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
    const NC: usize = 0;
    /// block by block with one Cholesky factorisation of the wrapped M
    const FORWARD_DYNAMICS_GENERATED: bool = true;

    fn info(&self) -> &'static ModelInfo {
        self.info
    }

    fn params(&self) -> &Self::Params {
        self.model.params()
    }

    fn set_params(&mut self, params: Self::Params) -> Result<(), ParamError> {
        self.model.set_params(params)
    }

    fn initial_state(&self, q: &mut [f64], qd: &mut [f64]) {
        let n = M::NQ;
        q.fill(0.0);
        qd.fill(0.0);
        self.model.initial_state(&mut q[..n], &mut qd[..n]);
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

    fn constraints(&self, _: f64, _: &[f64], _: &mut [f64]) {}
    fn constraint_jacobian(&self, _: f64, _: &[f64], _: &mut [f64]) {}
    fn constraint_rate(&self, _: f64, _: &[f64], _: &mut [f64]) {}
    fn constraint_bias(&self, _: f64, _: &[f64], _: &[f64], _: &mut [f64]) {}
    fn constraint_tangent(&self, _: f64, _: &[f64], _: &[f64], _: &mut [f64]) {}

    fn frames(&self, t: f64, q: &[f64], out: &mut [Pose]) {
        self.model.frames(t, &q[..M::NQ], out)
    }

    fn kinematics(&self, t: f64, q: &[f64], qd: &[f64], out: &mut Kinematics) {
        self.model.kinematics(t, &q[..M::NQ], &qd[..M::NQ], out)
    }
}
