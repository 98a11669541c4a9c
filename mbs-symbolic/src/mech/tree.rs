//! The kinematic tree: every elementary factor of every TOG product is an edge. Each product
//! is first put in a canonical order (a translation along the axis of the rotation before it
//! moves in front of the rotation: both give the same transform, and a body whose product then
//! ends with its rotation may spin about a symmetry axis, see `mech::spin`). Products that
//! start alike share their first edges (CAGeM's absolute chains: a common prefix is a massless
//! intermediate frame), and consecutive factors that no frame separates are fused
//! (`Tdisp·Tdisp`, rotations about one axis or about opposite axes).

use super::spatial::{V3, cross};
use super::system::{Factor, System};
use crate::expr::{Arena, ExprId, Var};

/// A node is a frame: the ground (node 0), a user's body or frame, or an intermediate frame.
#[derive(Clone, Debug)]
pub struct TreeNode {
    /// parent node (the ground's parent is itself)
    pub parent: usize,
    /// the factor from the parent's frame to this one (`None` for the ground)
    pub factor: Option<Factor>,
    /// the system's frames (bodies, massless frames) located at this node
    pub frames: Vec<usize>,
    pub children: Vec<usize>,
}

#[derive(Clone, Debug)]
pub struct Tree {
    /// parents before children; node 0 is the ground
    pub nodes: Vec<TreeNode>,
    /// node of each system frame
    pub frame_node: Vec<usize>,
}

impl Tree {
    pub fn build(sys: &mut System) -> Tree {
        let mut nodes = vec![TreeNode {
            parent: 0,
            factor: None,
            frames: Vec::new(),
            children: Vec::new(),
        }];
        let n = sys.frames.len();
        let mut frame_node = vec![0; n];
        for i in sys.frames_parents_first() {
            let f = &sys.frames[i];
            let mut cur = f.parent.map_or(0, |p| frame_node[p]);
            let factors = canonical(&f.factors, &mut sys.arena);
            for fac in &factors {
                let existing = nodes[cur]
                    .children
                    .iter()
                    .copied()
                    .find(|&c| nodes[c].factor == Some(*fac));
                cur = match existing {
                    Some(c) => c,
                    None => {
                        nodes.push(TreeNode {
                            parent: cur,
                            factor: Some(*fac),
                            frames: Vec::new(),
                            children: Vec::new(),
                        });
                        let n = nodes.len() - 1;
                        nodes[cur].children.push(n);
                        n
                    }
                };
            }
            nodes[cur].frames.push(i);
            frame_node[i] = cur;
        }
        let mut t = Tree { nodes, frame_node };
        t.fuse(&mut sys.arena);
        t
    }

    /// Fuses a frame-less node with a single child when their two factors make one.
    fn fuse(&mut self, a: &mut Arena) {
        let mut alive = vec![true; self.nodes.len()];
        for x in 1..self.nodes.len() {
            let node = &self.nodes[x];
            if !node.frames.is_empty() || node.children.len() != 1 {
                continue;
            }
            let c = node.children[0];
            let (Some(fx), Some(fc)) = (node.factor, self.nodes[c].factor) else {
                continue;
            };
            let fused = match (fx, fc) {
                (Factor::Disp(d1), Factor::Disp(d2)) => Some(Factor::Disp([
                    a.add(d1[0], d2[0]),
                    a.add(d1[1], d2[1]),
                    a.add(d1[2], d2[2]),
                ])),
                (
                    Factor::Rot {
                        axis: n1,
                        angle: a1,
                    },
                    Factor::Rot {
                        axis: n2,
                        angle: a2,
                    },
                ) if n1 == n2 => Some(Factor::Rot {
                    axis: n1,
                    angle: a.add(a1, a2),
                }),
                (
                    Factor::Rot {
                        axis: n1,
                        angle: a1,
                    },
                    Factor::Rot {
                        axis: n2,
                        angle: a2,
                    },
                ) if opposite(a, n1, n2) => Some(Factor::Rot {
                    axis: n1,
                    angle: a.sub(a1, a2),
                }),
                _ => None,
            };
            let Some(f) = fused else { continue };
            let p = node.parent;
            self.nodes[c].factor = Some(f);
            self.nodes[c].parent = p;
            for ch in self.nodes[p].children.iter_mut() {
                if *ch == x {
                    *ch = c;
                }
            }
            alive[x] = false;
        }
        // renumber, keeping parents before children
        let mut map = vec![usize::MAX; self.nodes.len()];
        let mut next = 0;
        for (i, &al) in alive.iter().enumerate() {
            if al {
                map[i] = next;
                next += 1;
            }
        }
        let old = std::mem::take(&mut self.nodes);
        for (i, mut n) in old.into_iter().enumerate() {
            if !alive[i] {
                continue;
            }
            n.parent = map[n.parent];
            n.children = n.children.iter().map(|&c| map[c]).collect();
            self.nodes.push(n);
        }
        for f in self.frame_node.iter_mut() {
            *f = map[*f];
        }
    }

