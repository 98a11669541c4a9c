//! `for` loops and `part`s: the statements they expand to generate the same code as the
//! statements written out, indexed names stay readable, and errors say which instance.

mod expansion;
use expansion::{errors, generate};

/// Equal code, or the first line that differs.
fn same(a: &str, b: &str) {
    for (k, (x, y)) in a.lines().zip(b.lines()).enumerate() {
        assert_eq!(x, y, "line {k} differs");
    }
    assert_eq!(a.lines().count(), b.lines().count());
}

/// chain8 of MODELS.md written bar by bar, with `bars` naming bar k.
fn chain_written_out(n: usize, bar: impl Fn(usize) -> String) -> String {
    let mut s = String::from(
        "model Chain { param l = 0.5; param m = 1.0; param g = 9.81; param k = 10.0;\n",
    );
    for i in 0..n {
        s += &format!("dof q[{i}] = 0.3;\n");
    }
    for i in 0..n {
        s += &format!(
            "body {} {{ mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }}\n",
            bar(i)
        );
    }
    s += &format!("TOG[{}] = Trotz(q[0]) * Tdisp(0, -l/2, 0);\n", bar(0));
    for i in 1..n {
        s += &format!(
            "TOG[{}] = TOG[{}] * Tdisp(0, -l/2, 0) * Trotz(q[{i}]) * Tdisp(0, -l/2, 0);\n",
            bar(i),
            bar(i - 1)
        );
    }
    s += "gravity(0, -g, 0);\neffect springs {\n";
    for i in 1..n {
        s += &format!("generalized_force(q[{i}], -k * q[{i}] + 0.5 * {i});\n");
    }
    s + "}\nscene Sprung = [springs];\n}"
}

const CHAIN_LOOP: &str = "model Chain {
    param l = 0.5; param m = 1.0; param g = 9.81; param k = 10.0;
    for i in 0..8 { dof q[i] = 0.3; }
    for i in 0..8 { body bar[i] { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); } }
    TOG[bar[0]] = Trotz(q[0]) * Tdisp(0, -l/2, 0);
    for i in 1..8 {
        TOG[bar[i]] = TOG[bar[i-1]] * Tdisp(0, -l/2, 0) * Trotz(q[i]) * Tdisp(0, -l/2, 0);
    }
    gravity(0, -g, 0);
    effect springs { for i in 1..8 { generalized_force(q[i], -k * q[i] + 0.5 * i); } }
    scene Sprung = [springs];
}";

#[test]
fn a_loop_generates_the_code_written_out() {
    let looped = generate(CHAIN_LOOP).expect("loop chain");
    let written = generate(&chain_written_out(8, |i| format!("bar{i}"))).expect("chain");
    // the same code but for the bodies' names, which read `bar[3]`
    let mut renamed = looped.clone();
    for i in 0..8 {
        renamed = renamed.replace(&format!("bar[{i}]"), &format!("bar{i}"));
    }
    assert_ne!(renamed, looped, "the names appear in the code");
    same(&renamed, &written);
    // indexed names written out literally are the same names
    let literal = generate(&chain_written_out(8, |i| format!("bar[{i}]"))).expect("chain");
    same(&looped, &literal);
}

