//! `bushing(A, B, k = …, kr = …, c = …, cr = …)`: six-axis linear spring–damper between two
//! frames (or a frame and the ground).

use super::*;

const BUSHING_USAGE: &str = "bushing(A, B, k = (kx, ky, kz), kr = (…), c = (…), cr = (…))";

pub(super) const KIND: Kind = Kind {
    name: "bushing",
    named: &["k", "kr", "c", "cr"],
    lower: |c, s| c.lower_bushing(s).into_iter().collect(),
};

impl Checker {
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
    fn lower_bushing(&mut self, s: &EffectStmt) -> Option<Load> {
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
