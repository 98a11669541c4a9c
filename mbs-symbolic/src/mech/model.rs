//! The symbolic model of a system: its frame tree, world kinematics, declared points, the
//! equations of every scene (`dynamics`) and of the constraints (`constraints`), which
//! depend on the kinematics and not on each other.

use super::constraints::ConstraintEquations;
use super::dynamics::{SceneEquations, at_rest, energies, tangent_matrices};
use super::effects::Loads;
use super::recursive::{load_tau, newton_euler};
use super::spatial::{self as s, Matrix};
use super::system::{Jacobians, System};
use super::tree::Tree;
use super::world::{Cols, World, composite_inertias};
use crate::expr::{ExprId, Var};

/// Kinematics of a declared point, world axes.
#[derive(Clone, Debug)]
pub struct PointKin {
    pub position: s::V3,
    pub velocity: s::V3,
    pub jacobian: Cols,
    /// acceleration at qdd = 0
    pub bias: s::V3,
}

/// K_t and C_t of τ when the model asks for tangents, empty matrices otherwise.
fn tangents(sys: &mut System, tau: &[ExprId]) -> (Matrix, Matrix) {
    if sys.options.tangents {
        tangent_matrices(&mut sys.arena, tau)
    } else {
        (Vec::new(), Vec::new())
    }
}

/// −τ at qd = 0 and qdd = 0: the static forces h(q, 0) of τ = M qdd − h.
fn static_forces(sys: &mut System, tau: &[ExprId]) -> Vec<ExprId> {
    let a = &mut sys.arena;
    let rest = at_rest(a, tau.len());
    let tau0 = a.substitute(tau, &rest);
    tau0.into_iter().map(|t| a.neg(t)).collect()
}

/// A part of τ shared by scenes: the bodies' and the common effects' (the first), or a group
/// of other effects', emitted once for the scenes that add them (τ is linear in the loads),
/// with its K_t and C_t when the model asks for tangents (empty otherwise).
pub struct SharedParts {
    /// the effects whose loads these are (and the bodies', for the first part)
    pub effects: Vec<usize>,
    pub tau: Vec<ExprId>,
    /// −τ at qd = 0, qdd = 0: the part's static forces
    pub static_h: Vec<ExprId>,
    /// kinetic energy (the bodies', in the first part; 0 in the others), potential energy
    /// and power of the non-conservative effects
    pub kinetic: ExprId,
    pub potential: ExprId,
    pub power: ExprId,
    pub k: Matrix,
    pub c: Matrix,
}

/// The symbolic model: system, tree, world kinematics and the equations of every scene.
pub struct SymbolicModel {
    pub sys: System,
    pub tree: Tree,
    pub world: World,
    pub points: Vec<PointKin>,
    pub scenes: Vec<SceneEquations>,
    /// With several scenes, emitted once each: τ, static forces, energies, power (and K, C
    /// with tangents) of the bodies and the effects every scene has (the first part), then of
    /// each group of the other effects that the same scenes have; a scene's are the sum of
    /// its `shared_parts`
    pub shared_parts: Vec<SharedParts>,
    /// Φ, B, Φ_t, γ, ∂(Bᵀλ)/∂q of the constraints (empty without constraints)
    pub constraints: ConstraintEquations,
    /// whether the Jacobians of frames and points, and M, are assembled at run time from
    /// the coordinates' twists rather than generated whole: as the model asks (`option
    /// jacobians = …;`), or when the generated columns would be many ([`ASSEMBLED_COLUMNS`])
    pub assembled: bool,
    /// with `assembled`, per node with twists its origin and composite inertia
    /// (`world::composite_inertias`), from which the runtime assembles M
    pub composites: Vec<[ExprId; 13]>,
    /// with `option motion;`, the generalised forces of wrenches given at run time
    /// (`Var::Force`: per frame a force at its origin and a torque, then per point a force,
    /// world axes), Q = Σ J_vᵀ F + J_ωᵀ T carried by one inward pass of the tree
    /// ([`transmission`])
    pub transmission: Option<Vec<ExprId>>,
}

/// Nonzero columns of the frames' and points' Jacobians above which they, and M, are
/// assembled at run time by default.
pub const ASSEMBLED_COLUMNS: usize = 2048;

