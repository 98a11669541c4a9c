//! Syntax tree of a `multibody!` block, with spans. Scalar and transform expressions stay
//! `syn::Expr` (Rust expression syntax, Rust precedence); the checker gives them meaning.

use proc_macro2::Span;
use syn::{Expr, Ident};

pub use super::repeat::Origin;

/// One `model` of a `multibody!` block.
#[derive(Clone)]
pub struct ModelDef {
    /// `///` doc lines
    pub docs: Vec<String>,
    /// visibility as written (`pub`, `pub(crate)`, or empty)
    pub vis: syn::Visibility,
    pub name: Ident,
    pub items: Vec<Item>,
    /// which loop iteration or part instance each item comes from (parallel to `items`)
    pub origins: Vec<Origin>,
    /// statements that did not parse (the parser skips them and goes on, so that the model
    /// still gets placeholder types)
    pub errors: Vec<syn::Error>,
}

/// A reference to a body or frame: `TOG[bar1]`, `TOG[2]` (declaration order) or `ground`.
#[derive(Clone, Debug)]
pub enum BodyRef {
    Name(Ident),
    Index(usize, Span),
}

impl BodyRef {
    pub fn span(&self) -> Span {
        match self {
            BodyRef::Name(i) => i.span(),
            BodyRef::Index(_, s) => *s,
        }
    }
}

/// A coordinate named in a declaration: `q[3]` or `knee`.
#[derive(Clone, Debug)]
pub enum DofName {
    Indexed(usize, Span),
    Named(Ident),
}

/// A statement inside the model block.
#[derive(Clone)]
pub enum Item {
    /// `param l = 1.0;`, `param k = 1e4 sensitive;` (generate ∂τ/∂k)
    Param {
        name: Ident,
        value: Expr,
        sensitive: bool,
    },
    /// `let I = m*l*l/12;` (an alias, substituted where used)
    Let { name: Ident, value: Expr },
    /// `dof q[0] = PI/2;`, `dof knee = 0.2, qd = 1.0;`
    Dof {
        /// kept at its value when a closed loop is assembled
        independent: bool,
        name: DofName,
        q0: Option<Expr>,
        qd0: Option<Expr>,
        span: Span,
    },
    /// `input torque;`
    Input { name: Ident },
    /// `body bar { mass = m; inertia = (ixx, iyy, izz); }`
    Body {
        name: Ident,
        props: Vec<(Ident, Expr)>,
    },
    /// `frame sensor;` (massless)
    Frame { name: Ident },
    /// `point tip on bar at (x, y, z);`
    Point {
        name: Ident,
        body: BodyRef,
        at: Expr,
    },
    /// `mass tip on bar at (x, y, z) = 0.5;`: a point mass fixed on a body
    Mass {
        name: Ident,
        body: BodyRef,
        at: Expr,
        value: Expr,
    },
    /// `TOG[bar] = chain;`
    Tog {
        target: BodyRef,
        chain: Expr,
        span: Span,
    },
    /// `fn f(x, y) = expr;`
    Fn {
        name: Ident,
        args: Vec<Ident>,
        body: Expr,
    },
    /// `extern fn g = [path, d_path, dd_path];`
    ExternFn { name: Ident, paths: Vec<syn::Path> },
    /// an effect statement outside any `effect` block: always on
    Effect(EffectStmt),
    /// `effect name { statements }`
    EffectBlock {
        name: Ident,
        stmts: Vec<EffectStmt>,
        /// which loop iteration or part instance each statement comes from
        origins: Vec<Origin>,
    },
    /// `scene Name = [effect, …];`
    Scene { name: Ident, effects: Vec<Ident> },
    /// `constraint NAME = Φ;` or `constraint NAME: coincide(…);`
    Constraint { name: Ident, body: ConstraintBody },
    /// `option tangents;`, `option formulation = recursive;`
    Option { key: Ident, value: Option<Expr> },
    /// `shape bar: box(lx, ly, lz, at = (x, y, z), color = "#rrggbb");`: what to draw
    Shape { body: Ident, shape: EffectStmt },
}

/// The body of a `constraint` statement.
#[derive(Clone)]
pub enum ConstraintBody {
    /// `constraint drive = crank - omega * t;` (Φ = 0)
    Scalar(Expr),
    /// `constraint loop: coincide(a, b[, along = [x, y]][, frame = body]);`,
    /// `constraint hinge: align(A, B[, about = [x, y]]);`
    Closure(EffectStmt),
}

/// `gravity(0, -g, 0);`, `spring(a, b, k = 10, l0 = 1);`, … : a call with positional and
/// named (`name = expr`) arguments.
#[derive(Clone)]
pub struct EffectStmt {
    pub kind: Ident,
    pub positional: Vec<Expr>,
    pub named: Vec<(Ident, Expr)>,
}
