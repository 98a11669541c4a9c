//! Holonomic constraints Φ(q, t) = 0 on the DAG: Φ from the constraint descriptions (world
//! kinematics for closures), B = ∂Φ/∂q, Φ_t = ∂Φ/∂t, γ with B qdd = γ (γ = −Φ̈ at qdd = 0:
//! the total time derivative of Φ̇ = B qd + Φ_t with the accelerations set to zero), and
//! ∂(Bᵀλ)/∂q for Newton, with λ as symbols; with parameters marked `sensitive`, the
//! derivatives the sensitivities of a closed loop need ([`ConstraintSensitivity`]).

use super::spatial::{self as s, Matrix};
use super::system::{Attach, ConstraintKind, System};
use super::tree::Tree;
use super::world::World;
use crate::expr::{Arena, ExprId, Var};

/// The constraints of a system, symbolically.
#[derive(Clone, Debug, Default)]
pub struct ConstraintEquations {
    pub phi: Vec<ExprId>,
    /// B (nc × n, row-major)
    pub b: Matrix,
    pub phi_t: Vec<ExprId>,
    pub gamma: Vec<ExprId>,
    /// ∂(Bᵀλ)/∂q (n × n, row-major), λ as `Var::Lambda`
    pub tangent: Matrix,
    /// with parameters marked `sensitive` (and constraints)
    pub sensitivity: Option<ConstraintSensitivity>,
}

/// What forward and static sensitivities of a closed loop need besides ∂τ/∂p: the
/// derivatives of Φ, of Φ̇ = B qd + Φ_t and of Φ̈ = B qdd − γ by the coordinates and by the
/// sensitive parameters, and ∂(Bᵀλ)/∂p (row-major; NS columns in declaration order).
#[derive(Clone, Debug, Default)]
pub struct ConstraintSensitivity {
    /// ∂Φ/∂p (nc × ns)
    pub dphi_dp: Matrix,
    /// ∂Φ̇/∂q (nc × n)
    pub drate_dq: Matrix,
    /// ∂Φ̇/∂p (nc × ns)
    pub drate_dp: Matrix,
    /// ∂Φ̈/∂q (nc × n), qdd as symbols
    pub dacc_dq: Matrix,
    /// ∂Φ̈/∂qd (nc × n)
    pub dacc_dqd: Matrix,
    /// ∂Φ̈/∂p (nc × ns)
    pub dacc_dp: Matrix,
    /// ∂(Bᵀλ)/∂p (n × ns)
    pub dforce_dp: Matrix,
    /// with `option tangents;` (pole sensitivities): the derivatives of B (nc × n) and of
    /// K_λ = ∂(Bᵀλ)/∂q (n × n), each as n·(1 + ns) columns in blocks: block 0 along the
    /// direction given as `Var::Qd` (Σₖ ∂X/∂qₖ qdₖ: B and K_λ do not depend on qd), block
    /// 1 + j by sensitive parameter j
    pub rest: Option<[Matrix; 2]>,
}

impl ConstraintSensitivity {
    fn build(
        a: &mut Arena,
        c: &ConstraintEquations,
        btl: &[ExprId],
        sensitive: &[u16],
        rest: bool,
    ) -> ConstraintSensitivity {
        let n = c.tangent.len();
        // B v ∘ e row by row: Φ̇ = B qd + Φ_t, Φ̈ = B qdd − γ
        let mut b_times = |var: fn(u16) -> Var,
                           with: fn(&mut Arena, ExprId, ExprId) -> ExprId,
                           e: &[ExprId]|
         -> Vec<ExprId> {
            let v: Vec<ExprId> = (0..n).map(|j| a.var(var(j as u16))).collect();
            c.b.iter()
                .zip(e)
                .map(|(row, &e)| {
                    let bv = a.dot(row, &v);
                    with(a, bv, e)
                })
                .collect()
        };
        let rate = b_times(Var::Qd, Arena::add, &c.phi_t);
        let acc = b_times(Var::Qdd, Arena::sub, &c.gamma);
        let rest = rest
            .then(|| [&c.b, &c.tangent].map(|x| super::dynamics::along_and_by(a, x, n, sensitive)));
        let mut by = |x: &[ExprId], var: &dyn Fn(usize) -> Var, count: usize| -> Matrix {
            x.iter()
                .map(|&e| (0..count).map(|j| a.diff(e, var(j))).collect())
                .collect()
        };
        let param = |j: usize| Var::Param(sensitive[j]);
        let q = |j: usize| Var::Q(j as u16);
        let qd = |j: usize| Var::Qd(j as u16);
        let ns = sensitive.len();
        ConstraintSensitivity {
            rest,
            dphi_dp: by(&c.phi, &param, ns),
            drate_dq: by(&rate, &q, n),
            drate_dp: by(&rate, &param, ns),
            dacc_dq: by(&acc, &q, n),
            dacc_dqd: by(&acc, &qd, n),
            dacc_dp: by(&acc, &param, ns),
            dforce_dp: by(btl, &param, ns),
        }
    }
}

