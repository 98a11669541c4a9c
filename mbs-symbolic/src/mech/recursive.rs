//! The recursive formulation, in node axes (Featherstone, Robotran's semi-explicit scheme):
//! - Newton–Euler: velocities and accelerations outwards, forces inwards, projected on each
//!   factor's motion → τ(q, qd, qdd) = M qdd − h; gravity enters as a base acceleration −g.
//! - Composite rigid body: subtree inertias inwards; each factor's unit motion times its
//!   composite inertia is a force carried inwards and projected on the factors it meets → M.
//!
//! A factor's motion: a rotation `Rot(n, θ)` moves its frame by θ̇ n about the common origin;
//! a displacement `Disp(d)` moves it by ḋ (parent axes = child axes for a displacement).

use super::effects::Loads;
use super::spatial::{self as s, M3, V3};
use super::spin::spinning_frames;
use super::system::{Factor, System};
use super::tree::Tree;
use super::world::World;
use crate::expr::{Arena, ExprId, Var};

/// Velocities and accelerations of a node, in its own axes.
#[derive(Clone, Copy)]
pub struct BodyKin {
    pub w: V3,
    /// velocity of the origin
    pub v: V3,
    pub al: V3,
    /// acceleration of the origin (with −g added when gravity acts)
    pub a: V3,
}

/// The relative rotation of each node's factor (`None` for a displacement or the ground).
pub fn rotations(a: &mut Arena, tree: &Tree) -> Vec<Option<M3>> {
    tree.nodes
        .iter()
        .map(|n| match n.factor {
            Some(Factor::Rot { axis, angle }) => Some(s::rotation(a, axis, angle)),
            Some(Factor::Chart(j)) => Some(s::chart(a, j)),
            _ => None,
        })
        .collect()
}

/// Outward pass. `with_qdd`: accelerations include qdd (for τ) or not (for h).
pub fn body_kinematics(
    a: &mut Arena,
    tree: &Tree,
    gravity: Option<V3>,
    with_qdd: bool,
) -> Vec<BodyKin> {
    let z = s::zero3(a);
    let a0 = match gravity {
        Some(g) => s::neg(a, g),
        None => z,
    };
    let rots = rotations(a, tree);
    let mut out = vec![BodyKin {
        w: z,
        v: z,
        al: z,
        a: a0,
    }];
    for n in 1..tree.nodes.len() {
        let p = out[tree.nodes[n].parent];
        let k = match tree.nodes[n].factor.unwrap() {
            Factor::Rot { axis, angle } => {
                let r = rots[n].unwrap();
                let th_d = a.dt(angle);
                let th_dd = if with_qdd {
                    a.dt(th_d)
                } else {
                    a.dt_bias(th_d)
                };
                let wp = s::mul_mtv(a, &r, p.w);
                let rel = s::scale(a, th_d, axis);
                let w = s::add(a, wp, rel);
                let v = s::mul_mtv(a, &r, p.v);
                let alp = s::mul_mtv(a, &r, p.al);
                let t1 = s::scale(a, th_dd, axis);
                let t2 = s::cross(a, wp, rel);
                let al = s::add(a, alp, t1);
                let al = s::add(a, al, t2);
                let acc = s::mul_mtv(a, &r, p.a);
                BodyKin { w, v, al, a: acc }
            }
            // a constant rotation: the parent's motion in the new axes
            Factor::Chart(_) => {
                let r = rots[n].unwrap();
                BodyKin {
                    w: s::mul_mtv(a, &r, p.w),
                    v: s::mul_mtv(a, &r, p.v),
                    al: s::mul_mtv(a, &r, p.al),
                    a: s::mul_mtv(a, &r, p.a),
                }
            }
            Factor::Disp(d) => {
                let dd = [a.dt(d[0]), a.dt(d[1]), a.dt(d[2])];
                let ddd = if with_qdd {
                    [a.dt(dd[0]), a.dt(dd[1]), a.dt(dd[2])]
                } else {
                    [a.dt_bias(dd[0]), a.dt_bias(dd[1]), a.dt_bias(dd[2])]
                };
                let (v, acc) = s::displaced_motion(a, p.w, p.al, p.v, p.a, d, dd, ddd);
                BodyKin {
                    w: p.w,
                    v,
                    al: p.al,
                    a: acc,
                }
            }
        };
        out.push(k);
    }
    out
}

