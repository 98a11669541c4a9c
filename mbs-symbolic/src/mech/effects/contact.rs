//! Contact of a point (or a sphere of radius r centred at it) at x, velocity v, with the
//! plane n·x = h0: δ = h0 + r − n·x, δ̇ = −n·v,
//! F_n = step(δ)·pos(k δ + c δ̇), v_c = v + ω × (−r n) (the contact point's velocity),
//! v_t = v_c − (n·v) n, F_t = −μ F_n v_t / sqrt(v_t·v_t + eps²); the force F_n n + F_t acts
//! at the centre with the torque (−r n) × F_t. Potential ½ k pos(δ)² (its gradient gives
//! the elastic part k pos(δ) n); power (F_n − k pos(δ)) (n·v) + F_t·v_c, both terms ≤ 0.

use super::Build;
use crate::expr::Func;
use crate::mech::spatial as s;
use crate::mech::system::Load;

pub(super) fn build(b: &mut Build, load: &Load) {
    let Load::Contact {
        at,
        radius,
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
    let x = b.position(&p);
    let v = b.velocity(&p);
    let a = &mut *b.a;
    let nx = s::dot(a, n, x);
    let h = a.add(offset, radius);
    let delta = a.sub(h, nx);
    let nv = s::dot(a, n, v);
    // elastic part k pos(δ), potential ½ k pos(δ)²
    let pd = a.func(Func::Pos, delta);
    let elastic = a.mul(k, pd);
    let pd2 = a.powi(pd, 2);
    let e = a.mul(k, pd2);
    let e = a.mul(b.half, e);
    b.add_potential(e);
    // F_n = step(δ) pos(k δ + c δ̇), δ̇ = −n·v; without damping it is the elastic part
    // (k ≥ 0)
    let f_n = if b.a.is_num(c, 0.0) {
        elastic
    } else {
        b.dissipative = true;
        let a = &mut *b.a;
        let kd = a.mul(k, delta);
        let cn = a.mul(c, nv);
        let raw = a.sub(kd, cn);
        let on = a.func(Func::Step, delta);
        let pr = a.func(Func::Pos, raw);
        let f_n = a.mul(on, pr);
        let damping = a.sub(f_n, elastic);
        let pw = a.mul(damping, nv);
        b.add_power(pw);
        f_n
    };
    let mut f = s::scale(b.a, f_n, n);
    if !b.a.is_num(mu, 0.0) {
        b.dissipative = true;
        let a = &mut *b.a;
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
