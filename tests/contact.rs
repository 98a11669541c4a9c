//! Force elements of the DSL: penalty contacts with a plane (points and spheres, damping,
//! regularised friction), bushings and preloaded springs, generated with the equations.
//!
//! - exact tangents against central differences of τ at states in contact;
//! - the energy identity dE/dt = power along a run with every force element;
//! - a box dropped on its 8 corners comes to rest, carried by its weight;
//! - E(t) never grows during the drop;
//! - small oscillations on a bushing at √(k/m) and √(k_r/I);
//! - the static position of a mass on a preloaded spring.

mod common;

#[path = "common/quoted.rs"]
mod quoted;

use common::{accelerations, energy_rate, fd_tangents};
use mbs::{Kinematics, Model, Options, Output, Scheme, simulate};

const G: f64 = 9.81;

mbs::multibody! {
    /// A box of side 0.2 m (1 kg) on the ground z = 0, touching it with its 8 corners.
    pub model Block {
        param k = 2e4; param c = 100.0; param mu = 0.5; param eps = 1e-4;
        dof x = 0.0, qd = 0.8; dof y = 0.0, qd = -0.3; dof z = 0.3;
        dof a = 0.3, qd = 2.0; dof b = 0.2; dof r = -0.15, qd = 1.0;
        body box1 { mass = 1.0; inertia = (0.2 * 0.2 / 6, 0.2 * 0.2 / 6, 0.2 * 0.2 / 6); }
        point c0 on box1 at (-0.1, -0.1, -0.1);
        point c1 on box1 at (0.1, -0.1, -0.1);
        point c2 on box1 at (0.1, 0.1, -0.1);
        point c3 on box1 at (-0.1, 0.1, -0.1);
        point c4 on box1 at (-0.1, -0.1, 0.1);
        point c5 on box1 at (0.1, -0.1, 0.1);
        point c6 on box1 at (0.1, 0.1, 0.1);
        point c7 on box1 at (-0.1, 0.1, 0.1);
        TOG[box1] = Tdisp(x, y, z) * Trotz(a) * Troty(b) * Trotx(r);
        gravity(0, 0, -9.81);
        contact(c0, k = k, c = c, mu = mu, eps = eps);
        contact(c1, k = k, c = c, mu = mu, eps = eps);
        contact(c2, k = k, c = c, mu = mu, eps = eps);
        contact(c3, k = k, c = c, mu = mu, eps = eps);
        contact(c4, k = k, c = c, mu = mu, eps = eps);
        contact(c5, k = k, c = c, mu = mu, eps = eps);
        contact(c6, k = k, c = c, mu = mu, eps = eps);
        contact(c7, k = k, c = c, mu = mu, eps = eps);
        option tangents;
    }
}

mbs::multibody! {
    /// Every force element at once: a ball (sphere contact with friction) carrying an arm on
    /// a bushing, the arm hung from the ground by a preloaded, damped spring and touching a
    /// tilted wall with its tip.
    pub model Rig {
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
        contact(ball, sphere = 0.1, k = k, c = c, mu = mu, eps = eps);
        contact(tip, plane = (-0.6, 0, 0.8), offset = -0.13, k = k, c = c, mu = mu, eps = eps);
        bushing(ball, arm, k = (300, 200, 400), kr = (3, 2, 1), c = 0.5, cr = (0.01, 0.02, 0.03));
        spring(hook, arm, k = 10, l0 = 0.6, c = 0.3, preload = 2);
        option tangents;
    }
}

