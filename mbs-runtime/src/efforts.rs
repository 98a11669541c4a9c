//! Efforts written in Rust and extra first-order states, around a generated model (EasyDyn's
//! `AddAppliedEfforts` and its extra differential equations).
//!
//! [`WithEfforts`] wraps a model `M` and a user part `E: Efforts` into a model of its own, so
//! every scheme, constraint method and analysis runs it unchanged:
//!
//! - at every evaluation the generated kinematics of `M` (poses, velocities and Jacobians of
//!   its frames and points) are handed to [`Efforts::efforts`], which adds forces and torques
//!   in world axes at points of bodies ([`Effort`]); they are projected to generalised forces
//!   through the Jacobians, Q = Σ J_vᵀF + J_ωᵀT, and added to h. A user part that reads no
//!   Jacobian ([`Efforts::reads_jacobians`] false) on a model with `option motion;` gets the
//!   poses and velocities alone ([`Model::motion`]) and its forces and torques are carried
//!   to Q by one inward pass of the tree ([`Model::transmit`], O(n)): the human model's
//!   12,227 flops of `kinematics` become 3,264 of `motion` and 3,992 of `transmit`;
//! - `E::NX` extra states x with ẋ = f(t, q, qd, x, u) ([`Efforts::state_derivatives`]: motor
//!   currents, PID integrators, activation dynamics) ride along as auxiliary coordinates s
//!   with ṡ = x and s̈ = f: unit mass, no other coupling. Every scheme integrates them with its
//!   own velocity update (for the Newmark family, its first-order form: the trapezoidal rule
//!   at γ = ½); the states are the velocities `qd[NQ_M + k]` of the coordinates named
//!   `x:NAME`, their integrals s are not used;
//! - tangents: the generated ones of `M` plus forward differences of the user part only
//!   (2·NQ_M + NX + 1 evaluations of it), counted in `Stats::user_efforts`; without generated
//!   tangents the schemes difference the whole of τ ([`Model::differenced_tangents`],
//!   [`Model::differenced_iteration_matrix`]), to the numbers of the default differences
//!   with less work: nothing reads the states' integrals s, so their columns are zero without
//!   an evaluation, and a state's column calls the user part alone, on the kinematics and the
//!   wrapped model's τ of the unmoved state (a Radau5 matrix of the human model on muscles,
//!   23 coordinates and 53 states: 47 evaluations of the wrapped model and 100 of the user
//!   part, 53 of them without kinematics, where it took 153 of both);
//!
//! The user part must be a function of (t, q, qd, x, u): it is called at trial states, for
//! differences and several times per step. Memory belongs in extra states or in sampled
//! controllers ([`crate::Inputs`]). A user error (`Err`) or a non-finite effort stops the run
//! with [`Failure::UserEffort`] or [`Failure::NonFinite`] naming the coordinate or state. A
//! state the efforts are not defined at, which a smaller step may avoid (an overshooting
//! trial state), is rejected with `Err(e.reject(…))` instead ([`Effort::reject`]): the step
//! is retried smaller, as SUNDIALS does with a right-hand side's recoverable error.

use crate::elements::cross;
use crate::error::{Failure, ModelError, ParamError};
use crate::model::{
    DifferenceBuffers, Energy, FrameKinematics, Kinematics, Model, ModelInfo, PointKinematics,
    Pose, increment, iteration_column,
};
use std::any::TypeId;
use std::cell::{Cell, Ref, RefCell, RefMut};
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

/// The user part of a [`WithEfforts`] model.
pub trait Efforts: 'static {
    /// number of extra first-order states x
    const NX: usize = 0;
    /// their names (NX of them)
    const STATE_NAMES: &'static [&'static str] = &[];
    /// whether [`Efforts::efforts`] reads frames ([`Effort::frame`]); when false only the
    /// points' positions, velocities and Jacobians are computed at each evaluation
    /// ([`Model::point_kinematics`], a fraction of the cost on a model of many bodies), and
    /// the frames and the points' bias accelerations are left unset (efforts transmitted,
    /// [`Efforts::reads_jacobians`], read [`Model::motion`]'s frames and points whatever
    /// this says)
    const FRAMES: bool = true;
    /// Whether [`Efforts::efforts`] and [`Efforts::state_derivatives`] read Jacobians or
    /// bias accelerations (`e.frame(i).jv`, `e.point(i).jv`, …): asked at each evaluation,
    /// and must not change during a run. When false and the model is generated with
    /// `option motion;` ([`Model::MOTION_GENERATED`]), each evaluation computes the poses
    /// and velocities alone ([`Model::motion`]) and carries the forces and torques the user
    /// part adds to generalised forces by one inward pass of the tree ([`Model::transmit`]):
    /// no Jacobian is computed, and the Jacobians and bias accelerations are NaN (a user
    /// part that reads them all the same stops with [`Failure::NonFinite`]).
    /// Without the option the Jacobians are computed and read as when it is true.
    /// `transmit` takes a wrench on every frame and a force at every point: where the
    /// efforts act at a few points of a large model and read nothing else, the points'
    /// Jacobians ([`Efforts::FRAMES`] false) may cost less (`mbs expand FILE --counts-only`
    /// gives both counts).
    fn reads_jacobians(&self) -> bool {
        true
    }
    /// x(0) (NX)
    fn initial_states(&self, _x: &mut [f64]) {}
    /// Adds the efforts at the state in `e` (world axes). An `Err` stops the run;
    /// `Err(e.reject(…))` has the step retried smaller ([`Effort::reject`]).
    fn efforts(&mut self, e: &mut Effort) -> Result<(), String>;
    /// ẋ (NX) at the state in `e`.
    fn state_derivatives(&mut self, _e: &Effort, _xd: &mut [f64]) -> Result<(), String> {
        Ok(())
    }
}

