//! The virtual-power formulation of the seed course: with J_G and J_ω composed along the tree,
//! M = Σ m J_Gᵀ J_G + J_ωᵀ Φ J_ω and h = Σ J_Gᵀ (m g − m a_b) − J_ωᵀ (Φ α_b + ω × Φ ω) + Σ Jᵀ F_ext,
//! with the rotational terms in body axes so that Φ stays constant.

use super::effects::Loads;
use super::spatial::{self as s, V3};
use super::spin::spinning_frames;
use super::system::System;
use super::tree::Tree;
use super::world::World;
use crate::expr::ExprId;

/// Mass matrix (dense, row-major, symmetric) and h.
pub fn virtual_power(
    sys: &mut System,
    tree: &Tree,
    world: &World,
    loads: &Loads,
) -> (Vec<Vec<ExprId>>, Vec<ExprId>) {
    let nd = sys.ndof();
    let spinning = spinning_frames(sys, tree);
    let a = &mut sys.arena;
    let zero = a.zero();
    let mut m = vec![vec![zero; nd]; nd];
    let mut h = vec![zero; nd];
    for (n, node) in tree.nodes.iter().enumerate().skip(1) {
        for &f in &node.frames {
            let Some(inr) = sys.frames[f].inertia else {
                continue;
            };
            let k = &world.nodes[n];
            let phi = s::sym(&inr.tensor);
            // a body spinning about a symmetry axis has the same inertia in its parent's axes
            let r = if spinning[f] {
                world.nodes[node.parent].r
            } else {
                k.r
            };
            // rotational columns in body axes, and Φ times them
            let jwb: Vec<(u16, V3)> =
                k.jw.iter()
                    .map(|&(q, c)| (q, s::mul_mtv(a, &r, c)))
                    .collect();
            let ijw: Vec<V3> = jwb.iter().map(|&(_, c)| s::mul_mv(a, &phi, c)).collect();
            for (x, &(i, vi)) in k.jv.iter().enumerate() {
                for &(j, vj) in &k.jv[..=x] {
                    let d = s::dot(a, vi, vj);
                    let t = a.mul(inr.mass, d);
                    m[i as usize][j as usize] = a.add(m[i as usize][j as usize], t);
                }
            }
            for (x, &(i, wi)) in jwb.iter().enumerate() {
                for (y, &(j, _)) in jwb[..=x].iter().enumerate() {
                    let t = s::dot(a, wi, ijw[y]);
                    m[i as usize][j as usize] = a.add(m[i as usize][j as usize], t);
                }
            }
            // translational: m (g − a_b)
            let mut acc = s::neg(a, k.ab);
            if let Some(g) = loads.gravity {
                acc = s::add(a, acc, g);
            }
            let lin = s::scale(a, inr.mass, acc);
            for &(i, vi) in &k.jv {
                let t = s::dot(a, vi, lin);
                h[i as usize] = a.add(h[i as usize], t);
            }
            // rotational: −(Φ α_b + ω × Φ ω), body axes
            let wb = s::mul_mtv(a, &r, k.w);
            let alb = s::mul_mtv(a, &r, k.alb);
            let ia = s::mul_mv(a, &phi, alb);
            let iw = s::mul_mv(a, &phi, wb);
            let gyro = s::cross(a, wb, iw);
            let rot = s::add(a, ia, gyro);
            for &(i, wi) in &jwb {
                let t = s::dot(a, wi, rot);
                h[i as usize] = a.sub(h[i as usize], t);
            }
        }
    }
    for &(n, r, f) in &loads.forces {
        for (i, c) in world.point_jacobian(a, n, r) {
            let t = s::dot(a, c, f);
            h[i as usize] = a.add(h[i as usize], t);
        }
    }
    for &(n, t) in &loads.torques {
        for &(i, c) in &world.nodes[n].jw {
            let p = s::dot(a, c, t);
            h[i as usize] = a.add(h[i as usize], p);
        }
    }
    for &(k, q) in &loads.generalized {
        h[k] = a.add(h[k], q);
    }
    for r in 0..nd {
        for c in (r + 1)..nd {
            m[r][c] = m[c][r];
        }
    }
    (m, h)
}
