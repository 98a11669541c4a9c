//! Constraints: scalar Φ(q, t) = 0 and loop closures (points coinciding along chosen
//! directions, frames aligned about chosen axes), one named scalar constraint per direction.

use super::*;
use crate::dsl::ast::ConstraintBody;
use crate::mech::system::{ConstraintDef, ConstraintKind};

impl Checker {
    pub(super) fn lower_constraint(&mut self, name: &Ident, body: &ConstraintBody) {
        let base = name.to_string();
        if self
            .sys
            .constraints
            .iter()
            .any(|c| c.name == base || c.name.starts_with(&format!("{base}.")))
        {
            self.error(
                name.span(),
                format!("duplicate constraint `{base}`: each constraint needs its own name"),
            );
            return;
        }
        match body {
            ConstraintBody::Scalar(e) => {
                let before = self.errors.len();
                let phi = self.lower(
                    e,
                    Allow {
                        what: "a constraint Φ(q, t) = 0",
                        ..POSITION
                    },
                );
                if self.errors.len() > before {
                    return;
                }
                if self.sys.arena.is_const(phi) {
                    self.error_at(e, format!("constraint `{base}` does not depend on the coordinates or the time: it constrains nothing (or everything); write Φ(q, t) so that Φ = 0 holds on the motion"));
                    return;
                }
                self.sys.constraints.push(ConstraintDef {
                    name: base,
                    kind: ConstraintKind::Scalar(phi),
                });
            }
            ConstraintBody::Closure(stmt) => self.lower_closure(&base, stmt),
        }
    }

    /// `[x, y]` → axis indices; `None` after an error.
    fn axes(&mut self, e: &Expr, what: &str) -> Option<Vec<usize>> {
        let Expr::Array(arr) = e else {
            self.error_at(e, format!("{what} is a list of axes, e.g. `[x, y]`"));
            return None;
        };
        let mut out = Vec::new();
        for el in &arr.elems {
            let k = match el {
                Expr::Path(p) if p.path.is_ident("x") => 0,
                Expr::Path(p) if p.path.is_ident("y") => 1,
                Expr::Path(p) if p.path.is_ident("z") => 2,
                other => {
                    self.error_at(
                        other,
                        format!(
                            "unknown axis `{}` in {what}: the axes are x, y and z",
                            text(other)
                        ),
                    );
                    return None;
                }
            };
            if out.contains(&k) {
                self.error_at(el, format!("axis `{}` is listed twice in {what}", text(el)));
                return None;
            }
            out.push(k);
        }
        if out.is_empty() {
            self.error_at(
                e,
                format!("{what} lists no axis: name at least one of x, y, z"),
            );
            return None;
        }
        Some(out)
    }

    fn lower_closure(&mut self, base: &str, s: &EffectStmt) {
        let kind = s.kind.to_string();
        let named = |key: &str| s.named.iter().find(|(k, _)| k == key).map(|(_, v)| v);
        let allowed: &[&str] = match kind.as_str() {
            "coincide" => &["along", "frame"],
            "align" => &["about"],
            _ => {
                self.error(s.kind.span(), format!("unknown loop closure `{kind}`: write `coincide(a, b[, along = [x, y]][, frame = body])` (two points meet) or `align(A, B[, about = [z]])` (two frames keep their orientation)"));
                return;
            }
        };
        for (k, _) in &s.named {
            if !allowed.contains(&k.to_string().as_str()) {
                self.error(
                    k.span(),
                    format!(
                        "`{kind}` has no argument `{k}`; its named arguments are {}",
                        allowed
                            .iter()
                            .map(|a| format!("`{a}`"))
                            .collect::<Vec<_>>()
                            .join(" and ")
                    ),
                );
            }
        }
        if s.positional.len() != 2 {
            self.error(
                s.kind.span(),
                format!(
                    "`{kind}` joins two {}, found {} argument(s)",
                    if kind == "coincide" {
                        "points"
                    } else {
                        "frames"
                    },
                    s.positional.len()
                ),
            );
            return;
        }
        const AXES: [&str; 3] = ["x", "y", "z"];
        if kind == "coincide" {
            let (Some(a), Some(b)) = (self.attach(&s.positional[0]), self.attach(&s.positional[1]))
            else {
                return;
            };
            if a.frame == b.frame {
                self.error_at(&range(&s.positional[0], &s.positional[1]), "both points are on the same body: their distance never changes, so this closes no loop");
                return;
            }
            let axes = match named("along") {
                Some(e) => match self.axes(e, "`along`") {
                    Some(v) => v,
                    None => return,
                },
                None => vec![0, 1, 2],
            };
            let frame = match named("frame") {
                Some(e) => match self.ident_body_ref(e) {
                    Some(f) => f,
                    None => return,
                },
                None => None,
            };
            for axis in axes {
                let name = format!("{base}.{}", AXES[axis]);
                self.sys.constraints.push(ConstraintDef {
                    name,
                    kind: ConstraintKind::Coincide { a, b, axis, frame },
                });
            }
        } else {
            let (Some(a), Some(b)) = (
                self.ident_body_ref(&s.positional[0]),
                self.ident_body_ref(&s.positional[1]),
            ) else {
                return;
            };
            if a == b {
                self.error_at(
                    &range(&s.positional[0], &s.positional[1]),
                    "a frame is always aligned with itself: name two different frames",
                );
                return;
            }
            let axes = match named("about") {
                Some(e) => match self.axes(e, "`about`") {
                    Some(v) => v,
                    None => return,
                },
                None => vec![0, 1, 2],
            };
            for axis in axes {
                let name = format!("{base}.r{}", AXES[axis]);
                self.sys.constraints.push(ConstraintDef {
                    name,
                    kind: ConstraintKind::Align { a, b, axis },
                });
            }
        }
    }
}