/// The state handed to the user part, and where it adds its efforts.
///
/// Frames, points and coordinates are named by their indices in the wrapped model
/// (`ModelInfo::frame_index`, `ModelInfo::point_index`, found once when the user part is
/// built, where a missing name is an error the user part can report). An index the model
/// does not have is a bug in the user part: the accessors panic on it, as a slice does.
pub struct Effort<'a> {
    pub t: f64,
    /// coordinates and velocities of the wrapped model
    pub q: &'a [f64],
    pub qd: &'a [f64],
    /// extra states
    pub x: &'a [f64],
    /// inputs
    pub u: &'a [f64],
    /// kinematics of the wrapped model's frames and points at (t, q, qd)
    pub kin: &'a Kinematics,
    /// the charts of the rotation joints ([`Effort::chart`])
    charts: &'a [[[f64; 3]; 3]],
    qg: &'a mut [f64],
    /// where forces and torques are summed when they are transmitted ([`Efforts::reads_jacobians`]
    /// false): 6 per frame (force at its origin, torque), then 3 per point
    wrenches: Option<&'a mut [f64]>,
    rejected: bool,
}

impl Effort<'_> {
    /// Rejects this state as one the efforts are not defined at (a table's range, a guard)
    /// but which a smaller step may avoid: a trial state of a Newton iteration or an explicit
    /// stage can overshoot where the motion itself never goes. Return it as the error,
    /// `return Err(e.reject("knee beyond its table"))`: an adaptive step is then retried at a
    /// quarter of its size (counted in `Stats::rejected_effort`), and the run stops with
    /// [`Failure::EffortRejected`] only at a fixed step or when the step reaches its floor,
    /// keeping the trajectory. A plain `Err` stops the run at once.
    pub fn reject(&mut self, message: impl Into<String>) -> String {
        self.rejected = true;
        message.into()
    }

    /// The chart of rotation joint `joint` (the order of `ModelInfo::rotation_joints`): the
    /// rotation its angles in `q` are measured from, `R = chart · Rz(a) · Ry(b) · Rx(c)`,
    /// which the runtime moves past 60° of turn ([`crate::charts`]). Read a free body's
    /// orientation with [`crate::charts::joint_rotation`], or from its frame's pose.
    pub fn chart(&self, joint: usize) -> [[f64; 3]; 3] {
        self.charts[joint]
    }

    /// Kinematics of frame (or body) `i` (`ModelInfo::frame_index`); unset when the user
    /// part says it reads no frames ([`Efforts::FRAMES`]), its Jacobians and bias
    /// accelerations NaN when the efforts are transmitted ([`Efforts::reads_jacobians`]).
    pub fn frame(&self, i: usize) -> &FrameKinematics {
        &self.kin.frames[i]
    }

    /// Kinematics of declared point `i` (`ModelInfo::point_index`); its bias acceleration is
    /// set only when the user part reads frames ([`Efforts::FRAMES`]).
    pub fn point(&self, i: usize) -> &PointKinematics {
        &self.kin.points[i]
    }

    /// A force (world axes) at declared point `i`.
    pub fn force_at_point(&mut self, i: usize, f: [f64; 3]) {
        let nf = self.kin.frames.len();
        match &mut self.wrenches {
            Some(w) => add3(&mut w[6 * nf + 3 * i..], f),
            None => add_jt(self.qg, &self.kin.points[i].jv, f),
        }
    }

    /// A force (world axes) applied at the world position `at` of a point of frame `i`.
    pub fn force_on_frame(&mut self, i: usize, at: [f64; 3], f: [f64; 3]) {
        let k = &self.kin.frames[i];
        let o = k.pose.position;
        let r = [at[0] - o[0], at[1] - o[1], at[2] - o[2]];
        match &mut self.wrenches {
            Some(w) => {
                add3(&mut w[6 * i..], f);
                add3(&mut w[6 * i + 3..], cross(r, f));
            }
            None => {
                add_jt(self.qg, &k.jv, f);
                add_jt(self.qg, &k.jw, cross(r, f));
            }
        }
    }

    /// A torque (world axes) on frame `i`.
    pub fn torque_on_frame(&mut self, i: usize, torque: [f64; 3]) {
        match &mut self.wrenches {
            Some(w) => add3(&mut w[6 * i + 3..], torque),
            None => add_jt(self.qg, &self.kin.frames[i].jw, torque),
        }
    }

    /// A generalised force on coordinate `i` of the wrapped model.
    pub fn generalized_force(&mut self, i: usize, value: f64) {
        self.qg[i] += value;
    }
}

