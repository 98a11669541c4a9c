//! Canonicalising constructors. Every node enters the arena through these, so the arena only
//! holds canonical forms:
//! - constants are folded; 0 and 1 are absorbed;
//! - a number is the first operand of a commutative node, other operands are ordered by id;
//! - products carry at most one positive numeric factor, in front (`Mul(Num c, x)`, c > 0);
//! - signs float outwards (`Neg` above `Mul`/`Div`/odd functions) and are absorbed by
//!   `Add`/`Sub`: `a + (-b)` is `a - b`, `-(a - b)` is `b - a`;
//! - like terms merge: `c1·x + c2·x` is `(c1 + c2)·x`, `x - x` is 0;
//! - `pos` and `step` absorb each other and positive factors: `pos(pos x)` is `pos x`,
//!   `step(pos x)` is `step x`, `pos(c·x)` is `c·pos x` and `step(c·x)` is `step x` (c > 0).
//!
//! Each rule strictly shrinks or reorders, so construction terminates.

use super::{Arena, ExprId, Func, Node};

impl Arena {
    /// `c·x` in canonical form.
    pub fn scale(&mut self, c: f64, x: ExprId) -> ExprId {
        let cx = self.num(c);
        self.mul(cx, x)
    }

    /// Splits `e` as coefficient × term: `-x` → (-1, x), `c·x` → (c, x), `-(c·x)` → (-c, x).
    fn split_coef(&self, e: ExprId) -> (f64, ExprId) {
        match self.node(e) {
            Node::Neg(x) => match self.node(x) {
                Node::Mul(a, b) if self.as_num(a).is_some() => (-self.as_num(a).unwrap(), b),
                _ => (-1.0, x),
            },
            Node::Mul(a, b) if self.as_num(a).is_some() => (self.as_num(a).unwrap(), b),
            _ => (1.0, e),
        }
    }

    fn ordered(&self, a: ExprId, b: ExprId) -> (ExprId, ExprId) {
        let an = self.as_num(a).is_some();
        let bn = self.as_num(b).is_some();
        if bn && !an || (an == bn && b < a) {
            (b, a)
        } else {
            (a, b)
        }
    }

    pub fn add(&mut self, a: ExprId, b: ExprId) -> ExprId {
        if let (Some(x), Some(y)) = (self.as_num(a), self.as_num(b)) {
            return self.num(x + y);
        }
        if self.is_num(a, 0.0) {
            return b;
        }
        if self.is_num(b, 0.0) {
            return a;
        }
        let (ca, ta) = self.split_coef(a);
        let (cb, tb) = self.split_coef(b);
        if ta == tb {
            return self.scale(ca + cb, ta);
        }
        match (self.node(a), self.node(b)) {
            (Node::Neg(x), Node::Neg(y)) => {
                let s = self.add(x, y);
                return self.neg(s);
            }
            (_, Node::Neg(y)) => return self.sub(a, y),
            (Node::Neg(x), _) => return self.sub(b, x),
            _ => {}
        }
        let (a, b) = self.ordered(a, b);
        // fold a number into a sum that already starts with one
        if let Some(c) = self.as_num(a) {
            match self.node(b) {
                Node::Add(x, y) if self.as_num(x).is_some() => {
                    let s = self.num(c + self.as_num(x).unwrap());
                    return self.add(s, y);
                }
                Node::Sub(x, y) if self.as_num(x).is_some() => {
                    let s = self.num(c + self.as_num(x).unwrap());
                    return self.sub(s, y);
                }
                _ => {}
            }
        }
        self.intern(Node::Add(a, b))
    }

    pub fn sub(&mut self, a: ExprId, b: ExprId) -> ExprId {
        if let (Some(x), Some(y)) = (self.as_num(a), self.as_num(b)) {
            return self.num(x - y);
        }
        if self.is_num(b, 0.0) {
            return a;
        }
        if self.is_num(a, 0.0) {
            return self.neg(b);
        }
        if a == b {
            return self.zero();
        }
        let (ca, ta) = self.split_coef(a);
        let (cb, tb) = self.split_coef(b);
        if ta == tb {
            return self.scale(ca - cb, ta);
        }
        if let Node::Neg(y) = self.node(b) {
            return self.add(a, y);
        }
        if let Node::Neg(x) = self.node(a) {
            let s = self.add(x, b);
            return self.neg(s);
        }
        if let Some(c) = self.as_num(b) {
            let m = self.num(-c);
            return self.add(m, a);
        }
        self.intern(Node::Sub(a, b))
    }

