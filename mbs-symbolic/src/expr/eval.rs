//! Numeric evaluation of DAG nodes, used by tests and by the checker (parameter defaults).

use super::{Arena, ExprId, Node, Var};

/// Values of the leaves, and user functions.
pub trait Env {
    fn var(&self, v: Var) -> f64;
    /// Derivative number `order` of user function `f` at `x`. Models without user functions
    /// never call it.
    fn call(&self, f: u16, order: u8, x: f64) -> f64 {
        let _ = (f, order, x);
        f64::NAN
    }
}

/// An [`Env`] over slices; missing entries read as 0.
#[derive(Clone, Copy, Default, Debug)]
pub struct SliceEnv<'a> {
    pub t: f64,
    pub q: &'a [f64],
    pub qd: &'a [f64],
    pub qdd: &'a [f64],
    pub params: &'a [f64],
    pub u: &'a [f64],
    pub lambda: &'a [f64],
    /// the charts of rotation joints, 9 entries each (row-major); missing entries read as
    /// the identity's
    pub charts: &'a [f64],
}

impl Env for SliceEnv<'_> {
    fn var(&self, v: Var) -> f64 {
        let get = |s: &[f64], i: u16| s.get(i as usize).copied().unwrap_or(0.0);
        match v {
            Var::Q(i) => get(self.q, i),
            Var::Qd(i) => get(self.qd, i),
            Var::Qdd(i) => get(self.qdd, i),
            Var::T => self.t,
            Var::Param(i) => get(self.params, i),
            Var::Input(i) => get(self.u, i),
            Var::Lambda(i) => get(self.lambda, i),
            Var::Chart(i) => match self.charts.get(i as usize) {
                Some(&v) => v,
                // the identity: entries 0, 4 and 8 of each 3 × 3 block are 1
                None => f64::from(u8::from(i % 9 % 4 == 0)),
            },
            // no generalised force added from outside the model
            Var::Force(_) => 0.0,
        }
    }
}

impl Arena {
    /// Values of `roots`, evaluating each needed node once.
    pub fn eval(&self, roots: &[ExprId], env: &dyn Env) -> Vec<f64> {
        let order = self.reachable(roots);
        let mut val = vec![0.0; order.last().map_or(0, |n| n.index() + 1)];
        for n in order {
            let g = |c: ExprId| val[c.index()];
            let v = match self.node(n) {
                Node::Num(b) => f64::from_bits(b),
                Node::Var(v) => env.var(v),
                Node::Add(a, b) => g(a) + g(b),
                Node::Sub(a, b) => g(a) - g(b),
                Node::Mul(a, b) => g(a) * g(b),
                Node::Div(a, b) => g(a) / g(b),
                Node::Neg(a) => -g(a),
                Node::Powi(a, k) => g(a).powi(k),
                Node::Pow(a, b) => g(a).powf(g(b)),
                Node::Func(f, a) => f.apply(g(a)),
                Node::Atan2(y, x) => g(y).atan2(g(x)),
                Node::Call(f, k, a) => env.call(f, k, g(a)),
                Node::Spline(s, k, a) => self.splines()[s as usize].eval(k, g(a)),
            };
            val[n.index()] = v;
        }
        roots.iter().map(|r| val[r.index()]).collect()
    }
}
