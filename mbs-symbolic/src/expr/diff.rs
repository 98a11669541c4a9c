//! Forward-mode differentiation on the DAG, memoised per (node, direction), and substitution.
//! Both walk the sub-DAG iteratively (no recursion), so deep chains cannot overflow the stack.

use super::arena::Dir;
use super::{Arena, ExprId, Func, Node, Var};
use rustc_hash::FxHashMap;

impl Arena {
    /// ∂e/∂v.
    pub fn diff(&mut self, e: ExprId, v: Var) -> ExprId {
        self.derive(e, Dir::Partial(v))
    }

    /// Total time derivative along the motion: d/dt with q̇ = qd, q̈d = qdd, ṫ = 1; parameters
    /// and inputs are constant. Used for velocities and accelerations of positions.
    pub fn dt(&mut self, e: ExprId) -> ExprId {
        self.derive(e, Dir::Time)
    }

    /// Total time derivative with the accelerations set to zero: the "bias" part of d/dt.
    /// For a velocity ė(q, qd, t) it is ë at qdd = 0 (J̇·qd plus rheonomic terms).
    pub fn dt_bias(&mut self, e: ExprId) -> ExprId {
        self.derive(e, Dir::TimeBias)
    }

    /// True when the derivative in this direction is certainly zero.
    fn constant_along(&self, e: ExprId, dir: Dir) -> bool {
        match dir {
            Dir::Partial(v) => !self.may_depend(e, v),
            // parameters and inputs are constant in time: bits 0..=120 are q, qd, qdd and t
            Dir::Time | Dir::TimeBias => self.mask(e) & ((1u128 << 121) - 1) == 0,
        }
    }

    fn derive(&mut self, root: ExprId, dir: Dir) -> ExprId {
        if self.constant_along(root, dir) {
            return self.zero();
        }
        if let Some(&d) = self.dmemo.get(&dir.key(root)) {
            return d;
        }
        let mut stack = vec![(root, false)];
        while let Some((n, expanded)) = stack.pop() {
            if self.dmemo.contains_key(&dir.key(n)) {
                continue;
            }
            let (ch, k) = self.node(n).children();
            if !expanded {
                stack.push((n, true));
                for &c in &ch[..k] {
                    if !self.constant_along(c, dir) && !self.dmemo.contains_key(&dir.key(c)) {
                        stack.push((c, false));
                    }
                }
                continue;
            }
            let d = self.derive_node(n, dir);
            self.dmemo.insert(dir.key(n), d);
        }
        self.dmemo[&dir.key(root)]
    }