    pub fn neg(&mut self, a: ExprId) -> ExprId {
        match self.node(a) {
            Node::Num(b) => self.num(-f64::from_bits(b)),
            Node::Neg(x) => x,
            Node::Sub(x, y) => self.sub(y, x),
            _ => self.intern(Node::Neg(a)),
        }
    }

    pub fn mul(&mut self, a: ExprId, b: ExprId) -> ExprId {
        if let (Some(x), Some(y)) = (self.as_num(a), self.as_num(b)) {
            return self.num(x * y);
        }
        let (a, b) = self.ordered(a, b);
        if let Some(c) = self.as_num(a) {
            if c == 0.0 {
                return self.zero();
            }
            if c == 1.0 {
                return b;
            }
            if c == -1.0 {
                return self.neg(b);
            }
            match self.node(b) {
                Node::Neg(y) => {
                    let p = self.mul(a, y);
                    return self.neg(p);
                }
                Node::Mul(d, y) if self.as_num(d).is_some() => {
                    let cd = self.num(c * self.as_num(d).unwrap());
                    return self.mul(cd, y);
                }
                Node::Div(d, y) if self.as_num(d).is_some() => {
                    let cd = self.num(c * self.as_num(d).unwrap());
                    return self.div(cd, y);
                }
                _ => {}
            }
            if c < 0.0 {
                let p = self.scale(-c, b);
                return self.neg(p);
            }
            return self.intern(Node::Mul(a, b));
        }
        match (self.node(a), self.node(b)) {
            (Node::Neg(x), Node::Neg(y)) => return self.mul(x, y),
            (Node::Neg(x), _) => {
                let p = self.mul(x, b);
                return self.neg(p);
            }
            (_, Node::Neg(y)) => {
                let p = self.mul(a, y);
                return self.neg(p);
            }
            _ => {}
        }
        // numeric factors float to the front of a product
        let (ca, ta) = self.split_coef(a);
        let (cb, tb) = self.split_coef(b);
        if ca != 1.0 || cb != 1.0 {
            let p = self.mul(ta, tb);
            return self.scale(ca * cb, p);
        }
        self.intern(Node::Mul(a, b))
    }

    pub fn div(&mut self, a: ExprId, b: ExprId) -> ExprId {
        if self.is_num(b, 1.0) {
            return a;
        }
        if self.is_num(a, 0.0) {
            return self.zero();
        }
        if let (Some(x), Some(y)) = (self.as_num(a), self.as_num(b)) {
            return self.num(x / y);
        }
        if a == b {
            return self.one();
        }
        if let Node::Neg(x) = self.node(a) {
            let q = self.div(x, b);
            return self.neg(q);
        }
        if let Node::Neg(y) = self.node(b) {
            let q = self.div(a, y);
            return self.neg(q);
        }
        if let Some(c) = self.as_num(b) {
            return self.scale(1.0 / c, a);
        }
        if let Node::Mul(c, x) = self.node(a) {
            if let Some(cv) = self.as_num(c) {
                let q = self.div(x, b);
                return self.scale(cv, q);
            }
        }
        self.intern(Node::Div(a, b))
    }

    /// `x^n` for an integer n.
    pub fn powi(&mut self, x: ExprId, n: i32) -> ExprId {
        match n {
            0 => return self.one(),
            1 => return x,
            _ => {}
        }
        if let Some(v) = self.as_num(x) {
            return self.num(v.powi(n));
        }
        if n < 0 {
            let p = self.powi(x, -n);
            let one = self.one();
            return self.div(one, p);
        }
        if let Node::Neg(y) = self.node(x) {
            let p = self.powi(y, n);
            return if n % 2 == 0 { p } else { self.neg(p) };
        }
        if let Node::Powi(y, m) = self.node(x) {
            return self.powi(y, m * n);
        }
        self.intern(Node::Powi(x, n))
    }

