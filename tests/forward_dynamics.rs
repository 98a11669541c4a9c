//! The generated forward dynamics (articulated bodies or sparse LᵀDL, qdd = M⁻¹ h without a
//! dense factorisation) against the dense solve of the same model's M and h, on every model
//! of the repository, at states drawn about each model's start: qdd and the product of its
//! pivots (against det M) agree to 1e-12 relative, or to 4 ε κ₁(M) when M is so
//! ill-conditioned that no two backward-stable solves need agree closer (the long chains);
//! the backward error ‖M qdd − h‖ / (‖M‖ ‖qdd‖ + ‖h‖) is at most 1e-15. The same for
//! `forward_dynamics_forced` (M qdd = h + f, the path of efforts written in Rust) with a drawn
//! generalised force f of the size of h. Also prints the op counts of both paths per model.

use mbs::Model;
use mbs::linalg::{cholesky, cholesky_solve};
use mbs_models::*;

#[path = "common/quoted.rs"]
mod quoted;

/// A small deterministic generator (xorshift), uniform in [-1, 1).
struct Draw(u64);

impl Draw {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

fn flops<M: Model>(model: &M, prefix: &str) -> (String, usize) {
    model
        .info()
        .ops
        .iter()
        .find(|(label, _)| label.starts_with(prefix))
        .map(|(label, c)| (label.to_string(), c.flops()))
        .unwrap_or_else(|| panic!("no `{prefix}` row"))
}

/// What [`check`] measured of one model.
struct Checked {
    /// the worst relative differences of qdd and of log Π pivots, in their bounds
    worst: (f64, f64),
    name: String,
    /// flops of M + h and of forward dynamics
    flops: (usize, usize),
}

/// The worst relative difference of qdd and of log Π pivots against log det M over `STATES`
/// states; prints the op counts.
fn check<M: Model>(name: &str, model: &M) -> Checked {
    const STATES: usize = 20;
    let n = M::NQ;
    let (mut q0, mut qd0) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q0, &mut qd0);
    let u = vec![0.0; M::NU];
    let mut draw = Draw(0x9e37_79b9_7f4a_7c15 ^ n as u64);
    let (mut worst_qdd, mut worst_det) = (0.0f64, 0.0f64);
    let mut worst_eta = (0.0f64, 0.0f64);
    let mut worst_kappa = 0.0f64;
    let (mut m, mut h) = (vec![0.0; n * n], vec![0.0; n]);
    let (mut qdd, mut pivots) = (vec![0.0; n], vec![0.0; n]);
    let (mut forced, mut forced_pivots) = (vec![0.0; n], vec![0.0; n]);
    let mut worst_forced = 0.0f64;
    for _ in 0..STATES {
        let q: Vec<f64> = q0.iter().map(|x| x + 0.3 * draw.next()).collect();
        let qd: Vec<f64> = qd0.iter().map(|x| x + draw.next()).collect();
        let t = 0.1 * (draw.next() + 1.0);
        model.dynamics(t, &q, &qd, &u, &mut m, &mut h);
        let (m0, h0) = (m.clone(), h.clone());
        cholesky(&mut m, n).unwrap_or_else(|e| panic!("{name}: M singular at {q:?}: {e:?}"));
        // h + f, f drawn of the size of h
        let h_scale = h.iter().fold(1.0f64, |a, v| a.max(v.abs()));
        let f: Vec<f64> = (0..n).map(|_| h_scale * draw.next()).collect();
        let mut hf: Vec<f64> = h.iter().zip(&f).map(|(a, b)| a + b).collect();
        cholesky_solve(&m, n, &mut hf);
        model.forward_dynamics_forced(t, &q, &qd, &u, &f, &mut forced, &mut forced_pivots);
        cholesky_solve(&m, n, &mut h);
        model.forward_dynamics(t, &q, &qd, &u, &mut qdd, &mut pivots);
        let scale = h.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let diff = qdd
            .iter()
            .zip(&h)
            .fold(0.0f64, |a, (x, r)| a.max((x - r).abs()));
        let rel = if scale > 0.0 { diff / scale } else { diff };
        let eta = |x: &[f64]| {
            let mut r = 0.0f64;
            let mut mnorm = 0.0f64;
            for i in 0..n {
                let row: f64 = (0..n).map(|j| m0[i + n * j] * x[j]).sum::<f64>() - h0[i];
                r = r.max(row.abs());
                mnorm = mnorm.max((0..n).map(|j| m0[i + n * j].abs()).sum::<f64>());
            }
            let xn = x.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            let hn = h0.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            r / (mnorm * xn + hn).max(f64::MIN_POSITIVE)
        };
        // κ₁(M) = ‖M‖₁ ‖M⁻¹‖₁: a solve's error is bounded by κ ε
        let mut inv_norm = 0.0f64;
        for j in 0..n {
            let mut e = vec![0.0; n];
            e[j] = 1.0;
            cholesky_solve(&m, n, &mut e);
            inv_norm = inv_norm.max(e.iter().map(|v| v.abs()).sum());
        }
        let m_norm = (0..n)
            .map(|j| (0..n).map(|i| m0[i + n * j].abs()).sum::<f64>())
            .fold(0.0f64, f64::max);
        let kappa = m_norm * inv_norm;
        worst_kappa = worst_kappa.max(kappa);
        // 1e-12 relative, or the bound of any backward-stable solve when M is ill-conditioned
        let bound = 1e-12f64.max(4.0 * f64::EPSILON * kappa);
        worst_qdd = worst_qdd.max(rel / bound);
        worst_eta.0 = worst_eta.0.max(eta(&qdd));
        worst_eta.1 = worst_eta.1.max(eta(&h));
        let log_det: f64 = (0..n).map(|i| 2.0 * m[i + n * i].ln()).sum();
        let log_prod: f64 = pivots.iter().map(|p| p.ln()).sum();
        worst_det = worst_det.max((log_prod - log_det).abs() / bound);
        let scale = hf.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let diff = forced
            .iter()
            .zip(&hf)
            .fold(0.0f64, |a, (x, r)| a.max((x - r).abs()));
        worst_forced = worst_forced.max(diff / scale.max(f64::MIN_POSITIVE) / bound);
        assert_eq!(
            forced_pivots, pivots,
            "{name}: the pivots do not depend on f"
        );
    }
    // the forced path is the same solve: its qdd counts with the others
    worst_qdd = worst_qdd.max(worst_forced);
    let (label, fwd) = flops(model, "forward_dynamics");
    let (_, dynamics) = flops(model, "dynamics");
    println!(
        "{name:<28} {n:>3} dof  M + h {dynamics:>6} flops, {label} {fwd:>6} flops \
         ({:.0} per dof); qdd and log det within {:.2} and {:.2} of their bounds, backward error {:.1e} \
         (dense {:.1e}), κ₁(M) {worst_kappa:.1e}",
        fwd as f64 / n as f64,
        worst_qdd,
        worst_det,
        worst_eta.0,
        worst_eta.1
    );
    assert!(
        worst_eta.0 <= 1e-15,
        "{name}: backward error {:.1e}",
        worst_eta.0
    );
    Checked {
        name: name.to_string(),
        worst: (worst_qdd, worst_det),
        flops: (dynamics, fwd),
    }
}

