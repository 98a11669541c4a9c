//! Linearisation about any state (EasyDyn's SaveLinearizedSystem): with τ(q, qd, qdd) = M qdd − h
//! and qdd = M⁻¹h at the state, small deviations obey
//! M δq̈ + C δq̇ + K δq = B_u δu, with C = ∂τ/∂qd, K = ∂τ/∂q (the generated exact tangents, or
//! central differences of τ) and B_u = ∂h/∂u (generated); in state space x = (δq, δq̇),
//! ẋ = A x + B δu with A = [[0, I], [−M⁻¹K, −M⁻¹C]], B = [[0], [M⁻¹B_u]].
//!
//! ## Constrained models
//!
//! With `M qdd = h + Bᵀλ`, `Φ(q, t) = 0` the state must be consistent (|Φ_i| and
//! |Φ̇_i| = |B qd + ∂Φ/∂t| within [`CONSISTENCY_TOLERANCE`], the latter relative to
//! max(1, ‖qd‖∞)); qdd and λ come from the index-1 equations (B qdd = γ). The coordinates are
//! split into independent z (NQ − NC of them: the model's `independent` marks when they number
//! NQ − NC and B over the others is not much worse conditioned than the set complete pivoting
//! on B picks, else that set) and dependent ones, and δq = N δz with
//! N = [I on the independent rows; −B_d⁻¹B_i on the dependent rows]; E is B_d⁻¹ on the
//! dependent rows (B E = I). Then δq̇ = N δż − E P N δz and
//! δq̈ = N δz̈ − E(Q δq + 2P δq̇), with P = ∂Φ̇/∂q and Q = ∂Φ̈/∂q at fixed (qd, qdd)
//! (∂Φ̈/∂qd = 2P). Projecting `M qdd − h − Bᵀλ = 0` on N (NᵀBᵀ = 0 for every q, so
//! δNᵀ·Bᵀλ = −Nᵀ·∂(Bᵀλ)/∂q·δq) gives M_z δz̈ + C_z δż + K_z δz = B_u,z δu with
//!
//! - M_z = NᵀMN, B_u,z = NᵀB_u,
//! - C_z = NᵀW N, W = C − 2M E P,
//! - K_z = Nᵀ(K − G)N − NᵀM E Q N − NᵀW E P N, G = ∂(Bᵀλ)/∂q (the curvature of the
//!   constraints enters through λ).
//!
//! At rest with scleronomic constraints (qd = 0, ∂Φ/∂t ≡ 0) P = 0 and Q = ∂(B qdd)/∂q, so
//! C_z = NᵀCN and K_z = Nᵀ(K − G)N − NᵀM E Q N (the last term vanishes at an equilibrium).
//! Exact: G, the Hessians of Φ (from the generated `constraint_tangent`, one call per
//! constraint), hence ∂(B qd)/∂q and ∂(B qdd)/∂q; K and C as for unconstrained models.
//! By central differences: ∂γ/∂q (of the generated γ at fixed qd) and ∂(∂Φ/∂t)/∂q (of the
//! generated ∂Φ/∂t); both vanish identically at rest with scleronomic constraints, and
//! [`Linearization::constraint_terms_exact`] says whether they did. The result is the
//! linearisation of the reduced ODE z̈ = f(z, ż) (the dependent coordinates completed from
//! Φ = 0, Φ̇ = 0): `tests/analysis_constrained.rs` checks A against its central differences.

use super::{AnalysisError, check, check_named, reduce};
use crate::error::Failure;
use crate::linalg::{cholesky, cholesky_solve};
use crate::model::Model;
use crate::options::IterationMatrix;
use nalgebra::DMatrix;
use serde::Serialize;

/// Largest |Φ_i| (m or rad) a constrained state may have to be linearised; |Φ̇_i| is held to
/// this times max(1, ‖qd‖∞).
pub const CONSISTENCY_TOLERANCE: f64 = 1e-8;

