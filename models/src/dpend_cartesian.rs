//! dpend in Cartesian coordinates: the planar double pendulum of `tests/reference/MODELS.md`
//! with each bar free in the plane (x, y of its centre, θ its absolute angle) and the hinges
//! as four constraints. Used by `examples/dpend_cartesian.rs` and the tests.
//!
//! θ is measured as dpend's `q[0]`: from the downward vertical, counter-clockwise about +z; so
//! θ1 = `q[0]` and θ2 = `q[0] + q[1]` of [`dpend`](crate::dpend).

mbs::multibody! {
    /// Double pendulum of two uniform bars (1 m, 1 kg) in 6 Cartesian coordinates,
    /// `top: coincide(top1, ground)` and `knee: coincide(top2, bottom1)` along x and y. λ of
    /// `top.x`, `top.y` is the force bar 1 applies to the ground (the hinge's force on bar 1
    /// is −λ); λ of `knee.x`, `knee.y` the force bar 2 applies to bar 1 (−λ on bar 2).
    pub model DoublePendulumCartesian {
        param l = 1.0; param m = 1.0; param g = 9.81;
        // uniform bar along its y axis: m l²/12 about x and z, 0 about its own axis
        let i_bar = m * l * l / 12;
        // start: both bars horizontal along +x (dpend's q = (π/2, 0))
        dof x1 = 0.5; dof y1 = 0.0; dof th1 = PI / 2, independent;
        dof x2 = 1.5; dof y2 = 0.0; dof th2 = PI / 2, independent;
        body bar1 { mass = m; inertia = (i_bar, 0, i_bar); }
        body bar2 { mass = m; inertia = (i_bar, 0, i_bar); }
        TOG[bar1] = Tdisp(x1, y1, 0) * Trotz(th1);
        TOG[bar2] = Tdisp(x2, y2, 0) * Trotz(th2);
        point top1 on bar1 at (0, l / 2, 0);
        point bottom1 on bar1 at (0, -l / 2, 0);
        point top2 on bar2 at (0, l / 2, 0);
        point tip on bar2 at (0, -l / 2, 0);
        gravity(0, -g, 0);
        constraint top: coincide(top1, ground, along = [x, y]);
        constraint knee: coincide(top2, bottom1, along = [x, y]);
    }
}

/// The tip of bar 2 (x, y) from the Cartesian coordinates, l = 1 m.
pub fn tip(q: &[f64]) -> (f64, f64) {
    (q[3] + 0.5 * q[5].sin(), q[4] - 0.5 * q[5].cos())
}

/// The state (q, qd) of [`DoublePendulumCartesian`] from a state of
/// [`dpend`](crate::dpend) (relative angles q0, q1 and their rates), l = 1 m: the bars'
/// centres and absolute angles θ1 = q0, θ2 = q0 + q1, then their rates.
pub fn from_relative(y: &[f64]) -> Vec<f64> {
    let (a, b, ad, bd) = (y[0], y[0] + y[1], y[2], y[2] + y[3]);
    let (x1, y1) = (0.5 * a.sin(), -0.5 * a.cos());
    let (x2, y2) = (a.sin() + 0.5 * b.sin(), -a.cos() - 0.5 * b.cos());
    let (x1d, y1d) = (0.5 * a.cos() * ad, 0.5 * a.sin() * ad);
    let (x2d, y2d) = (
        a.cos() * ad + 0.5 * b.cos() * bd,
        a.sin() * ad + 0.5 * b.sin() * bd,
    );
    vec![x1, y1, a, x2, y2, b, x1d, y1d, ad, x2d, y2d, bd]
}
