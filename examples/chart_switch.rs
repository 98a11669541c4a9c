//! Chart switching for a free rotation, measured on the intermediate-axis tumble
//! (`docs/rotations.md` quotes its figures).
//!
//! The free body of `mbs_models::tumble::Tumble` (ZYX angles, singular where body x lies along
//! world z) is carried three ways:
//!
//! - ZYX only (today's model): stops with `SingularConfiguration` when a flip meets the
//!   singularity;
//! - ZYX ⇄ ZXY: the body written a second time on ZXY angles ([`TumbleZxy`], singular where
//!   body y lies along world z). No orientation is singular in both: when |R₃₁| = 1 the third
//!   row of R is ±e₁, so R₃₂ = 0 and ZXY's middle angle is zero, at its best;
//! - re-centred: ZYX angles relative to a reference orientation held in parameters
//!   ([`TumbleRecentred`]); leaving the chart sets the reference to the current orientation
//!   and the angles to zero.
//!
//! The program integrates in a chart until the cosine of its middle angle falls below
//! `--switch` (default 0.5), maps (q, q̇) exactly to the next chart through the rotation
//! matrix and the body angular velocity, and starts a new `Simulation` there with the last
//! step size as h0 (a real implementation would carry across more: the controller's error
//! history, the dense output of the step that crossed, the Newton matrices; see
//! `docs/rotations.md`).
//!
//! It prints the op counts of the three models, then, for MODELS.md's start and for the start
//! turned by φ0 about world x (whose flip meets ZYX's singularity at t = 8.003 s), with
//! DOPRI5 and Radau5 at rtol 1e-10 and generalized-α at h = 1e-3 for 20 s: the switches,
//! the largest relative drift of the energy and of the angular-momentum vector, steps,
//! evaluations, Newton iterations and CPU time (the least of 5 runs), and the largest
//! mismatch of the rotation and of the angular velocity across a switch, the new chart's
//! generated kinematics against the old one's (the map's exactness).
//!
//! Run with `cargo run --release --example chart_switch` (`-- --switch 0.3` moves the
//! threshold, `-- --t-end 40` the end, `-- --h 1e-4` generalized-α's step).

use mbs::{Integrator, Simulation};
use mbs::{Kinematics, Model, Options, Output, Parameters, Scheme, SimError, StepControl};
use mbs_models::tumble::Tumble;
use std::time::{Duration, Instant};

mbs::multibody! {
    /// tumble's body on ZXY Euler angles: singular at q1 = ±π/2, where body y lies along
    /// world z (at q = 0: ω_body = (q̇1, q̇2, q̇0)).
    pub model TumbleZxy {
        dof q[0] = 0.0;
        dof q[1] = 0.0;
        dof q[2] = 0.0;
        option tangents;
        body b { mass = 0.12; inertia = (1.7231e-4, 6.58e-6, 1.7243e-4); }
        TOG[b] = Trotz(q[0]) * Trotx(q[1]) * Troty(q[2]);
    }
}

mbs::multibody! {
    /// tumble's body on ZYX angles relative to a reference orientation R_ref =
    /// Rz(r0) Ry(r1) Rx(r2) held in parameters: re-centring the chart is a change of
    /// parameters and of (q, q̇), one generated model for every chart.
    pub model TumbleRecentred {
        param r0 = 0.0; param r1 = 0.0; param r2 = 0.0;
        dof q[0] = 0.0;
        dof q[1] = 0.0;
        dof q[2] = 0.0;
        option tangents;
        body b { mass = 0.12; inertia = (1.7231e-4, 6.58e-6, 1.7243e-4); }
        TOG[b] = Trotz(r0) * Troty(r1) * Trotx(r2) * Trotz(q[0]) * Troty(q[1]) * Trotx(q[2]);
    }
}

/// Principal inertias about body x, y, z (kg m²), as in both models.
const INERTIA: [f64; 3] = [1.7231e-4, 6.58e-6, 1.7243e-4];

/// Runs per measurement of CPU time (the least is printed).
const REPEAT: usize = 5;

/// The spin phase of `tests/hard_cases/tumble.rs` that makes the accurate ZYX flip meet the
/// singularity (t = 8.003 s).
const PHI0: f64 = -1.487_927_615_474_704;

type M3 = [[f64; 3]; 3];

fn mul(a: &M3, b: &M3) -> M3 {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

fn mul_v(a: &M3, v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2])
}

