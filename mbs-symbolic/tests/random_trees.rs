//! Random 3-D trees: M and h of both formulations (virtual power and recursive) against an
//! independent numeric Newton–Euler / composite-rigid-body oracle, M symmetric positive
//! definite, τ = M qdd − h for both τ's; also centre-of-mass positions, static h and the
//! kinetic and potential energies against the oracle.

mod common;
#[path = "../../tests/common/quoted.rs"]
mod quoted;

use common::*;
use mbs_symbolic::SymbolicModel;
use mbs_symbolic::expr::ExprId;
use mbs_symbolic::mech::effects::Loads;
use mbs_symbolic::mech::forward::{Elimination, Outward, articulated, bias_wrenches, ltdl};
use mbs_symbolic::mech::tree::canonical;

const TREES: u64 = 100;
const STATES: usize = 3;

fn pendulum_link(kind: Kind, axis: V3, drive: Drive, mass: f64, com: V3, i: [f64; 6]) -> Link {
    Link {
        parent: None,
        offset: [0.0; 3],
        fixed: Vec::new(),
        chart: false,
        kind,
        axis,
        drive,
        mass,
        com,
        inertia: i,
    }
}

fn dof_drive(k: usize) -> Drive {
    Drive {
        dof: Some(k),
        scale: 1.0,
        bias: 0.0,
        amp: 0.0,
        omega: 0.0,
        phase: 0.0,
    }
}

/// The oracle against closed forms: a pendulum (also with an imposed oscillation of its
/// angle) and a mass sliding on a spinning arm (Coriolis and centrifugal terms).
#[test]
fn oracle_closed_forms() {
    let (m, l, g, izz) = (1.7, 0.8, 9.81, 0.05);
    let (amp, om, ph) = (0.3, 2.0, 0.4);
    for rheo in [false, true] {
        let mut drive = dof_drive(0);
        if rheo {
            (drive.amp, drive.omega, drive.phase) = (amp, om, ph);
        }
        let desc = Desc {
            links: vec![pendulum_link(
                Kind::Revolute,
                [0.0, 0.0, 1.0],
                drive,
                m,
                [0.0, -l, 0.0],
                [0.02, 0.03, izz, 0.0, 0.0, 0.0],
            )],
            ndof: 1,
            gravity: [0.0, -g, 0.0],
        };
        let o = Oracle::new(&desc);
        for &(th, thd, t) in &[(0.3, 0.0, 0.0), (-1.2, 2.0, 0.7), (2.5, -1.0, 3.1)] {
            let mm = o.crba(&[th], t);
            let h = o.bias(&[th], &[thd], t);
            let inertia = izz + m * l * l;
            let (angle, h_ref) = if rheo {
                let angle = th + amp * (om * t + ph).sin();
                let thdd_rheo = -amp * om * om * (om * t + ph).sin();
                (angle, -m * g * l * angle.sin() - inertia * thdd_rheo)
            } else {
                (th, -m * g * l * th.sin())
            };
            let _ = angle;
            assert!((mm[0][0] - inertia).abs() < 1e-14, "{mm:?}");
            assert!((h[0] - h_ref).abs() < 1e-13, "{h:?} vs {h_ref}");
        }
    }
    // spinning arm (about z) carrying a slider along its x axis; no gravity
    let (i0, m1, i1) = (0.4, 1.3, 0.02);
    let desc = Desc {
        links: vec![
            pendulum_link(
                Kind::Revolute,
                [0.0, 0.0, 1.0],
                dof_drive(0),
                2.0,
                [0.0; 3],
                [0.3, 0.3, i0, 0.0, 0.0, 0.0],
            ),
            Link {
                parent: Some(0),
                ..pendulum_link(
                    Kind::Prismatic,
                    [1.0, 0.0, 0.0],
                    dof_drive(1),
                    m1,
                    [0.0; 3],
                    [0.01, 0.01, i1, 0.0, 0.0, 0.0],
                )
            },
        ],
        ndof: 2,
        gravity: [0.0; 3],
    };
    let o = Oracle::new(&desc);
    let (q, qd) = ([0.4, 0.7], [1.3, -0.6]);
    let (r, rd, thd) = (q[1], qd[1], qd[0]);
    let mm = o.crba(&q, 0.0);
    let h = o.bias(&q, &qd, 0.0);
    let m_ref = [[i0 + i1 + m1 * r * r, 0.0], [0.0, m1]];
    let h_ref = [-2.0 * m1 * r * rd * thd, m1 * r * thd * thd];
    for i in 0..2 {
        assert!((h[i] - h_ref[i]).abs() < 1e-14, "{h:?} vs {h_ref:?}");
        for j in 0..2 {
            assert!((mm[i][j] - m_ref[i][j]).abs() < 1e-14, "{mm:?}");
        }
    }
}