#[test]
fn parts_generate_the_code_written_out() {
    let part = "model Arms {
        param m = 1.0;
        part Arm(k, x, mount, side) {
            dof a[k] = 0.1 * k;
            body link[k] { mass = m; inertia = (0.1, 0.1, 0.1); }
            TOG[link[k]] = mount * Tdisp(x, side * 0.2, 0) * Trotz(a[k]) * Tdisp(0.5, 0, 0);
            point tip[k] on link[k] at (0.5, 0, 0);
            spring(tip[k], ground, k = 10.0 * (k + 1), l0 = 0.1);
        }
        frame base;
        TOG[base] = Tdisp(0, 0, 1);
        Arm(0, 0.4, TOG[base], 1);
        for i in 1..3 { Arm(i, -0.4 * i, TOG[base] * Trotx(0.1), -1); }
        gravity(0, 0, -9.81);
    }";
    let written = "model Arms {
        param m = 1.0;
        frame base;
        TOG[base] = Tdisp(0, 0, 1);
        dof a[0] = 0.1 * 0;
        body link[0] { mass = m; inertia = (0.1, 0.1, 0.1); }
        TOG[link[0]] = TOG[base] * Tdisp(0.4, 1 * 0.2, 0) * Trotz(a[0]) * Tdisp(0.5, 0, 0);
        point tip[0] on link[0] at (0.5, 0, 0);
        spring(tip[0], ground, k = 10.0 * (0 + 1), l0 = 0.1);
        dof a[1] = 0.1 * 1;
        body link[1] { mass = m; inertia = (0.1, 0.1, 0.1); }
        TOG[link[1]] = TOG[base] * Trotx(0.1) * Tdisp(-0.4 * 1, -1 * 0.2, 0) * Trotz(a[1]) * Tdisp(0.5, 0, 0);
        point tip[1] on link[1] at (0.5, 0, 0);
        spring(tip[1], ground, k = 10.0 * (1 + 1), l0 = 0.1);
        dof a[2] = 0.1 * 2;
        body link[2] { mass = m; inertia = (0.1, 0.1, 0.1); }
        TOG[link[2]] = TOG[base] * Trotx(0.1) * Tdisp(-0.4 * 2, -1 * 0.2, 0) * Trotz(a[2]) * Tdisp(0.5, 0, 0);
        point tip[2] on link[2] at (0.5, 0, 0);
        spring(tip[2], ground, k = 10.0 * (2 + 1), l0 = 0.1);
        gravity(0, 0, -9.81);
    }";
    let p = generate(part).expect("part");
    same(&p, &generate(written).expect("written"));
    for name in ["\"a[2]\"", "\"link[1]\"", "\"tip[0]\""] {
        assert!(p.contains(name), "{name} in the model's names");
    }
}

#[test]
fn indexed_parameters_are_rust_fields() {
    let src = "model P {
        for i in 0..2 { param k[i] = 1.0 + i; }
        dof x = 0.0;
        body b { mass = 1.0; inertia = (1, 1, 1); }
        TOG[b] = Tdisp(x, 0, 0);
        generalized_force(x, -k[0] * x - k[1] * x * x * x);
    }";
    let code = generate(src).expect("model");
    assert!(code.contains("pub k_0: f64"), "{code}");
    assert!(code.contains("pub k_1: f64"));
    let clash = errors(
        "model P { param k_1 = 2.0; param k[1] = 1.0; dof x; body b { mass = 1.0; inertia = (1, 1, 1); } TOG[b] = Tdisp(x, 0, 0); }",
    );
    assert_eq!(
        clash,
        [
            "parameters `k_1` and `k[1]` are both the field `k_1` of the parameter struct (an indexed parameter `k[3]` is the field `k_3`): rename one of them"
        ]
    );
    let clash = errors(
        "model P { param k[1] = 1.0; param k_1 = 2.0; dof x; body b { mass = 1.0; inertia = (1, 1, 1); } TOG[b] = Tdisp(x, 0, 0); }",
    );
    assert_eq!(
        clash,
        [
            "parameters `k[1]` and `k_1` are both the field `k_1` of the parameter struct (an indexed parameter `k[3]` is the field `k_3`): rename one of them"
        ]
    );
}

