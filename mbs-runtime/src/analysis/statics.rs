//! Static equilibrium (EasyDyn's StaticEquilibrium): Newton on the velocity-free forces
//! h(q, 0, t, u) = 0 with the stiffness K = ∂τ/∂q at rest (exact tangents, or central
//! differences of the static forces), a backtracking line search on ‖h‖, and coordinates that
//! can be held at their starting value (EasyDyn's `doflocked`). The stability of the
//! equilibrium is read from the eigenvalues of the stiffness restricted to the free coordinates.

use super::AnalysisError;
use crate::error::Failure;
use crate::linalg::Lu;
use crate::model::Model;
use crate::options::IterationMatrix;
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
    /// converged when every free generalised force is below this (N or N·m), default 1e-9
    pub tolerance: f64,
    /// Newton iterations before `NotConverged` (default 50)
    pub max_iterations: usize,
    /// how the stiffness is obtained: exact tangents (`Auto` when generated), or central
    /// differences of the static forces
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
    /// no negative eigenvalue but some zero (within 1e-9 of the largest): neutral directions
    Neutral,
}

/// A static equilibrium and how it was found.
#[derive(Clone, Debug, Serialize)]
#[non_exhaustive]
pub struct Equilibrium {
    pub q: Vec<f64>,
    /// largest |h| over the free coordinates at `q`
    pub residual: f64,
    pub iterations: usize,
    /// names of the free coordinates
    pub free: Vec<String>,
    /// eigenvalues of the (symmetrised) stiffness on the free coordinates, ascending
    pub stiffness_eigenvalues: Vec<f64>,
    pub stability: Stability,
}

impl fmt::Display for Equilibrium {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "static equilibrium ({:?}) after {} iterations, residual {:.2e}",
            self.stability, self.iterations, self.residual
        )?;
        write!(f, "stiffness eigenvalues:")?;
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
    check(model, "static forces", h)
}

pub(super) fn check<M: Model>(
    model: &M,
    quantity: &'static str,
    v: &[f64],
) -> Result<(), AnalysisError> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => Err(Failure::NonFinite {
            quantity,
            coordinate: model.info().dof_label(i % M::NQ),
        }
        .into()),
    }
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
    let exact = match how {
        IterationMatrix::Exact => true,
        IterationMatrix::Auto => model.info().has_tangents,
        _ => false,
    };
    if exact {
        let mut c = vec![0.0; n * n];
        model
            .tangents(t, q, &zero, &zero, u, k, &mut c)
            .map_err(|e| Failure::InvalidOption {
                name: "stiffness",
                value: "Exact".into(),
                reason: match e {
                    crate::error::ModelError::TangentsNotGenerated { .. } => {
                        "the model has no tangents: add `option tangents;`"
                    }
                },
            })?;
        return check(model, "stiffness", k);
    }
    let (mut qp, mut hp, mut hm) = (q.to_vec(), vec![0.0; n], vec![0.0; n]);
    for j in 0..n {
        let eps = f64::EPSILON.cbrt() * q[j].abs().max(1.0);
        qp[j] = q[j] + eps;
        forces(model, t, &qp, u, &mut hp)?;
        qp[j] = q[j] - eps;
        forces(model, t, &qp, u, &mut hm)?;
        qp[j] = q[j];
        for i in 0..n {
            // τ = −h at rest
            k[i + n * j] = -(hp[i] - hm[i]) / (2.0 * eps);
        }
    }
    Ok(())
}

