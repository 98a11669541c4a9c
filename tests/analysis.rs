//! The analyses (statics, linearisation, poles and inverse dynamics) against
//! independent references: poles of seed2dof (reference data, then with dampers against the
//! roots of det(λ²M + λC + K) written by hand), small oscillations of dpend and of an inverted
//! double pendulum on a cart (linearised M₀, K₀ derived by hand), the state matrix against
//! central differences of the nonlinear state derivative, statics with locked coordinates and
//! stability, inverse then forward dynamics, a rheonomic damped model, inputs, and the errors.
#![allow(clippy::needless_range_loop)]

#[path = "common/lcg.rs"]
mod lcg;
use lcg::Lcg;

#[path = "common/quoted.rs"]
mod quoted;

use mbs_models::arm3d_6;
use mbs_models::dpend;
use mbs_models::seed2dof;

use mbs::analysis::{
    AnalysisError, Stability, StaticsOptions, inverse_dynamics_along, linearize, modes,
    static_equilibrium,
};
use mbs::{Failure, IterationMatrix, Model};
use nalgebra::{Complex, DMatrix};
use std::f64::consts::PI;

// ---------------------------------------------------------------------------------------------
// Models written for these tests

/// Parameters of the cart with an inverted double pendulum (also the model's defaults).
const MC: f64 = 2.0;
const M1: f64 = 1.0;
const M2: f64 = 0.5;
const L1: f64 = 1.0;
const L2: f64 = 0.6;
const G: f64 = 9.81;

/// seed2dof's damping, ground–mass 1 and mass 1–mass 2.
const C1: f64 = 0.8;
const C2: f64 = 3.0;

#[path = "common/oscillators.rs"]
mod oscillators;

/// Three masses on springs along x, y and z, two soft (ω = 1 and 1.2 rad/s) beside a stiff
/// one (ω = 1e5 rad/s, a gear's stiffness on a small inertia), with exact tangents.
fn soft_beside_stiff() -> oscillators::Oscillators {
    oscillators_of(1.0, 1.44, 1e10)
}

/// The oscillators with springs of stiffness kx, ky and kz.
fn oscillators_of(kx: f64, ky: f64, kz: f64) -> oscillators::Oscillators {
    let mut model = oscillators::Oscillators::default();
    let mut p = model.params().clone();
    (p.kx, p.ky, p.kz) = (kx, ky, kz);
    model.set_params(p).unwrap();
    model
}

mbs::multibody! {
    /// A mass on a spring with forces that change on a micrometre scale: a regularised
    /// Coulomb friction fc tanh(v/v_e) (v_e = 1 µm/s) and a detent fd tanh(x/x_e) (x_e = 1 µm);
    /// at rest at x = 0 its stiffness is k + fd/x_e = 200 N/m and its damping fc/v_e = 2 N·s/m.
    model Micro {
        param k = 100.0; param fc = 2e-6; param fd = 1e-4;
        option tangents;
        dof x = 0.0;
        body a { mass = 1.0; inertia = (0.01, 0.01, 0.01); }
        TOG[a] = Tdisp(x, 0, 0);
        generalized_force(x, -k * x - fd * tanh(x / 1e-6) - fc * tanh(qd[x] / 1e-6));
    }
}

mbs::multibody! {
    /// seed2dof with dampers in parallel with both springs, named coordinates.
    model Seed2dofDamped {
        param m1 = 1.0; param m2 = 1.0;
        param k1 = 79.15; param k2 = 1961.0;
        param c1 = 0.8; param c2 = 3.0;
        dof x1 = 0.0; dof x2 = 1.0;
        body mass1 { mass = m1; }
        body mass2 { mass = m2; }
        TOG[mass1] = Tdisp(1 + x1, 0, 0);
        TOG[mass2] = Tdisp(2 + x2, 0, 0);
        spring(ground, mass1, k = k1, l0 = 1, axis = x);
        spring(mass1, mass2, k = k2, l0 = 1, axis = x);
        damper(ground, mass1, c = c1, axis = x);
        damper(mass1, mass2, c = c2, axis = x);
    }
}

mbs::multibody! {
    /// A cart on x carrying two uniform bars hinged end to end, pointing up at a = b = 0;
    /// a = bar 1's angle from the upward vertical, b = bar 2's angle relative to bar 1.
    model CartPole {
        param mc = 2.0; param m1 = 1.0; param m2 = 0.5;
        param l1 = 1.0; param l2 = 0.6; param g = 9.81;
        dof x = 0.0; dof a = 0.0; dof b = 0.0;
        body cart { mass = mc; }
        body bar1 { mass = m1; inertia = (m1 * l1 * l1 / 12, 0, m1 * l1 * l1 / 12); }
        body bar2 { mass = m2; inertia = (m2 * l2 * l2 / 12, 0, m2 * l2 * l2 / 12); }
        TOG[cart] = Tdisp(x, 0, 0);
        TOG[bar1] = TOG[cart] * Trotz(a) * Tdisp(0, l1 / 2, 0);
        TOG[bar2] = TOG[bar1] * Tdisp(0, l1 / 2, 0) * Trotz(b) * Tdisp(0, l2 / 2, 0);
        gravity(0, -g, 0);
        option tangents;
    }
}

mbs::multibody! {
    /// A double pendulum whose support is moved along x (rheonomic), with a damper along x
    /// on its tip, a relative damping torque and a quadratic drag torque on bar 1.
    model Driven {
        param a = 0.05; param w = 3.0; param c1 = 0.4; param c2 = 0.1;
        param l = 1.0; param m = 1.0; param g = 9.81;
        dof th1 = 0.4, qd = 0.7; dof th2 = -0.3, qd = -0.5;
        body bar1 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar2 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        TOG[bar1] = Tdisp(a * sin(w * t), 0, 0) * Trotz(th1) * Tdisp(0, -l / 2, 0);
        TOG[bar2] = TOG[bar1] * Tdisp(0, -l / 2, 0) * Trotz(th2) * Tdisp(0, -l / 2, 0);
        point tip on bar2 at (0, -l / 2, 0);
        gravity(0, -g, 0);
        damper(ground, tip, c = c1, axis = x);
        torque(bar2, relative_to = bar1, axis = z, -c2 * qd[1]);
        torque(bar1, axis = z, -0.05 * qd[0] * abs(qd[0]));
        option tangents;
    }
}

