//! Work guards on generated code: operation counts are deterministic, so they are asserted.

use mbs_symbolic::SymbolicModel;
use mbs_symbolic::expr::{ExprId, ops};
use mbs_symbolic::mech::system::{Factor, Formulation, Inertia, Load, System};

/// chainN of MODELS.md: N uniform bars (l = 0.5 m, 1 kg), relative angles, gravity.
fn chain(n: usize) -> SymbolicModel {
    SymbolicModel::build(chain_system(n))
}

fn chain_system(n: usize) -> System {
    let mut sys = System::new(&format!("Chain{n}"));
    let l = sys.param("l", 0.5);
    let m = sys.param("m", 1.0);
    let g = sys.param("g", 9.81);
    let a = &mut sys.arena;
    let half = a.num(0.5);
    let hl = a.mul(half, l);
    let mhl = a.neg(hl);
    let ll = a.mul(l, l);
    let mll = a.mul(m, ll);
    let i = a.scale(1.0 / 12.0, mll);
    let z = a.zero();
    let inertia = Inertia {
        mass: m,
        tensor: [i, z, i, z, z, z],
    };
    serial(&mut sys, n, ("bar", 0.3), [z, mhl, z], inertia, |_| {
        [0.0, 0.0, 1.0]
    });
    let mg = sys.arena.neg(g);
    sys.effect(None, vec![Load::Gravity([z, mg, z])]);
    sys
}

/// `n` bodies `name[k]` in series, body k turning by q[k] (starting at `q0`) about `axis(k)`
/// between two displacements `offset` (the first body without the one before).
fn serial(
    sys: &mut System,
    n: usize,
    (name, q0): (&str, f64),
    offset: [ExprId; 3],
    inertia: Inertia,
    axis: impl Fn(usize) -> [f64; 3],
) {
    let mut parent = None;
    for k in 0..n {
        sys.dof(&format!("q[{k}]"), q0, 0.0);
        let qk = sys.q(k);
        let mut factors = Vec::new();
        if parent.is_some() {
            factors.push(Factor::Disp(offset));
        }
        factors.push(sys.rot(axis(k), qk));
        factors.push(Factor::Disp(offset));
        parent = Some(sys.frame(&format!("{name}{k}"), parent, factors, Some(inertia)));
    }
}

/// The scaling benchmark's spatial arm of n links (0.3 m × 0.05 m × 0.05 m, 1 kg) on
/// revolute joints whose axes alternate z, y; gravity along −z.
fn arm_system(n: usize) -> System {
    let mut sys = System::new(&format!("Arm{n}"));
    let g = sys.param("g", 9.81);
    let len = sys.param("len", 0.3);
    let w = sys.param("w", 0.05);
    let m = sys.param("m", 1.0);
    let a = &mut sys.arena;
    let (ww, ll) = (a.mul(w, w), a.mul(len, len));
    let ww2 = a.add(ww, ww);
    let llww = a.add(ll, ww);
    let (mx, my) = (a.mul(m, ww2), a.mul(m, llww));
    let (ixx, iyy) = (a.scale(1.0 / 12.0, mx), a.scale(1.0 / 12.0, my));
    let half = a.scale(0.5, len);
    let z = a.zero();
    let inertia = Inertia {
        mass: m,
        tensor: [ixx, iyy, iyy, z, z, z],
    };
    serial(&mut sys, n, ("link", 0.2), [half, z, z], inertia, |k| {
        if k % 2 == 0 {
            [0.0, 0.0, 1.0]
        } else {
            [0.0, 1.0, 0.0]
        }
    });
    let mg = sys.arena.neg(g);
    sys.effect(None, vec![Load::Gravity([z, z, mg])]);
    sys
}

fn mass_and_bias(model: &SymbolicModel) -> (usize, usize, usize) {
    let e = &model.scenes[0];
    let mb = e.chosen();
    let a = &model.sys.arena;
    let lower: Vec<_> =
        mb.m.iter()
            .enumerate()
            .flat_map(|(r, row)| row[..=r].to_vec())
            .collect();
    (
        ops(a, &lower).flops(),
        ops(a, &mb.h).flops(),
        ops(a, &mb.roots()).flops(),
    )
}

#[test]
fn chain_op_counts_grow_at_most_quadratically() {
    let (_, _, small) = mass_and_bias(&chain(12));
    let (m48, h48, big) = mass_and_bias(&chain(48));
    let ratio = big as f64 / small as f64;
    assert!(
        ratio <= 20.0,
        "M+h of chain48 is {ratio:.1} × chain12's ({big} vs {small} flops)"
    );
    // the README's figures, measured on chain48 (h 1,367 flops, lower triangle of M 9,648
    // flops), with 10 % headroom
    let n = 48.0;
    println!(
        "chain48: h {h48} flops ({:.1} per dof), M {m48} flops ({:.2} n²), M+h {big} flops",
        h48 as f64 / n,
        m48 as f64 / (n * n)
    );
    const H_PER_DOF: f64 = 28.5;
    const M_PER_N2: f64 = 4.2;
    assert!(
        h48 as f64 <= 1.1 * H_PER_DOF * n,
        "h of chain48: {h48} flops, the README says {H_PER_DOF} per dof"
    );
    assert!(
        m48 as f64 <= 1.1 * M_PER_N2 * n * n,
        "M of chain48: {m48} flops, the README says {M_PER_N2} n²"
    );
}

