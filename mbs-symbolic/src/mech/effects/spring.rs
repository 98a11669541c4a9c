//! A spring between two points, along their line or a fixed world axis: tension
//! F0 + k (l − l0), potential F0 (l − l0) + ½ k (l − l0)².

use super::{Build, length_and_direction};
use crate::mech::spatial as s;
use crate::mech::system::Load;

pub(super) fn build(b: &mut Build, load: &Load) {
    let Load::Spring {
        a: pa,
        b: pb,
        k,
        l0,
        axis,
        preload,
    } = *load
    else {
        unreachable!("spring::build is given springs")
    };
    b.elastic = true;
    let (p1, p2) = (b.pt(&pa), b.pt(&pb));
    let x1 = b.position(&p1);
    let x2 = b.position(&p2);
    let a = &mut *b.a;
    let d = s::sub(a, x2, x1);
    // length and direction: along the line of the ends, or the given axis
    let (l, e) = length_and_direction(a, d, axis);
    let stretch = a.sub(l, l0);
    let ks = a.mul(k, stretch);
    // tension F0 + k s, potential (F0 + ½ k s) s = F0 s + ½ k s²
    let tension = a.add(preload, ks);
    let f1 = s::scale(a, tension, e);
    let f2 = s::neg(a, f1);
    b.push_force(&p1, f1);
    b.push_force(&p2, f2);
    let a = &mut *b.a;
    let hks = a.mul(b.half, ks);
    let per = a.add(preload, hks);
    let v = a.mul(per, stretch);
    b.add_potential(v);
}
