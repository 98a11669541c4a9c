//! Effects of a scene → applied loads in world axes, their potential energy and the power of
//! the non-conservative ones. Both formulations consume the same loads. Each kind of load
//! is built in its own file, which adds its forces, torques, potential and power to a
//! `Build`.
//!
//! Every elastic force is exactly minus the gradient of the potential counted here, and every
//! other load's power is the power of the forces and torques pushed, so that
//! d(T + V)/dt = power holds identically along the motion (`tests/energy.rs`).

mod bushing;
mod contact;
mod damper;
mod force;
mod generalized_force;
mod gravity;
mod rotational_spring;
mod spring;
mod torque;

use super::spatial::{self as s, V3};
use super::system::{Attach, Load, System};
use super::tree::Tree;
use super::world::World;
use crate::expr::{Arena, ExprId};

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
    /// potential energy of springs, rotational springs, contacts and bushings (gravity's is computed from the
    /// bodies)
    pub elastic_potential: Option<ExprId>,
    /// power of the non-conservative loads
    pub power: Option<ExprId>,
}

/// The loads of a scene while they are built: what each kind of load adds to.
struct Build<'a> {
    a: &'a mut Arena,
    tree: &'a Tree,
    w: &'a World,
    out: Loads,
    /// sum of the elastic potentials
    potential: ExprId,
    /// sum of the powers of the non-conservative loads
    power: ExprId,
    /// whether a load has added to `potential`
    elastic: bool,
    /// whether a load has added to `power`
    dissipative: bool,
    /// the constant ½
    half: ExprId,
}

/// A point of the tree: a node (`None`: the ground) and a position in its axes.
struct Pt {
    node: Option<usize>,
    r: V3,
}

impl Build<'_> {
    fn pt(&self, at: &Attach) -> Pt {
        Pt {
            node: at.frame.map(|f| self.tree.frame_node[f]),
            r: at.pos,
        }
    }

    fn position(&mut self, p: &Pt) -> V3 {
        match p.node {
            Some(n) => self.w.point_position(self.a, n, p.r),
            None => p.r,
        }
    }

    fn velocity(&mut self, p: &Pt) -> V3 {
        match p.node {
            Some(n) => self.w.point_velocity(self.a, n, p.r),
            None => s::zero3(self.a),
        }
    }

    /// Adds `e` to the elastic potential.
    fn add_potential(&mut self, e: ExprId) {
        self.potential = self.a.add(self.potential, e);
    }

    /// Adds `p` to the power of the non-conservative loads.
    fn add_power(&mut self, p: ExprId) {
        self.power = self.a.add(self.power, p);
    }

    /// Subtracts `p` from the power of the non-conservative loads.
    fn sub_power(&mut self, p: ExprId) {
        self.power = self.a.sub(self.power, p);
    }

    fn push_force(&mut self, p: &Pt, f: V3) {
        if let Some(n) = p.node {
            self.out.forces.push((n, p.r, f));
        }
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
        let loads: Vec<Load> = effects
            .iter()
            .flat_map(|&e| sys.effects[e].loads.clone())
            .collect();
        let a = &mut sys.arena;
        let potential = a.zero();
        let power = a.zero();
        let half = a.num(0.5);
        let mut b = Build {
            a,
            tree,
            w,
            out: Loads::default(),
            potential,
            power,
            elastic: false,
            dissipative: false,
            half,
        };
        for load in &loads {
            match load {
                Load::Gravity(g) => gravity::build(&mut b, *g),
                Load::Spring { .. } => spring::build(&mut b, load),
                Load::Damper { .. } => damper::build(&mut b, load),
                Load::Force { .. } => force::build(&mut b, load),
                Load::Torque { .. } => torque::build(&mut b, load),
                Load::GenForce { .. } => generalized_force::build(&mut b, load),
                Load::Contact { .. } => contact::build(&mut b, load),
                Load::Bushing { .. } => bushing::build(&mut b, load),
                Load::RotationalSpring { .. } => rotational_spring::build(&mut b, load),
            }
        }
        let mut out = b.out;
        out.elastic_potential = b.elastic.then_some(b.potential);
        out.power = b.dissipative.then_some(b.power);
        out
    }
}
