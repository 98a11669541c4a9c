//! The pieces the analyses of constrained models share (`M qdd = h + Bᵀλ`, `Φ(q, t) = 0`,
//! `B = ∂Φ/∂q`, NC × NQ): the rank of B and the typed failure naming the constraints that
//! repeat, the split of the coordinates into dependent and independent ones (complete pivoting
//! on B, or the model's `independent` marks), the basis N of B's null space
//! (`δq = N δz`, with E the map of constraint corrections onto the dependent coordinates),
//! an orthonormal null-space basis, the Hessians of the constraints and the index-1
//! accelerations. Dense nalgebra matrices throughout: the analyses are not in a time loop.

use super::{AnalysisError, check, check_named};
use crate::error::Failure;
use crate::linalg::{cholesky, cholesky_solve};
use crate::model::Model;
use nalgebra::DMatrix;

/// A singular value at or below this fraction of the largest counts as zero.
pub(super) const RANK_TOL: f64 = 1e-10;

pub(super) use crate::integrators::constrained::worst;

/// Φ(q, t) (NC), checked finite.
pub(super) fn constraints<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
) -> Result<Vec<f64>, AnalysisError> {
    let mut phi = vec![0.0; M::NC];
    model.constraints(t, q, &mut phi);
    check_constraints(model, "Φ", &phi)?;
    Ok(phi)
}

/// B = ∂Φ/∂q (NC × NQ), checked finite.
pub(super) fn jacobian<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
) -> Result<DMatrix<f64>, AnalysisError> {
    let mut b = vec![0.0; M::NC * M::NQ];
    model.constraint_jacobian(t, q, &mut b);
    // column-major NC × NQ: entry i is in the column of coordinate i / NC
    let info = model.info();
    check_named("B = ∂Φ/∂q", &b, |i| info.dof_label(i / M::NC.max(1)))?;
    Ok(DMatrix::from_column_slice(M::NC, M::NQ, &b))
}

/// ∂(Bᵀλ)/∂q (NQ × NQ), checked finite.
pub(super) fn constraint_tangent<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
    lambda: &[f64],
) -> Result<DMatrix<f64>, AnalysisError> {
    let n = M::NQ;
    let mut g = vec![0.0; n * n];
    model.constraint_tangent(t, q, lambda, &mut g);
    check(model, "∂(Bᵀλ)/∂q", &g)?;
    Ok(DMatrix::from_column_slice(n, n, &g))
}

/// A non-finite value in a per-constraint vector, named by constraint.
pub(super) fn check_constraints<M: Model>(
    model: &M,
    quantity: &'static str,
    v: &[f64],
) -> Result<(), AnalysisError> {
    let names = model.info().constraints;
    Failure::non_finite(quantity, v, |i| {
        format!("(constraint `{}`)", names.get(i).copied().unwrap_or("?"))
    })
    .map_err(AnalysisError::from)
}

/// Numerical rank of B (nc × n), its smallest singular value and the constraints involved
/// in a deficiency (the simulation's test, from the SVD of B).
pub(super) fn rank_of(b: &DMatrix<f64>) -> (usize, f64, Vec<usize>) {
    if b.nrows() == 0 {
        return (0, 0.0, Vec::new());
    }
    crate::integrators::constrained::rank_of(b.as_slice(), b.nrows(), b.ncols())
}

/// `RankDeficientConstraints` for B when its rank is below its number of rows.
pub(super) fn rank_check(b: &DMatrix<f64>, names: &[&str]) -> Result<(), Failure> {
    let (rank, sigma_min, involved) = rank_of(b);
    if rank < b.nrows() {
        return Err(Failure::RankDeficientConstraints {
            rank,
            nc: b.nrows(),
            sigma_min,
            constraints: involved
                .iter()
                .map(|&i| names.get(i).copied().unwrap_or("?").to_string())
                .collect(),
        });
    }
    Ok(())
}

