//! The analyses of constrained models (`M qdd = h + Bᵀλ`, `Φ = 0`) against independent
//! references: Cartesian pendulums (a bar pinned to the ground in (x, y, θ), a point mass on a
//! rod in (x, y)) whose equilibria, pin forces and small oscillations are known in closed
//! form; a four-bar under gravity whose equilibria, reduced stiffness and frequency follow
//! from its potential and kinetic energy along the closed-form loop (an energy method); the
//! state matrix against central differences of the reduced ODE z̈ = f(z, ż), the dependent
//! coordinates completed by this file's own Newton, at rest, off equilibrium, moving and with
//! a rheonomic constraint; inverse dynamics of a slider-crank driven at its crank, fed back as
//! a generalised force and simulated; and the typed errors.
//!
//! Every test prints its measured figures:
//! `cargo test --release --test analysis_constrained -- --nocapture`.
#![allow(clippy::needless_range_loop)]

use mbs::analysis::{
    AnalysisError, Stability, StaticsOptions, inverse_dynamics_actuated_along, linearize, modes,
    static_equilibrium,
};
use mbs::{
    ConstraintMethod, ConstraintOptions, Failure, IterationMatrix, Model, Options, Scheme, simulate,
};
use nalgebra::DMatrix;
use std::f64::consts::PI;

#[path = "common/dense.rs"]
mod dense;
use dense::solve;

// ---------------------------------------------------------------------------------------------
// Models

/// Bar pendulum parameters (also the model's defaults).
const MB: f64 = 1.2;
const LB: f64 = 0.8;
const G: f64 = 9.81;

