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
