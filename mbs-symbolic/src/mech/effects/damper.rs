//! A linear damper between two points, along their line or a fixed world axis: force
//! c l̇ along the line, power −c l̇².

use super::{Build, length_and_direction};
use crate::mech::spatial as s;
use crate::mech::system::Load;

pub(super) fn build(b: &mut Build, load: &Load) {
    let Load::Damper {
        a: pa,
        b: pb,
        c,
        axis,
    } = *load
    else {
        unreachable!("damper::build is given dampers")
    };
    b.dissipative = true;
    let (p1, p2) = (b.pt(&pa), b.pt(&pb));
    let x1 = b.position(&p1);
    let x2 = b.position(&p2);
    let v1 = b.velocity(&p1);
    let v2 = b.velocity(&p2);
    let a = &mut *b.a;
    let d = s::sub(a, x2, x1);
    let (_, e) = length_and_direction(a, d, axis);
    let dv = s::sub(a, v2, v1);
    let ldot = s::dot(a, e, dv);
    let f = a.mul(c, ldot);
    let f1 = s::scale(a, f, e);
    let f2 = s::neg(a, f1);
    b.push_force(&p1, f1);
    b.push_force(&p2, f2);
    let p = b.a.mul(f, ldot);
    b.sub_power(p);
}