mbs::multibody! {
    /// The box of `Block` in three scenes (free, on the floor, on the floor and hung from a
    /// spring): with tangents and several scenes, the tangents of the bodies and gravity are
    /// generated once, those of `floor` (which two scenes have) once, and `Hung` adds those of
    /// `hung`.
    pub model Crate {
        param k = 2e4; param c = 100.0; param mu = 0.5; param eps = 1e-4;
        dof x = 0.0; dof y = 0.0; dof z = 0.3; dof a = 0.3; dof b = 0.2; dof r = -0.15;
        body box1 { mass = 1.0; inertia = (0.2 * 0.2 / 6, 0.2 * 0.2 / 6, 0.2 * 0.2 / 6); }
        point c0 on box1 at (-0.1, -0.1, -0.1);
        point c1 on box1 at (0.1, -0.1, -0.1);
        point c2 on box1 at (0.1, 0.1, -0.1);
        point c3 on box1 at (-0.1, 0.1, -0.1);
        point hook on ground at (0.3, 0.2, 1.0);
        TOG[box1] = Tdisp(x, y, z) * Trotz(a) * Troty(b) * Trotx(r);
        gravity(0, 0, -9.81);
        effect floor {
            contact(c0, k = k, c = c, mu = mu, eps = eps);
            contact(c1, k = k, c = c, mu = mu, eps = eps);
            contact(c2, k = k, c = c, mu = mu, eps = eps);
            contact(c3, k = k, c = c, mu = mu, eps = eps);
        }
        effect hung {
            spring(hook, c2, k = 50, l0 = 0.5, c = 0.7);
        }
        scene Free = [];
        scene Floor = [floor];
        scene Hung = [floor, hung];
        option tangents;
    }
}

mbs::multibody! {
    /// `Crate`'s `Hung` scene written without effects or scenes: its τ, static forces,
    /// energies, power and tangents are its own functions, each whole.
    pub model CrateWhole {
        param k = 2e4; param c = 100.0; param mu = 0.5; param eps = 1e-4;
        dof x = 0.0; dof y = 0.0; dof z = 0.3; dof a = 0.3; dof b = 0.2; dof r = -0.15;
        body box1 { mass = 1.0; inertia = (0.2 * 0.2 / 6, 0.2 * 0.2 / 6, 0.2 * 0.2 / 6); }
        point c0 on box1 at (-0.1, -0.1, -0.1);
        point c1 on box1 at (0.1, -0.1, -0.1);
        point c2 on box1 at (0.1, 0.1, -0.1);
        point c3 on box1 at (-0.1, 0.1, -0.1);
        point hook on ground at (0.3, 0.2, 1.0);
        TOG[box1] = Tdisp(x, y, z) * Trotz(a) * Troty(b) * Trotx(r);
        gravity(0, 0, -9.81);
        contact(c0, k = k, c = c, mu = mu, eps = eps);
        contact(c1, k = k, c = c, mu = mu, eps = eps);
        contact(c2, k = k, c = c, mu = mu, eps = eps);
        contact(c3, k = k, c = c, mu = mu, eps = eps);
        spring(hook, c2, k = 50, l0 = 0.5, c = 0.7);
        option tangents;
    }
}

mbs::multibody! {
    /// The box with gravity as an effect of its own: a scene whose effects beyond the common
    /// ones hold gravity (which acts through the bodies) builds its tangents whole; the others
    /// share theirs.
    pub model Weighed {
        param k = 2e4; param c = 100.0; param mu = 0.5; param eps = 1e-4;
        dof x = 0.0; dof y = 0.0; dof z = 0.3; dof a = 0.3; dof b = 0.2; dof r = -0.15;
        body box1 { mass = 1.0; inertia = (0.2 * 0.2 / 6, 0.2 * 0.2 / 6, 0.2 * 0.2 / 6); }
        point c0 on box1 at (-0.1, -0.1, -0.1);
        point c1 on box1 at (0.1, -0.1, -0.1);
        point c2 on box1 at (0.1, 0.1, -0.1);
        TOG[box1] = Tdisp(x, y, z) * Trotz(a) * Troty(b) * Trotx(r);
        effect weight { gravity(0, 0, -9.81); }
        effect floor {
            contact(c0, k = k, c = c, mu = mu, eps = eps);
            contact(c1, k = k, c = c, mu = mu, eps = eps);
            contact(c2, k = k, c = c, mu = mu, eps = eps);
        }
        scene Free = [];
        scene Floor = [floor];
        scene Heavy = [weight, floor];
        option tangents;
    }
}

