//! The force elements for efforts written in Rust (`mbs::elements`) against the DSL's:
//! `Rig` of tests/contact.rs (a ball in frictional sphere contact, an arm on a bushing, a
//! preloaded damped spring, a tip against a tilted wall) with its elements in the DSL, and
//! the same bodies with the elements applied by a hook: the same h at states in and out of
//! contact, and the same motion.

use mbs::elements::{Anchor, Bushing, PlaneContact, SpringDamper};
use mbs::{Effort, Efforts, Model, Options, Output, Scheme, WithEfforts, simulate};

mbs::multibody! {
    model Rig {
        param k = 1e4; param c = 30.0; param mu = 0.4; param eps = 1e-2;
        dof x = 0.0, qd = 1.0; dof y = 0.0; dof z = 0.2, qd = -1.0;
        dof a = 0.0, qd = 3.0; dof b = 0.1; dof r = 0.0, qd = -2.0;
        dof du = 0.3; dof dv = 0.0; dof dw = 0.02; dof s = 0.05;
        body ball { mass = 1.0; inertia = (0.004, 0.004, 0.004); }
        body arm { mass = 0.5; inertia = (0.001, 0.01, 0.01, 0.0005, 0.0, 0.0); }
        point tip on arm at (0.2, 0, 0);
        point hook on ground at (0.5, 0.2, 1.0);
        TOG[ball] = Tdisp(x, y, z) * Trotz(a) * Troty(b) * Trotx(r);
        TOG[arm] = TOG[ball] * Tdisp(du, dv, dw) * Trotz(s);
        gravity(0, 0, -9.81);
        effect elements {
            contact(ball, sphere = 0.1, k = k, c = c, mu = mu, eps = eps);
            contact(tip, plane = (-0.6, 0, 0.8), offset = -0.13, k = k, c = c, mu = mu, eps = eps);
            bushing(ball, arm, k = (300, 200, 400), kr = (3, 2, 1), c = 0.5, cr = (0.01, 0.02, 0.03));
            spring(hook, arm, k = 10, l0 = 0.6, c = 0.3, preload = 2);
        }
        scene Dsl = [elements]; scene Bare = [];
    }
}

/// The same elements, from `mbs::elements`.
struct Elements {
    ball: usize,
    arm: usize,
    tip: usize,
    hook: usize,
    ground: PlaneContact,
    wall: PlaneContact,
    bushing: Bushing,
    spring: SpringDamper,
}

impl Elements {
    fn new(info: &mbs::ModelInfo) -> Elements {
        let (k, c, mu, eps) = (1e4, 30.0, 0.4, 1e-2);
        let ground = PlaneContact {
            normal: [0.0, 0.0, 1.0],
            offset: 0.0,
            radius: 0.1,
            k,
            c,
            mu,
            eps,
        };
        Elements {
            ball: info.frame_index("ball").unwrap(),
            arm: info.frame_index("arm").unwrap(),
            tip: info.point_index("tip").unwrap(),
            hook: info.point_index("hook").unwrap(),
            ground,
            wall: PlaneContact {
                normal: [-0.6, 0.0, 0.8],
                offset: -0.13,
                radius: 0.0,
                ..ground
            },
            bushing: Bushing {
                k: [300.0, 200.0, 400.0],
                kr: [3.0, 2.0, 1.0],
                c: [0.5; 3],
                cr: [0.01, 0.02, 0.03],
            },
            spring: SpringDamper {
                k: 10.0,
                l0: 0.6,
                c: 0.3,
                preload: 2.0,
            },
        }
    }
}

impl Efforts for Elements {
    fn efforts(&mut self, e: &mut Effort) -> Result<(), String> {
        self.ground.apply_to_frame(e, self.ball);
        self.wall.apply_to_point(e, self.tip);
        self.bushing.apply(e, Some(self.ball), self.arm);
        self.spring
            .apply(e, Anchor::Point(self.hook), Anchor::Frame(self.arm));
        Ok(())
    }
}

fn hooked() -> WithEfforts<RigBare, Elements> {
    let bare = RigBare::default();
    let el = Elements::new(bare.info());
    WithEfforts::new(bare, el)
}

