//! Derivatives of the generated expressions against central finite differences of the
//! generated expressions themselves, on random trees with rheonomic joints and points:
//! - the tangents K = ∂τ/∂q and C = ∂τ/∂qd, with and without loads (springs, dampers,
//!   forces, torques, generalised forces);
//! - the Jacobians J_v of frames and points (d position / dq) and J_ω of frames (ω̂ = Ṙ Rᵀ);
//! - the full velocities v, ω and the bias accelerations a_b, α_b of frames and the bias
//!   of points (d velocity / dt along the motion at qdd = 0: q + ε qd, t + ε, qd fixed).

mod common;

use common::*;
use mbs_symbolic::SymbolicModel;
use mbs_symbolic::expr::ExprId;
use mbs_symbolic::mech::system::Factor;
use mbs_symbolic::mech::world::{Cols, dense};

/// Relative step of the central differences.
const STEP: f64 = 1e-6;

fn opts(max_dof: usize) -> GenOpts {
    GenOpts {
        min_dof: 2,
        max_dof,
        rheonomic: true,
        gravity: true,
    }
}

/// Central difference of `f` along the coordinate direction `j` (t fixed).
fn fd_q(f: &dyn Fn(&[f64]) -> Vec<f64>, q: &[f64], j: usize) -> Vec<f64> {
    let h = STEP * q[j].abs().max(1.0);
    let (mut qp, mut qm) = (q.to_vec(), q.to_vec());
    qp[j] += h;
    qm[j] -= h;
    let (a, b) = (f(&qp), f(&qm));
    a.iter().zip(&b).map(|(x, y)| (x - y) / (2.0 * h)).collect()
}

#[test]
fn tangents_match_finite_differences() {
    let mut wk = Worst::default();
    let mut wc = Worst::default();
    let mut trees = 0;
    for seed in 0..16u64 {
        let mut rng = Rng::new(1000 + seed);
        let desc = random_desc(&mut rng, opts(if seed < 12 { 6 } else { 12 }));
        let n = desc.ndof;
        let mut built = to_system(&desc, &mut rng);
        let charts = built.charts.clone();
        if seed % 2 == 1 {
            add_loads(&mut rng, &mut built.sys, n, &mut [0; 7]);
        }
        built.sys.options.tangents = true;
        let model = SymbolicModel::build(built.sys);
        trees += 1;
        let eq = &model.scenes[0];
        let (k, c) = eq.tangents.as_ref().expect("tangents asked for");
        let tau = eq.tau().to_vec();
        let kc: Vec<ExprId> = k.iter().chain(c).flatten().copied().collect();
        for s in 0..2 {
            let (t, q, qd, qdd) = random_state(&mut rng, n);
            let exact = eval_charts(&model, &kc, (t, &q, &qd, &qdd), &charts);
            let (k_ex, c_ex) = exact.split_at(n * n);
            // columns j of the finite differences, stored row-major
            let mut k_fd = vec![0.0; n * n];
            let mut c_fd = vec![0.0; n * n];
            for j in 0..n {
                let dq = fd_q(
                    &|x| eval_charts(&model, &tau, (t, x, &qd, &qdd), &charts),
                    &q,
                    j,
                );
                let dqd = fd_q(
                    &|x| eval_charts(&model, &tau, (t, &q, x, &qdd), &charts),
                    &qd,
                    j,
                );
                for i in 0..n {
                    k_fd[i * n + j] = dq[i];
                    c_fd[i * n + j] = dqd[i];
                }
            }
            // normalised by the largest entry, floored at 1 % of |τ| (per unit of q or qd):
            // some trees have K or C ≈ 0, where the differences are pure round-off
            let tau0 = eval_charts(&model, &tau, (t, &q, &qd, &qdd), &charts);
            let floor = 1e-2 * tau0.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let at = || format!("seed {}, state {s}, {n} dof", 1000 + seed);
            wk.see(rel_err_floor(k_ex, &k_fd, floor), at);
            wc.see(rel_err_floor(c_ex, &c_fd, floor), at);
        }
    }
    println!("{trees} trees x 2 states");
    wk.check("K = dtau/dq vs central differences", 1e-6);
    wc.check("C = dtau/dqd vs central differences", 1e-6);
}

