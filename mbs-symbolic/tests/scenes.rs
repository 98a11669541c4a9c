//! A scene pays only for the effects it calls for: an effect absent from a scene has no
//! operation in that scene's code, and every operation a scene has beyond a smaller one
//! depends on the effect it adds.

use mbs_symbolic::expr::{Arena, ExprId, Node, Var};
use mbs_symbolic::{SymbolicModel, systems_from_str};
use std::collections::HashSet;

const DPEND: &str = r#"
    model DoublePendulum {
        param l = 1.0; param m = 1.0; param g = 9.81; param c = 0.05;
        dof q[0] = PI / 2; dof q[1] = 0.0;
        body bar1 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar2 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        TOG[bar1] = Trotz(q[0]) * Tdisp(0, -l/2, 0);
        TOG[bar2] = TOG[bar1] * Tdisp(0, -l/2, 0) * Trotz(q[1]) * Tdisp(0, -l/2, 0);
        effect gravity { gravity(0, -g, 0); }
        effect damping { torque(bar2, relative_to = bar1, axis = z, -c * qd[1]); }
        scene Free = []; scene Swing = [gravity]; scene Full = [gravity, damping];
    }
"#;

/// Every function of a scene that effects can change: M and h, τ, static forces, power.
fn roots(model: &SymbolicModel, scene: usize) -> Vec<ExprId> {
    let e = &model.scenes[scene];
    let mut r = e.chosen().roots();
    r.extend_from_slice(e.tau());
    r.extend_from_slice(&e.static_h);
    r.push(e.power);
    r.push(e.potential);
    r
}

fn ops(a: &Arena, r: &[ExprId]) -> usize {
    let c = mbs_symbolic::expr::ops(a, r);
    c.flops() + c.funcs
}

/// Nodes (operations, not leaves) reachable from `r`.
fn op_nodes(a: &Arena, r: &[ExprId]) -> HashSet<ExprId> {
    a.reachable(r)
        .into_iter()
        .filter(|&n| !matches!(a.node(n), Node::Num(_) | Node::Var(_)))
        .collect()
}

#[test]
fn absent_effects_have_no_operations() {
    let sys = systems_from_str(DPEND).unwrap().remove(0);
    let model = SymbolicModel::build(sys);
    let a = &model.sys.arena;
    let (free, swing, full) = (roots(&model, 0), roots(&model, 1), roots(&model, 2));
    let g = Var::Param(2);
    let c = Var::Param(3);
    // the parameters of an absent effect appear nowhere in a scene's code
    assert!(!a.vars_of(&free).contains(&g) && !a.vars_of(&free).contains(&c));
    assert!(a.vars_of(&swing).contains(&g) && !a.vars_of(&swing).contains(&c));
    assert!(a.vars_of(&full).contains(&g) && a.vars_of(&full).contains(&c));
    // more effects, more operations
    let (of, os, ou) = (ops(a, &free), ops(a, &swing), ops(a, &full));
    assert!(of < os && os < ou, "ops: Free {of}, Swing {os}, Full {ou}");
    // every operation Swing has beyond Free serves a term that involves g (it is g itself or
    // lies below an operation on g); likewise for Full beyond Swing and the damping coefficient
    let (nf, ns, nu) = (op_nodes(a, &free), op_nodes(a, &swing), op_nodes(a, &full));
    let serving = |nodes: &HashSet<ExprId>, v: Var| -> HashSet<ExprId> {
        let dependent: Vec<ExprId> = nodes
            .iter()
            .copied()
            .filter(|&n| a.vars_of(&[n]).contains(&v))
            .collect();
        a.reachable(&dependent).into_iter().collect()
    };
    let for_g = serving(&ns, g);
    let extra_swing: Vec<_> = ns.difference(&nf).copied().collect();
    assert!(!extra_swing.is_empty());
    for n in &extra_swing {
        assert!(
            for_g.contains(n),
            "Swing has an operation beyond Free that serves no gravity term: {}",
            a.to_sexpr(*n)
        );
    }
    let for_c = serving(&nu, c);
    let extra_full: Vec<_> = nu.difference(&ns).copied().collect();
    assert!(!extra_full.is_empty());
    for n in &extra_full {
        assert!(
            for_c.contains(n),
            "Full has an operation beyond Swing that serves no damping term: {}",
            a.to_sexpr(*n)
        );
    }
}

#[test]
fn emitted_scene_code_mentions_only_its_effects() {
    let sys = systems_from_str(DPEND).unwrap().remove(0);
    let generated = mbs_symbolic::codegen::generate(sys, "pub").unwrap();
    let code = &generated.code;
    let section = |ty: &str| {
        let start = code.find(&format!("impl {ty} {{\n#[inline]")).unwrap();
        let end = code[start..]
            .find(&format!("impl ::mbs::Model for {ty}"))
            .unwrap();
        &code[start..start + end]
    };
    let (free, swing, full) = (
        section("DoublePendulumFree"),
        section("DoublePendulumSwing"),
        section("DoublePendulumFull"),
    );
    assert!(!free.contains("p_g") && !free.contains("p_c"));
    assert!(swing.contains("p_g") && !swing.contains("p_c"));
    assert!(full.contains("p_g") && full.contains("p_c"));
    let dynamics = |ty: &str| {
        generated
            .reports
            .iter()
            .find(|r| r.model == ty && r.function.starts_with("dynamics"))
            .unwrap()
            .ops
            .flops()
    };
    assert!(dynamics("DoublePendulumFree") < dynamics("DoublePendulumSwing"));
    assert!(dynamics("DoublePendulumSwing") < dynamics("DoublePendulumFull"));
}