/// τ(q, qd, qdd) by Newton–Euler (or −h when `with_qdd` is false).
pub fn newton_euler(
    sys: &mut System,
    tree: &Tree,
    world: &World,
    loads: &Loads,
    with_qdd: bool,
) -> Vec<ExprId> {
    let w = body_wrenches(sys, tree, loads, with_qdd);
    backward(&mut sys.arena, tree, world, loads, w)
}

/// What the bodies' motion asks of each node before anything is carried inwards: the force
/// and the moment about its origin, in its axes (the bodies' m a and Φ α + ω × Φ ω at the
/// accelerations `with_qdd` says, gravity included; a spinning body's in its parent's), and
/// the spinning bodies' axial moments on their coordinates (`tau`).
pub struct BodyWrenches {
    pub force: Vec<V3>,
    pub moment: Vec<V3>,
    pub tau: Vec<ExprId>,
}

/// The bodies' wrenches of Newton–Euler's outward pass (see [`BodyWrenches`]).
pub fn body_wrenches(sys: &mut System, tree: &Tree, loads: &Loads, with_qdd: bool) -> BodyWrenches {
    let nd = sys.ndof();
    let bk = body_kinematics(&mut sys.arena, tree, loads.gravity, with_qdd);
    let spinning = spinning_frames(sys, tree);
    let a = &mut sys.arena;
    let z = s::zero3(a);
    let mut force = vec![z; tree.nodes.len()];
    let mut moment = vec![z; tree.nodes.len()];
    let mut tau = vec![a.zero(); nd];
    for (n, node) in tree.nodes.iter().enumerate().skip(1) {
        for &f in &node.frames {
            let Some(inr) = sys.frames[f].inertia else {
                continue;
            };
            let phi = s::sym(&inr.tensor);
            if spinning[f] {
                // in the parent's axes, where the spin does not change the inertia
                let Some(Factor::Rot { axis, angle }) = tree.nodes[n].factor else {
                    unreachable!()
                };
                let p = tree.nodes[n].parent;
                let (fb, mb) =
                    spinning_body_wrench(a, &bk[p], axis, angle, inr.mass, &phi, with_qdd);
                for k in tree.factor_dofs(a, n) {
                    let d = a.diff(angle, Var::Q(k));
                    let nm = s::dot(a, axis, mb);
                    let t = a.mul(d, nm);
                    tau[k as usize] = a.add(tau[k as usize], t);
                }
                force[p] = s::add(a, force[p], fb);
                moment[p] = s::add(a, moment[p], mb);
                continue;
            }
            let k = bk[n];
            let ma = s::scale(a, inr.mass, k.a);
            force[n] = s::add(a, force[n], ma);
            let ia = s::mul_mv(a, &phi, k.al);
            let iw = s::mul_mv(a, &phi, k.w);
            let gyro = s::cross(a, k.w, iw);
            let m = s::add(a, ia, gyro);
            moment[n] = s::add(a, moment[n], m);
        }
    }
    BodyWrenches { force, moment, tau }
}

/// The part of τ that `loads` make, without the bodies' inertia: τ is linear in the loads,
/// so a scene's τ is that of the loads every scene has plus this of its own (which must not
/// include gravity, which acts through the bodies).
pub fn load_tau(sys: &mut System, tree: &Tree, world: &World, loads: &Loads) -> Vec<ExprId> {
    debug_assert!(loads.gravity.is_none(), "gravity acts through the bodies");
    let nd = sys.ndof();
    let a = &mut sys.arena;
    let (z, zero) = (s::zero3(a), a.zero());
    let nn = tree.nodes.len();
    let none = BodyWrenches {
        force: vec![z; nn],
        moment: vec![z; nn],
        tau: vec![zero; nd],
    };
    backward(a, tree, world, loads, none)
}

