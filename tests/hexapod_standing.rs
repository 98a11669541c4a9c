//! The hexapod standing: scene `Standing` of `models/src/hexapod.rs` (the six feet in
//! penalty contact with the ground z = 0, a PD controller on each of the 18 leg joints holding
//! the start angles), dropped from the MODELS.md start (feet ~1 cm above the ground).
//!
//! - it settles: after at most 5 s every velocity is below 1e-6 (m/s, rad/s);
//! - at rest the normal forces of the feet, from their kinematics and the contact law, sum to
//!   the total mass × g to 1e-6 relative;
//! - `static_equilibrium` of the scene, with the base's x, y and yaw ψ locked (they are
//!   neutral: see below), converges, is stable and is the state the simulation settled in;
//!   unlocked, the stiffness is singular in x, and a damped step (K + μ diag M) reaches the
//!   same equilibrium, neutral (three zero eigenvalues);
//! - the contact-free scene `Free` (the type `Hexapod`) has the same mechanics.
//!
//! One simulation (Radau5, rtol 1e-6, 5 s: about 30 ms in release, 0.3 s in a debug build)
//! serves every test.

use mbs::analysis::{Stability, StaticsOptions, linearize, modes, static_equilibrium};
use mbs::{
    IterationMatrix, Kinematics, Model, Options, Output, Scheme, Stats, Trajectory, simulate,
};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use mbs_models::hexapod;

use hexapod::{Hexapod, HexapodStanding};

/// Simulated time (s): the hexapod must come to rest within 5 s.
const T_END: f64 = 5.0;
/// "At rest": every |qd_i| below this (m/s, rad/s). A thousandth of a millimetre per second:
/// 1e-4 of the friction's regularisation velocity eps = 1e-2 m/s, where the friction left is
/// at most 1e-4 μ F_n ≈ 0.01 N per foot, and the creep left (decaying at ≥ 4/s, see
/// `slowest_decay`) would move a foot by less than 0.3 µm.
const V_REST: f64 = 1e-6;
/// The base's x, y and yaw ψ: neutral at rest (see `static_equilibrium_is_the_settled_state`).
const NEUTRAL: [usize; 3] = [0, 1, 3];

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

struct Settled {
    trajectory: Trajectory,
    stats: Stats,
    cpu: Duration,
}

/// The run every test reads: Radau5 (L-stable: the contact, 1e5 N/m on feet of ~0.6 kg, and
/// the friction, viscous at μ F_n/eps ≈ 1e4 N s/m below eps, make eigenvalues down to
/// −1.4e4/s), rtol 1e-6, output every 10 ms.
fn settled() -> &'static Settled {
    static RUN: OnceLock<Settled> = OnceLock::new();
    RUN.get_or_init(|| {
        let options = Options {
            output: Output::Every { dt: 0.01 },
            ..Options::adaptive(T_END, 1e-6)
        };
        let start = Instant::now();
        let (trajectory, stats) =
            simulate(HexapodStanding::default(), Scheme::Radau5, options).expect("the run");
        Settled {
            trajectory,
            stats,
            cpu: start.elapsed(),
        }
    })
}

/// Height, penetration δ = −z and normal force F_n = step(δ)·pos(k δ − c v_z) of each foot
/// (`contact` in src/language.rs for the plane z = 0), and the size of its friction force
/// μ F_n |v_t| / sqrt(|v_t|² + eps²).
fn foot_forces(model: &HexapodStanding, q: &[f64], qd: &[f64]) -> Vec<(f64, f64, f64)> {
    let p = model.params();
    let mut kin = Kinematics::new::<HexapodStanding>();
    model.kinematics(0.0, q, qd, &mut kin);
    // the six feet are the first points (the base's corners follow)
    kin.points[..6]
        .iter()
        .map(|foot| {
            let (z, v) = (foot.position[2], foot.velocity);
            let delta = -z;
            let f_n = if delta > 0.0 {
                (p.k_contact * delta - p.c_contact * v[2]).max(0.0)
            } else {
                0.0
            };
            let vt = v[0].hypot(v[1]);
            let f_t = p.mu * f_n * vt / (vt * vt + p.eps * p.eps).sqrt();
            (z, f_n, f_t)
        })
        .collect()
}