mbs::multibody! {
    /// A double pendulum driven by two inputs: a torque at the elbow, a horizontal push at the
    /// tip, and a generalised force nonlinear in the inputs.
    model Actuated {
        param l = 1.0; param m = 1.0; param g = 9.81;
        dof q[0] = 0.3; dof q[1] = -0.2;
        input torque; input push;
        body bar1 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body bar2 { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        TOG[bar1] = Trotz(q[0]) * Tdisp(0, -l / 2, 0);
        TOG[bar2] = TOG[bar1] * Tdisp(0, -l / 2, 0) * Trotz(q[1]) * Tdisp(0, -l / 2, 0);
        point tip on bar2 at (0, -l / 2, 0);
        gravity(0, -g, 0);
        torque(bar2, relative_to = bar1, axis = z, torque);
        force(tip, (push, 0, 0));
        generalized_force(q[0], 0.3 * torque * push);
        option tangents;
    }
}

mbs::multibody! {
    /// A uniform bar hinged at one end under a constant torque of 10 N·m, more than gravity's
    /// largest m g l/2 = 4.905 N·m: no static equilibrium.
    model Overdriven {
        param l = 1.0; param m = 1.0; param g = 9.81;
        dof th = 0.3;
        body bar { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        TOG[bar] = Trotz(th) * Tdisp(0, -l / 2, 0);
        gravity(0, -g, 0);
        generalized_force(q[0], 10.0);
    }
}

mbs::multibody! {
    /// A free mass pushed by a constant force: no stiffness at all.
    model Pushed {
        dof x = 0.0;
        body mass { mass = 1.0; }
        TOG[mass] = Tdisp(x, 0, 0);
        generalized_force(q[0], 1.0);
    }
}

// ---------------------------------------------------------------------------------------------
// Independent tools: a linear solve, the nonlinear state derivative and its differences

#[path = "common/dense.rs"]
mod dense;
use dense::solve;

/// f(x) = (qd, M⁻¹h) with x = (q, qd).
fn state_derivative<M: Model>(model: &M, t: f64, x: &[f64], u: &[f64]) -> Vec<f64> {
    let n = M::NQ;
    let (q, qd) = x.split_at(n);
    let (mut m, mut h) = (vec![0.0; n * n], vec![0.0; n]);
    model.dynamics(t, q, qd, u, &mut m, &mut h);
    qd.iter().copied().chain(solve(&m, &h)).collect()
}

/// Central differences of f with respect to x (2n × 2n) and to u (2n × nu).
fn fd_state_space<M: Model>(
    model: &M,
    t: f64,
    x: &[f64],
    u: &[f64],
) -> (DMatrix<f64>, DMatrix<f64>) {
    let n2 = x.len();
    let mut a = DMatrix::zeros(n2, n2);
    let mut b = DMatrix::zeros(n2, u.len());
    for j in 0..n2 + u.len() {
        let (mut xp, mut xm, mut up, mut um) = (x.to_vec(), x.to_vec(), u.to_vec(), u.to_vec());
        let v = if j < n2 { x[j] } else { u[j - n2] };
        let eps = 1e-5 * v.abs().max(1.0);
        if j < n2 {
            xp[j] += eps;
            xm[j] -= eps;
        } else {
            up[j - n2] += eps;
            um[j - n2] -= eps;
        }
        let (fp, fm) = (
            state_derivative(model, t, &xp, &up),
            state_derivative(model, t, &xm, &um),
        );
        for i in 0..n2 {
            let d = (fp[i] - fm[i]) / (2.0 * eps);
            if j < n2 {
                a[(i, j)] = d;
            } else {
                b[(i, j - n2)] = d;
            }
        }
    }
    (a, b)
}

/// Central differences of τ(q, qd, qdd) at fixed qdd: (K = ∂τ/∂q, C = ∂τ/∂qd).
fn fd_tangents<M: Model>(
    model: &M,
    t: f64,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    u: &[f64],
) -> (DMatrix<f64>, DMatrix<f64>) {
    let n = M::NQ;
    let mut k = DMatrix::zeros(n, n);
    let mut c = DMatrix::zeros(n, n);
    let (mut tp, mut tm) = (vec![0.0; n], vec![0.0; n]);
    for j in 0..n {
        for (var, out) in [(0, &mut k), (1, &mut c)] {
            let (mut qp, mut qm, mut vp, mut vm) =
                (q.to_vec(), q.to_vec(), qd.to_vec(), qd.to_vec());
            let base = if var == 0 { q[j] } else { qd[j] };
            let eps = 1e-5 * base.abs().max(1.0);
            if var == 0 {
                qp[j] += eps;
                qm[j] -= eps;
            } else {
                vp[j] += eps;
                vm[j] -= eps;
            }
            model.inverse_dynamics(t, &qp, &vp, qdd, u, &mut tp);
            model.inverse_dynamics(t, &qm, &vm, qdd, u, &mut tm);
            for i in 0..n {
                out[(i, j)] = (tp[i] - tm[i]) / (2.0 * eps);
            }
        }
    }
    (k, c)
}

fn max_abs(a: &DMatrix<f64>) -> f64 {
    a.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// max |a − b| / max |b|
fn rel_diff(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    assert_eq!(a.shape(), b.shape());
    max_abs(&(a - b)) / max_abs(b).max(f64::MIN_POSITIVE)
}

/// Eigenvalues of a real matrix (nalgebra's Schur decomposition).
fn eigenvalues(a: &DMatrix<f64>) -> Vec<Complex<f64>> {
    a.clone().complex_eigenvalues().iter().copied().collect()
}

/// Largest distance from each wanted eigenvalue to the nearest computed one, relative to
/// max(|wanted|, 1).
fn eig_mismatch(got: &[Complex<f64>], want: &[Complex<f64>]) -> f64 {
    want.iter()
        .map(|w| {
            got.iter()
                .map(|g| (g - w).norm())
                .fold(f64::INFINITY, f64::min)
                / w.norm().max(1.0)
        })
        .fold(0.0, f64::max)
}

/// Roots of the monic polynomial xⁿ + c[0] xⁿ⁻¹ + … + c[n−1]: eigenvalues of its companion.
fn roots(c: &[f64]) -> Vec<Complex<f64>> {
    let n = c.len();
    let comp = DMatrix::from_fn(n, n, |i, j| {
        if i == 0 {
            -c[j]
        } else if i == j + 1 {
            1.0
        } else {
            0.0
        }
    });
    eigenvalues(&comp)
}

/// Product of polynomials, coefficients from the highest degree.
fn poly_mul(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut p = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            p[i + j] += x * y;
        }
    }
    p
}

/// [[0, I], [−M⁻¹K, 0]]
fn undamped_state_matrix(m: &DMatrix<f64>, k: &DMatrix<f64>) -> DMatrix<f64> {
    let n = m.nrows();
    let mk = -m.clone().try_inverse().unwrap() * k;
    DMatrix::from_fn(2 * n, 2 * n, |i, j| {
        if i < n {
            if j == n + i { 1.0 } else { 0.0 }
        } else if j < n {
            mk[(i - n, j)]
        } else {
            0.0
        }
    })
}

// ---------------------------------------------------------------------------------------------
// seed2dof

#[test]
fn seed2dof_poles_match_the_reference_and_are_undamped() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/reference/seed2dof.json");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let want: Vec<f64> = json["eigenfrequencies_hz"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();

    let model = seed2dof::Seed2dof::default();
    let lin = linearize(
        &model,
        0.0,
        &[0.0; 2],
        &[0.0; 2],
        &[],
        IterationMatrix::Auto,
    )
    .unwrap();
    let modes = modes(&lin, None).unwrap();
    assert_eq!(modes.modes.len(), 2);
    for (mode, f) in modes.modes.iter().zip(&want) {
        let err = (mode.frequency_hz - f).abs() / f;
        println!(
            "seed2dof: {:.9} Hz vs {f:.9} Hz, relative error {err:.2e}, ζ = {:.1e}",
            mode.frequency_hz, mode.damping_ratio
        );
        assert!(err < 1e-6, "{} Hz vs {f} Hz", mode.frequency_hz);
        assert!(
            mode.damping_ratio.abs() < 1e-10,
            "ζ = {}",
            mode.damping_ratio
        );
    }
    // the window selects modes by frequency
    let low = mbs::analysis::modes(&lin, Some((0.0, 5.0))).unwrap();
    assert_eq!(low.modes.len(), 1);
    assert!((low.modes[0].frequency_hz - want[0]).abs() < 1e-6);
    // a window upside down or with a NaN bound is refused, not an empty answer
    for w in [(5.0, 0.0), (f64::NAN, 5.0), (0.0, f64::NAN)] {
        let e = mbs::analysis::modes(&lin, Some(w)).unwrap_err();
        assert!(
            matches!(
                e,
                mbs::AnalysisError::Failure(mbs::Failure::InvalidOption { name: "window", .. })
            ),
            "{w:?}: {e}"
        );
    }
    let all = mbs::analysis::modes(&lin, Some((0.0, f64::INFINITY))).unwrap();
    assert_eq!(all.modes.len(), want.len());
}

