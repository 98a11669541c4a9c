//! Bodies spinning about a symmetry axis: their spin angle must not enter M, h or τ, and the
//! equations must equal those of the same system with the symmetry hidden from the generator.

use mbs_symbolic::SymbolicModel;
use mbs_symbolic::expr::{ExprId, Func, Node, SliceEnv, Var};
use mbs_symbolic::mech::system::{Inertia, Load, System};

/// A turntable (q0) with an arm carrying a geared rotor (spin 50·q0 about z), a wheel on its
/// own axle (q1, about x), a flywheel driven in time (about y) and a pendulum (q2).
/// `hidden`: each spinning body's transverse moments are two parameters of equal value, so
/// the generator cannot see the symmetry. The rotor and the flywheel sit a little along their
/// spin axes: `after` writes that translation after the spin (`Trotz(50 q0) * Tdisp(0, 0,
/// 0.05)`), otherwise before it; both are the same transform.
fn system(hidden: bool, after: bool) -> System {
    let mut sys = System::new("Spin");
    let i_a = sys.param("i_a", 2e-4);
    let i_b = if hidden { sys.param("i_b", 2e-4) } else { i_a };
    let z = sys.num(0.0);
    for (k, q0) in [0.3, -0.4, 0.8].iter().enumerate() {
        sys.dof(&format!("q[{k}]"), *q0, 0.0);
    }
    let (q0, q1, q2, t) = (sys.q(0), sys.q(1), sys.q(2), sys.t());
    let table = sys.inertia(3.0, [0.05, 0.05, 0.09, 0.0, 0.0, 0.0]);
    let f = sys.rot([0.0, 0.0, 1.0], q0);
    let d = sys.disp([0.0, 0.0, 0.1]);
    let table = sys.frame("table", None, vec![f, d], Some(table));
    let arm_tip = sys.disp([0.4, 0.0, 0.0]);
    let gear = sys.arena.scale(50.0, q0);
    let spin_z = sys.rot([0.0, 0.0, 1.0], gear);
    let spin_i = sys.num(5e-4);
    let rotor = Inertia {
        mass: sys.num(0.2),
        tensor: [i_a, i_b, spin_i, z, z, z],
    };
    let lift = sys.disp([0.0, 0.0, 0.05]);
    let along = |tip, spin, shift| {
        if after {
            vec![tip, spin, shift]
        } else {
            vec![tip, shift, spin]
        }
    };
    sys.frame(
        "rotor",
        Some(table),
        along(arm_tip, spin_z, lift),
        Some(rotor),
    );
    let axle = sys.disp([0.0, 0.3, 0.0]);
    let spin_x = sys.rot([1.0, 0.0, 0.0], q1);
    let (w_a, w_b) = equal_pair(&mut sys, "w", 0.002, hidden);
    let (wx, wm) = (sys.num(0.004), sys.num(0.5));
    let wheel = Inertia {
        mass: wm,
        tensor: [wx, w_a, w_b, z, z, z],
    };
    let wheel = sys.frame("wheel", Some(table), vec![axle, spin_x], Some(wheel));
    let w = sys.arena.scale(30.0, t);
    let spin_y = sys.rot([0.0, -1.0, 0.0], w);
    let (f_a, f_b) = equal_pair(&mut sys, "f", 0.001, hidden);
    let (fy, fm) = (sys.num(0.003), sys.num(0.3));
    let fly = Inertia {
        mass: fm,
        tensor: [f_a, fy, f_b, z, z, z],
    };
    let off = sys.disp([-0.3, 0.0, 0.0]);
    let shift = sys.disp([0.0, 0.02, 0.0]);
    sys.frame(
        "flywheel",
        Some(table),
        along(off, spin_y, shift),
        Some(fly),
    );
    let hinge = sys.rot([1.0, 0.0, 0.0], q2);
    let down = sys.disp([0.0, 0.0, -0.2]);
    let bob = sys.inertia(0.4, [0.002, 0.002, 0.0005, 0.0, 0.0, 0.0]);
    sys.frame("bob", Some(wheel), vec![hinge, down], Some(bob));
    let g = sys.vec3([0.0, 0.0, -9.81]);
    let c = sys.num(0.02);
    let qd1 = sys.qd(1);
    let drag = sys.arena.mul(c, qd1);
    let drag = sys.arena.neg(drag);
    sys.effect(
        None,
        vec![
            Load::Gravity(g),
            Load::GenForce {
                dof: 1,
                value: drag,
            },
        ],
    );
    sys
}

/// Two transverse moments of equal value: the same expression, or two parameters.
fn equal_pair(sys: &mut System, name: &str, v: f64, hidden: bool) -> (ExprId, ExprId) {
    if hidden {
        (
            sys.param(&format!("{name}_a"), v),
            sys.param(&format!("{name}_b"), v),
        )
    } else {
        let e = sys.num(v);
        (e, e)
    }
}

