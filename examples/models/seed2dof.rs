//! seed2dof: two masses on a line, ground —k1— mass 1 —k2— mass 2, no gravity
//! (`tests/reference/MODELS.md`). Shared by `examples/seed2dof.rs` and the tests.

mbs::multibody! {
    /// The 2-dof spring–mass system of the seed course; q = displacements from rest.
    pub model Seed2dof {
        param m1 = 1.0; param m2 = 1.0;
        param k1 = 79.15; param k2 = 1961.0;
        dof q[0] = 0.0; dof q[1] = 1.0;
        body mass1 { mass = m1; }
        body mass2 { mass = m2; }
        // at rest 1 m and 2 m from the wall; linear springs along x (axis = x): their length
        // is the signed distance along x, so the system is linear for any displacement
        TOG[mass1] = Tdisp(1 + q[0], 0, 0);
        TOG[mass2] = Tdisp(2 + q[1], 0, 0);
        spring(ground, mass1, k = k1, l0 = 1, axis = x);
        spring(mass1, mass2, k = k2, l0 = 1, axis = x);
    }
}
