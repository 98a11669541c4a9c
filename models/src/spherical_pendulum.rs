//! spherical_pendulum: a ball on a rigid massless rod from a fixed pivot, swinging through the
//! bottom, on a spherical joint ([`SphericalPendulum`]) and on ZYX Euler angles
//! ([`SphericalPendulumZyx`]).
//!
//! The rod is the body x axis; ZYX angles (a, b, c) are singular where body x lies along world
//! z, which here is the bottom of the swing, the pole of the sphere the ball moves on. The
//! ball (a uniform sphere of radius r, so that the spin about the rod carries inertia) starts
//! at rest θ0 = 60° from the bottom in the x–z plane, with a small sideways velocity v0: it
//! swings through the bottom within about v0/ω of it (ω = √(g/l)) and on the other side, a
//! slowly precessing three-dimensional swing. Energy and the vertical angular momentum about
//! the pivot are conserved.

mbs::multibody! {
    /// A ball on a rod from a spherical joint (`Tball`).
    pub model SphericalPendulum {
        param m = 1.0;
        param l = 1.0;
        param r = 0.05;
        param g = 9.81;
        param theta0 = PI / 3;
        param v0 = 1e-3;
        dof a = 0.0, qd = v0 / (l * sin(theta0));
        dof b = PI / 2 - theta0;
        dof c = 0.0;
        option tangents;
        body ball { mass = m; inertia = (0.4 * m * r * r, 0.4 * m * r * r, 0.4 * m * r * r); }
        TOG[ball] = Tball(a, b, c) * Tdisp(l, 0, 0);
        gravity(0, 0, -g);
    }
}

mbs::multibody! {
    /// [`SphericalPendulum`] on ZYX Euler angles: singular at the bottom.
    pub model SphericalPendulumZyx {
        param m = 1.0;
        param l = 1.0;
        param r = 0.05;
        param g = 9.81;
        param theta0 = PI / 3;
        param v0 = 1e-3;
        dof a = 0.0, qd = v0 / (l * sin(theta0));
        dof b = PI / 2 - theta0;
        dof c = 0.0;
        option tangents;
        body ball { mass = m; inertia = (0.4 * m * r * r, 0.4 * m * r * r, 0.4 * m * r * r); }
        TOG[ball] = Trotz(a) * Troty(b) * Trotx(c) * Tdisp(l, 0, 0);
        gravity(0, 0, -g);
    }
}
