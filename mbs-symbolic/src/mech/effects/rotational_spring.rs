//! Rotational spring–damper between frames A and B about a unit axis n (A's axes): θ is the
//! angle of B relative to A about n, T = k (θ − θ0) + c θ̇, and the load is the generalised
//! force −T ∂θ/∂q on every coordinate θ depends on, the torque −T n on B and T n on A when B
//! turns about n relative to A. Potential ½ k (θ − θ0)²; power −c θ̇² (θ̇ the total time
//! derivative, so that the damping's power is that of its torques).
//!
//! θ, in the order tried:
//! - along the tree, when every rotation between A and B (up from each to their common
//!   ancestor) is about ±n: θ = Σ (±angle) on B's side − Σ (±angle) on A's side, the angles
//!   of the `Trot…` factors themselves (for `TOG[B] = TOG[A] * … * Trotz(q[i]) * …`, θ is
//!   q[i]: no trigonometry, ∂θ/∂q[i] = 1), not wrapped;
//! - otherwise from R = R_Aᵀ R_B: θ = atan2(n·vee(R − Rᵀ), tr R − nᵀ R n), the angle in
//!   (−π, π] of a rotation about n, and for any R the twist of R about n.
//!
//! Either way the generalised force is the exact gradient of the potential.

use super::Build;
use crate::expr::{Arena, ExprId, Var};
use crate::mech::spatial as s;
use crate::mech::system::{Factor, Load};
use crate::mech::tree::Tree;

pub(super) fn build(b: &mut Build, load: &Load) {
    let Load::RotationalSpring {
        a: fa,
        b: fb,
        axis,
        k,
        c,
        angle0,
    } = *load
    else {
        unreachable!("rotational_spring::build is given rotational springs")
    };
    let theta = match along_tree(b.a, b.tree, fa, fb, axis) {
        Some(th) => th,
        None => from_rotations(b, fa, fb, axis),
    };
    let has_k = !b.a.is_num(k, 0.0);
    let has_c = !b.a.is_num(c, 0.0);
    let a = &mut *b.a;
    let mut t = a.zero();
    if has_k {
        let stretch = a.sub(theta, angle0);
        t = a.mul(k, stretch);
        let ks2 = a.mul(t, stretch);
        let e = a.mul(b.half, ks2);
        b.elastic = true;
        b.add_potential(e);
    }
    if has_c {
        let a = &mut *b.a;
        let thd = a.dt(theta);
        let ct = a.mul(c, thd);
        t = a.add(t, ct);
        let pw = a.mul(ct, thd);
        b.dissipative = true;
        b.sub_power(pw);
    }
    let a = &mut *b.a;
    for v in a.vars_of(&[theta]) {
        let Var::Q(j) = v else { continue };
        let d = a.diff(theta, v);
        if a.is_num(d, 0.0) {
            continue;
        }
        let td = a.mul(t, d);
        let q = a.neg(td);
        b.out.generalized.push((j as usize, q));
    }
}

/// +1 or −1 when `m` is ±`n` (the same expressions, or the same numbers), else `None`.
fn same_axis(a: &Arena, m: [ExprId; 3], n: [ExprId; 3]) -> Option<f64> {
    if m == n {
        return Some(1.0);
    }
    let num = |v: [ExprId; 3]| -> Option<[f64; 3]> {
        Some([a.as_num(v[0])?, a.as_num(v[1])?, a.as_num(v[2])?])
    };
    let (m, n) = (num(m)?, num(n)?);
    let close = |sg: f64| (0..3).all(|i| (m[i] - sg * n[i]).abs() <= 1e-12);
    [1.0, -1.0].into_iter().find(|&sg| close(sg))
}

/// θ as the sum of the rotation angles between A and B, when they all turn about ±n.
fn along_tree(
    a: &mut Arena,
    tree: &Tree,
    fa: Option<usize>,
    fb: Option<usize>,
    n: [ExprId; 3],
) -> Option<ExprId> {
    let node = |f: Option<usize>| f.map_or(0, |f| tree.frame_node[f]);
    let (mut na, mut nb) = (node(fa), node(fb));
    // signed angles on each side, up to the common ancestor (parents have smaller indices)
    let mut terms: Vec<(f64, ExprId)> = Vec::new();
    while na != nb {
        let (side, cur) = if na > nb {
            (-1.0, &mut na)
        } else {
            (1.0, &mut nb)
        };
        match tree.nodes[*cur].factor {
            Some(Factor::Rot { axis, angle }) => terms.push((side * same_axis(a, axis, n)?, angle)),
            // a chart turns about every axis
            Some(Factor::Chart(_)) => return None,
            _ => {}
        }
        *cur = tree.nodes[*cur].parent;
    }
    let mut th = a.zero();
    for (sg, angle) in terms {
        th = if sg > 0.0 {
            a.add(th, angle)
        } else {
            a.sub(th, angle)
        };
    }
    Some(th)
}

/// θ = atan2(n·vee(R − Rᵀ), tr R − nᵀ R n) with R = R_Aᵀ R_B.
fn from_rotations(b: &mut Build, fa: Option<usize>, fb: Option<usize>, n: [ExprId; 3]) -> ExprId {
    let (tree, w) = (b.tree, b.w);
    let a = &mut *b.a;
    let rot = |a: &Arena, f: Option<usize>| match f {
        Some(f) => w.nodes[tree.frame_node[f]].r,
        None => s::identity(a),
    };
    let (ra, rb) = (rot(a, fa), rot(a, fb));
    let r = s::mul_mm(a, &s::transpose(&ra), &rb);
    let v = [(2, 1), (0, 2), (1, 0)].map(|(i, j)| a.sub(r[i][j], r[j][i]));
    let sin2 = s::dot(a, n, v);
    let tr = a.sum([r[0][0], r[1][1], r[2][2]]);
    let rn = s::mul_mv(a, &r, n);
    let nrn = s::dot(a, n, rn);
    let cos2 = a.sub(tr, nrn);
    a.atan2(sin2, cos2)
}