#[test]
fn forward_dynamics_equal_the_dense_solve_on_every_model() {
    let mut worst = (0.0f64, 0.0f64);
    let mut flops = std::collections::HashMap::new();
    let mut see = |c: Checked| {
        worst = (worst.0.max(c.worst.0), worst.1.max(c.worst.1));
        flops.insert(c.name, c.flops);
    };
    see(check("seed2dof", &seed2dof::Seed2dof::default()));
    see(check("dpend", &dpend::DoublePendulum::default()));
    see(check(
        "dpend_cartesian",
        &dpend_cartesian::DoublePendulumCartesian::default(),
    ));
    see(check("arm3d_6", &arm3d_6::Arm3d6::default()));
    see(check("chain8", &chain8::Chain8::default()));
    see(check(
        "chain16_stiff",
        &chain16_stiff::Chain16Stiff::default(),
    ));
    see(check("chain24", &chain24::Chain24::default()));
    see(check(
        "chain30_stiff",
        &chain30_stiff::Chain30Stiff::default(),
    ));
    see(check("hexapod Free", &hexapod::HexapodFree::default()));
    see(check(
        "hexapod Standing",
        &hexapod::HexapodStanding::default(),
    ));
    see(check(
        "hexapod Tumbling",
        &hexapod::HexapodTumbling::default(),
    ));
    see(check("pendulum3", &pendulum3::Pendulum3::default()));
    see(check("fourbar", &fourbar::FourBar::default()));
    see(check("fastlink", &fastlink::FastLink::default()));
    see(check("slidercrank", &slidercrank::SliderCrank::default()));
    see(check(
        "slidercrank closed",
        &slidercrank::SliderCrankClosed::default(),
    ));
    see(check("dc_motor arm", &dc_motor::Arm::default()));
    see(check("springpend", &springpend::SpringPend::default()));
    see(check("tumble", &tumble::Tumble::default()));
    see(check("tumble xyz", &tumble::TumbleXyz::default()));
    see(check("tumble ball", &tumble::TumbleBall::default()));
    see(check("top", &top::Top::default()));
    see(check("top zyx", &top::TopZyx::default()));
    see(check(
        "spherical pendulum",
        &spherical_pendulum::SphericalPendulum::default(),
    ));
    see(check(
        "spherical pendulum zyx",
        &spherical_pendulum::SphericalPendulumZyx::default(),
    ));
    see(check("sine slider", &structural::SineSlider::default()));
    see(check(
        "hexapod walker",
        &hexapod_walker::HexapodWalker::default(),
    ));
    see(check("human", &human::Human::default()));
    see(check("damped chain", &damped_chain::DampedChain::default()));
    see(check("sprung arm", &sprung_arm::SprungArm::default()));
    println!(
        "worst: qdd {:.2}, log det {:.2} of max(1e-12, 4 ε κ₁(M))",
        worst.0, worst.1
    );
    // the README's op counts (`mbs expand --counts-only` prints the same rows)
    let t = |name: &str, which: usize| {
        let f = flops[name];
        quoted::thousands(if which == 0 { f.0 } else { f.1 })
    };
    quoted::says(
        "README.md",
        &[
            format!(
                "arm3d_6 {}, chain8 {}, chain16_stiff {}, chain24 {}, chain30_stiff {} flops; dpend {}, fourbar {}, fastlink {}, slidercrank {} (closed: {}), tumble {}",
                t("arm3d_6", 0),
                t("chain8", 0),
                t("chain16_stiff", 0),
                t("chain24", 0),
                t("chain30_stiff", 0),
                t("dpend", 0),
                t("fourbar", 0),
                t("fastlink", 0),
                t("slidercrank", 0),
                t("slidercrank closed", 0),
                t("tumble", 0)
            ),
            format!("chain8 by sparse LᵀDL {}", t("chain8", 1)),
            format!(
                "(chain16_stiff {}, chain24 {}, chain30_stiff {}: O(n), below M+h alone)",
                t("chain16_stiff", 1),
                t("chain24", 1),
                t("chain30_stiff", 1)
            ),
        ],
    );
    assert!(worst.0 <= 1.0, "qdd differs by {:.2} of its bound", worst.0);
    assert!(
        worst.1 <= 1.0,
        "log det differs by {:.2} of its bound",
        worst.1
    );
}
