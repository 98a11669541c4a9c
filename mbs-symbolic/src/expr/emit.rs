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
}

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
    fn name(&self, n: ExprId) -> String {
        match self.arena.node(n) {
            Node::Func(f @ (Func::Sin | Func::Cos), a) => match self.arena.node(a) {
                Node::Var(v) => format!("{}_{}", f.name(), self.naming.var(v)),
                _ => format!("x{}", n.index()),
            },
            _ => format!("x{}", n.index()),
        }
    }

    /// Text and precedence of `n` where it is used.
    fn expr(&mut self, n: ExprId) -> (String, Prec) {
        if self.sch.is_let(n) {
            return (self.name(n), Prec::Atom);
        }
        self.body(n)
    }

    fn wrap(&mut self, n: ExprId, min: Prec) -> String {
        let (s, p) = self.expr(n);
        if p < min { format!("({s})") } else { s }
    }

    /// Text of the definition of `n` (ignoring any `let` of its own).
    fn body(&mut self, n: ExprId) -> (String, Prec) {
        match self.arena.node(n) {
            Node::Num(b) => {
                let v = f64::from_bits(b);
                let s = literal(v);
                (s, if v < 0.0 { Prec::Unary } else { Prec::Atom })
            }
            Node::Var(v) => (self.naming.var(v), Prec::Atom),
            Node::Add(a, b) => (
                format!("{} + {}", self.wrap(a, Prec::Add), self.wrap(b, Prec::Mul)),
                Prec::Add,
            ),
            Node::Sub(a, b) => (
                format!("{} - {}", self.wrap(a, Prec::Add), self.wrap(b, Prec::Mul)),
                Prec::Add,
            ),
            Node::Mul(a, b) => (
                format!(
                    "{} * {}",
                    self.wrap(a, Prec::Mul),
                    self.wrap(b, Prec::Unary)
                ),
                Prec::Mul,
            ),
            Node::Div(a, b) => (
                format!(
                    "{} / {}",
                    self.wrap(a, Prec::Mul),
                    self.wrap(b, Prec::Unary)
                ),
                Prec::Mul,
            ),
            Node::Neg(a) => (format!("-{}", self.wrap(a, Prec::Atom)), Prec::Unary),
            Node::Powi(a, 2) => {
                let s = self.wrap(a, Prec::Atom);
                (format!("{s} * {s}"), Prec::Mul)
            }
            Node::Powi(a, k) => (
                format!("{}.powi({k})", self.wrap(a, Prec::Atom)),
                Prec::Atom,
            ),
            Node::Pow(a, b) => (
                format!("{}.powf({})", self.wrap(a, Prec::Atom), self.expr(b).0),
                Prec::Atom,
            ),
            Node::Func(Func::Sign, a) => {
                let s = self.wrap(a, Prec::Atom);
                (
                    format!("if {s} == 0.0 {{ 0.0 }} else {{ {s}.signum() }}"),
                    Prec::Add,
                )
            }
            Node::Func(f, a) => (
                format!("{}.{}()", self.wrap(a, Prec::Atom), f.name()),
                Prec::Atom,
            ),
            Node::Atan2(y, x) => (
                format!("{}.atan2({})", self.wrap(y, Prec::Atom), self.expr(x).0),
                Prec::Atom,
            ),
            Node::Call(f, k, a) => {
                let uf = &self.arena.user_fns()[f as usize];
                let path = match uf.paths.get(k as usize) {
                    Some(p) => p.clone(),
                    None => {
                        let m = MissingDerivative {
                            function: uf.name.clone(),
                            order: k,
                        };
                        if !self.missing.contains(&m) {
                            self.missing.push(m);
                        }
                        "f64::from".into()
                    }
                };
                (format!("{path}({})", self.expr(a).0), Prec::Atom)
            }
        }
    }
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
    };
    let mut chunks = Vec::with_capacity(nchunks);
    for (c, r) in sch.chunks.iter().enumerate() {
        let mut s = String::new();
        let vars = &mut chunk_vars[c];
        vars.sort_unstable();
        vars.dedup();
        for &v in vars.iter() {
            let _ = writeln!(s, "{}", naming.bind(v));
        }
        let loads = &mut chunk_loads[c];
        loads.sort_unstable();
        loads.dedup();
        for &l in loads.iter() {
            let _ = writeln!(s, "let {} = w[{}];", w.name(l), slot[l.index()].unwrap());
        }
        for &n in &sch.lets[r.clone()] {
            let (text, _) = w.body(n);
            let name = w.name(n);
            let _ = writeln!(s, "let {name} = {text};");
            if let Some(k) = slot[n.index()] {
                let _ = writeln!(s, "w[{k}] = {name};");
            }
        }
        for (i, &o) in sch.outputs.iter().enumerate() {
            if sch.output_chunk[i] as usize == c {
                let (text, _) = w.expr(o);
                let _ = writeln!(s, "{} = {text};", targets[i]);
            }
        }
        chunks.push(s);
    }
    if !w.missing.is_empty() {
        return Err(w.missing);
    }
    let mut count = OpCount::of(arena, &sch.outputs);
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
    use super::{Naming, emit};

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
        let e = emit(&a, &sch, &["out[0]".into(), "out[1]".into()], &N).unwrap();
        assert_eq!(e.chunks.len(), 1);
        let code = &e.chunks[0];
        assert!(code.contains("let sin_q0 = q0.sin();"), "{code}");
        assert!(code.contains("out[0] = q1 - (q0 - q1) * sin_q0;"), "{code}");
        assert!(code.contains("out[1] = sin_q0;"), "{code}");
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
        let e = emit(&a, &sch, &targets, &N).unwrap();
        assert!(e.workspace > 0);
        assert!(e.chunks[1].contains("= w["), "{}", e.chunks[1]);
        assert!(
            e.chunks
                .iter()
                .all(|c| c.matches("let x").count() <= 3 + e.workspace)
        );
    }
}