/// A state: the declared start, shifted by `s` along a fixed direction, the ball's centre at
/// height 0.1 + s (in contact with the ground for s < 0).
fn state(s: f64) -> ([f64; 10], [f64; 10]) {
    let m = RigDsl::default();
    let (mut q, mut qd) = ([0.0; 10], [0.0; 10]);
    m.initial_state(&mut q, &mut qd);
    for i in 0..10 {
        q[i] += s * (0.3 * i as f64 + 0.1).sin();
        qd[i] += s * (0.7 * i as f64).cos();
    }
    // the ball's height from 0.05 (pressing) to 0.15 (free)
    q[2] = 0.1 + s;
    (q, qd)
}

#[test]
fn elements_in_rust_give_the_dsl_forces() {
    let (dsl, hook) = (RigDsl::default(), hooked());
    let (mut m1, mut h1, mut m2, mut h2) = ([0.0; 100], [0.0; 10], [0.0; 100], [0.0; 10]);
    let mut worst = 0.0f64;
    let mut pressing = 0;
    for k in 0..20 {
        let (q, qd) = state(-0.05 + 0.01 * k as f64);
        dsl.dynamics(0.0, &q, &qd, &[], &mut m1, &mut h1);
        hook.dynamics(0.0, &q, &qd, &[], &mut m2, &mut h2);
        let scale = h1.iter().fold(1.0f64, |a, x| a.max(x.abs()));
        let d = (0..10).map(|i| (h1[i] - h2[i]).abs()).fold(0.0, f64::max) / scale;
        worst = worst.max(d);
        // the ball touches the ground when z < 0.1
        if q[2] < 0.1 {
            pressing += 1;
        }
    }
    println!(
        "h: DSL vs Rust elements, worst relative difference {worst:.1e}; {pressing} states in ground contact"
    );
    assert!(pressing > 3 && pressing < 20);
    assert!(worst < 1e-12);
}

