//! Effects: attachment points, gravity, springs, dampers, forces, torques, generalised
//! forces (contacts and bushings in `force_elements.rs`).

use super::*;

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
        let named = |key: &str| s.named.iter().find(|(k, _)| k == key).map(|(_, v)| v);
        let known_named: &[&str] = match kind.as_str() {
            "spring" => &["k", "l0", "c", "axis", "preload"],
            "contact" => &["k", "c", "mu", "eps", "plane", "offset", "sphere"],
            "bushing" => &["k", "kr", "c", "cr"],
            "damper" => &["c", "axis"],
            "force" => &["frame"],
            "torque" => &["frame", "relative_to", "axis"],
            _ => &[],
        };
        for (i, (k, _)) in s.named.iter().enumerate() {
            if s.named[..i].iter().any(|(j, _)| j == k) {
                self.error(
                    k.span(),
                    format!("argument `{k}` is given twice: remove one"),
                );
            } else if !known_named.contains(&k.to_string().as_str())
                // reported below, with what to write instead
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
        let npos = |c: &mut Checker, n: usize, usage: &str| {
            if s.positional.len() != n {
                c.error(
                    s.kind.span(),
                    format!(
                        "`{kind}` takes {}, found {}: write `{usage}`",
                        count(n, "positional argument"),
                        s.positional.len()
                    ),
                );
                false
            } else {
                true
            }
        };
        let pa = Allow {
            what: "",
            ..PARAMS_ONLY
        };
        let mut out = Vec::new();
        match kind.as_str() {
            "gravity" => {
                if npos(self, 3, "gravity(gx, gy, gz)") {
                    let g = [0, 1, 2].map(|i| {
                        self.lower(
                            &s.positional[i],
                            Allow {
                                what: "gravity",
                                ..PARAMS_ONLY
                            },
                        )
                    });
                    out.push(Load::Gravity(g));
                }
            }
            "spring" | "damper" => {
                let usage = if kind == "spring" {
                    "spring(a, b, k = …, l0 = …)"
                } else {
                    "damper(a, b, c = …)"
                };
                if !npos(self, 2, usage) {
                    return out;
                }
                let (Some(a), Some(b)) =
                    (self.attach(&s.positional[0]), self.attach(&s.positional[1]))
                else {
                    return out;
                };
                if a.frame == b.frame && a.pos == b.pos {
                    self.error_at(
                        &range(&s.positional[0], &s.positional[1]),
                        format!(
                            "this {kind} joins `{}` to itself, so it has no length or direction: attach its ends to two different points",
                            text(&s.positional[0])
                        ),
                    );
                    return out;
                }
                // along a fixed direction of the world (linear), or along the line of its ends
                let axis = match named("axis") {
                    Some(e) => match self.axis_arg(
                        e,
                        kind_static(&kind),
                        &format!("{kind}(a, b, …, axis = (nx, ny, nz))"),
                        "in world axes",
                    ) {
                        Some(n) => Some(n),
                        None => return out,
                    },
                    None => None,
                };
                if kind == "spring" {
                    let Some(k) = named("k") else {
                        self.error(
                            s.kind.span(),
                            "a spring needs its stiffness: add `k = …`, as in `spring(a, b, k = …, l0 = …)`",
                        );
                        return out;
                    };
                    let k_expr = k;
                    let k = self.lower(
                        k,
                        Allow {
                            what: "a spring stiffness",
                            ..pa
                        },
                    );
                    self.not_negative(k, k_expr, "the stiffness `k` of a spring");
                    let l0 = match named("l0") {
                        Some(e) => {
                            let l0 = self.lower(
                                e,
                                Allow {
                                    what: "a rest length",
                                    ..pa
                                },
                            );
                            self.not_negative(l0, e, "the rest length `l0` of a spring");
                            l0
                        }
                        None => self.sys.arena.zero(),
                    };
                    let preload = match named("preload") {
                        Some(e) => self.lower(
                            e,
                            Allow {
                                what: "a spring preload",
                                ..pa
                            },
                        ),
                        None => self.sys.arena.zero(),
                    };
                    out.push(Load::Spring {
                        a,
                        b,
                        k,
                        l0,
                        axis,
                        preload,
                    });
                }
                let c_expr = named("c");
                if kind == "damper" && c_expr.is_none() {
                    self.error(
                        s.kind.span(),
                        "a damper needs its coefficient: add `c = …`, as in `damper(a, b, c = …)`",
                    );
                }
                if let (Some((key, _)), "damper") =
                    (s.named.iter().find(|(k, _)| k == "preload"), kind.as_str())
                {
                    self.error(key.span(), "a damper has no preload: for a constant force between two points use `spring(a, b, k = 0, preload = F0)`");
                }
                if let Some(e) = c_expr {
                    let c = self.lower(
                        e,
                        Allow {
                            what: "a damping coefficient",
                            ..pa
                        },
                    );
                    self.not_negative(c, e, &format!("the damping coefficient `c` of a {kind}"));
                    out.push(Load::Damper { a, b, c, axis });
                }
            }
            "force" => {
                if !npos(self, 2, "force(point, (fx, fy, fz)[, frame = body])") {
                    return out;
                }
                let at = self.attach(&s.positional[0]);
                let f = self.triple(&s.positional[1], ANY, "a force");
                let frame = match named("frame") {
                    Some(e) => self.ident_body_ref(e),
                    None => Some(None),
                };
                if let (Some(at), Some(force), Some(frame)) = (at, f, frame) {
                    out.push(Load::Force { at, force, frame });
                }
            }
            "torque" => {
                let on = s.positional.first().and_then(|e| self.ident_body_ref(e));
                let reaction = match named("relative_to") {
                    Some(e) => self.ident_body_ref(e).map(Some),
                    None => Some(None),
                };
                let (torque, frame) = if let Some(axis) = named("axis") {
                    if !npos(
                        self,
                        2,
                        "torque(body, axis = z, value[, relative_to = other])",
                    ) {
                        return out;
                    }
                    if let Some((k, _)) = s.named.iter().find(|(k, _)| k == "frame") {
                        self.error(k.span(), "`frame` does not go with `axis`: the axis is in the axes of the body the torque acts on; remove `frame = …`");
                    }
                    let dir = self.axis_arg(
                        axis,
                        "torque",
                        "torque(body, axis = (nx, ny, nz), value)",
                        "in the axes of the body",
                    );
                    let v = self.lower(&s.positional[1], ANY);
                    let t = dir.map(|d| d.map(|c| self.sys.arena.mul(c, v)));
                    (t, on)
                } else {
                    if !npos(
                        self,
                        2,
                        "torque(body, (mx, my, mz)[, frame = body][, relative_to = other])",
                    ) {
                        return out;
                    }
                    let t = self.triple(&s.positional[1], ANY, "a torque");
                    let frame = match named("frame") {
                        Some(e) => self.ident_body_ref(e),
                        None => Some(None),
                    };
                    (t, frame)
                };
                if let (Some(on), Some(torque), Some(frame), Some(reaction)) =
                    (on, torque, frame, reaction)
                {
                    if on.is_none() {
                        let msg = match reaction {
                            Some(Some(r)) => format!(
                                "a torque on the ground does nothing, the ground does not move: put it on `{}` with the opposite sign",
                                self.sys.frames[r].name
                            ),
                            _ => "a torque on the ground does nothing, the ground does not move: apply it to a body".to_string(),
                        };
                        self.error(s.positional[0].span(), msg);
                        return out;
                    }
                    out.push(Load::Torque {
                        on,
                        torque,
                        frame,
                        reaction,
                    });
                }
            }
            "generalized_force" => {
                if !npos(self, 2, "generalized_force(q[i], value)") {
                    return out;
                }
                let dof = self.dof_ref(&s.positional[0]);
                let v = self.lower(&s.positional[1], ANY);
                if let Some(dof) = dof {
                    out.push(Load::GenForce { dof, value: v });
                }
            }
            "contact" => out.extend(self.lower_contact(s)),
            "bushing" => out.extend(self.lower_bushing(s)),
            "friction" => {
                self.error(
                    s.kind.span(),
                    "friction acts only where a body touches the ground: give the contact its friction coefficient, `contact(point, k = …, mu = …);`",
                );
            }
            other => {
                let known = [
                    "gravity",
                    "spring",
                    "damper",
                    "force",
                    "torque",
                    "generalized_force",
                    "contact",
                    "bushing",
                ];
                self.error(s.kind.span(), format!("unknown effect `{other}`{}", did_you_mean(other, known.into_iter(), "the effects are gravity, spring, damper, force, torque, generalized_force, contact and bushing")));
            }
        }
        out
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
}

/// The name of an effect kind that takes an axis, as a static string for messages.
fn kind_static(kind: &str) -> &'static str {
    match kind {
        "spring" => "spring",
        "damper" => "damper",
        _ => "effect",
    }
}