#[test]
fn seed2dof_with_dampers_has_the_analytic_poles() {
    // M = I, K = [[k1 + k2, −k2], [−k2, k2]], C = [[c1 + c2, −c2], [−c2, c2]]:
    // det(λ²M + λC + K) = (λ² + (c1+c2)λ + k1+k2)(λ² + c2 λ + k2) − (c2 λ + k2)²
    let (k1, k2) = (79.15, 1961.0);
    let p11 = [1.0, C1 + C2, k1 + k2];
    let p22 = [1.0, C2, k2];
    let p12 = [0.0, C2, k2];
    let mut quartic = poly_mul(&p11, &p22);
    for (c, d) in quartic.iter_mut().zip(poly_mul(&p12, &p12)) {
        *c -= d;
    }
    assert_eq!(quartic[0], 1.0);
    let mut want: Vec<Complex<f64>> = roots(&quartic[1..])
        .into_iter()
        .filter(|z| z.im > 0.0)
        .collect();
    want.sort_by(|a, b| a.norm().total_cmp(&b.norm()));
    assert_eq!(want.len(), 2, "both modes are underdamped");

    let model = Seed2dofDamped::default();
    for how in [IterationMatrix::Auto, IterationMatrix::FiniteDifferences] {
        let lin = linearize(&model, 0.0, &[0.0; 2], &[0.0; 2], &[], how).unwrap();
        let c_hand = DMatrix::from_row_slice(2, 2, &[C1 + C2, -C2, -C2, C2]);
        assert!(rel_diff(&lin.c, &c_hand) < 1e-8, "C = {}", lin.c);
        let modes = modes(&lin, None).unwrap();
        assert_eq!(modes.modes.len(), 2);
        for (mode, w) in modes.modes.iter().zip(&want) {
            let (f, zeta) = (w.norm() / (2.0 * PI), -w.re / w.norm());
            let (ef, ez) = (
                (mode.frequency_hz - f).abs() / f,
                (mode.damping_ratio - zeta).abs(),
            );
            println!(
                "seed2dof damped ({how:?}): {:.9} Hz ζ = {:.9} vs {f:.9} Hz ζ = {zeta:.9}: errors {ef:.1e}, {ez:.1e}",
                mode.frequency_hz, mode.damping_ratio
            );
            assert!(ef < 1e-9 && ez < 1e-9);
            assert!((mode.re - w.re).abs() < 1e-8 * w.norm());
            assert!((mode.im - w.im).abs() < 1e-8 * w.norm());
        }
    }
}

// ---------------------------------------------------------------------------------------------
// dpend

