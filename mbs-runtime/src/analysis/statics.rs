//! Static equilibrium (EasyDyn's StaticEquilibrium): Newton on the velocity-free forces
//! h(q, 0, t, u) = 0 with the stiffness K = ∂τ/∂q at rest (exact tangents, or central
//! differences of the static forces), a backtracking line search on ‖h‖, and coordinates that
//! can be held at their starting value (EasyDyn's `doflocked`). The stability of the
//! equilibrium is read from the eigenvalues of the stiffness restricted to the free coordinates.
//!
//! With constraints (`M::NC > 0`) the unknowns are the free coordinates and the multipliers
//! λ: Newton on h(q, 0) + Bᵀλ = 0 (free rows) and Φ(q, t) = 0, with the Jacobian
//! `[−K + ∂(Bᵀλ)/∂q, Bᵀ; B, 0]` over the free coordinates (∂(Bᵀλ)/∂q is the generated
//! `constraint_tangent`, exact; K as above), λ started at the least-squares fit of Bᵀλ = −h,
//! and a backtracking line search on ‖h + Bᵀλ‖∞ + μ‖Φ‖∞ (μ = ‖K − ∂(Bᵀλ)/∂q‖∞/‖B‖∞ over the
//! free coordinates, which turns a constraint violation into the force that closing it
//! costs). The stability is read from the reduced stiffness Nᵀ(K − ∂(Bᵀλ)/∂q)N, N an
//! orthonormal basis of the null space of B over the free coordinates (one column per
//! degree of freedom of the mechanism): the Hessian of the potential on the constraint
//! manifold, where the curvature of the constraints enters through λ. Everything is exact
//! except K without tangents.
//!
//! First-order states riding as velocities (the extra states x of [`crate::WithEfforts`]: a
//! motor's current, a muscle's activation; [`Model::first_order_states`]) are unknowns too:
//! read from their coordinates' positions, with ẋ = 0 as their equations (their integrals
//! mean nothing at rest), so `Equilibrium::q` holds them there; without `q0` they start from
//! their initial values. Without constraints the stability is then read from the stiffness
//! of the mechanical coordinates with the states condensed out (settled at each
//! configuration), with constraints from the reduced stiffness of the mechanical coordinates
//! with the states condensed out alike.

use super::{AnalysisError, check, reduce};
use crate::error::Failure;
use crate::linalg::{Lu, Singular};
use crate::model::Model;
use crate::options::IterationMatrix;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;
use std::fmt;

/// Options of [`static_equilibrium`].
#[derive(Clone, Debug)]
pub struct StaticsOptions {
    /// time at which forces are evaluated (s), default 0
    pub t: f64,
    /// starting coordinates (default: the model's declared initial q)
    pub q0: Option<Vec<f64>>,
    /// inputs u (default 0)
    pub u: Option<Vec<f64>>,
    /// indices of coordinates held at their starting value (default none)
    pub locked: Vec<usize>,
    /// converged when every free generalised force (with the constraint forces Bᵀλ) is
    /// below this (N or N·m), default 1e-9; or, where the forces' rounding is above it (stiff
    /// springs), when Newton's correction moves no free coordinate by more than 100 ε of its
    /// value (`Equilibrium::residual` then says what was left)
    pub tolerance: f64,
    /// constrained models: and every |Φ_i| below this (m or rad), default 1e-11
    pub constraint_tolerance: f64,
    /// and Newton's correction at `q` moves no free coordinate by more than this (m or rad),
    /// or than 100 ε of its value, default 1e-10: a small force does not mean a near
    /// equilibrium where the stiffness is small too (a spring of 5e-7 N/m started 1 mm off
    /// pulls with 5e-10 N, which the force test alone accepted as converged)
    pub step_tolerance: f64,
    /// Newton iterations before `NotConverged` (default 50)
    pub max_iterations: usize,
    /// how the stiffness is obtained: exact tangents (`Exact`, or `Auto` when generated), or
    /// central differences of the static forces (`FiniteDifferences`, `Auto` without
    /// tangents, and `MassOnly`: statics has no use for M alone)
    pub stiffness: IterationMatrix,
}

impl Default for StaticsOptions {
    fn default() -> Self {
        StaticsOptions {
            t: 0.0,
            q0: None,
            u: None,
            locked: Vec::new(),
            tolerance: 1e-9,
            constraint_tolerance: 1e-11,
            step_tolerance: 1e-10,
            max_iterations: 50,
            stiffness: IterationMatrix::Auto,
        }
    }
}

/// The nature of an equilibrium from its stiffness.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Stability {
    /// every stiffness eigenvalue positive: a minimum of the potential
    Stable,
    /// some eigenvalue negative: a small push grows
    Unstable,
    /// no negative eigenvalue but some zero (within 1e-12 of the largest with exact
    /// tangents, 1e-9 with central differences, 1e-7 when part of the tangents is forward
    /// differences, as [`crate::WithEfforts`]' efforts written in Rust): neutral directions
    Neutral,
}

