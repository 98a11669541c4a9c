//! A 40-link planar chain with a torsional spring and damper in every joint, written with
//! `for` loops in 13 lines of `multibody!`, against the same chain written out link by link
//! (absolute products from the ground, generalised forces instead of joint torques) and
//! evaluated on the generator's expression DAG: M and h agree to 1e-13 at random states.
//! Inline `fn`s are scoped lexically: an argument named like a model's name hides it in that
//! body alone, not in a `let` or another `fn` the body uses.

use mbs::{Model, Options, Scheme, simulate};
use mbs_symbolic::expr::SliceEnv;
use mbs_symbolic::{SymbolicModel, systems_from_str};

mbs::multibody! {
    /// 40 uniform bars hinged end to end about +z, a spring and damper in every joint.
    model Chain40 {
        param l = 0.5; param m = 1.0; param g = 9.81; param k = 50.0; param c = 0.2;
        for i in 0..40 {
            dof q[i] = 0.1;
            body bar[i] { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        }
        TOG[bar[0]] = Trotz(q[0]) * Tdisp(0, -l/2, 0);
        for i in 1..40 {
            TOG[bar[i]] = TOG[bar[i-1]] * Tdisp(0, -l/2, 0) * Trotz(q[i]) * Tdisp(0, -l/2, 0);
            torque(bar[i], relative_to = bar[i-1], axis = z, -k * q[i] - c * qd[i]);
        }
        gravity(0, -g, 0);
    }
}

mbs::multibody! {
    /// Two legs from one part, with indexed coordinates, bodies, points and parameters.
    model Legs {
        for k in 0..2 { param kp[k] = 100.0 * (k + 1); }
        part Leg(k, hy) {
            dof a[k] = 0.1;
            body thigh[k] { mass = 1.0; inertia = (0.01, 0.01, 0.002); }
            TOG[thigh[k]] = Tdisp(0, hy, 0) * Troty(a[k]) * Tdisp(0, 0, -0.2);
            point foot[k] on thigh[k] at (0, 0, -0.2);
            generalized_force(a[k], -kp[k] * a[k]);
        }
        Leg(0, 0.2);
        Leg(1, -0.2);
        gravity(0, 0, -9.81);
    }
}

mbs::multibody! {
    /// A slider pushed by a generalised force written with functions whose arguments are
    /// named like the model's parameter `l` and coordinate `x`.
    model Scoped {
        param l = 2.0;
        dof x = 0.0;
        body b { mass = 1.0; inertia = (1, 1, 1); }
        TOG[b] = Tdisp(x, 0, 0);
        let half = l / 2;
        fn f(l) = l * half;
        fn g(a) = a * x;
        fn k(x) = g(2.0) + x;
        generalized_force(q[x], f(3.0) + 10 * k(5.0));
        // functions of a number and a coordinate (a method on a bare number did not compile)
        generalized_force(q[x], pow(2.0, x) + atan2(1.0, x));
    }
}

mbs::multibody! {
    /// Three sliders pushed by a part's argument: a number written as integer arithmetic
    /// that does not divide (`3 / 2`, `i / 2`) is the real number the statement written out
    /// would give.
    model HalfPushes {
        part Push(k, f) {
            dof x[k] = 0.0;
            body b[k] { mass = 1.0; inertia = (1, 1, 1); }
            TOG[b[k]] = Tdisp(x[k], 0, 0);
            generalized_force(x[k], f);
        }
        Push(0, 3 / 2);
        for i in 1..3 { Push(i, i / 2 + 4 / 2); }
    }
}

/// A part's integer arguments were evaluated in integers wherever they were pasted: `3 / 2`
/// pushed with 1 N, where `generalized_force(x, 3 / 2)` pushes with 1.5.
#[test]
fn a_part_s_argument_that_does_not_divide_is_a_real_number() {
    let model = HalfPushes::default();
    let (mut m, mut h) = (vec![0.0; 9], vec![0.0; 3]);
    model.dynamics(0.0, &[0.0; 3], &[0.0; 3], &[], &mut m, &mut h);
    assert_eq!(h, [1.5, 2.5, 3.0]);
}

/// `half` is the model's l/2 = 1 even when first used inside `f(l)`, and `g` reads the
/// coordinate x even when called from `k(x)`: f(3) + 10 k(5) = 3·1 + 10 (2x + 5). Names
/// were bound for the whole of a call (dynamic scope): `half` became 3/2 for every use and
/// `g(2.0)` read k's argument, 4.5 + 10 (2·5 + 5) = 154.5 at any x.
#[test]
fn inline_functions_see_their_own_arguments_and_the_models_names() {
    let model = Scoped::default();
    let (mut m, mut h) = ([0.0], [0.0]);
    model.dynamics(0.0, &[0.7], &[0.0], &[], &mut m, &mut h);
    assert_eq!(m[0], 1.0);
    let want = 3.0 + 10.0 * (2.0 * 0.7 + 5.0) + 2f64.powf(0.7) + 1f64.atan2(0.7);
    assert!((h[0] - want).abs() < 1e-12, "{} against {want}", h[0]);
}

#[test]
fn indexed_names_read_as_written_in_outputs() {
    let model = Legs::default();
    let info = model.info();
    assert_eq!(info.dofs, ["a[0]", "a[1]"]);
    assert_eq!(info.frames, ["thigh[0]", "thigh[1]"]);
    assert_eq!(info.points, ["foot[0]", "foot[1]"]);
    // parameters are Rust fields: `kp[1]` is `kp_1`
    assert_eq!(info.params, ["kp_0", "kp_1"]);
    assert_eq!(model.params().kp_1, 200.0);
    let (tr, _) = simulate(
        model,
        Scheme::Dopri5,
        Options {
            output: mbs::Output::Every { dt: 0.01 },
            ..Options::adaptive(0.02, 1e-6)
        },
    )
    .expect("run");
    let mut csv = Vec::new();
    tr.write_csv(&mut csv).expect("csv");
    let header = String::from_utf8(csv).expect("utf-8");
    let header = header.lines().next().expect("header");
    let columns: Vec<&str> = header.split(',').collect();
    for c in ["a[0]", "a[1]", "qd[a[0]]", "qd[a[1]]", "qdd[a[1]]"] {
        assert!(columns.contains(&c), "{c} in {header}");
    }
}

/// The same chain, written out: bar j's pose from the ground, the joint springs and dampers
/// as generalised forces on their own angles (a torque about z between two bars joined by
/// q[i] does work on q[i] only).
fn written_out(n: usize) -> String {
    let mut s = String::from(
        "model Chain { param l = 0.5; param m = 1.0; param g = 9.81; param k = 50.0; param c = 0.2;\n",
    );
    for j in 0..n {
        s += &format!("dof q[{j}] = 0.1;\n");
        s += &format!("body link{j} {{ mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }}\n");
        let mut pose = String::new();
        for i in 0..=j {
            if i > 0 {
                pose += "Tdisp(0, -l, 0) * ";
            }
            pose += &format!("Trotz(q[{i}]) * ");
        }
        s += &format!("TOG[link{j}] = {pose}Tdisp(0, -l/2, 0);\n");
        if j > 0 {
            s += &format!("generalized_force(q[{j}], -k * q[{j}] - c * qd[{j}]);\n");
        }
    }
    s + "gravity(0, -g, 0);\n}"
}

#[test]
fn a_40_link_chain_in_a_loop_is_the_chain_written_out() {
    const N: usize = 40;
    let sys = systems_from_str(&written_out(N))
        .expect("written-out chain")
        .remove(0);
    let params = sys.param_defaults();
    let reference = SymbolicModel::build(sys);
    let model = Chain40::default();
    assert_eq!(Chain40::NQ, N);
    assert_eq!(model.info().frames[39], "bar[39]");
    assert_eq!(model.info().dofs[7], "q[7]");
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut random = || {
        // xorshift64*
        seed ^= seed >> 12;
        seed ^= seed << 25;
        seed ^= seed >> 27;
        (seed.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    };
    let (mut dev_m, mut dev_h) = (0.0f64, 0.0f64);
    for _ in 0..3 {
        let q: Vec<f64> = (0..N).map(|_| 2.0 * random() - 1.0).collect();
        let qd: Vec<f64> = (0..N).map(|_| 4.0 * random() - 2.0).collect();
        let (mut m, mut h) = (vec![0.0; N * N], vec![0.0; N]);
        model.dynamics(0.0, &q, &qd, &[], &mut m, &mut h);
        let env = SliceEnv {
            q: &q,
            qd: &qd,
            params: &params,
            ..SliceEnv::default()
        };
        let eq = &reference.scenes[0];
        let a = &reference.sys.arena;
        // 40 bars are beyond the size at which virtual power is built: the recursive one only
        assert!(eq.vp.is_none());
        {
            let mb = &eq.rec;
            let scale_m = m.iter().fold(0.0f64, |s, v| s.max(v.abs()));
            let scale_h = h.iter().fold(0.0f64, |s, v| s.max(v.abs()));
            for i in 0..N {
                for j in 0..N {
                    let r = a.eval(&[mb.m[i][j]], &env)[0];
                    let v = m[i * N + j];
                    dev_m = dev_m.max((v - r).abs() / scale_m);
                    assert!(
                        (v - r).abs() <= 1e-13 * scale_m,
                        "M[{i}][{j}] = {v}, written out {r}"
                    );
                }
                let r = a.eval(&[mb.h[i]], &env)[0];
                dev_h = dev_h.max((h[i] - r).abs() / scale_h);
                assert!(
                    (h[i] - r).abs() <= 1e-13 * scale_h,
                    "h[{i}] = {}, written out {r}",
                    h[i]
                );
            }
        }
    }
    println!("largest deviation, relative to the largest entry: M {dev_m:.1e}, h {dev_h:.1e}");
}

mbs::multibody! {
    #[doc = "A doc attribute with a carriage return:\rits second line."]
    model CarriageReturn {
        dof x = 0.0;
        body b { mass = 1.0; inertia = (1, 1, 1); }
        TOG[b] = Tdisp(x, 0, 0);
    }
}

/// A carriage return in a model's doc attribute ends a line of the generated docs: it was
/// written inside a `///` comment, which rustc refuses ("generated code does not parse").
#[test]
fn a_carriage_return_in_a_doc_attribute_is_a_line_break() {
    assert_eq!(CarriageReturn::NQ, 1);
}
