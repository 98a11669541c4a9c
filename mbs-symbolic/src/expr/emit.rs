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
    /// The statement of [`Numbers::Lanes`] code binding `v` to its four lanes (an
    /// [`F64x4`](../../../mbs_runtime/lanes/struct.F64x4.html)): parameters and charts too
    /// are each lane's own, those of the lane's model.
    fn bind_lanes(&self, v: Var) -> String {
        self.bind(v)
    }
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
    /// in the body every leaf is a `Simd` (a vector register), the parameters and charts each
    /// lane's own ([`Naming::bind_lanes`]); constants stay `f64` and meet them through mixed
    /// operators and the functions of `Math` (`Math::sin(x)`), which take either
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

    /// Opens the call of method `f` on `a` with further arguments: `a.f(`, or `f64::f(a, `
    /// where `a` is written as a bare number (`2.0.powf(x)` does not compile: E0689, an
    /// ambiguous float type).
    fn method_call(&mut self, a: ExprId, f: &str, out: &mut String) {
        if !self.sch.is_let(a) && matches!(self.arena.node(a), Node::Num(_)) {
            let _ = write!(out, "f64::{f}(");
            self.expr(a, Prec::Add, out);
            out.push_str(", ");
        } else {
            self.expr(a, Prec::Atom, out);
            let _ = write!(out, ".{f}(");
        }
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
                self.method_call(a, "powi", out);
                let _ = write!(out, "{k})");
            }
            Node::Pow(a, b) => {
                self.method_call(a, "powf", out);
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
                self.method_call(y, "atan2", out);
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

/// In functions split into chunks, stores to consecutive elements of one slice are one
/// statement (`*array_mut(&mut m[4..9]) = […];`), and so are reads of the workspace, from
/// this many elements: rustc's front end (type and borrow checking) takes far longer over one
/// statement per element.
const MIN_RUN: usize = 3;
/// At most this many elements per statement.
const MAX_RUN: usize = 32;
/// At most this many zeros written inside a run, where the buffer was filled with zeros
/// before (the zero entries of a Jacobian's columns).
const MAX_GAP: usize = 2;

/// Where the outputs go: targets of the form `base[index]` by base, for runs of stores.
struct Stores<'t> {
    targets: &'t [String],
    /// per target, `(base, index)` when it has that form
    split: Vec<Option<(&'t str, usize)>>,
    /// every indexed target
    all: rustc_hash::FxHashSet<(&'t str, usize)>,
    /// the bases filled with zeros before the computation
    zeroed: rustc_hash::FxHashSet<&'t str>,
}

impl<'t> Stores<'t> {
    fn new(targets: &'t [String], zeroed: &'t [String]) -> Stores<'t> {
        let split: Vec<_> = targets.iter().map(|t| split_index(t)).collect();
        Stores {
            targets,
            all: split.iter().flatten().copied().collect(),
            split,
            zeroed: zeroed.iter().map(|z| z.as_str()).collect(),
        }
    }

    /// Writes `targets[i] = value` for each `(i, value)`: runs of one base's consecutive
    /// indices as one statement each (zeros filling short gaps of a zeroed base that no
    /// output writes), the other targets one by one.
    fn write(&self, s: &mut String, outs: Vec<(usize, String)>, numbers: Numbers) {
        let mut indexed: Vec<(&str, usize, String)> = Vec::new();
        for (i, v) in outs {
            match self.split[i] {
                Some((b, k)) => indexed.push((b, k, v)),
                None => {
                    let _ = writeln!(s, "{} = {v};", self.targets[i]);
                }
            }
        }
        indexed.sort_by(|a, b| (a.0, a.1).cmp(&(b.0, b.1)));
        let mut run: Vec<(usize, Option<String>)> = Vec::new();
        let mut base = "";
        for (b, k, v) in indexed {
            if let Some(&(last, _)) = run.last() {
                let gap = if b == base { k - last - 1 } else { usize::MAX };
                let fills = gap > 0
                    && gap <= MAX_GAP
                    && self.zeroed.contains(base)
                    && (last + 1..k).all(|g| !self.all.contains(&(base, g)));
                if gap == 0 || fills {
                    run.extend((last + 1..k).map(|g| (g, None)));
                } else {
                    write_runs(s, base, &run, numbers);
                    run.clear();
                }
            }
            base = b;
            run.push((k, Some(v)));
        }
        write_runs(s, base, &run, numbers);
    }
}

/// Writes `let name = w[k];` for the `(k, name)` of `loads` (increasing `k`): stretches
/// with at most [`MAX_GAP`] slots skipped between reads, from [`MIN_RUN`] reads, as one
/// statement of at most [`MAX_RUN`] slots (`let [x3, _, x8] = w[4..7] else { … };`).
fn write_loads(s: &mut String, loads: &[(usize, String)]) {
    let mut i = 0;
    while i < loads.len() {
        let mut j = i + 1;
        while j < loads.len()
            && loads[j].0 - loads[j - 1].0 <= MAX_GAP + 1
            && loads[j].0 - loads[i].0 < MAX_RUN
        {
            j += 1;
        }
        if j - i >= MIN_RUN {
            let (a, b) = (loads[i].0, loads[j - 1].0 + 1);
            let mut names = vec!["_"; b - a];
            for (k, name) in &loads[i..j] {
                names[k - a] = name;
            }
            let _ = writeln!(
                s,
                "let [{}] = w[{a}..{b}] else {{ unreachable!() }};",
                names.join(", ")
            );
        } else {
            for (k, name) in &loads[i..j] {
                let _ = writeln!(s, "let {name} = w[{k}];");
            }
        }
        i = j;
    }
}

/// In functions of at most this many `let`s, the lengths of the slices the outputs go to are
/// checked once, at the top ([`bounded`]).
const BOUNDED_LETS: usize = 32;

/// `let base = &mut base[..n];` for each slice of the elements `(base, k)` stored to (`base`
/// a plain name, `n` one past its largest `k`), so that the stores check no length. A check
/// is a branch, and LLVM computes the sine and the cosine of one angle by one call (`sincos`)
/// only where both are in one block: in the forward dynamics of a two-bar chain the check of
/// `qdd` fell between them (three calls where two do). In longer functions the branches stay:
/// without them LLVM's SLP vectorizer packed the planar chains' and the arms' forward
/// dynamics into pairs whose shuffles cost more than they saved (8–20 % slower).
fn bounded<'a>(elements: impl Iterator<Item = (&'a str, usize)>) -> String {
    let mut len: Vec<(&str, usize)> = Vec::new();
    for (base, k) in elements {
        if !base.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_') {
            continue;
        }
        match len.iter_mut().find(|(b, _)| *b == base) {
            Some((_, n)) => *n = (*n).max(k + 1),
            None => len.push((base, k + 1)),
        }
    }
    let mut s = String::new();
    for (base, n) in len {
        let _ = writeln!(s, "let {base} = &mut {base}[..{n}];");
    }
    s
}