mbs::multibody! {
    /// A body on a bushing to the ground: translation x and rotation a about z.
    pub model Mount {
        param m = 2.0; param izz = 0.05;
        dof x = 0.01; dof a = 0.001;
        body block { mass = m; inertia = (0.03, 0.04, izz); }
        TOG[block] = Tdisp(x, 0, 0) * Trotz(a);
        bushing(ground, block, k = (800, 500, 900), kr = (7, 6, 5));
    }
}

mbs::multibody! {
    /// A mass hanging from the origin on a preloaded spring (tension F0 at the rest length).
    pub model Hang {
        param m = 2.0; param k = 50.0; param l0 = 0.4; param f0 = 6.0;
        dof z = -1.0;
        body bob { mass = m; }
        TOG[bob] = Tdisp(0, 0, z);
        gravity(0, 0, -9.81);
        spring(ground, bob, k = k, l0 = l0, c = 3.0, preload = f0);
    }
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// Penetrations δ and normal forces F_n = step(δ)·pos(k δ + c δ̇) of the Block's corners,
/// from its kinematics (plane z = 0: δ = −z, δ̇ = −ż).
fn corner_forces(m: &Block, q: &[f64], qd: &[f64]) -> Vec<(f64, f64)> {
    let p = m.params();
    let mut kin = Kinematics::new::<Block>();
    m.kinematics(0.0, q, qd, &mut kin);
    kin.points
        .iter()
        .map(|pt| {
            let (d, dd) = (-pt.position[2], -pt.velocity[2]);
            let f = if d > 0.0 {
                (p.k * d + p.c * dd).max(0.0)
            } else {
                0.0
            };
            (d, f)
        })
        .collect()
}

fn check_tangents<M: Model>(m: &M, q: &[f64], qd: &[f64], qdd: &[f64], what: &str) -> f64 {
    let n = M::NQ;
    let (mut k, mut c) = (vec![0.0; n * n], vec![0.0; n * n]);
    m.tangents(0.0, q, qd, qdd, &[], &mut k, &mut c).unwrap();
    let (kf, cf) = fd_tangents(m, q, qd, qdd, 1e-6);
    let rel = |x: &[f64], y: &[f64]| {
        let d: Vec<f64> = x.iter().zip(y).map(|(a, b)| a - b).collect();
        max_abs(&d) / max_abs(y).max(1e-300)
    };
    let (ek, ec) = (rel(&k, &kf), rel(&c, &cf));
    println!(
        "{what}: K_t {ek:.2e}, C_t {ec:.2e} (max |K| {:.3e}, |C| {:.3e})",
        max_abs(&kf),
        max_abs(&cf)
    );
    assert!(ek < 1e-6 && ec < 1e-6, "{what}: K_t {ek:.2e}, C_t {ec:.2e}");
    ek.max(ec)
}

#[test]
fn exact_tangents_in_contact_match_central_differences() {
    // the box tilted with three corners penetrating, sliding fast (|v_t| ≫ eps) …
    let block = Block::default();
    let q = [0.1, -0.2, 0.0985, 0.4, 0.05, -0.03];
    let qd = [0.7, -0.4, -0.05, 1.5, 0.3, -0.6];
    let qdd = [0.3, -1.0, 2.0, 0.5, -0.2, 0.1];
    let f = corner_forces(&block, &q, &qd);
    let pressing = f.iter().filter(|(d, fn_)| *d > 0.0 && *fn_ > 0.0).count();
    assert!(pressing >= 2, "{f:?}");
    check_tangents(&block, &q, &qd, &qdd, "block sliding on 3 corners");
    // … and creeping, |v_t| of the order of eps (the regularised part of friction), with a
    // larger eps so that the differences resolve the curvature of sqrt(|v_t|² + eps²)
    let mut creep = Block::default();
    let mut p = creep.params().clone();
    p.eps = 1e-2;
    creep.set_params(p).unwrap();
    let qd = [0.004, -0.006, -0.01, 0.02, 0.01, -0.01];
    check_tangents(&creep, &q, &qd, &qdd, "block creeping on 3 corners");
    // the rig: the ball penetrating and spinning (friction at the contact point, ω × (−r n)),
    // the tip in the tilted wall, the bushing deformed, the spring stretched
    let rig = Rig::default();
    let q = [0.1, 0.05, 0.097, 0.3, 0.1, -0.2, 0.32, 0.01, 0.03, 0.1];
    let qd = [0.8, -0.2, -0.3, 2.0, -1.0, 0.5, 0.1, -0.2, 0.05, 0.4];
    let qdd = [0.1; 10];
    let mut kin = Kinematics::new::<Rig>();
    rig.kinematics(0.0, &q, &qd, &mut kin);
    let tip = kin.points[0].position;
    assert!(
        0.1 - kin.frames[0].pose.position[2] > 0.0,
        "ball in contact"
    );
    assert!(
        -0.13 - (-0.6 * tip[0] + 0.8 * tip[2]) > 0.0,
        "tip in the wall: {tip:?}"
    );
    check_tangents(&rig, &q, &qd, &qdd, "rig: sphere, tip, bushing, spring");
}

#[test]
fn tangents_shared_by_scenes_match_central_differences() {
    // three corners in the floor, sliding, the spring stretched
    let q = [0.1, -0.2, 0.0985, 0.4, 0.05, -0.03];
    let qd = [0.7, -0.4, -0.05, 1.5, 0.3, -0.6];
    let qdd = [0.3, -1.0, 2.0, 0.5, -0.2, 0.1];
    check_tangents(&CrateFree::default(), &q, &qd, &qdd, "crate, free");
    check_tangents(&CrateFloor::default(), &q, &qd, &qdd, "crate on the floor");
    check_tangents(
        &CrateHung::default(),
        &q,
        &qd,
        &qdd,
        "crate on the floor, hung",
    );
    // each part generated once: the floor's tangents serve two scenes
    fn parts<M: Model>(m: &M) -> Vec<&'static str> {
        let rows = m.info().ops.iter().map(|(label, _)| *label);
        rows.filter(|l| l.starts_with("tangents")).collect()
    }
    let common = "tangents (K, C), common part";
    let floor = "tangents (K, C), effects floor";
    assert_eq!(parts(&CrateFree::default()), [common]);
    assert_eq!(parts(&CrateFloor::default()), [common, floor]);
    let hung = "tangents (K, C), effects hung";
    assert_eq!(parts(&CrateHung::default()), [common, floor, hung]);
    // gravity as an effect: the scene that has it builds its own; the floor's part then
    // serves one scene
    check_tangents(&WeighedFree::default(), &q, &qd, &qdd, "weighed, free");
    check_tangents(&WeighedFloor::default(), &q, &qd, &qdd, "weighed, floor");
    check_tangents(&WeighedHeavy::default(), &q, &qd, &qdd, "weighed, heavy");
    assert_eq!(parts(&WeighedFree::default()), [common]);
    assert_eq!(parts(&WeighedFloor::default()), [common, floor]);
    assert_eq!(parts(&WeighedHeavy::default()), ["tangents (K, C)"]);
}