/// The oracle against the reference double pendulum of `reference_eval.rs`.
#[test]
fn oracle_matches_reference_double_pendulum() {
    let (l, m) = (1.0, 1.0);
    let i = [m * l * l / 12.0, 0.0, m * l * l / 12.0, 0.0, 0.0, 0.0];
    let bar = |parent, offset| Link {
        parent,
        offset,
        ..pendulum_link(
            Kind::Revolute,
            [0.0, 0.0, 1.0],
            dof_drive(0),
            m,
            [0.0, -l / 2.0, 0.0],
            i,
        )
    };
    let mut b2 = bar(Some(0), [0.0, -l, 0.0]);
    b2.drive = dof_drive(1);
    let desc = Desc {
        links: vec![bar(None, [0.0; 3]), b2],
        ndof: 2,
        gravity: [0.0, -9.81, 0.0],
    };
    let q: Vec<f64> = (0..2).map(|i| 0.5 * (1.3 * i as f64 + 0.4).sin()).collect();
    let qd: Vec<f64> = (0..2).map(|i| 0.7 * (0.9 * i as f64 + 0.2).cos()).collect();
    let m_ref = [
        [2.546239652854929, 0.7731198264274626],
        [0.7731198264274626, 0.333333333333333],
    ];
    let f_ref = [-5.843720128970542, -3.236224706838456];
    let o = Oracle::new(&desc);
    let mm = o.crba(&q, 0.0);
    let h = o.bias(&q, &qd, 0.0);
    for r in 0..2 {
        assert!((h[r] - f_ref[r]).abs() < 1e-12, "{h:?}");
        for c in 0..2 {
            assert!((mm[r][c] - m_ref[r][c]).abs() < 1e-12, "{mm:?}");
        }
    }
}

fn flat(m: &[Vec<ExprId>]) -> Vec<ExprId> {
    m.iter().flatten().copied().collect()
}

fn square(v: &[f64], n: usize) -> Vec<Vec<f64>> {
    v.chunks(n).map(|r| r.to_vec()).collect()
}

/// The worst errors of the generated equations against the oracle over many trees.
#[derive(Default)]
struct Checks {
    m_vp: Worst,
    m_rec: Worst,
    h_vp: Worst,
    h_rec: Worst,
    vp_rec: Worst,
    tau_rec: Worst,
    tau_vp: Worst,
    sym: Worst,
    pos: Worst,
    static_h: Worst,
    energy: Worst,
    /// qdd by articulated bodies and by sparse LᵀDL against the oracle's dense solve
    fwd_aba: Worst,
    fwd_ltdl: Worst,
    /// Π pivots against det M
    pivots: Worst,
    /// trees whose coordinates each move one node (articulated bodies apply)
    articulated: usize,
    /// errors are relative to the largest entry of the reference, or to this when larger
    /// (0: no floor)
    floor: f64,
}