impl SymbolicModel {
    /// The model built twice, products of a factor of parameters alone and a state value
    /// keeping that factor's coefficient ((m l/2)·x, see `Arena::keep_fixed`) or floating it
    /// out (½·(m l·x), which lets sums collect like terms): the one whose dynamics, forward
    /// dynamics and tangents take fewer flops. Neither wins everywhere: keeping saves 5 % of
    /// the hexapod's M and h and costs 8 % of a 24-bar chain's.
    pub fn build(sys: System) -> SymbolicModel {
        let floated = Self::build_with(sys.clone(), false);
        let kept = Self::build_with(sys, true);
        if kept.cost() < floated.cost() {
            kept
        } else {
            floated
        }
    }

    /// Flops of what the choice of [`SymbolicModel::build`] weighs: every scene's M and h
    /// of the chosen formulation, forward dynamics and own tangents, and the shared
    /// tangents, each function counted on its own as it is emitted.
    pub fn cost(&self) -> usize {
        let a = &self.sys.arena;
        let flops = |roots: &[ExprId]| crate::expr::ops(a, roots).flops();
        let matrices = |k: &Matrix, c: &Matrix| {
            let roots: Vec<ExprId> = k.iter().chain(c).flatten().copied().collect();
            flops(&roots)
        };
        let scenes: usize = self
            .scenes
            .iter()
            .map(|eq| {
                flops(&eq.chosen().roots())
                    + flops(&eq.forward.roots())
                    + eq.tangents.as_ref().map_or(0, |(k, c)| matrices(k, c))
            })
            .sum();
        let shared: usize = self.shared_parts.iter().map(|t| matrices(&t.k, &t.c)).sum();
        scenes + shared
    }

    /// The model, products keeping the coefficients of their factors of parameters alone
    /// or not (`keep`; forward dynamics keep them always).
    pub fn build_with(mut sys: System, keep: bool) -> SymbolicModel {
        sys.arena.keep_fixed = keep;
        let tree = Tree::build(&mut sys);
        let world = World::build(&mut sys.arena, &tree);
        let scenes: Vec<Option<usize>> = if sys.scenes.is_empty() {
            vec![None]
        } else {
            (0..sys.scenes.len()).map(Some).collect()
        };
        // τ is linear in the loads: τ of the bodies and of the effects every scene has, and
        // its tangents, are built once (not with sensitive parameters, whose derivatives at
        // rest are built from each scene's whole tangents)
        let common: Option<Vec<usize>> =
            (scenes.len() > 1 && !sys.params.iter().any(|p| p.sensitive)).then(|| {
                let all: Vec<Vec<usize>> = scenes.iter().map(|&s| sys.scene_effects(s)).collect();
                all[0]
                    .iter()
                    .copied()
                    .filter(|e| all.iter().all(|v| v.contains(e)))
                    .collect()
            });
        let mut scenes: Vec<SceneEquations> = scenes
            .into_iter()
            .map(|s| SceneEquations::build(&mut sys, &tree, &world, s, common.as_deref()))
            .collect();
        let sharing: Vec<usize> = (0..scenes.len())
            .filter(|&i| !scenes[i].shared_parts.is_empty())
            .collect();
        let mut shared_parts = Vec::new();
        if let Some(common) = common.filter(|_| !sharing.is_empty()) {
            let loads = Loads::build(&mut sys, &tree, &world, &common);
            let tau = newton_euler(&mut sys, &tree, &world, &loads, true);
            let (k, c) = tangents(&mut sys, &tau);
            let (kinetic, potential) = energies(&mut sys, &tree, &world, &loads);
            shared_parts.push(SharedParts {
                effects: common.clone(),
                static_h: static_forces(&mut sys, &tau),
                tau,
                kinetic,
                potential,
                power: loads.power.unwrap_or(sys.arena.zero()),
                k,
                c,
            });
            // the other effects of those scenes, grouped by the scenes that have them: τ is
            // linear in the loads, so each group's part is carried to the coordinates
            // without the bodies, once
            let mut groups: Vec<(Vec<usize>, Vec<usize>)> = Vec::new();
            for e in (0..sys.effects.len()).filter(|e| !common.contains(e)) {
                let users: Vec<usize> = sharing
                    .iter()
                    .copied()
                    .filter(|&i| scenes[i].effects.contains(&e))
                    .collect();
                if users.is_empty() {
                    continue;
                }
                match groups.iter_mut().find(|g| g.0 == users) {
                    Some(g) => g.1.push(e),
                    None => groups.push((users, vec![e])),
                }
            }
            for (users, effects) in groups {
                let loads = Loads::build(&mut sys, &tree, &world, &effects);
                let tau = load_tau(&mut sys, &tree, &world, &loads);
                let (k, c) = tangents(&mut sys, &tau);
                for i in users {
                    scenes[i].shared_parts.push(shared_parts.len());
                }
                let zero = sys.arena.zero();
                shared_parts.push(SharedParts {
                    effects,
                    static_h: static_forces(&mut sys, &tau),
                    tau,
                    kinetic: zero,
                    potential: loads.elastic_potential.unwrap_or(zero),
                    power: loads.power.unwrap_or(zero),
                    k,
                    c,
                });
            }
        }
        let points: Vec<PointKin> = sys
            .points
            .clone()
            .iter()
            .map(|pt| {
                let a = &mut sys.arena;
                match pt.frame {
                    Some(fr) => {
                        let node = tree.frame_node[fr];
                        PointKin {
                            position: world.point_position(a, node, pt.pos),
                            velocity: world.point_velocity(a, node, pt.pos),
                            jacobian: world.point_jacobian(a, node, pt.pos),
                            bias: world.point_bias(a, node, pt.pos),
                        }
                    }
                    None => PointKin {
                        position: pt.pos,
                        velocity: s::zero3(a),
                        jacobian: Vec::new(),
                        bias: s::zero3(a),
                    },
                }
            })
            .collect();
        let constraints = ConstraintEquations::build(&mut sys, &tree, &world);
        let transmission = sys
            .options
            .motion
            .then(|| transmission(&mut sys, &tree, &world));
        let assembled = match sys.options.jacobians {
            Some(j) => j == Jacobians::Assembled,
            None => {
                let frames: usize = tree
                    .frame_node
                    .iter()
                    .map(|&n| world.nodes[n].jv.len() + world.nodes[n].jw.len())
                    .sum();
                let points: usize = points.iter().map(|p| p.jacobian.len()).sum();
                frames + points > ASSEMBLED_COLUMNS
            }
        };
        let composites = if assembled {
            composite_inertias(&mut sys, &tree, &world)
        } else {
            Vec::new()
        };
        sys.arena.keep_fixed = false;
        SymbolicModel {
            assembled,
            composites,
            sys,
            tree,
            world,
            points,
            scenes,
            shared_parts,
            constraints,
            transmission,
        }
    }
}

