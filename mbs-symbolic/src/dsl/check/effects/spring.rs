//! `spring(a, b, k = …, l0 = …[, c = …][, axis = …][, preload = …])` and
//! `damper(a, b, c = …[, axis = …])`: line elements between two points, along their line or
//! a fixed world axis. A spring with `c` is also a damper.

use super::*;

pub(super) const KIND: Kind = Kind {
    name: "spring",
    named: &["k", "l0", "c", "axis", "preload"],
    lower,
};

pub(super) const DAMPER: Kind = Kind {
    name: "damper",
    named: &["c", "axis"],
    lower,
};

fn lower(c: &mut Checker, s: &EffectStmt) -> Vec<Load> {
    let kind = s.kind.to_string();
    let pa = Allow {
        what: "",
        ..PARAMS_ONLY
    };
    let mut out = Vec::new();
    let usage = if kind == "spring" {
        "spring(a, b, k = …, l0 = …)"
    } else {
        "damper(a, b, c = …)"
    };
    if !c.positional(s, 2, usage) {
        return out;
    }
    let (Some(a), Some(b)) = (c.attach(&s.positional[0]), c.attach(&s.positional[1])) else {
        return out;
    };
    if a.frame == b.frame && a.pos == b.pos {
        c.error_at(
            &range(&s.positional[0], &s.positional[1]),
            format!(
                "this {kind} joins `{}` to itself, so it has no length or direction: attach its ends to two different points",
                text(&s.positional[0])
            ),
        );
        return out;
    }
    // along a fixed direction of the world (linear), or along the line of its ends
    let axis = match named(s, "axis") {
        Some(e) => match c.axis_arg(
            e,
            if kind == "spring" { "spring" } else { "damper" },
            &format!("{kind}(a, b, …, axis = (nx, ny, nz))"),
            "in world axes",
        ) {
            Some(n) => Some(n),
            None => return out,
        },
        None => None,
    };
    if kind == "spring" {
        let Some(k) = named(s, "k") else {
            c.error(
                s.kind.span(),
                "a spring needs its stiffness: add `k = …`, as in `spring(a, b, k = …, l0 = …)`",
            );
            return out;
        };
        let k_expr = k;
        let k = c.lower(
            k,
            Allow {
                what: "a spring stiffness",
                ..pa
            },
        );
        c.not_negative(k, k_expr, "the stiffness `k` of a spring");
        let l0 = match named(s, "l0") {
            Some(e) => {
                let l0 = c.lower(
                    e,
                    Allow {
                        what: "a rest length",
                        ..pa
                    },
                );
                c.not_negative(l0, e, "the rest length `l0` of a spring");
                l0
            }
            None => c.sys.arena.zero(),
        };
        let preload = match named(s, "preload") {
            Some(e) => c.lower(
                e,
                Allow {
                    what: "a spring preload",
                    ..pa
                },
            ),
            None => c.sys.arena.zero(),
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
    let c_expr = named(s, "c");
    if kind == "damper" && c_expr.is_none() {
        c.error(
            s.kind.span(),
            "a damper needs its coefficient: add `c = …`, as in `damper(a, b, c = …)`",
        );
    }
    if let (Some((key, _)), "damper") =
        (s.named.iter().find(|(k, _)| k == "preload"), kind.as_str())
    {
        c.error(key.span(), "a damper has no preload: for a constant force between two points use `spring(a, b, k = 0, preload = F0)`");
    }
    if let Some(e) = c_expr {
        let damping = c.lower(
            e,
            Allow {
                what: "a damping coefficient",
                ..pa
            },
        );
        c.not_negative(
            damping,
            e,
            &format!("the damping coefficient `c` of a {kind}"),
        );
        out.push(Load::Damper {
            a,
            b,
            c: damping,
            axis,
        });
    }
    out
}