    /// `x^y` for a real exponent; integer constant exponents become [`Arena::powi`].
    pub fn pow(&mut self, x: ExprId, y: ExprId) -> ExprId {
        if let Some(e) = self.as_num(y) {
            if e.fract() == 0.0 && e.abs() <= 64.0 {
                return self.powi(x, e as i32);
            }
            if e == 0.5 {
                return self.func(Func::Sqrt, x);
            }
        }
        if let (Some(a), Some(b)) = (self.as_num(x), self.as_num(y)) {
            return self.num(a.powf(b));
        }
        self.intern(Node::Pow(x, y))
    }

    pub fn func(&mut self, f: Func, x: ExprId) -> ExprId {
        if let Some(v) = self.as_num(x) {
            return self.num(f.apply(v));
        }
        // positive part and step of a non-negative or 0/1-valued argument, and of c·x (c > 0)
        if let Node::Func(g, y) = self.node(x) {
            match (f, g) {
                // pos(pos y) = pos y, pos(step y) = step y, step(step y) = step y
                (Func::Pos, Func::Pos | Func::Step) | (Func::Step, Func::Step) => return x,
                // step(pos y) = step y
                (Func::Step, Func::Pos) => return self.func(Func::Step, y),
                _ => {}
            }
        }
        if let Node::Mul(c, y) = self.node(x) {
            if let Some(c) = self.as_num(c).filter(|c| *c > 0.0 && c.is_finite()) {
                // canonical products carry c > 0: pos(c y) = c pos(y), step(c y) = step(y)
                match f {
                    Func::Pos => {
                        let p = self.func(Func::Pos, y);
                        return self.scale(c, p);
                    }
                    Func::Step => return self.func(Func::Step, y),
                    _ => {}
                }
            }
        }
        if let Node::Neg(y) = self.node(x) {
            match f {
                Func::Sin
                | Func::Tan
                | Func::Asin
                | Func::Atan
                | Func::Sinh
                | Func::Tanh
                | Func::Sign => {
                    let r = self.func(f, y);
                    return self.neg(r);
                }
                Func::Cos | Func::Cosh | Func::Abs => return self.func(f, y),
                _ => {}
            }
        }
        self.intern(Node::Func(f, x))
    }

    pub fn sin(&mut self, x: ExprId) -> ExprId {
        self.func(Func::Sin, x)
    }

    pub fn cos(&mut self, x: ExprId) -> ExprId {
        self.func(Func::Cos, x)
    }

    pub fn sqrt(&mut self, x: ExprId) -> ExprId {
        self.func(Func::Sqrt, x)
    }

    /// `atan2(y, x)`.
    pub fn atan2(&mut self, y: ExprId, x: ExprId) -> ExprId {
        if let (Some(a), Some(b)) = (self.as_num(y), self.as_num(x)) {
            return self.num(a.atan2(b));
        }
        self.intern(Node::Atan2(y, x))
    }

    /// Derivative number `order` of user function `f` at `x`.
    pub fn call(&mut self, f: u16, order: u8, x: ExprId) -> ExprId {
        self.intern(Node::Call(f, order, x))
    }

    /// Sum of many terms (0 when empty).
    pub fn sum(&mut self, terms: impl IntoIterator<Item = ExprId>) -> ExprId {
        let mut acc = self.zero();
        for t in terms {
            acc = self.add(acc, t);
        }
        acc
    }

    /// Σ a_i b_i.
    pub fn dot(&mut self, a: &[ExprId], b: &[ExprId]) -> ExprId {
        let mut acc = self.zero();
        for (&x, &y) in a.iter().zip(b) {
            let p = self.mul(x, y);
            acc = self.add(acc, p);
        }
        acc
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Arena, Node, Var};