impl Checks {
    /// Builds the system of `desc` (drawing how it is written from `rng`) and compares it
    /// with the oracle at `STATES` random states.
    fn tree(&mut self, seed: u64, desc: &Desc, rng: &mut Rng) {
        let n = desc.ndof;
        let floor = self.floor;
        let rel = |x: &[f64], r: &[f64]| {
            if floor > 0.0 {
                rel_err_floor(x, r, floor)
            } else {
                rel_err(x, r)
            }
        };
        let oracle = Oracle::new(desc);
        let built = to_system(desc, rng);
        let bodies = built.body.clone();
        let charts = built.charts.clone();
        let mut model = SymbolicModel::build(built.sys);
        let (m_sym, h_sym) = {
            let mb = model.scenes[0].chosen();
            (mb.m.clone(), mb.h.clone())
        };
        // articulated bodies in both places of elimination, applied to h and to the bodies'
        // wrenches of Newton–Euler, their outward pass as built and in ready order
        let effects = model.scenes[0].effects.clone();
        let loads = Loads::build(&mut model.sys, &model.tree, &model.world, &effects);
        let (direct, bias) = bias_wrenches(&mut model.sys, &model.tree, &model.world, &loads);
        let mut aba = Vec::new();
        for (rhs, bias) in [(&h_sym, None), (&direct, Some(&bias[..]))] {
            for e in [Elimination::ParentAxes, Elimination::ChildAxes] {
                for o in [Outward::AsBuilt, Outward::ReadyFirst] {
                    aba.extend(articulated(&mut model.sys, &model.tree, rhs, bias, e, o));
                }
            }
        }
        let sparse = ltdl(&mut model.sys.arena, &m_sym, &h_sym);
        self.articulated += !aba.is_empty() as usize;
        let mut forward = Vec::new();
        for f in aba.iter().chain([&sparse]) {
            forward.extend(f.roots());
        }
        let eq = &model.scenes[0];
        let mut roots = Vec::new();
        let vp = eq
            .vp
            .as_ref()
            .expect("random trees are small enough for virtual power");
        roots.extend(flat(&vp.m));
        roots.extend(&vp.h);
        roots.extend(flat(&eq.rec.m));
        roots.extend(&eq.rec.h);
        roots.extend(&eq.tau_rec);
        roots.extend(eq.tau_vp.as_ref().expect("built with vp"));
        roots.extend(&eq.static_h);
        roots.extend([eq.kinetic, eq.potential]);
        for &b in &bodies {
            roots.extend(model.world.nodes[model.tree.frame_node[b]].p);
        }
        roots.extend(&forward);
        for s in 0..STATES {
            let (t, q, qd, qdd) = random_state(rng, n);
            let v = eval_charts(&model, &roots, (t, &q, &qd, &qdd), &charts);
            let mut it = 0;
            let mut take = |k: usize| {
                let s = v[it..it + k].to_vec();
                it += k;
                s
            };
            let (m_vp, h_vp) = (take(n * n), take(n));
            let (m_rec, h_rec) = (take(n * n), take(n));
            let (tau_rec, tau_vp) = (take(n), take(n));
            let static_h = take(n);
            let energy = take(2);
            let pos = take(3 * bodies.len());
            let aba_v: Vec<_> = aba.iter().map(|_| (take(n), take(n))).collect();
            let ltdl_v = (take(n), take(n));
            let at = || format!("seed {seed}, state {s}, {n} dof");
            let m_ref = oracle.crba(&q, t);
            let m_flat: Vec<f64> = m_ref.iter().flatten().copied().collect();
            let h_ref = oracle.bias(&q, &qd, t);
            let tau_ref = oracle.rnea(&q, &qd, &qdd, t, true);
            self.m_vp.see(rel(&m_vp, &m_flat), at);
            self.m_rec.see(rel(&m_rec, &m_flat), at);
            self.h_vp.see(rel(&h_vp, &h_ref), at);
            self.h_rec.see(rel(&h_rec, &h_ref), at);
            self.vp_rec
                .see(rel(&m_vp, &m_rec).max(rel(&h_vp, &h_rec)), at);
            // τ at random qdd equals M qdd − h (of the oracle and of the same formulation)
            for (tau, m, h, w) in [
                (&tau_rec, &m_rec, &h_rec, &mut self.tau_rec),
                (&tau_vp, &m_vp, &h_vp, &mut self.tau_vp),
            ] {
                let mq = mat_vec(&square(m, n), &qdd);
                let own: Vec<f64> = mq.iter().zip(h).map(|(a, b)| a - b).collect();
                w.see(rel(tau, &tau_ref).max(rel(tau, &own)), at);
            }
            // symmetric positive definite
            for m in [&m_vp, &m_rec] {
                let mm = square(m, n);
                let scale = m.iter().fold(0.0f64, |a, b| a.max(b.abs()));
                let asym = (0..n)
                    .flat_map(|i| (0..n).map(move |j| (i, j)))
                    .fold(0.0f64, |a, (i, j)| a.max((mm[i][j] - mm[j][i]).abs()));
                self.sym.see(asym / scale, at);
                assert!(
                    cholesky(&mm).is_some(),
                    "M not positive definite at {}",
                    at()
                );
            }
            let g_ref: Vec<f64> = oracle.com_positions(&q, t).concat();
            self.pos.see(rel(&pos, &g_ref), at);
            let zero = vec![0.0; n];
            self.static_h
                .see(rel(&static_h, &oracle.bias(&q, &zero, t)), at);
            let e_ref = [oracle.kinetic(&q, &qd, t), oracle.potential(&q, t)];
            self.energy.see(rel(&energy, &e_ref), at);
            // forward dynamics: qdd against the dense solve, Π pivots against det M
            let qdd_ref = solve_spd(&m_ref, &h_ref);
            let l = cholesky(&m_ref).expect("M positive definite");
            let log_det: f64 = (0..n).map(|i| 2.0 * l[i][i].ln()).sum();
            let forms = aba_v.iter().map(|v| (v, 0)).chain([(&ltdl_v, 1)]);
            for ((qdd_f, pivots), form) in forms {
                let w = if form == 0 {
                    &mut self.fwd_aba
                } else {
                    &mut self.fwd_ltdl
                };
                w.see(rel(qdd_f, &qdd_ref), at);
                let log_prod: f64 = pivots.iter().map(|p| p.ln()).sum();
                self.pivots.see((log_prod - log_det).abs(), at);
            }
        }
    }