#[test]
fn dpend_small_oscillations_match_two_uniform_bars() {
    // Absolute angles θ1 = q0, θ2 = q0 + q1 of two uniform bars (m = l = 1) hanging down:
    // T = ½ θ̇ᵀ [[m l²/3 + m l², m l²/2], [m l²/2, m l²/3]] θ̇ near θ = 0,
    // V = −m g (l/2) cos θ1 − m g (l cos θ1 + (l/2) cos θ2) ⇒ K_θ = diag(3/2, 1/2) m g l.
    // With θ = T q, T = [[1, 0], [1, 1]]: M₀ = TᵀM_θT, K₀ = TᵀK_θT.
    let m0 = DMatrix::from_row_slice(2, 2, &[8.0 / 3.0, 5.0 / 6.0, 5.0 / 6.0, 1.0 / 3.0]);
    let k0 = DMatrix::from_row_slice(2, 2, &[2.0 * G, 0.5 * G, 0.5 * G, 0.5 * G]);
    // ω² solves det(K₀ − ω² M₀) = 0: det(M₀) s² − (K00 M11 + K11 M00 − 2 K01 M01) s + det(K₀)
    let (a, b, c) = (
        m0.determinant(),
        k0[(0, 0)] * m0[(1, 1)] + k0[(1, 1)] * m0[(0, 0)] - 2.0 * k0[(0, 1)] * m0[(0, 1)],
        k0.determinant(),
    );
    let disc = (b * b - 4.0 * a * c).sqrt();
    let want = [(b - disc) / (2.0 * a), (b + disc) / (2.0 * a)].map(|s| s.sqrt() / (2.0 * PI));

    let model = dpend::DoublePendulum::default();
    let lin = linearize(
        &model,
        0.0,
        &[0.0; 2],
        &[0.0; 2],
        &[],
        IterationMatrix::Auto,
    )
    .unwrap();
    let (em, ek) = (rel_diff(&lin.m, &m0), rel_diff(&lin.k, &k0));
    println!(
        "dpend: M₀ error {em:.1e}, K₀ error {ek:.1e} (exact: {})",
        lin.exact
    );
    assert!(em < 1e-12 && ek < 1e-8);
    let modes = modes(&lin, None).unwrap();
    assert_eq!(modes.modes.len(), 2);
    for (mode, f) in modes.modes.iter().zip(want) {
        let err = (mode.frequency_hz - f).abs() / f;
        println!(
            "dpend: {:.9} Hz vs {f:.9} Hz, relative error {err:.1e}",
            mode.frequency_hz
        );
        assert!(err < 1e-8);
        assert!(mode.damping_ratio.abs() < 1e-8);
    }
}

// ---------------------------------------------------------------------------------------------
// Inverted double pendulum on a cart

/// Hand-derived M₀, K₀ of the cart–double-pendulum upright, in its coordinates (x, a, b).
fn cart_pole_linearised() -> (DMatrix<f64>, DMatrix<f64>) {
    // Absolute angles φ1 = a, φ2 = a + b from the upward vertical. Near upright the centroids
    // move horizontally: ẋ_G1 = ẋ − (l1/2) φ̇1, ẋ_G2 = ẋ − l1 φ̇1 − (l2/2) φ̇2, so with
    // Ii = mi li²/12, in (x, φ1, φ2):
    let m_abs = DMatrix::from_row_slice(
        3,
        3,
        &[
            MC + M1 + M2,
            -(M1 * L1 / 2.0 + M2 * L1),
            -M2 * L2 / 2.0,
            -(M1 * L1 / 2.0 + M2 * L1),
            M1 * L1 * L1 / 3.0 + M2 * L1 * L1,
            M2 * L1 * L2 / 2.0,
            -M2 * L2 / 2.0,
            M2 * L1 * L2 / 2.0,
            M2 * L2 * L2 / 3.0,
        ],
    );
    // V = m1 g (l1/2) cos φ1 + m2 g (l1 cos φ1 + (l2/2) cos φ2): its Hessian at 0
    let k_abs = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![
        0.0,
        -(M1 * L1 / 2.0 + M2 * L1) * G,
        -M2 * L2 / 2.0 * G,
    ]));
    // (x, φ1, φ2) = T (x, a, b)
    let t = DMatrix::from_row_slice(3, 3, &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0]);
    (t.transpose() * m_abs * &t, t.transpose() * k_abs * &t)
}

#[test]
fn inverted_cart_pendulum_state_matrix_and_poles() {
    let model = CartPole::default();
    let (q, qd) = ([0.3, 0.0, 0.0], [0.0; 3]);
    let lin = linearize(&model, 0.0, &q, &qd, &[], IterationMatrix::Auto).unwrap();
    assert!(lin.exact, "CartPole has `option tangents`");
    assert_eq!(lin.dof_names, ["q[0] (x)", "q[1] (a)", "q[2] (b)"]);

    // M₀, K₀ by hand
    let (m0, k0) = cart_pole_linearised();
    let (em, ek) = (rel_diff(&lin.m, &m0), rel_diff(&lin.k, &k0));
    println!(
        "cart pole: M₀ error {em:.1e}, K₀ error {ek:.1e}, C = {:.1e}",
        max_abs(&lin.c)
    );
    assert!(em < 1e-12 && ek < 1e-12);
    assert_eq!(max_abs(&lin.c), 0.0);

    // A vs central differences of f(x) = (qd, M⁻¹h)
    let x: Vec<f64> = q.iter().chain(&qd).copied().collect();
    let (a_fd, _) = fd_state_space(&model, 0.0, &x, &[]);
    let ea = rel_diff(&lin.a, &a_fd);
    println!(
        "cart pole: A vs central differences of f: {ea:.1e} (max |A| = {:.3})",
        max_abs(&lin.a)
    );
    assert!(ea < 1e-6);

    // eigenvalues vs those of [[0, I], [−M₀⁻¹K₀, 0]]: a double zero (the cart) and two
    // real pairs ±λ (both bars fall)
    let want = eigenvalues(&undamped_state_matrix(&m0, &k0));
    let got = eigenvalues(&lin.a);
    let nonzero: Vec<Complex<f64>> = want.iter().copied().filter(|z| z.norm() > 1e-3).collect();
    assert_eq!(nonzero.len(), 4);
    assert!(nonzero.iter().all(|z| z.im.abs() < 1e-9 * z.norm()));
    let ee = eig_mismatch(&got, &nonzero).max(eig_mismatch(
        &nonzero,
        &got.iter()
            .copied()
            .filter(|z| z.norm() > 1e-3)
            .collect::<Vec<_>>(),
    ));
    let zeros = got.iter().filter(|z| z.norm() < 1e-6).count();
    println!("cart pole: eigenvalues {got:.6?}, error {ee:.1e}");
    assert!(ee < 1e-10);
    assert_eq!(zeros, 2);

    // the modes: the unstable ones have ζ = −1
    let modes = modes(&lin, None).unwrap();
    let unstable = modes.modes.iter().filter(|m| m.re > 1e-3).count();
    assert_eq!(unstable, 2);
    assert!(
        modes
            .modes
            .iter()
            .filter(|m| m.re > 1e-3)
            .all(|m| (m.damping_ratio + 1.0).abs() < 1e-12)
    );
}