/// A static equilibrium and how it was found.
#[derive(Clone, Debug, Serialize)]
#[non_exhaustive]
pub struct Equilibrium {
    pub q: Vec<f64>,
    /// largest |h| over the free coordinates at `q` (|h + Bᵀλ| with constraints)
    pub residual: f64,
    pub iterations: usize,
    /// the largest move of a free coordinate (m or rad) in Newton's correction at `q`: how far
    /// `q` may be from the equilibrium; `None` where the stiffness at `q` does not factor
    /// (a neutral direction, its forces within the tolerance)
    pub correction: Option<f64>,
    /// names of the free coordinates
    pub free: Vec<String>,
    /// eigenvalues of the (symmetrised) stiffness on the free coordinates, ascending (free
    /// first-order states condensed out, so one per free mechanical coordinate); with
    /// constraints, of the reduced stiffness Nᵀ(K − ∂(Bᵀλ)/∂q)N on the constraint manifold,
    /// one per degree of freedom left (free mechanical coordinates − constraints, the states
    /// condensed out likewise)
    pub stiffness_eigenvalues: Vec<f64>,
    pub stability: Stability,
    /// names of the constraints (empty without constraints)
    pub constraint_names: Vec<String>,
    /// the multipliers at `q`, one per constraint: for `coincide(a, b, along = [x])` the
    /// force along x that the closure applies to b
    pub lambda: Vec<f64>,
    /// largest |Φ_i| at `q` (0 without constraints)
    pub constraint_residual: f64,
    /// the charts of the rotation joints (`Tball`, `Tfree`) `q` is read in: centred on each
    /// joint's orientation at the start, and again on the equilibrium's if Newton took a
    /// joint towards its chart's gimbal lock (empty without rotation joints)
    pub charts: Vec<[[f64; 3]; 3]>,
}

impl Equilibrium {
    /// λ of the constraint `name` (`pin.x`, …).
    pub fn lambda_of(&self, name: &str) -> Option<f64> {
        let i = self.constraint_names.iter().position(|n| n == name)?;
        Some(self.lambda[i])
    }
}

impl fmt::Display for Equilibrium {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "static equilibrium ({:?}) after {} iterations, residual {:.2e}, {}",
            self.stability,
            self.iterations,
            self.residual,
            match self.correction {
                Some(c) => format!("Newton's correction {c:.2e}"),
                None => "no Newton correction (singular stiffness)".into(),
            }
        )?;
        if !self.constraint_names.is_empty() {
            write!(f, "max |Φ| {:.2e}, λ:", self.constraint_residual)?;
            for (n, l) in self.constraint_names.iter().zip(&self.lambda) {
                write!(f, " {n} = {l:.6e}")?;
            }
            writeln!(f)?;
        }
        write!(f, "stiffness eigenvalues:")?;
        if self.stiffness_eigenvalues.is_empty() {
            write!(f, " none (no degree of freedom left)")?;
        }
        for e in &self.stiffness_eigenvalues {
            write!(f, " {e:.6e}")?;
        }
        Ok(())
    }
}

/// h(q, 0, t, u) at q.
fn forces<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
    u: &[f64],
    h: &mut [f64],
) -> Result<(), AnalysisError> {
    model.static_forces(t, q, u, h);
    check(model, "static generalized force", h)
}

/// The stiffness K = ∂τ/∂q at rest (column-major NQ × NQ): exact when the model has tangents
/// and `how` allows, else central differences of −h(q, 0).
pub(super) fn stiffness<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
    u: &[f64],
    how: IterationMatrix,
    k: &mut [f64],
) -> Result<(), AnalysisError> {
    let n = M::NQ;
    let zero = vec![0.0; n];
    if exact_stiffness(model, how) {
        // first-order states are read from their positions: their rates at the state, and
        // their columns of K those of C
        let f0 = n - model.first_order_states();
        let mut qd = zero.clone();
        qd[f0..].copy_from_slice(&q[f0..]);
        let mut c = vec![0.0; n * n];
        model
            .tangents(t, q, &qd, &zero, u, k, &mut c)
            .map_err(|e| Failure::InvalidOption {
                name: "stiffness",
                value: "Exact".into(),
                reason: crate::integrators::model_error_reason(&e),
            })?;
        k[n * f0..].copy_from_slice(&c[n * f0..]);
        return check(model, "stiffness", k);
    }
    let (mut qp, mut column) = (q.to_vec(), vec![0.0; n]);
    for j in 0..n {
        super::central_difference(q[j], &mut column, |x, h| {
            qp[j] = x;
            forces(model, t, &qp, u, h)
        })?;
        qp[j] = q[j];
        for i in 0..n {
            // τ = −h at rest
            k[i + n * j] = -column[i];
        }
    }
    Ok(())
}

/// The symmetrised stiffness over the free coordinates, the free first-order states
/// ([`Model::first_order_states`]) condensed out: K_mm − K_ms K_ss⁻¹ K_sm, the stiffness of
/// the mechanical coordinates when the states settle at each configuration (a motor's current
/// at V/R, a muscle's activation at its excitation), which decides whether a small push
/// grows; the whole K where K_ss is singular.
fn condensed<M: Model>(model: &M, k: &[f64], free: &[usize]) -> DMatrix<f64> {
    let n = M::NQ;
    let f0 = n - model.first_order_states();
    let full = DMatrix::from_fn(free.len(), free.len(), |r, c| k[free[r] + n * free[c]]);
    let mech: Vec<usize> = (0..free.len()).filter(|&i| free[i] < f0).collect();
    let states: Vec<usize> = (0..free.len()).filter(|&i| free[i] >= f0).collect();
    let part = |rows: &[usize], cols: &[usize]| {
        DMatrix::from_fn(rows.len(), cols.len(), |r, c| full[(rows[r], cols[c])])
    };
    let kept = if states.is_empty() {
        full
    } else {
        match part(&states, &states).lu().solve(&part(&states, &mech)) {
            Some(x) if x.iter().all(|v| v.is_finite()) => {
                part(&mech, &mech) - part(&mech, &states) * x
            }
            _ => full,
        }
    };
    (&kept + kept.transpose()) * 0.5
}