/// What `motion` does not compute, set to NaN.
fn unset(kin: &mut Kinematics) {
    for f in &mut kin.frames {
        f.jv.fill(f64::NAN);
        f.jw.fill(f64::NAN);
        f.bias_acceleration = [f64::NAN; 3];
        f.bias_angular_acceleration = [f64::NAN; 3];
    }
    for p in &mut kin.points {
        p.jv.fill(f64::NAN);
        p.bias_acceleration = [f64::NAN; 3];
    }
}

/// w[..3] += f
fn add3(w: &mut [f64], f: [f64; 3]) {
    for (w, f) in w.iter_mut().zip(f) {
        *w += f;
    }
}

/// qg += Jᵀ f for a 3 × n Jacobian stored column-major (`j[3k + i]`).
pub(crate) fn add_jt(qg: &mut [f64], j: &[f64], f: [f64; 3]) {
    for (k, g) in qg.iter_mut().enumerate() {
        *g += j[3 * k] * f[0] + j[3 * k + 1] * f[1] + j[3 * k + 2] * f[2];
    }
}

/// Buffers of the wrapper, allocated once.
struct Scratch {
    kin: Kinematics,
    m: Vec<f64>,
    h: Vec<f64>,
    b: Vec<f64>,
    bu: Vec<f64>,
    k: Vec<f64>,
    c: Vec<f64>,
    qg: Vec<f64>,
    xd: Vec<f64>,
    /// the wrenches summed for [`Model::transmit`] and what it makes of them
    wrenches: Vec<f64>,
    transmitted: Vec<f64>,
    /// whether the Jacobians and bias accelerations in `kin` are NaN: set before the first
    /// evaluation whose efforts are transmitted, so that a user part that reads them
    /// anyway stops with [`Failure::NonFinite`] rather than reading stale values
    unset_nan: bool,
    qg1: Vec<f64>,
    xd1: Vec<f64>,
    qp: Vec<f64>,
    vp: Vec<f64>,
    up: Vec<f64>,
    /// the wrapped model's τ at the state being differenced
    tau: Vec<f64>,
    charts: Vec<[[f64; 3]; 3]>,
}

/// A generated model with efforts and extra states written in Rust: a [`Model`] with
/// NQ = M::NQ + E::NX coordinates.
pub struct WithEfforts<M: Model, E: Efforts> {
    pub model: M,
    user: RefCell<E>,
    scratch: RefCell<Scratch>,
    failure: RefCell<Option<Failure>>,
    evaluations: Cell<usize>,
    info: &'static ModelInfo,
}

/// A copy with fresh buffers and counters (what statics and linearisation ask of a model).
impl<M: Model + Clone + 'static, E: Efforts + Clone> Clone for WithEfforts<M, E> {
    fn clone(&self) -> Self {
        WithEfforts::new(self.model.clone(), self.user.borrow().clone())
    }
}

impl<M: Model + 'static, E: Efforts> WithEfforts<M, E> {
    pub fn new(model: M, efforts: E) -> WithEfforts<M, E> {
        let (n, nx) = (M::NQ, E::NX);
        let big = n + nx;
        let z = |k: usize| vec![0.0; k];
        let scratch = Scratch {
            kin: Kinematics::new::<M>(),
            m: z(n * n),
            h: z(n),
            b: z(M::NC * n),
            bu: z(n * M::NU),
            k: z(n * n),
            c: z(n * n),
            qg: z(n),
            xd: z(nx),
            wrenches: z(6 * M::NFRAMES + 3 * M::NPOINTS),
            transmitted: z(n),
            unset_nan: false,
            qg1: z(n),
            xd1: z(nx),
            qp: z(big),
            vp: z(big),
            up: z(M::NU),
            tau: z(n),
            charts: vec![[[0.0; 3]; 3]; model.info().rotation_joints.len()],
        };
        let info = extended_info::<M, E>(model.info());
        WithEfforts {
            model,
            user: RefCell::new(efforts),
            scratch: RefCell::new(scratch),
            failure: RefCell::new(None),
            evaluations: Cell::new(0),
            info,
        }
    }

    /// The user part.
    pub fn efforts(&self) -> Ref<'_, E> {
        self.user.borrow()
    }

    /// The user part, mutably (between runs: it must not change during one).
    pub fn efforts_mut(&self) -> RefMut<'_, E> {
        self.user.borrow_mut()
    }
}

