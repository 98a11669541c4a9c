//! Emission of a [`Schedule`] as Rust statements. Each chunk becomes the body of one function;
//! a value defined in one chunk and read in a later one travels through a workspace slice `w`.
//! The caller names the leaves and wraps chunk bodies into functions.

use super::cse::Schedule;
use super::{Arena, ExprId, Func, Node, OpCount, Var};
use std::fmt::Write;

/// How leaves appear in the emitted code.
pub trait Naming {
    /// Identifier of a leaf (bound by [`Naming::bind`]).
    fn var(&self, v: Var) -> String;
    /// Statement that binds the identifier of `v` from the function's arguments.
    fn bind(&self, v: Var) -> String;
    /// Path of spline number `s` of the arena, an [`mbs::Spline`](../../../mbs_runtime/spline/struct.Spline.html)
    /// (`eval(order, x)`).
    fn spline(&self, s: u16) -> String {
        format!("SPLINES[{s}]")
    }
}

/// The number type of emitted code.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Numbers {
    /// `f64`
    Scalar,
    /// several states at once: arguments, outputs and workspace slots are [`LANES_TYPE`];
    /// in the body every value that depends on the arguments is a `Simd` (a vector register),
    /// parameters and constants stay `f64` and meet them through mixed operators and the
    /// functions of `Math` (`Math::sin(x)`), which take either
    Lanes,
}

impl Numbers {
    /// The type of arguments, outputs and workspace slots.
    pub fn type_name(self) -> &'static str {
        match self {
            Numbers::Scalar => "f64",
            Numbers::Lanes => LANES_TYPE,
        }
    }

    /// The zero of that type.
    pub fn zero(self) -> String {
        match self {
            Numbers::Scalar => "0.0".into(),
            Numbers::Lanes => format!("{LANES_TYPE}::ZERO"),
        }
    }
}

/// The lanes type of [`Numbers::Lanes`] in arguments, outputs and workspace (the runtime's
/// `F64x4`).
pub const LANES_TYPE: &str = "::mbs::F64x4";
/// The lanes type in registers, which values that depend on the states have in the body of
/// a lanes function (`Simd::new` loads an `F64x4`).
const SIMD_TYPE: &str = "::mbs::lanes::Simd";
/// The functions of lanes code (`Math`, and `Math2` for two arguments), on `f64` or `Simd`.
const MATH: &str = "::mbs::lanes::Math";

/// A user function's derivative that the code needs but the model does not supply.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MissingDerivative {
    /// DSL name of the function
    pub function: String,
    /// derivative order needed (1 = first derivative)
    pub order: u8,
}

/// Emitted statements.
#[derive(Debug, Clone)]
pub struct Emitted {
    /// statements of each chunk, in order
    pub chunks: Vec<String>,
    /// length of the workspace slice `w` shared by the chunks (0 with a single chunk)
    pub workspace: usize,
    /// work of the whole function
    pub count: OpCount,
}

#[derive(Clone, Copy, PartialEq, PartialOrd)]
enum Prec {
    Add = 1,
    Mul = 2,
    Unary = 3,
    Atom = 4,
}

struct Writer<'a> {
    arena: &'a Arena,
    sch: &'a Schedule,
    naming: &'a dyn Naming,
    missing: Vec<MissingDerivative>,
    /// identifier of each leaf, computed once
    var_names: rustc_hash::FxHashMap<Var, String>,
    numbers: Numbers,
}

/// Rust literal of a number.
pub fn literal(v: f64) -> String {
    if v.is_nan() {
        "f64::NAN".into()
    } else if v.is_infinite() {
        if v > 0.0 {
            "f64::INFINITY".into()
        } else {
            "f64::NEG_INFINITY".into()
        }
    } else {
        format!("{v:?}")
    }
}

