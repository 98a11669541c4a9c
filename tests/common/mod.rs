//! Helpers shared by the integration tests: exact solutions and reference data.
#![allow(dead_code)]

use mbs::{ConstraintMethod, ConstraintOptions, Model, Options, Output, Stats, Trajectory};

/// The seed2dof system: M = I, K = [[k1 + k2, −k2], [−k2, k2]], q0 = (0, 1), qd0 = 0.
pub const K1: f64 = 79.15;
pub const K2: f64 = 1961.0;

/// Angular frequencies ω₁ < ω₂ and orthonormal modes (columns) of seed2dof.
pub fn seed2dof_modes() -> ([f64; 2], [[f64; 2]; 2]) {
    let (a, b, d) = (K1 + K2, -K2, K2);
    let tr = a + d;
    let disc = ((a - d) * (a - d) / 4.0 + b * b).sqrt();
    let lam = [tr / 2.0 - disc, tr / 2.0 + disc];
    let mut modes = [[0.0; 2]; 2];
    for (k, &l) in lam.iter().enumerate() {
        let v = [b, l - a];
        let nv = v[0].hypot(v[1]);
        modes[k] = [v[0] / nv, v[1] / nv];
    }
    ([lam[0].sqrt(), lam[1].sqrt()], modes)
}

/// Exact q(t) of seed2dof from q0 = (0, 1), qd0 = 0.
pub fn seed2dof_exact(t: f64) -> [f64; 2] {
    let (w, v) = seed2dof_modes();
    let mut q = [0.0; 2];
    for k in 0..2 {
        let c = v[k][1]; // projection of q0 = (0, 1) on mode k
        for i in 0..2 {
            q[i] += v[k][i] * c * (w[k] * t).cos();
        }
    }
    q
}

/// Largest |q − q_exact| over the outputs of a seed2dof trajectory.
pub fn seed2dof_max_error(tr: &Trajectory) -> f64 {
    (0..tr.len())
        .map(|i| {
            let e = seed2dof_exact(tr.t[i]);
            let q = tr.q(i);
            (q[0] - e[0]).abs().max((q[1] - e[1]).abs())
        })
        .fold(0.0, f64::max)
}