/// With several scenes, τ, the static forces, the energies and the power are sums of parts
/// generated once too (the bodies' and gravity's, then each group of effects'): `Crate`'s
/// `Hung` scene gives what `CrateWhole`, the same system in one piece, gives.
#[test]
fn parts_shared_by_scenes_sum_to_the_scene_s_equations() {
    let (hung, whole) = (CrateHung::default(), CrateWhole::default());
    let n = CrateWhole::NQ;
    // three corners in the floor, sliding, the spring stretched
    let q = [0.1, -0.2, 0.0985, 0.4, 0.05, -0.03];
    let qd = [0.7, -0.4, -0.05, 1.5, 0.3, -0.6];
    let qdd = [0.3, -1.0, 2.0, 0.5, -0.2, 0.1];
    let close = |a: &[f64], b: &[f64], what: &str| {
        let scale = 1.0 + max_abs(b);
        let d = a
            .iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(d <= 1e-12 * scale, "{what}: {a:?} against {b:?}");
    };
    let (mut t1, mut t2) = (vec![0.0; n], vec![0.0; n]);
    hung.inverse_dynamics(0.0, &q, &qd, &qdd, &[], &mut t1);
    whole.inverse_dynamics(0.0, &q, &qd, &qdd, &[], &mut t2);
    close(&t1, &t2, "inverse dynamics");
    // and τ = M qdd − h of the scene's own dynamics
    let (mut m, mut h) = (vec![0.0; n * n], vec![0.0; n]);
    hung.dynamics(0.0, &q, &qd, &[], &mut m, &mut h);
    let mh: Vec<f64> = (0..n)
        .map(|i| (0..n).map(|j| m[i + n * j] * qdd[j]).sum::<f64>() - h[i])
        .collect();
    close(&t1, &mh, "inverse dynamics against M qdd − h");
    hung.static_forces(0.0, &q, &[], &mut t1);
    whole.static_forces(0.0, &q, &[], &mut t2);
    close(&t1, &t2, "static forces");
    let (e1, e2) = (hung.energy(0.0, &q, &qd), whole.energy(0.0, &q, &qd));
    close(
        &[e1.kinetic, e1.potential],
        &[e2.kinetic, e2.potential],
        "energies",
    );
    let (p1, p2) = (
        hung.power(0.0, &q, &qd, &[]),
        whole.power(0.0, &q, &qd, &[]),
    );
    close(&[p1], &[p2], "power");
    assert!(
        p1 < 0.0,
        "the floor's friction and the spring's damper dissipate: {p1}"
    );
    let (mut k1, mut c1) = (vec![0.0; n * n], vec![0.0; n * n]);
    let (mut k2, mut c2) = (vec![0.0; n * n], vec![0.0; n * n]);
    hung.tangents(0.0, &q, &qd, &qdd, &[], &mut k1, &mut c1)
        .unwrap();
    whole
        .tangents(0.0, &q, &qd, &qdd, &[], &mut k2, &mut c2)
        .unwrap();
    close(&k1, &k2, "K");
    close(&c1, &c2, "C");
    // each generated once: the scene's rows are the parts'
    let rows = |f: &str| -> Vec<&'static str> {
        let rows = hung.info().ops.iter().map(|(label, _)| *label);
        rows.filter(|l| l.split(',').next() == Some(f)).collect()
    };
    for f in ["inverse_dynamics", "static_forces", "energy", "power"] {
        let parts: Vec<String> = ["common part", "effects floor", "effects hung"]
            .iter()
            .map(|p| format!("{f}, {p}"))
            .collect();
        assert_eq!(rows(f), parts, "{f}");
    }
}