#[test]
fn inverted_cart_pendulum_statics() {
    let model = CartPole::default();
    let (_, k0) = cart_pole_linearised();
    // eigenvalues of K₀ on (a, b), symmetric 2 × 2 in closed form
    let (p, r, s) = (k0[(1, 1)], k0[(1, 2)], k0[(2, 2)]);
    let mid = (p + s) / 2.0;
    let rad = (((p - s) / 2.0).powi(2) + r * r).sqrt();
    let want = [mid - rad, mid + rad];
    let d = 5.0_f64.to_radians();
    for (a, b) in [(d, d), (d, -d), (-d, d), (-d, -d)] {
        let options = StaticsOptions {
            q0: Some(vec![0.3, a, b]),
            locked: vec![0],
            ..Default::default()
        };
        let eq = static_equilibrium(&model, &options).unwrap();
        let err = eq.q[1].abs().max(eq.q[2].abs());
        let ek = (0..2)
            .map(|i| (eq.stiffness_eigenvalues[i] - want[i]).abs() / want[i].abs())
            .fold(0.0, f64::max);
        println!(
            "cart pole statics from ({a:+.4}, {b:+.4}): {:?} in {} iterations, |q − upright| = {err:.1e}, residual {:.1e}, stiffness eigenvalues error {ek:.1e}",
            eq.stability, eq.iterations, eq.residual
        );
        assert_eq!(eq.q[0], 0.3, "the locked cart stays where it started");
        assert!(err < 1e-10);
        assert!(eq.residual <= 1e-9);
        assert_eq!(eq.stability, Stability::Unstable);
        assert_eq!(eq.free, ["q[1] (a)", "q[2] (b)"]);
        assert!(ek < 1e-10);
    }

    // free cart: the stiffness has a zero column along x, and Newton's step no solution; the
    // damped step (K + μ diag M) leaves the cart where it is, whose force is zero, and rights
    // the pendulum: upright, unstable, neutral along x (before, a `SingularMatrix` along x)
    let options = StaticsOptions {
        q0: Some(vec![0.3, d, -d]),
        ..Default::default()
    };
    let eq = static_equilibrium(&model, &options).unwrap();
    println!(
        "cart pole statics, cart free: {:?} in {} iterations, {:?} {:?}",
        eq.q, eq.iterations, eq.stability, eq.stiffness_eigenvalues
    );
    assert!(
        (eq.q[0] - 0.3).abs() < 1e-12,
        "the cart stays where it started"
    );
    assert!(eq.q[1].abs().max(eq.q[2].abs()) < 1e-10);
    assert!(eq.residual <= 1e-9);
    assert_eq!(eq.stability, Stability::Unstable);
    let e = &eq.stiffness_eigenvalues;
    assert!(e[2].abs() < 1e-9, "neutral along x: {e:?}");
    quoted::says(
        "README.md",
        &[format!(
            "the cart with its inverted double pendulum and the cart free the upright \
             equilibrium, `{:?}` and neutral along x",
            eq.stability
        )],
    );
    assert!(
        (0..2).all(|i| (e[i] - want[i]).abs() < 1e-10 * want[i].abs()),
        "{e:?} {want:?}"
    );
}

// ---------------------------------------------------------------------------------------------
// Inverse dynamics

#[test]
fn inverse_then_forward_dynamics_returns_qdd() {
    let model = arm3d_6::Arm3d6::default();
    let n = arm3d_6::Arm3d6::NQ;
    let mut rng = Lcg(7);
    let mut worst: f64 = 0.0;
    for _ in 0..20 {
        let t = rng.next();
        let q: Vec<f64> = (0..n).map(|_| PI * rng.next()).collect();
        let qd: Vec<f64> = (0..n).map(|_| 2.0 * rng.next()).collect();
        let qdd: Vec<f64> = (0..n).map(|_| 5.0 * rng.next()).collect();
        let efforts =
            inverse_dynamics_along(&model, &[t], &[], |_| (q.clone(), qd.clone(), qdd.clone()))
                .unwrap();
        assert_eq!(efforts.t, [t]);
        let tau = efforts.at(0);
        // forward dynamics with τ as a generalised force: M qdd = h + τ
        let (mut m, mut h) = (vec![0.0; n * n], vec![0.0; n]);
        model.dynamics(t, &q, &qd, &[], &mut m, &mut h);
        let rhs: Vec<f64> = h.iter().zip(tau).map(|(h, t)| h + t).collect();
        let back = solve(&m, &rhs);
        let err = back
            .iter()
            .zip(&qdd)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        worst = worst.max(err);
    }
    println!("arm3d_6: inverse then forward dynamics, max |qdd − qdd₀| = {worst:.1e}");
    assert!(worst < 1e-12);
}

/// A measured motion built by hand that does not fit the model is a typed error naming the
/// field, not an index out of range.
#[test]
fn a_trajectory_that_does_not_fit_the_model_is_named() {
    use mbs::analysis::{inverse_dynamics_actuated_of, inverse_dynamics_of};
    let model = seed2dof::Seed2dof::default();
    let measured = mbs::Trajectory {
        dof_names: vec!["x1".into(), "x2".into()],
        t: vec![0.0, 0.1],
        q_data: vec![0.0; 4],
        qd_data: vec![0.0; 4],
        // no accelerations
        ..Default::default()
    };
    let name = |e: mbs::analysis::AnalysisError| match e {
        mbs::analysis::AnalysisError::Failure(Failure::InvalidOption { name, .. }) => name,
        other => panic!("{other}"),
    };
    let e = inverse_dynamics_of(&model, &measured, &[]).unwrap_err();
    assert_eq!(name(e), "trajectory.qdd_data");
    let e = inverse_dynamics_actuated_of(&model, &measured, &[], &[0, 1]).unwrap_err();
    assert_eq!(name(e), "trajectory.qdd_data");
    // rotation joints the model does not have
    let joints = mbs::Trajectory {
        qdd_data: vec![0.0; 4],
        joint_names: vec!["base".into()],
        charts: vec![vec![[0.0, 0.0, 0.0, 1.0]]],
        chart_data: vec![0, 0],
        ..measured.clone()
    };
    let e = inverse_dynamics_of(&model, &joints, &[]).unwrap_err();
    assert_eq!(name(e), "trajectory.joint_names");
    // once it fits, it runs
    let fits = mbs::Trajectory {
        qdd_data: vec![0.0; 4],
        ..measured
    };
    assert_eq!(inverse_dynamics_of(&model, &fits, &[]).unwrap().t.len(), 2);
}

