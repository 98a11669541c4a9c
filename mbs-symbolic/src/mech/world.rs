//! World-frame kinematics composed along the tree (EasyDyn's ComposeMotion): for every node,
//! its pose, its velocity Jacobians (sparse columns, world axes), its full velocities and its
//! bias accelerations (J̇·qd plus rheonomic terms, i.e. the acceleration at qdd = 0).
//! Each factor is differentiated once, locally; cost grows with the tree, not with the square
//! of its depth.

use super::spatial::{self as s, M3, V3};
use super::spin::spinning_frames;
use super::system::{Factor, System};
use super::tree::Tree;
use crate::expr::{Arena, ExprId, Var};

/// Sparse Jacobian: (coordinate, column) sorted by coordinate.
pub type Cols = Vec<(u16, V3)>;

/// Kinematics of one node, world axes.
#[derive(Clone, Debug)]
pub struct NodeKin {
    /// orientation: columns are the node's axes
    pub r: M3,
    /// origin
    pub p: V3,
    /// ∂ω/∂qd
    pub jw: Cols,
    /// ∂v/∂qd (velocity of the origin)
    pub jv: Cols,
    /// angular velocity
    pub w: V3,
    /// velocity of the origin
    pub v: V3,
    /// angular acceleration at qdd = 0
    pub alb: V3,
    /// acceleration of the origin at qdd = 0
    pub ab: V3,
}

/// The motion one coordinate gives a node's factor alone, per unit of its velocity: a twist
/// in world axes, (ω, v₀) with v₀ the velocity of the point of the moving body at the world
/// origin. A point p carried by the node or its descendants then moves at v₀ + ω × p, and its
/// Jacobian's column of that coordinate is the sum of the twists of that coordinate along its
/// path to the root: O(n) twists describe the O(n²) columns of a tree's Jacobians, which the
/// runtime assembles (`Jacobians::Assembled`).
#[derive(Clone, Copy, Debug)]
pub struct Twist {
    pub coordinate: u16,
    pub w: V3,
    pub v0: V3,
}

/// World kinematics of every node of a tree.
pub struct World {
    pub nodes: Vec<NodeKin>,
    /// the twists of each node's own factor (none for the root, constant factors and charts)
    pub twists: Vec<Vec<Twist>>,
}

fn add_cols(a: &mut Arena, x: &Cols, y: &Cols) -> Cols {
    let mut out = Vec::with_capacity(x.len() + y.len());
    let (mut i, mut j) = (0, 0);
    while i < x.len() || j < y.len() {
        if j == y.len() || (i < x.len() && x[i].0 < y[j].0) {
            out.push(x[i]);
            i += 1;
        } else if i == x.len() || y[j].0 < x[i].0 {
            out.push(y[j]);
            j += 1;
        } else {
            out.push((x[i].0, s::add(a, x[i].1, y[j].1)));
            i += 1;
            j += 1;
        }
    }
    out
}

/// Coordinates that `e` depends on.
pub fn q_deps(a: &Arena, roots: &[ExprId]) -> Vec<u16> {
    a.vars_of(roots)
        .into_iter()
        .filter_map(|v| match v {
            Var::Q(k) => Some(k),
            _ => None,
        })
        .collect()
}

impl World {
    /// The number of twists of all nodes.
    pub fn twist_count(&self) -> usize {
        self.twists.iter().map(Vec::len).sum()
    }