    /// Prints and asserts the bounds.
    fn check(&self) {
        // relative to the largest entry; the README quotes these bounds and the worst
        // measured, checked below
        self.pos.check("centre-of-mass positions vs oracle", 1e-14);
        self.m_vp.check("M virtual power vs oracle", 1e-14);
        self.m_rec.check("M recursive vs oracle", 1e-14);
        self.h_vp.check("h virtual power vs oracle", 1e-13);
        self.h_rec.check("h recursive vs oracle", 1e-13);
        self.vp_rec.check("M, h virtual power vs recursive", 1e-13);
        self.tau_rec.check("tau_rec vs oracle and M qdd - h", 1e-13);
        self.tau_vp.check("tau_vp vs oracle and M qdd - h", 1e-13);
        self.sym.check("M symmetry", 1e-14);
        self.static_h.check("static h (qd = 0) vs oracle", 1e-13);
        self.energy
            .check("kinetic and potential energy vs oracle", 1e-13);
        self.fwd_aba.check(
            "forward dynamics, articulated bodies, vs dense solve",
            1e-12,
        );
        self.fwd_ltdl
            .check("forward dynamics, sparse LTDL, vs dense solve", 1e-12);
        self.pivots
            .check("log of the product of pivots vs log det M", 1e-12);
    }

    /// The worst relative errors of M and positions, and of h, τ and energies.
    fn worst_m_h(&self) -> (f64, f64) {
        let worst = |w: &[&Worst]| w.iter().map(|w| w.err).fold(0.0, f64::max);
        let m = worst(&[&self.pos, &self.m_vp, &self.m_rec]);
        let h = worst(&[
            &self.h_vp,
            &self.h_rec,
            &self.vp_rec,
            &self.tau_rec,
            &self.tau_vp,
            &self.static_h,
            &self.energy,
        ]);
        (m, h)
    }
}

const OPTS: GenOpts = GenOpts {
    min_dof: 1,
    max_dof: 12,
    rheonomic: true,
    gravity: true,
};