#[test]
fn errors_name_the_instance() {
    let body = |extra: &str| {
        format!(
            "model C {{
            for i in 0..4 {{ dof q[i]; body bar[i] {{ mass = 1.0; inertia = (1, 1, 1); }} }}
            TOG[bar[0]] = Trotz(q[0]);
            {extra}
        }}"
        )
    };
    // one bar short: bar[4] is undeclared at the last iteration
    let e = errors(&body(
        "for i in 1..5 { TOG[bar[i]] = TOG[bar[i-1]] * Trotz(q[i]); }",
    ));
    assert_eq!(
        e[0],
        "unknown body `bar[4]`; `bar[…]` is declared with the indices 0 to 3; in `for i in 1..5`, i = 4",
        "{e:?}"
    );
    // a negative index
    let e = errors(&body(
        "for i in 0..4 { TOG[bar[i]] = TOG[bar[i-1]] * Trotz(q[i]); }",
    ));
    assert!(
        e[0].starts_with("`bar[-1]`: indices start at 0")
            && e[0].ends_with("in `for i in 0..4`, i = 0"),
        "{e:?}"
    );
    // a range that is not a constant integer
    let e = errors(&body(
        "param n = 4.0; for i in 1..n { TOG[bar[i]] = TOG[bar[i-1]] * Trotz(q[i]); }",
    ));
    assert!(
        e[0].starts_with("a loop range must be constant integers: `n` is not a loop variable"),
        "{e:?}"
    );
    // parts: instance number and arguments; an error every instance repeats is reported
    // once, at the first
    let e = errors(
        "model L {
            part Leg(k, x, m) { dof a[k]; body leg[k] { mass = m; inertia = (1, 1, 1); } TOG[leg[k]] = Tdisp(x, 0, 0) * Trotz(a[k]) * Tdisp(y, 0, 0); }
            Leg(0, 0.5, 1.0); Leg(1, -0.5, -2.0); Leg(2, 0, 1.0);
        }",
    );
    assert_eq!(
        e,
        [
            "unknown name `y`; did you mean `t`? (in part Leg, instance 1 (k = 0, x = 0.5, m = 1.0))",
            "the mass of body `leg[1]` must be positive, it is -2: give it a positive mass, or declare a massless `frame leg[1];`; in part Leg, instance 2 (k = 1, x = -0.5, m = -2.0)",
        ]
    );
}

#[test]
fn part_mistakes() {
    let e = errors(
        "model L { part Leg(k) { frame f[k]; TOG[f[k]] = Tdisp(0, 0, k); } Leg(0, 1); Legg(1); }",
    );
    assert!(
        e[0].starts_with("part `Leg` takes 1 argument (k), found 2"),
        "{e:?}"
    );
    assert!(
        e[1].starts_with("unknown part `Legg`; did you mean `Leg`?"),
        "{e:?}"
    );
    // a part without arguments; a part whose declaration is wrong: its instances say nothing
    generate("model L { part Base() { dof x; body b { mass = 1.0; } TOG[b] = Tdisp(x, 0, 0); } Base(); }")
        .expect("a part without arguments");
    let e =
        errors("model L { part Leg(k, 2) { frame f[k]; TOG[f[k]] = Tdisp(0, 0, k); } Leg(0, 1); }");
    assert_eq!(
        e,
        ["the arguments of a part are names: write `part Name(a, b, …) { statements }`"]
    );
}