    /// Coordinates that the factor into `node` depends on.
    pub fn factor_dofs(&self, a: &Arena, node: usize) -> Vec<u16> {
        let Some(f) = self.nodes[node].factor else {
            return Vec::new();
        };
        let roots: Vec<ExprId> = match f {
            Factor::Disp(d) => d.to_vec(),
            Factor::Rot { angle, .. } => vec![angle],
            Factor::Chart(_) => return Vec::new(),
        };
        a.vars_of(&roots)
            .into_iter()
            .filter_map(|v| match v {
                Var::Q(k) => Some(k),
                _ => None,
            })
            .collect()
    }

    /// Nodes from `node` up to (excluding) the ground.
    pub fn path_to_root(&self, mut node: usize) -> Vec<usize> {
        let mut v = Vec::new();
        while node != 0 {
            v.push(node);
            node = self.nodes[node].parent;
        }
        v
    }
}

/// `factors` in canonical order: a translation d along the axis n of the rotation before it
/// (n × d = 0) moves in front of it, since Rot(n, φ)·Disp(d) = Disp(d)·Rot(n, φ) when R d = d;
/// repeated, so it passes every such rotation. The transform of the product is unchanged and
/// its rotations come last, where `mech::spin` can see a symmetric body's spin (no
/// trigonometry of φ), and products written either way share their edges.
pub fn canonical(factors: &[Factor], a: &mut Arena) -> Vec<Factor> {
    let mut f = factors.to_vec();
    let mut i = 1;
    while i < f.len() {
        if let (Factor::Rot { axis, .. }, Factor::Disp(d)) = (f[i - 1], f[i]) {
            if along(a, axis, d) {
                f.swap(i - 1, i);
                i = (i - 1).max(1);
                continue;
            }
        }
        i += 1;
    }
    f
}

/// Whether the translation `d` lies along the unit axis `n` (n × d simplifies to zero).
fn along(a: &mut Arena, n: V3, d: V3) -> bool {
    cross(a, n, d).iter().all(|&c| a.is_num(c, 0.0))
}

/// Whether two axes are opposite numeric vectors (`Troty(a)·Trotn(0, -1, 0, b)`).
fn opposite(a: &Arena, n1: V3, n2: V3) -> bool {
    n1.iter()
        .zip(&n2)
        .all(|(&x, &y)| matches!((a.as_num(x), a.as_num(y)), (Some(x), Some(y)) if x == -y))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rot(a: &mut Arena, n: [f64; 3], angle: ExprId) -> Factor {
        Factor::Rot {
            axis: n.map(|c| a.num(c)),
            angle,
        }
    }

    #[test]
    fn translations_along_the_axis_move_in_front_of_rotations() {
        let mut a = Arena::new();
        let (phi, psi, l) = (a.var(Var::Q(0)), a.var(Var::Q(1)), a.var(Var::Param(0)));
        let (z, c) = (a.zero(), a.num(0.3));
        // Troty(φ)·Tdisp(0, l, 0) → Tdisp(0, l, 0)·Troty(φ)
        let ry = rot(&mut a, [0.0, 1.0, 0.0], phi);
        let dy = Factor::Disp([z, l, z]);
        assert_eq!(canonical(&[ry, dy], &mut a), vec![dy, ry]);
        // a translation off the axis stays
        let dx = Factor::Disp([c, l, z]);
        assert_eq!(canonical(&[ry, dx], &mut a), vec![ry, dx]);
        // it passes every rotation about its direction, opposite axes included, and stops
        // at the first that is not
        let rny = rot(&mut a, [0.0, -1.0, 0.0], psi);
        let rz = rot(&mut a, [0.0, 0.0, 1.0], psi);
        assert_eq!(
            canonical(&[rz, ry, rny, dy, dx], &mut a),
            vec![rz, dy, ry, rny, dx]
        );
        // Trotn with a translation that is a multiple of its axis, symbolic length
        let n = [0.6, 0.0, 0.8];
        let rn = rot(&mut a, n, phi);
        let d = n.map(|k| a.scale(k, l));
        let dn = Factor::Disp(d);
        assert_eq!(canonical(&[rn, dn], &mut a), vec![dn, rn]);
        let d = [0.6, 0.8, 0.0].map(|k| a.scale(k, l));
        let off = Factor::Disp(d);
        assert_eq!(canonical(&[rn, off], &mut a), vec![rn, off]);
    }

    #[test]
    fn rotations_about_opposite_axes_fuse() {
        let mut sys = System::new("T");
        sys.dof("a", 0.0, 0.0);
        sys.dof("b", 0.0, 0.0);
        let (qa, qb) = (sys.q(0), sys.q(1));
        let ry = sys.rot([0.0, 1.0, 0.0], qa);
        let rny = sys.rot([0.0, -1.0, 0.0], qb);
        let i = sys.inertia(1.0, [0.1, 0.2, 0.3, 0.0, 0.0, 0.0]);
        sys.frame("b", None, vec![ry, rny], Some(i));
        let t = Tree::build(&mut sys);
        assert_eq!(t.nodes.len(), 2, "{:?}", t.nodes);
        let angle = sys.arena.sub(qa, qb);
        assert_eq!(
            t.nodes[1].factor,
            Some(Factor::Rot {
                axis: [sys.arena.zero(), sys.arena.one(), sys.arena.zero()],
                angle
            })
        );
    }
}