/// Total mass from the model: the base translates in world axes, so M[x][x] is the sum of
/// the body masses (checked against the parameters).
fn total_mass(model: &HexapodStanding) -> f64 {
    let n = HexapodStanding::NQ;
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q, &mut qd);
    let mut m = vec![0.0; n * n];
    model.mass_matrix(0.0, &q, &mut m);
    let p = model.params();
    let from_params = p.m_base
        + 6.0 * (p.m_support + p.m_thigh + p.m_shank + p.m_panto + p.m_coupler + 3.0 * p.m_rotor);
    assert!((m[0] - from_params).abs() < 1e-12 * from_params, "{}", m[0]);
    m[0]
}

/// Slowest decay rate (1/s) of the linearisation at the settled state, the neutral
/// directions (|λ| < 1e-6/s) left out: the creep of the feet under the regularised friction,
/// which sets how fast the robot comes to rest.
fn slowest_decay(model: &HexapodStanding, q: &[f64]) -> f64 {
    let n = HexapodStanding::NQ;
    let lin = linearize(
        model,
        0.0,
        q,
        &vec![0.0; n],
        &[],
        IterationMatrix::FiniteDifferences,
    )
    .expect("linearisation");
    let modes = modes(&lin, None).expect("modes");
    let rate = modes
        .modes
        .iter()
        .map(|m| -m.re)
        .filter(|&r| r > 1e-6)
        .fold(f64::INFINITY, f64::min);
    let neutral = modes.modes.iter().filter(|m| m.re.abs() <= 1e-6).count();
    let unstable = modes.modes.iter().filter(|m| m.re > 1e-6).count();
    println!("linearised at rest: slowest decay {rate:.3}/s, {neutral} neutral poles");
    assert_eq!(unstable, 0, "{modes}");
    rate
}

#[test]
fn the_standing_hexapod_settles_within_5_s() {
    let run = settled();
    let tr = &run.trajectory;
    let speed: Vec<f64> = (0..tr.len()).map(|i| max_abs(tr.qd(i))).collect();
    // the last output still moving at V_REST or faster
    let last_moving = (0..tr.len()).rev().find(|&i| speed[i] >= V_REST);
    let settle = last_moving.map_or(0.0, |i| tr.t[(i + 1).min(tr.len() - 1)]);
    let n = tr.len() - 1;
    println!(
        "standing, radau5 rtol 1e-6 to t = {T_END} s in {:.1?}:\n{}",
        run.cpu, run.stats
    );
    for k in 0..=10 {
        let i = k * n / 10;
        println!(
            "t = {:.1} s: base z = {:.6} m, max |qd| = {:.2e}",
            tr.t[i],
            tr.q(i)[2],
            speed[i]
        );
    }
    println!("every |qd_i| < {V_REST:e} from t = {settle:.2} s on");
    assert!(tr.t[n] == T_END);
    assert!(
        speed[n] < V_REST,
        "still moving at t = {T_END}: {:?}",
        tr.qd(n)
    );
    assert!(settle < T_END, "settled at {settle}");
    // measured: 1.0e-10 at t = 5 s, below 1e-6 from t ≈ 2.5 s
    let model = HexapodStanding::default();
    let rate = slowest_decay(&model, tr.q(n));
    assert!(rate > 1.0, "slowest decay {rate}/s");
}

