//! hexapod: a 24-dof, 49-body walking robot in the spirit of the seed's AMRU5
//! (`tests/reference/MODELS.md`). Used by `examples/hexapod.rs`, `tests/hexapod_model.rs`,
//! `tests/hexapod_standing.rs` and the benchmarks.
//!
//! Legs are numbered k = 2i + j with the hip at (hx_i, hy_j, 0) in the base frame,
//! hx = (0.4, 0, −0.4), hy = (0.3, −0.3): 0 front left, 1 front right, 2 middle left, … 5 rear
//! right. Every leg has the dofs a_k (hip yaw), b_k (thigh pitch), c_k (knee pitch) and eight
//! bodies; the pantograph link and coupler follow their products literally (no closed loop),
//! the motor rotors turn 100 times as fast as their joints.
//!
//! Two scenes: `Free` (gravity only; also named `Hexapod`, the type of the contact-free
//! figures) and `Standing` (`HexapodStanding`: the feet's ground contact and a PD controller
//! on every leg joint). Dropped from the start, the standing robot comes to rest in about
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
        TOG[base] = Tdisp(x, y, z) * Trotz(psi) * Troty(theta) * Trotx(phi);

        // Leg 0, front left: hip at (0.4, 0.3, 0).
        dof a0 = 0.0; dof b0 = 0.3; dof c0 = -0.3;
        body support0 { mass = m_support; inertia = (i_support, i_support, i_support); }
        body thigh0 { mass = m_thigh; inertia = (0, i_thigh, i_thigh); }
        body shank0 { mass = m_shank; inertia = (i_shank, i_shank, 0); }
        body panto0 { mass = m_panto; inertia = (0, i_panto, i_panto); }
        body coupler0 { mass = m_coupler; inertia = (i_coupler, i_coupler, 0); }
        body rotor_a0 { mass = m_rotor; inertia = (1e-5, 1e-5, 2e-5); }
        body rotor_b0 { mass = m_rotor; inertia = (1e-5, 2e-5, 1e-5); }
        body rotor_c0 { mass = m_rotor; inertia = (1e-5, 2e-5, 1e-5); }
        TOG[support0] = TOG[base] * Tdisp(0.4, 0.3, 0) * Trotz(a0) * Tdisp(0.05, 0, 0);
        TOG[thigh0] = TOG[support0] * Tdisp(0.05, 0, 0) * Troty(b0) * Tdisp(0.15, 0, 0);
        TOG[shank0] = TOG[thigh0] * Tdisp(0.15, 0, 0) * Troty(c0) * Tdisp(0, 0, -0.2);
        TOG[panto0] = TOG[support0] * Tdisp(0.05, 0, -0.05) * Troty(b0) * Tdisp(0.15, 0, 0);
        TOG[coupler0] = TOG[thigh0] * Tdisp(0.15, 0, 0) * Troty(c0) * Tdisp(0, 0, -0.05);
        TOG[rotor_a0] = TOG[base] * Tdisp(0.4, 0.3, 0.05) * Trotz(100 * a0);
        TOG[rotor_b0] = TOG[support0] * Tdisp(0, 0.05, 0) * Troty(100 * b0);
        TOG[rotor_c0] = TOG[thigh0] * Tdisp(0, 0.05, 0) * Troty(100 * c0);
        point foot0 on shank0 at (0, 0, -0.2);

        // Leg 1, front right: hip at (0.4, -0.3, 0).
        dof a1 = 0.0; dof b1 = 0.3; dof c1 = -0.3;
        body support1 { mass = m_support; inertia = (i_support, i_support, i_support); }
        body thigh1 { mass = m_thigh; inertia = (0, i_thigh, i_thigh); }
        body shank1 { mass = m_shank; inertia = (i_shank, i_shank, 0); }
        body panto1 { mass = m_panto; inertia = (0, i_panto, i_panto); }
        body coupler1 { mass = m_coupler; inertia = (i_coupler, i_coupler, 0); }
        body rotor_a1 { mass = m_rotor; inertia = (1e-5, 1e-5, 2e-5); }
        body rotor_b1 { mass = m_rotor; inertia = (1e-5, 2e-5, 1e-5); }
        body rotor_c1 { mass = m_rotor; inertia = (1e-5, 2e-5, 1e-5); }
        TOG[support1] = TOG[base] * Tdisp(0.4, -0.3, 0) * Trotz(a1) * Tdisp(0.05, 0, 0);
        TOG[thigh1] = TOG[support1] * Tdisp(0.05, 0, 0) * Troty(b1) * Tdisp(0.15, 0, 0);
        TOG[shank1] = TOG[thigh1] * Tdisp(0.15, 0, 0) * Troty(c1) * Tdisp(0, 0, -0.2);
        TOG[panto1] = TOG[support1] * Tdisp(0.05, 0, -0.05) * Troty(b1) * Tdisp(0.15, 0, 0);
        TOG[coupler1] = TOG[thigh1] * Tdisp(0.15, 0, 0) * Troty(c1) * Tdisp(0, 0, -0.05);
        TOG[rotor_a1] = TOG[base] * Tdisp(0.4, -0.3, 0.05) * Trotz(100 * a1);
        TOG[rotor_b1] = TOG[support1] * Tdisp(0, 0.05, 0) * Troty(100 * b1);
        TOG[rotor_c1] = TOG[thigh1] * Tdisp(0, 0.05, 0) * Troty(100 * c1);
        point foot1 on shank1 at (0, 0, -0.2);

        // Leg 2, middle left: hip at (0, 0.3, 0).
        dof a2 = 0.0; dof b2 = 0.3; dof c2 = -0.3;
        body support2 { mass = m_support; inertia = (i_support, i_support, i_support); }
        body thigh2 { mass = m_thigh; inertia = (0, i_thigh, i_thigh); }
        body shank2 { mass = m_shank; inertia = (i_shank, i_shank, 0); }
        body panto2 { mass = m_panto; inertia = (0, i_panto, i_panto); }
        body coupler2 { mass = m_coupler; inertia = (i_coupler, i_coupler, 0); }
        body rotor_a2 { mass = m_rotor; inertia = (1e-5, 1e-5, 2e-5); }
        body rotor_b2 { mass = m_rotor; inertia = (1e-5, 2e-5, 1e-5); }
        body rotor_c2 { mass = m_rotor; inertia = (1e-5, 2e-5, 1e-5); }
        TOG[support2] = TOG[base] * Tdisp(0, 0.3, 0) * Trotz(a2) * Tdisp(0.05, 0, 0);
        TOG[thigh2] = TOG[support2] * Tdisp(0.05, 0, 0) * Troty(b2) * Tdisp(0.15, 0, 0);
        TOG[shank2] = TOG[thigh2] * Tdisp(0.15, 0, 0) * Troty(c2) * Tdisp(0, 0, -0.2);
        TOG[panto2] = TOG[support2] * Tdisp(0.05, 0, -0.05) * Troty(b2) * Tdisp(0.15, 0, 0);
        TOG[coupler2] = TOG[thigh2] * Tdisp(0.15, 0, 0) * Troty(c2) * Tdisp(0, 0, -0.05);
        TOG[rotor_a2] = TOG[base] * Tdisp(0, 0.3, 0.05) * Trotz(100 * a2);
        TOG[rotor_b2] = TOG[support2] * Tdisp(0, 0.05, 0) * Troty(100 * b2);
        TOG[rotor_c2] = TOG[thigh2] * Tdisp(0, 0.05, 0) * Troty(100 * c2);
        point foot2 on shank2 at (0, 0, -0.2);

        // Leg 3, middle right: hip at (0, -0.3, 0).
        dof a3 = 0.0; dof b3 = 0.3; dof c3 = -0.3;
        body support3 { mass = m_support; inertia = (i_support, i_support, i_support); }
        body thigh3 { mass = m_thigh; inertia = (0, i_thigh, i_thigh); }
        body shank3 { mass = m_shank; inertia = (i_shank, i_shank, 0); }
        body panto3 { mass = m_panto; inertia = (0, i_panto, i_panto); }
        body coupler3 { mass = m_coupler; inertia = (i_coupler, i_coupler, 0); }
        body rotor_a3 { mass = m_rotor; inertia = (1e-5, 1e-5, 2e-5); }
        body rotor_b3 { mass = m_rotor; inertia = (1e-5, 2e-5, 1e-5); }
        body rotor_c3 { mass = m_rotor; inertia = (1e-5, 2e-5, 1e-5); }
        TOG[support3] = TOG[base] * Tdisp(0, -0.3, 0) * Trotz(a3) * Tdisp(0.05, 0, 0);
        TOG[thigh3] = TOG[support3] * Tdisp(0.05, 0, 0) * Troty(b3) * Tdisp(0.15, 0, 0);
        TOG[shank3] = TOG[thigh3] * Tdisp(0.15, 0, 0) * Troty(c3) * Tdisp(0, 0, -0.2);
        TOG[panto3] = TOG[support3] * Tdisp(0.05, 0, -0.05) * Troty(b3) * Tdisp(0.15, 0, 0);
        TOG[coupler3] = TOG[thigh3] * Tdisp(0.15, 0, 0) * Troty(c3) * Tdisp(0, 0, -0.05);
        TOG[rotor_a3] = TOG[base] * Tdisp(0, -0.3, 0.05) * Trotz(100 * a3);
        TOG[rotor_b3] = TOG[support3] * Tdisp(0, 0.05, 0) * Troty(100 * b3);
        TOG[rotor_c3] = TOG[thigh3] * Tdisp(0, 0.05, 0) * Troty(100 * c3);
        point foot3 on shank3 at (0, 0, -0.2);

        // Leg 4, rear left: hip at (-0.4, 0.3, 0).
        dof a4 = 0.0; dof b4 = 0.3; dof c4 = -0.3;
        body support4 { mass = m_support; inertia = (i_support, i_support, i_support); }
        body thigh4 { mass = m_thigh; inertia = (0, i_thigh, i_thigh); }
        body shank4 { mass = m_shank; inertia = (i_shank, i_shank, 0); }
        body panto4 { mass = m_panto; inertia = (0, i_panto, i_panto); }
        body coupler4 { mass = m_coupler; inertia = (i_coupler, i_coupler, 0); }
        body rotor_a4 { mass = m_rotor; inertia = (1e-5, 1e-5, 2e-5); }
        body rotor_b4 { mass = m_rotor; inertia = (1e-5, 2e-5, 1e-5); }
        body rotor_c4 { mass = m_rotor; inertia = (1e-5, 2e-5, 1e-5); }
        TOG[support4] = TOG[base] * Tdisp(-0.4, 0.3, 0) * Trotz(a4) * Tdisp(0.05, 0, 0);
        TOG[thigh4] = TOG[support4] * Tdisp(0.05, 0, 0) * Troty(b4) * Tdisp(0.15, 0, 0);
        TOG[shank4] = TOG[thigh4] * Tdisp(0.15, 0, 0) * Troty(c4) * Tdisp(0, 0, -0.2);
        TOG[panto4] = TOG[support4] * Tdisp(0.05, 0, -0.05) * Troty(b4) * Tdisp(0.15, 0, 0);
        TOG[coupler4] = TOG[thigh4] * Tdisp(0.15, 0, 0) * Troty(c4) * Tdisp(0, 0, -0.05);
        TOG[rotor_a4] = TOG[base] * Tdisp(-0.4, 0.3, 0.05) * Trotz(100 * a4);
        TOG[rotor_b4] = TOG[support4] * Tdisp(0, 0.05, 0) * Troty(100 * b4);
        TOG[rotor_c4] = TOG[thigh4] * Tdisp(0, 0.05, 0) * Troty(100 * c4);
        point foot4 on shank4 at (0, 0, -0.2);

        // Leg 5, rear right: hip at (-0.4, -0.3, 0).
        dof a5 = 0.0; dof b5 = 0.3; dof c5 = -0.3;
        body support5 { mass = m_support; inertia = (i_support, i_support, i_support); }
        body thigh5 { mass = m_thigh; inertia = (0, i_thigh, i_thigh); }
        body shank5 { mass = m_shank; inertia = (i_shank, i_shank, 0); }
        body panto5 { mass = m_panto; inertia = (0, i_panto, i_panto); }
        body coupler5 { mass = m_coupler; inertia = (i_coupler, i_coupler, 0); }
        body rotor_a5 { mass = m_rotor; inertia = (1e-5, 1e-5, 2e-5); }
        body rotor_b5 { mass = m_rotor; inertia = (1e-5, 2e-5, 1e-5); }
        body rotor_c5 { mass = m_rotor; inertia = (1e-5, 2e-5, 1e-5); }
        TOG[support5] = TOG[base] * Tdisp(-0.4, -0.3, 0) * Trotz(a5) * Tdisp(0.05, 0, 0);
        TOG[thigh5] = TOG[support5] * Tdisp(0.05, 0, 0) * Troty(b5) * Tdisp(0.15, 0, 0);
        TOG[shank5] = TOG[thigh5] * Tdisp(0.15, 0, 0) * Troty(c5) * Tdisp(0, 0, -0.2);
        TOG[panto5] = TOG[support5] * Tdisp(0.05, 0, -0.05) * Troty(b5) * Tdisp(0.15, 0, 0);
        TOG[coupler5] = TOG[thigh5] * Tdisp(0.15, 0, 0) * Troty(c5) * Tdisp(0, 0, -0.05);
        TOG[rotor_a5] = TOG[base] * Tdisp(-0.4, -0.3, 0.05) * Trotz(100 * a5);
        TOG[rotor_b5] = TOG[support5] * Tdisp(0, 0.05, 0) * Troty(100 * b5);
        TOG[rotor_c5] = TOG[thigh5] * Tdisp(0, 0.05, 0) * Troty(100 * c5);
        point foot5 on shank5 at (0, 0, -0.2);

        gravity(0, 0, -g);

        // Ground contact of the six feet with the plane z = 0 (MODELS.md).
        effect contact {
            contact(foot0, k = k_contact, c = c_contact, mu = mu, eps = eps);
            contact(foot1, k = k_contact, c = c_contact, mu = mu, eps = eps);
            contact(foot2, k = k_contact, c = c_contact, mu = mu, eps = eps);
            contact(foot3, k = k_contact, c = c_contact, mu = mu, eps = eps);
            contact(foot4, k = k_contact, c = c_contact, mu = mu, eps = eps);
            contact(foot5, k = k_contact, c = c_contact, mu = mu, eps = eps);
        }

        // A PD controller on each of the 18 leg joints, holding the start angles.
        effect pd {
            generalized_force(a0, -kp_a * (a0 - a_ref) - kd_a * qd[a0]);
            generalized_force(b0, -kp_b * (b0 - b_ref) - kd_b * qd[b0]);
            generalized_force(c0, -kp_c * (c0 - c_ref) - kd_c * qd[c0]);
            generalized_force(a1, -kp_a * (a1 - a_ref) - kd_a * qd[a1]);
            generalized_force(b1, -kp_b * (b1 - b_ref) - kd_b * qd[b1]);
            generalized_force(c1, -kp_c * (c1 - c_ref) - kd_c * qd[c1]);
            generalized_force(a2, -kp_a * (a2 - a_ref) - kd_a * qd[a2]);
            generalized_force(b2, -kp_b * (b2 - b_ref) - kd_b * qd[b2]);
            generalized_force(c2, -kp_c * (c2 - c_ref) - kd_c * qd[c2]);
            generalized_force(a3, -kp_a * (a3 - a_ref) - kd_a * qd[a3]);
            generalized_force(b3, -kp_b * (b3 - b_ref) - kd_b * qd[b3]);
            generalized_force(c3, -kp_c * (c3 - c_ref) - kd_c * qd[c3]);
            generalized_force(a4, -kp_a * (a4 - a_ref) - kd_a * qd[a4]);
            generalized_force(b4, -kp_b * (b4 - b_ref) - kd_b * qd[b4]);
            generalized_force(c4, -kp_c * (c4 - c_ref) - kd_c * qd[c4]);
            generalized_force(a5, -kp_a * (a5 - a_ref) - kd_a * qd[a5]);
            generalized_force(b5, -kp_b * (b5 - b_ref) - kd_b * qd[b5]);
            generalized_force(c5, -kp_c * (c5 - c_ref) - kd_c * qd[c5]);
        }

        scene Free = [];
        scene Standing = [contact, pd];
    }
}

/// The hexapod without contact or controllers (gravity only): the type of the contact-free
/// figures (M+h 5,760 flops).
pub type Hexapod = HexapodFree;
