//! A generalised force on one coordinate; power Q q̇.

use super::Build;
use crate::expr::Var;
use crate::mech::system::Load;

pub(super) fn build(b: &mut Build, load: &Load) {
    let Load::GenForce { dof, value } = *load else {
        unreachable!("generalized_force::build is given generalised forces")
    };
    b.dissipative = true;
    let qd = b.a.var(Var::Qd(dof as u16));
    let pw = b.a.mul(value, qd);
    b.add_power(pw);
    b.out.generalized.push((dof, value));
}
