//! Tangents written as tables of operations (`option tangents = table;`, which the runtime
//! reads in a loop) against the same tangents as straight-line code (`option tangents =
//! code;`): the same operations in the same order, so the same bits, on a model whose
//! tangents hold every kind of operation the language has (the functions of one argument,
//! integer and real powers, atan2, a contact's one-sided law), at random states. The
//! generated trees of `tests/compiled_trees.rs` check a table's tangents against an
//! independent oracle.

use mbs::Model;

/// The model, with its tangents in the form `$form`: a spatial double pendulum with a
/// contact, a spring and a generalised force of every function.
macro_rules! mixed {
    ($name:ident, $form:ident) => {
        mbs::multibody! {
            pub model $name {
                param m = 1.5; param l = 0.6; param k = 40.0;
                dof a = 0.3, qd = 0.5; dof b = -0.4, qd = 1.0; dof c = 0.2; dof s = 0.1;
                body upper { mass = m; inertia = (0.02, 0.03, 0.04, 0.001, 0.002, 0.003); }
                body lower { mass = m / 2; inertia = (0.01, 0.02, 0.015); }
                body slider { mass = 0.3; inertia = (0.001, 0.001, 0.001); }
                TOG[upper] = Trotz(a) * Troty(b) * Tdisp(l, 0, 0);
                TOG[lower] = TOG[upper] * Trotx(c) * Tdisp(0, -l / 2, 0.1);
                TOG[slider] = TOG[lower] * Tdisp(s, 0, 0);
                point tip on lower at (0, -l / 2, 0);
                gravity(0, 0, -9.81);
                effect ground { contact(tip, k = 1e4, dissipation = 2.0, mu = 0.6, eps = 0.01, exponent = 1.5); }
                effect springs { spring(tip, slider, k = k, l0 = 0.2, c = 0.5); }
                effect laws {
                    generalized_force(a, -sin(a) * cos(b) + tan(0.1 * c) - asin(0.2 * b) * acos(0.3 * c) + atan(qd[0]));
                    generalized_force(b, -sinh(0.5 * b) + cosh(0.2 * c) - tanh(qd[1]) + exp(-a * a) - ln(2 + b * b) * sqrt(1 + powi(c, 2)));
                    generalized_force(c, -abs(c) * sign(qd[2]) - k * pos(c - 0.1) - step(c) + atan2(b, 2 + a) + pow(1.5 + s * s, 1.5) - powi(c, 3) / (1 + powi(a, 4)));
                    generalized_force(s, -k * s - 0.3 * qd[3] * abs(qd[3]));
                }
                option tangents = $form;
            }
        }
    };
}

mixed!(MixedCode, code);
mixed!(MixedTable, table);

/// A small generator of states in [−1, 1).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

#[test]
fn a_table_gives_the_bits_of_straight_line_code() {
    let (code, table) = (MixedCode::default(), MixedTable::default());
    let n = MixedCode::NQ;
    let mut rng = Lcg(7);
    let mut nonzero = 0;
    for _ in 0..50 {
        let mut draw = || (0..n).map(|_| rng.next()).collect::<Vec<f64>>();
        let (q, qd, qdd) = (draw(), draw(), draw());
        // the tip under the ground (z below 0) in some states: the contact's terms too
        let q: Vec<f64> = q.iter().map(|x| 1.5 * x).collect();
        let t = rng.next().abs();
        let out = |m: &dyn Fn(&mut [f64], &mut [f64])| {
            let (mut k, mut c) = (vec![f64::NAN; n * n], vec![f64::NAN; n * n]);
            m(&mut k, &mut c);
            (k, c)
        };
        let (k1, c1) = out(&|k, c| code.tangents(t, &q, &qd, &qdd, &[], k, c).unwrap());
        let (k2, c2) = out(&|k, c| table.tangents(t, &q, &qd, &qdd, &[], k, c).unwrap());
        for (x, y) in k1.iter().chain(&c1).zip(k2.iter().chain(&c2)) {
            assert!(x.is_finite(), "{k1:?}");
            assert_eq!(x.to_bits(), y.to_bits(), "code {x}, table {y}");
            nonzero += usize::from(*x != 0.0);
        }
    }
    // most entries of K and C are not zero: the comparison covers them
    assert!(nonzero > 50 * n * n, "{nonzero} nonzero entries");
}

#[test]
fn a_table_counts_the_operations_of_its_code() {
    let ops = |info: &mbs::ModelInfo| {
        info.ops
            .iter()
            .find(|(f, _)| f.starts_with("tangents"))
            .map(|(_, c)| c.flops())
            .expect("the tangents' op count")
    };
    let (code, table) = (
        ops(MixedCode::default().info()),
        ops(MixedTable::default().info()),
    );
    assert_eq!(code, table);
    assert!(code > 500, "{code} flops");
}

mbs::multibody! {
    /// A planar double pendulum with a law of several functions, its tangents a table: what
    /// `mbs expand` lists of it (`a_listing_computes_the_tangents`).
    pub model Listed {
        param m = 1.2; param l = 0.5; param k = 30.0;
        dof a = 0.3, qd = 0.4; dof b = -0.2;
        body upper { mass = m; inertia = (0, 0.02, 0.02); }
        body lower { mass = m / 2; inertia = (0, 0.01, 0.01); }
        TOG[upper] = Trotz(a) * Tdisp(l, 0, 0);
        TOG[lower] = TOG[upper] * Trotz(b) * Tdisp(l, 0, 0);
        gravity(0, -9.81, 0);
        effect laws {
            generalized_force(b, -k * sin(b) - 0.3 * qd[1] * abs(qd[1]) + atan2(a, 2 + b) - powi(b, 3) / (1 + exp(-a * a)) + pow(1.5 + a * a, 0.7));
        }
        option tangents = table;
    }
}

