//! `rotational_spring(A, B, axis = …, k = …[, angle0 = …][, c = …])` and
//! `rotational_damper(A, B, axis = …, c = …)`: a torque about one axis between two bodies or
//! frames (or one and the ground), from the angle of B relative to A about it.

use super::*;

pub(super) const KIND: Kind = Kind {
    name: "rotational_spring",
    named: &["axis", "k", "c", "angle0"],
    lower,
};

pub(super) const DAMPER: Kind = Kind {
    name: "rotational_damper",
    named: &["axis", "c"],
    lower,
};

fn lower(c: &mut Checker, s: &EffectStmt) -> Vec<Load> {
    let kind = s.kind.to_string();
    let spring = kind == "rotational_spring";
    let usage = if spring {
        "rotational_spring(A, B, axis = z, k = …, angle0 = …)"
    } else {
        "rotational_damper(A, B, axis = z, c = …)"
    };
    let what = if spring {
        "a rotational spring"
    } else {
        "a rotational damper"
    };
    if s.positional.len() != 2 {
        c.error(
            s.kind.span(),
            format!(
                "`{kind}` joins two bodies or frames (or one and `ground`), found {}: write `{usage}`",
                count(s.positional.len(), "positional argument")
            ),
        );
        return Vec::new();
    }
    let fa = c.ident_body_ref(&s.positional[0]);
    let fb = c.ident_body_ref(&s.positional[1]);
    let axis = match named(s, "axis") {
        Some(e) => c.axis_arg(e, kind_name(spring), usage, "in the axes of A"),
        None => {
            c.error(
                s.kind.span(),
                format!("{what} needs the axis it turns about, in the axes of A: add `axis = z` (or `x`, `y`, a unit `(nx, ny, nz)`), as in `{usage}`"),
            );
            None
        }
    };
    let coef = |c: &mut Checker, key: &str, what: &'static str, name: &str| {
        named(s, key).map(|e| {
            let v = c.lower(
                e,
                Allow {
                    what,
                    ..PARAMS_ONLY
                },
            );
            c.not_negative(v, e, name);
            v
        })
    };
    let mut ok = true;
    let k = if spring {
        let k = coef(
            c,
            "k",
            "a rotational stiffness",
            "the stiffness `k` of a rotational spring",
        );
        if k.is_none() {
            c.error(
                s.kind.span(),
                format!("a rotational spring needs its stiffness: add `k = …` (N·m/rad), as in `{usage}`"),
            );
            ok = false;
        }
        k
    } else {
        None
    };
    let damping = coef(
        c,
        "c",
        "a rotational damping",
        &format!("the damping `c` of {what}"),
    );
    if !spring && damping.is_none() {
        c.error(
            s.kind.span(),
            format!("a rotational damper needs its coefficient: add `c = …` (N·m·s/rad), as in `{usage}`"),
        );
        ok = false;
    }
    let angle0 = match named(s, "angle0") {
        Some(e) => c.lower(
            e,
            Allow {
                what: "a rest angle",
                ..PARAMS_ONLY
            },
        ),
        None => c.sys.arena.zero(),
    };
    let (Some(fa), Some(fb), Some(axis), true) = (fa, fb, axis, ok) else {
        return Vec::new();
    };
    if fa == fb {
        let msg = if fa.is_none() {
            format!(
                "{what} between the ground and itself never turns: join a body or frame to the ground or to another body"
            )
        } else {
            format!(
                "this {} joins `{}` to itself, so it never turns: join two different bodies or frames (or one and `ground`)",
                kind.replace('_', " "),
                text(&s.positional[0])
            )
        };
        c.error_at(&range(&s.positional[0], &s.positional[1]), msg);
        return Vec::new();
    }
    let z = c.sys.arena.zero();
    vec![Load::RotationalSpring {
        a: fa,
        b: fb,
        axis,
        k: k.unwrap_or(z),
        c: damping.unwrap_or(z),
        angle0,
    }]
}

fn kind_name(spring: bool) -> &'static str {
    if spring {
        "rotational spring"
    } else {
        "rotational damper"
    }
}
