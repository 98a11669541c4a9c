//! The generated constraint functions: Φ, B = ∂Φ/∂q, ∂Φ/∂t, γ (B qdd = γ) and ∂(Bᵀλ)/∂q,
//! against hand formulas (the Cartesian pendulum) and central differences (a four-bar loop
//! with a rheonomic driving constraint, and a frame alignment).

use mbs::Model;

mbs::multibody! {
    /// pendulum3: unit point mass on a rod of length 1, Cartesian coordinates, g = 1.
    pub model Pendulum3 {
        param g = 1.0;
        dof x = 1.0; dof y = 0.0, qd = 1.0;
        body mass { mass = 1.0; }
        TOG[mass] = Tdisp(x, y, 0);
        gravity(0, -g, 0);
        constraint rod = (x * x + y * y - 1) / 2;
    }
}

mbs::multibody! {
    /// A four-bar loop (crank, coupler, rocker) with a driving constraint on the crank, and a
    /// dummy frame aligned with the coupler.
    pub model FourBar {
        param w = 5.0;
        dof a = PI / 3, independent; dof b = -0.6; dof c = 1.9;
        body crank { mass = 0.1; inertia = (0, 0.1 * 0.01 / 12, 0.1 * 0.01 / 12); }
        body coupler { mass = 0.35; inertia = (0, 0.35 * 0.1225 / 12, 0.35 * 0.1225 / 12); }
        body rocker { mass = 0.3; inertia = (0, 0.3 * 0.09 / 12, 0.3 * 0.09 / 12); }
        point crank_tip on crank at (0.05, 0, 0);
        point coupler_end on coupler at (0.175, 0, 0);
        point rocker_tip on rocker at (0.15, 0, 0);
        TOG[crank] = Trotz(a) * Tdisp(0.05, 0, 0);
        TOG[coupler] = TOG[crank] * Tdisp(0.05, 0, 0) * Trotz(b) * Tdisp(0.175, 0, 0);
        TOG[rocker] = Tdisp(0.4, 0, 0) * Trotz(c) * Tdisp(0.15, 0, 0);
        gravity(0, -9.81, 0);
        constraint close: coincide(coupler_end, rocker_tip, along = [x, y]);
        constraint drive = a - PI / 3 - w * t;
        constraint level: align(coupler, rocker, about = [z]);
    }
}

#[test]
fn pendulum3_constraints_match_hand_formulas() {
    let m = Pendulum3::default();
    assert_eq!(Pendulum3::NC, 1);
    assert_eq!(m.info().constraints, &["rod"]);
    let (q, qd) = ([0.6, -0.8], [0.4, 0.3]);
    let (mut phi, mut b, mut rate, mut gamma, mut k) = ([9.0], [9.0; 2], [9.0], [9.0], [9.0; 4]);
    m.constraints(0.0, &q, &mut phi);
    m.constraint_jacobian(0.0, &q, &mut b);
    m.constraint_rate(0.0, &q, &mut rate);
    m.constraint_bias(0.0, &q, &qd, &mut gamma);
    m.constraint_tangent(0.0, &q, &[2.5], &mut k);
    assert!(phi[0].abs() < 1e-15);
    assert_eq!(b, [0.6, -0.8]);
    assert_eq!(rate, [0.0]);
    // Φ̈ = ẋ² + ẏ² + x ẍ + y ÿ, so γ = −(ẋ² + ẏ²)
    assert!((gamma[0] + 0.25).abs() < 1e-15);
    // Bᵀλ = λ (x, y): ∂/∂q = λ I
    assert_eq!(k, [2.5, 0.0, 0.0, 2.5]);
}

fn fd<const N: usize>(
    f: impl Fn(&[f64; 3], f64) -> [f64; N],
    q: [f64; 3],
    t: f64,
) -> ([[f64; 3]; N], [f64; N]) {
    let e = 1e-6;
    let mut jac = [[0.0; 3]; N];
    for j in 0..3 {
        let (mut qp, mut qm) = (q, q);
        qp[j] += e;
        qm[j] -= e;
        let (fp, fm) = (f(&qp, t), f(&qm, t));
        for i in 0..N {
            jac[i][j] = (fp[i] - fm[i]) / (2.0 * e);
        }
    }
    let (fp, fm) = (f(&q, t + e), f(&q, t - e));
    let mut dt = [0.0; N];
    for i in 0..N {
        dt[i] = (fp[i] - fm[i]) / (2.0 * e);
    }
    (jac, dt)
}

