//! Contact of a point (or a sphere of radius r centred at it) at x, velocity v, with the
//! plane n·x = h0: δ = h0 + r − n·x, δ̇ = −n·v,
//! F_n = step(δ)·pos(k δ + c δ̇), v_c = v + ω × (−r n) (the contact point's velocity),
//! v_t = v_c − (n·v) n, F_t = −μ F_n v_t / sqrt(v_t·v_t + eps²); the force F_n n + F_t acts
//! at the centre with the torque (−r n) × F_t. Potential ½ k pos(δ)² (its gradient gives
//! the elastic part k pos(δ) n); power (F_n − k pos(δ)) (n·v) + F_t·v_c, both terms ≤ 0.
//!
//! An ellipsoid with semi-axes D = diag(a, b, c) along its body's axes R, centred at x: its
//! support point along −n is x − R D² m / s with m = Rᵀ n and s = sqrt(mᵀ D² m), so
//! δ = h0 − n·x + s. The material point at the support point moves with n·v_s = −δ̇ (the
//! derivative of s is ω·(R D² m × n)/s), so the forces act there and the energy identity
//! holds as for a point.
//!
//! With an exponent e or a Hunt–Crossley dissipation d: elastic part k pos(δ)^e, potential
//! k pos(δ)^(e+1)/(e + 1), F_n = step(δ)·pos(k pos(δ)^e (1 + d δ̇) + c δ̇).

use super::{Build, Pt};
use crate::expr::{ExprId, Func};
use crate::mech::spatial::{self as s, V3};
use crate::mech::system::Load;

pub(super) fn build(b: &mut Build, load: &Load) {
    let Load::Contact {
        at,
        radius,
        ellipsoid,
        exponent,
        dissipation,
        normal: n,
        offset,
        k,
        c,
        mu,
        eps,
    } = *load
    else {
        unreachable!("contact::build is given contacts")
    };
    b.elastic = true;
    let p = b.pt(&at);
    // where the forces act, the penetration, n·v there (= −δ̇), the friction's velocity and
    // the arm of the friction's torque about the point where the force is pushed
    let (p, delta, nv, vc, arm) = match (ellipsoid, p.node) {
        (Some(axes), Some(node)) => {
            let (p, delta, nv, v) = support_point(b, &p, node, axes, n, offset);
            (p, delta, nv, v, None)
        }
        _ => {
            let x = b.position(&p);
            let v = b.velocity(&p);
            let a = &mut *b.a;
            let nx = s::dot(a, n, x);
            let h = a.add(offset, radius);
            let delta = a.sub(h, nx);
            let nv = s::dot(a, n, v);
            // the contact point x − r n, material point of the body
            let (vc, arm) = match p.node {
                Some(node) if !a.is_num(radius, 0.0) => {
                    let arm = s::scale(a, radius, n);
                    let arm = s::neg(a, arm);
                    let wxr = s::cross(a, b.w.nodes[node].w, arm);
                    (s::add(a, v, wxr), Some((node, arm)))
                }
                _ => (v, None),
            };
            (p, delta, nv, vc, arm)
        }
    };
    let f_n = if b.a.is_num(exponent, 1.0) && b.a.is_num(dissipation, 0.0) {
        linear_normal(b, delta, nv, k, c)
    } else {
        hunt_crossley_normal(b, delta, nv, k, c, exponent, dissipation)
    };
    let mut f = s::scale(b.a, f_n, n);
    if !b.a.is_num(mu, 0.0) {
        b.dissipative = true;
        let a = &mut *b.a;
        let vn = s::scale(a, nv, n);
        let vt = s::sub(a, vc, vn);
        let vt2 = s::dot(a, vt, vt);
        let e2 = a.mul(eps, eps);
        let r2 = a.add(vt2, e2);
        let r = a.sqrt(r2);
        let mf = a.mul(mu, f_n);
        let coef = a.div(mf, r);
        let coef = a.neg(coef);
        let ft = s::scale(a, coef, vt);
        f = s::add(a, f, ft);
        let pw = s::dot(a, ft, vc);
        b.add_power(pw);
        if let Some((node, arm)) = arm {
            let m = s::cross(b.a, arm, ft);
            b.out.torques.push((node, m));
        }
    }
    b.push_force(&p, f);
}