#[test]
fn nested_parts_name_arguments_and_integer_arithmetic() {
    // a part instantiating another in a loop, a name argument, `/` and `%` on indices
    let parts = "model Legs {
        part Leg(k, mount, side) {
            dof a[k];
            body leg[k] { mass = 1.0; inertia = (0.1, 0.1, 0.1); }
            TOG[leg[k]] = TOG[mount] * Tdisp(0, side * 0.1, 0) * Troty(a[k]) * Tdisp(0, 0, -0.5);
        }
        part Pair(p) {
            frame hip[p];
            TOG[hip[p]] = Tdisp(p, 0, 0);
            for s in 0..2 { Leg(2 * p + s, hip[p], 1 - 2 * s); }
        }
        for p in 0..2 { Pair(p); }
        for i in 0..4 { spring(leg[(i + 1) % 4], hip[i / 2], k = 10.0 + i, l0 = 0.3); }
    }";
    let written = "model Legs {
        frame hip[0];
        TOG[hip[0]] = Tdisp(0, 0, 0);
        dof a[0];
        body leg[0] { mass = 1.0; inertia = (0.1, 0.1, 0.1); }
        TOG[leg[0]] = TOG[hip[0]] * Tdisp(0, 1 * 0.1, 0) * Troty(a[0]) * Tdisp(0, 0, -0.5);
        dof a[1];
        body leg[1] { mass = 1.0; inertia = (0.1, 0.1, 0.1); }
        TOG[leg[1]] = TOG[hip[0]] * Tdisp(0, -1 * 0.1, 0) * Troty(a[1]) * Tdisp(0, 0, -0.5);
        frame hip[1];
        TOG[hip[1]] = Tdisp(1, 0, 0);
        dof a[2];
        body leg[2] { mass = 1.0; inertia = (0.1, 0.1, 0.1); }
        TOG[leg[2]] = TOG[hip[1]] * Tdisp(0, 1 * 0.1, 0) * Troty(a[2]) * Tdisp(0, 0, -0.5);
        dof a[3];
        body leg[3] { mass = 1.0; inertia = (0.1, 0.1, 0.1); }
        TOG[leg[3]] = TOG[hip[1]] * Tdisp(0, -1 * 0.1, 0) * Troty(a[3]) * Tdisp(0, 0, -0.5);
        spring(leg[1], hip[0], k = 10.0 + 0, l0 = 0.3);
        spring(leg[2], hip[0], k = 10.0 + 1, l0 = 0.3);
        spring(leg[3], hip[1], k = 10.0 + 2, l0 = 0.3);
        spring(leg[0], hip[1], k = 10.0 + 3, l0 = 0.3);
    }";
    same(
        &generate(parts).expect("parts"),
        &generate(written).expect("written"),
    );
    // nested instances name every level, outermost first
    let e = errors(
        "model Legs {
            part Leg(k) { dof a[k]; body leg[k] { mass = 1.0 - k; inertia = (0.1, 0.1, 0.1); } TOG[leg[k]] = Troty(a[k]); }
            part Pair(p) { for s in 0..2 { Leg(2 * p + s); } }
            for p in 0..2 { Pair(p); }
        }",
    );
    assert_eq!(e.len(), 3, "{e:?}");
    assert!(
        e[2].ends_with("; in `for p in 0..2`, p = 1; in part Pair, instance 2 (p = 1); in `for s in 0..2`, s = 1; in part Leg, instance 4 (k = 3)"),
        "{e:?}"
    );
    // a part that instantiates itself, a part inside a loop
    let e = errors("model L { part P(k) { P(k + 1); } P(0); for i in 0..2 { part Q(k) { } } }");
    assert!(
        e.iter()
            .any(|m| m.starts_with("a part is declared at model level")),
        "{e:?}"
    );
    assert!(
        e.iter().any(|m| m
            == "part `P` instantiates itself: a part cannot be recursive; repeat its statements with `for` instead"),
        "{e:?}"
    );
    // through another part instantiated twice: reported by each of B's instances, at once
    // (a depth limit let it instantiate itself 16 parts deep first, its instances doubling)
    let e = errors("model L { part A() { B(); B(); } part B() { A(); } A(); }");
    let recursive: Vec<&String> = e
        .iter()
        .filter(|m| m.contains("instantiates itself"))
        .collect();
    assert_eq!(recursive.len(), 2, "{e:?}");
    assert!(
        recursive[0].starts_with("part `A` instantiates itself (through `B`)"),
        "{e:?}"
    );
}

