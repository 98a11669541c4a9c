//! The expression DAG: a hash-consed arena of scalar expressions, with canonical local rules,
//! differentiation, numeric evaluation, s-expressions, op counting, scheduling and emission.
//! Nothing here knows about mechanics.

mod arena;
pub mod count;
pub mod cse;
mod diff;
pub mod emit;
mod eval;
pub mod ready;
pub mod sexpr;
mod simplify;
#[path = "../../../mbs-runtime/src/spline.rs"]
#[allow(dead_code)]
mod spline;

pub use arena::Arena;
pub use count::{OpCount, critical_path, ops, ops_of_nodes};
pub use eval::{Env, SliceEnv};
pub use spline::{SplineError, evaluate as spline_value, natural_coefficients};

use std::fmt;

/// Handle of a node in an [`Arena`]. Ids are handed out in creation order, and a node's
/// children are always created before it, so id order is a topological order.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Debug)]
pub struct ExprId(pub(crate) u32);

impl ExprId {
    /// Position of the node in its arena.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// The leaves an expression can depend on.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Debug)]
pub enum Var {
    /// coordinate `q[i]`
    Q(u16),
    /// velocity `qd[i]`
    Qd(u16),
    /// acceleration `qdd[i]`
    Qdd(u16),
    /// time `t`
    T,
    /// parameter number `i` of the model
    Param(u16),
    /// input `u[i]`
    Input(u16),
    /// Lagrange multiplier `λ[i]` of constraint i (in generated constraint tangents)
    Lambda(u16),
    /// entry `i = 9 j + 3 r + c` of the chart of rotation joint `j`: row r, column c of the
    /// reference rotation the joint's angles are measured from, held by the model at run time
    /// and constant in time between re-centrings
    Chart(u16),
    /// generalised force `f[i]` added to h at run time (the argument of the generated
    /// forward dynamics that carries efforts computed outside the model)
    Force(u16),
}

impl Var {
    /// The bits of the dependency mask that parameters take.
    pub(crate) const PARAM_BITS: u128 = 0xf << 121;

    /// Bit of the dependency mask: coordinates, velocities and accelerations get 40 bits each,
    /// parameters and inputs share a few. Collisions only make the mask conservative.
    pub(crate) fn mask(self) -> u128 {
        let bit = match self {
            Var::Q(i) => i as u32 % 40,
            Var::Qd(i) => 40 + i as u32 % 40,
            Var::Qdd(i) => 80 + i as u32 % 40,
            Var::T => 120,
            Var::Param(i) => 121 + i as u32 % 4,
            Var::Input(i) | Var::Lambda(i) | Var::Chart(i) | Var::Force(i) => 125 + i as u32 % 3,
        };
        1u128 << bit
    }
}

impl fmt::Display for Var {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Var::Q(i) => write!(f, "q{i}"),
            Var::Qd(i) => write!(f, "qd{i}"),
            Var::Qdd(i) => write!(f, "qdd{i}"),
            Var::T => write!(f, "t"),
            Var::Param(i) => write!(f, "p{i}"),
            Var::Input(i) => write!(f, "u{i}"),
            Var::Lambda(i) => write!(f, "l{i}"),
            Var::Chart(i) => write!(f, "r{i}"),
            Var::Force(i) => write!(f, "f{i}"),
        }
    }
}

/// Elementary functions of one argument.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub enum Func {
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sinh,
    Cosh,
    Tanh,
    Exp,
    Ln,
    Sqrt,
    Abs,
    Sign,
    /// `pos(x)` = max(x, 0), the positive part (derivative `step(x)`)
    Pos,
    /// `step(x)` = 1 if x > 0, else 0 (derivative 0)
    Step,
}

impl Func {
    /// All functions, for name lookup.
    pub const ALL: [Func; 16] = [
        Func::Sin,
        Func::Cos,
        Func::Tan,
        Func::Asin,
        Func::Acos,
        Func::Atan,
        Func::Sinh,
        Func::Cosh,
        Func::Tanh,
        Func::Exp,
        Func::Ln,
        Func::Sqrt,
        Func::Abs,
        Func::Sign,
        Func::Pos,
        Func::Step,
    ];

