//! A method written as a table of operations (`mbs::__private::tape`) that one loop of the
//! runtime reads: `option tangents = table;`. rustc then checks a byte string instead of one
//! statement per operation; the run reads every operation's slots from the table.

use super::function::{EmittedFn, FnSpec};
use crate::expr::emit::{Naming, Numbers, split_index};
use crate::expr::{Arena, ExprId, Func, Node, Var, ops_of_nodes};
use rustc_hash::{FxHashMap, FxHashSet};
use std::fmt::Write;

#[path = "../../../mbs-runtime/src/tape.rs"]
#[allow(dead_code)]
mod ops;

/// Slots a table may use: its array lives on the stack of the method (64 KiB).
const MAX_SLOTS: usize = 8192;

/// One operation of a table before its slots are chosen.
struct Instruction {
    op: u16,
    node: ExprId,
    operands: Vec<ExprId>,
    /// [`ops::POWI`]'s exponent
    immediate: Option<u16>,
}

/// The operation code of a function of one argument.
fn function_code(f: Func) -> u16 {
    let name = f.name();
    let k = ops::FUNCTIONS
        .iter()
        .position(|&n| n == name)
        .expect("every function has an operation");
    ops::SIN + k as u16
}

/// The outputs of a method as a table of operations.
struct Table {
    words: Vec<u16>,
    constants: Vec<f64>,
    /// the leaves, in their slots after the constants
    leaves: Vec<Var>,
    /// the outputs' buffers, by the number the stores give them
    buffers: Vec<String>,
    slots: usize,
    count: crate::expr::OpCount,
}

/// The method of `spec` as a table, or `None` when it cannot be one (user functions, splines,
/// lanes, more than [`MAX_SLOTS`] slots or an output index beyond `u16`): the caller then
/// emits straight-line code.
pub fn emit(arena: &Arena, spec: &FnSpec, names: &dyn Naming) -> Option<EmittedFn> {
    if spec.numbers != Numbers::Scalar || spec.prefix.is_some() {
        return None;
    }
    let t = table(arena, spec)?;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "#[inline(never)]\nfn {}(&self, {}) {{",
        spec.name, spec.args
    );
    for p in &spec.prelude {
        let _ = writeln!(s, "{p}");
    }
    for &v in &t.leaves {
        let b = names.bind(v);
        if !b.is_empty() {
            let _ = writeln!(s, "{b}");
        }
    }
    let _ = write!(s, "const CONSTANTS: [f64; {}] = [", t.constants.len());
    for c in &t.constants {
        let _ = write!(s, "{}, ", crate::expr::emit::literal(*c));
    }
    s.push_str("];\n// the operations: see `mbs::__private::tape`\nconst CODE: &[u8] = b\"");
    for byte in t.words.iter().flat_map(|w| w.to_le_bytes()) {
        match byte {
            0 => s.push_str("\\0"),
            b'0'..=b'9' | b'a'..=b'z' | b'A'..=b'Z' => s.push(byte as char),
            _ => {
                let _ = write!(s, "\\x{byte:02x}");
            }
        }
    }
    let _ = writeln!(
        s,
        "\";\nstatic WORDS: ::mbs::__private::tape::Words = ::mbs::__private::tape::Words::new();\nlet mut slots = [0.0f64; {}];",
        t.slots
    );
    let leaves: Vec<String> = t.leaves.iter().map(|&v| names.var(v)).collect();
    let outputs: Vec<String> = t.buffers.iter().map(|b| format!("&mut *{b}")).collect();
    let _ = writeln!(
        s,
        "::mbs::__private::tape::run(&WORDS, CODE, &CONSTANTS, &[{}], &mut slots, &mut [{}]);\n}}",
        leaves.join(", "),
        outputs.join(", ")
    );
    Some(EmittedFn {
        text: s,
        chunks: Vec::new(),
        count: t.count,
        prefix: None,
    })
}

