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
