//! The Jacobians of `kinematics` and `point_kinematics` in both forms the generator offers
//! (`option jacobians = generated | assembled;`): every column generated, or the coordinates'
//! twists generated and the columns summed from them at run time. One mechanism written twice,
//! with a free base, a ball joint in a moved chart, a geared rotor (a coordinate that turns two
//! bodies), a slider, a rheonomic joint, a joint driven by two coordinates and points on
//! bodies: both forms agree with each other and with central differences of the poses.

use mbs::Model;

#[path = "common/quoted.rs"]
mod quoted;

/// How far the two forms' Jacobians may differ, and their M relative to its largest entry.
const JACOBIANS_WITHIN: f64 = 1e-13;
const M_WITHIN: f64 = 1e-14;

macro_rules! mechanism {
    ($name:ident, $form:ident) => {
        mbs::multibody! {
            pub model $name {
                option jacobians = $form;
                option motion;
                param l = 0.4;
                dof x = 0.1; dof y = -0.2; dof z = 0.3;
                dof psi = 0.2; dof theta = 0.1; dof phi = -0.3;
                dof a = 0.3; dof b = -0.4; dof c = 0.2; dof s = 0.1;
                dof e1 = 0.2; dof e2 = -0.1; dof e3 = 0.3;
                body base { mass = 2.0; inertia = (0.1, 0.2, 0.3, 0, 0, 0); }
                body arm { mass = 1.0; inertia = (0.01, 0.02, 0.03, 0, 0, 0); }
                body rotor { mass = 0.1; inertia = (0.001, 0.001, 0.002, 0, 0, 0); }
                body slider { mass = 0.5; inertia = (0.01, 0.01, 0.01, 0, 0, 0); }
                body tip { mass = 0.3; inertia = (0.01, 0.02, 0.01, 0, 0, 0); }
                body ball { mass = 0.2; inertia = (0.01, 0.01, 0.02, 0, 0, 0); }
                TOG[base] = Tfree(x, y, z, psi, theta, phi);
                TOG[arm] = TOG[base] * Tdisp(0.1, 0.2, 0) * Trotz(a) * Tdisp(l, 0, 0);
                TOG[rotor] = TOG[base] * Tdisp(0.1, 0.2, 0) * Trotz(30 * a);
                TOG[slider] = TOG[arm] * Troty(b + 0.3 * sin(2 * t)) * Tdisp(s, 0, 0.1);
                TOG[tip] = TOG[slider] * Trotx(c - b) * Tdisp(0, l * s, 0.05);
                TOG[ball] = TOG[tip] * Tball(e1, e2, e3) * Tdisp(0, 0, -l);
                point p_arm on arm at (0.1, -0.05, 0.02);
                point p_tip on tip at (0.02, 0.03, -0.1);
                point p_ball on ball at (0.05, 0.0, 0.1);
                gravity(0, 0, -9.81);
            }
        }
    };
}

mechanism!(Generated, generated);
mechanism!(Assembled, assembled);