#[test]
fn elements_in_rust_give_the_dsl_motion() {
    // fixed steps: with adaptive ones the contacts' kinks make the two runs choose different
    // steps from rounding-level differences (1925 and 1932 DOPRI5 steps, 3.6e-7 apart)
    let o = || Options {
        output: Output::Every { dt: 0.01 },
        ..Options::fixed(1.0, 1e-4)
    };
    let (a, sa) = simulate(RigDsl::default(), Scheme::Rk4, o()).unwrap();
    let (b, sb) = simulate(hooked(), Scheme::Rk4, o()).unwrap();
    let d = (0..a.len())
        .map(|i| {
            (0..10)
                .map(|k| (a.q(i)[k] - b.q(i)[k]).abs())
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max);
    println!(
        "motion over 1 s: max |Δq| {d:.1e}; {} and {} steps",
        sa.steps, sb.steps
    );
    assert!(d < 1e-10);
}

mbs::multibody! {
    /// A yoke turning about x carries a base turning about z, which carries a bar turning
    /// about z, with gravity: rotational springs at the three joints (scene `Rot`), or the
    /// same springs written as generalised forces (scene `Gen`); scene `Twist` adds a spring
    /// between the ground and the bar about z, whose angle is not a coordinate.
    model Hinged {
        param k = 4.0; param c = 0.3; param a0 = 0.2;
        dof r = 0.3, qd = -1.0; dof a = 0.4, qd = 1.0; dof b = -0.3, qd = 2.0;
        frame yoke;
        body base { mass = 2.0; inertia = (0.02, 0.03, 0.04); }
        body bar { mass = 1.0; inertia = (0.01, 0.002, 0.01); }
        TOG[yoke] = Trotx(r);
        TOG[base] = TOG[yoke] * Trotz(a) * Tdisp(0, -0.5, 0);
        TOG[bar] = TOG[base] * Tdisp(0, -0.5, 0) * Trotz(b) * Tdisp(0, -0.5, 0);
        gravity(0, -9.81, 0);
        effect rot {
            rotational_spring(ground, yoke, axis = x, k = 2 * k, angle0 = -a0);
            rotational_spring(yoke, base, axis = z, k = k, angle0 = a0);
            rotational_spring(base, bar, axis = (0, 0, 1), k = k, c = c, angle0 = a0);
        }
        effect gen {
            generalized_force(r, -2 * k * (r + a0));
            generalized_force(a, -k * (a - a0));
            generalized_force(b, -k * (b - a0) - c * qd[b]);
        }
        effect twist { rotational_spring(ground, bar, axis = z, k = k, c = c); }
        scene Rot = [rot]; scene Gen = [gen]; scene Twist = [rot, twist];
    }
}

fn hinged_state(s: f64) -> ([f64; 3], [f64; 3]) {
    let q = [0.3 + s, 0.4 - 2.0 * s, -0.3 + 3.0 * s];
    let qd = [-1.0 + s, 1.0 + 0.5 * s, 2.0 - s];
    (q, qd)
}

#[test]
fn rotational_springs_at_joints_are_the_generalised_forces_of_their_coordinates() {
    let (rot, gen_) = (HingedRot::default(), HingedGen::default());
    let (mut m1, mut h1, mut m2, mut h2) = ([0.0; 9], [0.0; 3], [0.0; 9], [0.0; 3]);
    let (k, c, a0) = (4.0, 0.3, 0.2);
    for i in 0..10 {
        let (q, qd) = hinged_state(0.4 * i as f64 - 2.0);
        rot.dynamics(0.0, &q, &qd, &[], &mut m1, &mut h1);
        gen_.dynamics(0.0, &q, &qd, &[], &mut m2, &mut h2);
        for j in 0..3 {
            assert!(
                (h1[j] - h2[j]).abs() < 1e-12 * (1.0 + h2[j].abs()),
                "h[{j}] at {q:?}"
            );
        }
        // the springs' potential, and the power of the damper alone
        let springs = 0.5 * 2.0 * k * (q[0] + a0).powi(2)
            + 0.5 * k * (q[1] - a0).powi(2)
            + 0.5 * k * (q[2] - a0).powi(2);
        let (e1, e2) = (rot.energy(0.0, &q, &qd), gen_.energy(0.0, &q, &qd));
        assert!((e1.kinetic - e2.kinetic).abs() < 1e-12);
        assert!((e1.potential - e2.potential - springs).abs() < 1e-12);
        let p = rot.power(0.0, &q, &qd, &[]);
        assert!((p + c * qd[2] * qd[2]).abs() < 1e-12, "{p}");
    }
}

/// Along a run, T + V changes by the work of the dampers, ∫ power dt: with the spring between
/// the ground and the bar (its angle from the rotations, atan2) and without.
#[test]
fn rotational_springs_keep_the_energy_balance() {
    fn balance<M: Model + 'static>(make: impl Fn() -> M) -> (f64, f64) {
        let opts = Options {
            output: Output::Every { dt: 1e-4 },
            energy: true,
            ..Options::adaptive(2.0, 1e-11)
        };
        let (tr, _) = simulate(make(), Scheme::Dopri5, opts).unwrap();
        let model = make();
        let power: Vec<f64> = (0..tr.len())
            .map(|i| model.power(tr.t[i], tr.q(i), tr.qd(i), &[]))
            .collect();
        let (mut work, mut worst) = (0.0, 0.0f64);
        for i in 1..tr.len() {
            work += 0.5 * (power[i] + power[i - 1]) * (tr.t[i] - tr.t[i - 1]);
            let de = tr.energy[i].total() - tr.energy[0].total();
            worst = worst.max((de - work).abs());
        }
        (worst, work)
    }
    for (name, (worst, work)) in [
        ("joints", balance(HingedRot::default)),
        ("joints and twist", balance(HingedTwist::default)),
    ] {
        println!(
            "{name}: |ΔE − ∫power| ≤ {worst:.1e} over 2 s, the dampers dissipated {:.3} J",
            -work
        );
        assert!(work < -0.1, "{name}: the damper works");
        // the trapezoidal rule on the outputs makes an error of about 1e-7 J
        assert!(worst < 1e-6, "{name}: {worst:e}");
    }
}