#[test]
fn energy_identity_along_a_run_with_every_force_element() {
    let rig = Rig::default();
    let opts = Options {
        output: Output::Every { dt: 2e-3 },
        ..Options::adaptive(1.5, 1e-7)
    };
    let (tr, st) = simulate(Rig::default(), Scheme::Radau5, opts).unwrap();
    let (mut worst, mut in_contact, mut dissipated) = (0.0f64, [0usize; 2], 0.0f64);
    let mut kin = Kinematics::new::<Rig>();
    for i in 0..tr.len() {
        let (t, q, qd) = (tr.t[i], tr.q(i), tr.qd(i));
        let qdd = accelerations(&rig, t, q, qd);
        let de = energy_rate(&rig, t, q, qd, &qdd, 1e-6);
        let p = rig.power(t, q, qd, &[]);
        // relative to the size of the power and of the kinetic energy's rate
        let scale = p.abs().max(de.abs()).max(1.0);
        worst = worst.max((de - p).abs() / scale);
        assert!(p <= 1e-12 * scale, "power {p} > 0 at t = {t}");
        dissipated = dissipated.min(p);
        rig.kinematics(t, q, qd, &mut kin);
        let tip = kin.points[0].position;
        in_contact[0] += (0.1 - kin.frames[0].pose.position[2] > 0.0) as usize;
        in_contact[1] += (-0.13 - (-0.6 * tip[0] + 0.8 * tip[2]) > 0.0) as usize;
    }
    println!(
        "rig, radau5 rtol 1e-7, {} steps: {} outputs, ball in contact at {}, tip at {}; \
         max |dE/dt − P| / max(|P|, |dE/dt|, 1 W) = {worst:.2e}; most negative power {dissipated:.2} W",
        st.steps,
        tr.len(),
        in_contact[0],
        in_contact[1]
    );
    assert!(in_contact[0] > 50 && in_contact[1] > 50, "{in_contact:?}");
    assert!(worst < 1e-5, "energy identity: {worst:.2e}");
}

