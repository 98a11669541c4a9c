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

/// Latency of one node's operation in cycles (see [`critical_path`]).
pub fn latency(node: Node) -> u32 {
    match node {
        Node::Num(_) | Node::Var(_) => 0,
        Node::Add(..) | Node::Sub(..) | Node::Neg(..) => 3,
        Node::Mul(..) => 4,
        Node::Powi(_, k) => 4u32.saturating_mul(k.unsigned_abs().saturating_sub(1)),
        Node::Div(..) => 13,
        Node::Func(super::Func::Sqrt, _) => 15,
        _ => 40,
    }
}

/// Latency of the longest chain of dependent operations from the inputs to any of `roots`,
/// in cycles of a typical out-of-order core (add 3, multiply 4, divide 13, square root 15,
/// other functions 40): what bounds straight-line code whose work is a recursion, as the
/// articulated-body algorithm's, rather than its operation count.
pub fn critical_path(arena: &Arena, roots: &[ExprId]) -> u32 {
    let mut ready = super::ready::Ready::default();
    roots.iter().map(|&r| ready.of(arena, r)).max().unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::Var;

    #[test]
    fn the_critical_path_is_the_longest_chain_of_latencies() {
        let mut a = crate::expr::Arena::new();
        let (x, y, z) = (a.var(Var::Q(0)), a.var(Var::Q(1)), a.var(Var::Q(2)));
        // (x·y + z) / x: multiply, add, divide in a row
        let p = a.mul(x, y);
        let s = a.add(p, z);
        let d = a.div(s, x);
        assert_eq!(critical_path(&a, &[d]), 4 + 3 + 13);
        // a side branch shorter than the chain does not lengthen it, a root alone counts
        let short = a.add(x, z);
        assert_eq!(critical_path(&a, &[d, short]), 20);
        assert_eq!(critical_path(&a, &[short]), 3);
        assert_eq!(critical_path(&a, &[]), 0);
    }
}