fn position(a: &mut Arena, w: &World, tree: &Tree, p: &Attach) -> s::V3 {
    match p.frame {
        Some(f) => w.point_position(a, tree.frame_node[f], p.pos),
        None => p.pos,
    }
}

/// Axis k of frame f (world axes): a column of its rotation, or e_k for the ground.
fn axis(a: &Arena, w: &World, tree: &Tree, f: Option<usize>, k: usize) -> s::V3 {
    match f {
        Some(f) => {
            let r = &w.nodes[tree.frame_node[f]].r;
            [r[0][k], r[1][k], r[2][k]]
        }
        None => {
            let mut e = s::zero3(a);
            e[k] = a.one();
            e
        }
    }
}

impl ConstraintEquations {
    pub fn build(sys: &mut System, tree: &Tree, w: &World) -> ConstraintEquations {
        let defs = sys.constraints.clone();
        let n = sys.ndof();
        let a = &mut sys.arena;
        let phi: Vec<ExprId> = defs
            .iter()
            .map(|c| match c.kind {
                ConstraintKind::Scalar(e) => e,
                ConstraintKind::Coincide {
                    a: pa,
                    b: pb,
                    axis: k,
                    frame,
                } => {
                    let xa = position(a, w, tree, &pa);
                    let xb = position(a, w, tree, &pb);
                    let d = s::sub(a, xb, xa);
                    let e = axis(a, w, tree, frame, k);
                    s::dot(a, e, d)
                }
                ConstraintKind::Align {
                    a: fa,
                    b: fb,
                    axis: k,
                } => {
                    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                    let (ai, aj) = (axis(a, w, tree, fa, i), axis(a, w, tree, fa, j));
                    let (bi, bj) = (axis(a, w, tree, fb, i), axis(a, w, tree, fb, j));
                    let x = s::dot(a, ai, bj);
                    let y = s::dot(a, aj, bi);
                    let d = a.sub(x, y);
                    a.scale(0.5, d)
                }
            })
            .collect();
        let b: Matrix = phi
            .iter()
            .map(|&p| (0..n).map(|j| a.diff(p, Var::Q(j as u16))).collect())
            .collect();
        let phi_t: Vec<ExprId> = phi.iter().map(|&p| a.diff(p, Var::T)).collect();
        let gamma: Vec<ExprId> = phi
            .iter()
            .map(|&p| {
                let rate = a.dt(p);
                let acc0 = a.dt_bias(rate);
                a.neg(acc0)
            })
            .collect();
        // Σ_i λ_i B_ij, then its q-derivatives
        let lam: Vec<ExprId> = (0..phi.len())
            .map(|i| a.var(Var::Lambda(i as u16)))
            .collect();
        let btl: Vec<ExprId> = (0..n)
            .map(|j| {
                let col: Vec<ExprId> = b.iter().map(|row| row[j]).collect();
                a.dot(&col, &lam)
            })
            .collect();
        let tangent: Matrix = btl
            .iter()
            .map(|&f| (0..n).map(|k| a.diff(f, Var::Q(k as u16))).collect())
            .collect();
        let sensitive: Vec<u16> = (0..sys.params.len())
            .filter(|&i| sys.params[i].sensitive)
            .map(|i| i as u16)
            .collect();
        let mut c = ConstraintEquations {
            phi,
            b,
            phi_t,
            gamma,
            tangent,
            sensitivity: None,
        };
        if !c.phi.is_empty() && !sensitive.is_empty() {
            let rest = sys.options.tangents;
            c.sensitivity = Some(ConstraintSensitivity::build(a, &c, &btl, &sensitive, rest));
        }
        c
    }
}
