//! Models whose mass matrix is singular by construction, for the hard cases' structural
//! singularities: singular everywhere ([`CoincidentAxes`], [`SpinningPointMass`]) or at a
//! configuration reached during a run ([`SineSlider`]).

mbs::multibody! {
    /// Two revolute joints about the same axis at the same point: q0 and q1 move the bar
    /// exactly alike, M = [[a, a], [a, a]] in every configuration.
    pub model CoincidentAxes {
        dof q[0] = 0.3; dof q[1] = 0.2;
        body bar { mass = 1.0; inertia = (1.0 / 12.0, 0, 1.0 / 12.0); }
        TOG[bar] = Trotz(q[0]) * Trotz(q[1]) * Tdisp(0, -0.5, 0);
        gravity(0, -9.81, 0);
    }
}

mbs::multibody! {
    /// A pendulum whose tip is a point mass turned about its own centre by q1: q1 appears in
    /// the pose of a body with mass (so the generator's "moves no body with mass" check
    /// passes) but moves no mass, as a coordinate of a massless terminal body would.
    pub model SpinningPointMass {
        dof q[0] = 0.3; dof q[1] = 0.0;
        body bar { mass = 1.0; inertia = (1.0 / 12.0, 0, 1.0 / 12.0); }
        body tip { mass = 0.5; }
        TOG[bar] = Trotz(q[0]) * Tdisp(0, -0.5, 0);
        TOG[tip] = TOG[bar] * Tdisp(0, -0.5, 0) * Trotz(q[1]);
        gravity(0, -9.81, 0);
    }
}

mbs::multibody! {
    /// A slider driven through a sine, x = sin q0, coasting at 1 m/s from x = 0: at
    /// q0 = π/2 (t = 1 s) q0 stops moving it (M = cos² q0), a singular configuration reached
    /// during the run.
    pub model SineSlider {
        dof q[0] = 0.0, qd = 1.0;
        option tangents;
        body slider { mass = 1.0; }
        TOG[slider] = Tdisp(sin(q[0]), 0, 0);
    }
}