#[test]
fn at_rest_the_feet_carry_the_weight() {
    let run = settled();
    let tr = &run.trajectory;
    let n = tr.len() - 1;
    let model = HexapodStanding::default();
    let weight = total_mass(&model) * model.params().g;
    let feet = foot_forces(&model, tr.q(n), tr.qd(n));
    let sum: f64 = feet.iter().map(|f| f.1).sum();
    for (k, (z, f_n, f_t)) in feet.iter().enumerate() {
        println!("foot {k}: z = {z:+.4e} m, F_n = {f_n:9.4} N, |F_t| = {f_t:.1e} N");
    }
    let rel = (sum - weight).abs() / weight;
    println!("Σ F_n = {sum:.9} N, m g = {weight:.9} N ({rel:.1e} relative)");
    assert!(rel < 1e-6, "Σ F_n = {sum}, m g = {weight}");
    // friction vanishes at rest: |F_t| ≤ μ F_n |v_t| / eps
    assert!(feet.iter().all(|f| f.2 < 1e-3), "{feet:?}");
    // The middle and rear feet carry the robot; the front ones hang just above the ground:
    // every leg points forward (+x) from its hip (a = 0), so the feet stand in rows at
    // x ≈ 0.78, 0.38 and −0.01 m while the centre of mass is at x ≈ 0.09 m, behind the middle
    // row; a (nearly) rigid base on three rows of springs would need a pulling front row.
    for (k, foot) in feet.iter().enumerate().take(2) {
        assert!(foot.1 == 0.0 && foot.0 > 0.0, "front foot {k}: {foot:?}");
    }
    for (k, foot) in feet.iter().enumerate().skip(2) {
        assert!(foot.1 > 0.1 * weight / 6.0, "foot {k}: {foot:?}");
    }
    // centre of pressure = centre of mass (no friction left, no acceleration)
    let mut kin = Kinematics::new::<HexapodStanding>();
    model.kinematics(0.0, tr.q(n), tr.qd(n), &mut kin);
    let cop: f64 = (0..6)
        .map(|k| feet[k].1 * kin.points[k].position[0])
        .sum::<f64>()
        / sum;
    println!("centre of pressure x = {cop:.4} m");
}

#[test]
fn static_equilibrium_is_the_settled_state() {
    let run = settled();
    let tr = &run.trajectory;
    let n = tr.len() - 1;
    let (q_sim, qd_sim) = (tr.q(n), tr.qd(n));
    let model = HexapodStanding::default();
    // At rest the regularised friction is zero (it is viscous below eps: no static friction
    // and no stiffness), and gravity and the normal forces are invariant under horizontal
    // translations and yaw of the whole robot: x, y and ψ are neutral and the stiffness is
    // singular in them. Held at the simulation's values, the rest has a unique equilibrium.
    let options = StaticsOptions {
        q0: Some(q_sim.to_vec()),
        locked: NEUTRAL.to_vec(),
        ..Default::default()
    };
    let start = Instant::now();
    let eq = static_equilibrium(&model, &options).expect("the equilibrium");
    let cpu = start.elapsed();
    let gap = max_abs(
        &eq.q
            .iter()
            .zip(q_sim)
            .map(|(a, b)| a - b)
            .collect::<Vec<_>>(),
    );
    // The settled state is still creeping: the slowest mode decays at rate r, so the state is
    // |qd|/r from its end; the Newton tolerance (1e-9 N) over the smallest stiffness adds
    // ~1e-13. Allow ten times that distance.
    let rate = slowest_decay(&model, q_sim);
    let k_min = eq.stiffness_eigenvalues[0];
    let tol = 10.0 * (max_abs(qd_sim) / rate + options.tolerance / k_min);
    println!(
        "from the settled state, x, y, ψ locked ({cpu:.1?}): {eq}\nmax |q_eq − q_sim| = \
         {gap:.2e} (allowed {tol:.1e}: |qd| {:.1e}, slowest decay {rate:.2}/s)",
        max_abs(qd_sim)
    );
    assert!(eq.residual < options.tolerance, "{eq}");
    assert_eq!(eq.stability, Stability::Stable, "{eq}");
    assert_eq!(eq.free.len(), 21);
    assert!(gap < tol, "{gap:e} ≥ {tol:e}");

    // From the declared start, lowered by the feet's clearance so that they touch (in the
    // air the stiffness has no z column): the same equilibrium up to x, y, ψ.
    let (mut q0, mut qd0) = (vec![0.0; 24], vec![0.0; 24]);
    model.initial_state(&mut q0, &mut qd0);
    let clearance = foot_forces(&model, &q0, &qd0)
        .iter()
        .map(|f| f.0)
        .fold(f64::INFINITY, f64::min);
    q0[2] -= clearance + 1e-3;
    let lowered = StaticsOptions {
        q0: Some(q0),
        locked: NEUTRAL.to_vec(),
        ..Default::default()
    };
    let eq2 = static_equilibrium(&model, &lowered).expect("from the lowered start");
    let gap2 = (0..24)
        .filter(|i| !NEUTRAL.contains(i))
        .map(|i| (eq2.q[i] - eq.q[i]).abs())
        .fold(0.0, f64::max);
    println!(
        "from the declared start lowered by {:.4} m: {} iterations, residual {:.1e}, \
         {:?}; max |Δq| outside x, y, ψ = {gap2:.1e}",
        clearance + 1e-3,
        eq2.iterations,
        eq2.residual,
        eq2.stability
    );
    assert_eq!(eq2.stability, Stability::Stable);
    assert!(gap2 < 1e-9, "{gap2:e}");

    // Unlocked: Newton meets a singular stiffness (x first), where a damped step
    // (K + μ diag M) goes on, to the same equilibrium up to x, y, ψ (before, a
    // `SingularMatrix` in x) …
    let free = StaticsOptions {
        q0: Some(q_sim.to_vec()),
        ..Default::default()
    };
    let unlocked = static_equilibrium(&model, &free).expect("unlocked from the settled state");
    // read in the model's chart, as `eq` (whose yaw was locked, its chart left as it was)
    let mut q_unlocked = unlocked.q.clone();
    let joint = &model.info().rotation_joints[0];
    mbs::charts::in_identity_chart(joint, &unlocked.charts[0], &mut q_unlocked, &mut [0.0; 24]);
    let gap3 = (0..24)
        .filter(|i| !NEUTRAL.contains(i))
        .map(|i| (q_unlocked[i] - eq.q[i]).abs())
        .fold(0.0, f64::max);
    println!(
        "unlocked from the settled state: {} iterations, {:?}, max |Δq| outside x, y, ψ = \
         {gap3:.1e}, x, y, ψ moved by {:.1e}, {:.1e}, {:.1e}",
        unlocked.iterations,
        unlocked.stability,
        q_unlocked[0] - q_sim[0],
        q_unlocked[1] - q_sim[1],
        q_unlocked[3] - q_sim[3],
    );
    assert_eq!(unlocked.stability, Stability::Neutral);
    assert!(gap3 < 1e-9, "{gap3:e}");
    // … and at the equilibrium itself it has three zero eigenvalues: Neutral.
    let at_eq = StaticsOptions {
        q0: Some(eq.q.clone()),
        ..Default::default()
    };
    let neutral = static_equilibrium(&model, &at_eq).expect("already at rest");
    let zeros = neutral
        .stiffness_eigenvalues
        .iter()
        .filter(|e| e.abs() < 1e-6)
        .count();
    println!(
        "unlocked at the equilibrium: {:?}, smallest eigenvalues {:.1e} {:.1e} {:.1e} {:.1e}",
        neutral.stability,
        neutral.stiffness_eigenvalues[0],
        neutral.stiffness_eigenvalues[1],
        neutral.stiffness_eigenvalues[2],
        neutral.stiffness_eigenvalues[3]
    );
    assert_eq!(neutral.stability, Stability::Neutral);
    assert_eq!(zeros, 3);
}