/// The loads' forces and moments on the nodes (in their axes, about their origins) taken from
/// what the bodies ask of them.
pub fn subtract_loads(
    a: &mut Arena,
    world: &World,
    loads: &Loads,
    force: &mut [V3],
    moment: &mut [V3],
) {
    for &(n, r, fw) in &loads.forces {
        let f = s::mul_mtv(a, &world.nodes[n].r, fw);
        force[n] = s::sub(a, force[n], f);
        let rxf = s::cross(a, r, f);
        moment[n] = s::sub(a, moment[n], rxf);
    }
    for &(n, tw) in &loads.torques {
        let t = s::mul_mtv(a, &world.nodes[n].r, tw);
        moment[n] = s::sub(a, moment[n], t);
    }
}

/// The loads added to the bodies' forces and moments, then everything carried to the root
/// and projected on the coordinates.
fn backward(
    a: &mut Arena,
    tree: &Tree,
    world: &World,
    loads: &Loads,
    wrenches: BodyWrenches,
) -> Vec<ExprId> {
    let BodyWrenches {
        mut force,
        mut moment,
        mut tau,
    } = wrenches;
    let rots = rotations(a, tree);
    subtract_loads(a, world, loads, &mut force, &mut moment);
    for n in (1..tree.nodes.len()).rev() {
        let fac = tree.nodes[n].factor.unwrap();
        let (f, m) = (force[n], moment[n]);
        for k in tree.factor_dofs(a, n) {
            let t = match fac {
                Factor::Rot { axis, angle } => {
                    let d = a.diff(angle, Var::Q(k));
                    let nm = s::dot(a, axis, m);
                    a.mul(d, nm)
                }
                Factor::Disp(dv) => {
                    let dd = [
                        a.diff(dv[0], Var::Q(k)),
                        a.diff(dv[1], Var::Q(k)),
                        a.diff(dv[2], Var::Q(k)),
                    ];
                    s::dot(a, dd, f)
                }
                Factor::Chart(_) => unreachable!("a chart moves no coordinate"),
            };
            tau[k as usize] = a.add(tau[k as usize], t);
        }
        let p = tree.nodes[n].parent;
        if p == 0 {
            continue;
        }
        let (fp, mp) = match fac {
            Factor::Rot { .. } | Factor::Chart(_) => {
                let r = rots[n].unwrap();
                (s::mul_mv(a, &r, f), s::mul_mv(a, &r, m))
            }
            Factor::Disp(d) => {
                let dxf = s::cross(a, d, f);
                (f, s::add(a, m, dxf))
            }
        };
        force[p] = s::add(a, force[p], fp);
        moment[p] = s::add(a, moment[p], mp);
    }
    for &(k, q) in &loads.generalized {
        tau[k] = a.sub(tau[k], q);
    }
    tau
}

/// Velocity of a body spinning by `angle` about `axis` relative to the frame whose kinematics
/// is `p`, in that frame's axes: (ω, α).
pub fn spinning_body_motion(
    a: &mut Arena,
    p: &BodyKin,
    axis: V3,
    angle: ExprId,
    with_qdd: bool,
) -> (V3, V3) {
    let th_d = a.dt(angle);
    let th_dd = if with_qdd {
        a.dt(th_d)
    } else {
        a.dt_bias(th_d)
    };
    let rel = s::scale(a, th_d, axis);
    let w = s::add(a, p.w, rel);
    let t1 = s::scale(a, th_dd, axis);
    let t2 = s::cross(a, p.w, rel);
    let al = s::add(a, p.al, t1);
    (w, s::add(a, al, t2))
}