mbs::multibody! {
    /// A bar turning about z with a lumped mass at its tip, in the shorthands (`inertia_z`,
    /// `mass … on … at …`) and in the long forms.
    model Short {
        param l = 0.8; param m = 1.5;
        dof th = 0.3, qd = 1.0; dof s = 0.2, qd = -0.5;
        body cart { mass = 2.0; }
        body bar { mass = m; inertia_z = m * l * l / 12; }
        TOG[cart] = Tdisp(s, 0, 0);
        TOG[bar] = TOG[cart] * Trotz(th) * Tdisp(0, -l / 2, 0);
        mass tip on bar at (0, -l / 2, 0) = 0.5;
        gravity(0, -9.81, 0);
        rotational_damper(cart, bar, axis = z, c = 0.1);
    }
    model Long {
        param l = 0.8; param m = 1.5;
        dof th = 0.3, qd = 1.0; dof s = 0.2, qd = -0.5;
        body cart { mass = 2.0; }
        body bar { mass = m; inertia = (m * l * l / 12, 0, m * l * l / 12); }
        body tip { mass = 0.5; }
        TOG[cart] = Tdisp(s, 0, 0);
        TOG[bar] = TOG[cart] * Trotz(th) * Tdisp(0, -l / 2, 0);
        TOG[tip] = TOG[bar] * Tdisp(0, -l / 2, 0);
        gravity(0, -9.81, 0);
        torque(bar, axis = z, -0.1 * qd[th], relative_to = cart);
    }
}

#[test]
fn planar_inertia_and_point_mass_shorthands_give_the_long_forms() {
    let (short, long) = (Short::default(), Long::default());
    let (mut m1, mut h1, mut m2, mut h2) = ([0.0; 4], [0.0; 2], [0.0; 4], [0.0; 2]);
    for i in 0..10 {
        let x = i as f64 - 4.5;
        let (q, qd) = ([0.7 * x, 0.1 * x], [1.0 - 0.3 * x, 0.2 * x]);
        short.dynamics(0.0, &q, &qd, &[], &mut m1, &mut h1);
        long.dynamics(0.0, &q, &qd, &[], &mut m2, &mut h2);
        for j in 0..4 {
            assert!((m1[j] - m2[j]).abs() < 1e-12, "M at {q:?}");
        }
        for j in 0..2 {
            assert!(
                (h1[j] - h2[j]).abs() < 1e-12 * (1.0 + h2[j].abs()),
                "h at {q:?}"
            );
        }
        let (e1, e2) = (short.energy(0.0, &q, &qd), long.energy(0.0, &q, &qd));
        assert!((e1.total() - e2.total()).abs() < 1e-12);
    }
    // the tip is a body of the model, named like the others
    assert!(short.info().frame_index("tip").is_some());
}

/// A rotational spring's stiffness and damping made negative by parameters are refused at run
/// time (the defaults are checked at compile time).
#[test]
fn negative_rotational_coefficients_from_parameters_are_typed_errors() {
    use mbs::{ParamError, Parameters};
    let mut model = HingedRot::default();
    for (name, element, coefficient) in [
        ("k", "rotational spring 0", "k"),
        ("c", "rotational spring 2", "c"),
    ] {
        let mut p = model.params().clone();
        p.set(name, -1.0).unwrap();
        let e = model.set_params(p).unwrap_err();
        assert!(
            matches!(e, ParamError::InvalidCoefficient { element: el, name: n, .. } if el == element && n == coefficient),
            "{e:?}"
        );
    }
}

/// `Path::through` finds a path's points by name, and refuses a name the model does not
/// declare, or a path of fewer than two points, with a typed error that says so.
#[test]
fn a_path_is_built_from_declared_point_names() {
    use mbs::elements::{Path, PathError};
    let info = RigBare::default().info();
    let path = Path::through(info, &["hook", "tip"]).unwrap();
    assert_eq!(
        path.points,
        [
            info.point_index("hook").unwrap(),
            info.point_index("tip").unwrap()
        ]
    );
    let e = Path::through(info, &["hook", "tipp"]).unwrap_err();
    assert!(matches!(&e, PathError::NoPoint { name, .. } if name == "tipp"));
    assert!(e.to_string().contains("has no point `tipp`"), "{e}");
    let e = Path::through(info, &["hook"]).unwrap_err();
    assert!(matches!(e, PathError::TooShort { found: 1 }), "{e}");
}

