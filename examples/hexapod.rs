//! A walking robot in the spirit of the seed's AMRU5: a 20 kg floating base and six 3-dof legs
//! with pantograph links and geared motor rotors, 24 dof and 49 bodies: the `hexapod` model of
//! `tests/reference/MODELS.md`, in two scenes: `Free` (gravity only, the type `Hexapod`) and
//! `Standing` (the feet in contact with the ground z = 0, a PD controller on every leg joint).
//!
//! Prints the model's sizes, a summary of M and h at the MODELS.md test state, the feet's
//! heights at the initial state and the operation counts of the generated functions. Then
//! drops the standing robot from the MODELS.md start (feet ~1 cm above the ground) for 5 s
//! (`--scheme`, default radau5; `--rtol`, `--t-end`, `--out DIR`; `--help` for all) and prints
//! the base height and the largest velocity over time, the feet's normal forces at the end
//! against the weight, the work done, and the static equilibrium of the standing robot.
//! `--scene Free` runs the other scene instead: no ground, a free fall for 1 s. The model
//! itself is in `models/src/hexapod.rs`.
//!
//! Run with `cargo run --release --example hexapod`.

#[path = "common/mod.rs"]
mod common;
use mbs_models::hexapod as model;

use clap::Parser;
use mbs::analysis::{AnalysisError, StaticsOptions, static_equilibrium};
use mbs::{Kinematics, Model};
use model::{Hexapod, HexapodStanding};

/// The base's x, y and yaw ψ: neutral at rest (no static friction), held in the statics.
const NEUTRAL: [usize; 3] = [0, 1, 3];

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// Height z, normal force F_n = step(δ)·pos(k δ − c v_z) with δ = −z (the contact law of
/// `mbs::language` for the plane z = 0) and size of the friction force
/// μ F_n |v_t| / sqrt(|v_t|² + eps²) of each foot.
fn foot_forces(model: &HexapodStanding, q: &[f64], qd: &[f64]) -> Vec<(f64, f64, f64)> {
    let p = model.params();
    let mut kin = Kinematics::new::<HexapodStanding>();
    model.kinematics(0.0, q, qd, &mut kin);
    // the six feet are the first points (the base's corners follow)
    kin.points[..6]
        .iter()
        .map(|foot| {
            let (z, v) = (foot.position[2], foot.velocity);
            let f_n = if z < 0.0 {
                (-p.k_contact * z - p.c_contact * v[2]).max(0.0)
            } else {
                0.0
            };
            let vt = v[0].hypot(v[1]);
            (z, f_n, p.mu * f_n * vt / (vt * vt + p.eps * p.eps).sqrt())
        })
        .collect()
}

/// The feet at the end of the run: forces, their sum against m g, the joints' PD torques.
fn at_rest(model: &HexapodStanding, q: &[f64], qd: &[f64]) {
    let p = model.params();
    let n = HexapodStanding::NQ;
    let mut m = vec![0.0; n * n];
    model.mass_matrix(0.0, q, &mut m);
    // the base translates in world axes: M[x][x] is the total mass
    let weight = m[0] * p.g;
    let feet = foot_forces(model, q, qd);
    let mut kin = Kinematics::new::<HexapodStanding>();
    model.kinematics(0.0, q, qd, &mut kin);
    println!(
        "\nfeet at the end:\n{:>6} {:>12} {:>12} {:>12}",
        "foot", "z (m)", "F_n (N)", "|F_t| (N)"
    );
    for (k, (z, f_n, f_t)) in feet.iter().enumerate() {
        println!("{k:>6} {z:>12.4e} {f_n:>12.6} {f_t:>12.2e}");
    }
    let sum: f64 = feet.iter().map(|f| f.1).sum();
    let cop = (0..6)
        .map(|k| feet[k].1 * kin.points[k].position[0])
        .sum::<f64>()
        / sum;
    println!(
        "Σ F_n = {sum:.9} N, total mass {:.4} kg × g = {weight:.9} N ({:.1e} relative); \
         centre of pressure at x = {cop:.4} m",
        m[0],
        (sum - weight).abs() / weight
    );
    println!("PD torques −Kp (q − q_ref) at the end (N m), per leg (hip yaw a, thigh b, knee c):");
    for leg in 0..6 {
        let j = 6 + 3 * leg;
        let tau = [
            -p.kp_a * (q[j] - p.a_ref),
            -p.kp_b * (q[j + 1] - p.b_ref),
            -p.kp_c * (q[j + 2] - p.c_ref),
        ];
        println!(
            "  leg {leg}: {:>8.3} {:>8.3} {:>8.3}",
            tau[0], tau[1], tau[2]
        );
    }
}