/// The scenes share the mechanics: the same M everywhere, and the same static forces where
/// neither the contact (feet in the air) nor the controllers (joints at their references)
/// push.
#[test]
fn free_and_standing_scenes_share_the_mechanics() {
    let (free, standing) = (Hexapod::default(), HexapodStanding::default());
    assert_eq!(free.info().scene, "Free");
    assert_eq!(standing.info().scene, "Standing");
    let n = Hexapod::NQ;
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    free.initial_state(&mut q, &mut qd);
    let (mut m1, mut m2) = (vec![0.0; n * n], vec![0.0; n * n]);
    let q_test: Vec<f64> = (0..n).map(|i| 0.5 * (1.3 * i as f64 + 0.4).sin()).collect();
    free.mass_matrix(0.0, &q_test, &mut m1);
    standing.mass_matrix(0.0, &q_test, &mut m2);
    assert_eq!(m1, m2);
    let (mut h1, mut h2) = (vec![0.0; n], vec![0.0; n]);
    free.static_forces(0.0, &q, &[], &mut h1);
    standing.static_forces(0.0, &q, &[], &mut h2);
    let d = max_abs(&h1.iter().zip(&h2).map(|(a, b)| a - b).collect::<Vec<_>>());
    assert!(d < 1e-12 * max_abs(&h1), "{d:e}");
}
