//! Bodies spinning about a symmetry axis. When a body's frame ends with a rotation about a
//! coordinate axis and its inertia is invariant under that rotation (the two transverse
//! moments are the same expression, no products of inertia), its dynamics do not depend on
//! the spin angle: the formulations carry its inertia in the axes before the rotation, so no
//! trigonometry of the spin angle enters M, h or τ (geared motor rotors, wheels, flywheels).
//! Poses and Jacobians still see the full rotation.

use super::spatial::V3;
use super::system::{Factor, System};
use super::tree::Tree;
use crate::expr::Arena;

/// The spin axis (0, 1, 2 for ±x, ±y, ±z) when the body of `frame`, located at `node`, spins
/// about its node's factor with an invariant inertia.
pub fn spin_axis(sys: &System, tree: &Tree, node: usize, frame: usize) -> Option<usize> {
    let Some(Factor::Rot { axis, .. }) = tree.nodes[node].factor else {
        return None;
    };
    let inr = sys.frames[frame].inertia?;
    let a = &sys.arena;
    let k = coordinate_axis(a, axis)?;
    let t = inr.tensor;
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let products_zero = t[3..].iter().all(|&p| a.is_num(p, 0.0));
    (t[i] == t[j] && products_zero).then_some(k)
}

/// For each frame of the system: whether it is a body spinning about its node's axis.
pub fn spinning_frames(sys: &System, tree: &Tree) -> Vec<bool> {
    (0..sys.frames.len())
        .map(|f| spin_axis(sys, tree, tree.frame_node[f], f).is_some())
        .collect()
}

/// k when `axis` is ±e_k with numeric components.
fn coordinate_axis(a: &Arena, axis: V3) -> Option<usize> {
    let n: Vec<f64> = axis.iter().map(|&e| a.as_num(e)).collect::<Option<_>>()?;
    (0..3).find(|&k| n[k].abs() == 1.0 && n[(k + 1) % 3] == 0.0 && n[(k + 2) % 3] == 0.0)
}