/// A deterministic state: (t, q, qd).
fn state(k: usize) -> (f64, Vec<f64>, Vec<f64>) {
    let n = Generated::NQ;
    let x = |i: usize| (((i * 7919 + k * 104_729) % 1000) as f64 / 1000.0 - 0.5) * 1.6;
    let q: Vec<f64> = (0..n).map(x).collect();
    let qd: Vec<f64> = (0..n).map(|i| x(i + 31)).collect();
    (0.3 * k as f64, q, qd)
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// The mechanism in both forms, the ball joint's chart at the identity, then moved away from
/// it.
fn both_forms() -> Vec<(Generated, Assembled, &'static str)> {
    let (c, s) = (0.6f64.cos(), 0.6f64.sin());
    let moved = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
    [(mbs::IDENTITY3, "identity chart"), (moved, "moved chart")]
        .into_iter()
        .map(|(chart, label)| {
            let mut g = Generated::default();
            let mut a = Assembled::default();
            g.set_chart(0, chart);
            a.set_chart(0, chart);
            (g, a, label)
        })
        .collect()
}

#[test]
fn both_forms_agree() {
    let mut worst = 0.0f64;
    for (g, a, label) in both_forms() {
        for k in 0..8 {
            let (t, q, qd) = state(k);
            let (mut kg, mut ka) = (
                mbs::Kinematics::new::<Generated>(),
                mbs::Kinematics::new::<Assembled>(),
            );
            g.kinematics(t, &q, &qd, &mut kg);
            a.kinematics(t, &q, &qd, &mut ka);
            for (f, (x, y)) in kg.frames.iter().zip(&ka.frames).enumerate() {
                let d = max_diff(&x.jv, &y.jv).max(max_diff(&x.jw, &y.jw));
                assert!(
                    d < JACOBIANS_WITHIN,
                    "state {k}, {label}: frame {f}'s Jacobians differ by {d:e}"
                );
                assert_eq!(x.pose, y.pose, "state {k}, {label}: frame {f}'s pose");
                assert_eq!(x.velocity, y.velocity);
                worst = worst.max(d);
            }
            for (i, (x, y)) in kg.points.iter().zip(&ka.points).enumerate() {
                let d = max_diff(&x.jv, &y.jv);
                assert!(
                    d < JACOBIANS_WITHIN,
                    "state {k}, {label}: point {i}'s Jacobian differs by {d:e}"
                );
                worst = worst.max(d);
            }
            // point_kinematics alone, into buffers that held other values
            let mut kp = mbs::Kinematics::new::<Assembled>();
            for p in &mut kp.points {
                p.jv.fill(7.0);
            }
            a.point_kinematics(t, &q, &qd, &mut kp);
            for (i, (x, y)) in kg.points.iter().zip(&kp.points).enumerate() {
                let d = max_diff(&x.jv, &y.jv);
                assert!(
                    d < JACOBIANS_WITHIN,
                    "state {k}, {label}: point_kinematics' point {i} differs by {d:e}"
                );
                assert_eq!(x.position, y.position);
            }
        }
    }
    println!("largest difference between the two forms: {worst:e}");
    quoted::says(
        "README.md",
        &[format!(
            "`tests/jacobians.rs` checks both forms against each other (Jacobians to \
             {JACOBIANS_WITHIN:.0e}, M to {M_WITHIN:.0e} of its largest entry)"
        )],
    );
}

/// M assembled from the twists and composite inertias equals the generated M, and
/// `mass_matrix` equals `dynamics`' M.
#[test]
fn assembled_mass_matrix_equals_generated() {
    let n = Generated::NQ;
    let mut worst = 0.0f64;
    for (g, a, _) in both_forms() {
        for k in 0..8 {
            let (t, q, qd) = state(k);
            let (mut mg, mut hg) = (vec![0.0; n * n], vec![0.0; n]);
            let (mut ma, mut ha) = (vec![7.0; n * n], vec![0.0; n]);
            g.dynamics(t, &q, &qd, &[], &mut mg, &mut hg);
            a.dynamics(t, &q, &qd, &[], &mut ma, &mut ha);
            let scale = mg.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let d = max_diff(&mg, &ma) / scale;
            assert!(
                d < M_WITHIN,
                "state {k}: M differs by {d:e} of its largest entry"
            );
            assert!(max_diff(&hg, &ha) < 1e-12, "state {k}: h");
            let mut mm = vec![0.0; n * n];
            a.mass_matrix(t, &q, &mut mm);
            assert_eq!(mm, ma, "state {k}: mass_matrix and dynamics' M");
            worst = worst.max(d);
        }
    }
    println!("largest difference of M between the two forms: {worst:e} of its largest entry");
}

/// Central differences of the poses and points' positions against the assembled Jacobians.
#[test]
fn assembled_jacobians_are_derivatives() {
    let m = Assembled::default();
    let n = Assembled::NQ;
    let step = 1e-6;
    let mut worst = 0.0f64;
    for k in 0..4 {
        let (t, q, qd) = state(k);
        let mut kin = mbs::Kinematics::new::<Assembled>();
        m.kinematics(t, &q, &qd, &mut kin);
        for j in 0..n {
            let (mut kp, mut km) = (
                mbs::Kinematics::new::<Assembled>(),
                mbs::Kinematics::new::<Assembled>(),
            );
            let (mut qp, mut qm) = (q.clone(), q.clone());
            qp[j] += step;
            qm[j] -= step;
            m.kinematics(t, &qp, &qd, &mut kp);
            m.kinematics(t, &qm, &qd, &mut km);
            for (f, fk) in kin.frames.iter().enumerate() {
                let (rp, rm) = (kp.frames[f].pose.rotation, km.frames[f].pose.rotation);
                let r = fk.pose.rotation;
                // Ṙ Rᵀ = [ω]×, by differences of R
                let rdot = |i: usize, c: usize| (rp[i][c] - rm[i][c]) / (2.0 * step);
                let wx = |i: usize, l: usize| (0..3).map(|c| rdot(i, c) * r[l][c]).sum::<f64>();
                let w = [wx(2, 1), wx(0, 2), wx(1, 0)];
                for (i, wi) in w.into_iter().enumerate() {
                    let v = (kp.frames[f].pose.position[i] - km.frames[f].pose.position[i])
                        / (2.0 * step);
                    let d = (v - fk.jv[3 * j + i])
                        .abs()
                        .max((wi - fk.jw[3 * j + i]).abs());
                    assert!(d < 1e-7, "frame {f}, coordinate {j}, axis {i}: {d:e}");
                    worst = worst.max(d);
                }
            }
            for (p, pk) in kin.points.iter().enumerate() {
                for i in 0..3 {
                    let v = (kp.points[p].position[i] - km.points[p].position[i]) / (2.0 * step);
                    let d = (v - pk.jv[3 * j + i]).abs();
                    assert!(d < 1e-7, "point {p}, coordinate {j}, axis {i}: {d:e}");
                    worst = worst.max(d);
                }
            }
        }
    }
    println!("largest difference from central differences: {worst:e}");
}

/// The assembled form's generated code is smaller: the twists are O(n), the columns O(n²) on
/// a chain.
#[test]
fn assembled_form_generates_fewer_operations() {
    let ops = |info: &mbs::ModelInfo| {
        info.ops
            .iter()
            .find(|(l, _)| *l == "kinematics")
            .map(|(_, c)| c.flops())
            .expect("a kinematics row")
    };
    let (g, a) = (
        ops(Generated::default().info()),
        ops(Assembled::default().info()),
    );
    println!("kinematics: {g} flops generated, {a} with the Jacobians assembled");
    assert!(a < g, "{a} vs {g}");
}

/// A state of the human model: (q, qd).
fn human_state() -> (Vec<f64>, Vec<f64>) {
    let n = mbs_models::human::Human::NQ;
    let q = (0..n)
        .map(|i| 0.1 * ((i * 37 % 11) as f64 - 5.0) / 5.0)
        .collect();
    let qd = (0..n)
        .map(|i| 0.5 * ((i * 53 % 13) as f64 - 6.0) / 6.0)
        .collect();
    (q, qd)
}

/// The flops of the human model's generated function `label` (`mbs expand --counts-only`).
fn human_flops(human: &mbs_models::human::Human, label: &str) -> usize {
    let ops = &human.info().ops;
    let row = ops.iter().find(|(l, _)| *l == label);
    row.unwrap_or_else(|| panic!("no row {label}")).1.flops()
}

/// `motion` (`option motion;`) is `kinematics` less its Jacobians and bias accelerations: the
/// poses and velocities of every frame and point the same to the bit, on the mechanism in both
/// forms and on the human model, and what it does not compute left as it was; without the
/// option, all of `kinematics`.
#[test]
fn motion_is_kinematics_without_its_jacobians() {
    fn check<M: Model>(model: &M, t: f64, q: &[f64], qd: &[f64], label: &str) {
        let mut full = mbs::Kinematics::new::<M>();
        model.kinematics(t, q, qd, &mut full);
        let mut moved = mbs::Kinematics::new::<M>();
        for f in &mut moved.frames {
            f.jv.fill(7.0);
            f.bias_acceleration = [7.0; 3];
        }
        for p in &mut moved.points {
            p.jv.fill(7.0);
        }
        model.motion(t, q, qd, &mut moved);
        for (i, (a, b)) in full.frames.iter().zip(&moved.frames).enumerate() {
            assert_eq!(a.pose, b.pose, "{label}: frame {i}'s pose");
            assert_eq!(a.velocity, b.velocity, "{label}: frame {i}'s velocity");
            assert_eq!(a.angular_velocity, b.angular_velocity, "{label}: frame {i}");
            assert!(b.jv.iter().all(|v| *v == 7.0), "{label}: frame {i}'s J_v");
            assert_eq!(b.bias_acceleration, [7.0; 3], "{label}: frame {i}");
        }
        for (i, (a, b)) in full.points.iter().zip(&moved.points).enumerate() {
            assert_eq!(a.position, b.position, "{label}: point {i}'s position");
            assert_eq!(a.velocity, b.velocity, "{label}: point {i}'s velocity");
            assert!(b.jv.iter().all(|v| *v == 7.0), "{label}: point {i}'s J_v");
        }
    }
    for (g, a, label) in both_forms() {
        for k in 0..4 {
            let (t, q, qd) = state(k);
            check(&g, t, &q, &qd, &format!("generated, {label}, state {k}"));
            check(&a, t, &q, &qd, &format!("assembled, {label}, state {k}"));
        }
    }
    // without `option motion;`, all of `kinematics`
    let dpend = mbs_models::dpend::DoublePendulum::default();
    let (mut full, mut moved) = (
        mbs::Kinematics::new::<mbs_models::dpend::DoublePendulum>(),
        mbs::Kinematics::new::<mbs_models::dpend::DoublePendulum>(),
    );
    dpend.kinematics(0.1, &[0.3, -0.2], &[1.0, 0.5], &mut full);
    dpend.motion(0.1, &[0.3, -0.2], &[1.0, 0.5], &mut moved);
    assert_eq!(full, moved);
    let human = mbs_models::human::Human::default();
    let (q, qd) = human_state();
    check(&human, 0.0, &q, &qd, "human");
    let (motion, kinematics) = (
        human_flops(&human, "motion"),
        human_flops(&human, "kinematics"),
    );
    println!("human model: motion {motion} flops, kinematics {kinematics}");
    assert!(3 * motion < kinematics, "{motion} against {kinematics}");
    let thousands = |n: usize| format!("{},{:03}", n / 1000, n % 1000);
    quoted::says(
        "README.md",
        &[format!(
            "model's {} flops where `kinematics` takes {}, `mbs expand models/src/human.rs",
            thousands(motion),
            thousands(kinematics)
        )],
    );
}

/// `transmit` (`option motion;`) carries wrenches to the coordinates by one inward pass of the
/// tree: Q = Σ J_vᵀ F + J_ωᵀ T over the frames and J_vᵀ F over the points, the Jacobians those
/// of `kinematics`, on the mechanism in both forms and on the human model; a wrapper whose
/// efforts are transmitted (`Efforts::reads_jacobians` false) forms the h of one that reads the
/// Jacobians.
#[test]
fn transmit_is_the_jacobians_transposed() {
    fn check<M: Model>(model: &M, t: f64, q: &[f64], label: &str) -> f64 {
        let (n, nf, np) = (M::NQ, M::NFRAMES, M::NPOINTS);
        let f: Vec<f64> = (0..6 * nf + 3 * np)
            .map(|i| ((i * 7919 % 1000) as f64 / 500.0 - 1.0) * 10.0)
            .collect();
        let mut kin = mbs::Kinematics::new::<M>();
        model.kinematics(t, q, &vec![0.0; n], &mut kin);
        let mut by_jacobians = vec![0.0; n];
        let dot = |j: &[f64], k: usize, w: &[f64]| (0..3).map(|r| j[3 * k + r] * w[r]).sum::<f64>();
        for (k, g) in by_jacobians.iter_mut().enumerate() {
            for (i, fr) in kin.frames.iter().enumerate() {
                *g += dot(&fr.jv, k, &f[6 * i..]) + dot(&fr.jw, k, &f[6 * i + 3..]);
            }
            for (j, p) in kin.points.iter().enumerate() {
                *g += dot(&p.jv, k, &f[6 * nf + 3 * j..]);
            }
        }
        let mut transmitted = vec![7.0; n];
        model.transmit(t, q, &f, &mut transmitted);
        let scale = by_jacobians.iter().fold(1.0, |m: f64, v| m.max(v.abs()));
        let err = max_diff(&by_jacobians, &transmitted) / scale;
        assert!(err < 1e-13, "{label}: transmitted Q {err:e} from Σ Jᵀ W");
        err
    }
    let mut worst: f64 = 0.0;
    for (g, a, label) in both_forms() {
        const { assert!(Generated::MOTION_GENERATED && Assembled::MOTION_GENERATED) };
        for k in 0..4 {
            let (t, q, _) = state(k);
            worst = worst.max(check(&g, t, &q, &format!("generated, {label}, state {k}")));
            worst = worst.max(check(&a, t, &q, &format!("assembled, {label}, state {k}")));
        }
    }
    let human = mbs_models::human::Human::default();
    worst = worst.max(check(&human, 0.0, &human_state().0, "human"));
    // a model without the option: the default, through the Jacobians
    let dpend = mbs_models::dpend::DoublePendulum::default();
    const { assert!(!mbs_models::dpend::DoublePendulum::MOTION_GENERATED) };
    check(&dpend, 0.0, &[0.3, -0.2], "dpend");
    println!("transmitted Q within {worst:.1e} of Σ Jᵀ W (relative to its largest entry)");
    let transmit = human_flops(&human, "transmit");
    let kinematics = human_flops(&human, "kinematics");
    assert!(transmit < kinematics / 2, "{transmit} against {kinematics}");
    quoted::says(
        "README.md",
        &[format!(
            "the human model's transmission is {},{:03} flops, within {worst:.1e} of Σ Jᵀ W",
            transmit / 1000,
            transmit % 1000
        )],
    );

    // the same efforts through the Jacobians and transmitted
    #[derive(Clone)]
    struct Pushes<const JACOBIANS: bool>;
    impl<const JACOBIANS: bool> mbs::Efforts for Pushes<JACOBIANS> {
        fn reads_jacobians(&self) -> bool {
            JACOBIANS
        }
        fn efforts(&mut self, e: &mut mbs::Effort) -> Result<(), String> {
            let v = e.frame(3).velocity;
            let at = e.point(1).position;
            e.force_on_frame(3, at, [-2.0 * v[0], 1.0 + v[1], 0.5]);
            e.torque_on_frame(5, [0.3, -0.1 * e.qd[6], 0.2]);
            e.torque_on_frame(0, [0.1, 0.2, 0.3]);
            e.force_at_point(2, [1.0, 0.0, -3.0 * e.point(2).velocity[2]]);
            e.force_at_point(0, [0.0, 4.0, 0.0]);
            e.generalized_force(9, 0.7);
            Ok(())
        }
    }
    for (g, _, label) in both_forms() {
        let read = mbs::WithEfforts::new(g.clone(), Pushes::<true>);
        let transmitted = mbs::WithEfforts::new(g, Pushes::<false>);
        let n = Generated::NQ;
        for k in 0..3 {
            let (t, q, qd) = state(k);
            let (mut m1, mut h1) = (vec![0.0; n * n], vec![0.0; n]);
            let (mut m2, mut h2) = (vec![0.0; n * n], vec![0.0; n]);
            read.dynamics(t, &q, &qd, &[], &mut m1, &mut h1);
            transmitted.dynamics(t, &q, &qd, &[], &mut m2, &mut h2);
            let scale = h1.iter().fold(1.0, |m: f64, v| m.max(v.abs()));
            let err = max_diff(&h1, &h2) / scale;
            assert!(err < 1e-13, "{label}, state {k}: h {err:e} apart");
        }
    }
}

/// A user part that says it reads no Jacobian (`Efforts::reads_jacobians` false) and reads
/// one all the same finds it NaN, and the run stops with a typed error at its first
/// evaluation, the trajectory before it kept; the same user part saying it reads them runs.
#[test]
fn a_jacobian_read_where_the_efforts_are_transmitted_stops_the_run_typed() {
    #[derive(Clone)]
    struct Reads<const SAYS: bool>;
    impl<const SAYS: bool> mbs::Efforts for Reads<SAYS> {
        fn reads_jacobians(&self) -> bool {
            SAYS
        }
        fn efforts(&mut self, e: &mut mbs::Effort) -> Result<(), String> {
            let j = e.frame(1).jw[3 * 6 + 2];
            e.torque_on_frame(1, [0.0, 0.0, -0.1 * j]);
            Ok(())
        }
    }
    let (g, _, _) = both_forms().remove(0);
    let options = mbs::Options::adaptive(0.1, 1e-6);
    let ok = mbs::simulate(
        mbs::WithEfforts::new(g.clone(), Reads::<true>),
        mbs::Scheme::Dopri5,
        options.clone(),
    );
    assert!(ok.is_ok(), "{:?}", ok.err().map(|e| e.to_string()));
    let e = mbs::simulate(
        mbs::WithEfforts::new(g, Reads::<false>),
        mbs::Scheme::Dopri5,
        options,
    )
    .expect_err("a NaN Jacobian read");
    assert!(
        matches!(&e.kind, mbs::Failure::NonFinite { quantity, .. } if *quantity == "user effort"),
        "{e}"
    );
    assert_eq!(e.t, 0.0, "{e}");
    assert!(
        e.to_string()
            .contains("`Efforts::reads_jacobians` is false"),
        "{e}"
    );
    println!("{e}");
}
