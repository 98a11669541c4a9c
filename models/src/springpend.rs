//! springpend (`tests/reference/MODELS.md`): a point mass on a stiff spring, hinged at the
//! origin, in polar coordinates. Used by the hard cases' stiffness sweep (k = 1e2 … 1e8 N/m).

mbs::multibody! {
    /// springpend: a 1 kg point mass on a massless spring of rest length 1 m hinged at the
    /// origin, in polar coordinates (θ from the downward vertical, r). The start
    /// (θ, r) = (0.5, 1 + 9.81/k) is set by the runs.
    pub model SpringPend {
        param k = 1e4;
        dof theta = 0.5;
        dof r = 1.0;
        option tangents;
        body mass { mass = 1.0; }
        TOG[mass] = Trotz(theta) * Tdisp(0, -r, 0);
        spring(ground, mass, k = k, l0 = 1);
        gravity(0, -9.81, 0);
    }
}