#[test]
fn both_formulations_are_built_and_the_cheaper_is_chosen() {
    for n in [2, 8] {
        let model = chain(n);
        let e = &model.scenes[0];
        let a = &model.sys.arena;
        let vp = ops(a, &e.vp.as_ref().expect("built").roots()).flops();
        let rec = ops(a, &e.rec.roots()).flops();
        assert_eq!(ops(a, &e.chosen().roots()).flops(), vp.min(rec));
    }
}

/// Products of a factor of parameters alone and a state value either keep that factor's
/// coefficient or float it out: the arm is cheaper kept, the chain floated, and each is
/// built in its cheaper form.
#[test]
fn of_the_two_forms_of_products_the_cheaper_is_built() {
    for (sys, kept_wins) in [(chain_system(8), false), (arm_system(6), true)] {
        let floated = SymbolicModel::build_with(sys.clone(), false).cost();
        let kept = SymbolicModel::build_with(sys.clone(), true).cost();
        assert_eq!(
            kept < floated,
            kept_wins,
            "{}: kept {kept}, floated {floated}",
            sys.name
        );
        assert_eq!(SymbolicModel::build(sys).cost(), kept.min(floated));
    }
}

#[test]
fn virtual_power_is_not_built_for_long_chains() {
    // 60 bars: Σ k(k+1)/2 over J_G and J_ω is about 75,000 products, above the limit; 30
    // bars (about 10,000) still build both
    let long = chain(60);
    assert!(long.scenes[0].vp.is_none() && long.scenes[0].tau_vp.is_none());
    assert_eq!(long.scenes[0].formulation, Formulation::Recursive);
    assert!(chain(30).scenes[0].vp.is_some());
}

/// An n-bar chain (relative angles) with a damped rotational spring at every joint, written
/// with `rotational_spring` (scene `Rot`) and with the equivalent generalised forces (scene
/// `Gen`), both with gravity.
fn sprung_chain(n: usize, absolute: bool) -> SymbolicModel {
    let mut src =
        String::from("model SprungChain { param l = 0.5; param k = 3.0; param c = 0.2;\n");
    let (mut rot, mut gen_) = (String::new(), String::new());
    let mut prefix = String::new();
    for i in 0..n {
        src += &format!(
            "dof q[{i}] = 0.1; body bar{i} {{ mass = 1.0; inertia = (0.02, 0.0, 0.02); }}\n"
        );
        let joint = format!("Trotz(q[{i}]) * Tdisp(0, -l/2, 0)");
        let pose = if i == 0 {
            joint.clone()
        } else if absolute {
            // CAGeM's absolute style: every pose from the ground
            format!("{prefix} * Tdisp(0, -l/2, 0) * {joint}")
        } else {
            format!("TOG[bar{}] * Tdisp(0, -l/2, 0) * {joint}", i - 1)
        };
        src += &format!("TOG[bar{i}] = {pose};\n");
        prefix = if i == 0 {
            joint
        } else {
            format!("{prefix} * Tdisp(0, -l/2, 0) * {joint}")
        };
        let parent = if i == 0 {
            "ground".to_string()
        } else {
            format!("bar{}", i - 1)
        };
        rot += &format!(
            "rotational_spring({parent}, bar{i}, axis = z, k = k, c = c, angle0 = 0.1);\n"
        );
        gen_ += &format!("generalized_force(q[{i}], -k * (q[{i}] - 0.1) - c * qd[{i}]);\n");
    }
    src += &format!(
        "effect rot {{ {rot} }} effect gen {{ {gen_} }} effect gravity {{ gravity(0, -9.81, 0); }}\n\
         scene Rot = [gravity, rot]; scene Gen = [gravity, gen]; }}"
    );
    let sys = mbs_symbolic::systems_from_str(&src).unwrap().remove(0);
    SymbolicModel::build(sys)
}

fn has_atan2(a: &mbs_symbolic::expr::Arena, roots: &[mbs_symbolic::expr::ExprId]) -> bool {
    a.reachable(roots)
        .into_iter()
        .any(|e| matches!(a.node(e), mbs_symbolic::expr::Node::Atan2(..)))
}

/// In a chain the angle of a rotational spring between a bar and its parent is the joint's
/// coordinate: its code is that of the generalised force −k (q − θ0) − c q̇, with no atan2,
/// whether the poses are relative (`TOG[parent] * …`) or absolute (shared prefixes).
#[test]
fn rotational_springs_in_a_chain_cost_what_generalised_forces_cost() {
    for absolute in [false, true] {
        let model = sprung_chain(8, absolute);
        let a = &model.sys.arena;
        let count = |scene: usize| {
            let eq = &model.scenes[scene];
            let mut r = eq.chosen().roots();
            r.push(eq.potential);
            r.push(eq.power);
            (ops(a, &eq.chosen().h), ops(a, &r), has_atan2(a, &r))
        };
        let (rot, gen_) = (count(0), count(1));
        println!(
            "chain of 8 bars with rotational springs ({}): h {} flops, M + h + V + power {} flops; \
             with generalised forces: h {} flops, M + h + power {} flops",
            if absolute {
                "absolute poses"
            } else {
                "relative poses"
            },
            rot.0.flops(),
            rot.1.flops(),
            gen_.0.flops(),
            gen_.1.flops()
        );
        assert!(!rot.2, "no atan2 in a chain's rotational springs");
        assert_eq!(rot.0.flops(), gen_.0.flops(), "h");
        assert_eq!(rot.0.funcs, gen_.0.funcs, "functions in h");
    }
}