    /// Derivative of one node, its children's derivatives being known.
    fn derive_node(&mut self, n: ExprId, dir: Dir) -> ExprId {
        let d = |a: &Arena, c: ExprId| -> ExprId {
            if a.constant_along(c, dir) {
                a.zero()
            } else {
                a.dmemo[&dir.key(c)]
            }
        };
        match self.node(n) {
            Node::Num(_) => self.zero(),
            Node::Var(v) => match dir {
                Dir::Partial(w) => {
                    if v == w {
                        self.one()
                    } else {
                        self.zero()
                    }
                }
                Dir::Time | Dir::TimeBias => match v {
                    Var::Q(i) => self.var(Var::Qd(i)),
                    Var::Qd(i) if dir == Dir::Time => self.var(Var::Qdd(i)),
                    Var::Qd(_) => self.zero(),
                    Var::T => self.one(),
                    // jerk, parameters and inputs: never differentiated in time by the
                    // generator (the checker keeps inputs and velocities out of positions);
                    // a chart is constant between re-centrings
                    Var::Qdd(_)
                    | Var::Param(_)
                    | Var::Input(_)
                    | Var::Lambda(_)
                    | Var::Chart(_)
                    | Var::Force(_) => self.zero(),
                },
            },
            Node::Add(a, b) => {
                let (da, db) = (d(self, a), d(self, b));
                self.add(da, db)
            }
            Node::Sub(a, b) => {
                let (da, db) = (d(self, a), d(self, b));
                self.sub(da, db)
            }
            Node::Neg(a) => {
                let da = d(self, a);
                self.neg(da)
            }
            Node::Mul(a, b) => {
                let (da, db) = (d(self, a), d(self, b));
                let x = self.mul(da, b);
                let y = self.mul(a, db);
                self.add(x, y)
            }
            Node::Div(a, b) => {
                // (a/b)' = a'/b - (a/b) b'/b
                let (da, db) = (d(self, a), d(self, b));
                let x = self.div(da, b);
                let y = self.mul(n, db);
                let y = self.div(y, b);
                self.sub(x, y)
            }
            Node::Powi(a, k) => {
                let da = d(self, a);
                let p = self.powi(a, k - 1);
                let p = self.scale(k as f64, p);
                self.mul(p, da)
            }
            Node::Pow(a, b) => {
                let (da, db) = (d(self, a), d(self, b));
                if db == self.zero() {
                    // (a^b)' = b a^(b−1) a' for an exponent constant in this direction: no
                    // ln a and no division by a, so a = 0 (pos(δ)^1.5 out of contact) gives 0;
                    // below 1 the power is infinite there, so it is taken off the kink
                    let one = self.one();
                    let e = self.sub(b, one);
                    let base = if self.as_num(b).is_some_and(|b| b >= 1.0) {
                        a
                    } else {
                        self.off_the_kink(a)
                    };
                    let p = self.pow(base, e);
                    let p = self.mul(b, p);
                    return self.mul(p, da);
                }
                // (a^b)' = a^b (b' ln a + b a'/a), a taken off the kink of a positive part
                let a_off = self.off_the_kink(a);
                let la = self.func(Func::Ln, a_off);
                let x = self.mul(db, la);
                let y = self.mul(b, da);
                let y = self.div(y, a_off);
                let s = self.add(x, y);
                self.mul(n, s)
            }
            Node::Func(f, a) => {
                let da = d(self, a);
                let fp = self.func_derivative(f, a, n);
                self.mul(fp, da)
            }
            Node::Atan2(y, x) => {
                // (x y' - y x') / (x² + y²)
                let (dy, dx) = (d(self, y), d(self, x));
                let p = self.mul(x, dy);
                let q = self.mul(y, dx);
                let num = self.sub(p, q);
                let x2 = self.powi(x, 2);
                let y2 = self.powi(y, 2);
                let den = self.add(x2, y2);
                self.div(num, den)
            }
            Node::Call(f, k, a) => {
                let da = d(self, a);
                let c = self.call(f, k + 1, a);
                self.mul(c, da)
            }
            Node::Spline(s, k, a) => {
                let da = d(self, a);
                let c = self.spline(s, k + 1, a);
                self.mul(c, da)
            }
        }
    }

    /// `a`, or where `a` is a positive part pos(u) (or c·pos(u)), pos(u) + 1 − step(u): equal
    /// to it where u > 0, 1 where u ≤ 0; where `a` is |u| (or c·|u|), |u| + 1 − sign(u)²:
    /// equal to it where u ≠ 0, 1 where u = 0. The factor of a chain rule that is infinite at
    /// 0 (0.5/√a, a^(b−1) with b < 1, ln a, 1/a) then stays finite where pos(u) or |u| is 0,
    /// and is multiplied there by the derivative of pos(u), step(u)·u' = 0, or of |u|,
    /// sign(u)·u' = 0: the derivative is 0 where inf·0 gave NaN (√pos(x), pos(δ)^b with
    /// b < 1, the second derivatives of pos(δ)^1.5 out of contact, √|v|, |v|^b).
    ///
    /// A product or quotient with such a factor (`c·pos(u)`, `pos(u)/v0`, `k·c·|u|`, the
    /// other factors numbers, parameters or anything else) is taken off the kink in that
    /// factor: √(|v|/v0) with a parameter v0 gave NaN at v = 0 where √|v| gives 0.
    fn off_the_kink(&mut self, a: ExprId) -> ExprId {
        let (at_kink, u) = match self.node(a) {
            Node::Func(Func::Pos, u) => (Func::Step, u),
            Node::Func(Func::Abs, u) => (Func::Sign, u),
            Node::Mul(x, y) => {
                let y_off = self.off_the_kink(y);
                if y_off != y {
                    return self.mul(x, y_off);
                }
                let x_off = self.off_the_kink(x);
                return if x_off != x { self.mul(x_off, y) } else { a };
            }
            Node::Div(x, y) => {
                let x_off = self.off_the_kink(x);
                return if x_off != x { self.div(x_off, y) } else { a };
            }
            _ => return a,
        };
        let one = self.one();
        // 1 − step(u), or 1 − sign(u)²: 1 at the kink (and below it, for pos)
        let k = self.func(at_kink, u);
        let k = if at_kink == Func::Sign {
            self.powi(k, 2)
        } else {
            k
        };
        let lift = self.sub(one, k);
        self.add(a, lift)
    }

