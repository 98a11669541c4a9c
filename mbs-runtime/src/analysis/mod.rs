//! Analyses from the generated exact tangents: static equilibrium, linearisation, poles and
//! modes, inverse dynamics along a motion (EasyDyn's StaticEquilibrium, SaveLinearizedSystem,
//! ComputePoles; here without finite differences when the model has `option tangents`).
//!
//! Constrained models (`M qdd = h + Bᵀλ`, `Φ = 0`) are analysed on the constraint manifold:
//! the statics solve for q and λ together and judge stability on the null space of B; the
//! linearisation is in the independent coordinates (NQ − NC of them); the inverse dynamics
//! split M qdd − h into actuator efforts and constraint reactions. What is exact and what
//! uses central differences is said in each module:
//!
//! Central differences check their step against its quarter (`central_difference`).
//!
//! | analysis | exact | central differences |
//! |---|---|---|
//! | statics | h, B, ∂(Bᵀλ)/∂q; K with tangents | K without tangents |
//! | linearisation | M, B_u, B, Hessians of Φ, G; K, C with tangents | K, C without tangents; with constraints ∂γ/∂q and ∂(∂Φ/∂t)/∂q (identically zero at rest with scleronomic constraints, then exact) |
//! | modes | eigen-decomposition of A | — |
//! | inverse dynamics | τ, and τ_a, λ from one LU of [S Bᵀ] | — |
//! | sensitivities | ∂τ/∂p, dq_eq/dp; dλ/dp of poles from generated M′, C′, K′ | K without tangents (statics only) |

mod inverse;
mod linearize;
mod modes;
mod reduce;
mod sensitivity;
mod statics;

pub use inverse::{
    ActuatedEfforts, Efforts, inverse_dynamics_actuated_along, inverse_dynamics_actuated_of,
    inverse_dynamics_along, inverse_dynamics_of,
};
pub use linearize::{CONSISTENCY_TOLERANCE, Linearization, linearize};
pub use modes::{Mode, Modes, modes};
pub use sensitivity::{PoleSensitivity, StaticSensitivity, pole_sensitivity, static_sensitivity};
pub use statics::{Equilibrium, Stability, StaticsOptions, static_equilibrium};

use crate::error::Failure;
use crate::model::Model;
use thiserror::Error;

/// Why an analysis failed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum AnalysisError {
    /// invalid input, singular matrix or non-finite value, as in simulations
    #[error(transparent)]
    Failure(#[from] Failure),
    #[error(
        "no static equilibrium found in {iterations} iterations: the largest free force is still {residual:.3e}{} at q = [{}] (start closer, lock the coordinates that have no stiffness, or check that an equilibrium exists)",
        if *constraint_residual > 0.0 { format!(" and the largest |Φ| {constraint_residual:.3e}") } else { String::new() },
        q.iter().map(|x| crate::error::short(*x)).collect::<Vec<_>>().join(", ")
    )]
    NotConverged {
        iterations: usize,
        /// largest free generalised force (with the constraint forces Bᵀλ)
        residual: f64,
        /// largest |Φ_i| (0 without constraints)
        constraint_residual: f64,
        /// where Newton stopped, rotation joints' angles in the model's charts (a start to
        /// retry from)
        q: Vec<f64>,
    },
    /// The QR iteration of a Schur decomposition did not converge, even where it set to zero
    /// the subdiagonal entries below `deflation` of their neighbours.
    #[error(
        "the eigenvalues of {matrix} ({size} × {size}) were not found: the QR iteration of its Schur decomposition did not converge, even deflating at {deflation:.0e} of the neighbouring entries (a matrix of exactly repeated structure; perturb the state slightly, or linearise about another)"
    )]
    EigenvaluesNotFound {
        matrix: &'static str,
        size: usize,
        deflation: f64,
    },
    /// An analysis along a motion (inverse dynamics) failed at one of its times; what it
    /// computed at the times before is kept.
    #[error("at t = {t} (time {index} of the motion; the {index} before it computed): {cause}")]
    AlongMotion {
        /// the index of the time in the motion, and the time
        index: usize,
        t: f64,
        /// the failure there
        cause: Box<AnalysisError>,
        /// the rows of the times before
        computed: Box<Computed>,
    },
}

/// What an analysis along a motion computed before a time it failed at
/// ([`AnalysisError::AlongMotion`]).
#[derive(Debug, Clone, PartialEq)]
pub enum Computed {
    Efforts(Efforts),
    Actuated(ActuatedEfforts),
}

impl AnalysisError {
    /// The failure itself: for an analysis along a motion that stopped, its cause at that
    /// time; otherwise the error.
    pub fn cause(&self) -> &AnalysisError {
        match self {
            AnalysisError::AlongMotion { cause, .. } => cause.cause(),
            other => other,
        }
    }
}

/// The factor s by which the constraints' rows and columns of an augmented matrix
/// [K, ±Bᵀ; B, 0] are scaled to the size of the block beside them (`block` and `constraints`
/// the two blocks' sizes; their unknowns are then λ/s): a stiff loop's Schur complement
/// B K⁻¹ Bᵀ otherwise leaves pivots the factorisation takes for singular. 1 when either size
/// is 0 or their ratio is not finite.
fn constraint_scale(block: f64, constraints: f64) -> f64 {
    let s = block / constraints;
    if s.is_finite() && s > 0.0 { s } else { 1.0 }
}

