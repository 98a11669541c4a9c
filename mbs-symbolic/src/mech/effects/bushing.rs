//! Bushing between frames A and B (rotations R_A, R_B, origins p_A, p_B, ground: I, 0):
//! d = p_B − p_A, Δp = R_Aᵀ d, Δv = R_Aᵀ (v_B − v_A − ω_A × d) = d(Δp)/dt (B's origin
//! relative to the point of A it coincides with), R = R_Aᵀ R_B,
//! θ = ½ (R₃₂ − R₂₃, R₁₃ − R₃₁, R₂₁ − R₁₂) (≈ the rotation vector of B relative to A),
//! Ω = R_Aᵀ (ω_B − ω_A), E = ½ (tr(R) I − R) (so that dθ/dt = E Ω). In A's axes the force on
//! B at its origin is f = −K Δp − C Δv and the torque on B is m = −Eᵀ K_r θ − C_r Ω
//! (−Eᵀ K_r θ = −K_r θ to first order in the angle; it is the exact gradient of the
//! potential). A receives −f at the point coinciding with B's origin and −m. Potential
//! ½ Δpᵀ K Δp + ½ θᵀ K_r θ; power −Δvᵀ C Δv − Ωᵀ C_r Ω.

use super::Build;
use crate::expr::{Arena, ExprId};
use crate::mech::spatial as s;
use crate::mech::system::Load;

pub(super) fn build(b: &mut Build, load: &Load) {
    let Load::Bushing {
        a: fa,
        b: fb,
        k,
        kr,
        c,
        cr,
    } = *load
    else {
        unreachable!("bushing::build is given bushings")
    };
    let (tree, w, half) = (b.tree, b.w, b.half);
    let kin = |a: &Arena, f: Option<usize>| match f {
        Some(f) => {
            let node = tree.frame_node[f];
            let nk = &w.nodes[node];
            (Some(node), nk.r, nk.p, nk.v, nk.w)
        }
        None => {
            let z = s::zero3(a);
            (None, s::identity(a), z, z, z)
        }
    };
    let (na, ra, pa, va, wa) = kin(b.a, fa);
    let (nb, rb, pb, vb, wb) = kin(b.a, fb);
    let zero3 = |a: &Arena, x: &[ExprId; 3]| x.iter().all(|&e| a.is_num(e, 0.0));
    let (has_k, has_kr) = (!zero3(b.a, &k), !zero3(b.a, &kr));
    let (has_c, has_cr) = (!zero3(b.a, &c), !zero3(b.a, &cr));
    b.elastic |= has_k || has_kr;
    b.dissipative |= has_c || has_cr;
    let mul3 = |a: &mut Arena, x: [ExprId; 3], y: [ExprId; 3]| {
        [a.mul(x[0], y[0]), a.mul(x[1], y[1]), a.mul(x[2], y[2])]
    };
    // translation, A's axes
    let d = s::sub(b.a, pb, pa);
    let dp = s::mul_mtv(b.a, &ra, d);
    let mut f = s::zero3(b.a);
    if has_k {
        let a = &mut *b.a;
        let kdp = mul3(a, k, dp);
        f = s::neg(a, kdp);
        let e = s::dot(a, dp, kdp);
        let e = a.mul(half, e);
        b.add_potential(e);
    }
    if has_c {
        let a = &mut *b.a;
        let wxd = s::cross(a, wa, d);
        let dv = s::sub(a, vb, va);
        let dv = s::sub(a, dv, wxd);
        let dv = s::mul_mtv(a, &ra, dv);
        let cdv = mul3(a, c, dv);
        f = s::sub(a, f, cdv);
        let pw = s::dot(a, cdv, dv);
        b.sub_power(pw);
    }
    // rotation, A's axes
    let mut m = s::zero3(b.a);
    if has_kr {
        let a = &mut *b.a;
        // R = R_Aᵀ R_B, θ = vee(½ (R − Rᵀ)), m = −Eᵀ K_r θ, E = ½ (tr R I − R)
        let r = s::mul_mm(a, &s::transpose(&ra), &rb);
        let th = [(2, 1), (0, 2), (1, 0)].map(|(i, j)| {
            let x = a.sub(r[i][j], r[j][i]);
            a.mul(half, x)
        });
        let kth = mul3(a, kr, th);
        let e = s::dot(a, th, kth);
        let e = a.mul(half, e);
        b.add_potential(e);
        let a = &mut *b.a;
        let tr = a.sum([r[0][0], r[1][1], r[2][2]]);
        let rtk = s::mul_mtv(a, &r, kth);
        let trk = s::scale(a, tr, kth);
        let etk = s::sub(a, trk, rtk);
        let etk = s::scale(a, half, etk);
        m = s::neg(a, etk);
    }
    if has_cr {
        let a = &mut *b.a;
        let dw = s::sub(a, wb, wa);
        let om = s::mul_mtv(a, &ra, dw);
        let crw = mul3(a, cr, om);
        m = s::sub(a, m, crw);
        let pw = s::dot(a, crw, om);
        b.sub_power(pw);
    }
    let a = &mut *b.a;
    let fw = s::mul_mv(a, &ra, f);
    let mw = s::mul_mv(a, &ra, m);
    let nfw = s::neg(a, fw);
    let nmw = s::neg(a, mw);
    let z = s::zero3(a);
    if let Some(nb) = nb {
        b.out.forces.push((nb, z, fw));
        b.out.torques.push((nb, mw));
    }
    if let Some(na) = na {
        // at the point of A where B's origin is
        b.out.forces.push((na, dp, nfw));
        b.out.torques.push((na, nmw));
    }
}