impl Writer<'_> {
    fn var(&mut self, v: Var) -> &str {
        let naming = self.naming;
        self.var_names.entry(v).or_insert_with(|| naming.var(v))
    }

    fn name(&mut self, n: ExprId, out: &mut String) {
        if let Node::Func(f @ (Func::Sin | Func::Cos), a) = self.arena.node(n) {
            if let Node::Var(v) = self.arena.node(a) {
                out.push_str(f.name());
                out.push('_');
                out.push_str(self.var(v));
                return;
            }
        }
        out.push('x');
        push_int(out, n.index());
    }

    fn name_string(&mut self, n: ExprId) -> String {
        let mut s = String::new();
        self.name(n, &mut s);
        s
    }

    /// Precedence of `n` where it is used.
    fn prec(&self, n: ExprId) -> Prec {
        if self.sch.is_let(n) {
            return Prec::Atom;
        }
        match self.arena.node(n) {
            Node::Num(b) => {
                if f64::from_bits(b) < 0.0 {
                    Prec::Unary
                } else {
                    Prec::Atom
                }
            }
            Node::Add(..) | Node::Sub(..) | Node::Func(Func::Sign | Func::Step, _) => Prec::Add,
            Node::Mul(..) | Node::Div(..) | Node::Powi(_, 2) => Prec::Mul,
            Node::Neg(_) => Prec::Unary,
            _ => Prec::Atom,
        }
    }

    /// Writes `n` where it is used: its name if it has a `let`, its definition otherwise,
    /// in parentheses when its precedence is below `min`.
    fn expr(&mut self, n: ExprId, min: Prec, out: &mut String) {
        if self.sch.is_let(n) {
            self.name(n, out);
            return;
        }
        if self.prec(n) < min {
            out.push('(');
            self.body(n, out);
            out.push(')');
        } else {
            self.body(n, out);
        }
    }

    /// Writes the definition of `n` (ignoring any `let` of its own).
    fn body(&mut self, n: ExprId, out: &mut String) {
        match self.arena.node(n) {
            Node::Num(b) => out.push_str(&literal(f64::from_bits(b))),
            Node::Var(v) => {
                let name = self.var(v).to_string();
                out.push_str(&name);
            }
            Node::Add(a, b) | Node::Sub(a, b) => {
                self.expr(a, Prec::Add, out);
                out.push_str(if matches!(self.arena.node(n), Node::Add(..)) {
                    " + "
                } else {
                    " - "
                });
                self.expr(b, Prec::Mul, out);
            }
            Node::Mul(a, b) | Node::Div(a, b) => {
                self.expr(a, Prec::Mul, out);
                out.push_str(if matches!(self.arena.node(n), Node::Mul(..)) {
                    " * "
                } else {
                    " / "
                });
                self.expr(b, Prec::Unary, out);
            }
            Node::Neg(a) => {
                out.push('-');
                self.expr(a, Prec::Atom, out);
            }
            Node::Powi(a, 2) => {
                self.expr(a, Prec::Atom, out);
                out.push_str(" * ");
                self.expr(a, Prec::Atom, out);
            }
            // lanes: the functions of `Math`/`Math2`, which take `f64` or lanes alike
            Node::Func(f, a) if self.numbers == Numbers::Lanes => {
                let _ = write!(out, "{MATH}::{}(", f.name());
                self.expr(a, Prec::Add, out);
                out.push(')');
            }
            Node::Powi(a, k) if self.numbers == Numbers::Lanes => {
                let _ = write!(out, "{MATH}::powi(");
                self.expr(a, Prec::Add, out);
                let _ = write!(out, ", {k})");
            }
            Node::Pow(a, b) | Node::Atan2(a, b) if self.numbers == Numbers::Lanes => {
                let f = if matches!(self.arena.node(n), Node::Pow(..)) {
                    "powf"
                } else {
                    "atan2"
                };
                let _ = write!(out, "{MATH}2::{f}(");
                self.expr(a, Prec::Add, out);
                out.push_str(", ");
                self.expr(b, Prec::Add, out);
                out.push(')');
            }
            Node::Powi(a, k) => {
                self.expr(a, Prec::Atom, out);
                let _ = write!(out, ".powi({k})");
            }
            Node::Pow(a, b) => {
                self.expr(a, Prec::Atom, out);
                out.push_str(".powf(");
                self.expr(b, Prec::Add, out);
                out.push(')');
            }
            Node::Func(Func::Sign, a) => {
                let mut s = String::new();
                self.expr(a, Prec::Atom, &mut s);
                let _ = write!(out, "if {s} == 0.0 {{ 0.0 }} else {{ {s}.signum() }}");
            }
            Node::Func(Func::Step, a) => {
                let mut s = String::new();
                self.expr(a, Prec::Atom, &mut s);
                let _ = write!(out, "if {s} > 0.0 {{ 1.0 }} else {{ 0.0 }}");
            }
            Node::Func(Func::Pos, a) => {
                self.expr(a, Prec::Atom, out);
                out.push_str(".max(0.0)");
            }
            Node::Func(f, a) => {
                self.expr(a, Prec::Atom, out);
                let _ = write!(out, ".{}()", f.name());
            }
            Node::Atan2(y, x) => {
                self.expr(y, Prec::Atom, out);
                out.push_str(".atan2(");
                self.expr(x, Prec::Add, out);
                out.push(')');
            }
            Node::Call(f, k, a) => {
                let uf = &self.arena.user_fns()[f as usize];
                let path = match uf.paths.get(k as usize) {
                    Some(p) => p.as_str(),
                    None => {
                        let m = MissingDerivative {
                            function: uf.name.clone(),
                            order: k,
                        };
                        if !self.missing.contains(&m) {
                            self.missing.push(m);
                        }
                        "f64::from"
                    }
                };
                match self.numbers {
                    Numbers::Scalar => {
                        out.push_str(path);
                        out.push('(');
                        self.expr(a, Prec::Add, out);
                        out.push(')');
                    }
                    // lanes: the Rust function lane by lane
                    Numbers::Lanes => {
                        let _ = write!(out, "{MATH}::map(");
                        self.expr(a, Prec::Add, out);
                        let _ = write!(out, ", {path})");
                    }
                }
            }
            Node::Spline(s, k, a) => {
                let path = self.naming.spline(s);
                match self.numbers {
                    Numbers::Scalar => {
                        let _ = write!(out, "{path}.eval({k}, ");
                        self.expr(a, Prec::Add, out);
                        out.push(')');
                    }
                    Numbers::Lanes => {
                        let _ = write!(out, "{MATH}::map(");
                        self.expr(a, Prec::Add, out);
                        let _ = write!(out, ", |x| {path}.eval({k}, x))");
                    }
                }
            }
        }
    }

    /// Writes the value of `n` where it is stored (an output, a workspace slot): lanes in
    /// [`Numbers::Lanes`] (`X::from(n)`, from lanes in registers or from an `f64`).
    fn stored(&mut self, n: ExprId, out: &mut String) {
        if self.numbers == Numbers::Lanes {
            out.push_str(LANES_TYPE);
            out.push_str("::from(");
            self.expr(n, Prec::Add, out);
            out.push(')');
        } else {
            self.expr(n, Prec::Add, out);
        }
    }
}