#[test]
fn random_trees_match_oracle() {
    let mut checks = Checks::default();
    let (mut branching, mut prismatic, mut revolute, mut rheonomic, mut driven, mut coupled) =
        (0, 0, 0, 0, 0, 0);
    let mut charts = 0;
    let mut max_dof = 0;
    let mut dof_hist = [0usize; 13];
    for seed in 0..TREES {
        let mut rng = Rng::new(seed);
        let desc = random_desc(&mut rng, OPTS);
        let n = desc.ndof;
        max_dof = max_dof.max(n);
        dof_hist[n] += 1;
        branching += desc.branching() as usize;
        for l in &desc.links {
            match l.kind {
                Kind::Prismatic => prismatic += 1,
                Kind::Revolute => revolute += 1,
            }
            rheonomic += l.drive.rheonomic() as usize;
            driven += l.drive.dof.is_none() as usize;
            charts += l.chart as usize;
        }
        let mut used = vec![0; n];
        for l in &desc.links {
            if let Some(k) = l.drive.dof {
                used[k] += 1;
            }
        }
        coupled += used.iter().any(|&u| u > 1) as usize;
        checks.tree(seed, &desc, &mut rng);
    }
    println!(
        "{TREES} trees x {STATES} states; dof histogram {dof_hist:?}; {branching} branching; \
         {revolute} revolute, {prismatic} prismatic joints; {rheonomic} rheonomic, {driven} \
         purely time-driven; {coupled} trees with a coordinate driving two joints; {charts} \
         fixed rotations read from charts at run time"
    );
    checks.check();
    let (m, h) = checks.worst_m_h();
    quoted::says(
        "../README.md",
        &[format!(
            "on 100 random trees M matches an independent numeric Newton–Euler to 1e-14, h, τ and energies to 1e-13 (asserted in `mbs-symbolic/tests/random_trees.rs`; worst measured {m:.1e} and {h:.1e})"
        )],
    );
    println!(
        "{} of {TREES} trees solved by articulated bodies too",
        checks.articulated
    );
    // the others have a coordinate that moves two nodes: one driving two joints, or a joint
    // written in two products that part before it (sparse LTDL serves them)
    assert!(checks.articulated >= 40, "{} trees", checks.articulated);
    assert_eq!(max_dof, 12);
    assert!(
        branching >= TREES as usize / 2,
        "{branching} branching trees"
    );
    assert!(prismatic > 20 && revolute > 20 && rheonomic > 20 && driven > 10 && coupled > 3);
    assert!(charts > 50, "{charts} charts");
}

/// Translations along a revolute joint's axis — the centre of mass on the axis, a child's
/// offset along its parent's axis — are the products the tree reorders (the translation moves
/// in front of the rotation, `mech::tree::canonical`), siblings then part at the rotation
/// they shared; the equations must still match the oracle.
#[test]
fn translations_along_joint_axes_match_oracle() {
    // h vanishes in some of these trees (a single joint with its centre of mass on its axis):
    // errors relative to the largest entry or to 1 (entries are of order 1 to 10)
    let mut checks = Checks {
        floor: 1.0,
        ..Checks::default()
    };
    let mut reordered = 0;
    for seed in 0..40 {
        let mut rng = Rng::new(seed);
        let mut desc = random_desc(&mut rng, OPTS);
        let mut along = Rng::new(1000 + seed);
        let joints: Vec<(Kind, [f64; 3])> = desc.links.iter().map(|l| (l.kind, l.axis)).collect();
        for l in desc.links.iter_mut() {
            if l.kind == Kind::Revolute && along.chance(0.6) {
                l.com = scale(along.range(-0.4, 0.4), l.axis);
            }
            if let Some((Kind::Revolute, axis)) = l.parent.map(|p| joints[p]) {
                if along.chance(0.6) {
                    l.offset = scale(along.range(-0.5, 0.5), axis);
                }
            }
        }
        // the same draws as `checks.tree` makes below
        let mut same = Rng::new(seed);
        random_desc(&mut same, OPTS);
        let mut sys = to_system(&desc, &mut same).sys;
        for f in 0..sys.frames.len() {
            let factors = sys.frames[f].factors.clone();
            reordered += (canonical(&factors, &mut sys.arena) != factors) as usize;
        }
        checks.tree(seed, &desc, &mut rng);
    }
    checks.check();
    println!("{reordered} products reordered");
    assert!(reordered > 40, "{reordered} products reordered");
}