/// The relative error of the K that [`stiffness`] takes: rounding (a part in 10¹²) for exact
/// tangents; about √ε ≈ 1.5e-8 where a part is forward differences (a wrapper's efforts
/// written in Rust, [`Model::tangents_exact`]), a part in 10⁷ with a margin; a part in 10⁹ for
/// central differences (their truncation and rounding, about ε^⅔ ≈ 4e-11, with a margin).
fn stiffness_error<M: Model>(model: &M, how: IterationMatrix) -> f64 {
    match (exact_stiffness(model, how), model.tangents_exact()) {
        (true, true) => 1e-12,
        (true, false) => 1e-7,
        (false, _) => 1e-9,
    }
}

/// Whether [`stiffness`] takes K from the exact tangents (else from differences).
fn exact_stiffness<M: Model>(model: &M, how: IterationMatrix) -> bool {
    match how {
        IterationMatrix::Exact => true,
        IterationMatrix::Auto => model.info().has_tangents,
        _ => false,
    }
}

/// The inputs of `options` (zero when not given), after checking what statics and its
/// sensitivities read of them: t and u finite, u of the model's size, locked coordinates of
/// the model, tolerances > 0 and iterations > 0, each by its own name.
pub(super) fn checked_inputs<M: Model>(
    options: &StaticsOptions,
) -> Result<Vec<f64>, AnalysisError> {
    let invalid = |name: &'static str, value: String, reason: &'static str| {
        Err(AnalysisError::from(Failure::InvalidOption {
            name,
            value,
            reason,
        }))
    };
    let u = options.u.clone().unwrap_or_else(|| vec![0.0; M::NU]);
    if u.len() != M::NU {
        return invalid(
            "u",
            format!("{} values", u.len()),
            "must have one value per input",
        );
    }
    if let Some(v) = u.iter().find(|v| !v.is_finite()) {
        return invalid("u", v.to_string(), "must be finite");
    }
    if !options.t.is_finite() {
        return invalid("t", options.t.to_string(), "must be finite");
    }
    if let Some(&i) = options.locked.iter().find(|&&i| i >= M::NQ) {
        return invalid("locked", i.to_string(), "is not a coordinate index");
    }
    if !(options.tolerance > 0.0 && options.tolerance.is_finite()) {
        return invalid(
            "tolerance",
            options.tolerance.to_string(),
            "must be > 0 and finite",
        );
    }
    if !(options.step_tolerance > 0.0 && options.step_tolerance.is_finite()) {
        return invalid(
            "step_tolerance",
            options.step_tolerance.to_string(),
            "must be > 0 and finite",
        );
    }
    if M::NC > 0
        && !(options.constraint_tolerance > 0.0 && options.constraint_tolerance.is_finite())
    {
        return invalid(
            "constraint_tolerance",
            options.constraint_tolerance.to_string(),
            "must be > 0 and finite",
        );
    }
    if options.max_iterations == 0 {
        return invalid("max_iterations", "0".into(), "must be at least 1");
    }
    Ok(u)
}

/// Finds q with h(q, 0, t, u) = 0 on the free coordinates, from `options.q0`; with
/// constraints, q and λ with h(q, 0, t, u) + Bᵀλ = 0 on the free coordinates and Φ(q, t) = 0.
/// Rotation joints (`Tball`, `Tfree`) whose angles are free are solved for in charts centred
/// on their orientation at `q0` (`q0` read in the model's charts); when Newton ends a joint
/// far from its chart's centre (|cos b| < 0.5), it starts again there in a chart centred on
/// it ([`Equilibrium::charts`]).
pub fn static_equilibrium<M: Model + Clone>(
    model: &M,
    options: &StaticsOptions,
) -> Result<Equilibrium, AnalysisError> {
    let n = M::NQ;
    let invalid = |name: &'static str, value: String, reason: &'static str| {
        AnalysisError::from(Failure::InvalidOption {
            name,
            value,
            reason,
        })
    };
    let q = match &options.q0 {
        Some(q0) if q0.len() != n => {
            return Err(invalid(
                "q0",
                q0.len().to_string(),
                "must have one value per coordinate",
            ));
        }
        Some(q0) => q0.clone(),
        None => {
            let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
            model.initial_state(&mut q, &mut qd);
            // first-order states start from their initial values
            let f0 = n - model.first_order_states();
            q[f0..].copy_from_slice(&qd[f0..]);
            q
        }
    };
    let u = checked_inputs::<M>(options)?;
    check(model, "q0", &q)?;
    let free: Vec<usize> = (0..n).filter(|i| !options.locked.contains(i)).collect();
    let solve = |model: &M, q: Vec<f64>| {
        if M::NC == 0 {
            unconstrained(model, options, q, &u, &free)
        } else {
            constrained(model, options, q, &u, &free)
        }
    };
    // a singular stiffness names the parameters that, set back to their default alone, let
    // statics find an equilibrium from the same start (as a run's start names them)
    let blamed = |e: AnalysisError, model: &M, q: &[f64]| {
        let found = |m: &M| solve(m, q.to_vec()).is_ok();
        let what = "an equilibrium is found from this start";
        super::singular_blamed(e, None, model, found, what)
    };
    if model.info().rotation_joints.is_empty() {
        return solve(model, q.clone()).map_err(|e| blamed(e, model, &q));
    }
    let mut centred = model.clone();
    let (mut q, mut zero) = (q, vec![0.0; n]);
    crate::charts::recentre(&mut centred, &mut q, &mut zero, &options.locked);
    // a failure's q is read in the model's charts, where a retry from it starts
    let mut eq = solve(&centred, q.clone()).map_err(|mut e| {
        if let AnalysisError::NotConverged { q, .. } = &mut e {
            crate::charts::reread_angles(&centred, model, q);
        }
        blamed(e, &centred, &q)
    })?;
    // a restart or two, each from a chart centred on where Newton went; a restart that fails
    // leaves the equilibrium found (converged, in a chart far from its centre)
    for _ in 0..3 {
        if !crate::charts::below(&centred, &eq.q, 0.5) {
            break;
        }
        let mut q = eq.q.clone();
        let before = centred.clone();
        crate::charts::recentre(&mut centred, &mut q, &mut zero, &options.locked);
        match solve(&centred, q) {
            Ok(restarted) => {
                let done = eq.iterations;
                eq = restarted;
                eq.iterations += done;
            }
            Err(_) => {
                centred = before;
                break;
            }
        }
    }
    eq.charts = crate::charts::charts_of(&centred);
    Ok(eq)
}