/// `e` with, where it is a singular matrix (named `matrix`, or any when None), the
/// parameters that, set back to their default alone, make `holds` true of the model: "; with
/// `l` at its default 1 rather than 0 {what}: check that parameter", as a run's start names
/// them. Other errors unchanged.
fn singular_blamed<M: Model + Clone>(
    mut e: AnalysisError,
    matrix: Option<&str>,
    model: &M,
    mut holds: impl FnMut(&M) -> bool,
    what: &str,
) -> AnalysisError {
    if let AnalysisError::Failure(Failure::SingularMatrix {
        matrix: singular,
        cause,
        ..
    }) = &mut e
        && matrix.is_none_or(|m| m == *singular)
    {
        let (found, _) = crate::model::defaults_for_which(&mut model.clone(), &mut holds);
        cause.push_str(&crate::model::blamed_parameters(&found, what));
    }
    e
}

/// Steps of inverse iteration at a shift μ that leaves r = |λ − μ| / |λ' − μ| of the nearest
/// other eigenvalue λ' in the vector at each step: until r^k is below rounding, at least
/// three and at most 100; `otherwise` where r is not in (0, 1).
fn inverse_iterations(r: f64, otherwise: usize) -> usize {
    if r > 0.0 && r < 1.0 {
        ((f64::EPSILON.ln() / r.ln()).ceil() as usize).clamp(3, 100)
    } else {
        otherwise
    }
}

/// Central differences of a vector function by one variable at x, into `out`
/// (`f(x', values)` evaluates it with the variable at x'), with a step that is checked: from
/// ε^⅓ max(|x|, 1) it is divided by 4 while the differences with a step and with its quarter
/// disagree in some entry by more than 1e-6 of it (their truncation error) and more than its
/// rounding (1000 ε of the values over the step), at most 12 times and while they come to
/// agree better; where no two agree, the difference of the pair that disagrees least, its
/// larger step's. The first step alone, a unit's part in 6·10⁶ of a coordinate of size 1 or
/// less, misses nonlinearities on a smaller scale: a friction force μN tanh(v/v_ε) with
/// v_ε = 1e-6 m/s gave a sixth of its damping at v = 0. Smooth functions keep the first
/// step's difference, at twice its evaluations.
fn central_difference<E>(
    x: f64,
    out: &mut [f64],
    mut f: impl FnMut(f64, &mut [f64]) -> Result<(), E>,
) -> Result<(), E> {
    let m = out.len();
    let (mut fp, mut fm) = (vec![0.0; m], vec![0.0; m]);
    // the difference with step h into d, and the rounding of each entry into r
    let mut difference = |h: f64, d: &mut [f64], r: &mut [f64]| -> Result<(), E> {
        let (xp, xm) = (x + h, x - h);
        f(xp, &mut fp)?;
        f(xm, &mut fm)?;
        let step = xp - xm;
        for i in 0..m {
            d[i] = (fp[i] - fm[i]) / step;
            r[i] = 1e3 * f64::EPSILON * fp[i].abs().max(fm[i].abs()) / step;
        }
        Ok(())
    };
    let (mut next, mut r, mut r_next) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
    let mut h = f64::EPSILON.cbrt() * x.abs().max(1.0);
    difference(h, out, &mut r)?;
    let (mut best, mut kept) = (f64::INFINITY, out.to_vec());
    for _ in 0..12 {
        h *= 0.25;
        difference(h, &mut next, &mut r_next)?;
        // the largest disagreement, in units of what each entry allows
        let worst = (0..m)
            .map(|i| {
                let allowed = (1e-6 * out[i].abs()).max(r[i]).max(r_next[i]);
                let gap = (out[i] - next[i]).abs();
                if gap <= allowed { 0.0 } else { gap / allowed }
            })
            .fold(0.0, f64::max);
        if worst == 0.0 {
            return Ok(());
        }
        // past the least disagreement the smaller steps lose to rounding
        if !(worst < best) {
            break;
        }
        best = worst;
        kept.copy_from_slice(out);
        out.copy_from_slice(&next);
        r.copy_from_slice(&r_next);
    }
    out.copy_from_slice(&kept);
    Ok(())
}

/// The first non-finite entry of `v` (NQ-periodic, named by its coordinate) as an error; a
/// failure of user code in the evaluations before it ([`crate::WithEfforts`]) first, as in
/// simulations (a NaN it caused is only its symptom), which also leaves none behind for a
/// later run once an analysis has probed a trial state that failed.
fn check<M: Model>(model: &M, quantity: &'static str, v: &[f64]) -> Result<(), AnalysisError> {
    if let Some(f) = model.take_failure() {
        return Err(f.into());
    }
    let info = model.info();
    check_named(quantity, v, |i| info.dof_label(i % M::NQ.max(1)))
}

/// The first non-finite entry of `v` as an error, entry i named by `name(i)` (for quantities
/// not laid out by coordinate: inputs, constraints, modes).
fn check_named(
    quantity: &'static str,
    v: &[f64],
    name: impl FnOnce(usize) -> String,
) -> Result<(), AnalysisError> {
    Failure::non_finite(quantity, v, name).map_err(AnalysisError::from)
}

/// Names entry i of a quantity with one value per constraint (NC-periodic).
fn constraint_label(info: &crate::model::ModelInfo, nc: usize, i: usize) -> String {
    let k = i % nc.max(1);
    match info.constraints.get(k) {
        Some(name) => format!("constraint {k} (`{name}`)"),
        None => format!("constraint {k}"),
    }
}
