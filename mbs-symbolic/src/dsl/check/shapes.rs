//! `shape` statements: what to draw with a body, a frame or the ground. Their values are
//! constants, numbers or parameters taken at their defaults.

use super::*;

/// The shapes and how each is written, for messages.
const SHAPES: [(&str, &str); 4] = [
    ("box", "box(lx, ly, lz)"),
    ("cylinder", "cylinder(radius, length, axis = z)"),
    ("sphere", "sphere(radius)"),
    ("line", "line(from = (x, y, z), to = (x, y, z))"),
];

impl Checker {
    pub(super) fn lower_shape(&mut self, body: &Ident, s: &EffectStmt) {
        let frame = self.body_ref(&BodyRef::Name(body.clone()));
        let kind = s.kind.to_string();
        let Some(&(_, usage)) = SHAPES.iter().find(|(k, _)| *k == kind) else {
            let known = SHAPES.map(|(k, _)| k);
            self.error(
                s.kind.span(),
                format!(
                    "unknown shape `{kind}`{}",
                    did_you_mean(
                        &kind,
                        known.into_iter(),
                        "the shapes are box(lx, ly, lz), cylinder(radius, length), sphere(radius) and line(from = …, to = …)"
                    )
                ),
            );
            return;
        };
        let known_named: &[&str] = match kind.as_str() {
            "box" | "sphere" => &["at", "color"],
            "cylinder" => &["axis", "at", "color"],
            _ => &["from", "to", "color"],
        };
        let before = self.errors.len();
        for (i, (k, _)) in s.named.iter().enumerate() {
            if s.named[..i].iter().any(|(j, _)| j == k) {
                self.error(
                    k.span(),
                    format!("argument `{k}` is given twice: remove one"),
                );
            } else if !known_named.contains(&k.to_string().as_str()) {
                let (init, last) = known_named.split_at(known_named.len() - 1);
                let list = init
                    .iter()
                    .map(|a| format!("`{a}`"))
                    .collect::<Vec<_>>()
                    .join(", ");
                self.error(
                    k.span(),
                    format!(
                        "`{kind}` has no argument `{k}`{}",
                        did_you_mean(
                            &k.to_string(),
                            known_named.iter().copied(),
                            &format!("its named arguments are {list} and `{}`", last[0])
                        )
                    ),
                );
            }
        }
        let npos = match kind.as_str() {
            "box" => 3,
            "cylinder" => 2,
            "sphere" => 1,
            _ => 0,
        };
        if s.positional.len() != npos {
            let takes = if npos == 0 {
                "no positional argument".to_string()
            } else {
                count(npos, "positional argument")
            };
            self.error(
                s.kind.span(),
                format!(
                    "`{kind}` takes {takes}, found {}: write `{usage}`",
                    s.positional.len()
                ),
            );
            return;
        }
        let named = |key: &str| s.named.iter().find(|(k, _)| k == key).map(|(_, v)| v);
        let what = Allow {
            what: "a shape",
            ..PARAMS_ONLY
        };
        let sizes: Vec<Option<f64>> = s
            .positional
            .iter()
            .enumerate()
            .map(|(i, e)| {
                let name = match (kind.as_str(), i) {
                    ("box", _) => ["side `lx`", "side `ly`", "side `lz`"][i],
                    (_, 0) => "radius",
                    _ => "length",
                };
                self.shape_size(e, what, &kind, name)
            })
            .collect();
        let at = match named("at") {
            Some(e) => self.shape_point(e, what, "the centre `at` of a shape"),
            None => Some([0.0; 3]),
        };
        let color = named("color").and_then(|e| self.shape_color(e));
        let geometry = match kind.as_str() {
            "box" => match sizes[..] {
                [Some(x), Some(y), Some(z)] => Some(Geometry::Box([x, y, z])),
                _ => None,
            },
            "sphere" => sizes[0].map(Geometry::Sphere),
            "cylinder" => {
                let axis = match named("axis") {
                    Some(Expr::Path(p)) if p.path.is_ident("x") => Some(0),
                    Some(Expr::Path(p)) if p.path.is_ident("y") => Some(1),
                    Some(Expr::Path(p)) if p.path.is_ident("z") => Some(2),
                    Some(e) => {
                        self.error_at(
                            e,
                            format!(
                                "the axis of a cylinder is `x`, `y` or `z` (of the body's axes), found `{}`: write `axis = z`",
                                text(e)
                            ),
                        );
                        None
                    }
                    None => Some(2),
                };
                match (sizes[0], sizes[1], axis) {
                    (Some(r), Some(l), Some(a)) => Some(Geometry::Cylinder(r, l, a)),
                    _ => None,
                }
            }
            _ => {
                let end = |c: &mut Checker, key: &str| match named(key) {
                    Some(e) => c.shape_point(e, what, &format!("the end `{key}` of a line")),
                    None => {
                        c.error(
                            s.kind.span(),
                            format!(
                                "a line needs both ends: add `{key} = (x, y, z)`, as in `{usage}`"
                            ),
                        );
                        None
                    }
                };
                let from = end(self, "from");
                let to = end(self, "to");
                match (from, to) {
                    (Some(a), Some(b)) if a == b => {
                        let how = if [named("from"), named("to")]
                            .into_iter()
                            .flatten()
                            .any(|e| !is_literal(e))
                        {
                            " with the default parameters"
                        } else {
                            ""
                        };
                        self.error_at(
                            &s.kind,
                            format!(
                                "this line goes from ({}, {}, {}) to the same point{how}: give it two different ends",
                                a[0], a[1], a[2]
                            ),
                        );
                        None
                    }
                    (Some(a), Some(b)) => Some(Geometry::Line(a, b)),
                    _ => None,
                }
            }
        };
        if self.errors.len() > before {
            return;
        }
        let (Some(frame), Some(geometry), Some(at)) = (frame, geometry, at) else {
            return;
        };
        self.sys.shapes.push(ShapeDef {
            frame,
            geometry,
            at: if matches!(geometry, Geometry::Line(..)) {
                [0.0; 3]
            } else {
                at
            },
            rotation: IDENTITY,
            color,
            declared: true,
        });
    }