    #[test]
    fn zeros_ones_and_signs_fold() {
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let y = a.var(Var::Q(1));
        let z = a.zero();
        let one = a.one();
        assert_eq!(a.add(x, z), x);
        assert_eq!(a.mul(x, one), x);
        assert_eq!(a.mul(x, z), z);
        let nx = a.neg(x);
        assert_eq!(a.neg(nx), x);
        assert_eq!(a.add(x, nx), z);
        let s = a.sub(x, y);
        let ns = a.neg(s);
        assert_eq!(a.node(ns), Node::Sub(y, x));
        let ny = a.neg(y);
        assert_eq!(a.add(x, ny), s);
        let p = a.mul(nx, ny);
        let q = a.mul(x, y);
        assert_eq!(p, q);
    }

    #[test]
    fn like_terms_and_coefficients_merge() {
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let y = a.var(Var::Q(1));
        let two = a.num(2.0);
        let three = a.num(3.0);
        let x2 = a.mul(two, x);
        let x3 = a.mul(x, three);
        let s = a.add(x2, x3);
        assert_eq!(a.node(s), Node::Mul(a.num(5.0), x));
        let d = a.sub(x2, x2);
        assert!(a.is_num(d, 0.0));
        // 2 * (3 * (x * y)) → 6 * (x * y)
        let xy = a.mul(x, y);
        let t = a.mul(three, xy);
        let u = a.mul(two, t);
        assert_eq!(a.node(u), Node::Mul(a.num(6.0), xy));
        // (2x)(3y) → 6 (x y)
        let y3 = a.mul(three, y);
        let v = a.mul(x2, y3);
        assert_eq!(v, u);
        // commutative canonical order
        assert_eq!(a.mul(y, x), a.mul(x, y));
        assert_eq!(a.add(y, x), a.add(x, y));
    }

    #[test]
    fn positive_part_and_step_fold() {
        use super::super::{Func, SliceEnv};
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let m = a.num(-2.5);
        let r = a.func(Func::Pos, m);
        assert!(a.is_num(r, 0.0));
        let three = a.num(3.0);
        let r = a.func(Func::Pos, three);
        assert!(a.is_num(r, 3.0));
        let r = a.func(Func::Step, m);
        assert!(a.is_num(r, 0.0));
        let r = a.func(Func::Step, three);
        assert!(a.is_num(r, 1.0));
        let z = a.zero();
        let r = a.func(Func::Step, z);
        assert!(a.is_num(r, 0.0), "step(0) = 0");
        let p = a.func(Func::Pos, x);
        let s = a.func(Func::Step, x);
        for (f, arg, want) in [
            (Func::Pos, p, p),
            (Func::Pos, s, s),
            (Func::Step, s, s),
            (Func::Step, p, s),
        ] {
            let r = a.func(f, arg);
            assert_eq!(r, want, "{f:?}");
        }
        // positive factors come out of pos and vanish in step
        let x3 = a.mul(three, x);
        let p3 = a.func(Func::Pos, x3);
        let want = a.scale(3.0, p);
        assert_eq!(p3, want);
        let s3 = a.func(Func::Step, x3);
        assert_eq!(s3, s);
        // a negated argument stays inside: pos(−x) is not −pos(x)
        let nx = a.neg(x);
        let pn = a.func(Func::Pos, nx);
        assert_eq!(a.node(pn), Node::Func(Func::Pos, nx));
        for (xv, want) in [
            (-1.5, [0.0, 0.0, 1.5]),
            (0.0, [0.0, 0.0, 0.0]),
            (2.0, [2.0, 1.0, 0.0]),
        ] {
            let q = [xv];
            let env = SliceEnv {
                q: &q,
                ..SliceEnv::default()
            };
            assert_eq!(a.eval(&[p, s, pn], &env), want.to_vec(), "x = {xv}");
        }
    }

    #[test]
    fn negative_coefficients_become_neg() {
        let mut a = Arena::new();
        let x = a.var(Var::Q(0));
        let m = a.num(-2.0);
        let p = a.mul(m, x);
        match a.node(p) {
            Node::Neg(inner) => assert_eq!(a.node(inner), Node::Mul(a.num(2.0), x)),
            other => panic!("expected Neg, got {other:?}"),
        }
    }
}