/// Whether leaf `v` differs between the states of a batch (parameters and charts do not).
fn varies(v: Var) -> bool {
    !matches!(v, Var::Param(_) | Var::Chart(_))
}

/// Appends a non-negative integer without the formatting machinery (slow unoptimised).
fn push_int(out: &mut String, mut v: usize) {
    let mut buf = [0u8; 20];
    let mut i = buf.len();
    loop {
        i -= 1;
        buf[i] = b'0' + (v % 10) as u8;
        v /= 10;
        if v == 0 {
            break;
        }
    }
    out.push_str(std::str::from_utf8(&buf[i..]).expect("ascii digits"));
}

/// Leaves and `let`s that the inline text of `n` reads.
fn refs(arena: &Arena, sch: &Schedule, n: ExprId, vars: &mut Vec<Var>, lets: &mut Vec<ExprId>) {
    let mut stack = vec![n];
    while let Some(m) = stack.pop() {
        match arena.node(m) {
            Node::Var(v) => vars.push(v),
            Node::Num(_) => {}
            node => {
                if m != n && sch.is_let(m) {
                    lets.push(m);
                    continue;
                }
                let (ch, k) = node.children();
                stack.extend_from_slice(&ch[..k]);
            }
        }
    }
}

/// What each chunk reads; workspace slots of values that cross chunks.
struct Plan {
    vars: Vec<Vec<Var>>,
    loads: Vec<Vec<ExprId>>,
    slot: Vec<Option<usize>>,
    workspace: usize,
}

