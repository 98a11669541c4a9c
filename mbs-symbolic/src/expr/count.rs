//! Operation counts of straight-line code: every node reachable from the outputs is computed
//! exactly once (hash-consing shares equal subexpressions), so counting nodes counts work.

use super::{Arena, ExprId, Node};
use std::fmt;
use std::ops::AddAssign;

/// Operations of a generated function.
#[derive(Clone, Copy, Default, Debug, PartialEq, Eq, serde::Serialize)]
pub struct OpCount {
    /// additions, subtractions and negations
    pub adds: usize,
    /// multiplications (an integer power `x^n` counts n − 1)
    pub muls: usize,
    pub divs: usize,
    /// sqrt, trigonometric and other elementary or user functions
    pub funcs: usize,
    /// `let` temporaries in the emitted code (filled in by the scheduler)
    pub lets: usize,
}

impl OpCount {
    /// Floating-point operations: adds + muls + divs (functions are counted apart).
    pub fn flops(&self) -> usize {
        self.adds + self.muls + self.divs
    }

    /// Counts the work to compute all of `roots`.
    pub fn of(arena: &Arena, roots: &[ExprId]) -> OpCount {
        Self::of_nodes(arena, &arena.reachable(roots))
    }

    /// Counts the work of computing each of `nodes` once.
    pub fn of_nodes(arena: &Arena, nodes: &[ExprId]) -> OpCount {
        let mut c = OpCount::default();
        for &n in nodes {
            match arena.node(n) {
                Node::Num(_) | Node::Var(_) => {}
                Node::Add(..) | Node::Sub(..) => c.adds += 1,
                Node::Mul(..) => c.muls += 1,
                Node::Div(..) => c.divs += 1,
                Node::Neg(..) => c.adds += 1,
                Node::Powi(_, k) => c.muls += (k.unsigned_abs() as usize).saturating_sub(1),
                Node::Pow(..) | Node::Func(..) | Node::Atan2(..) | Node::Call(..) => c.funcs += 1,
            }
        }
        c
    }
}

impl AddAssign for OpCount {
    fn add_assign(&mut self, o: OpCount) {
        self.adds += o.adds;
        self.muls += o.muls;
        self.divs += o.divs;
        self.funcs += o.funcs;
        self.lets += o.lets;
    }
}

impl fmt::Display for OpCount {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} flops ({} adds, {} muls, {} divs), {} funcs, {} lets",
            self.flops(),
            self.adds,
            self.muls,
            self.divs,
            self.funcs,
            self.lets
        )
    }
}
