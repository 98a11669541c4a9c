//! Effects: attachment points, the arguments every effect shares, and the table of effect
//! kinds; each kind is lowered in its own file (gravity, springs and dampers, forces,
//! torques, generalised forces, contacts, bushings, rotational springs and dampers).

mod bushing;
mod contact;
mod force;
mod generalized_force;
mod gravity;
mod rotational_spring;
mod spring;
mod torque;

use super::*;

/// A kind of effect statement: its name, its named arguments and how it becomes loads.
struct Kind {
    name: &'static str,
    named: &'static [&'static str],
    lower: fn(&mut Checker, &EffectStmt) -> Vec<Load>,
}

/// Every kind of effect, in the order error messages list them.
const KINDS: [Kind; 10] = [
    gravity::KIND,
    spring::KIND,
    spring::DAMPER,
    force::KIND,
    torque::KIND,
    generalized_force::KIND,
    contact::KIND,
    bushing::KIND,
    rotational_spring::KIND,
    rotational_spring::DAMPER,
];

/// The value of the named argument `key` of `s`.
fn named<'a>(s: &'a EffectStmt, key: &str) -> Option<&'a Expr> {
    s.named.iter().find(|(k, _)| k == key).map(|(_, v)| v)
}

impl Checker {
    /// `(x, y, z)` → three expressions.
    pub(super) fn triple(&mut self, e: &Expr, a: Allow, what: &str) -> Option<[ExprId; 3]> {
        match e {
            Expr::Tuple(t) if t.elems.len() == 3 => {
                let v: Vec<ExprId> = t.elems.iter().map(|x| self.lower(x, a)).collect();
                Some([v[0], v[1], v[2]])
            }
            Expr::Paren(p) => self.triple(&p.expr, a, what),
            _ => {
                self.error_at(
                    e,
                    format!("{what} is a vector `(x, y, z)`, found `{}`", text(e)),
                );
                None
            }
        }
    }

    pub(super) fn attach(&mut self, e: &Expr) -> Option<Attach> {
        let z = self.sys.arena.zero();
        if let Expr::Path(p) = e {
            if let Some(id) = p.path.get_ident() {
                let s = id.to_string();
                if let Some(&pi) = self.points.get(&s) {
                    let pt = &self.sys.points[pi];
                    return Some(Attach {
                        frame: pt.frame,
                        pos: pt.pos,
                    });
                }
                if s == "ground" {
                    return Some(Attach {
                        frame: None,
                        pos: [z; 3],
                    });
                }
                if let Some(&fi) = self.frame_names.get(&s) {
                    return Some(Attach {
                        frame: Some(fi),
                        pos: [z; 3],
                    });
                }
                if self.taken_reserved.contains(&s) {
                    return None;
                }
                let names: Vec<String> = self
                    .points
                    .keys()
                    .chain(self.frame_names.keys())
                    .cloned()
                    .collect();
                self.error(
                    id.span(),
                    format!(
                        "unknown point or body `{s}`{}",
                        did_you_mean(
                            &s,
                            names.iter().map(String::as_str),
                            &format!("declare it with `point {s} on BODY at (x, y, z);`")
                        )
                    ),
                );
                return None;
            }
        }
        self.error_at(
            e,
            format!(
                "expected the name of a point, a body or `ground`, found `{}`",
                text(e)
            ),
        );
        None
    }

    pub(super) fn lower_effect(&mut self, s: &EffectStmt) -> Vec<Load> {
        let kind = s.kind.to_string();
        let found = KINDS.iter().find(|k| k.name == kind);
        let known_named: &[&str] = found.map_or(&[], |k| k.named);
        for (i, (k, _)) in s.named.iter().enumerate() {
            if s.named[..i].iter().any(|(j, _)| j == k) {
                self.error(
                    k.span(),
                    format!("argument `{k}` is given twice: remove one"),
                );
            } else if !known_named.contains(&k.to_string().as_str())
                // reported by the kind, with what to write instead
                && kind != "friction"
                && (kind.as_str(), k.to_string().as_str()) != ("damper", "preload")
            {
                let list = match known_named {
                    [] => format!("`{kind}` takes no named argument"),
                    [one] => format!("its only named argument is `{one}`"),
                    [init @ .., last] => format!(
                        "its named arguments are {} and `{last}`",
                        init.iter()
                            .map(|a| format!("`{a}`"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                };
                self.error(k.span(), format!("`{kind}` has no argument `{k}`; {list}"));
            }
        }
        if let Some(k) = found {
            return (k.lower)(self, s);
        }
        if kind == "friction" {
            self.error(
                s.kind.span(),
                "friction acts only where a body touches the ground: give the contact its friction coefficient, `contact(point, k = …, mu = …);`",
            );
        } else {
            let known = KINDS.iter().map(|k| k.name);
            let (last, init) = KINDS.split_last().expect("effect kinds");
            let list = format!(
                "the effects are {} and {}",
                init.iter().map(|k| k.name).collect::<Vec<_>>().join(", "),
                last.name
            );
            self.error(
                s.kind.span(),
                format!(
                    "unknown effect `{kind}`{}",
                    did_you_mean(&kind, known, &list)
                ),
            );
        }
        Vec::new()
    }

    /// Whether `s` has `n` positional arguments; reports it with the usage `usage` if not.
    fn positional(&mut self, s: &EffectStmt, n: usize, usage: &str) -> bool {
        if s.positional.len() == n {
            return true;
        }
        self.error(
            s.kind.span(),
            format!(
                "`{}` takes {}, found {}: write `{usage}`",
                s.kind,
                count(n, "positional argument"),
                s.positional.len()
            ),
        );
        false
    }

    /// Reports `value` (on `at`) if it is negative with the default parameters.
    pub(super) fn not_negative(&mut self, value: ExprId, at: &Expr, what: &str) {
        if let Some(v) = self.eval_default(value) {
            if v < 0.0 {
                let how = self.with_defaults(value);
                self.error_at(
                    at,
                    format!("{what} must not be negative, it is {v}{how}: give a value ≥ 0"),
                );
            }
        }
    }

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
}