/// Roots of one frame's kinematics, in a fixed layout.
struct FrameRoots {
    p: usize,
    r: usize,
    jv: usize,
    jw: usize,
    w: usize,
    v: usize,
    alb: usize,
    ab: usize,
}

struct PointRoots {
    pos: usize,
    vel: usize,
    jac: usize,
    bias: usize,
}

fn push(roots: &mut Vec<ExprId>, x: &[ExprId]) -> usize {
    roots.extend_from_slice(x);
    roots.len() - x.len()
}

fn push_cols(roots: &mut Vec<ExprId>, model: &SymbolicModel, c: &Cols, n: usize) -> usize {
    let d: Vec<ExprId> = dense(&model.sys.arena, c, n).concat();
    push(roots, &d)
}

/// ω from Ṙ and R (row-major 3×3 each): the axial vector of Ṙ Rᵀ.
fn omega(rdot: &[f64], r: &[f64]) -> V3 {
    let mut w = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            w[i][j] = (0..3).map(|k| rdot[3 * i + k] * r[3 * j + k]).sum();
        }
    }
    [
        0.5 * (w[2][1] - w[1][2]),
        0.5 * (w[0][2] - w[2][0]),
        0.5 * (w[1][0] - w[0][1]),
    ]
}

/// Per-quantity accumulation: every frame's error normalised by its own scale, floored at
/// 1 % of the largest value of that quantity in the tree.
#[derive(Default)]
struct Acc {
    pairs: Vec<(Vec<f64>, Vec<f64>)>,
}

impl Acc {
    fn add(&mut self, x: &[f64], r: &[f64]) {
        self.pairs.push((x.to_vec(), r.to_vec()));
    }

    fn err(&self) -> f64 {
        let global = self
            .pairs
            .iter()
            .flat_map(|(_, r)| r.iter())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        self.pairs
            .iter()
            .map(|(x, r)| rel_err_floor(x, r, 1e-2 * global))
            .fold(0.0, f64::max)
    }
}

