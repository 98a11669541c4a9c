//! A pendulum pushed by a generalized force that is not defined everywhere in time (the
//! square root of a negative number): the failure cases of a user's force.

mbs::multibody! {
    /// A pendulum pushed by a force that is not defined after t = 0.5 (sqrt of a negative).
    pub model LateForce {
        dof theta = 0.3;
        body bob { mass = 1.0; inertia = (0.01, 0.01, 0.01); }
        TOG[bob] = Trotz(theta) * Tdisp(0, -1, 0);
        gravity(0, -9.81, 0);
        generalized_force(theta, sqrt(0.5 - t));
    }
}

mbs::multibody! {
    /// The same pendulum with a force that is not defined at the start already.
    pub model EarlyForce {
        dof theta = 0.3;
        body bob { mass = 1.0; inertia = (0.01, 0.01, 0.01); }
        TOG[bob] = Trotz(theta) * Tdisp(0, -1, 0);
        gravity(0, -9.81, 0);
        generalized_force(theta, sqrt(t - 0.5));
    }
}