    /// f'(a) where `fa` = f(a).
    fn func_derivative(&mut self, f: Func, a: ExprId, fa: ExprId) -> ExprId {
        let one = self.one();
        match f {
            Func::Sin => self.cos(a),
            Func::Cos => {
                let s = self.sin(a);
                self.neg(s)
            }
            Func::Tan => {
                let t2 = self.powi(fa, 2);
                self.add(one, t2)
            }
            Func::Asin | Func::Acos => {
                let a2 = self.powi(a, 2);
                let r = self.sub(one, a2);
                let r = self.sqrt(r);
                let inv = self.div(one, r);
                if f == Func::Asin { inv } else { self.neg(inv) }
            }
            Func::Atan => {
                let a2 = self.powi(a, 2);
                let r = self.add(one, a2);
                self.div(one, r)
            }
            Func::Sinh => self.func(Func::Cosh, a),
            Func::Cosh => self.func(Func::Sinh, a),
            Func::Tanh => {
                let t2 = self.powi(fa, 2);
                self.sub(one, t2)
            }
            Func::Exp => fa,
            Func::Ln => self.div(one, a),
            Func::Sqrt => {
                let h = self.num(0.5);
                let off = self.off_the_kink(a);
                let root = if off == a {
                    fa
                } else {
                    self.func(Func::Sqrt, off)
                };
                self.div(h, root)
            }
            Func::Abs => self.func(Func::Sign, a),
            Func::Pos => self.func(Func::Step, a),
            Func::Sign | Func::Step => self.zero(),
        }
    }

