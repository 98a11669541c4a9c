//! `force(point, (fx, fy, fz)[, frame = body])`: a force at a point, components in the world's
//! or a body's axes.

use super::*;

pub(super) const KIND: Kind = Kind {
    name: "force",
    named: &["frame"],
    lower,
};

fn lower(c: &mut Checker, s: &EffectStmt) -> Vec<Load> {
    if !c.positional(s, 2, "force(point, (fx, fy, fz)[, frame = body])") {
        return Vec::new();
    }
    let at = c.attach(&s.positional[0]);
    let f = c.triple(&s.positional[1], ANY, "a force");
    let frame = match named(s, "frame") {
        Some(e) => c.ident_body_ref(e),
        None => Some(None),
    };
    match (at, f, frame) {
        (Some(at), Some(force), Some(frame)) => vec![Load::Force { at, force, frame }],
        _ => Vec::new(),
    }
}