#[test]
fn a_dropped_box_comes_to_rest_on_its_weight_and_never_gains_energy() {
    let block = Block::default();
    let opts = Options {
        output: Output::Steps,
        ..Options::adaptive(3.0, 1e-8)
    };
    let (tr, st) = simulate(Block::default(), Scheme::Radau5, opts).unwrap();
    // E(t) = kinetic + potential (gravity, contacts) never grows beyond the integrator's error
    let e: Vec<f64> = tr.energy.iter().map(|e| e.total()).collect();
    let e0 = e[0];
    let growth = e.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
    // the largest rise between any two outputs, earlier to later
    let mut min_so_far = f64::INFINITY;
    let mut rise = 0.0f64;
    for &ei in &e {
        min_so_far = min_so_far.min(ei);
        rise = rise.max(ei - min_so_far);
    }
    let n = tr.len();
    let (q, qd) = (tr.q(n - 1), tr.qd(n - 1));
    let f = corner_forces(&block, q, qd);
    let total: f64 = f.iter().map(|(_, fn_)| fn_).sum();
    let touching = f.iter().filter(|(d, _)| *d > 0.0).count();
    println!(
        "box drop, radau5 rtol 1e-8: {} steps ({} rejected); E {:.4} J → {:.6} J, largest \
         rise of E {rise:.2e} J (step to step {growth:.2e} J); at t = 3: max |qd| {:.2e}, \
         {touching} corners touching, Σ F_n = {total:.9} N (m g = {G})",
        st.steps,
        st.rejected_error + st.rejected_newton,
        e0,
        e[n - 1],
        max_abs(qd)
    );
    // measured 9e-12 J with radau5 at rtol 1e-8 (E0 = 3.3 J): a margin of 1000
    assert!(rise < 1e-8, "E grew by {rise:.2e} J");
    assert!(max_abs(qd) < 1e-6, "still moving: {qd:?}");
    assert_eq!(touching, 4, "resting on a face: {f:?}");
    assert!((total - G).abs() < 1e-6 * G, "Σ F_n = {total}");
    // as the README says it: the weight to 1e-9 relative
    println!("Σ F_n against m g: {:.1e} relative", (total - G).abs() / G);
    assert!((total - G).abs() <= 1e-9 * G, "Σ F_n = {total}");
    quoted::says(
        "docs/status.md",
        &[format!(
            "a dropped box rests with its normal forces summing to its weight to 1e-9 relative, \
             its energy never rising by more than {rise:.0e} J"
        )],
    );
}

/// Times of the upward zero crossings of a sampled signal (linear interpolation).
fn upward_crossings(t: &[f64], x: &[f64]) -> Vec<f64> {
    (1..x.len())
        .filter(|&i| x[i - 1] < 0.0 && x[i] >= 0.0)
        .map(|i| t[i - 1] + (t[i] - t[i - 1]) * (-x[i - 1]) / (x[i] - x[i - 1]))
        .collect()
}

