//! A torque on a body, its components in the world's or a frame's axes, with the opposite
//! torque on a reaction body when given; power M·ω of each.

use super::Build;
use crate::mech::spatial::{self as s, V3};
use crate::mech::system::Load;

pub(super) fn build(b: &mut Build, load: &Load) {
    let Load::Torque {
        on,
        torque,
        frame,
        reaction,
    } = *load
    else {
        unreachable!("torque::build is given torques")
    };
    b.dissipative = true;
    let tw = match frame {
        Some(fr) => s::mul_mv(b.a, &b.w.nodes[b.tree.frame_node[fr]].r, torque),
        None => torque,
    };
    push(b, on, tw);
    if let Some(r) = reaction {
        let nt = s::neg(b.a, tw);
        push(b, r, nt);
    }
}

/// The torque `t` on frame `on` (nothing on the ground) and its power.
fn push(b: &mut Build, on: Option<usize>, t: V3) {
    if let Some(n) = on.map(|f| b.tree.frame_node[f]) {
        let pw = s::dot(b.a, t, b.w.nodes[n].w);
        b.add_power(pw);
        b.out.torques.push((n, t));
    }
}