impl Plan {
    fn read_let(&mut self, sch: &Schedule, l: ExprId, c: usize) {
        let lc = sch.let_chunk[l.index()].unwrap() as usize;
        if lc < c {
            if self.slot[l.index()].is_none() {
                self.slot[l.index()] = Some(self.workspace);
                self.workspace += 1;
            }
            self.loads[c].push(l);
        }
    }

    fn visit(&mut self, arena: &Arena, sch: &Schedule, n: ExprId, c: usize) {
        let mut ls = Vec::new();
        refs(arena, sch, n, &mut self.vars[c], &mut ls);
        for l in ls {
            self.read_let(sch, l, c);
        }
    }
}

/// Emits the statements of `sch`, output `i` assigned as `targets[i] = …;`.
pub fn emit(
    arena: &Arena,
    sch: &Schedule,
    targets: &[String],
    naming: &dyn Naming,
    numbers: Numbers,
) -> Result<Emitted, Vec<MissingDerivative>> {
    assert_eq!(targets.len(), sch.outputs.len(), "one target per output");
    let nchunks = sch.chunks.len();
    // pass 1: what each chunk reads, and which lets cross chunk boundaries
    let mut plan = Plan {
        vars: vec![Vec::new(); nchunks],
        loads: vec![Vec::new(); nchunks],
        slot: vec![None; sch.let_chunk.len()],
        workspace: 0,
    };
    for (c, r) in sch.chunks.iter().enumerate() {
        for &n in &sch.lets[r.clone()] {
            plan.visit(arena, sch, n, c);
        }
    }
    for (i, &o) in sch.outputs.iter().enumerate() {
        let c = sch.output_chunk[i] as usize;
        if sch.is_let(o) {
            plan.read_let(sch, o, c);
        } else {
            plan.visit(arena, sch, o, c);
        }
    }
    let Plan {
        vars: mut chunk_vars,
        loads: mut chunk_loads,
        slot,
        workspace,
    } = plan;
    // pass 2: text
    let mut w = Writer {
        arena,
        sch,
        naming,
        missing: Vec::new(),
        var_names: Default::default(),
        numbers,
    };
    let mut chunks = Vec::with_capacity(nchunks);
    for (c, r) in sch.chunks.iter().enumerate() {
        let mut s = String::new();
        let vars = &mut chunk_vars[c];
        vars.sort_unstable();
        vars.dedup();
        for &v in vars.iter() {
            let _ = writeln!(s, "{}", naming.bind(v));
            if numbers == Numbers::Lanes && varies(v) {
                let name = w.var(v).to_string();
                let _ = writeln!(s, "let {name} = {SIMD_TYPE}::new({name});");
            }
        }
        let loads = &mut chunk_loads[c];
        loads.sort_unstable();
        loads.dedup();
        for &l in loads.iter() {
            let (name, k) = (w.name_string(l), slot[l.index()].unwrap());
            if numbers == Numbers::Lanes {
                let _ = writeln!(s, "let {name} = {SIMD_TYPE}::new(w[{k}]);");
            } else {
                let _ = writeln!(s, "let {name} = w[{k}];");
            }
        }
        for &n in &sch.lets[r.clone()] {
            s.push_str("let ");
            w.name(n, &mut s);
            s.push_str(" = ");
            w.body(n, &mut s);
            s.push_str(";\n");
            if let Some(k) = slot[n.index()] {
                let _ = write!(s, "w[{k}] = ");
                w.stored(n, &mut s);
                s.push_str(";\n");
            }
        }
        for (i, &o) in sch.outputs.iter().enumerate() {
            if sch.output_chunk[i] as usize == c {
                s.push_str(&targets[i]);
                s.push_str(" = ");
                w.stored(o, &mut s);
                s.push_str(";\n");
            }
        }
        chunks.push(s);
    }
    if !w.missing.is_empty() {
        return Err(w.missing);
    }
    let mut count = super::ops_of_nodes(arena, &sch.order);
    count.lets = sch.lets.len();
    Ok(Emitted {
        chunks,
        workspace,
        count,
    })
}

#[cfg(test)]
mod tests {
    use super::super::cse::Schedule;
    use super::super::{Arena, Var};
    use super::{Naming, Numbers, emit};

