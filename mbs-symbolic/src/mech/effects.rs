//! Effects of a scene → applied loads in world axes, their potential energy and the power of
//! the non-conservative ones. Both formulations consume the same loads.
//!
//! Every elastic force is exactly minus the gradient of the potential counted here, and every
//! other load's power is the power of the forces and torques pushed, so that
//! d(T + V)/dt = power holds identically along the motion (`tests/energy.rs`).
//!
//! **Contact** of a point (or a sphere of radius r centred at it) at x, velocity v, with the
//! plane n·x = h0: δ = h0 + r − n·x, δ̇ = −n·v,
//! F_n = step(δ)·pos(k δ + c δ̇), v_c = v + ω × (−r n) (the contact point's velocity),
//! v_t = v_c − (n·v) n, F_t = −μ F_n v_t / sqrt(v_t·v_t + eps²); the force F_n n + F_t acts
//! at the centre with the torque (−r n) × F_t. Potential ½ k pos(δ)² (its gradient gives
//! the elastic part k pos(δ) n); power (F_n − k pos(δ)) (n·v) + F_t·v_c, both terms ≤ 0.
//!
//! **Bushing** between frames A and B (rotations R_A, R_B, origins p_A, p_B, ground: I, 0):
//! d = p_B − p_A, Δp = R_Aᵀ d, Δv = R_Aᵀ (v_B − v_A − ω_A × d) = d(Δp)/dt (B's origin
//! relative to the point of A it coincides with), R = R_Aᵀ R_B,
//! θ = ½ (R₃₂ − R₂₃, R₁₃ − R₃₁, R₂₁ − R₁₂) (≈ the rotation vector of B relative to A),
//! Ω = R_Aᵀ (ω_B − ω_A), E = ½ (tr(R) I − R) (so that dθ/dt = E Ω). In A's axes the force on
//! B at its origin is f = −K Δp − C Δv and the torque on B is m = −Eᵀ K_r θ − C_r Ω
//! (−Eᵀ K_r θ = −K_r θ to first order in the angle; it is the exact gradient of the
//! potential). A receives −f at the point coinciding with B's origin and −m. Potential
//! ½ Δpᵀ K Δp + ½ θᵀ K_r θ; power −Δvᵀ C Δv − Ωᵀ C_r Ω.

use super::spatial::{self as s, V3};
use super::system::{Attach, Load, System};
use super::tree::Tree;
use super::world::World;
use crate::expr::{Arena, ExprId, Func, Var};

/// Loads of a scene, world axes.
#[derive(Clone, Debug, Default)]
pub struct Loads {
    /// uniform gravity (summed over gravity effects), `None` when absent
    pub gravity: Option<V3>,
    /// (node, point in node axes, force)
    pub forces: Vec<(usize, V3, V3)>,
    /// (node, torque)
    pub torques: Vec<(usize, V3)>,
    /// (coordinate, generalised force)
    pub generalized: Vec<(usize, ExprId)>,
    /// potential energy of springs, contacts and bushings (gravity's is computed from the
    /// bodies)
    pub elastic_potential: Option<ExprId>,
    /// power of the non-conservative loads
    pub power: Option<ExprId>,
}

struct Pt {
    node: Option<usize>,
    r: V3,
}

fn pt(tree: &Tree, at: &Attach) -> Pt {
    Pt {
        node: at.frame.map(|f| tree.frame_node[f]),
        r: at.pos,
    }
}

fn position(a: &mut Arena, w: &World, p: &Pt) -> V3 {
    match p.node {
        Some(n) => w.point_position(a, n, p.r),
        None => p.r,
    }
}

fn velocity(a: &mut Arena, w: &World, p: &Pt) -> V3 {
    match p.node {
        Some(n) => w.point_velocity(a, n, p.r),
        None => s::zero3(a),
    }
}

/// The length of d and its direction: |d| and d/|d| along the line, or n·d and n along a
/// fixed unit axis n (a linear element: signed length, constant direction).
fn length_and_direction(a: &mut Arena, d: V3, axis: Option<V3>) -> (ExprId, V3) {
    match axis {
        Some(n) => (s::dot(a, n, d), n),
        None => {
            let l2 = s::dot(a, d, d);
            let l = a.sqrt(l2);
            (l, [a.div(d[0], l), a.div(d[1], l), a.div(d[2], l)])
        }
    }
}

