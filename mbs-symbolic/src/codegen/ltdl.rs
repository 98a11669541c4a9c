//! Forward dynamics by sparse LᵀDL as two calls, where the generator would otherwise emit it
//! as one function: the scene's `__dynamics` writes M and h into buffers, then the model's one
//! `__ltdl` (on the parameter struct) factorises that M and solves. The LᵀDL is straight-line
//! code over M's structure (the union of the scenes'), its entries read from the buffer.
//!
//! The fused function (M, h and the factorisation in one schedule) repeats all of M and h,
//! which `__dynamics` has already, in every scene: on the hexapod (24 coordinates, three
//! scenes) 27,000 of the 142,000 operations the model's code had, and compile time follows
//! the operations (type checking alone is about 15 µs per operation). It is kept where the
//! dynamics is one chunk ([`after_dynamics`]): there the fused function holds M in registers,
//! which small models' timings depend on; where dynamics is split into chunks its values go
//! through the workspace already.

use super::function::{EmittedFn, FnSpec, emit_fn};
use crate::expr::emit::{MissingDerivative, Naming};
use crate::expr::{Arena, ExprId, OpCount, Var};
use crate::mech::SymbolicModel;
use crate::mech::dynamics::SceneEquations;
use crate::mech::forward::{ForwardMethod, ltdl};

/// Above this many coordinates the buffer of M (n² numbers on the stack) is not worth it: the
/// fused function is kept.
const MAX_COORDINATES: usize = 64;

/// Whether `eq`'s forward dynamics is `__dynamics` then `__ltdl`: sparse LᵀDL, M emitted whole
/// (not assembled at run time), dynamics in more than one chunk and at most
/// [`MAX_COORDINATES`].
pub fn after_dynamics(model: &SymbolicModel, eq: &SceneEquations) -> bool {
    let n = model.sys.ndof();
    if eq.forward.method != ForwardMethod::SparseLtdl || model.assembled || n > MAX_COORDINATES {
        return false;
    }
    let a = &model.sys.arena;
    let mb = eq.chosen();
    let mut roots: Vec<ExprId> =
        mb.m.iter()
            .flatten()
            .copied()
            .filter(|&e| !a.is_num(e, 0.0))
            .collect();
    roots.extend_from_slice(&mb.h);
    crate::expr::cse::Schedule::new(a, &roots).chunks.len() > 1
}

/// Leaves of the LᵀDL's own arena: `Var::Q(k)` stands for entry k of the buffer `m` (M
/// column-major, `m[i + n j]`), `Var::Qd(i)` for `h[i]`.
struct BufferNames;

impl Naming for BufferNames {
    fn var(&self, v: Var) -> String {
        match v {
            Var::Q(k) => format!("m_{k}"),
            Var::Qd(i) => format!("h_{i}"),
            _ => unreachable!("the LTDL reads M and h only"),
        }
    }

    fn bind(&self, v: Var) -> String {
        match v {
            Var::Q(k) => format!("let m_{k} = m[{k}];"),
            Var::Qd(i) => format!("let h_{i} = h[{i}];"),
            _ => unreachable!("the LTDL reads M and h only"),
        }
    }
}

/// The method `__ltdl(&self, m, h, qdd, pivots)` for M's structure in `scenes` (the union of
/// their structural zeros' complements).
pub fn emit(
    model: &SymbolicModel,
    scenes: &[&SceneEquations],
) -> Result<EmittedFn, Vec<MissingDerivative>> {
    let n = model.sys.ndof();
    let sa = &model.sys.arena;
    let nonzero = |i: usize, j: usize| scenes.iter().any(|eq| !sa.is_num(eq.chosen().m[i][j], 0.0));
    let mut a = Arena::new();
    let zero = a.zero();
    // rows of the symmetric M, every entry read from its lower-triangle position
    let m: Vec<Vec<ExprId>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    let (r, c) = (i.max(j), i.min(j));
                    if nonzero(r, c) {
                        a.var(Var::Q((r + n * c) as u16))
                    } else {
                        zero
                    }
                })
                .collect()
        })
        .collect();
    let h: Vec<ExprId> = (0..n).map(|i| a.var(Var::Qd(i as u16))).collect();
    let f = ltdl(&mut a, &m, &h);
    let mut spec = FnSpec::new(
        "__ltdl",
        "m: &[f64], h: &[f64], qdd: &mut [f64], pivots: &mut [f64]",
    );
    spec.vector("qdd", &f.qdd);
    spec.vector("pivots", &f.pivots);
    emit_fn(&a, &spec, &BufferNames)
}

/// The scene's `__forward_dynamics` (the arguments of `forward_dynamics_forced`): M and h by
/// `__dynamics`, the given generalised force added, then the model's `__ltdl`.
pub fn forward_method(n: usize) -> String {
    format!(
        "#[inline]
fn __forward_dynamics(&self, {}) {{
let (mut m, mut hf) = ([0.0f64; {}], [0.0f64; {n}]);
self.__dynamics(t, q, qd, u, &mut m, &mut hf);
for (h, f) in hf.iter_mut().zip(f) {{
*h += f;
}}
self.params.__ltdl(&m, &hf, qdd, pivots);
}}
",
        super::api::FORWARD_DYNAMICS_FORCED.args,
        n * n
    )
}

/// The op count of that method: dynamics', the force's additions and the LTDL's.
pub fn forward_count(n: usize, dynamics: OpCount, ltdl: OpCount) -> OpCount {
    OpCount {
        adds: dynamics.adds + n + ltdl.adds,
        muls: dynamics.muls + ltdl.muls,
        divs: dynamics.divs + ltdl.divs,
        funcs: dynamics.funcs + ltdl.funcs,
        lets: dynamics.lets + ltdl.lets,
    }
}