/// Force m a and moment Φ α + ω × Φ ω of a spinning body, in its parent's axes.
fn spinning_body_wrench(
    a: &mut Arena,
    p: &BodyKin,
    axis: V3,
    angle: ExprId,
    mass: ExprId,
    phi: &M3,
    with_qdd: bool,
) -> (V3, V3) {
    let (w, al) = spinning_body_motion(a, p, axis, angle, with_qdd);
    let f = s::scale(a, mass, p.a);
    let ia = s::mul_mv(a, phi, al);
    let iw = s::mul_mv(a, phi, w);
    let gyro = s::cross(a, w, iw);
    (f, s::add(a, ia, gyro))
}

/// Spatial inertia about a frame origin: mass, first moment h = m·c, inertia about the origin.
#[derive(Clone, Copy)]
struct SpInertia {
    m: ExprId,
    h: V3,
    i: M3,
}

impl SpInertia {
    fn add(a: &mut Arena, x: &SpInertia, y: &SpInertia) -> SpInertia {
        let mut i = x.i;
        for r in 0..3 {
            for c in 0..3 {
                i[r][c] = a.add(x.i[r][c], y.i[r][c]);
            }
        }
        SpInertia {
            m: a.add(x.m, y.m),
            h: s::add(a, x.h, y.h),
            i,
        }
    }

    /// This inertia (child axes) expressed in the parent's axes/origin across `fac`, whose
    /// rotation is `rot`.
    fn to_parent(self, a: &mut Arena, fac: &Factor, rot: Option<M3>) -> SpInertia {
        match rot {
            Some(r) => {
                let h = s::mul_mv(a, &r, self.h);
                let ri = s::mul_mm(a, &r, &self.i);
                let mut i = self.i;
                for row in 0..3 {
                    for col in 0..3 {
                        i[row][col] = a.dot(&ri[row], &r[col]);
                    }
                }
                SpInertia { m: self.m, h, i }
            }
            None => {
                let Factor::Disp(d) = *fac else {
                    unreachable!()
                };
                // I' = I + (2 d·h + m d·d) 1 − (d hᵀ + h dᵀ + m d dᵀ)
                let md = s::scale(a, self.m, d);
                let dh = s::dot(a, d, self.h);
                let two = a.num(2.0);
                let dh2 = a.mul(two, dh);
                let mdd = s::dot(a, md, d);
                let diag = a.add(dh2, mdd);
                let mut i = self.i;
                for row in 0..3 {
                    for col in 0..3 {
                        let x = a.mul(d[row], self.h[col]);
                        let y = a.mul(self.h[row], d[col]);
                        let w = a.mul(md[row], d[col]);
                        let sxy = a.add(x, y);
                        let sub = a.add(sxy, w);
                        let mut e = a.sub(self.i[row][col], sub);
                        if row == col {
                            e = a.add(e, diag);
                        }
                        i[row][col] = e;
                    }
                }
                SpInertia {
                    m: self.m,
                    h: s::add(a, self.h, md),
                    i,
                }
            }
        }
    }
}

/// Unit motion of factor `fac` for coordinate `k`: (angular, linear) in the child's axes.
fn motion(a: &mut Arena, fac: &Factor, k: u16) -> (V3, V3) {
    let z = s::zero3(a);
    match *fac {
        Factor::Rot { axis, angle } => {
            let d = a.diff(angle, Var::Q(k));
            (s::scale(a, d, axis), z)
        }
        Factor::Disp(dv) => (
            z,
            [
                a.diff(dv[0], Var::Q(k)),
                a.diff(dv[1], Var::Q(k)),
                a.diff(dv[2], Var::Q(k)),
            ],
        ),
        Factor::Chart(_) => (z, z),
    }
}

