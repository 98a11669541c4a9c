//! `gravity(gx, gy, gz)`: uniform gravity, world components.

use super::*;

pub(super) const KIND: Kind = Kind {
    name: "gravity",
    named: &[],
    lower,
};

fn lower(c: &mut Checker, s: &EffectStmt) -> Vec<Load> {
    if !c.positional(s, 3, "gravity(gx, gy, gz)") {
        return Vec::new();
    }
    let g = [0, 1, 2].map(|i| {
        c.lower(
            &s.positional[i],
            Allow {
                what: "gravity",
                ..PARAMS_ONLY
            },
        )
    });
    vec![Load::Gravity(g)]
}
