//! slidercrank: a crank, a connecting rod and a slider on the x axis
//! (`tests/reference/MODELS.md`), written twice. Used by `examples/slidercrank.rs` and the
//! tests.
//!
//! - [`SliderCrank`], form (a): three coordinates (crank angle θ, the rod's absolute angle
//!   ψ, the slider's position s) and the loop closed at the slider's pin by two constraints,
//!   `pin.x` and `pin.y`; θ is kept when the start is assembled.
//! - [`SliderCrankClosed`], form (b): θ alone, the loop solved in closed form,
//!   ψ = −asin(r sin θ / l) and s = r cos θ + l cos ψ.
//!
//! Crank: uniform bar r = 0.1 m, 0.5 kg, hinged at the origin about z. Rod: uniform bar
//! l = 0.3 m, 1.0 kg, hinged to the crank tip. Slider: a 2.0 kg point mass on the x axis,
//! hinged to the rod's end. No gravity, no torque. θ(0) = 0 (dead centre), θ'(0) = 10 rad/s.

mbs::multibody! {
    /// Slider-crank, form (a): θ (crank), ψ (rod, absolute, from +x), s (slider along x),
    /// closed by `pin: coincide(rod_end, slider, along = [x, y])`. λ of `pin.x` is the x force
    /// the rod applies to the slider, λ of `pin.y` the y force (the slider's guide carries
    /// none in this model: the constraint holds it on the x axis).
    pub model SliderCrank {
        param r = 0.1; param l = 0.3;
        param m_crank = 0.5; param m_rod = 1.0; param m_slider = 2.0;
        // ψ'(0) = −r θ'/l at the dead centre, s'(0) = 0: the assembly computes them anyway
        dof theta = 0.0, qd = 10.0, independent;
        dof psi = 0.0, qd = -10.0 / 3.0;
        dof s = 0.4;
        // uniform bars along their x axis: m l²/12 about y and z, 0 about their own axis
        body crank { mass = m_crank; inertia = (0, m_crank * r * r / 12, m_crank * r * r / 12); }
        body rod { mass = m_rod; inertia = (0, m_rod * l * l / 12, m_rod * l * l / 12); }
        body slider { mass = m_slider; }
        point crank_tip on crank at (r / 2, 0, 0);
        point rod_end on rod at (l / 2, 0, 0);
        TOG[crank] = Trotz(theta) * Tdisp(r / 2, 0, 0);
        // the rod hinged at the crank tip, at its absolute angle ψ
        TOG[rod] = Tdisp(r * cos(theta), r * sin(theta), 0) * Trotz(psi) * Tdisp(l / 2, 0, 0);
        TOG[slider] = Tdisp(s, 0, 0);
        constraint pin: coincide(rod_end, slider, along = [x, y]);
    }
}

mbs::multibody! {
    /// Slider-crank, form (b): θ alone; the rod's angle ψ = −asin(r sin θ / l) and the
    /// slider's position s = r cos θ + l cos ψ are the closed-form solution of the loop.
    pub model SliderCrankClosed {
        param r = 0.1; param l = 0.3;
        param m_crank = 0.5; param m_rod = 1.0; param m_slider = 2.0;
        dof theta = 0.0, qd = 10.0;
        let psi = -asin(r * sin(theta) / l);
        body crank { mass = m_crank; inertia = (0, m_crank * r * r / 12, m_crank * r * r / 12); }
        body rod { mass = m_rod; inertia = (0, m_rod * l * l / 12, m_rod * l * l / 12); }
        body slider { mass = m_slider; }
        point crank_tip on crank at (r / 2, 0, 0);
        point rod_end on rod at (l / 2, 0, 0);
        TOG[crank] = Trotz(theta) * Tdisp(r / 2, 0, 0);
        TOG[rod] = Tdisp(r * cos(theta), r * sin(theta), 0) * Trotz(psi) * Tdisp(l / 2, 0, 0);
        TOG[slider] = Tdisp(r * cos(theta) + l * cos(psi), 0, 0);
    }
}

/// The closed-form loop (form (b)): the rod's angle ψ(θ) and the slider's position s(θ) for
/// the default r = 0.1 m, l = 0.3 m.
pub fn closed_loop(theta: f64) -> (f64, f64) {
    let (r, l) = (0.1, 0.3);
    let psi = -(r * theta.sin() / l).asin();
    (psi, r * theta.cos() + l * psi.cos())
}

/// Form (a)'s state (θ, ψ, s, θ̇, ψ̇, ṡ) from form (b)'s (θ, θ̇), by [`closed_loop`] and its
/// derivative: how a reference computed on form (b) is compared with form (a).
pub fn form_a_state(theta: f64, theta_d: f64) -> [f64; 6] {
    let (r, l) = (0.1, 0.3);
    let (psi, s) = closed_loop(theta);
    let psi_d = -r * theta.cos() * theta_d / (l * psi.cos());
    let s_d = -r * theta.sin() * theta_d - l * psi.sin() * psi_d;
    [theta, psi, s, theta_d, psi_d, s_d]
}
