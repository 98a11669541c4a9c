//! A free body with contacts and every kind of function the generated code may call, with
//! `option batch;`: the model of the batch functions' tests (`tests/batch.rs`) and of an
//! ensemble of a free body (`tests/ensemble.rs`).

/// A push of the arm that is a Rust function of its angle.
pub fn push(x: f64) -> f64 {
    0.2 * x.tanh()
}

mbs::multibody! {
    /// A box on a free joint touching the ground at two corners, with an arm on a hinge
    /// pushed by a Rust function of its angle, an input and a force varying in time.
    pub model Mixed {
        param k = 1e4; param c = 50.0; param mu = 0.6; param g = 9.81;
        extern fn push = [push];
        dof x = 0.1; dof y = -0.05; dof z = 0.02, qd = -0.3;
        dof a = 0.2; dof b = -0.1; dof r = 0.3, qd = 1.5;
        dof hinge = 0.4, qd = -2.0;
        input torque;
        body base { mass = 2.0; inertia = (0.02, 0.03, 0.04); }
        body arm { mass = 0.5; inertia = (0.001, 0.01, 0.01); }
        point corner0 on base at (0.1, 0.05, -0.03);
        point corner1 on base at (-0.1, -0.05, -0.03);
        TOG[base] = Tfree(x, y, z, a, b, r);
        TOG[arm] = TOG[base] * Tdisp(0.1, 0, 0.05) * Troty(hinge) * Tdisp(0.15, 0, 0);
        gravity(0, 0, -g);
        contact(corner0, k = k, c = c, mu = mu);
        contact(corner1, k = k, c = c, mu = mu);
        generalized_force(hinge, push(hinge) + torque + 0.1 * sin(3 * t) - 0.05 * sqrt(1 + hinge * hinge) - 0.01 * atan2(z, 0.3 + x));
        option batch;
    }
}
