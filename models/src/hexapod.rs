//! hexapod: a 24-dof, 49-body walking robot in the spirit of the seed's AMRU5
//! (`tests/reference/MODELS.md`). Used by `examples/hexapod.rs`, `tests/hexapod_model.rs`,
//! `tests/hexapod_standing.rs`, `tests/hexapod_somersault.rs` and the benchmarks.
//!
//! The base is on a free joint, `Tfree(x, y, z, psi, theta, phi)`: (x, y, z) its position in
//! world axes, (psi, theta, phi) ZYX angles in a chart the runtime re-centres before the
//! pitch theta reaches ±90°, so the robot may turn over. The points `corner[0..8]` are the
//! base's corners (±0.5, ±0.3, ±0.075).
//!
//! Legs are numbered k = 2i + j with the hip at (hx_i, hy_j, 0) in the base frame,
//! hx = (0.4, 0, −0.4), hy = (0.3, −0.3): 0 front left, 1 front right, 2 middle left, … 5 rear
//! right. Every leg is an instance of `part Leg(k, hx, hy)`: the dofs `a[k]` (hip yaw), `b[k]`
//! (thigh pitch), `c[k]` (knee pitch), eight bodies (`support[k]`, `thigh[k]`, `shank[k]`,
//! `panto[k]`, `coupler[k]`, `rotor_a[k]`, `rotor_b[k]`, `rotor_c[k]`) and the point `foot[k]`;
//! the pantograph link and coupler follow their products literally (no closed loop), the motor
//! rotors turn 100 times as fast as their joints.
//!
//! Three scenes: `Free` (gravity only; also named `Hexapod`, the type of the contact-free
//! figures), `Standing` (`HexapodStanding`: the feet's ground contact and a PD controller
//! on every leg joint) and `Tumbling` (`HexapodTumbling`: `Standing` with the base's corners
//! in ground contact too, for a robot that lands on its back or side). Dropped from the start, the standing robot comes to rest in about
//! 2.5 s on its middle and rear feet: every leg points forward (+x) from its hip, so the feet
//! stand in rows at x ≈ 0.78, 0.38, −0.01 m and the centre of mass (x ≈ 0.09 m) is behind the
//! middle row; the front feet hang 0.6 mm above the ground.
//!
//! Choice of the coefficients (poles of the linearisation at rest and 5 s runs with Radau5 at
//! rtol 1e-6, as in `tests/hexapod_standing.rs`):
//!
//! - `eps` = 1e-2 m/s. Regularised friction has no static friction: at rest it is a viscous
//!   damper μ F_n/eps per foot, and the legs' tangential preloads left by the landing relax
//!   by creep at about K_h·eps/(μ F_n), K_h ≈ 4e4 N/m the horizontal stiffness of a leg at
//!   its foot (Kp/0.49²), F_n ≈ 120 N: 4/s here (the slowest pole of the linearisation at
//!   rest, −3.98/s), so the velocities fall below 1e-6 within 2.5 s. With eps = 3e-3 the
//!   slowest pole is −1.3/s (max |qd| 3e-6 at t = 5 s), with 1e-3 −0.46/s (7e-5 at 5 s).
//! - Kp = 1e4 N m/rad on every joint. At rest the rear thighs hold 32 N m (122 N on a foot
//!   0.29 m ahead of the pitch axis, less the leg's own weight), the middle ones 10 N m, the
//!   hanging front ones −3.5 N m; the knees almost nothing (the shank is vertical) and the hip
//!   yaws nothing. The rear thighs give 3.2 mrad (1 mm at the foot); the knees' stiffness is
//!   200 times the geometric softening F_n·l_shank ≈ 50 N m/rad. A softer servo creeps longer
//!   (Kp = 2000: slowest pole −0.77/s, max |qd| 4e-5 at t = 5 s); a stiffer one gains little
//!   (3e4: −5.4/s, but the least damped mode of the base falls to ζ = 0.16).
//! - Kd = 400 N m s/rad: a joint alone (J = 0.23–0.45 kg m², of which the geared rotor's
//!   2e-5 × 100² = 0.2) is critically damped at 2 sqrt(Kp J) ≈ 100–130; what limits the
//!   settling are the base's modes on its legs (pitch 5 Hz, roll 9 Hz, heave 17 Hz), whose
//!   smallest damping ratio is 0.16, 0.22, 0.28, 0.25 at Kd = 100, 200, 400, 800.