    /// The name used in the DSL, in s-expressions and (as an `f64` method) in emitted code.
    pub fn name(self) -> &'static str {
        match self {
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Tan => "tan",
            Func::Asin => "asin",
            Func::Acos => "acos",
            Func::Atan => "atan",
            Func::Sinh => "sinh",
            Func::Cosh => "cosh",
            Func::Tanh => "tanh",
            Func::Exp => "exp",
            Func::Ln => "ln",
            Func::Sqrt => "sqrt",
            Func::Abs => "abs",
            Func::Sign => "sign",
            Func::Pos => "pos",
            Func::Step => "step",
        }
    }

    pub fn from_name(name: &str) -> Option<Func> {
        match name {
            "log" => Some(Func::Ln),
            "signum" => Some(Func::Sign),
            _ => Func::ALL.into_iter().find(|f| f.name() == name),
        }
    }

    pub fn apply(self, x: f64) -> f64 {
        match self {
            Func::Sin => x.sin(),
            Func::Cos => x.cos(),
            Func::Tan => x.tan(),
            Func::Asin => x.asin(),
            Func::Acos => x.acos(),
            Func::Atan => x.atan(),
            Func::Sinh => x.sinh(),
            Func::Cosh => x.cosh(),
            Func::Tanh => x.tanh(),
            Func::Exp => x.exp(),
            Func::Ln => x.ln(),
            Func::Sqrt => x.sqrt(),
            Func::Abs => x.abs(),
            Func::Sign => {
                if x > 0.0 {
                    1.0
                } else if x < 0.0 {
                    -1.0
                } else {
                    0.0
                }
            }
            // as emitted: `x.max(0.0)` (0 for NaN)
            Func::Pos => x.max(0.0),
            Func::Step => {
                if x > 0.0 {
                    1.0
                } else {
                    0.0
                }
            }
        }
    }
}

/// A user scalar function `f(x)` supplied as Rust code, with derivatives up to `orders - 1`.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct UserFn {
    /// DSL name (`g5`)
    pub name: String,
    /// Rust paths of f, f', f'', … as written by the user
    pub paths: Vec<String>,
}

/// A natural cubic spline of the language (`spline(x, [(x0, y0), …])`): its knots and the
/// coefficients of its intervals, computed when the model is generated.
#[derive(Clone, Debug, PartialEq)]
pub struct SplineTable {
    pub knots: Vec<f64>,
    pub coefficients: Vec<[f64; 4]>,
}

impl SplineTable {
    /// The natural cubic spline through `points`, or why there is none.
    pub fn natural(points: &[(f64, f64)]) -> Result<SplineTable, SplineError> {
        Ok(SplineTable {
            coefficients: natural_coefficients(points)?,
            knots: points.iter().map(|p| p.0).collect(),
        })
    }

    /// Derivative number `order` at `x` (0: the value).
    pub fn eval(&self, order: u8, x: f64) -> f64 {
        spline_value(&self.knots, &self.coefficients, order, x)
    }
}

/// One node of the DAG. Commutative operands are stored in canonical order (a number first,
/// otherwise by id); the rules in `simplify.rs` keep nodes in canonical form.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub enum Node {
    /// a finite or non-finite constant, stored by bits (`-0.0` is stored as `0.0`)
    Num(u64),
    Var(Var),
    Add(ExprId, ExprId),
    Sub(ExprId, ExprId),
    Mul(ExprId, ExprId),
    Div(ExprId, ExprId),
    Neg(ExprId),
    /// integer power, exponent ≥ 2
    Powi(ExprId, i32),
    /// real power x^y
    Pow(ExprId, ExprId),
    Func(Func, ExprId),
    /// atan2(y, x)
    Atan2(ExprId, ExprId),
    /// derivative number `order` of user function number `f`, at the argument
    Call(u16, u8, ExprId),
    /// derivative number `order` (< 4) of spline number `s` of the arena, at the argument
    Spline(u16, u8, ExprId),
}

impl Node {
    /// Children of the node, at most two.
    pub fn children(&self) -> ([ExprId; 2], usize) {
        let z = ExprId(0);
        match *self {
            Node::Num(_) | Node::Var(_) => ([z, z], 0),
            Node::Neg(a)
            | Node::Powi(a, _)
            | Node::Func(_, a)
            | Node::Call(_, _, a)
            | Node::Spline(_, _, a) => ([a, z], 1),
            Node::Add(a, b)
            | Node::Sub(a, b)
            | Node::Mul(a, b)
            | Node::Div(a, b)
            | Node::Pow(a, b)
            | Node::Atan2(a, b) => ([a, b], 2),
        }
    }
}

pub(crate) fn num_bits(v: f64) -> u64 {
    if v == 0.0 {
        0.0f64.to_bits()
    } else if v.is_nan() {
        f64::NAN.to_bits()
    } else {
        v.to_bits()
    }
}