/// Degenerate inputs give forces, not NaN: friction with no regularisation (ε = 0, exact
/// Coulomb) at rest, and a path whose two points coincide (no direction: it pulls nothing).
#[test]
fn exact_coulomb_at_rest_and_coincident_points_are_finite() {
    use mbs::elements::Path;
    use mbs::terrain::ContactLaw;
    let exact = PlaneContact {
        eps: 0.0,
        ..PlaneContact::default()
    };
    // 1 mm into the ground z = 0, at rest
    let f = exact.force([0.0, 0.0, -1e-3], [0.0; 3], [0.0; 3]);
    assert_eq!(f.force, [0.0, 0.0, 100.0]);
    // sliding, it is Coulomb's μ f_n against the motion
    let f = exact.force([0.0, 0.0, -1e-3], [0.5, 0.0, 0.0], [0.0; 3]);
    assert!((f.force[0] + 0.8 * 100.0).abs() < 1e-12, "{:?}", f.force);
    let law = ContactLaw {
        eps: 0.0,
        ..ContactLaw::default()
    };
    let f = law.force(1e-3, [0.0, 0.0, 1.0], [0.0, 0.0, -0.1]);
    assert!(
        f.iter().all(|x| x.is_finite()) && f[0] == 0.0 && f[2] > 0.0,
        "{f:?}"
    );

    let info = RigBare::default().info();
    let path = Path::through(info, &["hook", "tip"]).unwrap();
    let mut kin = mbs::Kinematics::new::<RigBare>();
    for p in &mut kin.points {
        p.position = [0.5, 0.2, 1.0];
        p.velocity = [0.0, 0.0, 1.0];
        p.jv.iter_mut().enumerate().for_each(|(k, x)| *x = k as f64);
    }
    kin.points[info.point_index("tip").unwrap()].velocity = [0.3, 0.0, 0.0];
    assert_eq!(path.length(&kin), (0.0, 0.0));
    let mut grad = vec![f64::NAN; RigBare::NQ];
    path.gradient(&kin, &mut grad);
    assert!(grad.iter().all(|&g| g == 0.0), "{grad:?}");
}

mbs::multibody! {
    /// One-sided forces whose derivatives are infinite at the kink of their positive part:
    /// √pos(x), pos(x)^0.7 and pos(x)^n with the exponent n a sensitive parameter.
    model Kinks {
        param k = 100.0; param n = 1.5 sensitive;
        dof x = 0.0;
        body b { mass = 1.0; inertia = (1, 1, 1); }
        TOG[b] = Tdisp(x, 0, 0);
        generalized_force(q[x], -k * sqrt(pos(x)) - pow(pos(x), 0.7) - pow(pos(x), n));
        option tangents;
    }
}

mbs::multibody! {
    /// Forces of the magnitude |x| whose derivatives are infinite at x = 0: √|x|, |x|^0.7 and
    /// |x|^n with the exponent n a sensitive parameter (a damper growing with √|v|, say).
    model AbsKinks {
        param k = 100.0; param n = 1.5 sensitive;
        dof x = 0.0;
        body b { mass = 1.0; inertia = (1, 1, 1); }
        TOG[b] = Tdisp(x, 0, 0);
        generalized_force(q[x], -k * sqrt(abs(x)) - pow(abs(x), 0.7) - pow(abs(x), n));
        option tangents;
    }
}

mbs::multibody! {
    /// The same kinks scaled by parameters: a damper √(|v|/v0), a spring pos(c·x/x0)^0.7 and
    /// √(k·pos(x)) written with the parameter inside the root.
    model ScaledKinks {
        param k = 100.0; param v0 = 0.01; param c = 2.0; param x0 = 0.5;
        dof x = 0.0;
        body b { mass = 1.0; inertia = (1, 1, 1); }
        TOG[b] = Tdisp(x, 0, 0);
        generalized_force(q[x], -sqrt(abs(qd[x]) / v0) - pow(c * pos(x) / x0, 0.7) - sqrt(k * pos(x)));
        option tangents;
    }
}

/// At rest (x = 0, v = 0) the tangents of kinks scaled by parameters are 0, where only a
/// numeric factor was taken off the kink and √(|v|/v0) gave ∂τ/∂v = inf·0 = NaN at every
/// start from rest; beside the kink they are the derivatives by hand.
#[test]
fn derivatives_at_a_kink_scaled_by_parameters_are_zero_not_nan() {
    let model = ScaledKinks::default();
    let at = |x: f64, v: f64| {
        let (mut k, mut c) = ([0.0], [0.0]);
        model
            .tangents(0.0, &[x], &[v], &[0.0], &[], &mut k, &mut c)
            .unwrap();
        (k[0], c[0])
    };
    assert_eq!(at(0.0, 0.0), (0.0, 0.0));
    let (x, v) = (0.2f64, -0.3f64);
    let (k, c) = at(x, v);
    let want_k = 0.7 * 4.0f64.powf(0.7) * x.powf(-0.3) + 0.5 * 100.0f64.sqrt() / x.sqrt();
    let want_c = -0.5 / (v.abs() / 0.01).sqrt() / 0.01;
    assert!((k - want_k).abs() < 1e-12 * want_k, "{k} against {want_k}");
    assert!(
        (c - want_c).abs() < 1e-12 * want_c.abs(),
        "{c} against {want_c}"
    );
}

