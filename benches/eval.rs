//! Evaluation time of generated functions (criterion).
//!
//! ```text
//! cargo bench --bench eval
//! ```
//!
//! At the MODELS.md test state: M+h (`dynamics`), M alone, τ (`inverse_dynamics`), and qdd
//! two ways — the generated `forward_dynamics` (articulated bodies or sparse LᵀDL) against
//! the dense path (M and h, then Cholesky and two triangular solves) — for dpend, arm3d_6,
//! chains of 8 to 30 bars and the hexapod.

mod common;

use common::test_state;
use criterion::{Criterion, criterion_group, criterion_main};
use mbs::Model;
use std::hint::black_box;

use mbs_models::arm3d_6;
use mbs_models::chain8;
use mbs_models::chain16_stiff;
use mbs_models::chain24;
use mbs_models::chain30_stiff;
use mbs_models::dpend;
use mbs_models::hexapod;

fn bench_model<M: Model>(c: &mut Criterion, name: &str, model: M) {
    let n = M::NQ;
    let (q, qd) = test_state(n);
    let qdd = vec![0.1; n];
    let u = vec![0.0; M::NU];
    let mut m = vec![0.0; n * n];
    let mut h = vec![0.0; n];
    let mut g = c.benchmark_group(name);
    g.bench_function("dynamics (M, h)", |b| {
        b.iter(|| model.dynamics(0.0, black_box(&q), black_box(&qd), &u, &mut m, &mut h))
    });
    g.bench_function("qdd dense (M, h, Cholesky, solve)", |b| {
        b.iter(|| {
            model.dynamics(0.0, black_box(&q), black_box(&qd), &u, &mut m, &mut h);
            mbs::linalg::cholesky(&mut m, n).expect("M positive definite");
            mbs::linalg::cholesky_solve(&m, n, &mut h);
        })
    });
    let mut pivots = vec![0.0; n];
    let mut acc = vec![0.0; n];
    g.bench_function("qdd forward_dynamics", |b| {
        b.iter(|| {
            model.forward_dynamics(
                0.0,
                black_box(&q),
                black_box(&qd),
                &u,
                &mut acc,
                &mut pivots,
            )
        })
    });
    g.bench_function("mass_matrix", |b| {
        b.iter(|| model.mass_matrix(0.0, black_box(&q), &mut m))
    });
    g.bench_function("inverse_dynamics", |b| {
        b.iter(|| {
            model.inverse_dynamics(
                0.0,
                black_box(&q),
                black_box(&qd),
                black_box(&qdd),
                &u,
                &mut h,
            )
        })
    });
    g.finish();
}

fn benches(c: &mut Criterion) {
    bench_model(c, "dpend", dpend::DoublePendulum::default());
    bench_model(c, "arm3d_6", arm3d_6::Arm3d6::default());
    bench_model(c, "chain8", chain8::Chain8::default());
    bench_model(c, "chain16", chain16_stiff::Chain16Stiff::default());
    bench_model(c, "chain24", chain24::Chain24::default());
    bench_model(c, "chain30", chain30_stiff::Chain30Stiff::default());
    bench_model(c, "hexapod", hexapod::Hexapod::default());
}

criterion_group!(eval, benches);
criterion_main!(eval);
