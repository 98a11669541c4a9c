//! Operation counts of generated functions. This file has no dependencies: the runtime
//! declares it as a module and the generator includes the same file, so the counts the
//! generator makes and the type generated models report them in are one definition.

use std::fmt;

/// Operation counts of one generated function, as reported by `mbs expand`. The generator
/// (`mbs-symbolic`) counts in this type too, so there is one definition.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OpCount {
    /// additions, subtractions and negations
    pub adds: usize,
    /// multiplications (an integer power `x^n` counts n − 1)
    pub muls: usize,
    /// divisions
    pub divs: usize,
    /// square roots, trigonometric and other elementary or user functions
    pub funcs: usize,
    /// `let` temporaries in the emitted code
    pub lets: usize,
}

impl OpCount {
    /// adds + muls + divs
    pub fn flops(&self) -> usize {
        self.adds + self.muls + self.divs
    }

    /// The columns of an op-count table, in its order: flops, adds, muls, divs, funcs, lets.
    pub fn columns(&self) -> [usize; 6] {
        [
            self.flops(),
            self.adds,
            self.muls,
            self.divs,
            self.funcs,
            self.lets,
        ]
    }
}

impl fmt::Display for OpCount {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} flops ({} adds, {} muls, {} divs), {} funcs",
            self.flops(),
            self.adds,
            self.muls,
            self.divs,
            self.funcs
        )
    }
}
