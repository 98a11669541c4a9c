//! sprung_arm: a double pendulum held up by rotational springs with rest angles, three of its
//! parameters marked `sensitive` (the model of the sensitivity tests and example).

mbs::multibody! {
    /// A double pendulum held up by rotational springs with rest angles: its equilibrium sags
    /// under gravity by an amount every parameter changes; a damper at the shoulder.
    pub model SprungArm {
        param l = 0.8 sensitive; param m = 1.5 sensitive; param k1 = 40.0 sensitive;
        param k2 = 25.0; param g = 9.81;
        let i_bar = m * l * l / 12;
        option tangents;
        dof a = 0.4; dof b = -0.2;
        body bar1 { mass = m; inertia = (i_bar, 0, i_bar); }
        body bar2 { mass = 0.5 * m; inertia = (0.5 * i_bar, 0, 0.5 * i_bar); }
        TOG[bar1] = Trotz(a) * Tdisp(l / 2, 0, 0);
        TOG[bar2] = TOG[bar1] * Tdisp(l / 2, 0, 0) * Trotz(b) * Tdisp(l / 2, 0, 0);
        gravity(0, -g, 0);
        rotational_spring(ground, bar1, axis = z, k = k1, angle0 = 0.6, c = 0.3);
        rotational_spring(bar1, bar2, axis = z, k = k2, angle0 = 0.3);
    }
}
