//! Storage: nodes in creation order, a hash map for hash-consing, and per-node dependency masks.

use super::{ExprId, Node, SplineTable, UserFn, Var, num_bits};
use rustc_hash::FxHashMap;

/// A hash-consed expression arena: structurally equal nodes get the same id, so common
/// subexpressions are shared by construction.
#[derive(Clone, Debug)]
pub struct Arena {
    nodes: Vec<Node>,
    /// conservative mask of the variables each node depends on (see [`Var::mask`])
    deps: Vec<u128>,
    /// open-addressing table of node ids by hash (hash-consing); `u32::MAX` is empty
    slots: Vec<u32>,
    /// memo of derivatives: (node, direction) packed by [`Dir::key`] -> derivative
    pub(super) dmemo: FxHashMap<u64, ExprId>,
    pub(super) user_fns: Vec<UserFn>,
    pub(super) splines: Vec<SplineTable>,
    /// while set, a product of a value of parameters alone (computed once per call) keeps
    /// that value's coefficient with it (`Arena::mul`)
    pub(crate) keep_fixed: bool,
}

/// Direction of differentiation.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub(crate) enum Dir {
    /// partial derivative with respect to one variable
    Partial(Var),
    /// total time derivative: q → qd, qd → qdd, t → 1
    Time,
    /// total time derivative at zero acceleration: q → qd, qd → 0, t → 1
    TimeBias,
}

impl Dir {
    /// The memo key of (node, direction).
    pub(super) fn key(self, n: ExprId) -> u64 {
        let d: u64 = match self {
            Dir::Partial(v) => var_code(v),
            // beyond every variable's code (kinds 0..=8 in bits 16..): no direction shares a key
            Dir::Time => 9 << 16,
            Dir::TimeBias => 10 << 16,
        };
        d << 32 | n.0 as u64
    }
}

fn var_code(v: Var) -> u64 {
    match v {
        Var::Q(i) => i as u64,
        Var::Qd(i) => 1 << 16 | i as u64,
        Var::Qdd(i) => 2 << 16 | i as u64,
        Var::T => 3 << 16,
        Var::Param(i) => 4 << 16 | i as u64,
        Var::Input(i) => 5 << 16 | i as u64,
        Var::Lambda(i) => 6 << 16 | i as u64,
        Var::Chart(i) => 7 << 16 | i as u64,
        Var::Force(i) => 8 << 16 | i as u64,
    }
}

impl Default for Arena {
    fn default() -> Self {
        Self::new()
    }
}

impl Arena {
    pub fn new() -> Self {
        let mut a = Arena {
            nodes: Vec::with_capacity(1 << 16),
            deps: Vec::with_capacity(1 << 16),
            slots: vec![u32::MAX; 1 << 17],
            dmemo: FxHashMap::default(),
            user_fns: Vec::new(),
            splines: Vec::new(),
            keep_fixed: false,
        };
        let z = a.intern(Node::Num(num_bits(0.0)));
        let o = a.intern(Node::Num(num_bits(1.0)));
        debug_assert!(z == ExprId(0) && o == ExprId(1));
        a
    }

    /// The constant 0 (always id 0).
    pub fn zero(&self) -> ExprId {
        ExprId(0)
    }