/// A model linearised about a state.
#[derive(Clone, Debug, Serialize)]
#[non_exhaustive]
pub struct Linearization {
    pub dof_names: Vec<String>,
    pub input_names: Vec<String>,
    /// the state: t, q, qd, qdd (= M⁻¹h, or the index-1 accelerations with constraints), u
    pub t: f64,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub u: Vec<f64>,
    /// mass, damping and stiffness matrices in all coordinates (n × n): M, C = ∂τ/∂qd,
    /// K = ∂τ/∂q at (q, qd, qdd); input matrix B_u = ∂h/∂u (n × nu)
    pub m: DMatrix<f64>,
    pub c: DMatrix<f64>,
    pub k: DMatrix<f64>,
    pub bu: DMatrix<f64>,
    /// state space ẋ = A x + B δu, x = (δz, δż) (z = q without constraints):
    /// A (2nz × 2nz), B (2nz × nu)
    pub a: DMatrix<f64>,
    pub b: DMatrix<f64>,
    /// whether C and K are exact: from generated tangents throughout (false for central
    /// differences, and for [`crate::WithEfforts`], whose efforts written in Rust are
    /// differenced within its tangents)
    pub exact: bool,
    /// names of the coordinates z of `a`, `b` and the reduced matrices: every coordinate
    /// without constraints, the independent ones with constraints
    pub coordinates: Vec<String>,
    /// indices of those coordinates in q
    pub independent: Vec<usize>,
    /// whether they are the model's `independent` marks (else chosen by pivoting on B)
    pub marks_used: bool,
    /// the positions in z of first-order states ([`Model::first_order_states`]: the extra
    /// states of [`crate::WithEfforts`], whose coordinates' positions are integrals nothing
    /// reads): each adds an eigenvalue 0 to A that is no mode, which [`super::modes`] leaves
    /// out
    pub first_order: Vec<usize>,
    /// δq = N δz (n × nz; the identity without constraints)
    pub basis: DMatrix<f64>,
    /// the linearised equations in z: M_z δz̈ + C_z δż + K_z δz = B_u,z δu (equal to m, c,
    /// k, bu without constraints)
    pub mz: DMatrix<f64>,
    pub cz: DMatrix<f64>,
    pub kz: DMatrix<f64>,
    pub buz: DMatrix<f64>,
    /// constraint names and λ at the state (index-1); empty without constraints
    pub constraint_names: Vec<String>,
    pub lambda: Vec<f64>,
    /// G = ∂(Bᵀλ)/∂q at the state (n × n; empty without constraints)
    pub constraint_tangent: DMatrix<f64>,
    /// whether the constraint terms are exact: false when ∂γ/∂q or ∂(∂Φ/∂t)/∂q, taken by
    /// central differences, were not identically zero (moving states, rheonomic constraints)
    pub constraint_terms_exact: bool,
    /// the charts of the rotation joints (`Tball`, `Tfree`) the linearisation is in: each
    /// centred on the joint's orientation at the state, whose angles in `q` are then zero and
    /// whose deviations δ(a, b, c) are the small rotation (δθz, δθy, δθx) in the joint's own
    /// axes (empty without rotation joints)
    pub charts: Vec<[[f64; 3]; 3]>,
}

/// K = ∂τ/∂q and C = ∂τ/∂qd at (q, qd, qdd), exact or by central differences of τ.
fn tangents<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    u: &[f64],
    exact: bool,
) -> Result<(Vec<f64>, Vec<f64>), AnalysisError> {
    let n = M::NQ;
    let (mut k, mut c) = (vec![0.0; n * n], vec![0.0; n * n]);
    if exact {
        model
            .tangents(t, q, qd, qdd, u, &mut k, &mut c)
            .map_err(|_| Failure::InvalidOption {
                name: "how",
                value: "Exact".into(),
                reason: "the model has no tangents: add `option tangents;`",
            })?;
    } else {
        // central differences of τ in q and in qd
        let (mut qp, mut vp, mut column) = (q.to_vec(), qd.to_vec(), vec![0.0; n]);
        for j in 0..n {
            for (var, out) in [(0, &mut k), (1, &mut c)] {
                let x = if var == 0 { q[j] } else { qd[j] };
                super::central_difference(x, &mut column, |x, tau| {
                    (if var == 0 { &mut qp } else { &mut vp })[j] = x;
                    model.inverse_dynamics(t, &qp, &vp, qdd, u, tau);
                    Ok::<(), AnalysisError>(())
                })?;
                (if var == 0 { &mut qp } else { &mut vp })[j] = x;
                out[n * j..n * (j + 1)].copy_from_slice(&column);
            }
        }
    }
    check(model, "K", &k)?;
    check(model, "C", &c)?;
    Ok((k, c))
}

