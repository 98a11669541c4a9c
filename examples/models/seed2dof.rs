//! seed2dof: two 1 kg masses on a line, ground —k1— mass 1 —k2— mass 2, no gravity
//! (`tests/reference/MODELS.md`). Shared by `examples/seed2dof.rs` and the tests.

mbs::multibody! {
    /// The 2-dof spring–mass system of the seed course; q = displacements from rest.
    pub model Seed2dof {
        param m1 = 1.0; param m2 = 1.0;
        param k1 = 79.15; param k2 = 1961.0;
        // Rest length of both springs. A point-to-point spring acts along the line between its
        // ends, so it must never shrink to zero: 10 m is far more than the motion (|q| ≤ 1 m).
        param rest = 10.0;
        dof q[0] = 0.0; dof q[1] = 1.0;
        body mass1 { mass = m1; }
        body mass2 { mass = m2; }
        TOG[mass1] = Tdisp(rest + q[0], 0, 0);
        TOG[mass2] = Tdisp(2 * rest + q[1], 0, 0);
        spring(ground, mass1, k = k1, l0 = rest);
        spring(mass1, mass2, k = k2, l0 = rest);
    }
}
