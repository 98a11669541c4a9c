//! Force elements: penalty contacts with a world plane and six-axis bushings between frames.

use super::*;

const CONTACT_USAGE: &str = "contact(point, k = …[, c = …][, mu = …])";
const BUSHING_USAGE: &str = "bushing(A, B, k = (kx, ky, kz), kr = (…), c = (…), cr = (…))";

impl Checker {
    /// Reports `value` (on `at`) unless it is positive with the default parameters.
    fn positive(&mut self, value: ExprId, at: &Expr, what: &str) {
        if let Some(v) = self.eval_default(value) {
            if v.is_nan() || v <= 0.0 {
                let how = self.with_defaults(value);
                self.error_at(
                    at,
                    format!("{what} must be positive, it is {v}{how}: give a value > 0"),
                );
            }
        }
    }

    /// The unit normal of a contact plane: `x`, `y`, `z` (optionally negated) or `(nx, ny, nz)`.
    fn plane_normal(&mut self, e: &Expr) -> Option<[ExprId; 3]> {
        let z = self.sys.arena.zero();
        let o = self.sys.arena.one();
        let m = self.sys.arena.num(-1.0);
        let axis = |e: &Expr| match e {
            Expr::Path(p) if p.path.is_ident("x") => Some(0),
            Expr::Path(p) if p.path.is_ident("y") => Some(1),
            Expr::Path(p) if p.path.is_ident("z") => Some(2),
            _ => None,
        };
        if let Some(k) = axis(e) {
            let mut n = [z; 3];
            n[k] = o;
            return Some(n);
        }
        if let Expr::Unary(u) = e {
            if let (syn::UnOp::Neg(_), Some(k)) = (u.op, axis(&u.expr)) {
                let mut n = [z; 3];
                n[k] = m;
                return Some(n);
            }
        }
        match e {
            Expr::Paren(p) => self.plane_normal(&p.expr),
            Expr::Tuple(_) => {
                let n = self.triple(
                    e,
                    Allow {
                        what: "the normal of a contact plane",
                        ..PARAMS_ONLY
                    },
                    "the normal of a contact plane",
                )?;
                self.unit_axis(
                    &n,
                    &e.to_token_stream(),
                    "the normal of a contact plane",
                    "contact(point, k = …, plane = (nx, ny, nz))",
                )
                .then_some(n)
            }
            _ => {
                self.error_at(
                    e,
                    format!(
                        "unknown contact plane `{}`: give its unit normal, pointing out of the ground: `plane = z`, `y`, `x` (or `-z`, …) or `(nx, ny, nz)`",
                        text(e)
                    ),
                );
                None
            }
        }
    }

