//! Holonomic constraints Φ(q, t) = 0 on the DAG: Φ from the constraint descriptions (world
//! kinematics for closures), B = ∂Φ/∂q, Φ_t = ∂Φ/∂t, γ with B qdd = γ (γ = −Φ̈ at qdd = 0:
//! the total time derivative of Φ̇ = B qd + Φ_t with the accelerations set to zero), and
//! ∂(Bᵀλ)/∂q for Newton, with λ as symbols.

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
        ConstraintEquations {
            phi,
            b,
            phi_t,
            gamma,
            tangent,
        }
    }
}