/// `"a.b[3]"` → `("a.b", 3)`.
pub(crate) fn split_index(t: &str) -> Option<(&str, usize)> {
    let inner = t.strip_suffix(']')?;
    let open = inner.rfind('[')?;
    let k = inner[open + 1..].parse().ok()?;
    Some((&inner[..open], k))
}

/// Writes `base[k] = v` for the `(k, v)` of `run`, whose indices are consecutive (`None`: a
/// zero where the buffer holds one already): from [`MIN_RUN`] elements as one assignment
/// of at most [`MAX_RUN`], the others one by one.
fn write_runs(s: &mut String, base: &str, run: &[(usize, Option<String>)], numbers: Numbers) {
    let zero = numbers.zero();
    for part in run.chunks(MAX_RUN) {
        // no statement starts or ends with a zero the buffer holds already
        let a = part
            .iter()
            .position(|e| e.1.is_some())
            .unwrap_or(part.len());
        let b = part
            .iter()
            .rposition(|e| e.1.is_some())
            .map_or(a, |b| b + 1);
        let part = &part[a..b];
        if part.len() >= MIN_RUN {
            let _ = write!(
                s,
                "*::mbs::__private::array_mut(&mut {base}[{}..{}]) = [",
                part[0].0,
                part[0].0 + part.len()
            );
            for (k, (_, v)) in part.iter().enumerate() {
                if k > 0 {
                    s.push_str(", ");
                }
                s.push_str(v.as_deref().unwrap_or(&zero));
            }
            s.push_str("];\n");
        } else {
            for (k, v) in part {
                if let Some(v) = v {
                    let _ = writeln!(s, "{base}[{k}] = {v};");
                }
            }
        }
    }
}