    /// Replaces variables by expressions everywhere below `roots`; returns the new roots.
    pub fn substitute(&mut self, roots: &[ExprId], map: &FxHashMap<Var, ExprId>) -> Vec<ExprId> {
        let mut memo: FxHashMap<ExprId, ExprId> = FxHashMap::default();
        let touched = map.keys().fold(0u128, |m, v| m | v.mask());
        for n in self.reachable(roots) {
            if self.mask(n) & touched == 0 {
                continue;
            }
            let r = |m: &FxHashMap<ExprId, ExprId>, c: ExprId| *m.get(&c).unwrap_or(&c);
            let new = match self.node(n) {
                Node::Num(_) => n,
                Node::Var(v) => *map.get(&v).unwrap_or(&n),
                Node::Add(a, b) => self.add(r(&memo, a), r(&memo, b)),
                Node::Sub(a, b) => self.sub(r(&memo, a), r(&memo, b)),
                Node::Mul(a, b) => self.mul(r(&memo, a), r(&memo, b)),
                Node::Div(a, b) => self.div(r(&memo, a), r(&memo, b)),
                Node::Neg(a) => self.neg(r(&memo, a)),
                Node::Powi(a, k) => self.powi(r(&memo, a), k),
                Node::Pow(a, b) => self.pow(r(&memo, a), r(&memo, b)),
                Node::Func(f, a) => self.func(f, r(&memo, a)),
                Node::Atan2(a, b) => self.atan2(r(&memo, a), r(&memo, b)),
                Node::Call(f, k, a) => self.call(f, k, r(&memo, a)),
                Node::Spline(s, k, a) => self.spline(s, k, r(&memo, a)),
            };
            memo.insert(n, new);
        }
        roots.iter().map(|r| *memo.get(r).unwrap_or(r)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Arena, SliceEnv, Var};

    fn central(f: impl Fn(f64) -> f64, x: f64) -> f64 {
        let h = 1e-6;
        (f(x + h) - f(x - h)) / (2.0 * h)
    }

    #[test]
    fn derivatives_match_central_differences() {
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let y = a.var(Var::Q(1));
        // f = atan2(y, x) * sqrt(1 + x²) + tanh(x y) / (2 + cos x) + asin(x/3) + powi(y, 3)
        let one = a.one();
        let two = a.num(2.0);
        let three = a.num(3.0);
        let at = a.atan2(y, x);
        let x2 = a.powi(x, 2);
        let r = a.add(one, x2);
        let r = a.sqrt(r);
        let t1 = a.mul(at, r);
        let xy = a.mul(x, y);
        let th = a.func(super::Func::Tanh, xy);
        let cx = a.cos(x);
        let den = a.add(two, cx);
        let t2 = a.div(th, den);
        let x3 = a.div(x, three);
        let t3 = a.func(super::Func::Asin, x3);
        let t4 = a.powi(y, 3);
        let f = a.sum([t1, t2, t3, t4]);
        let dfx = a.diff(f, Var::Q(0));
        let dfy = a.diff(f, Var::Q(1));
        let (x0, y0) = (0.7, -0.4);
        let val = |a: &Arena, e, xv: f64, yv: f64| {
            let env = SliceEnv {
                q: &[xv, yv],
                ..SliceEnv::default()
            };
            a.eval(&[e], &env)[0]
        };
        let num_x = central(|xv| val(&a, f, xv, y0), x0);
        let num_y = central(|yv| val(&a, f, x0, yv), y0);
        assert!((val(&a, dfx, x0, y0) - num_x).abs() < 1e-8);
        assert!((val(&a, dfy, x0, y0) - num_y).abs() < 1e-8);
    }

    #[test]
    fn positive_part_and_step_derivatives() {
        use super::Func;
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let y = a.var(Var::Qd(0));
        // f = pos(x² − y) · step(x) + pos(y)
        let x2 = a.powi(x, 2);
        let d = a.sub(x2, y);
        let p = a.func(Func::Pos, d);
        let s = a.func(Func::Step, x);
        let ps = a.mul(p, s);
        let py = a.func(Func::Pos, y);
        let f = a.add(ps, py);
        let dfx = a.diff(f, Var::Q(0));
        let dfy = a.diff(f, Var::Qd(0));
        // d pos(u) = step(u) du; d step = 0
        assert_eq!(a.diff(s, Var::Q(0)), a.zero());
        let su = a.func(Func::Step, d);
        let want = a.diff(d, Var::Q(0));
        let want = a.mul(su, want);
        assert_eq!(a.diff(p, Var::Q(0)), want);
        let val = |a: &Arena, e, xv: f64, yv: f64| {
            let env = SliceEnv {
                q: &[xv],
                qd: &[yv],
                ..SliceEnv::default()
            };
            a.eval(&[e], &env)[0]
        };
        // away from the kinks, on each side of them
        for (x0, y0) in [
            (0.9, 0.3),
            (0.9, -0.3),
            (-0.4, 0.5),
            (0.3, 0.5),
            (-0.8, -0.2),
        ] {
            let num_x = central(|xv| val(&a, f, xv, y0), x0);
            let num_y = central(|yv| val(&a, f, x0, yv), y0);
            assert!((val(&a, dfx, x0, y0) - num_x).abs() < 1e-8, "({x0}, {y0})");
            assert!((val(&a, dfy, x0, y0) - num_y).abs() < 1e-8, "({x0}, {y0})");
        }
    }

    #[test]
    fn time_derivative_follows_the_motion() {
        let mut a = Arena::new();
        let q = a.var(Var::Q(0));
        let t = a.var(Var::T);
        let s = a.sin(q);
        let f = a.mul(s, t); // t sin q
        let df = a.dt(f); // sin q + t cos q qd
        let ddf = a.dt(df);
        let env = SliceEnv {
            q: &[0.3],
            qd: &[1.1],
            qdd: &[-0.5],
            t: 2.0,
            ..SliceEnv::default()
        };
        let v = a.eval(&[df, ddf], &env);
        let (q0, qd0, qdd0, t0): (f64, f64, f64, f64) = (0.3, 1.1, -0.5, 2.0);
        assert!((v[0] - (q0.sin() + t0 * q0.cos() * qd0)).abs() < 1e-14);
        let expect = 2.0 * q0.cos() * qd0 - t0 * q0.sin() * qd0 * qd0 + t0 * q0.cos() * qdd0;
        assert!((v[1] - expect).abs() < 1e-14);
    }

    #[test]
    fn substitution_specialises() {
        let mut a = Arena::new();
        let q = a.var(Var::Q(0));
        let qd = a.var(Var::Qd(0));
        let s = a.sin(q);
        let p = a.mul(s, qd);
        let f = a.add(p, q);
        let mut m = rustc_hash::FxHashMap::default();
        m.insert(Var::Qd(0), a.zero());
        let g = a.substitute(&[f], &m)[0];
        assert_eq!(g, q);
    }
}