    /// `contact(point, k = …, c = …, mu = …, eps = …, plane = …, offset = …, sphere = …)`.
    pub(super) fn lower_contact(&mut self, s: &EffectStmt) -> Option<Load> {
        let named = |key: &str| s.named.iter().find(|(k, _)| k == key).map(|(_, v)| v);
        if s.positional.len() != 1 {
            self.error(
                s.kind.span(),
                format!(
                    "`contact` takes 1 positional argument (the point or body that touches the ground plane), found {}: write `{CONTACT_USAGE}`",
                    s.positional.len()
                ),
            );
            return None;
        }
        let at = self.attach(&s.positional[0]);
        if let Some(Attach { frame: None, .. }) = at {
            let what = match text(&s.positional[0]) {
                g if g == "ground" => "the ground cannot touch its own plane".to_string(),
                p => format!("`{p}` is fixed to the ground, so it never touches the ground plane"),
            };
            self.error_at(
                &s.positional[0],
                format!("{what}: a contact belongs to a point or body that moves"),
            );
            return None;
        }
        let param = |what: &'static str| Allow {
            what,
            ..PARAMS_ONLY
        };
        let k = match named("k") {
            Some(e) => {
                let k = self.lower(e, param("a contact stiffness"));
                self.positive(k, e, "the stiffness `k` of a contact");
                Some(k)
            }
            None => {
                self.error(
                    s.kind.span(),
                    format!("a contact needs its stiffness: add `k = …`, as in `{CONTACT_USAGE}`"),
                );
                None
            }
        };
        let coef = |c: &mut Checker, key: &str, what: &'static str, check: &str| match named(key) {
            Some(e) => {
                let v = c.lower(e, param(what));
                c.not_negative(v, e, check);
                v
            }
            None => c.sys.arena.zero(),
        };
        let c = coef(
            self,
            "c",
            "a contact damping",
            "the damping coefficient `c` of a contact",
        );
        let mu = coef(
            self,
            "mu",
            "a friction coefficient",
            "the friction coefficient `mu` of a contact",
        );
        let eps = match named("eps") {
            Some(e) => {
                if named("mu").is_none() {
                    let key = &s.named.iter().find(|(k, _)| k == "eps").unwrap().0;
                    self.error(
                        key.span(),
                        "`eps` regularises the friction, and this contact has none: add `mu = …` (the friction coefficient) or remove `eps`",
                    );
                }
                let v = self.lower(e, param("a friction regularisation"));
                self.positive(v, e, "the friction regularisation `eps` of a contact");
                v
            }
            None => self.sys.arena.num(1e-4),
        };
        let offset = match named("offset") {
            Some(e) => self.lower(e, param("the offset of a contact plane")),
            None => self.sys.arena.zero(),
        };
        let radius = match named("sphere") {
            Some(e) => {
                let r = self.lower(e, param("a sphere radius"));
                self.positive(r, e, "the radius `sphere` of a contact");
                r
            }
            None => self.sys.arena.zero(),
        };
        let normal = match named("plane") {
            Some(e) => self.plane_normal(e),
            None => {
                let (z, o) = (self.sys.arena.zero(), self.sys.arena.one());
                Some([z, z, o])
            }
        };
        Some(Load::Contact {
            at: at?,
            radius,
            normal: normal?,
            offset,
            k: k?,
            c,
            mu,
            eps,
        })
    }

    /// A bushing's coefficients: `(x, y, z)` in A's axes, or one value for the three axes.
    fn bushing_coefs(&mut self, e: &Expr, key: &str) -> Option<[ExprId; 3]> {
        let what = match key {
            "k" => "a bushing stiffness",
            "kr" => "a bushing rotational stiffness",
            "c" => "a bushing damping",
            _ => "a bushing rotational damping",
        };
        let a = Allow {
            what,
            ..PARAMS_ONLY
        };
        let check = |c: &mut Checker, v: ExprId, at: &Expr| {
            c.not_negative(v, at, &format!("each coefficient of `{key}` of a bushing"));
        };
        match e {
            Expr::Paren(p) => self.bushing_coefs(&p.expr, key),
            Expr::Tuple(t) if t.elems.len() == 3 => {
                let v = self.triple(e, a, what)?;
                for (x, el) in v.iter().zip(&t.elems) {
                    check(self, *x, el);
                }
                Some(v)
            }
            Expr::Tuple(t) => {
                self.error_at(
                    e,
                    format!(
                        "`{key}` of a bushing is three values `(x, y, z)` along A's axes, or one value for all three, found {} values",
                        t.elems.len()
                    ),
                );
                None
            }
            _ => {
                let v = self.lower(e, a);
                check(self, v, e);
                Some([v; 3])
            }
        }
    }

    /// `bushing(A, B, k = …, kr = …, c = …, cr = …)`.
    pub(super) fn lower_bushing(&mut self, s: &EffectStmt) -> Option<Load> {
        if s.positional.len() != 2 {
            self.error(
                s.kind.span(),
                format!(
                    "`bushing` joins two bodies or frames, found {}: write `{BUSHING_USAGE}`",
                    count(s.positional.len(), "positional argument")
                ),
            );
            return None;
        }
        let fa = self.ident_body_ref(&s.positional[0]);
        let fb = self.ident_body_ref(&s.positional[1]);
        let mut coefs = [None; 4];
        let mut bad = false;
        for (i, key) in ["k", "kr", "c", "cr"].into_iter().enumerate() {
            if let Some((_, e)) = s.named.iter().find(|(k, _)| k == key) {
                coefs[i] = self.bushing_coefs(e, key);
                bad |= coefs[i].is_none();
            }
        }
        let (fa, fb) = (fa?, fb?);
        if fa == fb {
            let msg = if fa.is_none() {
                "a bushing between the ground and itself never deforms: join a body or frame to the ground or to another body".to_string()
            } else {
                format!(
                    "this bushing joins `{}` to itself, so it never deforms: join two different bodies or frames (or one and `ground`)",
                    text(&s.positional[0])
                )
            };
            self.error_at(&range(&s.positional[0], &s.positional[1]), msg);
            return None;
        }
        if coefs.iter().all(Option::is_none) && !bad {
            self.error(
                s.kind.span(),
                format!(
                    "a bushing needs a stiffness or a damping: add `k = …`, `kr = …`, `c = …` or `cr = …`, as in `{BUSHING_USAGE}`"
                ),
            );
            return None;
        }
        if bad {
            return None;
        }
        let z = [self.sys.arena.zero(); 3];
        let [k, kr, c, cr] = coefs.map(|v| v.unwrap_or(z));
        Some(Load::Bushing {
            a: fa,
            b: fb,
            k,
            kr,
            c,
            cr,
        })
    }
}
