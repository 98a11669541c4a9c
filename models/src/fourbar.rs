//! fourbar: a Grashof crank-rocker (`tests/reference/MODELS.md`). Used by
//! `examples/fourbar.rs` and the tests.
//!
//! Ground link 0.4 m along x (pivots at (0, 0) and (0.4, 0)), crank 0.1 m, coupler 0.35 m,
//! rocker 0.3 m, uniform bars of 1 kg/m, gravity (0, −9.81, 0). Three absolute angles (from
//! +x, counter-clockwise): the crank's `a`, the coupler's `b`, the rocker's `c`; the loop is
//! closed where the coupler meets the rocker's tip. Crank angle π/3 at t = 0 (kept: marked
//! `independent`), crank speed 5 rad/s; `b` and `c` are given roughly, on the branch with the
//! coupler above the x axis, and the assembly closes the loop from them.
//!
//! [`SensitiveFourBar`] is the same mechanism with a rotational spring and damper at the crank
//! (a stable equilibrium) and four parameters marked `sensitive`: the sensitivities of a closed loop
//! (`tests/sensitivity.rs`, `examples/sensitivity.rs`).

mbs::multibody! {
    /// Four-bar crank-rocker: crank `a` at the origin, coupler `b` hinged at the crank tip,
    /// rocker `c` at (0.4, 0), absolute angles; `close: coincide(coupler_end, rocker_tip,
    /// along = [x, y])`. λ of `close.x`, `close.y` is the force the coupler applies to the
    /// rocker at their pin.
    pub model FourBar {
        param l0 = 0.4; param l1 = 0.1; param l2 = 0.35; param l3 = 0.3;
        param rho = 1.0; param g = 9.81;
        // rough guesses for b and c (the closed values are 0.6287 and 1.7958 rad); ḃ and ċ
        // follow from the velocity projection
        dof a = PI / 3, qd = 5.0, independent;
        dof b = 0.6;
        dof c = 1.8;
        // uniform bars along their x axis: m l²/12 about y and z, 0 about their own axis
        let m1 = rho * l1; let m2 = rho * l2; let m3 = rho * l3;
        body crank { mass = m1; inertia = (0, m1 * l1 * l1 / 12, m1 * l1 * l1 / 12); }
        body coupler { mass = m2; inertia = (0, m2 * l2 * l2 / 12, m2 * l2 * l2 / 12); }
        body rocker { mass = m3; inertia = (0, m3 * l3 * l3 / 12, m3 * l3 * l3 / 12); }
        point crank_tip on crank at (l1 / 2, 0, 0);
        point coupler_end on coupler at (l2 / 2, 0, 0);
        point rocker_tip on rocker at (l3 / 2, 0, 0);
        TOG[crank] = Trotz(a) * Tdisp(l1 / 2, 0, 0);
        // the coupler hinged at the crank tip, at its absolute angle b
        TOG[coupler] = TOG[crank] * Tdisp(l1 / 2, 0, 0) * Trotz(b - a) * Tdisp(l2 / 2, 0, 0);
        TOG[rocker] = Tdisp(l0, 0, 0) * Trotz(c) * Tdisp(l3 / 2, 0, 0);
        gravity(0, -g, 0);
        constraint close: coincide(coupler_end, rocker_tip, along = [x, y]);
    }
}

mbs::multibody! {
    /// [`FourBar`] with a rotational spring and a light damper at the crank, so that it has a
    /// stable, damped equilibrium, and its link lengths, density and spring rate marked
    /// `sensitive`.
    pub model SensitiveFourBar {
        param l0 = 0.4; param l1 = 0.1 sensitive; param l2 = 0.35 sensitive; param l3 = 0.3;
        param rho = 1.0 sensitive; param k1 = 2.0 sensitive; param g = 9.81;
        dof a = PI / 3, qd = 5.0, independent;
        dof b = 0.6;
        dof c = 1.8;
        let m1 = rho * l1; let m2 = rho * l2; let m3 = rho * l3;
        body crank { mass = m1; inertia = (0, m1 * l1 * l1 / 12, m1 * l1 * l1 / 12); }
        body coupler { mass = m2; inertia = (0, m2 * l2 * l2 / 12, m2 * l2 * l2 / 12); }
        body rocker { mass = m3; inertia = (0, m3 * l3 * l3 / 12, m3 * l3 * l3 / 12); }
        point coupler_end on coupler at (l2 / 2, 0, 0);
        point rocker_tip on rocker at (l3 / 2, 0, 0);
        TOG[crank] = Trotz(a) * Tdisp(l1 / 2, 0, 0);
        TOG[coupler] = TOG[crank] * Tdisp(l1 / 2, 0, 0) * Trotz(b - a) * Tdisp(l2 / 2, 0, 0);
        TOG[rocker] = Tdisp(l0, 0, 0) * Trotz(c) * Tdisp(l3 / 2, 0, 0);
        gravity(0, -g, 0);
        rotational_spring(ground, crank, axis = z, k = k1, angle0 = 1.0, c = 0.01);
        constraint close: coincide(coupler_end, rocker_tip, along = [x, y]);
        option tangents;
    }
}

/// The closed loop for the default dimensions: (b, c) for crank angle `a` on the branch with
/// the coupler–rocker pin on the left of the line from the crank tip to the rocker pivot (the
/// coupler above the x axis at a = π/3), by intersecting two circles.
pub fn closed_loop(a: f64) -> (f64, f64) {
    let (d, l1, l2, l3) = (0.4, 0.1, 0.35, 0.3);
    let (ax, ay) = (l1 * a.cos(), l1 * a.sin());
    let (ux, uy) = (d - ax, -ay);
    let dist = ux.hypot(uy);
    let along = (dist * dist + l2 * l2 - l3 * l3) / (2.0 * dist);
    let across = (l2 * l2 - along * along).sqrt();
    let (ex, ey) = (ux / dist, uy / dist);
    let (px, py) = (ax + along * ex - across * ey, ay + along * ey + across * ex);
    ((py - ay).atan2(px - ax), py.atan2(px - d))
}