    /// The constant 1 (always id 1).
    pub fn one(&self) -> ExprId {
        ExprId(1)
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The node behind an id.
    pub fn node(&self, id: ExprId) -> Node {
        self.nodes[id.index()]
    }

    /// Value of a constant node.
    pub fn as_num(&self, id: ExprId) -> Option<f64> {
        // a node on variables is not a number (cheap test first: this is called by every rule)
        if self.deps[id.index()] != 0 {
            return None;
        }
        match self.nodes[id.index()] {
            Node::Num(b) => Some(f64::from_bits(b)),
            _ => None,
        }
    }

    /// True when the node is the constant `v`.
    pub fn is_num(&self, id: ExprId, v: f64) -> bool {
        self.as_num(id) == Some(v)
    }

    /// False only when `id` certainly does not depend on `v`.
    pub fn may_depend(&self, id: ExprId, v: Var) -> bool {
        self.deps[id.index()] & v.mask() != 0
    }

    /// False only when `id` certainly depends on none of q, qd, qdd, t, inputs.
    pub(crate) fn mask(&self, id: ExprId) -> u128 {
        self.deps[id.index()]
    }

    /// True when `id` depends on parameters at most: a value computed once per call.
    pub(crate) fn is_fixed(&self, id: ExprId) -> bool {
        self.deps[id.index()] & !Var::PARAM_BITS == 0
    }

    /// True when the expression is a constant number.
    pub fn is_const(&self, id: ExprId) -> bool {
        self.deps[id.index()] == 0
    }

    /// Registers a user function and returns its number.
    pub fn user_fn(&mut self, f: UserFn) -> u16 {
        register(&mut self.user_fns, f)
    }

    pub fn user_fns(&self) -> &[UserFn] {
        &self.user_fns
    }

    /// Registers a spline and returns its number (equal tables share one).
    pub fn spline_table(&mut self, s: SplineTable) -> u16 {
        register(&mut self.splines, s)
    }

    /// The splines of the model, by number.
    pub fn splines(&self) -> &[SplineTable] {
        &self.splines
    }

    /// Inserts a node as is (no rules): callers are the canonicalising constructors.
    pub(super) fn intern(&mut self, n: Node) -> ExprId {
        let mask = self.slots.len() - 1;
        let mut i = node_hash(&n) as usize & mask;
        loop {
            let s = self.slots[i];
            if s == u32::MAX {
                break;
            }
            if self.nodes[s as usize] == n {
                return ExprId(s);
            }
            i = (i + 1) & mask;
        }
        let id = ExprId(self.nodes.len() as u32);
        let (ch, k) = n.children();
        let mut mask_deps = match n {
            Node::Var(v) => v.mask(),
            _ => 0,
        };
        for c in &ch[..k] {
            mask_deps |= self.deps[c.index()];
        }
        self.nodes.push(n);
        self.deps.push(mask_deps);
        self.slots[i] = id.0;
        if self.nodes.len() * 2 > self.slots.len() {
            self.grow();
        }
        id
    }

    /// Doubles the table and re-inserts every node.
    fn grow(&mut self) {
        let size = self.slots.len() * 2;
        self.slots = vec![u32::MAX; size];
        let mask = size - 1;
        for (id, n) in self.nodes.iter().enumerate() {
            let mut i = node_hash(n) as usize & mask;
            while self.slots[i] != u32::MAX {
                i = (i + 1) & mask;
            }
            self.slots[i] = id as u32;
        }
    }

    /// The variable node.
    pub fn var(&mut self, v: Var) -> ExprId {
        self.intern(Node::Var(v))
    }

    /// A constant.
    pub fn num(&mut self, v: f64) -> ExprId {
        self.intern(Node::Num(num_bits(v)))
    }

    /// All nodes reachable from `roots`, in increasing id (topological) order: a depth-first
    /// walk over a bitmap, then the visited ids in order (a sort when they are few, a scan of
    /// the bitmap otherwise).
    pub fn reachable(&self, roots: &[ExprId]) -> Vec<ExprId> {
        let Some(top) = roots.iter().max() else {
            return Vec::new();
        };
        let mut seen = vec![0u64; top.index() / 64 + 1];
        let mut stack: Vec<u32> = roots.iter().map(|r| r.0).collect();
        let mut out: Vec<ExprId> = Vec::new();
        while let Some(n) = stack.pop() {
            let (w, b) = (n as usize / 64, 1u64 << (n % 64));
            if seen[w] & b != 0 {
                continue;
            }
            seen[w] |= b;
            out.push(ExprId(n));
            let (ch, k) = self.nodes[n as usize].children();
            for c in &ch[..k] {
                stack.push(c.0);
            }
        }
        if out.len() * 16 < top.index() {
            out.sort_unstable();
            return out;
        }
        out.clear();
        for (w, &bits) in seen.iter().enumerate() {
            let mut x = bits;
            while x != 0 {
                out.push(ExprId((w * 64) as u32 + x.trailing_zeros()));
                x &= x - 1;
            }
        }
        out
    }

    /// The variables that the expressions depend on (exactly, by traversal), sorted.
    pub fn vars_of(&self, roots: &[ExprId]) -> Vec<Var> {
        let mut vs: Vec<Var> = self
            .reachable(roots)
            .into_iter()
            .filter_map(|n| match self.node(n) {
                Node::Var(v) => Some(v),
                _ => None,
            })
            .collect();
        vs.sort_unstable();
        vs.dedup();
        vs
    }
}

/// The number of `x` in `list`, pushed there unless an equal entry is there already.
fn register<T: PartialEq>(list: &mut Vec<T>, x: T) -> u16 {
    match list.iter().position(|y| *y == x) {
        Some(i) => i as u16,
        None => {
            list.push(x);
            (list.len() - 1) as u16
        }
    }
}

/// A cheap hash of a node, written out so that it stays fast without optimisation (the
/// proc-macro runs at opt-level 0).
fn node_hash(n: &Node) -> u64 {
    let (tag, a, b): (u64, u64, u64) = match *n {
        Node::Num(bits) => (1, bits, 0),
        Node::Var(v) => (2, var_code(v), 0),
        Node::Add(x, y) => (3, x.0 as u64, y.0 as u64),
        Node::Sub(x, y) => (4, x.0 as u64, y.0 as u64),
        Node::Mul(x, y) => (5, x.0 as u64, y.0 as u64),
        Node::Div(x, y) => (6, x.0 as u64, y.0 as u64),
        Node::Neg(x) => (7, x.0 as u64, 0),
        Node::Powi(x, k) => (8, x.0 as u64, k as u64),
        Node::Pow(x, y) => (9, x.0 as u64, y.0 as u64),
        Node::Func(f, x) => (10 + f as u64 * 16, x.0 as u64, 0),
        Node::Atan2(x, y) => (11, x.0 as u64, y.0 as u64),
        Node::Call(f, o, x) => (12 + ((f as u64) << 8 | o as u64) * 16, x.0 as u64, 0),
        Node::Spline(s, o, x) => (13 + ((s as u64) << 8 | o as u64) * 16, x.0 as u64, 0),
    };
    let h = (tag ^ a.wrapping_mul(0x9E3779B97F4A7C15)).wrapping_mul(0xff51afd7ed558ccd)
        ^ b.wrapping_mul(0xc4ceb9fe1a85ec53);
    h ^ (h >> 29)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every direction has its own memo key: the time directions' once equalled those of
    /// ∂/∂chart(0) and ∂/∂force(0).
    #[test]
    fn directions_have_distinct_memo_keys() {
        let n = ExprId(5);
        let mut keys = vec![Dir::Time.key(n), Dir::TimeBias.key(n)];
        for i in [0u16, 1, 300] {
            for v in [
                Var::Q(i),
                Var::Qd(i),
                Var::Qdd(i),
                Var::Param(i),
                Var::Input(i),
                Var::Lambda(i),
                Var::Chart(i),
                Var::Force(i),
            ] {
                keys.push(Dir::Partial(v).key(n));
            }
        }
        keys.push(Dir::Partial(Var::T).key(n));
        let all = keys.len();
        keys.sort_unstable();
        keys.dedup();
        assert_eq!(keys.len(), all);
    }
}