/// Mass matrix by composite rigid bodies; returned dense, row-major, symmetric.
pub fn crba(sys: &mut System, tree: &Tree) -> Vec<Vec<ExprId>> {
    let nd = sys.ndof();
    let spinning = spinning_frames(sys, tree);
    let a = &mut sys.arena;
    let rots = rotations(a, tree);
    let zero = a.zero();
    let z3 = s::zero3(a);
    let empty = SpInertia {
        m: zero,
        h: z3,
        i: [z3; 3],
    };
    let mut comp = vec![empty; tree.nodes.len()];
    // inertias of bodies spinning about their node's axis, carried by the parent
    let mut spin_phi: Vec<Option<M3>> = vec![None; tree.nodes.len()];
    for (n, node) in tree.nodes.iter().enumerate().skip(1) {
        for &f in &node.frames {
            if let Some(inr) = sys.frames[f].inertia {
                let body = SpInertia {
                    m: inr.mass,
                    h: z3,
                    i: s::sym(&inr.tensor),
                };
                if spinning[f] {
                    let p = tree.nodes[n].parent;
                    comp[p] = SpInertia::add(a, &comp[p], &body);
                    spin_phi[n] = Some(match spin_phi[n] {
                        Some(prev) => {
                            SpInertia::add(
                                a,
                                &SpInertia {
                                    m: zero,
                                    h: z3,
                                    i: prev,
                                },
                                &body,
                            )
                            .i
                        }
                        None => body.i,
                    });
                    continue;
                }
                comp[n] = SpInertia::add(a, &comp[n], &body);
            }
        }
    }
    for n in (1..tree.nodes.len()).rev() {
        let p = tree.nodes[n].parent;
        if p == 0 {
            continue;
        }
        let moved = comp[n].to_parent(a, &tree.nodes[n].factor.unwrap(), rots[n]);
        comp[p] = SpInertia::add(a, &comp[p], &moved);
    }
    let mut m = vec![vec![zero; nd]; nd];
    // unit motions of every factor, per coordinate
    let motions: Vec<Vec<(u16, V3, V3)>> = (0..tree.nodes.len())
        .map(|n| match tree.nodes[n].factor {
            Some(fac) => tree
                .factor_dofs(a, n)
                .into_iter()
                .map(|k| {
                    let (w, v) = motion(a, &fac, k);
                    (k, w, v)
                })
                .collect(),
            None => Vec::new(),
        })
        .collect();
    for n in 1..tree.nodes.len() {
        for &(k, sw, sv) in &motions[n] {
            let c = comp[n];
            // F = I S: linear m v + ω × h, angular I ω + h × v
            let mv = s::scale(a, c.m, sv);
            let wh = s::cross(a, sw, c.h);
            let mut lin = s::add(a, mv, wh);
            let iw = s::mul_mv(a, &c.i, sw);
            let hv = s::cross(a, c.h, sv);
            let mut ang = s::add(a, iw, hv);
            if let Some(phi) = spin_phi[n] {
                let spin = s::mul_mv(a, &phi, sw);
                ang = s::add(a, ang, spin);
            }
            let mut x = n;
            while x != 0 {
                let fx = tree.nodes[x].factor.unwrap();
                for &(j, jw, jv) in &motions[x] {
                    if x == n && j > k {
                        continue;
                    }
                    let p1 = s::dot(a, jw, ang);
                    let p2 = s::dot(a, jv, lin);
                    let c = a.add(p1, p2);
                    let (r, col) = (j.max(k) as usize, j.min(k) as usize);
                    let c = if x != n && j == k { a.scale(2.0, c) } else { c };
                    m[r][col] = a.add(m[r][col], c);
                }
                match fx {
                    Factor::Rot { .. } | Factor::Chart(_) => {
                        let r = rots[x].unwrap();
                        lin = s::mul_mv(a, &r, lin);
                        ang = s::mul_mv(a, &r, ang);
                    }
                    Factor::Disp(d) => {
                        let dxf = s::cross(a, d, lin);
                        ang = s::add(a, ang, dxf);
                    }
                }
                x = tree.nodes[x].parent;
            }
        }
    }
    for r in 0..nd {
        for c in (r + 1)..nd {
            m[r][c] = m[c][r];
        }
    }
    m
}
