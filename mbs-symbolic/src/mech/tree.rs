//! The kinematic tree: every elementary factor of every TOG product is an edge. Products that
//! start alike share their first edges (CAGeM's absolute chains: a common prefix is a massless
//! intermediate frame), and consecutive factors that no frame separates are fused
//! (`Tdisp·Tdisp`, rotations about one axis).

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
            for fac in &f.factors {
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
