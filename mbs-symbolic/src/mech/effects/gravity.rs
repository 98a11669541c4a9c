//! Uniform gravity: summed over the scene's gravity effects; its potential is computed from
//! the bodies (`mech::dynamics`), so it adds neither potential nor power here.

use super::Build;
use crate::mech::spatial::{self as s, V3};

pub(super) fn build(b: &mut Build, g: V3) {
    b.out.gravity = Some(match b.out.gravity {
        Some(g0) => s::add(b.a, g0, g),
        None => g,
    });
}
