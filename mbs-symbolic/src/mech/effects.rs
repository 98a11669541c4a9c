//! Effects of a scene → applied loads in world axes, their potential energy and the power of
//! the non-conservative ones. Both formulations consume the same loads.

use super::spatial::{self as s, V3};
use super::system::{Attach, Load, System};
use super::tree::Tree;
use super::world::World;
use crate::expr::{Arena, ExprId, Var};

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
    /// potential energy of springs (gravity's is computed from the bodies)
    pub spring_potential: Option<ExprId>,
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
                } => {
                    any_spring = true;
                    let (p1, p2) = (pt(tree, &pa), pt(tree, &pb));
                    let x1 = position(a, w, &p1);
                    let x2 = position(a, w, &p2);
                    let d = s::sub(a, x2, x1);
                    // length and direction: along the line of the ends, or the given axis
                    let (l, e) = length_and_direction(a, d, axis);
                    let stretch = a.sub(l, l0);
                    let tension = a.mul(k, stretch);
                    let f1 = s::scale(a, tension, e);
                    let f2 = s::neg(a, f1);
                    out.push_force(&p1, f1);
                    out.push_force(&p2, f2);
                    let st2 = a.mul(stretch, stretch);
                    let ks = a.mul(k, st2);
                    let v = a.mul(half, ks);
                    potential = a.add(potential, v);
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
        out.spring_potential = any_spring.then_some(potential);
        out.power = any_nc.then_some(power);
        out
    }

    fn push_force(&mut self, p: &Pt, f: V3) {
        if let Some(n) = p.node {
            self.forces.push((n, p.r, f));
        }
    }
}