/// The table of `spec`'s outputs (see [`emit`]).
fn table(arena: &Arena, spec: &FnSpec) -> Option<Table> {
    let roots: Vec<ExprId> = spec.outputs.iter().map(|o| o.1).collect();
    let order = arena.reachable(&roots);
    // the outputs' buffers, in order of first use, and each output's (buffer, index)
    let mut buffers: Vec<String> = Vec::new();
    let mut stores: FxHashMap<ExprId, Vec<(u16, u16)>> = FxHashMap::default();
    for (target, root) in &spec.outputs {
        let (base, index) = split_index(target)?;
        let index = u16::try_from(index).ok()?;
        let b = match buffers.iter().position(|x| x == base) {
            Some(b) => b,
            None => {
                buffers.push(base.to_string());
                buffers.len() - 1
            }
        };
        stores.entry(*root).or_default().push((b as u16, index));
    }
    // constants and leaves take the first slots
    let mut slot: FxHashMap<ExprId, u16> = FxHashMap::default();
    let mut constants: Vec<f64> = Vec::new();
    let mut leaves: Vec<Var> = Vec::new();
    for &n in &order {
        match arena.node(n) {
            Node::Num(b) => {
                slot.insert(n, constants.len() as u16);
                constants.push(f64::from_bits(b));
            }
            Node::Call(..) | Node::Spline(..) => return None,
            _ => {}
        }
    }
    for &n in &order {
        if let Node::Var(v) = arena.node(n) {
            slot.insert(n, (constants.len() + leaves.len()) as u16);
            leaves.push(v);
        }
    }
    let fixed = constants.len() + leaves.len();
    // a product read once, by a sum or a difference, is computed in it (`b c ± d`,
    // `b c ± d e`): fewer instructions, and fewer values through slots
    let mut readers: FxHashMap<ExprId, u32> = FxHashMap::default();
    for &n in &order {
        let (ch, m) = arena.node(n).children();
        for &c in &ch[..m] {
            *readers.entry(c).or_default() += 1;
        }
    }
    let product = |x: ExprId| match arena.node(x) {
        Node::Mul(b, c) if readers[&x] == 1 && !stores.contains_key(&x) => Some((b, c)),
        Node::Powi(b, 2) if readers[&x] == 1 && !stores.contains_key(&x) => Some((b, b)),
        _ => None,
    };
    let mut absorbed: FxHashSet<ExprId> = FxHashSet::default();
    for &n in &order {
        if let Node::Add(x, y) | Node::Sub(x, y) = arena.node(n)
            && x != y
        {
            for z in [x, y] {
                if product(z).is_some() {
                    absorbed.insert(z);
                }
            }
        }
    }
    // every operation as an instruction (operation, node, operands, immediate), grouped by
    // depth, then by operation; the stores of a depth's outputs after it
    let mut depth: FxHashMap<ExprId, u32> = FxHashMap::default();
    let mut by_depth: Vec<Vec<Instruction>> = Vec::new();
    for &n in &order {
        if absorbed.contains(&n) {
            continue;
        }
        let node = arena.node(n);
        let fused = |x: ExprId| product(x).filter(|_| absorbed.contains(&x));
        let (op, operands, immediate): (u16, Vec<ExprId>, Option<u16>) = match node {
            Node::Num(_) | Node::Var(_) | Node::Call(..) | Node::Spline(..) => continue,
            Node::Add(x, y) | Node::Sub(x, y) => {
                let add = matches!(node, Node::Add(..));
                match (fused(x), fused(y)) {
                    (Some((b, c)), Some((d, e))) => {
                        let op = if add { ops::DOT2 } else { ops::DIFF2 };
                        (op, vec![b, c, d, e], None)
                    }
                    (Some((b, c)), None) => {
                        let op = if add { ops::MULADD } else { ops::MULSUB };
                        (op, vec![b, c, y], None)
                    }
                    (None, Some((b, c))) => {
                        let op = if add { ops::MULADD } else { ops::SUBMUL };
                        (op, vec![b, c, x], None)
                    }
                    (None, None) => (if add { ops::ADD } else { ops::SUB }, vec![x, y], None),
                }
            }
            Node::Mul(x, y) => (ops::MUL, vec![x, y], None),
            Node::Div(x, y) => (ops::DIV, vec![x, y], None),
            Node::Pow(x, y) => (ops::POW, vec![x, y], None),
            Node::Atan2(x, y) => (ops::ATAN2, vec![x, y], None),
            Node::Neg(x) => (ops::NEG, vec![x], None),
            Node::Powi(x, 2) => (ops::MUL, vec![x, x], None),
            Node::Powi(x, e) => (ops::POWI, vec![x], Some(i16::try_from(e).ok()? as u16)),
            Node::Func(f, x) => (function_code(f), vec![x], None),
        };
        let d = 1 + operands
            .iter()
            .map(|x| depth.get(x).copied().unwrap_or(0))
            .max()
            .unwrap_or(0);
        depth.insert(n, d);
        if by_depth.len() < d as usize {
            by_depth.resize_with(d as usize, Vec::new);
        }
        by_depth[d as usize - 1].push(Instruction {
            op,
            node: n,
            operands,
            immediate,
        });
    }
    let store = if spec.accumulate {
        ops::STORE_ADD
    } else {
        ops::STORE
    };
    enum Item {
        Op(Instruction),
        Store(ExprId, u16, u16),
    }
    let mut items: Vec<Item> = Vec::new();
    let stores_of = |items: &mut Vec<Item>, nodes: &mut dyn Iterator<Item = ExprId>| {
        for n in nodes {
            for &(buf, i) in stores.get(&n).into_iter().flatten() {
                items.push(Item::Store(n, buf, i));
            }
        }
    };
    stores_of(
        &mut items,
        &mut order.iter().copied().filter(|n| !depth.contains_key(n)),
    );
    for mut level in by_depth {
        level.sort_by_key(|i| i.op);
        let nodes: Vec<ExprId> = level.iter().map(|i| i.node).collect();
        items.extend(level.into_iter().map(Item::Op));
        stores_of(&mut items, &mut nodes.into_iter());
    }
    // the last item that reads each value; slots given back after it
    let mut last: FxHashMap<ExprId, usize> = FxHashMap::default();
    for (k, item) in items.iter().enumerate() {
        match item {
            Item::Op(i) => {
                for &x in &i.operands {
                    last.insert(x, k);
                }
            }
            Item::Store(n, ..) => {
                last.insert(*n, k);
            }
        }
    }
    let mut free: Vec<u16> = Vec::new();
    let mut slots = fixed;
    let mut words: Vec<u16> = Vec::new();
    let mut batch_at = usize::MAX;
    let mut batch_op = u16::MAX;
    let release = |free: &mut Vec<u16>, slot: &FxHashMap<ExprId, u16>, x: ExprId, k| {
        if last.get(&x) == Some(&k) && slot[&x] as usize >= fixed {
            free.push(slot[&x]);
        }
    };
    for (k, item) in items.iter().enumerate() {
        let (op, instruction) = match item {
            Item::Op(i) => {
                let read: Vec<u16> = i.operands.iter().map(|x| slot[x]).collect();
                // an operand read twice by the instruction gives its slot back once
                for (j, &x) in i.operands.iter().enumerate() {
                    if !i.operands[..j].contains(&x) {
                        release(&mut free, &slot, x, k);
                    }
                }
                let a = free.pop().unwrap_or_else(|| {
                    slots += 1;
                    (slots - 1) as u16
                });
                slot.insert(i.node, a);
                let mut w = vec![a];
                w.extend(read);
                w.extend(i.immediate);
                (i.op, w)
            }
            Item::Store(n, buf, i) => {
                let sn = slot[n];
                release(&mut free, &slot, *n, k);
                (store, vec![*buf, sn, *i])
            }
        };
        debug_assert_eq!(instruction.len(), ops::words(op));
        if slots > MAX_SLOTS {
            return None;
        }
        if op != batch_op || words[batch_at + 1] == u16::MAX {
            batch_at = words.len();
            batch_op = op;
            words.extend([op, 0]);
        }
        words[batch_at + 1] += 1;
        words.extend(instruction);
    }
    let temporaries = slots - fixed;
    let mut count = ops_of_nodes(arena, &order);
    count.lets = temporaries;
    Some(Table {
        words,
        constants,
        leaves,
        buffers,
        slots,
        count,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::{Env, SliceEnv};

    /// Expressions of every operation a table has, fused and not, over four leaves.
    fn outputs(a: &mut Arena) -> Vec<ExprId> {
        let (x, y) = (a.var(Var::Q(0)), a.var(Var::Q(1)));
        let (v, p) = (a.var(Var::Qd(0)), a.var(Var::Param(0)));
        let mut out = Vec::new();
        let xy = a.mul(x, y);
        let vp = a.mul(v, p);
        // fused: b c + d e, b c − d e, b c + d, b c − d, d − b c
        out.push(a.add(xy, vp));
        let (xv, yp) = (a.mul(x, v), a.mul(y, p));
        out.push(a.sub(xv, yp));
        let xp = a.mul(x, p);
        out.push(a.add(xp, y));
        let yv = a.mul(y, v);
        out.push(a.sub(yv, x));
        let vx = a.add(v, x);
        let pv2 = a.mul(p, vx);
        out.push(a.sub(y, pv2));
        // a product read twice, and an output read by another: computed on their own
        let sx = a.sin(x);
        let twice = a.mul(sx, y);
        let s1 = a.add(twice, v);
        out.push(a.mul(s1, twice));
        out.push(xy);
        for f in Func::ALL {
            let xv = a.add(x, v);
            let arg = a.scale(0.3, xv);
            out.push(a.func(f, arg));
        }
        for n in [2, 3, -2] {
            out.push(a.powi(y, n));
        }
        let py = a.add(p, y);
        let d = a.div(x, py);
        let neg = a.neg(d);
        let pw = a.pow(p, y);
        out.push(a.sub(neg, pw));
        out.push(a.atan2(y, x));
        // a leaf and a constant as outputs
        out.push(v);
        out.push(a.num(2.5));
        out
    }

    struct Names;

    impl Naming for Names {
        fn var(&self, v: Var) -> String {
            format!("{v}")
        }
        fn bind(&self, v: Var) -> String {
            format!("let {v} = 0.0;")
        }
    }

    /// The table of [`outputs`], output i in `k[3 i]` (even i) or `c[3 i]` (odd i).
    fn spread_table() -> (Arena, Vec<ExprId>, Table) {
        let mut a = Arena::new();
        let out = outputs(&mut a);
        let mut spec = FnSpec::new("__f", "k: &mut [f64], c: &mut [f64]");
        for (i, &e) in out.iter().enumerate() {
            let target = if i % 2 == 0 { "k" } else { "c" };
            spec.outputs.push((format!("{target}[{}]", 3 * i), e));
        }
        let t = table(&a, &spec).expect("a table");
        (a, out, t)
    }

    #[test]
    fn a_table_computes_what_its_expressions_are() {
        let (a, out, t) = spread_table();
        assert_eq!(t.buffers, ["k", "c"]);
        for (q, qd, p) in [([0.3, -0.7], [0.45], [1.7]), ([1.1, -0.2], [-0.3], [0.6])] {
            let env = SliceEnv {
                q: &q,
                qd: &qd,
                params: &p,
                ..Default::default()
            };
            let want = a.eval(&out, &env);
            let leaves: Vec<f64> = t.leaves.iter().map(|&v| env.var(v)).collect();
            let mut slots = vec![0.0; t.slots];
            let (mut k, mut c) = (vec![f64::NAN; 3 * out.len()], vec![f64::NAN; 3 * out.len()]);
            let code: Vec<u8> = t.words.iter().flat_map(|w| w.to_le_bytes()).collect();
            ops::run(
                &ops::Words::new(),
                &code,
                &t.constants,
                &leaves,
                &mut slots,
                &mut [&mut k, &mut c],
            );
            for (i, w) in want.iter().enumerate() {
                let got = if i % 2 == 0 { k[3 * i] } else { c[3 * i] };
                assert!(
                    w.is_finite() && (got - w).abs() <= 1e-15 * w.abs().max(1.0),
                    "output {i}: {got} against {w}"
                );
            }
        }
    }

    #[test]
    fn products_read_once_are_fused_into_their_sums() {
        let (_, _, t) = spread_table();
        let mut fused = 0;
        let mut at = 0;
        while at < t.words.len() {
            let (op, n) = (t.words[at], t.words[at + 1] as usize);
            if (ops::MULADD..=ops::DIFF2).contains(&op) {
                fused += n;
            }
            at += 2 + ops::words(op) * n;
        }
        // the five sums of products above, and none of the products read twice
        assert_eq!(fused, 5);
    }

    #[test]
    fn user_functions_and_lanes_keep_straight_line_code() {
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let f = a.user_fn(crate::expr::UserFn {
            name: "g".into(),
            paths: vec!["g0".into()],
        });
        let g = a.call(f, 0, x);
        let mut spec = FnSpec::new("__f", "k: &mut [f64]");
        spec.outputs.push(("k[0]".into(), g));
        assert!(emit(&a, &spec, &Names).is_none());
        let mut lanes = FnSpec::lanes("__f", "k: &mut [f64]");
        lanes.outputs.push(("k[0]".into(), x));
        assert!(emit(&a, &lanes, &Names).is_none());
        spec.outputs[0].1 = a.sin(x);
        let e = emit(&a, &spec, &Names).expect("a table");
        assert!(e.text.contains("::mbs::__private::tape::run(&WORDS, CODE"));
        assert_eq!(e.count.funcs, 1);
    }
}