fn unconstrained<M: Model>(
    model: &M,
    options: &StaticsOptions,
    mut q: Vec<f64>,
    u: &[f64],
    free: &[usize],
) -> Result<Equilibrium, AnalysisError> {
    let n = M::NQ;
    let info = model.info();
    let nf = free.len();
    let (mut h, mut k, mut trial, mut ht) =
        (vec![0.0; n], vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
    let mut lu = Lu::<f64>::new(nf);
    let mut mass = vec![0.0; n * n];
    let norm = |h: &[f64]| free.iter().map(|&i| h[i].abs()).fold(0.0, f64::max);
    forces(model, options.t, &q, u, &mut h)?;
    let mut residual = norm(&h);
    let mut iterations = 0;
    let mut delta = vec![0.0; nf];
    // Newton's correction at the q returned (None where K does not factor there)
    let correction = loop {
        let small = residual <= options.tolerance;
        if !small && iterations == options.max_iterations {
            return Err(AnalysisError::NotConverged {
                iterations,
                residual,
                constraint_residual: 0.0,
                q,
            });
        }
        stiffness(model, options.t, &q, u, options.stiffness, &mut k)?;
        let mut singular = None;
        // K on the free coordinates, with μD added to its diagonal (`extra`)
        let fill = |lu: &mut Lu<f64>, extra: &[f64]| {
            let a = lu.matrix_mut();
            for (c, &j) in free.iter().enumerate() {
                for (r, &i) in free.iter().enumerate() {
                    a[r + nf * c] = k[i + n * j];
                }
                a[c + nf * c] += extra.get(c).copied().unwrap_or(0.0);
            }
            lu.factor()
        };
        if let Err(s) = fill(&mut lu, &[]) {
            // a neutral direction at a point whose forces are within the tolerance, or within
            // their rounding (the 6-joint arm, its first axis along gravity, 1000 t at its
            // tip: 2e-9 N·m left, its forces' rounding, where the tolerance is 1e-9)
            if small || forces_at_rounding(residual, &k, &q, free) {
                break None;
            }
            // a neutral direction at a point that is not yet an equilibrium (the double
            // pendulum's default start, both bars horizontal, where K = 0; an arm whose first
            // axis is vertical): a step of Levenberg–Marquardt instead
            model.mass_matrix(options.t, &q, &mut mass);
            let size_k = free
                .iter()
                .flat_map(|&j| free.iter().map(move |&i| (j, i)))
                .fold(0.0, |m: f64, (j, i)| m.max(k[i + n * j].abs()));
            let hf: Vec<f64> = free.iter().map(|&i| h[i]).collect();
            let regular = factor_damped(&mut lu, (&mass, n), free, size_k, &hf, fill);
            let error = Failure::SingularMatrix {
                matrix: "the stiffness K on the free coordinates (no restoring force along some direction, and a damped step along the forces lowers them no further: no equilibrium near this start, or one that needs a coordinate locked)",
                rcond: s.rcond,
                coordinates: vec![info.dof_label(free[s.column])],
                cause: String::new(),
            };
            if !regular {
                return Err(error.into());
            }
            // said if the damped step does not lower the forces either
            singular = Some(error);
        }
        // K δ = h (τ = −h at rest: h(q + δ) ≈ h − K δ)
        for (d, &i) in delta.iter_mut().zip(free) {
            *d = h[i];
        }
        lu.solve(&mut delta);
        let size = reduce::worst(&delta).0;
        if small && (within_step(&delta, &q, free, options) || iterations == options.max_iterations)
            || singular.is_none() && at_rounding(&delta, &q, free)
        {
            break Some(size);
        }
        iterations += 1;
        // backtracking on ‖h‖∞
        let accepted = backtrack(|alpha| {
            trial.copy_from_slice(&q);
            for (c, &i) in free.iter().enumerate() {
                trial[i] += alpha * delta[c];
            }
            let ok = forces(model, options.t, &trial, u, &mut ht).is_ok();
            ok && norm(&ht) < residual * (1.0 - 1e-4 * alpha)
        });
        if !accepted {
            // the forces cannot fall further: at their rounding when they are within the
            // tolerance, the correction then saying how far q may be
            if small || singular.is_none() && forces_at_rounding(residual, &k, &q, free) {
                break Some(size);
            }
            if let Some(error) = singular {
                return Err(error.into());
            }
            return Err(AnalysisError::NotConverged {
                iterations,
                residual,
                constraint_residual: 0.0,
                q,
            });
        }
        q.copy_from_slice(&trial);
        h.copy_from_slice(&ht);
        residual = norm(&h);
    };
    // stability from the symmetrised stiffness on the free coordinates (k is K at q), the
    // free first-order states condensed out (settled at each configuration)
    let ks = condensed(model, &k, free);
    let error = stiffness_error(model, options.stiffness);
    let (stiffness_eigenvalues, stability) = classify(&ks, error);
    Ok(Equilibrium {
        q,
        residual,
        iterations,
        correction,
        free: free.iter().map(|&i| info.dof_label(i)).collect(),
        stiffness_eigenvalues,
        stability,
        constraint_names: Vec::new(),
        lambda: Vec::new(),
        constraint_residual: 0.0,
        charts: Vec::new(),
    })
}

/// Factors into `lu` Newton's matrix with a damping μD added to the stiffness by `fill`, for
/// a step of Levenberg–Marquardt where the stiffness K itself is singular, (K + μD) δ = h;
/// false where no μ tried makes it regular. D is the diagonal of M over the free coordinates
/// (`mass`, NQ × NQ; 1 where it is not positive: a first-order state), μ the larger of 1e-8 of
/// K's size over D's and max |h_i/D_i| (so that where K = 0 the step moves no coordinate by
/// more than a unit: a radian, a metre), then ten and a hundred times that. Along a direction
/// with stiffness the step is Newton's damped by μ; along a neutral one it is the force over
/// μD, which a neutral direction's forces, zero at an equilibrium, leave small; as the forces
/// fall so does μ, and the steps become Newton's.
fn factor_damped(
    lu: &mut Lu<f64>,
    (mass, n): (&[f64], usize),
    free: &[usize],
    size_k: f64,
    forces: &[f64],
    mut fill: impl FnMut(&mut Lu<f64>, &[f64]) -> Result<(), Singular>,
) -> bool {
    let d: Vec<f64> = free
        .iter()
        .map(|&i| mass[i + n * i])
        .map(|m| if m > 0.0 && m.is_finite() { m } else { 1.0 })
        .collect();
    let size_d = d.iter().copied().fold(0.0, f64::max);
    let pull = forces
        .iter()
        .zip(&d)
        .map(|(f, d)| (f / d).abs())
        .fold(0.0, f64::max);
    let mu = (1e-8 * size_k / size_d).max(pull);
    if !(mu > 0.0 && mu.is_finite()) {
        return false;
    }
    [1.0, 10.0, 100.0].into_iter().any(|f| {
        let extra: Vec<f64> = d.iter().map(|d| f * mu * d).collect();
        fill(lu, &extra).is_ok()
    })
}

/// Newton's step scaled by α = 1, ½, ¼, … until `accept(α)` (false below α = 1e-6).
fn backtrack(mut accept: impl FnMut(f64) -> bool) -> bool {
    let mut alpha = 1.0;
    while alpha >= 1e-6 {
        if accept(alpha) {
            return true;
        }
        alpha *= 0.5;
    }
    false
}

/// Whether Newton's correction δ (over the free coordinates) moves each of them by no more
/// than 100 ε of its value, its rounding: the equilibrium is then q to the digits q has,
/// whatever forces are left. Beside a stiff spring the forces' own rounding is above an
/// absolute tolerance (the sprung arm with a 4e7 N/m spring stalled at 1.1e-9 N, its
/// correction 1e-17 of q, and statics said that no equilibrium was found).
fn at_rounding(delta: &[f64], q: &[f64], free: &[usize]) -> bool {
    delta
        .iter()
        .zip(free)
        .all(|(d, &i)| d.abs() <= 100.0 * f64::EPSILON * q[i].abs())
}

/// Whether the free forces left, which backtracking could not lower, are within their
/// rounding: 100 ε of the largest Σ_j |K_ij| |q_j| over the free coordinates, the size of the
/// terms a stiff spring's force is the difference of. Its rounding reaches the soft
/// coordinates too (the sprung arm with a 4e11 N/m spring: 5.3e-6 N·m left on its second
/// joint, whose correction of 1.7e-11 rad no step could take).
fn forces_at_rounding(residual: f64, k: &[f64], q: &[f64], free: &[usize]) -> bool {
    let n = q.len();
    let size = free
        .iter()
        .map(|&i| {
            free.iter()
                .map(|&j| (k[i + n * j] * q[j]).abs())
                .sum::<f64>()
        })
        .fold(0.0, f64::max);
    size.is_finite() && residual <= 100.0 * f64::EPSILON * size
}

/// Whether Newton's correction δ (over the free coordinates) moves none of them by more than
/// the step tolerance or 100 ε of its value (its rounding).
fn within_step(delta: &[f64], q: &[f64], free: &[usize], options: &StaticsOptions) -> bool {
    delta.iter().zip(free).all(|(d, &i)| {
        d.abs()
            <= options
                .step_tolerance
                .max(100.0 * f64::EPSILON * q[i].abs())
    })
}

/// Eigenvalues (ascending) of a symmetric stiffness and the stability they mean (`Stable`
/// with no eigenvalue: nothing left free to move). An eigenvalue counts as zero within the
/// stiffness' own relative error ([`stiffness_error`]) times its largest eigenvalue. Beside
/// a stiff spring the threshold was a part in 10⁹ for exact tangents too: with a 1e10 N/m
/// spring, an inverted pendulum's −0.49 N·m/rad was called neutral.
fn classify(ks: &DMatrix<f64>, error: f64) -> (Vec<f64>, Stability) {
    if ks.nrows() == 0 {
        return (Vec::new(), Stability::Stable);
    }
    let mut eig: Vec<f64> = ks.symmetric_eigenvalues().iter().copied().collect();
    eig.sort_by(f64::total_cmp);
    let scale = eig.iter().fold(0.0f64, |m, e| m.max(e.abs()));
    let zero = error * scale;
    let stability = if eig.iter().any(|&e| e < -zero) {
        Stability::Unstable
    } else if eig.iter().any(|&e| e <= zero) {
        Stability::Neutral
    } else {
        Stability::Stable
    };
    (eig, stability)
}

/// The residuals of the constrained statics at q, λ: F = (h + Bᵀλ) on the free coordinates
/// and Φ; with h and B at q.
struct ConstrainedState {
    h: Vec<f64>,
    b: DMatrix<f64>,
    f: Vec<f64>,
    phi: Vec<f64>,
}

impl ConstrainedState {
    fn new<M: Model>(
        model: &M,
        t: f64,
        q: &[f64],
        u: &[f64],
        lambda: &[f64],
        free: &[usize],
    ) -> Result<ConstrainedState, AnalysisError> {
        let mut h = vec![0.0; M::NQ];
        forces(model, t, q, u, &mut h)?;
        let b = reduce::jacobian(model, t, q)?;
        let phi = reduce::constraints(model, t, q)?;
        let mut s = ConstrainedState {
            h,
            b,
            f: Vec::new(),
            phi,
        };
        s.set_lambda(lambda, free);
        Ok(s)
    }

    fn set_lambda(&mut self, lambda: &[f64], free: &[usize]) {
        self.f = free
            .iter()
            .map(|&j| {
                self.h[j]
                    + (0..lambda.len())
                        .map(|i| self.b[(i, j)] * lambda[i])
                        .sum::<f64>()
            })
            .collect();
    }

    fn force_residual(&self) -> f64 {
        reduce::worst(&self.f).0
    }

    fn constraint_residual(&self) -> f64 {
        reduce::worst(&self.phi).0
    }
}

/// Newton on (q_free, λ); see the module documentation.
fn constrained<M: Model>(
    model: &M,
    options: &StaticsOptions,
    mut q: Vec<f64>,
    u: &[f64],
    free: &[usize],
) -> Result<Equilibrium, AnalysisError> {
    let (n, nc, t) = (M::NQ, M::NC, options.t);
    let info = model.info();
    let names = info.constraints;
    let nf = free.len();
    let locked_reason = "leaves the constraints no coordinates to satisfy them: B over the free coordinates has rank below the number of constraints (lock fewer coordinates)";
    if nf < nc {
        return Err(Failure::InvalidOption {
            name: "locked",
            value: format!("{:?}", options.locked),
            reason: locked_reason,
        }
        .into());
    }
    let restricted = |b: &DMatrix<f64>| b.select_columns(free);
    let mut st = ConstrainedState::new(model, t, &q, u, &vec![0.0; nc], free)?;
    // B must have full rank, and keep it over the free coordinates
    let rank = |b: &DMatrix<f64>| -> Result<(), AnalysisError> {
        reduce::rank_check(b, names)?;
        if reduce::rank_of(&restricted(b)).0 < nc {
            return Err(Failure::InvalidOption {
                name: "locked",
                value: format!("{:?}", options.locked),
                reason: locked_reason,
            }
            .into());
        }
        Ok(())
    };
    rank(&st.b)?;
    // λ₀: the least-squares fit of B_fᵀλ = −h_f
    let mut lambda = fitted_lambda(&st, free, names)?;
    st.set_lambda(&lambda, free);
    // K and ∂(Bᵀλ)/∂q at the last (q, λ) Newton was at, which the stability reads
    let mut k = vec![0.0; n * n];
    let mut g;
    let mut lu = Lu::<f64>::new(nf + nc);
    let mut mass = vec![0.0; n * n];
    let mut iterations = 0;
    let converged = |st: &ConstrainedState| {
        st.force_residual() <= options.tolerance
            && st.constraint_residual() <= options.constraint_tolerance
    };
    let mut delta = vec![0.0; nf + nc];
    // Newton's correction at the q returned (None where the Jacobian does not factor there)
    let correction = loop {
        let small = converged(&st);
        if !small && iterations == options.max_iterations {
            return Err(AnalysisError::NotConverged {
                iterations,
                residual: st.force_residual(),
                constraint_residual: st.constraint_residual(),
                q,
            });
        }
        stiffness(model, t, &q, u, options.stiffness, &mut k)?;
        g = reduce::constraint_tangent(model, t, &q, &lambda)?;
        let mut singular = None;
        // J = [−K + G, s B_fᵀ; s B_f, 0] over the free coordinates, the constraints' rows and
        // columns scaled by s to the size of the stiffness (and their unknowns δλ/s): a
        // stiff loop's Schur complement B K⁻¹ Bᵀ leaves pivots the factorisation takes for
        // singular otherwise (a four-bar with a 2e8 N·m/rad spring was refused as a singular
        // reduced stiffness)
        let m = nf + nc;
        let mut kg_norm = 0.0f64;
        for &i in free {
            let row = free
                .iter()
                .map(|&j| (-k[i + n * j] + g[(i, j)]).abs())
                .sum();
            kg_norm = kg_norm.max(row);
        }
        let b_norm = (0..nc)
            .map(|p| free.iter().map(|&j| st.b[(p, j)].abs()).sum::<f64>())
            .fold(0.0f64, f64::max);
        let scale = super::constraint_scale(kg_norm, b_norm);
        // with μD added to the stiffness' diagonal (`extra`): −μD in the block −K + G
        let fill = |lu: &mut Lu<f64>, extra: &[f64]| {
            let a = lu.matrix_mut();
            a.fill(0.0);
            for (r, &i) in free.iter().enumerate() {
                for (c, &j) in free.iter().enumerate() {
                    a[r + m * c] = -k[i + n * j] + g[(i, j)];
                }
                a[r + m * r] -= extra.get(r).copied().unwrap_or(0.0);
                for p in 0..nc {
                    a[r + m * (nf + p)] = scale * st.b[(p, i)];
                    a[(nf + p) + m * r] = scale * st.b[(p, i)];
                }
            }
            lu.factor()
        };
        if let Err(s) = fill(&mut lu, &[]) {
            if small
                || st.constraint_residual() <= options.constraint_tolerance
                    && forces_at_rounding(st.force_residual(), &k, &q, free)
            {
                break None;
            }
            // a neutral direction on the manifold at a point that is not yet an equilibrium
            // (pendulum3's default start): a step of Levenberg–Marquardt instead
            model.mass_matrix(t, &q, &mut mass);
            let regular = factor_damped(&mut lu, (&mass, n), free, kg_norm, &st.f, fill);
            let error = singular_reduced(model, options, free, &st.b, (&k, &g), s.rcond)?;
            if !regular {
                return Err(error);
            }
            // said if the damped step does not lower the residuals either
            singular = Some(error);
        }
        for (d, v) in delta.iter_mut().zip(st.f.iter().chain(&st.phi)) {
            *d = -v;
        }
        for d in &mut delta[nf..] {
            *d *= scale;
        }
        lu.solve(&mut delta);
        for d in &mut delta[nf..] {
            *d *= scale;
        }
        let size = reduce::worst(&delta[..nf]).0;
        if small
            && (within_step(&delta[..nf], &q, free, options)
                || iterations == options.max_iterations)
            || singular.is_none() && at_rounding(&delta[..nf], &q, free)
        {
            break Some(size);
        }
        iterations += 1;
        // backtracking on ‖F‖∞ + μ‖Φ‖∞, μ the same ratio of the blocks' sizes
        let merit = |st: &ConstrainedState| st.force_residual() + scale * st.constraint_residual();
        let current = merit(&st);
        let (mut trial, mut trial_lambda) = (q.clone(), lambda.clone());
        let damped = singular.is_some();
        let accepted = backtrack(|alpha| {
            trial.copy_from_slice(&q);
            for (c, &i) in free.iter().enumerate() {
                trial[i] += alpha * delta[c];
            }
            for p in 0..nc {
                trial_lambda[p] = lambda[p] + alpha * delta[nf + p];
            }
            // a damped step moves along the manifold's tangent, where the forces fall at
            // second order, as the constraints' residual grows: back onto it, λ fitted
            // there (pendulum3's default start, the rod horizontal, gravity's moment at its
            // largest: the merit did not fall)
            if damped {
                let back = onto_manifold(model, t, &mut trial, free).and_then(|_| {
                    let st = ConstrainedState::new(model, t, &trial, u, &trial_lambda, free)?;
                    fitted_lambda(&st, free, names)
                });
                match back {
                    Ok(fitted) => trial_lambda.copy_from_slice(&fitted),
                    Err(_) => return false,
                }
            }
            match ConstrainedState::new(model, t, &trial, u, &trial_lambda, free) {
                Ok(next) if merit(&next) < current * (1.0 - 1e-4 * alpha) => {
                    st = next;
                    true
                }
                _ => false,
            }
        });
        if !accepted {
            // the residuals cannot fall further: at their rounding when within the tolerances
            if small
                || singular.is_none()
                    && st.constraint_residual() <= options.constraint_tolerance
                    && forces_at_rounding(st.force_residual(), &k, &q, free)
            {
                break Some(size);
            }
            if let Some(error) = singular {
                return Err(error);
            }
            return Err(AnalysisError::NotConverged {
                iterations,
                residual: st.force_residual(),
                constraint_residual: st.constraint_residual(),
                q,
            });
        }
        q.copy_from_slice(&trial);
        lambda.copy_from_slice(&trial_lambda);
    };
    rank(&st.b)?;
    // stability from the reduced stiffness Nᵀ(K − G)N, N orthonormal over the free coordinates
    // (k and g are at q and λ), the free first-order states condensed out
    let kr = settled_reduced_stiffness(model, options, free, &st.b, (&k, &g))?;
    let error = stiffness_error(model, options.stiffness);
    let (stiffness_eigenvalues, stability) = classify(&kr, error);
    Ok(Equilibrium {
        residual: st.force_residual(),
        constraint_residual: st.constraint_residual(),
        q,
        iterations,
        free: free.iter().map(|&i| info.dof_label(i)).collect(),
        stiffness_eigenvalues,
        stability,
        constraint_names: names.iter().map(|s| s.to_string()).collect(),
        lambda,
        correction,
        charts: Vec::new(),
    })
}

/// λ by the least-squares fit of B_fᵀλ = −h_f at `st` (B and h over the free coordinates).
fn fitted_lambda(
    st: &ConstrainedState,
    free: &[usize],
    names: &[&str],
) -> Result<Vec<f64>, AnalysisError> {
    let bf = st.b.select_columns(free);
    let hf = DVector::from_iterator(free.len(), free.iter().map(|&i| st.h[i]));
    let rhs = -(&bf * hf);
    let lambda = (&bf * bf.transpose())
        .cholesky()
        .map(|c| c.solve(&rhs))
        .ok_or_else(|| AnalysisError::from(reduce::nearly_dependent(&st.b, names)))?;
    Ok(lambda.as_slice().to_vec())
}

/// Moves the free coordinates of q onto Φ(q, t) = 0 by Gauss–Newton with the least change,
/// δ = −B_fᵀ(B_f B_fᵀ)⁻¹Φ, until |Φ| stops falling (at most 20 iterations); `Err` where it
/// cannot (B_f losing rank, a non-finite Φ).
fn onto_manifold<M: Model>(
    model: &M,
    t: f64,
    q: &mut [f64],
    free: &[usize],
) -> Result<(), AnalysisError> {
    let mut last = f64::INFINITY;
    for _ in 0..20 {
        let phi = reduce::constraints(model, t, q)?;
        let size = phi.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        if size == 0.0 || size >= 0.5 * last {
            return Ok(());
        }
        last = size;
        let bf = reduce::jacobian(model, t, q)?.select_columns(free);
        let y = (&bf * bf.transpose())
            .cholesky()
            .map(|c| c.solve(&DVector::from_column_slice(&phi)))
            .ok_or(Failure::SingularMatrix {
                matrix: "B Bᵀ over the free coordinates",
                rcond: 0.0,
                coordinates: Vec::new(),
                cause: String::new(),
            })?;
        let dq = bf.transpose() * y;
        for (c, &i) in free.iter().enumerate() {
            q[i] -= dq[c];
        }
    }
    Ok(())
}

/// The symmetrised reduced stiffness Nᵀ(K − G)N over the free coordinates, and N (free ×
/// dof, orthonormal), from K and G = ∂(Bᵀλ)/∂q (`k`, column-major NQ × NQ, and `g`) at the
/// same q and λ.
fn reduced_stiffness<M: Model>(
    model: &M,
    options: &StaticsOptions,
    free: &[usize],
    b: &DMatrix<f64>,
    (k, g): (&[f64], &DMatrix<f64>),
) -> Result<(DMatrix<f64>, DMatrix<f64>), AnalysisError> {
    let n = M::NQ;
    let kf = DMatrix::from_fn(free.len(), free.len(), |r, c| {
        let (i, j) = (free[r], free[c]);
        k[i + n * j] - g[(i, j)]
    });
    reduced_stiffness_of(model, options, free, b, &kf)
}

/// The symmetrised Nᵀ kf N and N, N an orthonormal basis of the null space of B over the
/// coordinates `free` (kf over them too).
fn reduced_stiffness_of<M: Model>(
    model: &M,
    options: &StaticsOptions,
    free: &[usize],
    b: &DMatrix<f64>,
    kf: &DMatrix<f64>,
) -> Result<(DMatrix<f64>, DMatrix<f64>), AnalysisError> {
    let basis = reduce::orthonormal_null_basis(&b.select_columns(free)).ok_or_else(|| {
        AnalysisError::from(
            reduce::rank_check(b, model.info().constraints)
                .err()
                .unwrap_or(Failure::InvalidOption {
                    name: "locked",
                    value: format!("{:?}", options.locked),
                    reason: "leaves B over the free coordinates rank-deficient",
                }),
        )
    })?;
    let kr = basis.transpose() * kf * &basis;
    Ok(((&kr + kr.transpose()) * 0.5, basis))
}

/// [`reduced_stiffness`] with the free first-order states ([`Model::first_order_states`])
/// condensed out: the constraints do not read them (B's columns of the states are zero), so
/// K − G is condensed over the free coordinates as without constraints ([`condensed`]) and
/// reduced by N over the free mechanical coordinates; one eigenvalue per degree of freedom of
/// the mechanism. The whole reduced stiffness where K_ss is singular.
fn settled_reduced_stiffness<M: Model>(
    model: &M,
    options: &StaticsOptions,
    free: &[usize],
    b: &DMatrix<f64>,
    (k, g): (&[f64], &DMatrix<f64>),
) -> Result<DMatrix<f64>, AnalysisError> {
    let n = M::NQ;
    let f0 = n - model.first_order_states();
    let mech: Vec<usize> = free.iter().copied().filter(|&i| i < f0).collect();
    if mech.len() == free.len() {
        return Ok(reduced_stiffness(model, options, free, b, (k, g))?.0);
    }
    let kg: Vec<f64> = (0..n * n).map(|c| k[c] - g[(c % n, c / n)]).collect();
    let kc = condensed(model, &kg, free);
    if kc.nrows() != mech.len() {
        // K_ss singular: the states do not settle
        return Ok(reduced_stiffness(model, options, free, b, (k, g))?.0);
    }
    let (kr, _) = reduced_stiffness_of(model, options, &mech, b, &kc)?;
    Ok(kr)
}

/// Why the Newton matrix of the constrained statics is singular: redundant constraints, or
/// a reduced stiffness with a zero eigenvalue (a mechanism direction with no stiffness),
/// named by the coordinates that move most along it.
fn singular_reduced<M: Model>(
    model: &M,
    options: &StaticsOptions,
    free: &[usize],
    b: &DMatrix<f64>,
    kg: (&[f64], &DMatrix<f64>),
    rcond: f64,
) -> Result<AnalysisError, AnalysisError> {
    let (kr, basis) = reduced_stiffness(model, options, free, b, kg)?;
    let eig = nalgebra::SymmetricEigen::new(kr);
    let k = (0..eig.eigenvalues.len())
        .min_by(|&i, &j| {
            eig.eigenvalues[i]
                .abs()
                .total_cmp(&eig.eigenvalues[j].abs())
        })
        .unwrap_or(0);
    let mut coordinates = Vec::new();
    if basis.ncols() > 0 {
        let w = &basis * eig.eigenvectors.column(k);
        let wmax = w.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (r, &i) in free.iter().enumerate() {
            if w[r].abs() >= 0.3 * wmax {
                coordinates.push(model.info().dof_label(i));
            }
        }
    }
    Ok(Failure::SingularMatrix {
        matrix: "the reduced stiffness Nᵀ(K − ∂(Bᵀλ)/∂q)N on the constraint manifold",
        rcond,
        coordinates,
        cause: String::new(),
    }
    .into())
}
