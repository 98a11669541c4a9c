//! Storage: nodes in creation order, a hash map for hash-consing, and per-node dependency masks.

use super::{ExprId, Node, UserFn, Var, num_bits};
use rustc_hash::FxHashMap;

/// A hash-consed expression arena: structurally equal nodes get the same id, so common
/// subexpressions are shared by construction.
#[derive(Clone, Debug)]
pub struct Arena {
    nodes: Vec<Node>,
    /// conservative mask of the variables each node depends on (see [`Var::mask`])
    deps: Vec<u128>,
    interned: FxHashMap<Node, ExprId>,
    /// memo of derivatives: (node, direction) -> derivative
    pub(super) dmemo: FxHashMap<(ExprId, Dir), ExprId>,
    pub(super) user_fns: Vec<UserFn>,
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

impl Default for Arena {
    fn default() -> Self {
        Self::new()
    }
}

impl Arena {
    pub fn new() -> Self {
        let mut a = Arena {
            nodes: Vec::with_capacity(1 << 12),
            deps: Vec::with_capacity(1 << 12),
            interned: FxHashMap::default(),
            dmemo: FxHashMap::default(),
            user_fns: Vec::new(),
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

    /// True when the expression is a constant number.
    pub fn is_const(&self, id: ExprId) -> bool {
        self.deps[id.index()] == 0
    }

    /// Registers a user function and returns its number.
    pub fn user_fn(&mut self, f: UserFn) -> u16 {
        if let Some(i) = self.user_fns.iter().position(|g| *g == f) {
            return i as u16;
        }
        self.user_fns.push(f);
        (self.user_fns.len() - 1) as u16
    }

    pub fn user_fns(&self) -> &[UserFn] {
        &self.user_fns
    }

    /// Inserts a node as is (no rules): callers are the canonicalising constructors.
    pub(super) fn intern(&mut self, n: Node) -> ExprId {
        if let Some(&id) = self.interned.get(&n) {
            return id;
        }
        let id = ExprId(self.nodes.len() as u32);
        let (ch, k) = n.children();
        let mut mask = match n {
            Node::Var(v) => v.mask(),
            _ => 0,
        };
        for c in &ch[..k] {
            mask |= self.deps[c.index()];
        }
        self.nodes.push(n);
        self.deps.push(mask);
        self.interned.insert(n, id);
        id
    }

    /// The variable node.
    pub fn var(&mut self, v: Var) -> ExprId {
        self.intern(Node::Var(v))
    }

    /// A constant.
    pub fn num(&mut self, v: f64) -> ExprId {
        self.intern(Node::Num(num_bits(v)))
    }

    /// All nodes reachable from `roots`, in increasing id (topological) order. Children have
    /// smaller ids than parents, so one backward sweep marks everything.
    pub fn reachable(&self, roots: &[ExprId]) -> Vec<ExprId> {
        let Some(top) = roots.iter().max() else {
            return Vec::new();
        };
        let mut need = vec![false; top.index() + 1];
        for r in roots {
            need[r.index()] = true;
        }
        for i in (0..need.len()).rev() {
            if need[i] {
                let (ch, k) = self.nodes[i].children();
                for c in &ch[..k] {
                    need[c.index()] = true;
                }
            }
        }
        (0..need.len())
            .filter(|&i| need[i])
            .map(|i| ExprId(i as u32))
            .collect()
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
