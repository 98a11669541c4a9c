//! Operation counts of straight-line code: every node reachable from the outputs is computed
//! exactly once (hash-consing shares equal subexpressions), so counting nodes counts work.
//! [`OpCount`] is the runtime's own file, included here: one definition for the counts the
//! generator makes and the type generated models report them in.

use super::{Arena, ExprId, Node};

#[path = "../../../mbs-runtime/src/op_count.rs"]
mod op_count;
pub use op_count::OpCount;

/// Counts the work to compute all of `roots` (no `let`s: scheduling fills them in).
pub fn ops(arena: &Arena, roots: &[ExprId]) -> OpCount {
    ops_of_nodes(arena, &arena.reachable(roots))
}

/// Counts the work of computing each of `nodes` once: additions, subtractions and negations
/// as adds, an integer power `x^n` as n − 1 multiplications, every other power, elementary
/// or user function as a function.
pub fn ops_of_nodes(arena: &Arena, nodes: &[ExprId]) -> OpCount {
    let mut c = OpCount::default();
    for &n in nodes {
        match arena.node(n) {
            Node::Num(_) | Node::Var(_) => {}
            Node::Add(..) | Node::Sub(..) => c.adds += 1,
            Node::Mul(..) => c.muls += 1,
            Node::Div(..) => c.divs += 1,
            Node::Neg(..) => c.adds += 1,
            Node::Powi(_, k) => c.muls += (k.unsigned_abs() as usize).saturating_sub(1),
            Node::Pow(..)
            | Node::Func(..)
            | Node::Atan2(..)
            | Node::Call(..)
            | Node::Spline(..) => c.funcs += 1,
        }
    }
    c
}