/// Emits the statements of `sch`, output `i` assigned as `targets[i] = …;` (added, `+=`, with
/// `accumulate`); `zeroed` names the targets' bases that were filled with zeros before
/// (their other elements are zero).
pub fn emit(
    arena: &Arena,
    sch: &Schedule,
    targets: &[String],
    zeroed: &[String],
    accumulate: bool,
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
        mut slot,
        workspace,
    } = plan;
    // slots numbered in the order of the lets: what a chunk reads of an earlier one lies in
    // stretches of consecutive slots
    let mut next = 0;
    for &n in &sch.lets {
        if let Some(k) = slot[n.index()].as_mut() {
            *k = next;
            next += 1;
        }
    }
    let stores = (nchunks > 1 && !accumulate).then(|| Stores::new(targets, zeroed));
    let op = if accumulate { "+=" } else { "=" };
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
            if numbers == Numbers::Lanes {
                // every leaf in registers, the parameters' and charts' lanes too
                let name = w.var(v).to_string();
                let _ = writeln!(s, "{}", naming.bind_lanes(v));
                let _ = writeln!(s, "let {name} = {SIMD_TYPE}::new({name});");
            } else {
                let _ = writeln!(s, "{}", naming.bind(v));
            }
        }
        let loads = &mut chunk_loads[c];
        loads.sort_unstable_by_key(|l| slot[l.index()]);
        loads.dedup();
        let loads: Vec<(usize, String)> = loads
            .iter()
            .map(|&l| (slot[l.index()].unwrap(), w.name_string(l)))
            .collect();
        if numbers == Numbers::Lanes {
            for (k, name) in &loads {
                let _ = writeln!(s, "let {name} = {SIMD_TYPE}::new(w[{k}]);");
            }
        } else {
            write_loads(&mut s, &loads);
        }
        for &n in &sch.lets[r.clone()] {
            s.push_str("let ");
            w.name(n, &mut s);
            s.push_str(" = ");
            w.body(n, &mut s);
            s.push_str(";\n");
            // stored at once: held to the end of the chunk, the values spill
            if let Some(k) = slot[n.index()] {
                let _ = write!(s, "w[{k}] = ");
                w.stored(n, &mut s);
                s.push_str(";\n");
            }
        }
        let mut outs = Vec::new();
        for (i, &o) in sch.outputs.iter().enumerate() {
            if sch.output_chunk[i] as usize == c {
                let mut v = String::new();
                w.stored(o, &mut v);
                outs.push((i, v));
            }
        }
        if nchunks == 1 && sch.lets.len() <= BOUNDED_LETS {
            let stored = outs.iter().filter_map(|(i, _)| split_index(&targets[*i]));
            s.insert_str(0, &bounded(stored));
        }
        if let Some(stores) = &stores {
            stores.write(&mut s, outs, numbers);
        } else {
            for (i, v) in outs {
                let _ = writeln!(s, "{} {op} {v};", targets[i]);
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
            &[],
            false,
            &N,
            Numbers::Scalar,
        )
        .unwrap();
        assert_eq!(e.chunks.len(), 1);
        let code = &e.chunks[0];
        assert!(code.contains("let sin_q0 = q0.sin();"), "{code}");
        assert!(code.contains("out[0] = q1 - (q0 - q1) * sin_q0;"), "{code}");
        assert!(code.contains("out[1] = sin_q0;"), "{code}");
        // a short function checks its outputs' lengths once, at the top
        assert!(code.starts_with("let out = &mut out[..2];\n"), "{code}");
    }

    #[test]
    fn long_functions_check_lengths_at_their_stores() {
        let mut a = Arena::new();
        let mut e = a.var(Var::Q(0));
        let mut roots = Vec::new();
        for k in 0..2 * super::BOUNDED_LETS {
            let y = a.var(Var::Q(1 + k as u16 % 3));
            let s = a.sin(y);
            let sum = a.add(e, y);
            e = a.mul(sum, s);
            roots.push(e);
        }
        let sch = Schedule::new(&a, &roots);
        assert!(sch.lets.len() > super::BOUNDED_LETS);
        let targets: Vec<String> = (0..roots.len()).map(|i| format!("out[{i}]")).collect();
        let em = emit(&a, &sch, &targets, &[], false, &N, Numbers::Scalar).unwrap();
        assert!(!em.chunks[0].contains("&mut out[.."), "{}", em.chunks[0]);
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
            &[],
            false,
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
        let e = emit(&a, &sch, &targets, &[], false, &N, Numbers::Scalar).unwrap();
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
        let e = emit(&a, &sch, &targets, &[], false, &N, Numbers::Lanes).unwrap();
        let all = e.chunks.concat();
        // the state in a register, the parameter too (bound to its lanes by `bind_lanes`:
        // each lane's model's); functions through Math; outputs and the workspace as F64x4
        assert!(
            all.contains("let q0 = ::mbs::lanes::Simd::new(q0);"),
            "{all}"
        );
        assert!(
            all.contains("let p0 = ::mbs::lanes::Simd::new(p0);"),
            "{all}"
        );
        assert!(all.contains("::mbs::lanes::Math::sin("), "{all}");
        assert!(all.contains("::mbs::lanes::Math::pos("), "{all}");
        assert!(all.contains("out[0] = ::mbs::F64x4::from("), "{all}");
        assert!(all.contains("= ::mbs::lanes::Simd::new(w["), "{all}");
        assert!(all.contains("] = ::mbs::F64x4::from("), "{all}");
    }
    #[test]
    fn consecutive_stores_are_one_statement() {
        // m: four consecutive, given out of order; v (filled with zeros): gaps of one and two
        // zeros filled, not one of three; u (not filled): no gap filled; z alone (runs start
        // at three elements)
        let targets: Vec<String> = [
            "m[2]", "m[0]", "m[1]", "m[3]", "v[0]", "v[2]", "v[5]", "v[9]", "u[0]", "u[2]", "z",
        ]
        .iter()
        .map(|t| t.to_string())
        .collect();
        let zeroed = ["v".to_string()];
        let stores = super::Stores::new(&targets, &zeroed);
        let outs = (0..targets.len()).map(|i| (i, format!("a{i}"))).collect();
        let mut code = String::new();
        stores.write(&mut code, outs, Numbers::Scalar);
        let has = |s: &str| assert!(code.contains(s), "{s} in\n{code}");
        has("*::mbs::__private::array_mut(&mut m[0..4]) = [a1, a2, a0, a3];\n");
        has("*::mbs::__private::array_mut(&mut v[0..6]) = [a4, 0.0, a5, 0.0, 0.0, a6];\n");
        has("v[9] = a7;\n");
        has("u[0] = a8;\n");
        has("u[2] = a9;\n");
        has("z = a10;\n");
        assert_eq!(code.lines().count(), 6, "{code}");
    }

    #[test]
    fn a_function_of_one_chunk_stores_element_by_element() {
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let outs: Vec<_> = (0..6)
            .map(|i| {
                let c = a.num(i as f64 + 2.0);
                a.mul(c, x)
            })
            .collect();
        let sch = Schedule::new(&a, &outs);
        let targets: Vec<String> = (0..outs.len()).map(|i| format!("out[{i}]")).collect();
        let e = emit(&a, &sch, &targets, &[], false, &N, Numbers::Scalar).unwrap();
        assert!(
            e.chunks[0].contains("out[5] = 7.0 * q0;"),
            "{}",
            e.chunks[0]
        );
    }

    #[test]
    fn workspace_slots_are_loaded_in_runs() {
        // chunk 0 computes values that chunk 1 reads
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let mut vals = Vec::new();
        for i in 0..6 {
            let c = a.num(i as f64 + 2.0);
            let cx = a.mul(c, x);
            vals.push(a.sin(cx));
        }
        let mut outs = vals.clone();
        let mut acc = vals[0];
        for &v in &vals[1..] {
            acc = a.mul(acc, v);
            let s = a.sin(acc);
            acc = a.add(s, v);
        }
        outs.push(acc);
        let sch = Schedule::with_max_lets(&a, &outs, 6);
        assert!(sch.chunks.len() > 1);
        let targets: Vec<String> = (0..outs.len()).map(|i| format!("out[{i}]")).collect();
        let e = emit(&a, &sch, &targets, &[], false, &N, Numbers::Scalar).unwrap();
        // the values crossing the cut are read back as one slice pattern
        let later = e.chunks[1..].concat();
        let load = later
            .lines()
            .find(|l| l.contains("= w[0.."))
            .expect("a run of slots");
        let names = load.matches(", ").count() + 1;
        assert!(
            names > 1 && load.contains(&format!("] = w[0..{names}] else")),
            "{later}"
        );
    }
}
