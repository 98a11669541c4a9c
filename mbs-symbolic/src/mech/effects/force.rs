//! A force at a point, its components in the world's or a frame's axes; power F·v.

use super::Build;
use crate::mech::spatial as s;
use crate::mech::system::Load;

pub(super) fn build(b: &mut Build, load: &Load) {
    let Load::Force { at, force, frame } = *load else {
        unreachable!("force::build is given forces")
    };
    b.dissipative = true;
    let p = b.pt(&at);
    let fw = match frame {
        Some(fr) => s::mul_mv(b.a, &b.w.nodes[b.tree.frame_node[fr]].r, force),
        None => force,
    };
    let v = b.velocity(&p);
    let pw = s::dot(b.a, fw, v);
    b.add_power(pw);
    b.push_force(&p, fw);
}