    pub fn build(a: &mut Arena, tree: &Tree) -> World {
        let z = s::zero3(a);
        let ground = NodeKin {
            r: s::identity(a),
            p: z,
            jw: Vec::new(),
            jv: Vec::new(),
            w: z,
            v: z,
            alb: z,
            ab: z,
        };
        let mut nodes = vec![ground];
        let mut twists = vec![Vec::new()];
        for n in 1..tree.nodes.len() {
            let par = nodes[tree.nodes[n].parent].clone();
            let mut own_twists = Vec::new();
            let k = match tree.nodes[n].factor.expect("non-root nodes have a factor") {
                Factor::Rot { axis, angle } => {
                    let rel = s::rotation(a, axis, angle);
                    let r = s::mul_mm(a, &par.r, &rel);
                    let nw = s::mul_mv(a, &par.r, axis);
                    let cols: Cols = q_deps(a, &[angle])
                        .into_iter()
                        .map(|k| {
                            let d = a.diff(angle, Var::Q(k));
                            (k, s::scale(a, d, nw))
                        })
                        .collect();
                    // about an axis through the origin p: v₀ = ω × (0 − p) = p × ω
                    for &(coordinate, w) in &cols {
                        let v0 = s::cross(a, par.p, w);
                        own_twists.push(Twist { coordinate, w, v0 });
                    }
                    let jw = add_cols(a, &par.jw, &cols);
                    let th_d = a.dt(angle);
                    let th_dd0 = a.dt_bias(th_d);
                    let w_rel = s::scale(a, th_d, nw);
                    let w = s::add(a, par.w, w_rel);
                    // α = α_p + θ̈ n_w + ω_p × (θ̇ n_w)
                    let t1 = s::scale(a, th_dd0, nw);
                    let t2 = s::cross(a, par.w, w_rel);
                    let alb = s::add(a, par.alb, t1);
                    let alb = s::add(a, alb, t2);
                    NodeKin {
                        r,
                        p: par.p,
                        jw,
                        jv: par.jv.clone(),
                        w,
                        v: par.v,
                        alb,
                        ab: par.ab,
                    }
                }
                // a constant rotation: the origin, velocities and accelerations are the parent's
                Factor::Chart(j) => {
                    let rel = s::chart(a, j);
                    NodeKin {
                        r: s::mul_mm(a, &par.r, &rel),
                        ..par
                    }
                }
                Factor::Disp(d) => {
                    let dw = s::mul_mv(a, &par.r, d);
                    let p = s::add(a, par.p, dw);
                    // Jv = Jv_p + Jω_p × d_w + R_p ∂d/∂q
                    let mut jv_extra: Cols = par
                        .jw
                        .iter()
                        .map(|&(k, c)| (k, s::cross(a, c, dw)))
                        .collect();
                    let own: Cols = q_deps(a, &d)
                        .into_iter()
                        .map(|k| {
                            let dd = [
                                a.diff(d[0], Var::Q(k)),
                                a.diff(d[1], Var::Q(k)),
                                a.diff(d[2], Var::Q(k)),
                            ];
                            (k, s::mul_mv(a, &par.r, dd))
                        })
                        .collect();
                    for &(coordinate, v0) in &own {
                        own_twists.push(Twist {
                            coordinate,
                            w: z,
                            v0,
                        });
                    }
                    jv_extra = add_cols(a, &jv_extra, &own);
                    let jv = add_cols(a, &par.jv, &jv_extra);
                    let ddot = [a.dt(d[0]), a.dt(d[1]), a.dt(d[2])];
                    let ddot_w = s::mul_mv(a, &par.r, ddot);
                    let dd0 = [a.dt_bias(ddot[0]), a.dt_bias(ddot[1]), a.dt_bias(ddot[2])];
                    let dd0_w = s::mul_mv(a, &par.r, dd0);
                    let (v, ab) =
                        s::displaced_motion(a, par.w, par.alb, par.v, par.ab, dw, ddot_w, dd0_w);
                    NodeKin {
                        r: par.r,
                        p,
                        jw: par.jw.clone(),
                        jv,
                        w: par.w,
                        v,
                        alb: par.alb,
                        ab,
                    }
                }
            };
            nodes.push(k);
            twists.push(own_twists);
        }
        World { nodes, twists }
    }

    /// World position of a point at `r` (node axes) on node `n`.
    pub fn point_position(&self, a: &mut Arena, n: usize, r: V3) -> V3 {
        let k = &self.nodes[n];
        let rw = s::mul_mv(a, &k.r, r);
        s::add(a, k.p, rw)
    }

    /// World velocity of that point.
    pub fn point_velocity(&self, a: &mut Arena, n: usize, r: V3) -> V3 {
        let k = &self.nodes[n];
        let rw = s::mul_mv(a, &k.r, r);
        let wx = s::cross(a, k.w, rw);
        s::add(a, k.v, wx)
    }

    /// Jacobian of that point (sparse columns).
    pub fn point_jacobian(&self, a: &mut Arena, n: usize, r: V3) -> Cols {
        let k = &self.nodes[n];
        let rw = s::mul_mv(a, &k.r, r);
        let extra: Cols = k.jw.iter().map(|&(q, c)| (q, s::cross(a, c, rw))).collect();
        add_cols(a, &k.jv, &extra)
    }