// ---------------------------------------------------------------------------------------------
// Velocity-dependent, rheonomic model

#[test]
fn rheonomic_damped_linearisation_matches_differences() {
    let model = Driven::default();
    let (t, q, qd) = (0.3, [0.4, -0.3], [0.7, -0.5]);
    let lin = linearize(&model, t, &q, &qd, &[], IterationMatrix::Auto).unwrap();
    assert!(lin.exact);
    // not an equilibrium: qdd = M⁻¹h ≠ 0, from an independent solve
    let x: Vec<f64> = q.iter().chain(&qd).copied().collect();
    let f = state_derivative(&model, t, &x, &[]);
    let eq = (0..2)
        .map(|i| (lin.qdd[i] - f[2 + i]).abs())
        .fold(0.0, f64::max);
    assert!(eq < 1e-12 && f[2].abs() > 0.1, "qdd = {:?}", lin.qdd);

    let (k_fd, c_fd) = fd_tangents(&model, t, &q, &qd, &lin.qdd, &[]);
    let (ek, ec) = (rel_diff(&lin.k, &k_fd), rel_diff(&lin.c, &c_fd));
    let (a_fd, _) = fd_state_space(&model, t, &x, &[]);
    let ea = rel_diff(&lin.a, &a_fd);
    println!(
        "driven: exact K vs differences {ek:.1e}, C {ec:.1e}, A {ea:.1e}; |C| = {:.3}",
        max_abs(&lin.c)
    );
    assert!(max_abs(&lin.c) > 0.1);
    assert!(ek < 1e-7 && ec < 1e-7 && ea < 1e-6);

    // the finite-difference path agrees
    let fd = linearize(&model, t, &q, &qd, &[], IterationMatrix::FiniteDifferences).unwrap();
    assert!(!fd.exact);
    let (ek, ec, ea) = (
        rel_diff(&fd.k, &lin.k),
        rel_diff(&fd.c, &lin.c),
        rel_diff(&fd.a, &lin.a),
    );
    println!("driven: FiniteDifferences vs exact: K {ek:.1e}, C {ec:.1e}, A {ea:.1e}");
    assert!(ek < 1e-7 && ec < 1e-7 && ea < 1e-7);
}

// ---------------------------------------------------------------------------------------------
// Inputs

/// Differences of forces that change on a micrometre scale: their step, ε^⅓ of a unit
/// (6 µm, 6 µm/s), spanned the whole of the detent's and the friction's change and gave the
/// state matrix a stiffness of 117 N/m and a damping of 0.33 N·s/m where the tangents say 200
/// and 2; the step is now checked against its quarter.
#[test]
fn differences_see_forces_on_a_micrometre_scale() {
    let model = Micro::default();
    let at = |how| linearize(&model, 0.0, &[0.0], &[0.0], &[], how).unwrap().a;
    let (exact, fd) = (
        at(IterationMatrix::Exact),
        at(IterationMatrix::FiniteDifferences),
    );
    println!("exact {exact}differences {fd}");
    assert!((exact[(1, 0)] + 200.0).abs() < 1e-9 && (exact[(1, 1)] + 2.0).abs() < 1e-12);
    let err = rel_diff(&fd, &exact);
    println!("state matrix by differences, relative error {err:.1e}");
    assert!(err < 1e-6, "{err:e}");
    quoted::says(
        "docs/status.md",
        &[format!(
            "from a step of 6 µm where they are 200 and 2, now within {err:.1e};"
        )],
    );
    // the statics' stiffness by differences too: the detent's 100 N/m is seen
    let eq = static_equilibrium(
        &model,
        &StaticsOptions {
            q0: Some(vec![0.0]),
            stiffness: IterationMatrix::FiniteDifferences,
            ..Default::default()
        },
    )
    .unwrap();
    let k = eq.stiffness_eigenvalues[0];
    println!("stiffness at rest by differences {k}");
    assert!((k - 200.0).abs() < 2e-4, "{k}");
}

#[test]
fn input_matrix_matches_differences() {
    let model = Actuated::default();
    let (q, qd, u) = ([0.3, -0.2], [0.4, 0.1], [0.5, -1.0]);
    let lin = linearize(&model, 0.0, &q, &qd, &u, IterationMatrix::Auto).unwrap();
    assert_eq!(lin.input_names, ["torque", "push"]);
    assert_eq!(lin.b.shape(), (4, 2));
    let x: Vec<f64> = q.iter().chain(&qd).copied().collect();
    let (a_fd, b_fd) = fd_state_space(&model, 0.0, &x, &u);
    let (eb, ea) = (rel_diff(&lin.b, &b_fd), rel_diff(&lin.a, &a_fd));
    println!("actuated: B vs differences of f in u {eb:.1e}, A {ea:.1e}");
    assert!(eb < 1e-8 && ea < 1e-6);
    // the position rows of B are zero
    assert!(lin.b.rows(0, 2).iter().all(|&v| v == 0.0));
}

// ---------------------------------------------------------------------------------------------
// Errors and output

#[test]
fn statics_without_equilibrium_does_not_converge() {
    let err = static_equilibrium(&Overdriven::default(), &StaticsOptions::default()).unwrap_err();
    println!("overdriven: {err}");
    assert!(matches!(err, AnalysisError::NotConverged { .. }), "{err:?}");

    // a constant force on a free mass: no stiffness to solve with, named
    let err = static_equilibrium(&Pushed::default(), &StaticsOptions::default()).unwrap_err();
    println!("pushed: {err}");
    match err {
        AnalysisError::Failure(Failure::SingularMatrix { coordinates, .. }) => {
            assert_eq!(coordinates, ["q[0] (x)"])
        }
        other => panic!("{other:?}"),
    }
}