/// The generalised forces Q of wrenches on every frame and forces at every point, given at
/// run time as `f` (`Var::Force`): `f[6i..6i+3]` a force at frame i's origin and
/// `f[6i+3..6i+6]` a torque on it, then `f[6 NF + 3j..]` a force at point j, all in world
/// axes. Newton–Euler's inward pass without the bodies (τ is linear in the loads): the
/// wrenches are carried from node to parent and projected on each factor's motion, O(n),
/// where Σ Jᵢᵀ Wᵢ reads every frame's Jacobian.
pub fn transmission(sys: &mut System, tree: &Tree, world: &World) -> Vec<ExprId> {
    let nf = tree.frame_node.len();
    let a = &mut sys.arena;
    let zero3 = s::zero3(a);
    let mut input = |k: usize| a.var(Var::Force(k as u16));
    let mut forces = Vec::new();
    let mut torques = Vec::new();
    for (i, &node) in tree.frame_node.iter().enumerate() {
        // a frame of the ground moves no coordinate
        if node == 0 {
            continue;
        }
        let f = [input(6 * i), input(6 * i + 1), input(6 * i + 2)];
        let t = [input(6 * i + 3), input(6 * i + 4), input(6 * i + 5)];
        forces.push((node, zero3, f));
        torques.push((node, t));
    }
    for (j, p) in sys.points.iter().enumerate() {
        let Some(frame) = p.frame else { continue };
        let node = tree.frame_node[frame];
        if node == 0 {
            continue;
        }
        let k = 6 * nf + 3 * j;
        forces.push((node, p.pos, [input(k), input(k + 1), input(k + 2)]));
    }
    let loads = Loads {
        gravity: None,
        forces,
        torques,
        generalized: Vec::new(),
        elastic_potential: None,
        power: None,
    };
    // τ = −Q of the loads
    let tau = load_tau(sys, tree, world, &loads);
    tau.into_iter().map(|t| sys.arena.neg(t)).collect()
}