    /// Bias acceleration of that point: a_b + α_b × r + ω × (ω × r).
    pub fn point_bias(&self, a: &mut Arena, n: usize, r: V3) -> V3 {
        let k = &self.nodes[n];
        let rw = s::mul_mv(a, &k.r, r);
        let t1 = s::cross(a, k.alb, rw);
        let wr = s::cross(a, k.w, rw);
        let t2 = s::cross(a, k.w, wr);
        let x = s::add(a, k.ab, t1);
        s::add(a, x, t2)
    }
}

/// For every node with twists, in node order, 13 numbers from which the runtime assembles M
/// (`TwistTree::mass_matrix`): the node's origin o, then the composite inertia of its subtree
/// about o in world axes, mass m, first moment Σ mᵢ(cᵢ − o), inertia about o (xx, yy, zz, xy,
/// xz, yz). The composites are carried from child to parent by the lever arm of the factor,
/// R_parent d, not by differences of world positions, so a model far from the origin keeps
/// its digits. A body spinning about its node's axis takes its parent's axes (`mech::spin`).
pub fn composite_inertias(sys: &mut System, tree: &Tree, world: &World) -> Vec<[ExprId; 13]> {
    let spinning = spinning_frames(sys, tree);
    let frames = &sys.frames;
    let a = &mut sys.arena;
    let z3 = s::zero3(a);
    let mut mass = vec![a.zero(); tree.nodes.len()];
    let mut moment = vec![z3; tree.nodes.len()];
    let mut inertia = vec![[z3; 3]; tree.nodes.len()];
    let add_m3 = |a: &mut Arena, x: &M3, y: &M3| -> M3 {
        [
            s::add(a, x[0], y[0]),
            s::add(a, x[1], y[1]),
            s::add(a, x[2], y[2]),
        ]
    };
    for n in (1..tree.nodes.len()).rev() {
        let parent = tree.nodes[n].parent;
        for &f in &tree.nodes[n].frames {
            let Some(inr) = frames[f].inertia else {
                continue;
            };
            let r = if spinning[f] {
                world.nodes[parent].r
            } else {
                world.nodes[n].r
            };
            let ri = s::mul_mm(a, &r, &s::sym(&inr.tensor));
            let iw = s::mul_mm(a, &ri, &s::transpose(&r));
            mass[n] = a.add(mass[n], inr.mass);
            inertia[n] = add_m3(a, &inertia[n], &iw);
        }
        if parent == 0 {
            continue;
        }
        // about the parent's origin o_p = o_n − d: h + m d and
        // I + 2(h·d)1 − h dᵀ − d hᵀ + m(|d|²1 − d dᵀ)
        let (m, h, i) = (mass[n], moment[n], inertia[n]);
        let (h, i) = match tree.nodes[n].factor {
            Some(Factor::Disp(dl)) => {
                let d = s::mul_mv(a, &world.nodes[parent].r, dl);
                let md = s::scale(a, m, d);
                let hd = s::dot(a, h, d);
                let dd = s::dot(a, d, d);
                let mdd = a.mul(m, dd);
                let diag = a.scale(2.0, hd);
                let diag = a.add(diag, mdd);
                let mut shifted = i;
                for r in 0..3 {
                    for c in 0..3 {
                        let hdt = a.mul(h[r], d[c]);
                        let dht = a.mul(d[r], h[c]);
                        let mddt = a.mul(md[r], d[c]);
                        let off = a.add(hdt, dht);
                        let off = a.add(off, mddt);
                        let mut e = a.sub(i[r][c], off);
                        if r == c {
                            e = a.add(e, diag);
                        }
                        shifted[r][c] = e;
                    }
                }
                (s::add(a, h, md), shifted)
            }
            _ => (h, i),
        };
        mass[parent] = a.add(mass[parent], m);
        moment[parent] = s::add(a, moment[parent], h);
        inertia[parent] = add_m3(a, &inertia[parent], &i);
    }
    (1..tree.nodes.len())
        .filter(|&n| !world.twists[n].is_empty())
        .map(|n| {
            let (p, h, i) = (world.nodes[n].p, moment[n], inertia[n]);
            [
                p[0], p[1], p[2], mass[n], h[0], h[1], h[2], i[0][0], i[1][1], i[2][2], i[0][1],
                i[0][2], i[1][2],
            ]
        })
        .collect()
}

/// Dense n-column form of sparse columns (for emission).
pub fn dense(a: &Arena, cols: &Cols, n: usize) -> Vec<V3> {
    let mut out = vec![s::zero3(a); n];
    for &(k, c) in cols {
        out[k as usize] = c;
    }
    out
}