/// A = [[0, I], [−M⁻¹K, −M⁻¹C]], B = [[0], [M⁻¹B_u]] for symmetric positive definite M.
fn state_space(
    m: &DMatrix<f64>,
    c: &DMatrix<f64>,
    k: &DMatrix<f64>,
    bu: &DMatrix<f64>,
    matrix: &'static str,
    label: impl Fn(usize) -> String,
) -> Result<(DMatrix<f64>, DMatrix<f64>), AnalysisError> {
    let n = m.nrows();
    let nu = bu.ncols();
    let mut l = m.as_slice().to_vec();
    cholesky(&mut l, n).map_err(|s| Failure::SingularMatrix {
        matrix,
        rcond: s.rcond,
        coordinates: vec![label(s.column)],
        cause: String::new(),
    })?;
    let mut a = DMatrix::zeros(2 * n, 2 * n);
    let mut b = DMatrix::zeros(2 * n, nu);
    for i in 0..n {
        a[(i, n + i)] = 1.0;
    }
    let mut col = vec![0.0; n];
    for j in 0..n {
        for (src, off) in [(k, 0), (c, n)] {
            col.copy_from_slice(src.column(j).as_slice());
            cholesky_solve(&l, n, &mut col);
            for i in 0..n {
                a[(n + i, off + j)] = -col[i];
            }
        }
    }
    for j in 0..nu {
        col.copy_from_slice(bu.column(j).as_slice());
        cholesky_solve(&l, n, &mut col);
        for i in 0..n {
            b[(n + i, j)] = col[i];
        }
    }
    Ok((a, b))
}

/// The positions in z (of coordinates `independent`) of the model's first-order states.
fn first_order<M: Model>(model: &M, independent: &[usize]) -> Vec<usize> {
    let f0 = M::NQ - model.first_order_states();
    (0..independent.len())
        .filter(|&i| independent[i] >= f0)
        .collect()
}

/// Linearises `model` about (t, q, qd, u); K and C by `how` (Auto: exact tangents when
/// generated). With constraints, in the independent coordinates (see the module
/// documentation); the state must then be consistent. Rotation joints are first re-centred
/// on their orientation at the state (q and qd read in the model's charts), so that their
/// angles are linearised in their tangent space, away from gimbal lock
/// ([`Linearization::charts`]).
pub fn linearize<M: Model + Clone>(
    model: &M,
    t: f64,
    q: &[f64],
    qd: &[f64],
    u: &[f64],
    how: IterationMatrix,
) -> Result<Linearization, AnalysisError> {
    let n = M::NQ;
    let nu = M::NU;
    for (name, v, len) in [("q", q, n), ("qd", qd, n), ("u", u, nu)] {
        if v.len() != len {
            return Err(Failure::InvalidOption {
                name,
                value: v.len().to_string(),
                reason: "has the wrong length for this model",
            }
            .into());
        }
        if name == "u" {
            let inputs = model.info().inputs;
            check_named(name, v, |i| match inputs.get(i) {
                Some(input) => format!("input {i} (`{input}`)"),
                None => format!("input {i}"),
            })?;
        } else {
            check(model, name, v)?;
        }
    }
    if model.info().rotation_joints.is_empty() {
        return linearize_in_chart(model, t, q, qd, u, how)
            .map_err(|e| mass_blamed(e, model, t, q));
    }
    let mut centred = model.clone();
    let (mut q, mut qd) = (q.to_vec(), qd.to_vec());
    crate::charts::recentre(&mut centred, &mut q, &mut qd, &[]);
    let mut lin = linearize_in_chart(&centred, t, &q, &qd, u, how)
        .map_err(|e| mass_blamed(e, &centred, t, &q))?;
    lin.charts = crate::charts::charts_of(&centred);
    Ok(lin)
}

/// A mass matrix singular at (t, q), with the parameters that, set back to their default
/// alone, make it regular there; other errors unchanged.
fn mass_blamed<M: Model + Clone>(e: AnalysisError, model: &M, t: f64, q: &[f64]) -> AnalysisError {
    let n = M::NQ;
    let regular = |m: &M| {
        let mut mass = vec![0.0; n * n];
        m.mass_matrix(t, q, &mut mass);
        mass.iter().all(|x| x.is_finite()) && cholesky(&mut mass, n).is_ok()
    };
    super::singular_blamed(
        e,
        Some("the mass matrix M"),
        model,
        regular,
        "M is regular there",
    )
}