/// Why B failed a factorisation it needs full rank for: `RankDeficientConstraints` when its
/// singular values say so, and otherwise (full rank by them, but too nearly dependent for the
/// normal equations or for pivoting) a singular matrix that names the constraints involved.
pub(super) fn nearly_dependent(b: &DMatrix<f64>, names: &[&str]) -> Failure {
    match rank_check(b, names) {
        Err(f) => f,
        Ok(()) => {
            let (_, sigma_min, involved) = rank_of(b);
            let sigma_max = b.singular_values().max();
            Failure::SingularMatrix {
                matrix: "B (its constraints nearly dependent)",
                rcond: if sigma_max > 0.0 {
                    sigma_min / sigma_max
                } else {
                    0.0
                },
                coordinates: involved
                    .iter()
                    .map(|&i| format!("constraint `{}`", names.get(i).copied().unwrap_or("?")))
                    .collect(),
                cause: String::new(),
            }
        }
    }
}

/// The columns of B (nc × n) complete pivoting picks, in pivot order: the coordinates best
/// solved for (dependent). `None` when a pivot falls to `RANK_TOL` of the largest entry.
pub(super) fn pivot_columns(b: &DMatrix<f64>) -> Option<Vec<usize>> {
    let (nc, n) = b.shape();
    let mut a = b.clone();
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut cols = Vec::with_capacity(nc);
    for k in 0..nc {
        let (mut best, mut pi, mut pj) = (0.0, k, usize::MAX);
        for j in (0..n).filter(|j| !cols.contains(j)) {
            for i in k..nc {
                if a[(i, j)].abs() > best {
                    (best, pi, pj) = (a[(i, j)].abs(), i, j);
                }
            }
        }
        if pj == usize::MAX || !(best > RANK_TOL * scale) {
            return None;
        }
        a.swap_rows(k, pi);
        for i in k + 1..nc {
            let f = a[(i, pj)] / a[(k, pj)];
            for j in 0..n {
                let v = a[(k, j)];
                a[(i, j)] -= f * v;
            }
        }
        cols.push(pj);
    }
    Some(cols)
}

/// σ_min/σ_max of a square matrix (0 when singular or empty rows).
pub(super) fn rcond(a: &DMatrix<f64>) -> f64 {
    if a.nrows() == 0 {
        return 1.0;
    }
    let s = a.clone().singular_values();
    let (lo, hi) = s.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &v| {
        (lo.min(v), hi.max(v))
    });
    if hi > 0.0 { lo / hi } else { 0.0 }
}

/// The coordinates of a constrained model split in dependent (`dep`, NC of them) and
/// independent (`ind`, NQ − NC, ascending) ones.
#[derive(Clone, Debug)]
pub(super) struct Partition {
    pub ind: Vec<usize>,
    pub dep: Vec<usize>,
    /// whether the model's `independent` marks were used (else complete pivoting on B)
    pub marked: bool,
}

/// The model's marks when they number n − nc and B over the other coordinates has a
/// condition (σ_min/σ_max) at least 1e-3 of that of the set complete pivoting picks; else
/// the pivoting set. `None` when B has no full-rank square block.
pub(super) fn partition(b: &DMatrix<f64>, marks: &[bool]) -> Option<Partition> {
    let (nc, n) = b.shape();
    let mut dep = pivot_columns(b)?;
    dep.sort_unstable();
    let rest = |dep: &[usize]| (0..n).filter(|i| !dep.contains(i)).collect::<Vec<_>>();
    let marked_ind: Vec<usize> = (0..n).filter(|&i| marks.get(i) == Some(&true)).collect();
    if marked_ind.len() == n - nc {
        let mdep = rest(&marked_ind);
        let rc_marked = rcond(&b.select_columns(&mdep));
        let rc_pivot = rcond(&b.select_columns(&dep));
        if rc_marked > 0.0 && rc_marked >= 1e-3 * rc_pivot {
            return Some(Partition {
                ind: marked_ind,
                dep: mdep,
                marked: true,
            });
        }
    }
    Some(Partition {
        ind: rest(&dep),
        dep,
        marked: false,
    })
}