/// One leaked `ModelInfo` per (model type, user type): the wrapped model's with the extra
/// states appended as coordinates `x:NAME`.
fn extended_info<M: Model + 'static, E: Efforts>(inner: &'static ModelInfo) -> &'static ModelInfo {
    if E::NX == 0 {
        return inner;
    }
    static CACHE: OnceLock<Mutex<HashMap<(TypeId, TypeId), &'static ModelInfo>>> = OnceLock::new();
    let key = (TypeId::of::<M>(), TypeId::of::<E>());
    let mut cache = CACHE
        .get_or_init(|| Mutex::new(HashMap::new()))
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    cache.entry(key).or_insert_with(|| {
        let leak = |v: Vec<&'static str>| -> &'static [&'static str] { Vec::leak(v) };
        let mut dofs: Vec<&'static str> = inner.dofs.to_vec();
        for k in 0..E::NX {
            let name = E::STATE_NAMES.get(k).copied().unwrap_or("state");
            dofs.push(String::leak(format!("x:{name}")));
        }
        let mut independent = inner.independent.to_vec();
        independent.resize(dofs.len(), true);
        Box::leak(Box::new(ModelInfo {
            dofs: leak(dofs),
            independent: Vec::leak(independent),
            ..*inner
        }))
    })
}

impl<M: Model, E: Efforts> WithEfforts<M, E> {
    /// Whether the user part's efforts are summed as wrenches and carried to the
    /// coordinates by [`Model::transmit`] on the poses and velocities of [`Model::motion`]
    /// ([`Efforts::reads_jacobians`]).
    fn transmits(&self) -> bool {
        M::MOTION_GENERATED && !self.user.borrow().reads_jacobians()
    }

    /// The user part at (t, q, qd, u) (q, qd of length NQ_M + NX) into `qg` (NQ_M) and `xd`
    /// (NX); false (with the failure kept) when it fails or gives a non-finite value.
    fn user(
        &self,
        s: &mut Scratch,
        t: f64,
        q: &[f64],
        qd: &[f64],
        u: &[f64],
        into_1: bool,
    ) -> bool {
        let n = M::NQ;
        if self.transmits() {
            if !s.unset_nan {
                unset(&mut s.kin);
                s.unset_nan = true;
            }
            self.model.motion(t, &q[..n], &qd[..n], &mut s.kin);
        } else if E::FRAMES {
            s.unset_nan = false;
            self.model.kinematics(t, &q[..n], &qd[..n], &mut s.kin);
        } else {
            s.unset_nan = false;
            self.model
                .point_kinematics(t, &q[..n], &qd[..n], &mut s.kin);
        }
        self.user_on_kinematics(s, t, q, qd, u, into_1)
    }

    /// [`Self::user`] on the kinematics already in `s.kin`, those of (t, q, qd) (only the
    /// extra states, `qd[NQ_M..]`, changed since they were computed).
    fn user_on_kinematics(
        &self,
        s: &mut Scratch,
        t: f64,
        q: &[f64],
        qd: &[f64],
        u: &[f64],
        into_1: bool,
    ) -> bool {
        let n = M::NQ;
        self.evaluations.set(self.evaluations.get() + 1);
        let (qg, xd) = if into_1 {
            (&mut s.qg1, &mut s.xd1)
        } else {
            (&mut s.qg, &mut s.xd)
        };
        qg.fill(0.0);
        xd.fill(0.0);
        crate::charts::read_charts(&self.model, &mut s.charts);
        let transmits = self.transmits();
        let mut user = self.user.borrow_mut();
        let wrenches = transmits.then(|| {
            s.wrenches.fill(0.0);
            &mut s.wrenches[..]
        });
        let mut e = Effort {
            t,
            q: &q[..n],
            qd: &qd[..n],
            x: &qd[n..],
            u,
            kin: &s.kin,
            charts: &s.charts,
            qg,
            wrenches,
            rejected: false,
        };
        let r = user
            .efforts(&mut e)
            .and_then(|_| user.state_derivatives(&e, xd));
        let rejected = e.rejected;
        if r.is_ok() && transmits {
            self.model
                .transmit(t, &q[..n], &s.wrenches, &mut s.transmitted);
            for (g, w) in qg.iter_mut().zip(&s.transmitted) {
                *g += w;
            }
        }
        if let Err(message) = r {
            self.fail(if rejected {
                Failure::EffortRejected { t, message }
            } else {
                Failure::UserEffort { t, message }
            });
            return false;
        }
        let bad = qg
            .iter()
            .position(|v| !v.is_finite())
            .map(|i| self.info.dof_label(i))
            .or_else(|| {
                xd.iter()
                    .position(|v| !v.is_finite())
                    .map(|k| self.info.dof_label(n + k))
            });
        if let Some(coordinate) = bad {
            // where the Jacobians are NaN, reading them is the likely cause
            let cause = if transmits {
                "; the efforts are transmitted (`Efforts::reads_jacobians` is false), so the \
                 Jacobians and bias accelerations the user part is handed are NaN: a user part \
                 that reads them must say so"
                    .to_string()
            } else {
                String::new()
            };
            self.fail(Failure::NonFinite {
                quantity: "user effort",
                coordinate,
                cause,
            });
            return false;
        }
        true
    }