    /// A size of a shape: a positive constant (with the default parameters); `None` after an
    /// error, or when it depends on a parameter in error.
    fn shape_size(&mut self, e: &Expr, a: Allow, kind: &str, name: &str) -> Option<f64> {
        let before = self.errors.len();
        let id = self.lower(e, a);
        if self.errors.len() > before {
            return None;
        }
        let v = self.eval_default(id)?;
        if v.is_nan() || v <= 0.0 || v.is_infinite() {
            let how = self.with_defaults(id);
            self.error_at(
                e,
                format!(
                    "the {name} of a {kind} must be positive, it is {v}{how}: give it a size > 0"
                ),
            );
            return None;
        }
        Some(v)
    }

    /// `(x, y, z)` of constants.
    fn shape_point(&mut self, e: &Expr, a: Allow, what: &str) -> Option<[f64; 3]> {
        let before = self.errors.len();
        let p = self.triple(e, a, what)?;
        if self.errors.len() > before {
            return None;
        }
        let v = [
            self.eval_default(p[0])?,
            self.eval_default(p[1])?,
            self.eval_default(p[2])?,
        ];
        if v.iter().any(|x| !x.is_finite()) {
            let how = self.with_defaults_all(&p);
            self.error_at(
                e,
                format!("{what} is {v:?}{how}: give it finite coordinates"),
            );
            return None;
        }
        Some(v)
    }

    /// `color = "#rrggbb"`.
    fn shape_color(&mut self, e: &Expr) -> Option<[u8; 3]> {
        let hex = |s: &str| -> Option<[u8; 3]> {
            let h = s.strip_prefix('#')?;
            if h.len() != 6 || !h.bytes().all(|b| b.is_ascii_hexdigit()) {
                return None;
            }
            let c = |i: usize| u8::from_str_radix(&h[i..i + 2], 16).ok();
            Some([c(0)?, c(2)?, c(4)?])
        };
        let found = match e {
            Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Str(l),
                ..
            }) => match hex(&l.value()) {
                Some(c) => return Some(c),
                None => format!("\"{}\"", l.value()),
            },
            other => format!("`{}`", text(other)),
        };
        self.error_at(
            e,
            format!(
                "a colour is a string \"#rrggbb\" of hexadecimal red, green and blue, found {found}: write `color = \"#3080ff\"`"
            ),
        );
        None
    }
}

/// A number as written (possibly negative): no parameter in it.
fn is_literal(e: &Expr) -> bool {
    match e {
        Expr::Lit(_) => true,
        Expr::Unary(u) => is_literal(&u.expr),
        Expr::Paren(p) => is_literal(&p.expr),
        Expr::Tuple(t) => t.elems.iter().all(is_literal),
        _ => false,
    }
}