#[test]
fn jacobians_velocities_and_bias_match_finite_differences() {
    let names = [
        "frame J_v",
        "frame J_w",
        "frame v",
        "frame w",
        "frame a_b",
        "frame alpha_b",
        "point J",
        "point velocity",
        "point bias",
    ];
    let mut worst: Vec<Worst> = names.iter().map(|_| Worst::default()).collect();
    let (mut nframes, mut npoints, mut ntrees) = (0, 0, 0);
    for seed in 0..20u64 {
        let mut rng = Rng::new(2000 + seed);
        let desc = random_desc(&mut rng, opts(8));
        let n = desc.ndof;
        let mut built = to_system(&desc, &mut rng);
        let sys = &mut built.sys;
        // extra massless frames, one of them moved by an imposed rotation
        for (e, &b) in built.body.clone().iter().enumerate().take(3) {
            let mut f = vec![sys.disp(rng.vec(0.5))];
            let angle = if e == 0 {
                let t = sys.t();
                let wt = sys.arena.scale(rng.range(0.5, 2.0), t);
                let s = sys.arena.sin(wt);
                sys.arena.scale(0.7, s)
            } else {
                sys.num(rng.range(-3.0, 3.0))
            };
            f.push(sys.rot(rng.unit(), angle));
            let q0 = sys.q(0);
            let sq = sys.arena.sin(q0);
            let d = [sq, sys.num(0.1), q0];
            f.push(Factor::Disp(d));
            sys.frame(&format!("S{e}"), Some(b), f, None);
        }
        // points on every frame and on the ground
        for fr in 0..sys.frames.len() {
            let pos = rng.vec(0.5);
            let pos = sys.vec3(pos);
            sys.point(&format!("P{fr}"), Some(fr), pos);
        }
        let pos = sys.vec3([0.1, 0.2, 0.3]);
        sys.point("Pg", None, pos);
        let model = SymbolicModel::build(built.sys);
        ntrees += 1;
        let mut roots = Vec::new();
        let frames: Vec<FrameRoots> = (0..model.sys.frames.len())
            .map(|f| {
                let k = model.world.nodes[model.tree.frame_node[f]].clone();
                FrameRoots {
                    p: push(&mut roots, &k.p),
                    r: push(&mut roots, &k.r.concat()),
                    jv: push_cols(&mut roots, &model, &k.jv, n),
                    jw: push_cols(&mut roots, &model, &k.jw, n),
                    w: push(&mut roots, &k.w),
                    v: push(&mut roots, &k.v),
                    alb: push(&mut roots, &k.alb),
                    ab: push(&mut roots, &k.ab),
                }
            })
            .collect();
        let points: Vec<PointRoots> = model
            .points
            .iter()
            .map(|p| PointRoots {
                pos: push(&mut roots, &p.position),
                vel: push(&mut roots, &p.velocity),
                jac: push_cols(&mut roots, &model, &p.jacobian, n),
                bias: push(&mut roots, &p.bias),
            })
            .collect();
        nframes += frames.len();
        npoints += points.len();
        for s in 0..2 {
            let (t, q, qd, _) = random_state(&mut rng, n);
            let z = vec![0.0; n];
            let at_q = |x: &[f64]| eval(&model, &roots, t, x, &qd, &z);
            let v0 = at_q(&q);
            // along the motion at qdd = 0
            let eps = STEP;
            let shifted = |sign: f64| {
                let qs: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a + sign * eps * b).collect();
                eval(&model, &roots, t + sign * eps, &qs, &qd, &z)
            };
            let (vp, vm) = (shifted(1.0), shifted(-1.0));
            let dt: Vec<f64> = vp
                .iter()
                .zip(&vm)
                .map(|(a, b)| (a - b) / (2.0 * eps))
                .collect();
            let dq: Vec<Vec<f64>> = (0..n).map(|j| fd_q(&at_q, &q, j)).collect();
            let mut acc: Vec<Acc> = names.iter().map(|_| Acc::default()).collect();
            let sl = |v: &[f64], o: usize, k: usize| v[o..o + k].to_vec();
            for f in &frames {
                let r = sl(&v0, f.r, 9);
                for (j, dqj) in dq.iter().enumerate() {
                    acc[0].add(&sl(&v0, f.jv + 3 * j, 3), &sl(dqj, f.p, 3));
                    acc[1].add(&sl(&v0, f.jw + 3 * j, 3), &omega(&sl(dqj, f.r, 9), &r));
                }
                acc[2].add(&sl(&v0, f.v, 3), &sl(&dt, f.p, 3));
                acc[3].add(&sl(&v0, f.w, 3), &omega(&sl(&dt, f.r, 9), &r));
                acc[4].add(&sl(&v0, f.ab, 3), &sl(&dt, f.v, 3));
                acc[5].add(&sl(&v0, f.alb, 3), &sl(&dt, f.w, 3));
            }
            for p in &points {
                for (j, dqj) in dq.iter().enumerate() {
                    acc[6].add(&sl(&v0, p.jac + 3 * j, 3), &sl(dqj, p.pos, 3));
                }
                acc[7].add(&sl(&v0, p.vel, 3), &sl(&dt, p.pos, 3));
                acc[8].add(&sl(&v0, p.bias, 3), &sl(&dt, p.vel, 3));
            }
            for (w, a) in worst.iter_mut().zip(&acc) {
                w.see(a.err(), || {
                    format!("seed {}, state {s}, {n} dof", 2000 + seed)
                });
            }
        }
    }
    println!("{ntrees} trees x 2 states, {nframes} frames, {npoints} points");
    for (w, name) in worst.iter().zip(names) {
        w.check(&format!("{name} vs central differences"), 1e-6);
    }
}