    /// The user part at (t, q, qd), which differs from the state of the kinematics in `s.kin`
    /// by component `j` alone, into `qg1`, `xd1`: an extra state's (j ≥ NQ_M) reuses those
    /// kinematics, a coordinate's or its rate's computes them.
    fn user_moved(
        &self,
        s: &mut Scratch,
        t: f64,
        q: &[f64],
        qd: &[f64],
        u: &[f64],
        j: usize,
    ) -> bool {
        if j < M::NQ {
            self.user(s, t, q, qd, u, true)
        } else {
            self.user_on_kinematics(s, t, q, qd, u, true)
        }
    }

    /// τ at (t, q, qd, qdd) into `tau` as [`Model::inverse_dynamics`] forms it, the wrapped
    /// model's part kept in `s.tau` and the user part's in `s.qg`, `s.xd` and its kinematics in
    /// `s.kin`: the base of differences. False when the user part fails.
    fn differences_base(
        &self,
        s: &mut Scratch,
        t: f64,
        [q, qd, qdd]: [&[f64]; 3],
        u: &[f64],
        tau: &mut [f64],
    ) -> bool {
        let n = M::NQ;
        self.model
            .inverse_dynamics(t, &q[..n], &qd[..n], &qdd[..n], u, &mut s.tau);
        if !self.user(s, t, q, qd, u, false) {
            return false;
        }
        tau[..n].copy_from_slice(&s.tau);
        form_tau::<E>(tau, qdd, &s.qg, &s.xd);
        true
    }

    /// τ at (t, q, qd, qdd), which differs from the base of [`Self::differences_base`] in
    /// component `j` alone, into `tau`: the wrapped model's part evaluated for a coordinate
    /// (j < NQ_M) and the base's for an extra state. False when the user part fails.
    fn moved_tau(
        &self,
        s: &mut Scratch,
        t: f64,
        [q, qd, qdd]: [&[f64]; 3],
        u: &[f64],
        j: usize,
        tau: &mut [f64],
    ) -> bool {
        let n = M::NQ;
        if j < n {
            self.model
                .inverse_dynamics(t, &q[..n], &qd[..n], &qdd[..n], u, &mut tau[..n]);
        } else {
            tau[..n].copy_from_slice(&s.tau);
        }
        if !self.user_moved(s, t, q, qd, u, j) {
            return false;
        }
        form_tau::<E>(tau, qdd, &s.qg1, &s.xd1);
        true
    }

    fn fail(&self, f: Failure) {
        let mut slot = self.failure.borrow_mut();
        if slot.is_none() {
            *slot = Some(f);
        }
    }
}

impl<M: Model, E: Efforts> Model for WithEfforts<M, E> {
    type Params = M::Params;
    const NQ: usize = M::NQ + E::NX;
    const NU: usize = M::NU;
    const NFRAMES: usize = M::NFRAMES;
    const NPOINTS: usize = M::NPOINTS;
    const NC: usize = M::NC;
    /// the wrapped model's forward dynamics with the user's efforts added to h
    /// ([`Model::forward_dynamics_forced`]); the extra states have unit mass
    const FORWARD_DYNAMICS_GENERATED: bool = true;

