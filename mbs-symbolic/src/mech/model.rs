//! The symbolic model of a system: its frame tree, world kinematics, declared points, the
//! equations of every scene (`dynamics`) and of the constraints (`constraints`), which
//! depend on the kinematics and not on each other.

use super::constraints::ConstraintEquations;
use super::dynamics::{SceneEquations, tangent_matrices};
use super::effects::Loads;
use super::recursive::newton_euler;
use super::spatial::{self as s, Matrix};
use super::system::System;
use super::tree::Tree;
use super::world::{Cols, World};

/// Kinematics of a declared point, world axes.
#[derive(Clone, Debug)]
pub struct PointKin {
    pub position: s::V3,
    pub velocity: s::V3,
    pub jacobian: Cols,
    /// acceleration at qdd = 0
    pub bias: s::V3,
}

/// The symbolic model: system, tree, world kinematics and the equations of every scene.
pub struct SymbolicModel {
    pub sys: System,
    pub tree: Tree,
    pub world: World,
    pub points: Vec<PointKin>,
    pub scenes: Vec<SceneEquations>,
    /// With tangents and several scenes: K and C of the bodies and the effects every scene
    /// has, emitted once; the scenes whose `tangents_common` is set add their own effects'
    pub common_tangents: Option<(Matrix, Matrix)>,
    /// Φ, B, Φ_t, γ, ∂(Bᵀλ)/∂q of the constraints (empty without constraints)
    pub constraints: ConstraintEquations,
}

impl SymbolicModel {
    pub fn build(mut sys: System) -> SymbolicModel {
        let tree = Tree::build(&mut sys);
        let world = World::build(&mut sys.arena, &tree);
        let scenes: Vec<Option<usize>> = if sys.scenes.is_empty() {
            vec![None]
        } else {
            (0..sys.scenes.len()).map(Some).collect()
        };
        // τ is linear in the loads: the tangents of the bodies and of the effects every
        // scene has are built once (not with sensitive parameters, whose derivatives at rest
        // are built from each scene's whole tangents)
        let common: Option<Vec<usize>> = (sys.options.tangents
            && scenes.len() > 1
            && !sys.params.iter().any(|p| p.sensitive))
        .then(|| {
            let all: Vec<Vec<usize>> = scenes.iter().map(|&s| sys.scene_effects(s)).collect();
            all[0]
                .iter()
                .copied()
                .filter(|e| all.iter().all(|v| v.contains(e)))
                .collect()
        });
        let scenes: Vec<SceneEquations> = scenes
            .into_iter()
            .map(|s| SceneEquations::build(&mut sys, &tree, &world, s, common.as_deref()))
            .collect();
        let common_tangents = common
            .filter(|_| scenes.iter().any(|e| e.tangents_common))
            .map(|common| {
                let loads = Loads::build(&mut sys, &tree, &world, &common);
                let tau = newton_euler(&mut sys, &tree, &world, &loads, true);
                tangent_matrices(&mut sys.arena, &tau)
            });
        let points = sys
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
        SymbolicModel {
            sys,
            tree,
            world,
            points,
            scenes,
            common_tangents,
            constraints,
        }
    }
}