mbs::multibody! {
    /// A uniform bar (m, l) free in the plane — centre (px, py), angle θ — pinned to the
    /// ground at its top end: `pin: coincide(ground, top, along = [x, y])`, so λ is the force
    /// the pin applies to the bar. Hanging at θ = 0, py = −l/2.
    pub model BarPendulum {
        param m = 1.2; param l = 0.8; param g = 9.81;
        dof px = 0.0; dof py = -0.4; dof theta = 0.0, independent;
        body bar { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        point top on bar at (0, l / 2, 0);
        TOG[bar] = Tdisp(px, py, 0) * Trotz(theta);
        gravity(0, -g, 0);
        constraint pin: coincide(ground, top, along = [x, y]);
        option tangents;
    }
}

/// Point-mass pendulum parameters.
const MP: f64 = 0.7;
const LP: f64 = 1.3;

mbs::multibody! {
    /// A point mass on a rigid rod of length l, Cartesian coordinates, no marks:
    /// `rod = sqrt(px² + py²) − l`, so λ is the outward radial force on the mass (−tension).
    pub model PointPendulum {
        param m = 0.7; param l = 1.3; param g = 9.81;
        dof px = 0.0; dof py = -1.3;
        body mass { mass = m; }
        TOG[mass] = Tdisp(px, py, 0);
        gravity(0, -g, 0);
        constraint rod = sqrt(px * px + py * py) - l;
        option tangents;
    }
}

mbs::multibody! {
    /// The point-mass pendulum on a rod whose length is imposed, l + a sin(w t): a rheonomic
    /// constraint. No tangents (K and C by central differences).
    pub model Breathing {
        param m = 0.7; param l = 1.3; param g = 9.81; param a = 0.05; param w = 3.0;
        dof px = 0.0; dof py = -1.3;
        body mass { mass = m; }
        TOG[mass] = Tdisp(px, py, 0);
        gravity(0, -g, 0);
        constraint rod = sqrt(px * px + py * py) - l - a * sin(w * t);
    }
}

mbs::multibody! {
    /// The bar pendulum pinned twice along x: B has a repeated row.
    pub model BarPinnedTwice {
        param m = 1.2; param l = 0.8; param g = 9.81;
        dof px = 0.0; dof py = -0.4; dof theta = 0.0;
        body bar { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        point top on bar at (0, l / 2, 0);
        TOG[bar] = Tdisp(px, py, 0) * Trotz(theta);
        gravity(0, -g, 0);
        constraint pin: coincide(ground, top, along = [x, y]);
        constraint again: coincide(ground, top, along = [x]);
    }
}

mbs::multibody! {
    /// The bar pendulum pinned, and held by a second constraint that nearly repeats the first
    /// (rows [1, 1, 0] and [1, 1 + e, 0] of B): full rank by its singular values, too nearly
    /// dependent for the normal equations and for pivoting.
    pub model BarNearlyTwice {
        param m = 1.2; param l = 0.8; param g = 9.81; param e = 2e-9;
        dof px = 0.0; dof py = -0.4; dof theta = 0.0;
        body bar { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        TOG[bar] = Tdisp(px, py, 0) * Trotz(theta);
        gravity(0, -g, 0);
        constraint sum = px + py + 0.4;
        constraint near = px + (1 + e) * py + 0.4 * (1 + e);
    }
}

mbs::multibody! {
    /// fourbar (`tests/reference/MODELS.md`): ground 0.4 m, crank 0.1, coupler 0.35, rocker
    /// 0.3, uniform bars of 1 kg/m, gravity; absolute angles a, b, c; crank marked
    /// independent; a torque input on the crank.
    pub model FourBar {
        param l0 = 0.4; param l1 = 0.1; param l2 = 0.35; param l3 = 0.3;
        param rho = 1.0; param g = 9.81;
        dof a = PI / 3, qd = 5.0, independent;
        dof b = 0.6;
        dof c = 1.8;
        input torque;
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
        generalized_force(q[a], torque);
        constraint close: coincide(coupler_end, rocker_tip, along = [x, y]);
        option tangents;
    }
}

/// The four-bar's loop in closed form: (b, c) for crank angle `a`, coupler above the x axis.
fn fourbar_loop(a: f64) -> (f64, f64) {
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

/// Slider-crank dimensions.
const R: f64 = 0.1;
const L: f64 = 0.3;

mbs::multibody! {
    /// slidercrank (`tests/reference/MODELS.md`) in (θ, ψ, s) with the pin closed by two
    /// constraints, no gravity; an input torque on the crank (always on), and in scene
    /// `Driven` a crank torque `drive(t)` computed by this file's inverse dynamics.
    pub model SliderCrank {
        param r = 0.1; param l = 0.3;
        param m_crank = 0.5; param m_rod = 1.0; param m_slider = 2.0;
        extern fn drive = [drive_torque, drive_torque_d];
        dof theta = 0.0, qd = 10.0, independent;
        dof psi = 0.0, qd = -10.0 / 3.0;
        dof s = 0.4;
        input torque;
        body crank { mass = m_crank; inertia = (0, m_crank * r * r / 12, m_crank * r * r / 12); }
        body rod { mass = m_rod; inertia = (0, m_rod * l * l / 12, m_rod * l * l / 12); }
        body slider { mass = m_slider; }
        point rod_end on rod at (l / 2, 0, 0);
        TOG[crank] = Trotz(theta) * Tdisp(r / 2, 0, 0);
        TOG[rod] = Tdisp(r * cos(theta), r * sin(theta), 0) * Trotz(psi) * Tdisp(l / 2, 0, 0);
        TOG[slider] = Tdisp(s, 0, 0);
        generalized_force(q[theta], torque);
        effect driven { generalized_force(q[theta], drive(t)); }
        scene Free = [];
        scene Driven = [driven];
        constraint pin: coincide(rod_end, slider, along = [x, y]);
    }
}

/// The crank's prescribed motion θ(t) = 0.2 + 6t + 0.8 sin 4t and its derivatives.
fn crank_motion(t: f64) -> (f64, f64, f64) {
    (
        0.2 + 6.0 * t + 0.8 * (4.0 * t).sin(),
        6.0 + 3.2 * (4.0 * t).cos(),
        -12.8 * (4.0 * t).sin(),
    )
}

/// The slider-crank's (q, qd, qdd) along θ(t), ψ and s from the closed-form loop
/// sin ψ = −(r/l) sin θ, s = r cos θ + l cos ψ, differentiated by hand.
fn crank_path(t: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let (th, thd, thdd) = crank_motion(t);
    let k = R / L;
    let psi = -(k * th.sin()).asin();
    let psid = -k * th.cos() * thd / psi.cos();
    let psidd =
        (-k * (th.cos() * thdd - th.sin() * thd * thd) + psi.sin() * psid * psid) / psi.cos();
    let s = R * th.cos() + L * psi.cos();
    let sd = -R * th.sin() * thd - L * psi.sin() * psid;
    let sdd = -R * (th.cos() * thd * thd + th.sin() * thdd)
        - L * (psi.cos() * psid * psid + psi.sin() * psidd);
    (
        vec![th, psi, s],
        vec![thd, psid, sd],
        vec![thdd, psidd, sdd],
    )
}

/// The crank torque that makes the free slider-crank follow θ(t): the inverse dynamics
/// (`SliderCrankDriven`'s `drive`).
pub fn drive_torque(t: f64) -> f64 {
    let model = SliderCrankFree::default();
    inverse_dynamics_actuated_along(&model, &[t], &[0.0], &[0], crank_path)
        .expect("inverse dynamics of the slider-crank")
        .tau_at(0)[0]
}

/// Its derivative (central differences; the generated code needs it only for tangents).
pub fn drive_torque_d(t: f64) -> f64 {
    let e = 1e-5;
    (drive_torque(t + e) - drive_torque(t - e)) / (2.0 * e)
}

// ---------------------------------------------------------------------------------------------
// Independent tools: a dense solve, the reduced ODE with our own completion, differences

/// The index-1 accelerations and multipliers from the full KKT system
/// [M −Bᵀ; B 0] (qdd, λ) = (h, γ), solved densely.
fn kkt<M: Model>(model: &M, t: f64, q: &[f64], qd: &[f64], u: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let (n, nc) = (M::NQ, M::NC);
    let (mut m, mut h) = (vec![0.0; n * n], vec![0.0; n]);
    model.dynamics(t, q, qd, u, &mut m, &mut h);
    let (mut b, mut gamma) = (vec![0.0; nc * n], vec![0.0; nc]);
    model.constraint_jacobian(t, q, &mut b);
    model.constraint_bias(t, q, qd, &mut gamma);
    let s = n + nc;
    let mut a = vec![0.0; s * s];
    for j in 0..n {
        for i in 0..n {
            a[i + s * j] = m[i + n * j];
        }
        for i in 0..nc {
            a[(n + i) + s * j] = b[i + nc * j];
            a[j + s * (n + i)] = -b[i + nc * j];
        }
    }
    let rhs: Vec<f64> = h.iter().chain(&gamma).copied().collect();
    let x = solve(&a, &rhs);
    (x[..n].to_vec(), x[n..].to_vec())
}

/// q and qd with the independent coordinates `ind` at z, ż: Newton on Φ(q, t) = 0 over the
/// other coordinates from `guess` (to the last bit), then B_d qd_d = −Φ_t − B_i ż.
fn complete<M: Model>(
    model: &M,
    t: f64,
    ind: &[usize],
    z: &[f64],
    zd: &[f64],
    guess: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    let (n, nc) = (M::NQ, M::NC);
    let dep: Vec<usize> = (0..n).filter(|i| !ind.contains(i)).collect();
    let mut q = guess.to_vec();
    for (k, &i) in ind.iter().enumerate() {
        q[i] = z[k];
    }
    let (mut phi, mut b) = (vec![0.0; nc], vec![0.0; nc * n]);
    let bd = |b: &[f64]| {
        let mut a = vec![0.0; nc * nc];
        for (c, &j) in dep.iter().enumerate() {
            for i in 0..nc {
                a[i + nc * c] = b[i + nc * j];
            }
        }
        a
    };
    let mut small = 0;
    for _ in 0..60 {
        model.constraints(t, &q, &mut phi);
        model.constraint_jacobian(t, &q, &mut b);
        let dx = solve(&bd(&b), &phi);
        for (c, &j) in dep.iter().enumerate() {
            q[j] -= dx[c];
        }
        if dx.iter().all(|d| d.abs() < 1e-15) {
            small += 1;
            if small == 2 {
                break;
            }
        }
    }
    model.constraints(t, &q, &mut phi);
    assert!(
        phi.iter().all(|p| p.abs() < 1e-13),
        "completion: Φ = {phi:?}"
    );
    model.constraint_jacobian(t, &q, &mut b);
    let mut rate = vec![0.0; nc];
    model.constraint_rate(t, &q, &mut rate);
    let mut qd = vec![0.0; n];
    for (k, &i) in ind.iter().enumerate() {
        qd[i] = zd[k];
    }
    let rhs: Vec<f64> = (0..nc)
        .map(|i| -rate[i] - ind.iter().map(|&j| b[i + nc * j] * qd[j]).sum::<f64>())
        .collect();
    let v = solve(&bd(&b), &rhs);
    for (c, &j) in dep.iter().enumerate() {
        qd[j] = v[c];
    }
    (q, qd)
}

/// The reduced ODE: z̈ = f(t, z, ż) (independent rows of the index-1 accelerations).
fn reduced_f<M: Model>(
    model: &M,
    t: f64,
    ind: &[usize],
    x: &[f64],
    u: &[f64],
    guess: &[f64],
) -> Vec<f64> {
    let nz = ind.len();
    let (q, qd) = complete(model, t, ind, &x[..nz], &x[nz..], guess);
    let (qdd, _) = kkt(model, t, &q, &qd, u);
    ind.iter().map(|&i| qdd[i]).collect()
}

/// Central differences of (ż, f(z, ż)) in x = (z, ż): the reference state matrix.
fn fd_reduced_state_matrix<M: Model>(
    model: &M,
    t: f64,
    ind: &[usize],
    q: &[f64],
    qd: &[f64],
    u: &[f64],
) -> DMatrix<f64> {
    let nz = ind.len();
    let x: Vec<f64> = ind
        .iter()
        .map(|&i| q[i])
        .chain(ind.iter().map(|&i| qd[i]))
        .collect();
    let mut a = DMatrix::zeros(2 * nz, 2 * nz);
    for i in 0..nz {
        a[(i, nz + i)] = 1.0;
    }
    for j in 0..2 * nz {
        let eps = 1e-5 * x[j].abs().max(1.0);
        let (mut xp, mut xm) = (x.clone(), x.clone());
        xp[j] += eps;
        xm[j] -= eps;
        let (fp, fm) = (
            reduced_f(model, t, ind, &xp, u, q),
            reduced_f(model, t, ind, &xm, u, q),
        );
        for i in 0..nz {
            a[(nz + i, j)] = (fp[i] - fm[i]) / (2.0 * eps);
        }
    }
    a
}

fn max_abs(a: &DMatrix<f64>) -> f64 {
    a.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// max |a − b| / max |b|
fn rel_diff(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    assert_eq!(a.shape(), b.shape());
    max_abs(&(a - b)) / max_abs(b).max(f64::MIN_POSITIVE)
}

/// Five-point central first and second derivatives of f at x, step e.
fn derivatives(f: impl Fn(f64) -> f64, x: f64, e: f64) -> (f64, f64) {
    let (f2, f1, f0, g1, g2) = (f(x + 2.0 * e), f(x + e), f(x), f(x - e), f(x - 2.0 * e));
    (
        (-f2 + 8.0 * f1 - 8.0 * g1 + g2) / (12.0 * e),
        (-f2 + 16.0 * f1 - 30.0 * f0 + 16.0 * g1 - g2) / (12.0 * e * e),
    )
}

// ---------------------------------------------------------------------------------------------
// Cartesian pendulums

/// (px, py, θ) of the bar hanging (θ = 0) or upright (θ = π) from a pin at the origin.
fn bar_at(theta: f64) -> [f64; 3] {
    [0.5 * LB * theta.sin(), -0.5 * LB * theta.cos(), theta]
}

#[test]
fn bar_pendulum_statics_hanging_and_upright() {
    let model = BarPendulum::default();
    // reduced stiffness on the orthonormal tangent (l/2 cos θ, l/2 sin θ, 1)/√(1 + l²/4):
    // ±(m g l/2)/(1 + l²/4)
    let k_want = MB * G * LB / 2.0 / (1.0 + LB * LB / 4.0);
    println!(
        "bar pendulum statics (m = {MB}, l = {LB}): λ_y = m g = {:.12}",
        MB * G
    );
    println!(
        "{:>9} {:>5} {:>12} {:>10} {:>10} {:>14} {:>14} {:>10} {:>10}",
        "start", "iters", "θ*", "residual", "max|Φ|", "λ_x", "λ_y − m g", "eig err", "stability"
    );
    for (start, theta0, want_theta, sign, want) in [
        ("hanging", 0.4, 0.0, 1.0, Stability::Stable),
        ("upright", PI - 0.3, PI, -1.0, Stability::Unstable),
    ] {
        // off the constraint too: the statics close the loop as they go
        let mut q0 = bar_at(theta0);
        q0[0] += 0.02;
        q0[1] -= 0.01;
        let eq = static_equilibrium(
            &model,
            &StaticsOptions {
                q0: Some(q0.to_vec()),
                ..Default::default()
            },
        )
        .unwrap();
        let lx = eq.lambda_of("pin.x").unwrap();
        let ly = eq.lambda_of("pin.y").unwrap();
        let ek = (eq.stiffness_eigenvalues[0] - sign * k_want).abs() / k_want;
        let want_q = bar_at(want_theta);
        let eq_err = (0..3)
            .map(|i| (eq.q[i] - want_q[i]).abs())
            .fold(0.0, f64::max);
        println!(
            "{start:>9} {:>5} {:>12.9} {:>10.1e} {:>10.1e} {:>14.3e} {:>14.3e} {:>10.1e} {:>10?}",
            eq.iterations,
            eq.q[2],
            eq.residual,
            eq.constraint_residual,
            lx,
            ly - MB * G,
            ek,
            eq.stability
        );
        assert_eq!(eq.constraint_names, ["pin.x", "pin.y"]);
        assert!(eq_err < 1e-10, "q = {:?}", eq.q);
        assert!(eq.residual <= 1e-9 && eq.constraint_residual <= 1e-11);
        assert!(lx.abs() < 1e-9 && (ly - MB * G).abs() < 1e-9 * MB * G);
        assert_eq!(eq.stiffness_eigenvalues.len(), 1, "one degree of freedom");
        assert!(ek < 1e-9);
        assert_eq!(eq.stability, want);
        println!("{eq}");
    }
}

#[test]
fn point_pendulum_statics_give_the_rod_tension() {
    let model = PointPendulum::default();
    println!(
        "point pendulum statics (m = {MP}, l = {LP}): tension m g = {:.12}",
        MP * G
    );
    for (start, q0, sign, want) in [
        ("hanging", [0.3, -1.2], 1.0, Stability::Stable),
        ("upright", [-0.2, 1.25], -1.0, Stability::Unstable),
    ] {
        let eq = static_equilibrium(
            &model,
            &StaticsOptions {
                q0: Some(q0.to_vec()),
                ..Default::default()
            },
        )
        .unwrap();
        let lambda = eq.lambda_of("rod").unwrap();
        // λ is the outward radial force on the mass: −m g hanging (tension), +m g upright
        let el = (lambda + sign * MP * G).abs() / (MP * G);
        // reduced stiffness ±m g / l on the unit tangent
        let ek = (eq.stiffness_eigenvalues[0] - sign * MP * G / LP).abs() / (MP * G / LP);
        println!(
            "{start}: q = ({:+.3e}, {:+.12}) in {} iterations, λ = {lambda:+.12} (error {el:.1e}), stiffness {:+.9} (error {ek:.1e}), {:?}",
            eq.q[0], eq.q[1], eq.iterations, eq.stiffness_eigenvalues[0], eq.stability
        );
        assert!(eq.q[0].abs() < 1e-12 && (eq.q[1].abs() - LP).abs() < 1e-12);
        assert!(el < 1e-12 && ek < 1e-9);
        assert_eq!(eq.stability, want);
    }
}

#[test]
fn pendulums_oscillate_at_their_minimal_coordinate_frequencies() {
    // bar pinned at its end: ω² = (m g l/2)/(m l²/3) = 3g/(2l); point mass: ω² = g/l
    let bar = BarPendulum::default();
    let lin = linearize(
        &bar,
        0.0,
        &bar_at(0.0),
        &[0.0; 3],
        &[],
        IterationMatrix::Auto,
    )
    .unwrap();
    assert!(lin.marks_used && lin.constraint_terms_exact && lin.exact);
    assert_eq!(lin.coordinates, ["q[2] (theta)"]);
    let m = modes(&lin, None).unwrap();
    let want = (3.0 * G / (2.0 * LB)).sqrt() / (2.0 * PI);
    let err = (m.modes[0].frequency_hz - want).abs() / want;
    // M_z = m l²/3, K_z = m g l/2 in θ
    let (em, ek) = (
        (lin.mz[(0, 0)] - MB * LB * LB / 3.0).abs() / (MB * LB * LB / 3.0),
        (lin.kz[(0, 0)] - MB * G * LB / 2.0).abs() / (MB * G * LB / 2.0),
    );
    println!(
        "bar pendulum: {:.12} Hz vs √(3g/2l)/2π = {want:.12} Hz, error {err:.1e}; M_z error {em:.1e}, K_z error {ek:.1e}; λ = {:?}",
        m.modes[0].frequency_hz, lin.lambda
    );
    print!("{m}");
    assert!(err < 1e-9 && em < 1e-12 && ek < 1e-12);
    assert_eq!(m.dof_names, ["q[2] (theta)"]);
    // the shape in all coordinates: δq = (l/2, 0, 1) δθ
    let sq = &m.modes[0].shape_q;
    assert!((sq[0].0 - LB / 2.0).abs() < 1e-12 && sq[1].0.abs() < 1e-12 && sq[2].0 == 1.0);

    let point = PointPendulum::default();
    let lin = linearize(
        &point,
        0.0,
        &[0.0, -LP],
        &[0.0; 2],
        &[],
        IterationMatrix::Auto,
    )
    .unwrap();
    assert!(!lin.marks_used, "no marks: pivoting picks py as dependent");
    assert_eq!(lin.coordinates, ["q[0] (px)"]);
    let m = modes(&lin, None).unwrap();
    let want = (G / LP).sqrt() / (2.0 * PI);
    let err = (m.modes[0].frequency_hz - want).abs() / want;
    println!(
        "point pendulum: {:.12} Hz vs √(g/l)/2π = {want:.12} Hz, error {err:.1e}; λ = {:?} (−m g = {})",
        m.modes[0].frequency_hz,
        lin.lambda,
        -MP * G
    );
    assert!(err < 1e-9);
    assert!((lin.lambda[0] + MP * G).abs() < 1e-12);
}

#[test]
fn pendulum_state_matrices_match_the_reduced_ode() {
    println!(
        "{:<34} {:>12} {:>12} {:>8} {:>8}",
        "model, state", "A vs diff.", "max |A|", "exact K", "exact Φ"
    );
    let report = |name: &str, lin: &mbs::Linearization, a_fd: &DMatrix<f64>| {
        let e = rel_diff(&lin.a, a_fd);
        println!(
            "{name:<34} {e:>12.2e} {:>12.4} {:>8} {:>8}",
            max_abs(a_fd),
            lin.exact,
            lin.constraint_terms_exact
        );
        e
    };
    // the bar: hanging, at rest off equilibrium (Q ≠ 0), moving
    let bar = BarPendulum::default();
    for (name, theta, thd) in [
        ("bar, hanging at rest", 0.0, 0.0),
        ("bar, θ = 0.6 at rest", 0.6, 0.0),
        ("bar, θ = 2.2 moving", 2.2, 1.7),
    ] {
        let q = bar_at(theta);
        let qd = [
            0.5 * LB * theta.cos() * thd,
            0.5 * LB * theta.sin() * thd,
            thd,
        ];
        for how in [IterationMatrix::Auto, IterationMatrix::FiniteDifferences] {
            let lin = linearize(&bar, 0.0, &q, &qd, &[], how).unwrap();
            let a_fd = fd_reduced_state_matrix(&bar, 0.0, &lin.independent, &q, &qd, &[]);
            let e = report(&format!("{name} ({how:?})"), &lin, &a_fd);
            assert!(e < 1e-7, "{name}: {e:.2e}\n{}\n{a_fd}", lin.a);
            assert_eq!(lin.constraint_terms_exact, thd == 0.0);
        }
    }
    // the point mass: pivoting picks its coordinates; moving off the vertical
    let point = PointPendulum::default();
    let (ang, angd) = (1.1f64, -2.3);
    let q = [LP * ang.sin(), -LP * ang.cos()];
    let qd = [LP * ang.cos() * angd, LP * ang.sin() * angd];
    let lin = linearize(&point, 0.0, &q, &qd, &[], IterationMatrix::Auto).unwrap();
    let a_fd = fd_reduced_state_matrix(&point, 0.0, &lin.independent, &q, &qd, &[]);
    let e = report(
        &format!("point, moving, z = {}", lin.coordinates[0]),
        &lin,
        &a_fd,
    );
    assert!(e < 1e-7);
    // the rheonomic rod l + a sin(w t): consistent state at t = 0.4 with a radial velocity
    let model = Breathing::default();
    let t: f64 = 0.4;
    let (r, rd) = (LP + 0.05 * (3.0 * t).sin(), 0.15 * (3.0 * t).cos());
    let (ang, angd) = (0.5f64, 0.8);
    let q = [r * ang.sin(), -r * ang.cos()];
    let qd = [
        rd * ang.sin() + r * ang.cos() * angd,
        -rd * ang.cos() + r * ang.sin() * angd,
    ];
    let lin = linearize(&model, t, &q, &qd, &[], IterationMatrix::Auto).unwrap();
    assert!(!lin.exact && !lin.constraint_terms_exact);
    let a_fd = fd_reduced_state_matrix(&model, t, &lin.independent, &q, &qd, &[]);
    let e = report("rheonomic rod, moving", &lin, &a_fd);
    assert!(e < 1e-6);
    // and at rest at an instant where the rod does not breathe (ṙ = 0 at 3t = π/2): there
    // γ = −Φ_tt and ∂Φ/∂t do not depend on q, so the differenced terms vanish identically
    let t = PI / 6.0;
    let r = LP + 0.05;
    let q = [r * 0.3f64.sin(), -r * 0.3f64.cos()];
    let lin = linearize(&model, t, &q, &[0.0; 2], &[], IterationMatrix::Auto).unwrap();
    let a_fd = fd_reduced_state_matrix(&model, t, &lin.independent, &q, &[0.0; 2], &[]);
    let e = report("rheonomic rod, at rest", &lin, &a_fd);
    assert!(e < 1e-6 && lin.constraint_terms_exact);
}

// ---------------------------------------------------------------------------------------------
// Four-bar

/// The four-bar's q at crank angle a on the closed loop.
fn fourbar_q(a: f64) -> Vec<f64> {
    let (b, c) = fourbar_loop(a);
    vec![a, b, c]
}

/// Potential energy along the loop, V(a).
fn fourbar_v(model: &FourBar, a: f64) -> f64 {
    model.energy(0.0, &fourbar_q(a), &[0.0; 3]).potential
}

/// dq/da along the loop (central differences of the closed form).
fn fourbar_tangent(a: f64) -> Vec<f64> {
    let e = 1e-6;
    let (p, m) = (fourbar_q(a + e), fourbar_q(a - e));
    (0..3).map(|i| (p[i] - m[i]) / (2.0 * e)).collect()
}

/// Crank angles where V'(a) = τ (bisection on the five-point V'), from a scan of [0, 2π).
fn fourbar_equilibria(model: &FourBar, tau: f64) -> Vec<f64> {
    let dv = |a: f64| derivatives(|x| fourbar_v(model, x), a, 1e-3).0 - tau;
    let grid: Vec<f64> = (0..=720).map(|k| 2.0 * PI * k as f64 / 720.0).collect();
    let mut roots = Vec::new();
    for w in grid.windows(2) {
        let (mut lo, mut hi) = (w[0], w[1]);
        if dv(lo).signum() == dv(hi).signum() {
            continue;
        }
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if dv(mid).signum() == dv(lo).signum() {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        roots.push(0.5 * (lo + hi));
    }
    roots
}

#[test]
fn four_bar_statics_match_its_potential_energy() {
    let model = FourBar::default();
    // a torque of 40 % of gravity's largest moment about the crank
    let vmax = (0..360)
        .map(|k| {
            derivatives(|x| fourbar_v(&model, x), k as f64 * PI / 180.0, 1e-3)
                .0
                .abs()
        })
        .fold(0.0, f64::max);
    println!(
        "{:>7} {:>13} {:>13} {:>5} {:>9} {:>9} {:>12} {:>13} {:>9} {:>10}",
        "torque",
        "a (energy)",
        "a (statics)",
        "iters",
        "residual",
        "max|Φ|",
        "stiffness",
        "V''/|dq/da|²",
        "error",
        "stability"
    );
    for tau in [0.0, 0.4 * vmax] {
        let roots = fourbar_equilibria(&model, tau);
        assert_eq!(
            roots.len(),
            2,
            "one stable and one unstable equilibrium: {roots:?}"
        );
        for a_star in roots {
            let (_, v2) = derivatives(|x| fourbar_v(&model, x), a_star, 1e-3);
            let na = fourbar_tangent(a_star);
            let want = v2 / na.iter().map(|x| x * x).sum::<f64>();
            // start 0.15 rad away, off the loop
            let mut q0 = fourbar_q(a_star + 0.15);
            q0[1] += 0.01;
            q0[2] -= 0.01;
            let eq = static_equilibrium(
                &model,
                &StaticsOptions {
                    q0: Some(q0),
                    u: Some(vec![tau]),
                    ..Default::default()
                },
            )
            .unwrap();
            let got = eq.stiffness_eigenvalues[0];
            let err = (got - want).abs() / want.abs();
            println!(
                "{tau:>7.4} {a_star:>13.9} {:>13.9} {:>5} {:>9.1e} {:>9.1e} {got:>12.6e} {want:>13.6e} {err:>9.1e} {:>10?}",
                eq.q[0], eq.iterations, eq.residual, eq.constraint_residual, eq.stability
            );
            assert!(
                (eq.q[0] - a_star).abs() < 1e-7,
                "a = {} vs {a_star}",
                eq.q[0]
            );
            let on_loop = fourbar_q(eq.q[0]);
            assert!((1..3).all(|i| (eq.q[i] - on_loop[i]).abs() < 1e-9));
            assert!(eq.residual <= 1e-9 && eq.constraint_residual <= 1e-11);
            assert!(err < 1e-6);
            let want_stability = if v2 > 0.0 {
                Stability::Stable
            } else {
                Stability::Unstable
            };
            assert_eq!(eq.stability, want_stability);
            assert_eq!(eq.stiffness_eigenvalues.len(), 1);
        }
    }
}

/// A four-bar of light bars (1e-9 kg/m) rests where the one of 1 kg/m does: gravity's
/// moments scale with the mass and their equilibria do not. Its forces at a start 0.15 rad
/// off are below the force tolerance, which the start alone passed as an equilibrium.
#[test]
fn a_light_four_bar_rests_where_a_heavy_one_does() {
    let mut model = FourBar::default();
    let a_star = fourbar_equilibria(&model, 0.0)
        .into_iter()
        .find(|&a| derivatives(|x| fourbar_v(&model, x), a, 1e-3).1 > 0.0)
        .unwrap();
    let mut p = model.params().clone();
    p.rho = 1e-9;
    model.set_params(p).unwrap();
    let eq = static_equilibrium(
        &model,
        &StaticsOptions {
            q0: Some(fourbar_q(a_star + 0.15)),
            u: Some(vec![0.0]),
            ..Default::default()
        },
    )
    .unwrap();
    println!("{eq}");
    assert!(
        (eq.q[0] - a_star).abs() < 1e-7,
        "a = {} vs {a_star}",
        eq.q[0]
    );
    assert!(eq.correction.is_some_and(|c| c <= 1e-10));
    assert_eq!(eq.stability, Stability::Stable);
}

#[test]
fn four_bar_frequency_matches_the_energy_method() {
    let model = FourBar::default();
    let roots = fourbar_equilibria(&model, 0.0);
    let a_star = roots
        .into_iter()
        .find(|&a| derivatives(|x| fourbar_v(&model, x), a, 1e-3).1 > 0.0)
        .unwrap();
    let eq = static_equilibrium(
        &model,
        &StaticsOptions {
            q0: Some(fourbar_q(a_star)),
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(eq.stability, Stability::Stable);
    let lin = linearize(&model, 0.0, &eq.q, &[0.0; 3], &[0.0], IterationMatrix::Auto).unwrap();
    assert!(lin.marks_used);
    assert_eq!(lin.coordinates, ["q[0] (a)"]);
    // energy method: T = ½ m_eff ȧ², V(a): ω² = V''(a)/m_eff(a)
    let na = fourbar_tangent(a_star);
    let m_eff = 2.0 * model.energy(0.0, &fourbar_q(a_star), &na).kinetic;
    let (_, v2) = derivatives(|x| fourbar_v(&model, x), a_star, 1e-3);
    let want = (v2 / m_eff).sqrt() / (2.0 * PI);
    let m = modes(&lin, None).unwrap();
    let got = m.modes[0].frequency_hz;
    let err = (got - want).abs() / want;
    println!(
        "four-bar at a = {:.9}: {got:.10} Hz vs energy method {want:.10} Hz, error {err:.1e}; m_eff {m_eff:.6e} vs M_z {:.6e}, V'' {v2:.6e} vs K_z {:.6e}",
        eq.q[0],
        lin.mz[(0, 0)],
        lin.kz[(0, 0)]
    );
    print!("{m}");
    assert!(err < 1e-7);
    // the input: B_u,z = Nᵀ B_u = 1 (the torque acts on a, the independent coordinate)
    assert!((lin.buz[(0, 0)] - 1.0).abs() < 1e-12);

    // A vs the reduced ODE, at the equilibrium and moving at 5 rad/s off it
    let a_fd = fd_reduced_state_matrix(&model, 0.0, &lin.independent, &eq.q, &[0.0; 3], &[0.0]);
    let e0 = rel_diff(&lin.a, &a_fd);
    let q = fourbar_q(1.0);
    let t = fourbar_tangent(1.0);
    let qd: Vec<f64> = t.iter().map(|x| 5.0 * x).collect();
    let lin = linearize(&model, 0.0, &q, &qd, &[0.2], IterationMatrix::Auto).unwrap();
    let a_fd = fd_reduced_state_matrix(&model, 0.0, &lin.independent, &q, &qd, &[0.2]);
    let e1 = rel_diff(&lin.a, &a_fd);
    println!(
        "four-bar: A vs central differences of the reduced ODE: {e0:.1e} at the equilibrium, {e1:.1e} moving (ȧ = 5, τ = 0.2), exact constraint terms: {}",
        lin.constraint_terms_exact
    );
    assert!(e0 < 1e-7 && e1 < 1e-7);
}

// ---------------------------------------------------------------------------------------------
// Slider-crank: inverse dynamics, then forward

#[test]
fn slider_crank_inverse_dynamics_split_into_torque_and_pin_forces() {
    let model = SliderCrankFree::default();
    let (n, nc) = (SliderCrankFree::NQ, SliderCrankFree::NC);
    let times: Vec<f64> = (0..=10).map(|k| 0.1 * k as f64).collect();
    let eff = inverse_dynamics_actuated_along(&model, &times, &[0.0], &[0], crank_path).unwrap();
    assert_eq!(eff.actuated, ["q[0] (theta)"]);
    assert_eq!(eff.constraint_names, ["pin.x", "pin.y"]);
    println!(
        "{:>5} {:>10} {:>14} {:>14} {:>14} {:>10} {:>10} {:>10} {:>10}",
        "t", "θ", "τ_crank", "λ pin.x", "λ pin.y", "|Φ|", "|Φ̇|", "|Φ̈|", "balance"
    );
    let mut worst: f64 = 0.0;
    for (i, &t) in times.iter().enumerate() {
        let (q, qd, qdd) = crank_path(t);
        let (tau, lambda) = (eff.tau_at(i), eff.lambda_at(i));
        // S τ_a + Bᵀλ = M qdd − h
        let mut r = vec![0.0; n];
        model.inverse_dynamics(t, &q, &qd, &qdd, &[0.0], &mut r);
        let mut b = vec![0.0; nc * n];
        model.constraint_jacobian(t, &q, &mut b);
        let mut bal: f64 = 0.0;
        for j in 0..n {
            let lhs = if j == 0 { tau[0] } else { 0.0 }
                + (0..nc).map(|k| b[k + nc * j] * lambda[k]).sum::<f64>();
            bal = bal.max((lhs - r[j]).abs() / r[j].abs().max(1.0));
        }
        worst = worst.max(bal);
        println!(
            "{t:>5.2} {:>10.5} {:>14.8} {:>14.8} {:>14.8} {:>10.1e} {:>10.1e} {:>10.1e} {bal:>10.1e}",
            q[0], tau[0], lambda[0], lambda[1], eff.phi[i], eff.phi_dot[i], eff.phi_ddot[i]
        );
        assert!(eff.phi[i] < 1e-14 && eff.phi_dot[i] < 1e-13 && eff.phi_ddot[i] < 1e-11);
        // the y pin force carries no x load on the slider: λ_x = m_slider s̈ (the slider is
        // a free point mass on x pushed only by the rod)
        assert!((lambda[0] - 2.0 * qdd[2]).abs() < 1e-10 * (1.0 + lambda[0].abs()));
    }
    assert!(worst < 1e-12, "balance {worst:.1e}");

    // through the input u[0]: M qdd = h(u = τ_a) + Bᵀλ gives back qdd and λ (index 1)
    let t = 0.37;
    let (q, qd, qdd) = crank_path(t);
    let one = inverse_dynamics_actuated_along(&model, &[t], &[0.0], &[0], crank_path).unwrap();
    let (back, lambda) = kkt(&model, t, &q, &qd, &[one.tau_at(0)[0]]);
    let e = (0..n).map(|i| (back[i] - qdd[i]).abs()).fold(0.0, f64::max);
    let el = (0..nc)
        .map(|i| (lambda[i] - one.lambda_at(0)[i]).abs())
        .fold(0.0, f64::max);
    println!(
        "t = {t}: τ_a through u[0], forward index-1: max |qdd − qdd₀| = {e:.1e}, |λ − λ₀| = {el:.1e}"
    );
    assert!(e < 1e-10 && el < 1e-10);

    let mut csv = Vec::new();
    eff.write_csv(&mut csv).unwrap();
    let csv = String::from_utf8(csv).unwrap();
    assert_eq!(
        csv.lines().next().unwrap(),
        "t,q[0] (theta),pin.x.lambda,pin.y.lambda,phi,phi_dot,phi_ddot"
    );
    assert_eq!(csv.lines().count(), 1 + times.len());
}

#[test]
fn slider_crank_driven_by_its_inverse_dynamics_follows_the_motion() {
    // The crank torque drive(t) = τ_a(t) of the inverse dynamics, as a generalised force on θ
    // of the `Driven` scene (inputs are zero in simulations, so the torque enters through an
    // extern function that calls the inverse dynamics at the integrator's t). The motion is
    // open loop and neutrally stable (no stiffness): errors are not damped, an error δθ̇ in the
    // speed grows δθ linearly. With rtol = 1e-10 each step errs by at most ~1e-10·|θ| (θ ≤ 9.4
    // rad here), so even adding up without cancellation over the ≤ 350 steps the global error
    // stays below 350 · 1e-10 · 9.4 ≈ 3e-7 rad: we require 1e-6 rad on θ. λ is the index-1
    // multiplier of each state with projection (required within 1e-6 of its largest value),
    // but radau5 at index 3 computes λ to order s − 1 = 2 only (options.rs), so there within
    // 1e-3. Φ at the projection / Newton tolerance (1e-11), with margin: 1e-9.
    let t_end = 1.5;
    let (q0, qd0, _) = crank_path(0.0);
    println!(
        "{:<22} {:>6} {:>14} {:>14} {:>12}",
        "scheme, constraints", "steps", "max |θ − θ(t)|", "max |λ − λ(t)|", "max |Φ|"
    );
    for (scheme, method) in [
        (Scheme::Dopri5, ConstraintMethod::Projection),
        (Scheme::Radau5, ConstraintMethod::Index3),
    ] {
        let options = Options {
            q0: Some(q0.clone()),
            qd0: Some(qd0.clone()),
            constraints: ConstraintOptions {
                method,
                ..Default::default()
            },
            ..Options::adaptive(t_end, 1e-10)
        };
        let (traj, _stats) = simulate(SliderCrankDriven::default(), scheme, options).unwrap();
        let free = SliderCrankFree::default();
        let times = traj.t.clone();
        let eff = inverse_dynamics_actuated_along(&free, &times, &[0.0], &[0], crank_path).unwrap();
        let lmax = eff.lambda.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let (mut eth, mut el, mut ephi) = (0.0f64, 0.0f64, 0.0f64);
        let mut phi = [0.0; 2];
        for i in 0..traj.len() {
            let t = traj.t[i];
            eth = eth.max((traj.q(i)[0] - crank_motion(t).0).abs());
            // λ at the first output is the start's index-1 λ, then the scheme's
            for k in 0..2 {
                el = el.max((traj.lambda(i)[k] - eff.lambda_at(i)[k]).abs() / lmax);
            }
            free.constraints(t, traj.q(i), &mut phi);
            ephi = ephi.max(phi[0].abs().max(phi[1].abs()));
        }
        println!(
            "{:<22} {:>6} {eth:>14.2e} {el:>14.2e} {ephi:>12.1e}",
            format!("{}, {}", scheme.name(), method.name()),
            traj.len() - 1
        );
        assert!((traj.t[traj.len() - 1] - t_end).abs() < 1e-12);
        assert!(eth < 1e-6, "θ error {eth:.2e}");
        let el_tol = if method == ConstraintMethod::Index3 {
            1e-3
        } else {
            1e-6
        };
        assert!(el < el_tol, "λ error {el:.2e}");
        assert!(ephi < 1e-9);
    }
}

// ---------------------------------------------------------------------------------------------
// Typed errors

#[test]
fn constrained_analyses_fail_with_typed_errors() {
    let bar = BarPendulum::default();
    // linearize off the constraint: InconsistentStart naming the constraint
    let mut q = bar_at(0.3);
    q[1] += 1e-4;
    let err = linearize(&bar, 0.0, &q, &[0.0; 3], &[], IterationMatrix::Auto).unwrap_err();
    println!("off the constraint: {err}");
    match err {
        AnalysisError::Failure(Failure::InconsistentStart {
            constraint,
            residual,
            ..
        }) => {
            assert_eq!(constraint, "pin.y");
            assert!((residual - 1e-4).abs() < 1e-9);
        }
        other => panic!("{other:?}"),
    }
    // a velocity across the constraint: InvalidOption on qd
    let err = linearize(
        &bar,
        0.0,
        &bar_at(0.3),
        &[0.1, 0.0, 0.0],
        &[],
        IterationMatrix::Auto,
    )
    .unwrap_err();
    println!("velocity across the constraint: {err}");
    assert!(matches!(
        err,
        AnalysisError::Failure(Failure::InvalidOption { name: "qd", .. })
    ));

    // inverse dynamics: the actuated coordinates must number NQ − NC, once each
    let crank = SliderCrankFree::default();
    for actuated in [vec![0, 1], vec![], vec![0, 0], vec![5]] {
        let err = inverse_dynamics_actuated_along(&crank, &[0.0], &[0.0], &actuated, crank_path)
            .unwrap_err();
        println!("actuated {actuated:?}: {err}");
        assert!(matches!(
            err,
            AnalysisError::Failure(Failure::InvalidOption {
                name: "actuated",
                ..
            })
        ));
    }
    // driving the slider at a dead centre (ds/dθ = 0): [S Bᵀ] is singular
    let dead = |_: f64| (vec![0.0, 0.0, R + L], vec![0.0; 3], vec![0.0; 3]);
    let err = inverse_dynamics_actuated_along(&crank, &[0.0], &[0.0], &[2], dead).unwrap_err();
    println!("slider actuated at the dead centre: {err}");
    assert!(matches!(
        err.cause(),
        AnalysisError::Failure(Failure::SingularMatrix { .. })
    ));

    // redundant constraints: RankDeficientConstraints naming them, in all three analyses
    let twice = BarPinnedTwice::default();
    let q = bar_at(0.2);
    let rank_err = |e: AnalysisError| match e.cause().clone() {
        AnalysisError::Failure(Failure::RankDeficientConstraints {
            rank,
            nc,
            constraints,
            ..
        }) => {
            assert_eq!((rank, nc), (2, 3));
            assert!(constraints.contains(&"pin.x".to_string()));
            assert!(constraints.contains(&"again.x".to_string()));
        }
        other => panic!("{other:?}"),
    };
    let e = static_equilibrium(
        &twice,
        &StaticsOptions {
            q0: Some(q.to_vec()),
            ..Default::default()
        },
    )
    .unwrap_err();
    println!("pinned twice, statics: {e}");
    rank_err(e);
    rank_err(linearize(&twice, 0.0, &q, &[0.0; 3], &[], IterationMatrix::Auto).unwrap_err());
    rank_err(
        inverse_dynamics_actuated_along(&twice, &[0.0], &[], &[], |_| {
            (q.to_vec(), vec![0.0; 3], vec![0.0; 3])
        })
        .unwrap_err(),
    );
    // constraints full rank by their singular values but too nearly dependent for statics'
    // normal equations or linearize's pivoting: a typed error, never a panic
    let near = BarNearlyTwice::default();
    let q = [0.0, -0.4, 0.0];
    for (what, e) in [
        (
            "statics",
            static_equilibrium(
                &near,
                &StaticsOptions {
                    q0: Some(q.to_vec()),
                    ..Default::default()
                },
            )
            .map(|_| ()),
        ),
        (
            "linearize",
            linearize(&near, 0.0, &q, &[0.0; 3], &[], IterationMatrix::Auto).map(|_| ()),
        ),
    ] {
        println!("nearly pinned twice, {what}: {e:?}");
        assert!(
            matches!(
                e,
                Ok(())
                    | Err(AnalysisError::Failure(
                        Failure::SingularMatrix { .. } | Failure::RankDeficientConstraints { .. }
                    ))
            ),
            "{what}: {e:?}"
        );
    }
    // statics meets it in its multipliers' first fit (where it panicked on an `unwrap_err`)
    let e = static_equilibrium(
        &near,
        &StaticsOptions {
            q0: Some(q.to_vec()),
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("nearly dependent"), "{e}");

    // statics with every coordinate locked but one: the pin cannot be closed
    let e = static_equilibrium(
        &bar,
        &StaticsOptions {
            q0: Some(bar_at(0.2).to_vec()),
            locked: vec![0, 1],
            ..Default::default()
        },
    )
    .unwrap_err();
    println!("bar with px, py locked: {e}");
    assert!(matches!(
        e,
        AnalysisError::Failure(Failure::InvalidOption { name: "locked", .. })
    ));
    // the four-bar with no torque at a = 0 locked away: the crank is held, the loop is a
    // structure, and the statics still converge (no degree of freedom left)
    let fb = FourBar::default();
    let eq = static_equilibrium(
        &fb,
        &StaticsOptions {
            q0: Some(fourbar_q(1.0)),
            locked: vec![0],
            ..Default::default()
        },
    )
    .unwrap();
    println!("four-bar with the crank locked: {eq}");
    assert!(eq.stiffness_eigenvalues.is_empty() && eq.q[0] == 1.0);
    // a crank torque beyond gravity's largest moment: no equilibrium, NotConverged with
    // both residuals
    let e = static_equilibrium(
        &fb,
        &StaticsOptions {
            q0: Some(fourbar_q(1.0)),
            u: Some(vec![1.0]),
            ..Default::default()
        },
    )
    .unwrap_err();
    println!("four-bar under 1 N·m: {e}");
    assert!(matches!(e, AnalysisError::NotConverged { .. }));
    // a free point-mass pendulum with no gravity has no stiffness along the circle
    let mut p = PointPendulum::default();
    let mut params = p.params().clone();
    params.g = 0.0;
    p.set_params(params).unwrap();
    let e = static_equilibrium(
        &p,
        &StaticsOptions {
            q0: Some(vec![0.3, -1.2]),
            ..Default::default()
        },
    )
    .unwrap_err();
    println!("weightless pendulum: {e}");
    match e {
        AnalysisError::Failure(Failure::SingularMatrix { coordinates, .. }) => {
            assert!(!coordinates.is_empty())
        }
        other => panic!("{other:?}"),
    }
}