    fn info(&self) -> &'static ModelInfo {
        self.info
    }

    /// qdd of the wrapped model with the user's efforts added to its h, by its
    /// [`Model::forward_dynamics_forced`] (generated: articulated bodies or sparse LᵀDL, no
    /// dense factorisation; the default: dense Cholesky); the extra states' derivatives as
    /// they are. Pivots: the wrapped model's, 1 for the extra states.
    fn forward_dynamics(
        &self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        u: &[f64],
        qdd: &mut [f64],
        pivots: &mut [f64],
    ) {
        let n = M::NQ;
        let s = &mut *self.scratch.borrow_mut();
        if !self.user(s, t, q, qd, u, false) {
            qdd.fill(f64::NAN);
            pivots.fill(0.0);
            return;
        }
        self.model.forward_dynamics_forced(
            t,
            &q[..n],
            &qd[..n],
            u,
            &s.qg,
            &mut qdd[..n],
            &mut pivots[..n],
        );
        qdd[n..].copy_from_slice(&s.xd);
        pivots[n..].fill(1.0);
    }

    fn params(&self) -> &Self::Params {
        self.model.params()
    }

    fn set_params(&mut self, params: Self::Params) -> Result<(), ParamError> {
        self.model.set_params(params)
    }

    fn initial_state(&self, q: &mut [f64], qd: &mut [f64]) {
        let n = M::NQ;
        self.model.initial_state(&mut q[..n], &mut qd[..n]);
        q[n..].fill(0.0);
        self.user.borrow().initial_states(&mut qd[n..]);
    }

    fn mass_matrix(&self, t: f64, q: &[f64], m: &mut [f64]) {
        let s = &mut *self.scratch.borrow_mut();
        self.model.mass_matrix(t, &q[..M::NQ], &mut s.m);
        embed(&s.m, m, M::NQ, Self::NQ, 1.0);
    }

    fn dynamics(&self, t: f64, q: &[f64], qd: &[f64], u: &[f64], m: &mut [f64], h: &mut [f64]) {
        let n = M::NQ;
        let s = &mut *self.scratch.borrow_mut();
        self.model
            .dynamics(t, &q[..n], &qd[..n], u, &mut s.m, &mut s.h);
        embed(&s.m, m, n, Self::NQ, 1.0);
        if !self.user(s, t, q, qd, u, false) {
            h.fill(f64::NAN);
            return;
        }
        for i in 0..n {
            h[i] = s.h[i] + s.qg[i];
        }
        h[n..].copy_from_slice(&s.xd);
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
        let n = M::NQ;
        let s = &mut *self.scratch.borrow_mut();
        self.model
            .inverse_dynamics(t, &q[..n], &qd[..n], &qdd[..n], u, &mut tau[..n]);
        if !self.user(s, t, q, qd, u, false) {
            tau.fill(f64::NAN);
            return;
        }
        form_tau::<E>(tau, qdd, &s.qg, &s.xd);
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
        let (n, big) = (M::NQ, Self::NQ);
        let s = &mut *self.scratch.borrow_mut();
        self.model
            .tangents(t, &q[..n], &qd[..n], &qdd[..n], u, &mut s.k, &mut s.c)?;
        embed(&s.k, k, n, big, 0.0);
        embed(&s.c, c, n, big, 0.0);
        // the user part by forward differences: −∂Q/∂q, −∂ẋ/∂q (and qd)
        if !self.user(s, t, q, qd, u, false) {
            k.fill(f64::NAN);
            return Ok(());
        }
        let (mut qp, mut vp) = (std::mem::take(&mut s.qp), std::mem::take(&mut s.vp));
        qp.copy_from_slice(q);
        vp.copy_from_slice(qd);
        let mut ok = true;
        for (j, rate) in moved_columns(n, big) {
            let moved = if rate { &mut vp } else { &mut qp };
            let x = moved[j];
            let eps = increment(x);
            moved[j] = x + eps;
            ok = self.user_moved(s, t, &qp, &vp, u, j);
            let moved = if rate { &mut vp } else { &mut qp };
            moved[j] = x;
            if !ok {
                break;
            }
            let out = if rate { &mut *c } else { &mut *k };
            for i in 0..n {
                out[i + big * j] -= (s.qg1[i] - s.qg[i]) / eps;
            }
            for r in 0..E::NX {
                out[n + r + big * j] -= (s.xd1[r] - s.xd[r]) / eps;
            }
        }
        (s.qp, s.vp) = (qp, vp);
        if !ok {
            k.fill(f64::NAN);
        }
        Ok(())
    }

    /// τ differenced as the default does, to the same numbers, with less work: the columns
    /// of the extra states' integrals are zero without an evaluation (nothing reads them),
    /// and those of the extra states call the user part alone, on the wrapped model's
    /// kinematics and τ at the unchanged (q, qd). Returns the wrapped model's evaluations of
    /// τ, 2·NQ_M + 1; the user part's, 2·NQ_M + NX + 1, are counted in `Stats::user_efforts`.
    fn differenced_tangents(
        &self,
        t: f64,
        [q, qd, qdd]: [&[f64]; 3],
        u: &[f64],
        [k, c]: [&mut [f64]; 2],
        work: DifferenceBuffers<'_>,
    ) -> usize {
        let (n, big) = (M::NQ, Self::NQ);
        let DifferenceBuffers {
            tau0, tau1, qp, vp, ..
        } = work;
        let s = &mut *self.scratch.borrow_mut();
        if !self.differences_base(s, t, [q, qd, qdd], u, tau0) {
            k.fill(f64::NAN);
            c.fill(f64::NAN);
            return 1;
        }
        qp.copy_from_slice(q);
        vp.copy_from_slice(qd);
        for j in n..big {
            k[big * j..big * (j + 1)].fill(0.0);
        }
        for (j, rate) in moved_columns(n, big) {
            let moved = if rate { &mut *vp } else { &mut *qp };
            let x = moved[j];
            let eps = increment(x);
            moved[j] = x + eps;
            let ok = self.moved_tau(s, t, [qp, vp, qdd], u, j, tau1);
            let moved = if rate { &mut *vp } else { &mut *qp };
            moved[j] = x;
            if !ok {
                k.fill(f64::NAN);
                c.fill(f64::NAN);
                return 1 + 2 * n;
            }
            let out = if rate { &mut *c } else { &mut *k };
            for i in 0..big {
                out[i + big * j] = (tau1[i] - tau0[i]) / eps;
            }
        }
        1 + 2 * n
    }

    /// The iteration matrix differenced as the default does, to the same numbers, with less
    /// work (as [`Model::differenced_tangents`]): an extra state's column moves its integral,
    /// which nothing reads, its value and its rate, and calls the user part alone. Returns the
    /// wrapped model's evaluations of τ, NQ_M + 1; the user part's, NQ + 1, are counted in
    /// `Stats::user_efforts`.
    fn differenced_iteration_matrix(
        &self,
        t: f64,
        [q, qd, qdd]: [&[f64]; 3],
        u: &[f64],
        [beta, gamma]: [f64; 2],
        a: &mut [f64],
        work: DifferenceBuffers<'_>,
    ) -> usize {
        let (n, big) = (M::NQ, Self::NQ);
        let DifferenceBuffers {
            tau0,
            tau1,
            qp,
            vp,
            ap,
        } = work;
        let s = &mut *self.scratch.borrow_mut();
        if !self.differences_base(s, t, [q, qd, qdd], u, tau0) {
            a.fill(f64::NAN);
            return 1;
        }
        qp.copy_from_slice(q);
        vp.copy_from_slice(qd);
        ap.copy_from_slice(qdd);
        // the extra states first, on the kinematics of the unmoved state
        for j in (n..big).chain(0..n) {
            let ok = iteration_column(
                j,
                [q, qd, qdd],
                [beta, gamma],
                [&mut *qp, &mut *vp, &mut *ap],
                (tau0, &mut *tau1),
                &mut a[big * j..big * (j + 1)],
                |moved, tau1| self.moved_tau(s, t, moved, u, j, tau1),
            );
            if !ok {
                a.fill(f64::NAN);
                return 1 + n;
            }
        }
        1 + n
    }

    /// At rest: the wrapped model's velocities are zero and the extra states x are read from
    /// their coordinates' positions `q[NQ_M + k]` ([`Model::first_order_states`]); their rows
    /// are ẋ, which statics drives to zero with the forces.
    fn static_forces(&self, t: f64, q: &[f64], u: &[f64], h: &mut [f64]) {
        let n = M::NQ;
        let s = &mut *self.scratch.borrow_mut();
        self.model.static_forces(t, &q[..n], u, &mut s.h);
        s.vp.fill(0.0);
        s.vp[n..].copy_from_slice(&q[n..]);
        let vp = std::mem::take(&mut s.vp);
        let ok = self.user(s, t, q, &vp, u, false);
        s.vp = vp;
        if !ok {
            h.fill(f64::NAN);
            return;
        }
        for i in 0..n {
            h[i] = s.h[i] + s.qg[i];
        }
        h[n..].copy_from_slice(&s.xd);
    }

    fn input_matrix(&self, t: f64, q: &[f64], qd: &[f64], u: &[f64], b: &mut [f64]) {
        let (n, big, nu) = (M::NQ, Self::NQ, M::NU);
        let s = &mut *self.scratch.borrow_mut();
        self.model.input_matrix(t, &q[..n], &qd[..n], u, &mut s.bu);
        for j in 0..nu {
            for i in 0..big {
                b[i + big * j] = if i < n { s.bu[i + n * j] } else { 0.0 };
            }
        }
        if !self.user(s, t, q, qd, u, false) {
            b.fill(f64::NAN);
            return;
        }
        s.up.copy_from_slice(u);
        for j in 0..nu {
            let x = u[j];
            let eps = increment(x);
            s.up[j] = x + eps;
            let up = std::mem::take(&mut s.up);
            let ok = self.user(s, t, q, qd, &up, true);
            s.up = up;
            s.up[j] = x;
            if !ok {
                b.fill(f64::NAN);
                return;
            }
            for i in 0..n {
                b[i + big * j] += (s.qg1[i] - s.qg[i]) / eps;
            }
            for r in 0..E::NX {
                b[n + r + big * j] += (s.xd1[r] - s.xd[r]) / eps;
            }
        }
    }

    fn energy(&self, t: f64, q: &[f64], qd: &[f64]) -> Energy {
        let n = M::NQ;
        self.model.energy(t, &q[..n], &qd[..n])
    }

    fn power(&self, t: f64, q: &[f64], qd: &[f64], u: &[f64]) -> f64 {
        let n = M::NQ;
        let p = self.model.power(t, &q[..n], &qd[..n], u);
        let s = &mut *self.scratch.borrow_mut();
        if !self.user(s, t, q, qd, u, false) {
            return f64::NAN;
        }
        p + (0..n).map(|i| s.qg[i] * qd[i]).sum::<f64>()
    }

    fn constraints(&self, t: f64, q: &[f64], phi: &mut [f64]) {
        self.model.constraints(t, &q[..M::NQ], phi);
    }

    fn constraint_jacobian(&self, t: f64, q: &[f64], b: &mut [f64]) {
        let (n, nc) = (M::NQ, M::NC);
        let s = &mut *self.scratch.borrow_mut();
        self.model.constraint_jacobian(t, &q[..n], &mut s.b);
        b[..nc * n].copy_from_slice(&s.b);
        b[nc * n..].fill(0.0);
    }

    fn constraint_rate(&self, t: f64, q: &[f64], phi_t: &mut [f64]) {
        self.model.constraint_rate(t, &q[..M::NQ], phi_t);
    }

    fn constraint_bias(&self, t: f64, q: &[f64], qd: &[f64], gamma: &mut [f64]) {
        let n = M::NQ;
        self.model.constraint_bias(t, &q[..n], &qd[..n], gamma);
    }

    fn constraint_tangent(&self, t: f64, q: &[f64], lambda: &[f64], k: &mut [f64]) {
        let n = M::NQ;
        let s = &mut *self.scratch.borrow_mut();
        self.model.constraint_tangent(t, &q[..n], lambda, &mut s.k);
        embed(&s.k, k, n, Self::NQ, 0.0);
    }

    fn frames(&self, t: f64, q: &[f64], out: &mut [Pose]) {
        self.model.frames(t, &q[..M::NQ], out);
    }

    fn kinematics(&self, t: f64, q: &[f64], qd: &[f64], out: &mut Kinematics) {
        let n = M::NQ;
        self.model.kinematics(t, &q[..n], &qd[..n], out);
    }

    fn motion(&self, t: f64, q: &[f64], qd: &[f64], out: &mut Kinematics) {
        let n = M::NQ;
        self.model.motion(t, &q[..n], &qd[..n], out);
    }

    fn take_failure(&self) -> Option<Failure> {
        self.failure.borrow_mut().take()
    }

    // the efforts written in Rust are differenced (forward) within `tangents`
    fn tangents_exact(&self) -> bool {
        false
    }

    fn first_order_states(&self) -> usize {
        E::NX
    }

    fn user_evaluations(&self) -> usize {
        self.evaluations.get()
    }

    fn chart(&self, joint: usize) -> [[f64; 3]; 3] {
        self.model.chart(joint)
    }

    fn set_chart(&mut self, joint: usize, r: [[f64; 3]; 3]) {
        self.model.set_chart(joint, r);
    }
}