/// Finds q with h(q, 0, t, u) = 0 on the free coordinates, from `options.q0`.
pub fn static_equilibrium<M: Model>(
    model: &M,
    options: &StaticsOptions,
) -> Result<Equilibrium, AnalysisError> {
    let n = M::NQ;
    let info = model.info();
    let invalid = |name: &'static str, value: String, reason: &'static str| {
        AnalysisError::from(Failure::InvalidOption {
            name,
            value,
            reason,
        })
    };
    let mut q = match &options.q0 {
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
            q
        }
    };
    let u = options.u.clone().unwrap_or_else(|| vec![0.0; M::NU]);
    if u.len() != M::NU {
        return Err(invalid(
            "u",
            u.len().to_string(),
            "must have one value per input",
        ));
    }
    if let Some(&i) = options.locked.iter().find(|&&i| i >= n) {
        return Err(invalid(
            "locked",
            i.to_string(),
            "is not a coordinate index",
        ));
    }
    if !(options.tolerance > 0.0) || options.max_iterations == 0 {
        return Err(invalid(
            "tolerance",
            options.tolerance.to_string(),
            "must be > 0, with max_iterations > 0",
        ));
    }
    check(model, "q0", &q)?;
    let free: Vec<usize> = (0..n).filter(|i| !options.locked.contains(i)).collect();
    let nf = free.len();
    let (mut h, mut k, mut trial, mut ht) =
        (vec![0.0; n], vec![0.0; n * n], vec![0.0; n], vec![0.0; n]);
    let mut lu = Lu::<f64>::new(nf);
    let norm = |h: &[f64]| free.iter().map(|&i| h[i].abs()).fold(0.0, f64::max);
    forces(model, options.t, &q, &u, &mut h)?;
    let mut residual = norm(&h);
    let mut iterations = 0;
    while residual > options.tolerance {
        if iterations == options.max_iterations {
            return Err(AnalysisError::NotConverged {
                iterations,
                residual,
                q,
            });
        }
        iterations += 1;
        stiffness(model, options.t, &q, &u, options.stiffness, &mut k)?;
        let a = lu.matrix_mut();
        for (c, &j) in free.iter().enumerate() {
            for (r, &i) in free.iter().enumerate() {
                a[r + nf * c] = k[i + n * j];
            }
        }
        lu.factor().map_err(|s| Failure::SingularMatrix {
            matrix: "the stiffness K on the free coordinates",
            rcond: s.rcond,
            coordinates: vec![info.dof_label(free[s.column])],
        })?;
        // K δ = h (τ = −h at rest: h(q + δ) ≈ h − K δ)
        let mut delta: Vec<f64> = free.iter().map(|&i| h[i]).collect();
        lu.solve(&mut delta);
        // backtracking on ‖h‖∞
        let mut alpha = 1.0;
        loop {
            trial.copy_from_slice(&q);
            for (c, &i) in free.iter().enumerate() {
                trial[i] += alpha * delta[c];
            }
            let ok = forces(model, options.t, &trial, &u, &mut ht).is_ok();
            if ok && norm(&ht) < residual * (1.0 - 1e-4 * alpha) {
                break;
            }
            alpha *= 0.5;
            if alpha < 1e-6 {
                return Err(AnalysisError::NotConverged {
                    iterations,
                    residual,
                    q,
                });
            }
        }
        q.copy_from_slice(&trial);
        h.copy_from_slice(&ht);
        residual = norm(&h);
    }
    // stability from the symmetrised stiffness on the free coordinates
    stiffness(model, options.t, &q, &u, options.stiffness, &mut k)?;
    let ks = nalgebra::DMatrix::from_fn(nf, nf, |r, c| {
        0.5 * (k[free[r] + n * free[c]] + k[free[c] + n * free[r]])
    });
    let mut eig: Vec<f64> = ks.symmetric_eigenvalues().iter().copied().collect();
    eig.sort_by(f64::total_cmp);
    let scale = eig.iter().fold(0.0f64, |m, e| m.max(e.abs()));
    let stability = if eig.iter().any(|&e| e < -1e-9 * scale) {
        Stability::Unstable
    } else if eig.iter().any(|&e| e <= 1e-9 * scale) {
        Stability::Neutral
    } else {
        Stability::Stable
    };
    Ok(Equilibrium {
        q,
        residual,
        iterations,
        free: free.iter().map(|&i| info.dof_label(i)).collect(),
        stiffness_eigenvalues: eig,
        stability,
    })
}