/// The static equilibrium of the standing robot, from the state reached and from the
/// declared start lowered onto the ground.
fn statics(model: &HexapodStanding, q_end: &[f64]) -> Result<(), AnalysisError> {
    println!(
        "\nstatic equilibrium of the standing robot (x, y, ψ locked: at rest the regularised \
         friction is zero, so horizontal translation and yaw are neutral):"
    );
    let eq = static_equilibrium(
        model,
        &StaticsOptions {
            q0: Some(q_end.to_vec()),
            locked: NEUTRAL.to_vec(),
            ..Default::default()
        },
    )?;
    let gap = max_abs(
        &eq.q
            .iter()
            .zip(q_end)
            .map(|(a, b)| a - b)
            .collect::<Vec<_>>(),
    );
    println!("from the state reached: {eq}");
    println!("max |q_eq − q_end| = {gap:.2e}");
    print!("equilibrium:");
    for (name, q) in model.info().dofs.iter().zip(&eq.q) {
        print!(" {name} {q:.6}");
    }
    println!();

    let (mut q0, mut qd0) = (vec![0.0; 24], vec![0.0; 24]);
    model.initial_state(&mut q0, &mut qd0);
    let clearance = foot_forces(model, &q0, &qd0)
        .iter()
        .map(|f| f.0)
        .fold(f64::INFINITY, f64::min);
    // in the air the stiffness has no z column: start with the feet 1 mm into the ground
    q0[2] -= clearance + 1e-3;
    let eq2 = static_equilibrium(
        model,
        &StaticsOptions {
            q0: Some(q0),
            locked: NEUTRAL.to_vec(),
            ..Default::default()
        },
    )?;
    let gap2 = (0..24)
        .filter(|i| !NEUTRAL.contains(i))
        .map(|i| (eq2.q[i] - eq.q[i]).abs())
        .fold(0.0, f64::max);
    println!(
        "from the declared start lowered by {:.4} m: {:?} after {} iterations, residual {:.2e}; \
         max |Δq| outside x, y, ψ {gap2:.1e}",
        clearance + 1e-3,
        eq2.stability,
        eq2.iterations,
        eq2.residual
    );
    // unlocked, at the equilibrium: three zero eigenvalues
    let free = static_equilibrium(
        model,
        &StaticsOptions {
            q0: Some(eq.q.clone()),
            ..Default::default()
        },
    )?;
    println!(
        "x, y, ψ unlocked at the equilibrium: {:?}, smallest stiffness eigenvalues {:.1e} \
         {:.1e} {:.1e} {:.1e}",
        free.stability,
        free.stiffness_eigenvalues[0],
        free.stiffness_eigenvalues[1],
        free.stiffness_eigenvalues[2],
        free.stiffness_eigenvalues[3]
    );
    Ok(())
}

fn main() {
    let mut args = mbs::cli::RunArgs::parse();
    // the contact is stiff (1e5 N/m on ~0.6 kg feet, friction viscous at ~1e4 N s/m below
    // eps): an L-stable implicit scheme unless asked otherwise
    if !std::env::args().any(|a| a == "--scheme" || a.starts_with("--scheme=")) {
        args.scheme = "radau5".into();
    }
    if args.dt.is_none() {
        args.dt = Some(0.01);
    }
    match args.scene.as_deref() {
        Some("Free") => args.sweep_if_asked(&Hexapod::default(), 1.0),
        _ => args.sweep_if_asked(&HexapodStanding::default(), 5.0),
    }
    if !args.quiet {
        let model = Hexapod::default();
        common::show(&model);

        // feet at the initial state (base at z = 0.5 m, every leg at (a, b, c) = (0, 0.3, −0.3))
        let n = Hexapod::NQ;
        let (mut q0, mut qd0) = (vec![0.0; n], vec![0.0; n]);
        model.initial_state(&mut q0, &mut qd0);
        let mut kinematics = Kinematics::new::<Hexapod>();
        model.kinematics(0.0, &q0, &qd0, &mut kinematics);
        print!("foot heights at the start (m):");
        for foot in &kinematics.points[..6] {
            print!(" {:.4}", foot.position[2]);
        }
        println!();
    }

    match args.scene.as_deref() {
        None | Some("Standing") => {}
        Some("Free") => {
            // no ground: the robot falls freely with its legs still (exactly, for every
            // scheme of order ≥ 2: q is quadratic in t)
            if let Err(e) = args.run(Hexapod::default(), 1.0) {
                eprintln!("error: {e}");
                std::process::exit(1);
            }
            return;
        }
        Some(_) => {
            eprintln!("error: {}", args.unknown_scene(&["Free", "Standing"]));
            std::process::exit(2);
        }
    }
    let standing = HexapodStanding::default();
    if !args.quiet {
        let p = standing.params();
        println!(
            "\nscene Standing: contact k = {:e} N/m, c = {} N s/m, μ = {}, eps = {} m/s; PD \
             Kp = ({}, {}, {}) N m/rad, Kd = ({}, {}, {}) N m s/rad (hip yaw, thigh, knee)\n\
             {}",
            p.k_contact,
            p.c_contact,
            p.mu,
            p.eps,
            p.kp_a,
            p.kp_b,
            p.kp_c,
            p.kd_a,
            p.kd_b,
            p.kd_c,
            standing.info().ops_table()
        );
    }
    let report = match args.run(standing.clone(), 5.0) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    if args.quiet {
        return;
    }
    let tr = &report.trajectory;
    let n = tr.len() - 1;
    let speed: Vec<f64> = (0..tr.len()).map(|i| max_abs(tr.qd(i))).collect();
    println!(
        "\n{:>8} {:>14} {:>14}  fastest",
        "t (s)", "base z (m)", "max |qd|"
    );
    let mut next = 0.0;
    for (i, &v) in speed.iter().enumerate() {
        if tr.t[i] + 1e-9 >= next || i == n {
            let fastest = (0..24)
                .find(|&k| v > 0.0 && tr.qd(i)[k].abs() == v)
                .map_or("-", |k| tr.dof_names[k].as_str());
            println!(
                "{:>8.3} {:>14.9} {v:>14.3e}  {fastest}",
                tr.t[i],
                tr.q(i)[2],
            );
            next += 0.25;
        }
    }
    if let Some(i) = (0..tr.len()).rev().find(|&i| speed[i] >= 1e-6) {
        if i < n {
            println!("every |qd_i| < 1e-6 from t = {:.2} s on", tr.t[i + 1]);
        } else {
            println!("still moving at the end (max |qd| {:.1e})", speed[n]);
        }
    }
    // (the work counters were printed by `run`, above)
    at_rest(&standing, tr.q(n), tr.qd(n));
    if let Err(e) = statics(&standing, tr.q(n)) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
