//! Scheduling of straight-line code. Hash-consing already shares every structurally equal
//! subexpression; this stage decides which shared nodes become `let` temporaries, which are
//! inlined into their single user, and how the `let`s split into chunks of at most
//! [`MAX_LETS`] (bigger single functions crash rustc's debug-info generation).

use super::{Arena, ExprId, Node};

/// Most `let`s in one generated function.
pub const MAX_LETS: usize = 1500;

/// Deepest inlined expression before a temporary is introduced (keeps lines readable and
/// rustc's recursion shallow).
const MAX_INLINE_DEPTH: u32 = 10;

/// The plan of a straight-line function computing `outputs`.
#[derive(Debug, Clone)]
pub struct Schedule {
    /// output roots, in the order given
    pub outputs: Vec<ExprId>,
    /// every node the outputs need, in topological order
    pub order: Vec<ExprId>,
    /// nodes that get a `let`, in emission (topological) order
    pub lets: Vec<ExprId>,
    /// for each chunk, the range of `lets` it defines
    pub chunks: Vec<std::ops::Range<usize>>,
    /// per node index: `Some(chunk)` when the node has a `let` in that chunk
    pub(crate) let_chunk: Vec<Option<u32>>,
    /// per output: the chunk that assigns it
    pub(crate) output_chunk: Vec<u32>,
}

impl Schedule {
    pub fn new(arena: &Arena, outputs: &[ExprId]) -> Schedule {
        Self::with_max_lets(arena, outputs, MAX_LETS)
    }

    /// As [`Schedule::new`] with another chunk size (tests use small ones).
    pub fn with_max_lets(arena: &Arena, outputs: &[ExprId], max_lets: usize) -> Schedule {
        let order = arena.reachable(outputs);
        let top = order.last().map_or(0, |n| n.index() + 1);
        let mut uses = vec![0u32; top];
        for &n in &order {
            let (ch, k) = arena.node(n).children();
            for c in &ch[..k] {
                uses[c.index()] += 1;
            }
        }
        let mut is_output = vec![false; top];
        for o in outputs {
            uses[o.index()] += 1;
            is_output[o.index()] = true;
        }
        let mut depth = vec![0u32; top];
        let mut is_let = vec![false; top];
        let mut lets = Vec::new();
        for &n in order.iter() {
            let node = arena.node(n);
            if matches!(node, Node::Num(_) | Node::Var(_)) {
                continue;
            }
            let (ch, k) = node.children();
            let d = 1 + ch[..k]
                .iter()
                .map(|c| {
                    if is_let[c.index()] {
                        0
                    } else {
                        depth[c.index()]
                    }
                })
                .max()
                .unwrap_or(0);
            depth[n.index()] = d;
            let expensive = matches!(
                node,
                Node::Func(..)
                    | Node::Pow(..)
                    | Node::Atan2(..)
                    | Node::Call(..)
                    | Node::Spline(..)
            );
            let output_only = is_output[n.index()] && uses[n.index()] == 1;
            if !output_only && (uses[n.index()] > 1 || expensive || d > MAX_INLINE_DEPTH) {
                is_let[n.index()] = true;
                lets.push(n);
            }
        }
        let max_lets = max_lets.max(1);
        let chunks: Vec<_> = if lets.is_empty() {
            std::iter::once(0..0).collect()
        } else {
            (0..lets.len())
                .step_by(max_lets)
                .map(|s| s..(s + max_lets).min(lets.len()))
                .collect()
        };
        let mut let_chunk = vec![None; top];
        for (ci, r) in chunks.iter().enumerate() {
            for &n in &lets[r.clone()] {
                let_chunk[n.index()] = Some(ci as u32);
            }
        }
        // an output goes in the chunk that holds the last `let` created before its root
        let output_chunk = outputs
            .iter()
            .map(|o| (lets.partition_point(|l| l <= o).saturating_sub(1) / max_lets) as u32)
            .collect();
        Schedule {
            outputs: outputs.to_vec(),
            order,
            lets,
            chunks,
            let_chunk,
            output_chunk,
        }
    }

    /// True when the node is bound by a `let`.
    pub fn is_let(&self, n: ExprId) -> bool {
        self.let_chunk.get(n.index()).is_some_and(|c| c.is_some())
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Arena, Var};
    use super::Schedule;

    #[test]
    fn shared_nodes_get_lets_and_single_uses_inline() {
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let y = a.var(Var::Q(1));
        let s = a.add(x, y); // used twice
        let m = a.mul(s, s);
        let n = a.mul(s, x); // single use of s*x inlined into the output
        let sch = Schedule::new(&a, &[m, n]);
        assert!(sch.is_let(s));
        assert!(!sch.is_let(m) && !sch.is_let(n));
    }
}
