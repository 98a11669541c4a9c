//! Linearisation about any state (EasyDyn's SaveLinearizedSystem): with τ(q, qd, qdd) = M qdd − h
//! and qdd = M⁻¹h at the state, small deviations obey
//! M δq̈ + C δq̇ + K δq = B_u δu, with C = ∂τ/∂qd, K = ∂τ/∂q (the generated exact tangents, or
//! central differences of τ) and B_u = ∂h/∂u (generated); in state space x = (δq, δq̇),
//! ẋ = A x + B δu with A = [[0, I], [−M⁻¹K, −M⁻¹C]], B = [[0], [M⁻¹B_u]].

use super::AnalysisError;
use super::statics::check;
use crate::error::Failure;
use crate::linalg::{cholesky, cholesky_solve};
use crate::model::Model;
use crate::options::IterationMatrix;
use nalgebra::DMatrix;
use serde::Serialize;

/// A model linearised about a state.
#[derive(Clone, Debug, Serialize)]
#[non_exhaustive]
pub struct Linearization {
    pub dof_names: Vec<String>,
    pub input_names: Vec<String>,
    /// the state: t, q, qd, qdd (= M⁻¹h), u
    pub t: f64,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    pub u: Vec<f64>,
    /// mass, damping and stiffness matrices (n × n), input matrix B_u = ∂h/∂u (n × nu)
    pub m: DMatrix<f64>,
    pub c: DMatrix<f64>,
    pub k: DMatrix<f64>,
    pub bu: DMatrix<f64>,
    /// state space ẋ = A x + B δu, x = (δq, δq̇): A (2n × 2n), B (2n × nu)
    pub a: DMatrix<f64>,
    pub b: DMatrix<f64>,
    /// whether C and K come from exact tangents (else central differences)
    pub exact: bool,
}

/// Linearises `model` about (t, q, qd, u); K and C by `how` (Auto: exact tangents when
/// generated).
pub fn linearize<M: Model>(
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
    for (name, v, len) in [("q", q, n), ("qd", qd, n), ("u", u, nu)] {
        if v.len() != len {
            return Err(Failure::InvalidOption {
                name,
                value: v.len().to_string(),
                reason: "has the wrong length for this model",
            }
            .into());
        }
        check(model, name, v)?;
    }
    // qdd = M⁻¹ h
    let (mut m, mut h) = (vec![0.0; n * n], vec![0.0; n]);
    model.dynamics(t, q, qd, u, &mut m, &mut h);
    check(model, "M", &m)?;
    check(model, "h", &h)?;
    let mut l = m.clone();
    cholesky(&mut l, n).map_err(|s| Failure::SingularMatrix {
        matrix: "the mass matrix M",
        rcond: s.rcond,
        coordinates: vec![info.dof_label(s.column)],
    })?;
    let mut qdd = h.clone();
    cholesky_solve(&l, n, &mut qdd);
    let exact = match how {
        IterationMatrix::Exact => true,
        IterationMatrix::Auto => info.has_tangents,
        _ => false,
    };
    let (mut k, mut c) = (vec![0.0; n * n], vec![0.0; n * n]);
    if exact {
        model
            .tangents(t, q, qd, &qdd, u, &mut k, &mut c)
            .map_err(|_| Failure::InvalidOption {
                name: "how",
                value: "Exact".into(),
                reason: "the model has no tangents: add `option tangents;`",
            })?;
    } else {
        // central differences of τ in q and in qd
        let (mut tp, mut tm) = (vec![0.0; n], vec![0.0; n]);
        let (mut qp, mut vp) = (q.to_vec(), qd.to_vec());
        for j in 0..n {
            for (var, out) in [(0, &mut k), (1, &mut c)] {
                let x = if var == 0 { q[j] } else { qd[j] };
                let eps = f64::EPSILON.cbrt() * x.abs().max(1.0);
                let target = if var == 0 { &mut qp } else { &mut vp };
                target[j] = x + eps;
                model.inverse_dynamics(t, &qp, &vp, &qdd, u, &mut tp);
                let target = if var == 0 { &mut qp } else { &mut vp };
                target[j] = x - eps;
                model.inverse_dynamics(t, &qp, &vp, &qdd, u, &mut tm);
                let target = if var == 0 { &mut qp } else { &mut vp };
                target[j] = x;
                for i in 0..n {
                    out[i + n * j] = (tp[i] - tm[i]) / (2.0 * eps);
                }
            }
        }
    }
    check(model, "K", &k)?;
    check(model, "C", &c)?;
    let mut bu = vec![0.0; n * nu];
    model.input_matrix(t, q, qd, u, &mut bu);
    check(model, "B_u", &bu)?;
    // A and B: solve with M column by column
    let mut a = DMatrix::zeros(2 * n, 2 * n);
    let mut b = DMatrix::zeros(2 * n, nu);
    for i in 0..n {
        a[(i, n + i)] = 1.0;
    }
    let mut col = vec![0.0; n];
    for j in 0..n {
        for (src, off) in [(&k, 0), (&c, n)] {
            col.copy_from_slice(&src[j * n..(j + 1) * n]);
            cholesky_solve(&l, n, &mut col);
            for i in 0..n {
                a[(n + i, off + j)] = -col[i];
            }
        }
    }
    for j in 0..nu {
        col.copy_from_slice(&bu[j * n..(j + 1) * n]);
        cholesky_solve(&l, n, &mut col);
        for i in 0..n {
            b[(n + i, j)] = col[i];
        }
    }
    Ok(Linearization {
        dof_names: (0..n).map(|i| info.dof_label(i)).collect(),
        input_names: info.inputs.iter().map(|s| s.to_string()).collect(),
        t,
        q: q.to_vec(),
        qd: qd.to_vec(),
        qdd,
        u: u.to_vec(),
        m: DMatrix::from_column_slice(n, n, &m),
        c: DMatrix::from_column_slice(n, n, &c),
        k: DMatrix::from_column_slice(n, n, &k),
        bu: DMatrix::from_column_slice(n, nu, &bu),
        a,
        b,
        exact,
    })
}
