//! top: a fast symmetric top on a fixed tip whose axis passes through the vertical, on a
//! spherical joint ([`Top`]) and on ZYX Euler angles ([`TopZyx`]).
//!
//! The top's symmetry axis is its body x axis, its tip at the world origin and its centre of
//! mass at `l` along the axis. ZYX angles (a, b, c) are singular where cos b = 0, that is
//! where body x lies along world z: exactly when the axis is vertical. The start makes the
//! axis pass through the vertical: tilted by θ0 from it, spinning at ω3 about it, with no
//! nutation rate, and precessing at the rate that makes the vertical angular momentum about
//! the tip equal to the spin's, L_z = L_3 (Goldstein's p_φ = p_ψ): then cos θ = 1 is a root
//! of the nutation's effective potential, and when the kinetic energy of the precession
//! exceeds the potential energy the axis must gain, ½ I1' φ̇0² sin² θ0 > m g l (1 − cos θ0)
//! (ω3 above about 125 rad/s here), the axis nutates from θ0 up through the vertical and
//! back. [`TopZyx`] stops with `SingularConfiguration` at the
//! first passage (t ≈ 0.15 s); [`Top`] runs through every one, re-centring its chart.
//!
//! Energy and the vertical angular momentum about the tip are conserved.
//!
//! At the start (a, b, c) = (0, −(π/2 − θ0), 0): body x is (sin θ0, 0, cos θ0), and with
//! the precession rate φ̇0 = I3 ω3 (1 − cos θ0) / (I1' sin² θ0), I1' = I1 + m l² the
//! transverse inertia about the tip, the Euler rates are (φ̇0, 0, ω3 − φ̇0 cos θ0).

mbs::multibody! {
    /// Fast symmetric top on a spherical joint at its tip (`Tball`).
    pub model Top {
        param m = 0.1;
        param l = 0.04;
        param i1 = 2e-5;
        param i3 = 4e-5;
        param g = 9.81;
        param theta0 = 0.7;
        param w3 = 200.0;
        let precession = i3 * w3 * (1 - cos(theta0)) / ((i1 + m * l * l) * powi(sin(theta0), 2));
        dof a = 0.0, qd = precession;
        dof b = -(PI / 2 - theta0);
        dof c = 0.0, qd = w3 - precession * cos(theta0);
        option tangents;
        body top { mass = m; inertia = (i3, i1, i1); }
        TOG[top] = Tball(a, b, c) * Tdisp(l, 0, 0);
        gravity(0, 0, -g);
    }
}

mbs::multibody! {
    /// [`Top`] on ZYX Euler angles: singular where its axis is vertical.
    pub model TopZyx {
        param m = 0.1;
        param l = 0.04;
        param i1 = 2e-5;
        param i3 = 4e-5;
        param g = 9.81;
        param theta0 = 0.7;
        param w3 = 200.0;
        let precession = i3 * w3 * (1 - cos(theta0)) / ((i1 + m * l * l) * powi(sin(theta0), 2));
        dof a = 0.0, qd = precession;
        dof b = -(PI / 2 - theta0);
        dof c = 0.0, qd = w3 - precession * cos(theta0);
        option tangents;
        body top { mass = m; inertia = (i3, i1, i1); }
        TOG[top] = Trotz(a) * Troty(b) * Trotx(c) * Tdisp(l, 0, 0);
        gravity(0, 0, -g);
    }
}