/// A one-coordinate model's tangent stiffness K and ∂τ/∂n (its one sensitive parameter) at
/// rest at x.
fn stiffness_and_exponent_derivative<M: Model>(model: &M, x: f64) -> (f64, f64) {
    let (mut k, mut c) = ([0.0], [0.0]);
    model
        .tangents(0.0, &[x], &[0.0], &[0.0], &[], &mut k, &mut c)
        .unwrap();
    let mut dp = [0.0];
    model
        .parameter_tangents(0.0, &[x], &[0.0], &[0.0], &[], &mut dp)
        .unwrap();
    (k[0], dp[0])
}

/// At x = 0 the tangent and the derivative by the exponent of forces of |x| are 0, where the
/// chain rule gave inf·0 = NaN; on both sides of it they are the derivatives by hand.
#[test]
fn derivatives_at_the_kink_of_a_magnitude_are_zero_not_nan() {
    let model = AbsKinks::default();
    let k_at = |x: f64| stiffness_and_exponent_derivative(&model, x);
    assert_eq!(k_at(0.0), (0.0, 0.0));
    for x in [0.2f64, -0.3] {
        let (k, dp) = k_at(x);
        let (m, s) = (x.abs(), x.signum());
        // K = ∂τ/∂q, τ = M qdd − h: the derivative of minus the force
        let want = s * (100.0 * 0.5 / m.sqrt() + 0.7 * m.powf(-0.3) + 1.5 * m.powf(0.5));
        assert!(
            (k - want).abs() < 1e-12 * want.abs(),
            "x = {x}: {k} against {want}"
        );
        let want = m.powf(1.5) * m.ln();
        assert!((dp - want).abs() < 1e-14, "x = {x}: {dp} against {want}");
    }
}

/// Off contact (x ≤ 0) the tangent and the derivative by the exponent are 0, where the chain
/// rule gave inf·0 = NaN; in contact they are the derivatives by hand.
#[test]
fn derivatives_at_the_kink_of_a_positive_part_are_zero_not_nan() {
    let model = Kinks::default();
    let k_at = |x: f64| stiffness_and_exponent_derivative(&model, x);
    // K = ∂τ/∂q with τ = M qdd − h: the derivative of minus the force
    for x in [-0.1, 0.0] {
        assert_eq!(k_at(x), (0.0, 0.0), "x = {x}");
    }
    let x: f64 = 0.2;
    let (k, dp) = k_at(x);
    let want = 100.0 * 0.5 / x.sqrt() + 0.7 * x.powf(-0.3) + 1.5 * x.powf(0.5);
    assert!((k - want).abs() < 1e-12 * want, "{k} against {want}");
    let want = x.powf(1.5) * x.ln();
    assert!((dp - want).abs() < 1e-14, "{dp} against {want}");
}

/// A plane contact at a position, velocity or regularising speed that is not a number gives
/// a force that is not one (which stops a run naming the effort), not a silent zero: the
/// clamp of the normal force and the guard of friction's division made it 0.
#[test]
fn a_plane_contact_at_nan_is_nan_not_zero() {
    let c = PlaneContact::default();
    let nan = f64::NAN;
    for (x, v) in [
        ([0.0, 0.0, nan], [0.0; 3]),
        ([0.0, 0.0, -0.01], [0.0, 0.0, nan]),
        ([0.0, 0.0, -0.01], [nan, 0.0, 0.0]),
    ] {
        let f = c.force(x, v, [0.0; 3]);
        assert!(f.force.iter().any(|x| x.is_nan()), "{x:?} {v:?}: {f:?}");
    }
    let slippery = PlaneContact { eps: nan, ..c };
    let f = slippery.force([0.0, 0.0, -0.01], [0.1, 0.0, 0.0], [0.0; 3]);
    assert!(f.force[0].is_nan(), "{f:?}");
    // out of contact and at rest, a plain zero
    assert_eq!(c.force([0.0, 0.0, 0.5], [0.0; 3], [0.0; 3]).force, [0.0; 3]);
}