/// The support point of the ellipsoid of semi-axes `axes` centred at `p` (on `node`) along
/// −n: the point (in the node's axes), the penetration δ, n·v and the velocity there.
fn support_point(
    b: &mut Build,
    p: &Pt,
    node: usize,
    axes: [ExprId; 3],
    n: V3,
    offset: ExprId,
) -> (Pt, ExprId, ExprId, V3) {
    let x = b.position(p);
    let r = b.w.nodes[node].r;
    let a = &mut *b.a;
    let m = s::mul_mtv(a, &r, n);
    let d2m: V3 = std::array::from_fn(|i| {
        let sq = a.powi(axes[i], 2);
        a.mul(sq, m[i])
    });
    let s2 = s::dot(a, m, d2m);
    let sd = a.sqrt(s2);
    let reach: V3 = std::array::from_fn(|i| a.div(d2m[i], sd));
    let point = s::sub(a, p.r, reach);
    let nx = s::dot(a, n, x);
    let h = a.sub(offset, nx);
    let delta = a.add(h, sd);
    let support = Pt {
        node: Some(node),
        r: point,
    };
    let v = b.velocity(&support);
    let nv = s::dot(b.a, n, v);
    (support, delta, nv, v)
}

/// F_n = step(δ) pos(k δ + c δ̇) (k pos(δ) without damping), potential ½ k pos(δ)².
fn linear_normal(b: &mut Build, delta: ExprId, nv: ExprId, k: ExprId, c: ExprId) -> ExprId {
    let a = &mut *b.a;
    // elastic part k pos(δ), potential ½ k pos(δ)²
    let pd = a.func(Func::Pos, delta);
    let elastic = a.mul(k, pd);
    let pd2 = a.powi(pd, 2);
    let e = a.mul(k, pd2);
    let e = a.mul(b.half, e);
    b.add_potential(e);
    // F_n = step(δ) pos(k δ + c δ̇), δ̇ = −n·v; without damping it is the elastic part
    // (k ≥ 0)
    if b.a.is_num(c, 0.0) {
        return elastic;
    }
    let a = &mut *b.a;
    let kd = a.mul(k, delta);
    let cn = a.mul(c, nv);
    let raw = a.sub(kd, cn);
    gated(b, delta, nv, elastic, raw)
}

/// F_n = step(δ) pos(raw), a force that never pulls and acts in contact only; its part
/// beyond the elastic one counts in the power (at the contact point's n·v = −δ̇).
fn gated(b: &mut Build, delta: ExprId, nv: ExprId, elastic: ExprId, raw: ExprId) -> ExprId {
    b.dissipative = true;
    let a = &mut *b.a;
    let on = a.func(Func::Step, delta);
    let pr = a.func(Func::Pos, raw);
    let f_n = a.mul(on, pr);
    let damping = a.sub(f_n, elastic);
    let pw = a.mul(damping, nv);
    b.add_power(pw);
    f_n
}

/// F_n = step(δ) pos(k pos(δ)^e (1 + d δ̇) + c δ̇), potential k pos(δ)^(e+1) / (e + 1).
fn hunt_crossley_normal(
    b: &mut Build,
    delta: ExprId,
    nv: ExprId,
    k: ExprId,
    c: ExprId,
    e: ExprId,
    d: ExprId,
) -> ExprId {
    let a = &mut *b.a;
    let one = a.one();
    let pd = a.func(Func::Pos, delta);
    let pe = a.pow(pd, e);
    let elastic = a.mul(k, pe);
    let e1 = a.add(e, one);
    let pe1 = a.pow(pd, e1);
    let v = a.mul(k, pe1);
    let v = a.div(v, e1);
    b.add_potential(v);
    if b.a.is_num(c, 0.0) && b.a.is_num(d, 0.0) {
        return elastic;
    }
    let a = &mut *b.a;
    // δ̇ = −n·v
    let dn = a.mul(d, nv);
    let factor = a.sub(one, dn);
    let hc = a.mul(elastic, factor);
    let cn = a.mul(c, nv);
    let raw = a.sub(hc, cn);
    gated(b, delta, nv, elastic, raw)
}
