//! fastlink: a fast two-loop linkage of five light bodies, thrown by a stiff spring
//! (`tests/reference/MODELS.md`), in the spirit of Andrews' squeezing mechanism: accelerations
//! of bodies up to 6.6e4 m/s² and angular speeds up to 1,460 rad/s within its 30 ms. Reference:
//! `tests/reference/fastlink.json` (computed outside mbs by `tests/reference/fastlink.py`).
//!
//! Planar, in the vertical x–y plane, gravity (0, −9.81, 0). Bodies, all uniform bars (centre
//! at mid-length, inertia m l²/12 about z) except the slider, a point mass:
//!
//! | body | length | mass | joints |
//! |---|---|---|---|
//! | crank | l1 = 0.02 m | 4 g | hinged to the ground at O = (0, 0) |
//! | coupler | l2 = 0.05 m | 8 g | hinged to the crank's tip |
//! | rocker | l3 = 0.04 m | 6 g | hinged to the ground at C = (0.06, 0) |
//! | rod | l4 = 0.06 m | 5 g | hinged to the rocker's tip |
//! | slider | — | 15 g | on the x axis, hinged to the rod's end |
//!
//! Two loops: the four-bar O–crank–coupler–rocker–C (a Grashof crank-rocker, transmission
//! angle 51°–125°) is closed where the coupler's end meets the rocker's tip (`close`), and
//! the rocker's tip drives the slider through the rod (`pin`). Five coordinates, absolute
//! angles from +x counter-clockwise — `a` (crank), `b` (coupler), `c` (rocker), `e` (rod) —
//! and the slider's position `s`; four constraints, one degree of freedom.
//!
//! Forces: a spring of k = 2·10⁴ N/m, rest length 0.04 m, from the ground point (0, 0.07) to
//! the coupler's centre (stretched 21.8 mm at the start: 436 N on an 8 g bar), and a constant
//! motor torque of 0.05 N·m on the crank. Start: crank at a = 0, everything at rest, the loops
//! closed on the branch with the coupler above the x axis ([`closed_loop`]: b = 0.8955,
//! c = 1.7910, e = −0.7083, s = 0.0970). Released, the spring swings the crank to about
//! 3.3 rad and back every 9 ms; run to t_end = 0.03 s.

mbs::multibody! {
    /// The fast linkage: crank `a`, coupler `b`, rocker `c`, rod `e` (absolute angles),
    /// slider `s`; `close: coincide(coupler_end, rocker_tip, along = [x, y])` and
    /// `pin: coincide(rod_end, slider, along = [x, y])`. λ of `close.x`, `close.y` is the
    /// force the coupler applies to the rocker, λ of `pin.x`, `pin.y` the force the rod
    /// applies to the slider.
    pub model FastLink {
        param d = 0.06; param l1 = 0.02; param l2 = 0.05; param l3 = 0.04; param l4 = 0.06;
        param m1 = 0.004; param m2 = 0.008; param m3 = 0.006; param m4 = 0.005;
        param m5 = 0.015;
        param k = 2.0e4; param l0 = 0.04; param tau = 0.05; param g = 9.81;
        // rough guesses for b, c, e, s: the assembly closes both loops from them
        dof a = 0.0, independent;
        dof b = 0.9;
        dof c = 1.8;
        dof e = -0.7;
        dof s = 0.1;
        body crank { mass = m1; inertia = (0, m1 * l1 * l1 / 12, m1 * l1 * l1 / 12); }
        body coupler { mass = m2; inertia = (0, m2 * l2 * l2 / 12, m2 * l2 * l2 / 12); }
        body rocker { mass = m3; inertia = (0, m3 * l3 * l3 / 12, m3 * l3 * l3 / 12); }
        body rod { mass = m4; inertia = (0, m4 * l4 * l4 / 12, m4 * l4 * l4 / 12); }
        body slider { mass = m5; }
        point coupler_end on coupler at (l2 / 2, 0, 0);
        point rocker_tip on rocker at (l3 / 2, 0, 0);
        point rod_end on rod at (l4 / 2, 0, 0);
        point anchor on ground at (0, 0.07, 0);
        TOG[crank] = Trotz(a) * Tdisp(l1 / 2, 0, 0);
        // the coupler hinged at the crank's tip, at its absolute angle b
        TOG[coupler] = Tdisp(l1 * cos(a), l1 * sin(a), 0) * Trotz(b) * Tdisp(l2 / 2, 0, 0);
        TOG[rocker] = Tdisp(d, 0, 0) * Trotz(c) * Tdisp(l3 / 2, 0, 0);
        // the rod hinged at the rocker's tip, at its absolute angle e
        TOG[rod] = Tdisp(d + l3 * cos(c), l3 * sin(c), 0) * Trotz(e) * Tdisp(l4 / 2, 0, 0);
        TOG[slider] = Tdisp(s, 0, 0);
        gravity(0, -g, 0);
        spring(anchor, coupler, k = k, l0 = l0);
        torque(crank, axis = z, tau);
        constraint close: coincide(coupler_end, rocker_tip, along = [x, y]);
        constraint pin: coincide(rod_end, slider, along = [x, y]);
    }
}

/// Both loops closed for the default dimensions: (b, c, e, s) for crank angle `a`, on the
/// branch with the coupler–rocker pin on the left of the line from the crank's tip to the
/// rocker's pivot (the coupler above the x axis) and the slider to the right of the rocker's
/// tip.
pub fn closed_loop(a: f64) -> (f64, f64, f64, f64) {
    let (d, l1, l2, l3, l4) = (0.06, 0.02, 0.05, 0.04, 0.06);
    let (ax, ay) = (l1 * a.cos(), l1 * a.sin());
    let (ux, uy) = (d - ax, -ay);
    let dist = ux.hypot(uy);
    let along = (dist * dist + l2 * l2 - l3 * l3) / (2.0 * dist);
    let across = (l2 * l2 - along * along).sqrt();
    let (ex, ey) = (ux / dist, uy / dist);
    let (px, py) = (ax + along * ex - across * ey, ay + along * ey + across * ex);
    let e = -(py / l4).asin();
    (
        (py - ay).atan2(px - ax),
        py.atan2(px - d),
        e,
        px + l4 * e.cos(),
    )
}