fn transpose(a: &M3) -> M3 {
    let mut t = [[0.0; 3]; 3];
    for (i, row) in a.iter().enumerate() {
        for (j, x) in row.iter().enumerate() {
            t[j][i] = *x;
        }
    }
    t
}

/// Elementary rotation about axis 0 (x), 1 (y) or 2 (z).
fn rot(axis: usize, a: f64) -> M3 {
    let (s, c) = a.sin_cos();
    match axis {
        0 => [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
        1 => [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
        _ => [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
    }
}

/// A Tait–Bryan chart R = R_a(q0) R_b(q1) R_c(q2), singular where cos q1 = 0.
#[derive(Clone, Copy)]
struct Chart {
    axes: [usize; 3],
}

const ZYX: Chart = Chart { axes: [2, 1, 0] };
const ZXY: Chart = Chart { axes: [2, 0, 1] };

impl Chart {
    fn rotation(&self, q: &[f64]) -> M3 {
        let [a, b, c] = self.axes;
        mul(&mul(&rot(a, q[0]), &rot(b, q[1])), &rot(c, q[2]))
    }

    /// ω_body = J(q) q̇: columns R_c(q2)ᵀ R_b(q1)ᵀ e_a, R_c(q2)ᵀ e_b, e_c.
    fn body_jacobian(&self, q: &[f64]) -> M3 {
        let [a, b, c] = self.axes;
        let rc_t = transpose(&rot(c, q[2]));
        let rb_t = transpose(&rot(b, q[1]));
        let e = |k: usize| {
            let mut v = [0.0; 3];
            v[k] = 1.0;
            v
        };
        let c0 = mul_v(&mul(&rc_t, &rb_t), e(a));
        let c1 = mul_v(&rc_t, e(b));
        let c2 = e(c);
        [0, 1, 2].map(|i| [c0[i], c1[i], c2[i]])
    }

    /// The angles of a rotation matrix (q1 in [−π/2, π/2], the others in (−π, π]).
    fn angles(&self, r: &M3) -> [f64; 3] {
        match self.axes {
            // R = Rz Ry Rx: third row (−s1, c1 s2, c1 c2), first column (c0 c1, s0 c1, −s1)
            [2, 1, 0] => [
                r[1][0].atan2(r[0][0]),
                (-r[2][0]).atan2(r[2][1].hypot(r[2][2])),
                r[2][1].atan2(r[2][2]),
            ],
            // R = Rz Rx Ry: third row (−c1 s2, s1, c1 c2), second column (−s0 c1, c0 c1, s1)
            [2, 0, 1] => [
                (-r[0][1]).atan2(r[1][1]),
                r[2][1].atan2(r[2][0].hypot(r[2][2])),
                (-r[2][0]).atan2(r[2][2]),
            ],
            _ => unreachable!("only the two charts above"),
        }
    }

    /// (q, q̇) of this chart with the same rotation and body angular velocity.
    fn coordinates_of(&self, r: &M3, w_body: [f64; 3]) -> ([f64; 3], [f64; 3]) {
        let q = self.angles(r);
        let qd = solve3(&self.body_jacobian(&q), w_body);
        (q, qd)
    }
}

/// x with a x = b (Cramer's rule; a is a chart's Jacobian away from its singularity).
fn solve3(a: &M3, b: [f64; 3]) -> [f64; 3] {
    let det = |m: &M3| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(a);
    [0, 1, 2].map(|k| {
        let mut m = *a;
        for i in 0..3 {
            m[i][k] = b[i];
        }
        det(&m) / d
    })
}

/// Rotation and world angular velocity of the body from a generated model's kinematics.
fn motion<M: Model>(
    model: &M,
    k: &mut Kinematics,
    t: f64,
    q: &[f64],
    qd: &[f64],
) -> (M3, [f64; 3]) {
    model.kinematics(t, q, qd, k);
    let f = &k.frames[0];
    (f.pose.rotation, f.angular_velocity)
}

/// Energy and world angular momentum from the rotation and the world angular velocity.
fn invariants(r: &M3, w: [f64; 3]) -> (f64, [f64; 3]) {
    let wb = mul_v(&transpose(r), w);
    let lb = [0, 1, 2].map(|i| INERTIA[i] * wb[i]);
    let e = 0.5 * (0..3).map(|i| wb[i] * lb[i]).sum::<f64>();
    (e, mul_v(r, lb))
}

/// What the whole run measured.
#[derive(Default)]
struct Run {
    switches: usize,
    restarts_at: Vec<f64>,
    steps: usize,
    rejected: usize,
    evaluations: usize,
    newton: usize,
    cpu: Duration,
    e_drift: f64,
    l_drift: f64,
    /// largest mismatch of R and of ω (rad/s) across a switch
    map_r: f64,
    map_w: f64,
    min_cos: f64,
    /// the typed error that ended the run, if any
    failure: Option<String>,
    t_end: f64,
}

struct Reference {
    e0: f64,
    l0: [f64; 3],
}

impl Run {
    fn watch(&mut self, reference: &Reference, r: &M3, w: [f64; 3]) {
        let (e, l) = invariants(r, w);
        self.e_drift = self.e_drift.max((e / reference.e0 - 1.0).abs());
        let dl = (0..3)
            .map(|i| (l[i] - reference.l0[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        let l0 = reference.l0.iter().map(|x| x * x).sum::<f64>().sqrt();
        self.l_drift = self.l_drift.max(dl / l0);
    }
}

/// The run's settings: end, switching threshold on |cos q1|, fixed step of gen-α.
struct Setup {
    t_end: f64,
    switch: f64,
    h: f64,
}

fn options(
    scheme: &Scheme,
    t0: f64,
    setup: &Setup,
    q: [f64; 3],
    qd: [f64; 3],
    h0: Option<f64>,
) -> Options {
    let t_end = setup.t_end;
    let step = if matches!(scheme, Scheme::GenAlpha(_)) {
        StepControl::Fixed { h: setup.h }
    } else {
        StepControl::Adaptive {
            rtol: 1e-10,
            atol: 1e-12,
            h0,
        }
    };
    Options {
        t0,
        t_end,
        q0: Some(q.to_vec()),
        qd0: Some(qd.to_vec()),
        step,
        output: Output::Last,
        energy: false,
        ..Options::default()
    }
}

/// How a segment ended.
enum SegmentEnd {
    /// reached t_end
    Done,
    /// the chart's middle angle passed the threshold: the state (t, q, q̇) and the next step
    Switch { t: f64, r: M3, w: [f64; 3], h: f64 },
}

/// Integrates `model` from (t0, q, q̇) until t_end or until |cos q1| < `switch`.
fn segment<M: Model + 'static>(
    model: M,
    scheme: Scheme,
    o: Options,
    switch: f64,
    reference: &Reference,
    run: &mut Run,
) -> Result<SegmentEnd, SimError> {
    let t_end = o.t_end;
    let clock = Instant::now();
    let sim = Simulation::new(model, scheme, o);
    run.cpu += clock.elapsed();
    let mut sim = sim?;
    let mut k = Kinematics::new::<M>();
    let end = loop {
        let clock = Instant::now();
        let r = sim.step();
        run.cpu += clock.elapsed();
        if let Err(e) = r {
            let stats = &e.stats;
            run.steps += stats.steps;
            run.rejected += stats.rejected_error + stats.rejected_newton;
            run.evaluations += stats.evaluations();
            run.newton += stats.newton_iterations;
            return Err(e);
        }
        let s = sim.state();
        let (r, w) = motion(sim.model(), &mut k, s.t, &s.q, &s.qd);
        run.watch(reference, &r, w);
        let c = s.q[1].cos().abs();
        run.min_cos = run.min_cos.min(c);
        if s.t >= t_end {
            break SegmentEnd::Done;
        }
        if c < switch {
            break SegmentEnd::Switch {
                t: s.t,
                r,
                w,
                h: sim.h(),
            };
        }
    };
    let (_, stats) = sim.finish();
    run.steps += stats.steps;
    run.rejected += stats.rejected_error + stats.rejected_newton;
    run.evaluations += stats.evaluations();
    run.newton += stats.newton_iterations;
    Ok(end)
}

/// How the orientation is carried.
#[derive(Clone, Copy, PartialEq)]
enum Variant {
    /// ZYX angles throughout (today)
    Single,
    /// ZYX and ZXY, switched when the current one's |cos q1| falls below the threshold
    TwoCharts,
    /// ZYX relative to R_ref, re-centred (R_ref := R, q := 0) below the threshold
    Recentred,
}

impl Variant {
    fn label(self) -> &'static str {
        match self {
            Variant::Single => "ZYX only",
            Variant::TwoCharts => "ZYX ⇄ ZXY",
            Variant::Recentred => "re-centred",
        }
    }
}

/// ZYX angles of any rotation, singular ones included (for R_ref, which is a constant).
fn zyx_angles_any(r: &M3) -> [f64; 3] {
    let q0 = r[1][0].atan2(r[0][0]);
    let q1 = (-r[2][0]).atan2(r[0][0].hypot(r[1][0]));
    // Rx(q2) = Ry(q1)ᵀ Rz(q0)ᵀ R
    let x = mul(&transpose(&mul(&rot(2, q0), &rot(1, q1))), r);
    [q0, q1, x[2][1].atan2(x[1][1])]
}

fn max_diff(a: &M3, b: &M3) -> f64 {
    (0..9)
        .map(|i| (a[i / 3][i % 3] - b[i / 3][i % 3]).abs())
        .fold(0.0, f64::max)
}

/// The tumble from (q, q̇) on ZYX for `t_end`, carried as `variant` says, leaving a chart
/// when its |cos q1| falls below `switch`.
fn tumble(scheme: Scheme, q: [f64; 3], qd: [f64; 3], variant: Variant, setup: &Setup) -> Run {
    let (t_end, switch) = (setup.t_end, setup.switch);
    let a = Tumble::default();
    let b = TumbleZxy::default();
    let mut c = TumbleRecentred::default();
    let mut ka = Kinematics::new::<Tumble>();
    let mut kb = Kinematics::new::<TumbleZxy>();
    let mut kc = Kinematics::new::<TumbleRecentred>();
    let (r0, w0) = motion(&a, &mut ka, 0.0, &q, &qd);
    let (e0, l0) = invariants(&r0, w0);
    let e_model = a.energy(0.0, &q, &qd).total();
    assert!(
        (e_model / e0 - 1.0).abs() < 1e-14,
        "the model's energy {e_model} and ½ωᵀIω {e0} differ"
    );
    let reference = Reference { e0, l0 };
    let mut run = Run {
        min_cos: 1.0,
        ..Run::default()
    };
    let threshold = if variant == Variant::Single {
        0.0
    } else {
        switch
    };
    let (mut t, mut q, mut qd, mut h0, mut on_a) = (0.0, q, qd, None, true);
    loop {
        let o = options(&scheme, t, setup, q, qd, h0);
        let end = match (variant, on_a) {
            (Variant::Recentred, _) => {
                segment(c.clone(), scheme, o, threshold, &reference, &mut run)
            }
            (_, true) => segment(a.clone(), scheme, o, threshold, &reference, &mut run),
            (_, false) => segment(b.clone(), scheme, o, threshold, &reference, &mut run),
        };
        match end {
            Ok(SegmentEnd::Done) => {
                run.t_end = t_end;
                return run;
            }
            Err(e) => {
                run.t_end = e.t;
                run.failure = Some(e.kind.to_string());
                return run;
            }
            Ok(SegmentEnd::Switch { t: ts, r, w, h }) => {
                let w_body = mul_v(&transpose(&r), w);
                let (qn, qdn, rn, wn) = if variant == Variant::Recentred {
                    // R_ref := R, q := 0: ω_body = J(0) q̇
                    let mut p = c.params().clone();
                    let refs = zyx_angles_any(&r);
                    for (name, v) in ["r0", "r1", "r2"].iter().zip(refs) {
                        p.set(name, v).expect("a parameter of TumbleRecentred");
                    }
                    c.set_params(p).expect("finite angles");
                    let (qn, qdn) = ([0.0; 3], solve3(&ZYX.body_jacobian(&[0.0; 3]), w_body));
                    let (rn, wn) = motion(&c, &mut kc, ts, &qn, &qdn);
                    (qn, qdn, rn, wn)
                } else {
                    let to = if on_a { ZXY } else { ZYX };
                    let (qn, qdn) = to.coordinates_of(&r, w_body);
                    let from = if on_a { ZYX } else { ZXY };
                    let own = from.rotation(&from.angles(&r));
                    run.map_r = run.map_r.max(max_diff(&own, &r));
                    // the other chart's generated kinematics give the same motion
                    let (rn, wn) = if on_a {
                        motion(&b, &mut kb, ts, &qn, &qdn)
                    } else {
                        motion(&a, &mut ka, ts, &qn, &qdn)
                    };
                    (qn, qdn, rn, wn)
                };
                run.map_r = run.map_r.max(max_diff(&rn, &r));
                let dw = (0..3).map(|i| (wn[i] - w[i]).abs()).fold(0.0, f64::max);
                run.map_w = run
                    .map_w
                    .max(dw / w.iter().map(|x| x * x).sum::<f64>().sqrt());
                assert!(
                    run.map_r < 1e-13 && run.map_w < 1e-13,
                    "the map between charts is not exact at t = {ts}: R {:.1e}, ω {:.1e}",
                    run.map_r,
                    run.map_w
                );
                run.switches += 1;
                run.restarts_at.push(ts);
                (t, q, qd, h0, on_a) = (ts, qn, qdn, Some(h), !on_a);
            }
        }
    }
}

fn main() {
    let mut setup = Setup {
        t_end: 20.0,
        switch: 0.5,
        h: 1e-3,
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    for pair in args.chunks(2) {
        let value = pair.get(1).and_then(|v| v.parse::<f64>().ok());
        match (pair[0].as_str(), value) {
            ("--switch", Some(v)) if v > 0.0 && v < 1.0 => setup.switch = v,
            ("--t-end", Some(v)) if v > 0.0 => setup.t_end = v,
            ("--h", Some(v)) if v > 0.0 => setup.h = v,
            _ => {
                eprintln!(
                    "usage: chart_switch [--switch C in (0, 1)] [--t-end T] [--h H (gen-α's step)]"
                );
                std::process::exit(2);
            }
        }
    }
    println!("op counts (flops; funcs are trigonometric calls, not counted in flops):");
    for (name, m) in [
        ("ZYX (today's tumble)", Tumble::default().info()),
        ("ZXY", TumbleZxy::default().info()),
        (
            "ZYX relative to R_ref (parameters)",
            TumbleRecentred::default().info(),
        ),
    ] {
        println!("  {name}:");
        print!("{}", m.ops_table());
    }
    println!();
    println!(
        "tumble, {} s; a chart is left when |cos q1| < {}; DOPRI5 and Radau5 at rtol 1e-10, atol 1e-12; gen-alpha (ρ∞ default) at h = {}",
        setup.t_end, setup.switch, setup.h
    );
    let starts = [
        ("MODELS.md start", [0.0, 0.0, 0.0], [1e-3, 0.0, 10.0]),
        (
            "turned by φ0",
            [0.0, 0.0, PHI0],
            [1e-3 * PHI0.cos(), -1e-3 * PHI0.sin(), 10.0],
        ),
    ];
    for (label, q, qd) in starts {
        for name in ["dopri5", "radau5", "gen-alpha"] {
            let scheme = Scheme::from_name(name).expect("known scheme");
            for variant in [Variant::Single, Variant::TwoCharts, Variant::Recentred] {
                let how = variant.label();
                // CPU time: the least of `REPEAT` runs (the same run each time)
                let mut r = tumble(scheme, q, qd, variant, &setup);
                for _ in 1..REPEAT {
                    let again = tumble(scheme, q, qd, variant, &setup);
                    r.cpu = r.cpu.min(again.cpu);
                }
                println!(
                    "{label:<16} {name:<9} {how:<10} to t {:>6.3}: switches {:>2}  |E/E0−1| {:.1e}  |L−L0|/|L0| {:.1e}  steps {:>6} (+{} rejected)  evals {:>7}  Newton {:>6}  CPU {:>7.1} ms  min |cos q1| {:.2e}{}",
                    r.t_end,
                    r.switches,
                    r.e_drift,
                    r.l_drift,
                    r.steps,
                    r.rejected,
                    r.evaluations,
                    r.newton,
                    r.cpu.as_secs_f64() * 1e3,
                    r.min_cos,
                    match &r.failure {
                        Some(f) => format!("  STOPPED: {f}"),
                        None => String::new(),
                    }
                );
                if r.switches > 0 {
                    let at: Vec<String> = r.restarts_at.iter().map(|t| format!("{t:.3}")).collect();
                    println!(
                        "{:<38} switches at t = {}; map mismatch: R {:.1e}, ω {:.1e} (relative)",
                        "",
                        at.join(", "),
                        r.map_r,
                        r.map_w
                    );
                }
            }
        }
    }
}