#[test]
fn bushing_small_oscillations_at_sqrt_k_over_m() {
    let mount = Mount::default();
    let p = mount.params().clone();
    let opts = Options {
        output: Output::Every { dt: 1e-4 },
        energy: false,
        ..Options::adaptive(5.0, 1e-10)
    };
    let (tr, _) = simulate(Mount::default(), Scheme::Dopri5, opts).unwrap();
    for (i, (what, want)) in [
        ("translation x", (800.0 / p.m).sqrt()),
        ("rotation about z", (5.0 / p.izz).sqrt()),
    ]
    .into_iter()
    .enumerate()
    {
        let x: Vec<f64> = (0..tr.len()).map(|k| tr.q(k)[i]).collect();
        let c = upward_crossings(&tr.t, &x);
        let periods = (c.len() - 1) as f64;
        let omega = 2.0 * std::f64::consts::PI * periods / (c[c.len() - 1] - c[0]);
        // the rotation's elastic torque is −½ k_r sin 2a (the gradient of ½ k_r sin² a): at
        // amplitude A its frequency is lower by A²/4 = 2.5e-7 relative
        let err = (omega - want).abs() / want;
        println!("bushing {what}: ω = {omega:.8} rad/s, √(k/m) = {want:.8} ({err:.1e})");
        assert!(err < 1e-6, "{what}: {omega} vs {want}");
    }
}

#[test]
fn a_mass_hangs_where_the_preloaded_spring_carries_its_weight() {
    let hang = Hang::default();
    let p = hang.params().clone();
    // tension F0 + k (l − l0) = m g at l = −z
    let z_star = -(p.l0 + (p.m * G - p.f0) / p.k);
    let mut h = [0.0];
    hang.static_forces(0.0, &[z_star], &[], &mut h);
    println!("preloaded spring: z* = {z_star}, h(z*) = {:.2e}", h[0]);
    assert!(h[0].abs() < 1e-12 * p.m * G);
    // and a damped run settles there
    let opts = Options {
        output: Output::Last,
        ..Options::adaptive(30.0, 1e-10)
    };
    let (tr, _) = simulate(Hang::default(), Scheme::Dopri5, opts).unwrap();
    let z = tr.q(tr.len() - 1)[0];
    println!("settled at z = {z:.12} (z* = {z_star:.12})");
    assert!((z - z_star).abs() < 1e-8);
    // potential F0 (l − l0) + ½ k (l − l0)² − m g z, from the generated energy
    let e = hang.energy(0.0, &[z_star], &[0.0]);
    let s = -z_star - p.l0;
    let want = p.f0 * s + 0.5 * p.k * s * s + p.m * G * z_star;
    assert!(
        (e.potential - want).abs() < 1e-12 * want.abs(),
        "{} vs {want}",
        e.potential
    );
}

/// Parameters that make a force element unphysical are refused at run time too (the
/// defaults are checked at compile time).
#[test]
fn unphysical_coefficients_from_parameters_are_typed_errors() {
    use mbs::{ParamError, Parameters};
    let mut block = Block::default();
    let mut p = block.params().clone();
    p.set("k", -1.0).unwrap();
    let e = block.set_params(p).unwrap_err();
    assert!(
        matches!(
            e,
            ParamError::InvalidCoefficient {
                element: "contact 0",
                name: "k",
                ..
            }
        ),
        "{e:?}"
    );
    println!("{e}");
    let mut p = block.params().clone();
    p.set("mu", -0.2).unwrap();
    assert!(matches!(
        block.set_params(p),
        Err(ParamError::InvalidCoefficient { name: "mu", .. })
    ));
    let mut p = block.params().clone();
    p.set("eps", 0.0).unwrap();
    assert!(block.set_params(p).is_err());
}
