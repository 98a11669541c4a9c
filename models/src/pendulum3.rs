//! `pendulum3` of `tests/reference/MODELS.md`: Cash's index-3 test problem, a unit point mass
//! on a rigid rod of length 1 in Cartesian coordinates, g = 1. The sign of Φ makes λ the test
//! set's multiplier: x'' = −xλ, y'' = −yλ − 1, and ẋ² + ẏ² − λ − y = 0 on the motion.
//! Used by the index-3 and allocation tests.

mbs::multibody! {
    /// Cash's pendulum: (x, y) of a unit mass on a unit rod, started at (1, 0) moving up.
    pub model Pendulum3 {
        dof x = 1.0, qd = 0.0; dof y = 0.0, qd = 1.0;
        body m { mass = 1.0; }
        TOG[m] = Tdisp(x, y, 0);
        gravity(0, -1, 0);
        constraint rod = -(x * x + y * y - 1.0) / 2.0;
    }
}