/// `mbs expand` writes each table's operations below it, one a line, as comments; read back
/// and computed in their order, those lines give the tangents of the compiled model to the bit.
#[test]
fn a_listing_computes_the_tangents() {
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/tangent_tables.rs");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_mbs"))
        .args(["expand", file, "--model", "Listed"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text
        .lines()
        .map(str::trim)
        .skip_while(|l| !l.starts_with("// CODE, one operation a line"))
        .skip(1)
        .take_while(|l| l.starts_with("// "))
        .map(|l| &l[3..])
        .collect();
    assert!(lines.len() > 50, "{} lines listed in\n{text}", lines.len());

    let (q, qd, qdd) = ([0.7, -1.1], [0.4, -0.9], [2.0, -3.0]);
    let p = ListedParams::default();
    let leaf = |name: &str| -> Option<f64> {
        let index = |prefix: &str| name.strip_prefix(prefix)?.parse::<usize>().ok();
        if let Some(i) = index("qdd_") {
            return Some(qdd[i]);
        }
        if let Some(i) = index("qd_") {
            return Some(qd[i]);
        }
        if let Some(i) = index("q_") {
            return Some(q[i]);
        }
        match name {
            "p_m" => Some(p.m),
            "p_l" => Some(p.l),
            "p_k" => Some(p.k),
            _ => None,
        }
    };
    let n = Listed::NQ;
    let (mut k, mut c) = (vec![0.0; n * n], vec![0.0; n * n]);
    let mut slots = std::collections::HashMap::<String, f64>::new();
    let value = |slots: &std::collections::HashMap<String, f64>, x: &str| -> f64 {
        if let Ok(v) = x.parse::<f64>() {
            return v;
        }
        slots
            .get(x)
            .copied()
            .or_else(|| leaf(x))
            .unwrap_or_else(|| panic!("`{x}` read before it is written"))
    };
    for line in &lines {
        let (target, rhs, add) = match line.split_once(" += ") {
            Some((t, r)) => (t, r, true),
            None => {
                let (t, r) = line.split_once(" = ").expect("an assignment");
                (t, r, false)
            }
        };
        let v = |x: &str| value(&slots, x);
        let r = if let Some((f, args)) = rhs.strip_suffix(')').and_then(|r| r.split_once('(')) {
            let a: Vec<&str> = args.split(", ").collect();
            match (f, a.as_slice()) {
                ("powi", [x, e]) => v(x).powi(e.parse().unwrap()),
                ("pow", [x, y]) => v(x).powf(v(y)),
                ("atan2", [x, y]) => v(x).atan2(v(y)),
                ("sin", [x]) => v(x).sin(),
                ("cos", [x]) => v(x).cos(),
                ("exp", [x]) => v(x).exp(),
                ("abs", [x]) => v(x).abs(),
                ("sign", [x]) => {
                    let x = v(x);
                    if x == 0.0 { 0.0 } else { x.signum() }
                }
                other => panic!("no evaluation for {other:?} in `{line}`"),
            }
        } else {
            let t: Vec<&str> = rhs.split(' ').collect();
            match t.as_slice() {
                [x] if x.starts_with('-') && x.parse::<f64>().is_err() => -v(&x[1..]),
                [x] => v(x),
                [x, "+", y] => v(x) + v(y),
                [x, "-", y] => v(x) - v(y),
                [x, "*", y] => v(x) * v(y),
                [x, "/", y] => v(x) / v(y),
                [x, "*", y, "+", z] => v(x) * v(y) + v(z),
                [x, "*", y, "-", z] => v(x) * v(y) - v(z),
                [z, "-", x, "*", y] => v(z) - v(x) * v(y),
                [x, "*", y, "+", z, "*", w] => v(x) * v(y) + v(z) * v(w),
                [x, "*", y, "-", z, "*", w] => v(x) * v(y) - v(z) * v(w),
                other => panic!("no evaluation for {other:?}"),
            }
        };
        if let Some((buffer, i)) = target.strip_suffix(']').and_then(|t| t.split_once('[')) {
            let i: usize = i.parse().unwrap();
            let out = match buffer {
                "k" => &mut k,
                "c" => &mut c,
                other => panic!("no output {other}"),
            };
            if add { out[i] += r } else { out[i] = r }
        } else {
            assert!(!add && target.starts_with('s'), "`{line}`");
            slots.insert(target.to_string(), r);
        }
    }
    let (mut k2, mut c2) = (vec![f64::NAN; n * n], vec![f64::NAN; n * n]);
    Listed::default()
        .tangents(0.0, &q, &qd, &qdd, &[], &mut k2, &mut c2)
        .unwrap();
    for (x, y) in k.iter().chain(&c).zip(k2.iter().chain(&c2)) {
        assert_eq!(
            x.to_bits(),
            y.to_bits(),
            "listing {x}, model {y}\nK {k:?} / {k2:?}\nC {c:?} / {c2:?}"
        );
    }
    assert!(k2.iter().chain(&c2).all(|x| *x != 0.0), "{k2:?} {c2:?}");
}