/// Least-squares slope of log(y) against log(x).
pub fn loglog_slope(x: &[f64], y: &[f64]) -> f64 {
    let lx: Vec<f64> = x.iter().map(|v| v.ln()).collect();
    let ly: Vec<f64> = y.iter().map(|v| v.ln()).collect();
    let n = lx.len() as f64;
    let (mx, my) = (lx.iter().sum::<f64>() / n, ly.iter().sum::<f64>() / n);
    let sxy: f64 = lx.iter().zip(&ly).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = lx.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

/// A reference state from `tests/reference/<model>.json` at time `t`: (q, qd).
pub fn reference_state(model: &str, t: f64) -> (Vec<f64>, Vec<f64>) {
    let path = format!(
        "{}/tests/reference/{model}.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let states = json["states"].as_array().expect("states");
    let s = states
        .iter()
        .find(|s| (s["t"].as_f64().unwrap() - t).abs() < 1e-12)
        .unwrap_or_else(|| panic!("no state at t = {t}"));
    let v = |k: &str| {
        s[k].as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect::<Vec<f64>>()
    };
    (v("q"), v("qd"))
}

/// Largest difference between the last output of `tr` and a reference state.
pub fn final_error(tr: &Trajectory, q: &[f64], qd: &[f64]) -> f64 {
    let i = tr.len() - 1;
    tr.q(i)
        .iter()
        .zip(q)
        .chain(tr.qd(i).iter().zip(qd))
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

/// Largest |Φ_i| and |Φ̇_i| = |B qd + Φ_t| over the outputs of a trajectory.
pub fn constraint_residuals<M: Model>(m: &M, t: &Trajectory) -> (f64, f64) {
    let (n, nc) = (M::NQ, M::NC);
    let (mut phi, mut b, mut phi_t) = (vec![0.0; nc], vec![0.0; nc * n], vec![0.0; nc]);
    let (mut worst, mut worst_rate) = (0.0f64, 0.0f64);
    for k in 0..t.len() {
        let (tk, q, qd) = (t.t[k], t.q(k), t.qd(k));
        m.constraints(tk, q, &mut phi);
        m.constraint_jacobian(tk, q, &mut b);
        m.constraint_rate(tk, q, &mut phi_t);
        for i in 0..nc {
            let rate = phi_t[i] + (0..n).map(|j| b[i + nc * j] * qd[j]).sum::<f64>();
            worst = worst.max(phi[i].abs());
            worst_rate = worst_rate.max(rate.abs());
        }
    }
    (worst, worst_rate)
}

/// `base` keeping the last sample only, without energy, closing loops with `method`.
pub fn with_method(base: Options, method: ConstraintMethod) -> Options {
    Options {
        output: Output::Last,
        energy: false,
        constraints: ConstraintOptions {
            method,
            ..Default::default()
        },
        ..base
    }
}

/// Fixed steps of 1/k over 1 s with Newton converged well below the errors measured.
pub fn fixed(k: u32) -> Options {
    let mut o = Options::fixed(1.0, 1.0 / k as f64);
    o.newton.atol = 1e-14;
    o.newton.rtol = 1e-14;
    o.newton.max_iterations = 20;
    o
}

/// An example program, built by Cargo if it is not up to date.
pub fn example(name: &str) -> std::path::PathBuf {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| env!("CARGO").to_string());
    let mut build = std::process::Command::new(cargo);
    build.args(["build", "--quiet", "--example", name]);
    if !cfg!(debug_assertions) {
        build.arg("--release");
    }
    let status = build
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .status()
        .unwrap();
    assert!(status.success(), "cargo build --example {name}");
    // target/PROFILE/deps/cli-HASH → target/PROFILE/examples/NAME
    let exe = std::env::current_exe().unwrap();
    let path = exe.parent().unwrap().parent().unwrap().join("examples");
    path.join(format!("{name}{}", std::env::consts::EXE_SUFFIX))
}

/// Central differences of τ(q, qd, qdd) at fixed qdd with step `h`: (K, C), column-major
/// like the model's tangents.
pub fn fd_tangents<M: Model>(
    m: &M,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    h: f64,
) -> (Vec<f64>, Vec<f64>) {
    let n = M::NQ;
    let (mut k, mut c) = (vec![0.0; n * n], vec![0.0; n * n]);
    let (mut tp, mut tm) = (vec![0.0; n], vec![0.0; n]);
    for j in 0..n {
        for (var, out) in [(0, &mut k), (1, &mut c)] {
            let (mut qp, mut qm, mut vp, mut vm) =
                (q.to_vec(), q.to_vec(), qd.to_vec(), qd.to_vec());
            if var == 0 {
                qp[j] += h;
                qm[j] -= h;
            } else {
                vp[j] += h;
                vm[j] -= h;
            }
            m.inverse_dynamics(0.0, &qp, &vp, qdd, &[], &mut tp);
            m.inverse_dynamics(0.0, &qm, &vm, qdd, &[], &mut tm);
            for i in 0..n {
                out[i + n * j] = (tp[i] - tm[i]) / (2.0 * h);
            }
        }
    }
    (k, c)
}

/// ∂/∂s of E along the motion: E(q + s qd + ½ s² qdd, qd + s qdd) by central differences
/// of step `s`.
pub fn energy_rate<M: Model>(m: &M, t: f64, q: &[f64], qd: &[f64], qdd: &[f64], s: f64) -> f64 {
    let at = |s: f64| {
        let qs: Vec<f64> = (0..q.len())
            .map(|i| q[i] + s * qd[i] + 0.5 * s * s * qdd[i])
            .collect();
        let vs: Vec<f64> = (0..q.len()).map(|i| qd[i] + s * qdd[i]).collect();
        m.energy(t, &qs, &vs).total()
    };
    (at(s) - at(-s)) / (2.0 * s)
}

/// qdd = M⁻¹ h (dense Cholesky).
pub fn accelerations<M: Model>(m: &M, t: f64, q: &[f64], qd: &[f64]) -> Vec<f64> {
    let n = M::NQ;
    let (mut mm, mut h) = (vec![0.0; n * n], vec![0.0; n]);
    m.dynamics(t, q, qd, &[], &mut mm, &mut h);
    let mm = nalgebra::DMatrix::from_column_slice(n, n, &mm);
    mm.cholesky()
        .expect("M positive definite")
        .solve(&nalgebra::DVector::from_column_slice(&h))
        .as_slice()
        .to_vec()
}

/// steps, rejected by the error test, by Newton, M+h, forward dynamics, M, τ, factorisations,
/// solves, Newton iterations
pub fn work_counts(s: &Stats) -> [usize; 10] {
    [
        s.steps,
        s.rejected_error,
        s.rejected_newton,
        s.dynamics,
        s.forward_dynamics,
        s.mass_matrix,
        s.inverse_dynamics,
        s.factorizations,
        s.solves,
        s.newton_iterations,
    ]
}

/// The characteristic polynomial x³ + c₀x² + c₁x + c₂ of generalized-α's amplification matrix
/// (Chung & Hulbert 1993) on ẍ = −ω²x, state (d, v, a), with h = 1 and ω = `wh`:
/// (1 − α_m) a₁ + α_m a₀ = −ω²((1 − α_f) d₁ + α_f d₀) with Newmark's
/// d₁ = d₀ + h v₀ + h²((½ − β) a₀ + β a₁), v₁ = v₀ + h((1 − γ) a₀ + γ a₁); returns
/// [c₀, c₁, c₂] = [−trace, sum of the principal 2×2 minors, −determinant].
pub fn gen_alpha_characteristic(am: f64, af: f64, beta: f64, gamma: f64, wh: f64) -> [f64; 3] {
    // with h = 1 and ω = wh: eliminate a₁ from the equilibrium
    let w2 = wh * wh;
    let den = (1.0 - am) + (1.0 - af) * w2 * beta;
    // a₁ = (−α_m a₀ − ω²((1 − α_f)(d₀ + v₀ + (½ − β) a₀) + α_f d₀)) / den
    let a1 = [
        -w2 / den,
        -(1.0 - af) * w2 / den,
        (-am - (1.0 - af) * w2 * (0.5 - beta)) / den,
    ];
    let mut m = [[0.0; 3]; 3];
    for j in 0..3 {
        let unit = |k: usize| if j == k { 1.0 } else { 0.0 };
        m[0][j] = unit(0) + unit(1) + (0.5 - beta) * unit(2) + beta * a1[j];
        m[1][j] = unit(1) + (1.0 - gamma) * unit(2) + gamma * a1[j];
        m[2][j] = a1[j];
    }
    let tr = m[0][0] + m[1][1] + m[2][2];
    let minors = m[0][0] * m[1][1] - m[0][1] * m[1][0] + m[0][0] * m[2][2] - m[0][2] * m[2][0]
        + m[1][1] * m[2][2]
        - m[1][2] * m[2][1];
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    [-tr, minors, -det]
}