/// [`linearize`] in the model's charts, the inputs checked.
fn linearize_in_chart<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
    qd: &[f64],
    u: &[f64],
    how: IterationMatrix,
) -> Result<Linearization, AnalysisError> {
    let n = M::NQ;
    let nu = M::NU;
    let info = model.info();
    let (mut m, mut h) = (vec![0.0; n * n], vec![0.0; n]);
    model.dynamics(t, q, qd, u, &mut m, &mut h);
    check(model, "M", &m)?;
    check(model, "generalized force h", &h)?;
    let mut l = m.clone();
    cholesky(&mut l, n).map_err(|s| Failure::SingularMatrix {
        matrix: "the mass matrix M",
        rcond: s.rcond,
        coordinates: vec![info.dof_label(s.column)],
        cause: String::new(),
    })?;
    let exact = match how {
        IterationMatrix::Exact => true,
        IterationMatrix::Auto => info.has_tangents,
        _ => false,
    };
    let mut bu = vec![0.0; n * nu];
    model.input_matrix(t, q, qd, u, &mut bu);
    check(model, "B_u", &bu)?;
    let mm = DMatrix::from_column_slice(n, n, &m);
    let bu = DMatrix::from_column_slice(n, nu, &bu);
    let dof_names: Vec<String> = (0..n).map(|i| info.dof_label(i)).collect();
    let input_names = info.inputs.iter().map(|s| s.to_string()).collect();

    if M::NC == 0 {
        // qdd = M⁻¹ h
        let mut qdd = h.clone();
        cholesky_solve(&l, n, &mut qdd);
        let (k, c) = tangents(model, t, q, qd, &qdd, u, exact)?;
        let (k, c) = (
            DMatrix::from_column_slice(n, n, &k),
            DMatrix::from_column_slice(n, n, &c),
        );
        let (a, b) = state_space(&mm, &c, &k, &bu, "the mass matrix M", |i| info.dof_label(i))?;
        return Ok(Linearization {
            coordinates: dof_names.clone(),
            dof_names,
            input_names,
            t,
            q: q.to_vec(),
            qd: qd.to_vec(),
            qdd,
            u: u.to_vec(),
            mz: mm.clone(),
            cz: c.clone(),
            kz: k.clone(),
            buz: bu.clone(),
            m: mm,
            c,
            k,
            bu,
            a,
            b,
            exact: exact && model.tangents_exact(),
            independent: (0..n).collect(),
            first_order: first_order(model, &(0..n).collect::<Vec<_>>()),
            marks_used: false,
            basis: DMatrix::identity(n, n),
            constraint_names: Vec::new(),
            lambda: Vec::new(),
            constraint_tangent: DMatrix::zeros(0, 0),
            constraint_terms_exact: true,
            charts: Vec::new(),
        });
    }

    // ---- constrained: consistency, partition, index-1 accelerations
    let nc = M::NC;
    let names = info.constraints;
    let phi = reduce::constraints(model, t, q)?;
    let (worst_phi, at) = reduce::worst(&phi);
    if worst_phi > CONSISTENCY_TOLERANCE {
        return Err(Failure::InconsistentStart {
            reason: format!(
                "linearize needs a state on the constraints, but Φ(q, t) = {:.3e} at `{}` (close the loop first: mbs::assemble, or a static equilibrium)",
                phi[at], names[at]
            ),
            constraint: names[at].to_string(),
            residual: worst_phi,
            iterations: 0,
        }
        .into());
    }
    let b = reduce::jacobian(model, t, q)?;
    reduce::rank_check(&b, names)?;
    let mut phi_t = vec![0.0; nc];
    model.constraint_rate(t, q, &mut phi_t);
    reduce::check_constraints(model, "∂Φ/∂t", &phi_t)?;
    let phid: Vec<f64> = (0..nc)
        .map(|i| (0..n).map(|j| b[(i, j)] * qd[j]).sum::<f64>() + phi_t[i])
        .collect();
    let (worst_rate, at) = reduce::worst(&phid);
    let qd_scale = qd.iter().fold(1.0f64, |s, v| s.max(v.abs()));
    if worst_rate > CONSISTENCY_TOLERANCE * qd_scale {
        return Err(Failure::InvalidOption {
            name: "qd",
            value: format!(
                "Φ̇ = B qd + ∂Φ/∂t = {:.3e} at `{}`",
                phid[at], names[at]
            ),
            reason: "is not tangent to the constraints: linearize needs Φ̇ = 0 (project the velocities first, e.g. with mbs::assemble)",
        }
        .into());
    }
    let mut gamma = vec![0.0; nc];
    model.constraint_bias(t, q, qd, &mut gamma);
    reduce::check_constraints(model, "γ", &gamma)?;
    let (qdd, lambda) = reduce::index1(&l, &h, &b, &gamma, names)?;
    let part = reduce::partition(&b, info.independent)
        .ok_or_else(|| AnalysisError::from(reduce::nearly_dependent(&b, names)))?;
    let (nb, e) = reduce::basis(&b, &part).ok_or_else(|| {
        AnalysisError::from(Failure::SingularMatrix {
            matrix: "B over the dependent coordinates",
            rcond: 0.0,
            coordinates: part.dep.iter().map(|&i| info.dof_label(i)).collect(),
            cause: String::new(),
        })
    })?;

    // ---- K, C at the index-1 accelerations; G and the Hessians of Φ (exact)
    let (k, c) = tangents(model, t, q, qd, &qdd, u, exact)?;
    let (k, c) = (
        DMatrix::from_column_slice(n, n, &k),
        DMatrix::from_column_slice(n, n, &c),
    );
    let g = reduce::constraint_tangent(model, t, q, &lambda)?;
    let hess = reduce::hessians(model, t, q)?;
    // ∂(B v)/∂q row i = Σ_k H_i[k, ·] v_k
    let d_bv =
        |v: &[f64]| DMatrix::from_fn(nc, n, |i, j| (0..n).map(|k| hess[i][(k, j)] * v[k]).sum());
    // ∂(∂Φ/∂t)/∂q and ∂γ/∂q (fixed qd) by central differences
    let (mut phi_tq, mut gamma_q) = (DMatrix::zeros(nc, n), DMatrix::zeros(nc, n));
    {
        let (mut qp, mut column) = (q.to_vec(), vec![0.0; nc]);
        for j in 0..n {
            for (out, which) in [(&mut phi_tq, 0), (&mut gamma_q, 1)] {
                super::central_difference(q[j], &mut column, |x, f| {
                    qp[j] = x;
                    if which == 0 {
                        model.constraint_rate(t, &qp, f)
                    } else {
                        model.constraint_bias(t, &qp, qd, f)
                    }
                    Ok::<(), AnalysisError>(())
                })?;
                qp[j] = q[j];
                out.column_mut(j).copy_from_slice(&column);
            }
        }
    }
    check(model, "∂(∂Φ/∂t)/∂q", phi_tq.as_slice())?;
    check(model, "∂γ/∂q", gamma_q.as_slice())?;
    let constraint_terms_exact =
        phi_tq.iter().all(|&v| v == 0.0) && gamma_q.iter().all(|&v| v == 0.0);
    let p = d_bv(qd) + &phi_tq;
    let qq = d_bv(&qdd) - &gamma_q;

    // ---- the reduced matrices
    let nt = nb.transpose();
    let w = &c - 2.0 * (&mm * &e * &p);
    let mz = &nt * &mm * &nb;
    let cz = &nt * &w * &nb;
    let kz = &nt * (&k - &g) * &nb - &nt * &mm * &e * &qq * &nb - &nt * &w * &e * &p * &nb;
    let buz = &nt * &bu;
    let mz = (&mz + mz.transpose()) * 0.5;
    let coordinates: Vec<String> = part.ind.iter().map(|&i| info.dof_label(i)).collect();
    let (a, bs) = state_space(&mz, &cz, &kz, &buz, "the reduced mass matrix NᵀMN", |i| {
        coordinates.get(i).cloned().unwrap_or_default()
    })?;
    Ok(Linearization {
        dof_names,
        input_names,
        t,
        q: q.to_vec(),
        qd: qd.to_vec(),
        qdd,
        u: u.to_vec(),
        m: mm,
        c,
        k,
        bu,
        a,
        b: bs,
        exact: exact && model.tangents_exact(),
        coordinates,
        independent: part.ind.clone(),
        first_order: first_order(model, &part.ind),
        marks_used: part.marked,
        basis: nb,
        mz,
        cz,
        kz,
        buz,
        constraint_names: names.iter().map(|s| s.to_string()).collect(),
        lambda,
        constraint_tangent: g,
        constraint_terms_exact,
        charts: Vec::new(),
    })
}