fn has_trig_of(
    model: &SymbolicModel,
    roots: &[ExprId],
    angle: impl Fn(&SymbolicModel, ExprId) -> bool,
) -> bool {
    let a = &model.sys.arena;
    a.reachable(roots).into_iter().any(|n| match a.node(n) {
        Node::Func(Func::Sin | Func::Cos, x) => angle(model, x),
        _ => false,
    })
}

#[test]
fn spinning_bodies_need_no_trigonometry_of_their_spin() {
    // a translation along the spin axis written after the spin moves in front of it
    for after in [false, true] {
        spin_without_trigonometry(after);
    }
}

fn spin_without_trigonometry(after: bool) {
    let model = SymbolicModel::build(system(false, after));
    let e = &model.scenes[0];
    let mut roots = e.vp.as_ref().expect("small model").roots();
    roots.extend(e.rec.roots());
    roots.extend_from_slice(&e.tau_rec);
    roots.extend_from_slice(e.tau_vp.as_ref().expect("small model"));
    roots.push(e.kinetic);
    // the geared rotor's angle 50 q0 and the flywheel's 30 t never meet sin or cos
    let geared = |m: &SymbolicModel, x: ExprId| {
        let a = &m.sys.arena;
        matches!(a.node(x), Node::Mul(c, v) if a.as_num(c).is_some() && matches!(a.node(v), Node::Var(Var::Q(0) | Var::T)))
    };
    assert!(!has_trig_of(&model, &roots, geared), "after: {after}");
    // the wheel's own coordinate q1 does appear: the bob hangs from the wheel
    let wheel = |m: &SymbolicModel, x: ExprId| matches!(m.sys.arena.node(x), Node::Var(Var::Q(1)));
    assert!(has_trig_of(&model, &roots, wheel));
    // poses still carry the full rotation
    let rotor_node = model.tree.frame_node[1];
    let pose: Vec<ExprId> = model.world.nodes[rotor_node]
        .r
        .iter()
        .flatten()
        .copied()
        .collect();
    assert!(has_trig_of(&model, &pose, geared));
}

#[test]
fn spinning_bodies_have_the_same_equations_as_without_the_shortcut() {
    let mut flops_fast = Vec::new();
    for after in [false, true] {
        let fast = SymbolicModel::build(system(false, after));
        let slow = SymbolicModel::build(system(true, after));
        same_equations(&fast, &slow);
        flops_fast.push(flops(&fast));
    }
    // the order the product is written in costs nothing
    assert_eq!(flops_fast[0], flops_fast[1]);
}

fn flops(m: &SymbolicModel) -> usize {
    mbs_symbolic::expr::ops(&m.sys.arena, &m.scenes[0].chosen().roots()).flops()
}

/// `fast` and `slow` have the same M, h, τ and energies, and `fast` costs less.
fn same_equations(fast: &SymbolicModel, slow: &SymbolicModel) {
    let states = [
        ([0.3, -0.4, 0.8], [1.1, -2.0, 0.7], [0.5, 0.2, -1.3], 0.37),
        ([-1.2, 2.5, -0.1], [-0.3, 4.0, 2.2], [1.0, -1.0, 0.0], 1.9),
    ];
    for (q, qd, qdd, t) in states {
        for (mf, ms) in [(fast, slow)] {
            let pf = mf.sys.param_defaults();
            let ps = ms.sys.param_defaults();
            let ef = SliceEnv {
                t,
                q: &q,
                qd: &qd,
                qdd: &qdd,
                params: &pf,
                u: &[],
                lambda: &[],
                charts: &[],
            };
            let es = SliceEnv {
                t,
                q: &q,
                qd: &qd,
                qdd: &qdd,
                params: &ps,
                u: &[],
                lambda: &[],
                charts: &[],
            };
            let (f, s) = (&mf.scenes[0], &ms.scenes[0]);
            let pairs: Vec<(Vec<ExprId>, Vec<ExprId>)> = vec![
                (vp(f).roots(), vp(s).roots()),
                (f.rec.roots(), s.rec.roots()),
                (f.tau_rec.clone(), s.tau_rec.clone()),
                (tau_vp(f), tau_vp(s)),
                (vec![f.kinetic, f.potential], vec![s.kinetic, s.potential]),
            ];
            for (rf, rs) in pairs {
                let vf = mf.sys.arena.eval(&rf, &ef);
                let vs = ms.sys.arena.eval(&rs, &es);
                let scale = vs.iter().fold(1e-300f64, |m, x| m.max(x.abs()));
                for (x, y) in vf.iter().zip(&vs) {
                    assert!((x - y).abs() <= 1e-12 * scale, "{x} vs {y} (scale {scale})");
                }
            }
        }
    }
    // and the shortcut saves work
    assert!(
        flops(fast) < flops(slow),
        "{} vs {}",
        flops(fast),
        flops(slow)
    );
}

fn vp(e: &mbs_symbolic::mech::dynamics::SceneEquations) -> &mbs_symbolic::mech::dynamics::MassBias {
    e.vp.as_ref().expect("a small model builds virtual power")
}

fn tau_vp(e: &mbs_symbolic::mech::dynamics::SceneEquations) -> Vec<ExprId> {
    e.tau_vp
        .clone()
        .expect("a small model builds virtual power")
}
