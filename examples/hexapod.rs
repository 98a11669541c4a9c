//! A walking robot in the spirit of the seed's AMRU5: a 20 kg floating base and six 3-dof legs
//! with pantograph links and geared motor rotors, 24 dof and 49 bodies, under gravity, without
//! ground contact yet: the `hexapod` model of `tests/reference/MODELS.md`.
//!
//! Prints the model's sizes, a summary of M and h at the MODELS.md test state, the feet's
//! heights at the initial state and the operation counts of the generated functions. The
//! model itself is in `examples/models/hexapod.rs`.
//!
//! Run with `cargo run --release --example hexapod`.

#[path = "common/mod.rs"]
mod common;
#[path = "models/hexapod.rs"]
mod model;

use mbs::{Kinematics, Model};
use model::Hexapod;

fn main() {
    let model = Hexapod::default();
    common::show(&model);

    // feet at the initial state (base at z = 0.5 m, every leg at (a, b, c) = (0, 0.3, −0.3))
    let n = Hexapod::NQ;
    let (mut q0, mut qd0) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q0, &mut qd0);
    let mut kinematics = Kinematics::new::<Hexapod>();
    model.kinematics(0.0, &q0, &qd0, &mut kinematics);
    print!("foot heights at the start (m):");
    for foot in &kinematics.points {
        print!(" {:.4}", foot.position[2]);
    }
    println!();
}