/// τ as [`WithEfforts`] forms it from the wrapped model's part, already in `tau[..n]`, and the
/// user part's generalised forces `qg` and rates `xd`: τ − Q, and qdd − ẋ for the states.
fn form_tau<E: Efforts>(tau: &mut [f64], qdd: &[f64], qg: &[f64], xd: &[f64]) {
    let n = qg.len();
    for i in 0..n {
        tau[i] -= qg[i];
    }
    for r in 0..E::NX {
        tau[n + r] = qdd[n + r] - xd[r];
    }
}

/// The columns a wrapper of n coordinates and big − n extra states differences, as (column,
/// whether its rate moves): the extra states' rates first (they reuse the kinematics of the
/// unmoved state, which the wrapped model's columns overwrite), then the wrapped model's
/// positions and rates; not the extra states' integrals, which nothing reads.
fn moved_columns(n: usize, big: usize) -> impl Iterator<Item = (usize, bool)> {
    (n..big)
        .map(|j| (j, true))
        .chain((0..n).flat_map(|j| [(j, false), (j, true)]))
}

/// An n × n matrix into the top-left of a big × big one, `diag` on the rest of the diagonal
/// and zero elsewhere.
fn embed(inner: &[f64], out: &mut [f64], n: usize, big: usize, diag: f64) {
    for j in 0..big {
        for i in 0..big {
            out[i + big * j] = if i < n && j < n {
                inner[i + n * j]
            } else if i == j {
                diag
            } else {
                0.0
            };
        }
    }
}