mbs::multibody! {
    /// Hexapod walking robot: floating base (x, y, z, psi, theta, phi) and six 3-dof legs.
    pub model Hexapod {
        param g = 9.81;
        param m_base = 20.0;
        param m_support = 0.5;
        param m_thigh = 0.8;
        param m_shank = 0.6;
        param m_panto = 0.2;
        param m_coupler = 0.1;
        param m_rotor = 0.05;

        // Ground contact (MODELS.md): penalty k, damping c, regularised Coulomb friction mu
        // (viscous below eps; eps chosen above, in the module's documentation).
        param k_contact = 1e5;
        param c_contact = 500.0;
        param mu = 0.8;
        param eps = 1e-2;
        // PD joint controllers: references (the start angles) and gains per joint kind
        // (a hip yaw, b thigh pitch, c knee pitch), N m/rad and N m s/rad; the generalised
        // force on each joint is −Kp (q − q_ref) − Kd qd.
        param a_ref = 0.0;
        param b_ref = 0.3;
        param c_ref = -0.3;
        param kp_a = 1e4;
        param kd_a = 400.0;
        param kp_b = 1e4;
        param kd_b = 400.0;
        param kp_c = 1e4;
        param kd_c = 400.0;

        // Centroidal inertias: base box 1.0 × 0.6 × 0.15 m, support cube 0.1 m, uniform bars
        // (m l²/12 about both transverse axes, 0 about their own axis).
        let base_ixx = m_base * (0.6 * 0.6 + 0.15 * 0.15) / 12;
        let base_iyy = m_base * (1.0 * 1.0 + 0.15 * 0.15) / 12;
        let base_izz = m_base * (1.0 * 1.0 + 0.6 * 0.6) / 12;
        let i_support = m_support * (0.1 * 0.1 + 0.1 * 0.1) / 12;
        let i_thigh = m_thigh * 0.3 * 0.3 / 12;
        let i_shank = m_shank * 0.4 * 0.4 / 12;
        let i_panto = m_panto * 0.3 * 0.3 / 12;
        let i_coupler = m_coupler * 0.1 * 0.1 / 12;

        dof x = 0.0; dof y = 0.0; dof z = 0.5;
        dof psi = 0.0; dof theta = 0.0; dof phi = 0.0;
        body base { mass = m_base; inertia = (base_ixx, base_iyy, base_izz); }
        TOG[base] = Tfree(x, y, z, psi, theta, phi);

        // One leg, hip at (hx, hy, 0) in the base frame: hip yaw a[k], thigh pitch b[k], knee
        // pitch c[k]; the pantograph link and coupler follow the thigh and knee angles, the
        // rotors turn 100 times as fast as their joints.
        part Leg(k, hx, hy) {
            dof a[k] = 0.0; dof b[k] = 0.3; dof c[k] = -0.3;
            body support[k] { mass = m_support; inertia = (i_support, i_support, i_support); }
            body thigh[k] { mass = m_thigh; inertia = (0, i_thigh, i_thigh); }
            body shank[k] { mass = m_shank; inertia = (i_shank, i_shank, 0); }
            body panto[k] { mass = m_panto; inertia = (0, i_panto, i_panto); }
            body coupler[k] { mass = m_coupler; inertia = (i_coupler, i_coupler, 0); }
            body rotor_a[k] { mass = m_rotor; inertia = (1e-5, 1e-5, 2e-5); }
            body rotor_b[k] { mass = m_rotor; inertia = (1e-5, 2e-5, 1e-5); }
            body rotor_c[k] { mass = m_rotor; inertia = (1e-5, 2e-5, 1e-5); }
            TOG[support[k]] = TOG[base] * Tdisp(hx, hy, 0) * Trotz(a[k]) * Tdisp(0.05, 0, 0);
            TOG[thigh[k]] = TOG[support[k]] * Tdisp(0.05, 0, 0) * Troty(b[k]) * Tdisp(0.15, 0, 0);
            TOG[shank[k]] = TOG[thigh[k]] * Tdisp(0.15, 0, 0) * Troty(c[k]) * Tdisp(0, 0, -0.2);
            TOG[panto[k]] = TOG[support[k]] * Tdisp(0.05, 0, -0.05) * Troty(b[k]) * Tdisp(0.15, 0, 0);
            TOG[coupler[k]] = TOG[thigh[k]] * Tdisp(0.15, 0, 0) * Troty(c[k]) * Tdisp(0, 0, -0.05);
            TOG[rotor_a[k]] = TOG[base] * Tdisp(hx, hy, 0.05) * Trotz(100 * a[k]);
            TOG[rotor_b[k]] = TOG[support[k]] * Tdisp(0, 0.05, 0) * Troty(100 * b[k]);
            TOG[rotor_c[k]] = TOG[thigh[k]] * Tdisp(0, 0.05, 0) * Troty(100 * c[k]);
            point foot[k] on shank[k] at (0, 0, -0.2);
        }
        Leg(0, 0.4, 0.3);   // front left
        Leg(1, 0.4, -0.3);  // front right
        Leg(2, 0, 0.3);     // middle left
        Leg(3, 0, -0.3);    // middle right
        Leg(4, -0.4, 0.3);  // rear left
        Leg(5, -0.4, -0.3); // rear right

        gravity(0, 0, -g);

        // Ground contact of the six feet with the plane z = 0 (MODELS.md).
        effect contact {
            for i in 0..6 {
                contact(foot[i], k = k_contact, c = c_contact, mu = mu, eps = eps);
            }
        }

        // A PD controller on each of the 18 leg joints, holding the start angles.
        effect pd {
            for i in 0..6 {
                generalized_force(a[i], -kp_a * (a[i] - a_ref) - kd_a * qd[a[i]]);
                generalized_force(b[i], -kp_b * (b[i] - b_ref) - kd_b * qd[b[i]]);
                generalized_force(c[i], -kp_c * (c[i] - c_ref) - kd_c * qd[c[i]]);
            }
        }

        // Ground contact of the base's eight corners, for a robot that lands on its back or
        // side (the scene `Tumbling`).
        for i in 0..2 {
            for j in 0..2 {
                for k in 0..2 {
                    point corner[4 * i + 2 * j + k] on base at (0.5 * (1 - 2 * i), 0.3 * (1 - 2 * j), 0.075 * (1 - 2 * k));
                }
            }
        }
        effect hull {
            for i in 0..8 {
                contact(corner[i], k = k_contact, c = c_contact, mu = mu, eps = eps);
            }
        }

        scene Free = [];
        scene Standing = [contact, pd];
        scene Tumbling = [contact, pd, hull];
    }
}

/// The hexapod without contact or controllers (gravity only): the type of the contact-free
/// figures (M+h 5,887 flops).
pub type Hexapod = HexapodFree;

/// The hexapod thrown: `model`'s declared state (legs at their PD references) with the base
/// 1 m up, pitching at `pitch` rad/s and rolling at 1 rad/s: (q0, qd0).
pub fn thrown<M: mbs::Model>(model: &M, pitch: f64) -> (Vec<f64>, Vec<f64>) {
    let (mut q, mut qd) = (vec![0.0; M::NQ], vec![0.0; M::NQ]);
    model.initial_state(&mut q, &mut qd);
    q[2] = 1.0;
    qd[4] = pitch;
    qd[5] = 1.0;
    (q, qd)
}
