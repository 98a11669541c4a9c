//! `torque(body, (mx, my, mz)[, frame = body][, relative_to = other])` and
//! `torque(body, axis = …, value[, relative_to = other])`: a torque on a body, with the
//! opposite torque on `relative_to` when given.

use super::*;

pub(super) const KIND: Kind = Kind {
    name: "torque",
    named: &["frame", "relative_to", "axis"],
    lower,
};

fn lower(c: &mut Checker, s: &EffectStmt) -> Vec<Load> {
    let on = s.positional.first().and_then(|e| c.ident_body_ref(e));
    let reaction = match named(s, "relative_to") {
        Some(e) => c.ident_body_ref(e).map(Some),
        None => Some(None),
    };
    let (torque, frame) = if let Some(axis) = named(s, "axis") {
        if !c.positional(s, 2, "torque(body, axis = z, value[, relative_to = other])") {
            return Vec::new();
        }
        if let Some((k, _)) = s.named.iter().find(|(k, _)| k == "frame") {
            c.error(k.span(), "`frame` does not go with `axis`: the axis is in the axes of the body the torque acts on; remove `frame = …`");
        }
        let dir = c.axis_arg(
            axis,
            "torque",
            "torque(body, axis = (nx, ny, nz), value)",
            "in the axes of the body",
        );
        let v = c.lower(&s.positional[1], ANY);
        let t = dir.map(|d| d.map(|x| c.sys.arena.mul(x, v)));
        (t, on)
    } else {
        if !c.positional(
            s,
            2,
            "torque(body, (mx, my, mz)[, frame = body][, relative_to = other])",
        ) {
            return Vec::new();
        }
        let t = c.triple(&s.positional[1], ANY, "a torque");
        let frame = match named(s, "frame") {
            Some(e) => c.ident_body_ref(e),
            None => Some(None),
        };
        (t, frame)
    };
    let (Some(on), Some(torque), Some(frame), Some(reaction)) = (on, torque, frame, reaction)
    else {
        return Vec::new();
    };
    if on.is_none() {
        let msg = match reaction {
            Some(Some(r)) => format!(
                "a torque on the ground does nothing, the ground does not move: put it on `{}` with the opposite sign",
                c.sys.frames[r].name
            ),
            _ => {
                "a torque on the ground does nothing, the ground does not move: apply it to a body"
                    .to_string()
            }
        };
        c.error(s.positional[0].span(), msg);
        return Vec::new();
    }
    vec![Load::Torque {
        on,
        torque,
        frame,
        reaction,
    }]
}
