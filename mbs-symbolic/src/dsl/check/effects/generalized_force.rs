//! `generalized_force(q[i], value)`: a generalised force on one coordinate.

use super::*;

pub(super) const KIND: Kind = Kind {
    name: "generalized_force",
    named: &[],
    lower,
};

fn lower(c: &mut Checker, s: &EffectStmt) -> Vec<Load> {
    if !c.positional(s, 2, "generalized_force(q[i], value)") {
        return Vec::new();
    }
    let dof = c.dof_ref(&s.positional[0]);
    let value = c.lower(&s.positional[1], ANY);
    dof.map(|dof| Load::GenForce { dof, value })
        .into_iter()
        .collect()
}