#[test]
fn mistakes_in_the_statements_themselves() {
    let first = |src: &str| errors(src).remove(0);
    let body = "dof x; body b { mass = 1.0; } TOG[b] = Tdisp(x, 0, 0);";
    assert_eq!(
        first(&format!("model L {{ {body} part leg(k) {{ }} }}")),
        "a part's name starts with an uppercase letter, which tells its instances from effects: `part Leg…`"
    );
    assert_eq!(
        first(&format!(
            "model L {{ {body} part P(k) {{ }} part P(j) {{ }} }}"
        )),
        "duplicate part `P`: rename one of the two"
    );
    assert_eq!(
        first(&format!("model L {{ {body} part P(k, k) {{ }} }}")),
        "part `P` has two arguments named `k`: rename one of them"
    );
    assert_eq!(
        first(&format!("model L {{ {body} part P(q) {{ }} }}")),
        "`q` is reserved: give argument 1 of part `P` another name"
    );
    assert_eq!(
        first(&format!("model L {{ {body} for q in 0..2 {{ }} }}")),
        "`q` is reserved: give the loop variable another name"
    );
    assert_eq!(
        first(&format!("model L {{ {body} for i of 0..2 {{ }} }}")),
        "expected `in` after `for i`: write `for i in 0..n { statements }`"
    );
    assert_eq!(
        first(&format!("model L {{ {body} for i in 0.. {{ }} }}")),
        "a loop range needs both ends: write `for i in 0..n { statements }`"
    );
    assert_eq!(
        first(&format!("model L {{ {body} for i in 0..1000000 {{ }} }}")),
        "`for i in 0..1000000` repeats 1000000 times: at most 100000 instances per loop"
    );
    assert_eq!(
        first(&format!(
            "model L {{ {body} for i in 0..2 {{ frame f[i / 0]; }} }}"
        )),
        "the index of `f[…]` must be a constant integer: division by zero; in `for i in 0..2`, i = 0"
    );
    assert_eq!(
        first(&format!("model L {{ {body} frame f[1.5]; }}")),
        "the index of `f[…]` must be a constant integer: `1.5` is not an integer"
    );
    assert_eq!(
        first(&format!(
            "model L {{ {body} for i in 0..2 {{ scene S[i] = []; }} }}"
        )),
        "a scene's name names a type, so `S[0]` cannot be indexed: give it a plain name; in `for i in 0..2`, i = 0"
    );
    // `0..=n` includes n
    let code = generate("model L { for i in 0..=2 { dof x[i]; body b[i] { mass = 1.0; } TOG[b[i]] = Tdisp(x[i], i, 0); } }")
        .expect("closed range");
    assert!(code.contains("\"x[2]\""));
}

#[test]
fn a_loop_that_does_not_expand_is_an_error_of_systems_from_str() {
    let e = mbs_symbolic::systems_from_str(
        "model L { param n = 2.0; dof x; body b { mass = 1.0; } TOG[b] = Tdisp(x, 0, 0); for i in 0..n { frame f[i]; } }",
    )
    .expect_err("an error");
    assert!(e.contains("a loop range must be constant integers"), "{e}");
}

/// A coordinate indexed by integer arithmetic on a loop variable (`q[2*k + 1]`) is that
/// coordinate: an arm whose joints alternate z and y, written in pairs, generates the code of
/// the arm written out; `qd[…]` and `u[…]` take the value as well.
#[test]
fn integer_arithmetic_indexes_coordinates_and_inputs() {
    let looped = "model Arm { param c = 0.1;
        for i in 0..5 { dof q[i] = 0.2; body link[i] { mass = 1.0; inertia = (0.01, 0.02, 0.02); } }
        input f0; input f1;
        TOG[link[0]] = Trotz(q[0]) * Tdisp(0.15, 0, 0);
        for k in 0..2 {
            TOG[link[2*k+1]] = TOG[link[2*k]] * Tdisp(0.3, 0, 0) * Troty(q[2*k+1]);
            TOG[link[2*k+2]] = TOG[link[2*k+1]] * Tdisp(0.3, 0, 0) * Trotz(q[2*k+2]);
            generalized_force(q[2*k+1], u[k] - c * qd[2 * k + 1]);
        }
        gravity(0, 0, -9.81);
    }";
    let mut written = String::from("model Arm { param c = 0.1;\n");
    for i in 0..5 {
        written += &format!(
            "dof q[{i}] = 0.2; body link[{i}] {{ mass = 1.0; inertia = (0.01, 0.02, 0.02); }}\n"
        );
    }
    written += "input f0; input f1;\nTOG[link[0]] = Trotz(q[0]) * Tdisp(0.15, 0, 0);\n";
    for k in 0..2 {
        let (a, b, c) = (2 * k, 2 * k + 1, 2 * k + 2);
        written += &format!(
            "TOG[link[{b}]] = TOG[link[{a}]] * Tdisp(0.3, 0, 0) * Troty(q[{b}]);
             TOG[link[{c}]] = TOG[link[{b}]] * Tdisp(0.3, 0, 0) * Trotz(q[{c}]);
             generalized_force(q[{b}], u[{k}] - c * qd[{b}]);\n"
        );
    }
    written += "gravity(0, 0, -9.81);\n}";
    same(
        &generate(looped).expect("looped"),
        &generate(&written).expect("written"),
    );
}