#[test]
fn four_bar_constraints_match_central_differences() {
    let m = FourBar::default();
    assert_eq!(
        m.info().constraints,
        &["close.x", "close.y", "drive", "level.rz"]
    );
    assert_eq!(m.info().independent, &[true, false, false]);
    let (q, qd, t) = ([0.9, -0.7, 1.7], [1.3, -2.1, 0.8], 0.3);
    let phi = |q: &[f64; 3], t: f64| {
        let mut p = [0.0; 4];
        m.constraints(t, q, &mut p);
        p
    };
    let (jac, dt) = fd(phi, q, t);
    let (mut b, mut rate) = ([0.0; 12], [0.0; 4]);
    m.constraint_jacobian(t, &q, &mut b);
    m.constraint_rate(t, &q, &mut rate);
    for i in 0..4 {
        for j in 0..3 {
            assert!((b[i + 4 * j] - jac[i][j]).abs() < 1e-8, "B[{i}][{j}]");
        }
        assert!((rate[i] - dt[i]).abs() < 1e-8, "Φ_t[{i}]");
    }
    // γ = −Φ̈ at qdd = 0: second difference of Φ along q + s qd, t + s
    let mut gamma = [0.0; 4];
    m.constraint_bias(t, &q, &qd, &mut gamma);
    let s = 1e-4;
    let at = |k: f64| {
        phi(
            &[
                q[0] + k * s * qd[0],
                q[1] + k * s * qd[1],
                q[2] + k * s * qd[2],
            ],
            t + k * s,
        )
    };
    let (p1, p0, m1) = (at(1.0), at(0.0), at(-1.0));
    for i in 0..4 {
        let phidd = (p1[i] - 2.0 * p0[i] + m1[i]) / (s * s);
        assert!(
            (gamma[i] + phidd).abs() < 1e-5 * (1.0 + phidd.abs()),
            "γ[{i}] {} vs {}",
            gamma[i],
            -phidd
        );
    }
    // ∂(Bᵀλ)/∂q
    let lambda = [0.7, -1.1, 0.4, 2.0];
    let btl = |q: &[f64; 3], _: f64| {
        let mut b = [0.0; 12];
        m.constraint_jacobian(0.3, q, &mut b);
        let mut f = [0.0; 3];
        for j in 0..3 {
            f[j] = (0..4).map(|i| b[i + 4 * j] * lambda[i]).sum();
        }
        f
    };
    let (jac, _) = fd(btl, q, t);
    let mut k = [0.0; 9];
    m.constraint_tangent(t, &q, &lambda, &mut k);
    for i in 0..3 {
        for j in 0..3 {
            assert!((k[i + 3 * j] - jac[i][j]).abs() < 1e-7, "K[{i}][{j}]");
        }
    }
}

#[test]
fn constraint_functions_have_op_counts_in_the_model_info() {
    use mbs::Model;
    let info = FourBar::default().info();
    let labels: Vec<&str> = info.ops.iter().map(|(l, _)| *l).collect();
    for l in [
        "constraints Φ",
        "constraint_jacobian B",
        "constraint_rate Φ_t",
        "constraint_bias γ",
        "constraint_tangent",
    ] {
        let ops = info.ops.iter().find(|(k, _)| *k == l);
        let Some((_, c)) = ops else {
            panic!("no op count for {l} in {labels:?}")
        };
        // a closed loop's Φ, B, γ and tangent all involve the angles
        if l != "constraint_rate Φ_t" {
            assert!(c.flops() > 0 && c.funcs > 0, "{l}: {c:?}");
        }
    }
    // an unconstrained model lists none
    mbs::multibody! {
        model Free {
            dof x = 0.0;
            body b { mass = 1.0; }
            TOG[b] = Tdisp(x, 0, 0);
        }
    }
    let free = Free::default();
    assert!(
        free.info()
            .ops
            .iter()
            .all(|(l, _)| !l.starts_with("constraint"))
    );
}