/// A force within the tolerance is no equilibrium where the stiffness is as small: a spring
/// of 5e-7 N/m started 1 mm off pulls with 5e-10 N, below the default force tolerance of
/// 1e-9 N, and the start was returned as the equilibrium after no iteration.
#[test]
fn a_soft_spring_s_equilibrium_is_found_not_its_start() {
    let model = oscillators_of(5e-7, 1.0, 1.0);
    let eq = static_equilibrium(
        &model,
        &StaticsOptions {
            q0: Some(vec![1e-3, 0.0, 0.0]),
            ..Default::default()
        },
    )
    .unwrap();
    println!("{eq}");
    assert!(eq.q[0].abs() < 1e-12, "x = {} m", eq.q[0]);
    assert!(eq.iterations >= 1);
    assert!(eq.correction.is_some_and(|c| c <= 1e-10));
    assert_eq!(eq.stability, Stability::Stable);

    // a free mass at rest (no force, no stiffness): neutral, its start, no correction
    let free = oscillators_of(0.0, 1.0, 1.0);
    let eq = static_equilibrium(
        &free,
        &StaticsOptions {
            q0: Some(vec![0.3, 0.0, 0.0]),
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!((eq.q[0], eq.iterations, eq.correction), (0.3, 0, None));
    assert_eq!(eq.stability, Stability::Neutral);
}

#[test]
fn invalid_options_are_typed_errors() {
    let model = CartPole::default();
    let invalid = |options: StaticsOptions| match static_equilibrium(&model, &options) {
        Err(AnalysisError::Failure(Failure::InvalidOption { name, .. })) => name,
        other => panic!("{other:?}"),
    };
    let q0 = |v: Vec<f64>| StaticsOptions {
        q0: Some(v),
        ..Default::default()
    };
    assert_eq!(invalid(q0(vec![0.0; 2])), "q0");
    assert_eq!(invalid(q0(vec![0.0; 4])), "q0");
    assert_eq!(
        invalid(StaticsOptions {
            locked: vec![3],
            ..Default::default()
        }),
        "locked"
    );
    assert_eq!(
        invalid(StaticsOptions {
            u: Some(vec![1.0]),
            ..Default::default()
        }),
        "u"
    );
    assert_eq!(
        invalid(StaticsOptions {
            tolerance: 0.0,
            ..Default::default()
        }),
        "tolerance"
    );
    // each option by its own name
    assert_eq!(
        invalid(StaticsOptions {
            max_iterations: 0,
            ..Default::default()
        }),
        "max_iterations"
    );
    assert_eq!(
        invalid(StaticsOptions {
            t: f64::NAN,
            ..Default::default()
        }),
        "t"
    );
    // linearize: wrong lengths, and exact tangents of a model without them
    let lin_err = |r: Result<mbs::Linearization, AnalysisError>| match r {
        Err(AnalysisError::Failure(Failure::InvalidOption { name, .. })) => name,
        other => panic!("{other:?}"),
    };
    assert_eq!(
        lin_err(linearize(
            &model,
            0.0,
            &[0.0; 2],
            &[0.0; 3],
            &[],
            IterationMatrix::Auto
        )),
        "q"
    );
    assert_eq!(
        lin_err(linearize(
            &model,
            0.0,
            &[0.0; 3],
            &[0.0; 3],
            &[1.0],
            IterationMatrix::Auto
        )),
        "u"
    );
    let seed = seed2dof::Seed2dof::default();
    assert_eq!(
        lin_err(linearize(
            &seed,
            0.0,
            &[0.0; 2],
            &[0.0; 2],
            &[],
            IterationMatrix::Exact
        )),
        "how"
    );
    // inverse dynamics: a path of the wrong length
    let r = inverse_dynamics_along(&seed, &[0.0], &[], |_| (vec![0.0], vec![0.0], vec![0.0]));
    assert!(matches!(
        r.unwrap_err().cause(),
        AnalysisError::Failure(Failure::InvalidOption { name: "path", .. })
    ));
}

/// Inverse dynamics along a motion that turns non-finite at its third time: the failure
/// names the time and the value, and keeps the rows of the two times before it.
#[test]
fn inverse_dynamics_that_fail_along_a_motion_keep_the_rows_before() {
    use mbs::analysis::Computed;
    let seed = seed2dof::Seed2dof::default();
    let times = [0.0, 0.1, 0.2, 0.3];
    let path = |t: f64| {
        let x = if t > 0.15 { f64::NAN } else { t };
        (vec![x, 0.0], vec![0.0; 2], vec![1.0, 0.0])
    };
    let e = inverse_dynamics_along(&seed, &times, &[], path).unwrap_err();
    println!("{e}");
    let AnalysisError::AlongMotion {
        index, t, computed, ..
    } = &e
    else {
        panic!("{e:?}");
    };
    assert_eq!((*index, *t), (2, 0.2));
    assert!(matches!(
        e.cause(),
        AnalysisError::Failure(Failure::NonFinite { .. })
    ));
    let Computed::Efforts(kept) = computed.as_ref() else {
        panic!("{computed:?}");
    };
    let all = inverse_dynamics_along(&seed, &times[..2], &[], path).unwrap();
    assert_eq!(kept, &all);
}

#[test]
fn modes_table_and_csv_have_one_row_per_mode() {
    let model = Seed2dofDamped::default();
    let lin = linearize(
        &model,
        0.0,
        &[0.0; 2],
        &[0.0; 2],
        &[],
        IterationMatrix::Auto,
    )
    .unwrap();
    let modes = modes(&lin, None).unwrap();
    assert_eq!(modes.dof_names, ["q[0] (x1)", "q[1] (x2)"]);

    let table = modes.to_string();
    print!("{table}");
    let lines: Vec<&str> = table.lines().collect();
    assert!(lines[0].contains("frequency Hz") && lines[0].contains("damping"));
    let rows: Vec<&&str> = lines
        .iter()
        .filter(|l| {
            l.split_whitespace()
                .next()
                .is_some_and(|w| w.parse::<usize>().is_ok())
        })
        .collect();
    assert_eq!(rows.len(), 2);
    for (row, mode) in rows.iter().zip(&modes.modes) {
        assert!(row.contains(&format!("{:.6}", mode.frequency_hz)), "{row}");
    }
    let shapes: Vec<&&str> = lines.iter().filter(|l| l.contains("shape:")).collect();
    assert_eq!(shapes.len(), 2);
    assert!(
        shapes
            .iter()
            .all(|l| l.contains("q[0] (x1)") && l.contains("q[1] (x2)"))
    );

    let mut csv = Vec::new();
    modes.write_csv(&mut csv).unwrap();
    let csv = String::from_utf8(csv).unwrap();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 1 + 2);
    assert_eq!(
        lines[0],
        "frequency_hz,damping_ratio,re,im,modal_mass,q[0] (x1).re,q[0] (x1).im,q[1] (x2).re,q[1] (x2).im"
    );
    for (line, mode) in lines[1..].iter().zip(&modes.modes) {
        let v: Vec<f64> = line.split(',').map(|s| s.parse().unwrap()).collect();
        assert_eq!(v.len(), 9);
        assert_eq!(v[0], mode.frequency_hz);
        assert_eq!(v[1], mode.damping_ratio);
    }
}

/// The modes of the three oscillators about their rest.
fn modes_at_rest(model: &oscillators::Oscillators) -> mbs::Modes {
    let lin = linearize(model, 0.0, &[0.0; 3], &[0.0; 3], &[], IterationMatrix::Auto).unwrap();
    modes(&lin, None).unwrap()
}

/// Mode shapes beside a stiff mode: each of three uncoupled oscillators moves its own
/// coordinate alone. The shapes come from inverse iteration a hair off each pole; that hair
/// was a part in 10⁹ of the state matrix's largest entry (here 1e10/s², so 10/s), and the
/// 1 rad/s mode's shape came out a mix of all three coordinates (its neighbour at 1.2 rad/s
/// nearer the shifted pole than itself).
#[test]
fn mode_shapes_beside_a_stiff_mode_are_their_own() {
    let model = soft_beside_stiff();
    let modes = modes_at_rest(&model);
    assert_eq!(modes.modes.len(), 3);
    // the largest off-axis entry of a shape, and of a modal mass' distance from 1
    let (mut worst_off, mut worst_mass) = (0.0f64, 0.0f64);
    for (own, (mode, omega)) in modes.modes.iter().zip([1.0, 1.2, 1e5]).enumerate() {
        let off = (mode.shape.iter().enumerate())
            .filter(|&(i, _)| i != own)
            .fold(0.0f64, |m, (_, &(re, im))| m.max(re.hypot(im)));
        let (re, im) = mode.shape[own];
        println!(
            "{:.6} rad/s: shape on its own coordinate {re:.3e} + {im:.3e}i, largest elsewhere {off:.1e}, modal mass {:.12}",
            2.0 * PI * mode.frequency_hz,
            mode.modal_mass
        );
        assert!(
            (2.0 * PI * mode.frequency_hz - omega).abs() < 1e-9 * omega,
            "{}",
            mode.frequency_hz
        );
        assert!(off < 1e-10, "{off:e}");
        assert!((re - 1.0).abs() < 1e-12 && im.abs() < 1e-12, "{re} {im}");
        assert!((mode.modal_mass - 1.0).abs() < 1e-9, "{}", mode.modal_mass);
        worst_off = worst_off.max(off);
        worst_mass = worst_mass.max((mode.modal_mass - 1.0).abs());
    }
    assert!(worst_mass < 1e-12, "{worst_mass:e}");
    quoted::says(
        "docs/status.md",
        &[format!(
            "three oscillators of 1, 1.2 and 1e5 rad/s each give a shape on their own coordinate \
             alone (off-axis {worst_off:.1e} at most, modal masses 1 to 1e-12)"
        )],
    );
}

/// Slow modes beside a very stiff one oscillate: a pair counted as real when its imaginary
/// part was below 1e-12 of the state matrix's largest entry, here 1e13/s², so 10 rad/s, and
/// the modes of 1 and 1.2 rad/s were listed as real poles.
#[test]
fn slow_modes_beside_a_very_stiff_spring_oscillate() {
    let model = oscillators_of(1.0, 1.44, 1e13);
    let modes = modes_at_rest(&model);
    assert_eq!(modes.modes.len(), 3);
    for (mode, omega) in modes.modes.iter().zip([1.0, 1.2, 1e13f64.sqrt()]) {
        let w = 2.0 * PI * mode.frequency_hz;
        println!(
            "{w:.9e} rad/s, real {}, damping ratio {:.1e}",
            mode.is_real(),
            mode.damping_ratio
        );
        assert!(!mode.is_real());
        assert!((w - omega).abs() < 1e-9 * omega, "{w} rad/s");
        assert!(mode.damping_ratio.abs() < 1e-9, "{}", mode.damping_ratio);
    }
}

/// A repeated pole's two modes get two independent shapes of its plane, not one twice: the
/// inverse iteration starts differently for each (both started from one vector, and a
/// repeated eigenvalue keeps the start's mix of its eigenvectors).
#[test]
fn a_repeated_pole_has_two_independent_shapes() {
    let model = oscillators_of(1.0, 1.0, 1e10);
    let modes = modes_at_rest(&model);
    let (a, b) = (&modes.modes[0].shape, &modes.modes[1].shape);
    // |a × b| / (|a| |b|) over (x, y), the shapes real up to rounding
    let cross = a[0].0 * b[1].0 - a[1].0 * b[0].0;
    let sine = cross.abs() / (a[0].0.hypot(a[1].0) * b[0].0.hypot(b[1].0));
    println!("repeated pole's shapes {a:?} and {b:?}: sine of their angle {sine:.3}");
    assert!(sine > 0.1, "{sine}");
    assert!(a[2].0.abs() < 1e-10 && b[2].0.abs() < 1e-10);
}

/// An unstable equilibrium beside a stiff spring is unstable: K = diag(1, 1.44, 1e10) with
/// its first spring reversed (−0.49) has a negative eigenvalue five orders below 1e-9 of the
/// largest, which the verdict's threshold (a part in 10⁹ of the largest, for stiffnesses
/// from differences) called neutral; with exact tangents the threshold is a part in 10¹².
#[test]
fn an_unstable_direction_beside_a_stiff_spring_is_unstable() {
    let model = oscillators_of(-0.49, 1.44, 1e10);
    let eq = static_equilibrium(&model, &StaticsOptions::default()).unwrap();
    println!(
        "stiffness eigenvalues {:?}: {:?}",
        eq.stiffness_eigenvalues, eq.stability
    );
    assert_eq!(eq.stability, Stability::Unstable);
    quoted::says(
        "docs/status.md",
        &[format!(
            "and −0.49 N·m/rad beside 1e10 N/m is `{:?}`, where a threshold",
            eq.stability
        )],
    );
    // the same, stable
    let model = oscillators_of(0.49, 1.44, 1e10);
    let eq = static_equilibrium(&model, &StaticsOptions::default()).unwrap();
    assert_eq!(eq.stability, Stability::Stable);
}