impl Loads {
    /// The loads of `effects` (indices into `sys.effects`).
    pub fn build(sys: &mut System, tree: &Tree, w: &World, effects: &[usize]) -> Loads {
        let mut out = Loads::default();
        let loads: Vec<Load> = effects
            .iter()
            .flat_map(|&e| sys.effects[e].loads.clone())
            .collect();
        let a = &mut sys.arena;
        let mut potential = a.zero();
        let mut power = a.zero();
        let mut any_spring = false;
        let mut any_nc = false;
        let half = a.num(0.5);
        for load in &loads {
            match *load {
                Load::Gravity(g) => {
                    out.gravity = Some(match out.gravity {
                        Some(g0) => s::add(a, g0, g),
                        None => g,
                    });
                }
                Load::Spring {
                    a: pa,
                    b: pb,
                    k,
                    l0,
                    axis,
                    preload,
                } => {
                    any_spring = true;
                    let (p1, p2) = (pt(tree, &pa), pt(tree, &pb));
                    let x1 = position(a, w, &p1);
                    let x2 = position(a, w, &p2);
                    let d = s::sub(a, x2, x1);
                    // length and direction: along the line of the ends, or the given axis
                    let (l, e) = length_and_direction(a, d, axis);
                    let stretch = a.sub(l, l0);
                    let ks = a.mul(k, stretch);
                    // tension F0 + k s, potential (F0 + ½ k s) s = F0 s + ½ k s²
                    let tension = a.add(preload, ks);
                    let f1 = s::scale(a, tension, e);
                    let f2 = s::neg(a, f1);
                    out.push_force(&p1, f1);
                    out.push_force(&p2, f2);
                    let hks = a.mul(half, ks);
                    let per = a.add(preload, hks);
                    let v = a.mul(per, stretch);
                    potential = a.add(potential, v);
                }
                Load::Contact {
                    at,
                    radius,
                    normal: n,
                    offset,
                    k,
                    c,
                    mu,
                    eps,
                } => {
                    any_spring = true;
                    let p = pt(tree, &at);
                    let x = position(a, w, &p);
                    let v = velocity(a, w, &p);
                    let nx = s::dot(a, n, x);
                    let h = a.add(offset, radius);
                    let delta = a.sub(h, nx);
                    let nv = s::dot(a, n, v);
                    // elastic part k pos(δ), potential ½ k pos(δ)²
                    let pd = a.func(Func::Pos, delta);
                    let elastic = a.mul(k, pd);
                    let pd2 = a.powi(pd, 2);
                    let e = a.mul(k, pd2);
                    let e = a.mul(half, e);
                    potential = a.add(potential, e);
                    // F_n = step(δ) pos(k δ + c δ̇), δ̇ = −n·v; without damping it is the
                    // elastic part (k ≥ 0)
                    let f_n = if a.is_num(c, 0.0) {
                        elastic
                    } else {
                        any_nc = true;
                        let kd = a.mul(k, delta);
                        let cn = a.mul(c, nv);
                        let raw = a.sub(kd, cn);
                        let on = a.func(Func::Step, delta);
                        let pr = a.func(Func::Pos, raw);
                        let f_n = a.mul(on, pr);
                        let damping = a.sub(f_n, elastic);
                        let pw = a.mul(damping, nv);
                        power = a.add(power, pw);
                        f_n
                    };
                    let mut f = s::scale(a, f_n, n);
                    if !a.is_num(mu, 0.0) {
                        any_nc = true;
                        // the contact point x − r n, material point of the body
                        let (vc, arm) = match p.node {
                            Some(node) if !a.is_num(radius, 0.0) => {
                                let arm = s::scale(a, radius, n);
                                let arm = s::neg(a, arm);
                                let wxr = s::cross(a, w.nodes[node].w, arm);
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
                        power = a.add(power, pw);
                        if let Some((node, arm)) = arm {
                            let m = s::cross(a, arm, ft);
                            out.torques.push((node, m));
                        }
                    }
                    out.push_force(&p, f);
                }
                Load::Bushing {
                    a: fa,
                    b: fb,
                    k,
                    kr,
                    c,
                    cr,
                } => {
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
                    let (na, ra, pa, va, wa) = kin(a, fa);
                    let (nb, rb, pb, vb, wb) = kin(a, fb);
                    let zero3 = |a: &Arena, x: &[ExprId; 3]| x.iter().all(|&e| a.is_num(e, 0.0));
                    let (has_k, has_kr) = (!zero3(a, &k), !zero3(a, &kr));
                    let (has_c, has_cr) = (!zero3(a, &c), !zero3(a, &cr));
                    any_spring |= has_k || has_kr;
                    any_nc |= has_c || has_cr;
                    let mul3 = |a: &mut Arena, x: [ExprId; 3], y: [ExprId; 3]| {
                        [a.mul(x[0], y[0]), a.mul(x[1], y[1]), a.mul(x[2], y[2])]
                    };
                    // translation, A's axes
                    let d = s::sub(a, pb, pa);
                    let dp = s::mul_mtv(a, &ra, d);
                    let mut f = s::zero3(a);
                    if has_k {
                        let kdp = mul3(a, k, dp);
                        f = s::neg(a, kdp);
                        let e = s::dot(a, dp, kdp);
                        let e = a.mul(half, e);
                        potential = a.add(potential, e);
                    }
                    if has_c {
                        let wxd = s::cross(a, wa, d);
                        let dv = s::sub(a, vb, va);
                        let dv = s::sub(a, dv, wxd);
                        let dv = s::mul_mtv(a, &ra, dv);
                        let cdv = mul3(a, c, dv);
                        f = s::sub(a, f, cdv);
                        let pw = s::dot(a, cdv, dv);
                        power = a.sub(power, pw);
                    }
                    // rotation, A's axes
                    let mut m = s::zero3(a);
                    if has_kr {
                        // R = R_Aᵀ R_B, θ = vee(½ (R − Rᵀ)), m = −Eᵀ K_r θ, E = ½ (tr R I − R)
                        let r = s::mul_mm(a, &s::transpose(&ra), &rb);
                        let th = [(2, 1), (0, 2), (1, 0)].map(|(i, j)| {
                            let x = a.sub(r[i][j], r[j][i]);
                            a.mul(half, x)
                        });
                        let kth = mul3(a, kr, th);
                        let e = s::dot(a, th, kth);
                        let e = a.mul(half, e);
                        potential = a.add(potential, e);
                        let tr = a.sum([r[0][0], r[1][1], r[2][2]]);
                        let rtk = s::mul_mtv(a, &r, kth);
                        let trk = s::scale(a, tr, kth);
                        let etk = s::sub(a, trk, rtk);
                        let etk = s::scale(a, half, etk);
                        m = s::neg(a, etk);
                    }
                    if has_cr {
                        let dw = s::sub(a, wb, wa);
                        let om = s::mul_mtv(a, &ra, dw);
                        let crw = mul3(a, cr, om);
                        m = s::sub(a, m, crw);
                        let pw = s::dot(a, crw, om);
                        power = a.sub(power, pw);
                    }
                    let fw = s::mul_mv(a, &ra, f);
                    let mw = s::mul_mv(a, &ra, m);
                    let nfw = s::neg(a, fw);
                    let nmw = s::neg(a, mw);
                    let z = s::zero3(a);
                    if let Some(nb) = nb {
                        out.forces.push((nb, z, fw));
                        out.torques.push((nb, mw));
                    }
                    if let Some(na) = na {
                        // at the point of A where B's origin is
                        out.forces.push((na, dp, nfw));
                        out.torques.push((na, nmw));
                    }
                }
                Load::Damper {
                    a: pa,
                    b: pb,
                    c,
                    axis,
                } => {
                    any_nc = true;
                    let (p1, p2) = (pt(tree, &pa), pt(tree, &pb));
                    let x1 = position(a, w, &p1);
                    let x2 = position(a, w, &p2);
                    let v1 = velocity(a, w, &p1);
                    let v2 = velocity(a, w, &p2);
                    let d = s::sub(a, x2, x1);
                    let (_, e) = length_and_direction(a, d, axis);
                    let dv = s::sub(a, v2, v1);
                    let ldot = s::dot(a, e, dv);
                    let f = a.mul(c, ldot);
                    let f1 = s::scale(a, f, e);
                    let f2 = s::neg(a, f1);
                    out.push_force(&p1, f1);
                    out.push_force(&p2, f2);
                    let p = a.mul(f, ldot);
                    power = a.sub(power, p);
                }
                Load::Force { at, force, frame } => {
                    any_nc = true;
                    let p = pt(tree, &at);
                    let fw = match frame {
                        Some(fr) => s::mul_mv(a, &w.nodes[tree.frame_node[fr]].r, force),
                        None => force,
                    };
                    let v = velocity(a, w, &p);
                    let pw = s::dot(a, fw, v);
                    power = a.add(power, pw);
                    out.push_force(&p, fw);
                }
                Load::Torque {
                    on,
                    torque,
                    frame,
                    reaction,
                } => {
                    any_nc = true;
                    let tw = match frame {
                        Some(fr) => s::mul_mv(a, &w.nodes[tree.frame_node[fr]].r, torque),
                        None => torque,
                    };
                    let mut push = |a: &mut Arena, node: Option<usize>, t: V3, out: &mut Loads| {
                        if let Some(n) = node.map(|f| tree.frame_node[f]) {
                            let pw = s::dot(a, t, w.nodes[n].w);
                            power = a.add(power, pw);
                            out.torques.push((n, t));
                        }
                    };
                    push(a, on, tw, &mut out);
                    if let Some(r) = reaction {
                        let nt = s::neg(a, tw);
                        push(a, r, nt, &mut out);
                    }
                }
                Load::GenForce { dof, value } => {
                    any_nc = true;
                    let qd = a.var(Var::Qd(dof as u16));
                    let pw = a.mul(value, qd);
                    power = a.add(power, pw);
                    out.generalized.push((dof, value));
                }
            }
        }
        out.elastic_potential = any_spring.then_some(potential);
        out.power = any_nc.then_some(power);
        out
    }

    fn push_force(&mut self, p: &Pt, f: V3) {
        if let Some(n) = p.node {
            self.forces.push((n, p.r, f));
        }
    }
}