    struct N;
    impl Naming for N {
        fn var(&self, v: Var) -> String {
            format!("{v}")
        }
        fn bind(&self, v: Var) -> String {
            match v {
                Var::Q(i) => format!("let q{i} = q[{i}];"),
                _ => format!("let {v} = 0.0;"),
            }
        }
    }

    #[test]
    fn emits_lets_outputs_and_parentheses() {
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let y = a.var(Var::Q(1));
        let s = a.sub(x, y);
        let sx = a.sin(x);
        let p = a.mul(s, sx);
        let d = a.sub(y, p);
        let sch = Schedule::new(&a, &[d, sx]);
        let e = emit(
            &a,
            &sch,
            &["out[0]".into(), "out[1]".into()],
            &N,
            Numbers::Scalar,
        )
        .unwrap();
        assert_eq!(e.chunks.len(), 1);
        let code = &e.chunks[0];
        assert!(code.contains("let sin_q0 = q0.sin();"), "{code}");
        assert!(code.contains("out[0] = q1 - (q0 - q1) * sin_q0;"), "{code}");
        assert!(code.contains("out[1] = sin_q0;"), "{code}");
    }

    #[test]
    fn emits_positive_part_and_step() {
        use super::super::Func;
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let y = a.var(Var::Q(1));
        let d = a.sub(x, y);
        let p = a.func(Func::Pos, d);
        let s = a.func(Func::Step, x);
        let f = a.mul(s, p);
        let g = a.add(s, y);
        let sch = Schedule::new(&a, &[f, g]);
        let e = emit(
            &a,
            &sch,
            &["out[0]".into(), "out[1]".into()],
            &N,
            Numbers::Scalar,
        )
        .unwrap();
        let code = &e.chunks[0];
        assert!(code.contains("(q0 - q1).max(0.0)"), "{code}");
        assert!(code.contains("if q0 > 0.0 { 1.0 } else { 0.0 }"), "{code}");
        assert_eq!(e.count.funcs, 2, "{code}");
    }

    #[test]
    fn chunks_pass_values_through_the_workspace() {
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let mut acc = x;
        let mut outs = Vec::new();
        for i in 0..7 {
            let s = a.sin(acc);
            let c = a.num(i as f64 + 2.0);
            acc = a.mul(c, s);
            outs.push(acc);
        }
        let sch = Schedule::with_max_lets(&a, &outs, 3);
        assert!(sch.chunks.len() > 1);
        let targets: Vec<String> = (0..outs.len()).map(|i| format!("out[{i}]")).collect();
        let e = emit(&a, &sch, &targets, &N, Numbers::Scalar).unwrap();
        assert!(e.workspace > 0);
        assert!(e.chunks[1].contains("= w["), "{}", e.chunks[1]);
        assert!(
            e.chunks
                .iter()
                .all(|c| c.matches("let x").count() <= 3 + e.workspace)
        );
    }

    #[test]
    fn lanes_load_states_into_registers_and_call_math() {
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let p = a.var(Var::Param(0));
        let mut acc = x;
        let mut outs = Vec::new();
        for i in 0..5 {
            let s = a.sin(acc);
            let c = a.num(i as f64 + 2.0);
            let cs = a.mul(c, s);
            acc = a.add(cs, p);
            let pos = a.func(crate::expr::Func::Pos, acc);
            outs.push(pos);
        }
        let sch = Schedule::with_max_lets(&a, &outs, 3);
        let targets: Vec<String> = (0..outs.len()).map(|i| format!("out[{i}]")).collect();
        let e = emit(&a, &sch, &targets, &N, Numbers::Lanes).unwrap();
        let all = e.chunks.concat();
        // the state in a register, the parameter as it is; functions through Math; outputs
        // and the workspace as F64x4
        assert!(
            all.contains("let q0 = ::mbs::lanes::Simd::new(q0);"),
            "{all}"
        );
        assert!(!all.contains("Simd::new(p0)"), "{all}");
        assert!(all.contains("::mbs::lanes::Math::sin("), "{all}");
        assert!(all.contains("::mbs::lanes::Math::pos("), "{all}");
        assert!(all.contains("out[0] = ::mbs::F64x4::from("), "{all}");
        assert!(all.contains("= ::mbs::lanes::Simd::new(w["), "{all}");
        assert!(all.contains("] = ::mbs::F64x4::from("), "{all}");
    }
}