/// N (n × nz): identity on the independent rows, −B_d⁻¹B_i on the dependent ones, so that
/// B N = 0 and δq = N δz; and E (n × nc): B_d⁻¹ on the dependent rows, zero on the others,
/// so that B E = I (a velocity or acceleration satisfying B v = r with v_i = w is N w + E r).
/// `None` when B_d is singular.
pub(super) fn basis(b: &DMatrix<f64>, p: &Partition) -> Option<(DMatrix<f64>, DMatrix<f64>)> {
    let (nc, n) = b.shape();
    let nz = p.ind.len();
    let bd_inv = b.select_columns(&p.dep).try_inverse()?;
    let x = &bd_inv * b.select_columns(&p.ind);
    let mut nmat = DMatrix::zeros(n, nz);
    let mut e = DMatrix::zeros(n, nc);
    for (k, &i) in p.ind.iter().enumerate() {
        nmat[(i, k)] = 1.0;
    }
    for (r, &i) in p.dep.iter().enumerate() {
        for k in 0..nz {
            nmat[(i, k)] = -x[(r, k)];
        }
        for c in 0..nc {
            e[(i, c)] = bd_inv[(r, c)];
        }
    }
    Some((nmat, e))
}

/// An orthonormal basis (n × (n − nc)) of the null space of B (nc × n, full row rank): the
/// pivoting basis N, orthonormalised by QR. `None` when B is rank-deficient.
pub(super) fn orthonormal_null_basis(b: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let (nc, n) = b.shape();
    if nc == n {
        return Some(DMatrix::zeros(n, 0));
    }
    let p = partition(b, &[])?;
    let (nmat, _) = basis(b, &p)?;
    Some(nmat.qr().q())
}

/// The Hessians H_i = ∂(B_iᵀ)/∂q of the constraints (row i of B differentiated), one
/// `constraint_tangent` call with λ = e_i each: (H_i)[k, j] = ∂B[i, k]/∂q_j.
pub(super) fn hessians<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
) -> Result<Vec<DMatrix<f64>>, AnalysisError> {
    let mut e = vec![0.0; M::NC];
    (0..M::NC)
        .map(|i| {
            e.fill(0.0);
            e[i] = 1.0;
            constraint_tangent(model, t, q, &e)
        })
        .collect()
}

/// The index-1 accelerations and multipliers: M qdd = h + Bᵀλ with B qdd = γ, by the Schur
/// complement S = B M⁻¹Bᵀ. `l` is the Cholesky factor of M (column-major n × n).
pub(super) fn index1(
    l: &[f64],
    h: &[f64],
    b: &DMatrix<f64>,
    gamma: &[f64],
    names: &[&str],
) -> Result<(Vec<f64>, Vec<f64>), Failure> {
    let (nc, n) = b.shape();
    let mut qdd = h.to_vec();
    cholesky_solve(l, n, &mut qdd);
    // Y = M⁻¹Bᵀ (n × nc), S = B Y (nc × nc)
    let mut y = vec![0.0; n * nc];
    for c in 0..nc {
        let col = &mut y[c * n..(c + 1) * n];
        for j in 0..n {
            col[j] = b[(c, j)];
        }
        cholesky_solve(l, n, col);
    }
    let mut s = vec![0.0; nc * nc];
    for c in 0..nc {
        for r in 0..nc {
            s[r + nc * c] = (0..n).map(|j| b[(r, j)] * y[j + n * c]).sum();
        }
    }
    cholesky(&mut s, nc).map_err(|_| {
        rank_check(b, names)
            .err()
            .unwrap_or(Failure::SingularMatrix {
                matrix: "B M⁻¹ Bᵀ",
                rcond: 0.0,
                coordinates: Vec::new(),
                cause: String::new(),
            })
    })?;
    let mut lambda: Vec<f64> = (0..nc)
        .map(|r| gamma[r] - (0..n).map(|j| b[(r, j)] * qdd[j]).sum::<f64>())
        .collect();
    cholesky_solve(&s, nc, &mut lambda);
    for c in 0..nc {
        for j in 0..n {
            qdd[j] += y[j + n * c] * lambda[c];
        }
    }
    Ok((qdd, lambda))
}
