//! `contact(point, k = …[, c = …][, mu = …][, eps = …][, plane = …][, offset = …]
//! [, sphere = r | ellipsoid = (a, b, c)][, exponent = e][, dissipation = d])`: penalty
//! contact of a point, or a sphere or ellipsoid centred at it, with a world plane.

use super::*;

const CONTACT_USAGE: &str = "contact(point, k = …[, c = …][, mu = …])";

pub(super) const KIND: Kind = Kind {
    name: "contact",
    named: &[
        "k",
        "c",
        "mu",
        "eps",
        "plane",
        "offset",
        "sphere",
        "ellipsoid",
        "exponent",
        "dissipation",
    ],
    lower: |c, s| c.lower_contact(s).into_iter().collect(),
};

impl Checker {
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
    fn lower_contact(&mut self, s: &EffectStmt) -> Option<Load> {
        let named = |key: &str| named(s, key);
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
        let ellipsoid = match named("ellipsoid") {
            Some(e) => {
                if named("sphere").is_some() {
                    let key = &s.named.iter().find(|(k, _)| k == "ellipsoid").unwrap().0;
                    self.error(
                        key.span(),
                        "a contact is a sphere or an ellipsoid, not both: keep `sphere = r` or `ellipsoid = (a, b, c)`",
                    );
                }
                let axes = self.triple(
                    e,
                    param("the semi-axes of a contact ellipsoid"),
                    "the `ellipsoid` of a contact (its semi-axes)",
                );
                for v in axes.iter().flatten() {
                    self.positive(*v, e, "a semi-axis of a contact `ellipsoid`");
                }
                Some(axes)
            }
            None => None,
        };
        let exponent = match named("exponent") {
            Some(e) => {
                let v = self.lower(e, param("the exponent of a contact force"));
                match self.sys.arena.as_num(v) {
                    Some(x) if x >= 1.0 => {}
                    Some(x) => self.error_at(
                        e,
                        format!("the `exponent` of a contact must be at least 1 (1 linear, 1.5 Hertz), it is {x}: a smaller one makes the force's slope infinite at first touch"),
                    ),
                    None => self.error_at(
                        e,
                        format!("the `exponent` of a contact is a number known when the model is generated, found `{}`: write its value (1 linear, 1.5 Hertz)", text(e)),
                    ),
                }
                v
            }
            None => self.sys.arena.one(),
        };
        let dissipation = coef(
            self,
            "dissipation",
            "a Hunt–Crossley dissipation",
            "the Hunt–Crossley `dissipation` of a contact",
        );
        let normal = match named("plane") {
            Some(e) => self.plane_normal(e),
            None => {
                let (z, o) = (self.sys.arena.zero(), self.sys.arena.one());
                Some([z, z, o])
            }
        };
        let ellipsoid = match ellipsoid {
            Some(axes) => Some(axes?),
            None => None,
        };
        Some(Load::Contact {
            at: at?,
            radius,
            ellipsoid,
            exponent,
            dissipation,
            normal: normal?,
            offset,
            k: k?,
            c,
            mu,
            eps,
        })
    }
}
