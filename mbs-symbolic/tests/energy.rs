//! Energy balance on random scleronomic trees with gravity, springs (with preloads), dampers,
//! forces, torques and generalised forces, and then also with penalty contacts (points and
//! spheres, with friction), bushings and rotational springs: along the motion qdd = M⁻¹ h, the exact time
//! derivative of the generated T + V equals the generated power of the non-conservative
//! effects. The energy balance cannot see a load that is wrong but consistently so in h and
//! in the power (a reaction torque's sign, a force's axes), so h with every load is also
//! checked against the independent oracle, which applies the loads to its own kinematics.

mod common;

use common::*;
use mbs_symbolic::SymbolicModel;
use mbs_symbolic::expr::ExprId;
use mbs_symbolic::mech::effects::Loads;
use mbs_symbolic::mech::forward::{Elimination, Outward, articulated, bias_wrenches};
use mbs_symbolic::mech::system::{Attach, Load};

const TREES: u64 = 40;
const STATES: usize = 3;

/// Generalised forces h(q, qd, t) of a scene by the oracle: the loads' values (expressions of
/// q and qd) are evaluated, then applied as external spatial forces on the oracle's links.
/// `state` is (t, q, qd).
fn oracle_h(
    model: &SymbolicModel,
    oracle: &Oracle,
    frame_link: &[(usize, V3)],
    effects: &[usize],
    state: (f64, &[f64], &[f64]),
    charts: &[f64],
    regimes: &mut [usize; 3],
) -> Vec<f64> {
    let (t, q, qd) = state;
    let poses = oracle.link_poses(q, t);
    let vels = oracle.link_velocities(q, qd, t);
    let mut ext = vec![[0.0; 6]; poses.len()];
    let mut qgen = vec![0.0; q.len()];
    let ev = |e: &[ExprId]| eval_charts(model, e, (t, q, qd, &[]), charts);
    let ev3 = |e: &[ExprId; 3]| {
        let v = ev(e);
        [v[0], v[1], v[2]]
    };
    // world position and velocity of an attachment, and (link, position in link frame)
    let point = |at: &Attach| -> (V3, V3, Option<(usize, V3)>) {
        let r = ev3(&at.pos);
        match at.frame {
            None => (r, [0.0; 3], None),
            Some(f) => {
                let (l, off) = frame_link[f];
                let rl = add(off, r);
                let (rot, o) = poses[l];
                let v = vels[l];
                let (w, vo) = ([v[0], v[1], v[2]], [v[3], v[4], v[5]]);
                let vel = mv(&rot, add(vo, cross(w, rl)));
                (add(o, mv(&rot, rl)), vel, Some((l, rl)))
            }
        }
    };
    let force = |ext: &mut Vec<V6>, at: Option<(usize, V3)>, fw: V3| {
        if let Some((l, rl)) = at {
            let fl = mv(&tr(&poses[l].0), fw);
            let m = cross(rl, fl);
            let x = [m[0], m[1], m[2], fl[0], fl[1], fl[2]];
            for k in 0..6 {
                ext[l][k] += x[k];
            }
        }
    };
    let torque = |ext: &mut Vec<V6>, frame: Option<usize>, tw: V3| {
        if let Some(f) = frame {
            let l = frame_link[f].0;
            let tl = mv(&tr(&poses[l].0), tw);
            for k in 0..3 {
                ext[l][k] += tl[k];
            }
        }
    };
    let axes = |frame: Option<usize>, v: V3| match frame {
        Some(f) => mv(&poses[frame_link[f].0].0, v),
        None => v,
    };
    for &e in effects {
        for load in &model.sys.effects[e].loads {
            match load {
                Load::Gravity(_) => {}
                Load::Spring {
                    a,
                    b,
                    k,
                    l0,
                    axis,
                    preload,
                } => {
                    let (pa, _, la) = point(a);
                    let (pb, _, lb) = point(b);
                    let d = sub(pb, pa);
                    let kv = ev(&[*k, *l0, *preload]);
                    // tension F0 + k (l − l0), along the line of the ends, or a fixed axis
                    // (signed length)
                    let f = match axis {
                        None => scale((kv[2] + kv[0] * (norm(d) - kv[1])) / norm(d), d),
                        Some(n) => {
                            let n = ev3(n);
                            scale(kv[2] + kv[0] * (dot(n, d) - kv[1]), n)
                        }
                    };
                    force(&mut ext, la, f);
                    force(&mut ext, lb, scale(-1.0, f));
                }
                Load::Damper { a, b, c, axis } => {
                    let (pa, va, la) = point(a);
                    let (pb, vb, lb) = point(b);
                    let d = sub(pb, pa);
                    let e = match axis {
                        None => scale(1.0 / norm(d), d),
                        Some(n) => ev3(n),
                    };
                    let f = scale(ev(&[*c])[0] * dot(e, sub(vb, va)), e);
                    force(&mut ext, la, f);
                    force(&mut ext, lb, scale(-1.0, f));
                }
                Load::Force {
                    at,
                    force: f,
                    frame,
                } => {
                    let (_, _, la) = point(at);
                    force(&mut ext, la, axes(*frame, ev3(f)));
                }
                Load::Torque {
                    on,
                    torque: tq,
                    frame,
                    reaction,
                } => {
                    let tw = axes(*frame, ev3(tq));
                    torque(&mut ext, *on, tw);
                    if let Some(r) = reaction {
                        torque(&mut ext, *r, scale(-1.0, tw));
                    }
                }
                Load::GenForce { dof, value } => qgen[*dof] += ev(&[*value])[0],
                Load::Contact {
                    at,
                    radius,
                    ellipsoid,
                    exponent,
                    dissipation,
                    normal,
                    offset,
                    k,
                    c,
                    mu,
                    eps,
                } => {
                    let (x, v, la) = point(at);
                    let (l, rl) = la.expect("contacts are on bodies");
                    let n = ev3(normal);
                    let p = ev(&[*radius, *offset, *k, *c, *mu, *eps, *exponent, *dissipation]);
                    let (r, h0, k, c, mu, eps) = (p[0], p[1], p[2], p[3], p[4], p[5]);
                    let (e, d) = (p[6], p[7]);
                    let rot = poses[l].0;
                    let wl = [vels[l][0], vels[l][1], vels[l][2]];
                    let w = mv(&rot, wl);
                    // the point where the forces act, relative to x (world), its velocity and
                    // the penetration: an ellipsoid's support point along −n, in closed form
                    // from the link's axes, or the sphere's lowest point x − r n
                    let (arm, vc, delta) = match ellipsoid {
                        Some(axes) => {
                            let ax = ev3(axes);
                            let m = mv(&tr(&rot), n);
                            let u = [
                                ax[0] * ax[0] * m[0],
                                ax[1] * ax[1] * m[1],
                                ax[2] * ax[2] * m[2],
                            ];
                            let s = dot(m, u).sqrt();
                            let arm = mv(&rot, scale(-1.0 / s, u));
                            (arm, add(v, cross(w, arm)), h0 - dot(n, x) + s)
                        }
                        None => {
                            let arm = scale(-r, n);
                            (arm, add(v, cross(w, arm)), h0 + r - dot(n, x))
                        }
                    };
                    // n·v of the contact point (for an ellipsoid it is −δ̇; for a sphere, n·v
                    // of its centre)
                    let nv = dot(n, vc);
                    let raw = k * delta.max(0.0).powf(e) * (1.0 - d * nv) - c * nv;
                    regimes[if delta <= 0.0 {
                        0
                    } else if raw > 0.0 {
                        1
                    } else {
                        2
                    }] += 1;
                    let f_n = if delta > 0.0 { raw.max(0.0) } else { 0.0 };
                    // the force acts at the contact point, a material point of link l
                    let vt = sub(vc, scale(nv, n));
                    let ft = scale(-mu * f_n / (dot(vt, vt) + eps * eps).sqrt(), vt);
                    let at_contact = add(rl, mv(&tr(&rot), arm));
                    force(&mut ext, Some((l, at_contact)), add(scale(f_n, n), ft));
                }
                Load::Bushing { a, b, k, kr, c, cr } => {
                    // pose, velocity and angular velocity of a frame (world), and its link and
                    // offset in link axes (frames have their link's axes)
                    let frame = |f: Option<usize>| match f {
                        None => (eye3(), [0.0; 3], [0.0; 3], [0.0; 3], None),
                        Some(f) => {
                            let (l, off) = frame_link[f];
                            let (rot, o) = poses[l];
                            let v = vels[l];
                            let (w, vo) = ([v[0], v[1], v[2]], [v[3], v[4], v[5]]);
                            (
                                rot,
                                add(o, mv(&rot, off)),
                                mv(&rot, add(vo, cross(w, off))),
                                mv(&rot, w),
                                Some((l, off)),
                            )
                        }
                    };
                    let (ra, pa, va, wa, la) = frame(*a);
                    let (rb, pb, vb, wb, lb) = frame(*b);
                    let (k, kr, c, cr) = (ev3(k), ev3(kr), ev3(c), ev3(cr));
                    let mul = |x: V3, y: V3| [x[0] * y[0], x[1] * y[1], x[2] * y[2]];
                    let d = sub(pb, pa);
                    let dp = mv(&tr(&ra), d);
                    let dv = mv(&tr(&ra), sub(sub(vb, va), cross(wa, d)));
                    let r = mm(&tr(&ra), &rb);
                    let th = scale(
                        0.5,
                        [r[2][1] - r[1][2], r[0][2] - r[2][0], r[1][0] - r[0][1]],
                    );
                    let om = mv(&tr(&ra), sub(wb, wa));
                    let f = scale(-1.0, add(mul(k, dp), mul(c, dv)));
                    // −Eᵀ K_r θ with E = ½ (tr R I − R), then the damping
                    let kth = mul(kr, th);
                    let tr_r = r[0][0] + r[1][1] + r[2][2];
                    let el = scale(0.5, sub(scale(tr_r, kth), mv(&tr(&r), kth)));
                    let m = scale(-1.0, add(el, mul(cr, om)));
                    let (fw, mw) = (mv(&ra, f), mv(&ra, m));
                    force(&mut ext, lb, fw);
                    torque(&mut ext, *b, mw);
                    // A: the opposite force at its point where B's origin is
                    force(
                        &mut ext,
                        la.map(|(l, off)| (l, add(off, dp))),
                        scale(-1.0, fw),
                    );
                    torque(&mut ext, *a, scale(-1.0, mw));
                }
                Load::RotationalSpring {
                    a,
                    b,
                    axis,
                    k,
                    c,
                    angle0,
                } => {
                    // θ = atan2(s, co) from R = R_Aᵀ R_B; θ̇ = g·Ω with Ω = R_Aᵀ (ω_B − ω_A)
                    // and g = (co (tr R n − Rᵀ n) + s (v + R n × n)) / (s² + co²), so that
                    // the torque −T R_A g on B and T R_A g on A do the work −T θ̇
                    let rot = |f: Option<usize>| match f {
                        None => (eye3(), [0.0; 3]),
                        Some(f) => {
                            let (rot, _) = poses[frame_link[f].0];
                            let v = vels[frame_link[f].0];
                            (rot, mv(&rot, [v[0], v[1], v[2]]))
                        }
                    };
                    let ((ra, wa), (rb, wb)) = (rot(*a), rot(*b));
                    let n = ev3(axis);
                    let p = ev(&[*k, *c, *angle0]);
                    let r = mm(&tr(&ra), &rb);
                    let v = [r[2][1] - r[1][2], r[0][2] - r[2][0], r[1][0] - r[0][1]];
                    let rn = mv(&r, n);
                    let tr_r = r[0][0] + r[1][1] + r[2][2];
                    let (s, co) = (dot(n, v), tr_r - dot(n, rn));
                    let g = scale(
                        1.0 / (s * s + co * co),
                        add(
                            scale(co, sub(scale(tr_r, n), mv(&tr(&r), n))),
                            scale(s, add(v, cross(rn, n))),
                        ),
                    );
                    let om = mv(&tr(&ra), sub(wb, wa));
                    let tq = p[0] * (s.atan2(co) - p[2]) + p[1] * dot(g, om);
                    let mw = scale(-tq, mv(&ra, g));
                    torque(&mut ext, *b, mw);
                    torque(&mut ext, *a, scale(-1.0, mw));
                }
            }
        }
    }
    let z = vec![0.0; q.len()];
    let tau = oracle.rnea_ext(q, qd, &z, t, true, &ext);
    tau.iter().zip(&qgen).map(|(a, b)| b - a).collect()
}

#[derive(Default)]
struct Balance {
    cons: Worst,
    full: Worst,
    vp_rec: Worst,
    oracle: Worst,
    /// contacts seen separated, pressing, and penetrating with the damping clipped (F_n = 0)
    regimes: [usize; 3],
    /// largest power of contacts and damped bushings alone, relative to the other terms
    max_power: f64,
    /// qdd of the articulated bodies applied to the bodies' wrenches of Newton–Euler, the
    /// loads taken off, against the dense solve of M qdd = h (recursive)
    forward: Worst,
    /// scenes (of trees whose coordinates each move one node) where that applies
    articulated: usize,
}

/// Builds `TREES` random trees from `seed0` with the loads of `add_loads` (and the force
/// elements of `add_force_elements` when `elements`) in two scenes, Conservative and Full
/// (and Contacts: the lossy force elements alone, with gravity), and checks the energy
/// balance and h against the oracle at `STATES` states of each.
fn balance(
    seed0: u64,
    elements: bool,
    tally: &mut [usize; 7],
    el_tally: &mut [usize; 8],
) -> Balance {
    let mut out = Balance {
        max_power: f64::NEG_INFINITY,
        ..Balance::default()
    };
    for seed in 0..TREES {
        let mut rng = Rng::new(seed0 + seed);
        let desc = random_desc(
            &mut rng,
            GenOpts {
                min_dof: 1,
                max_dof: 10,
                rheonomic: false,
                gravity: true,
            },
        );
        let n = desc.ndof;
        let mut built = to_system(&desc, &mut rng);
        let charts = built.charts.clone();
        let (springs, losses) = add_loads(&mut rng, &mut built.sys, n, tally);
        let (mut cons, mut full) = (vec![springs], vec![springs, losses]);
        if elements {
            let (elastic, contacts) = add_force_elements(&mut rng, &mut built.sys, el_tally);
            cons.push(elastic);
            full.extend([elastic, contacts]);
        }
        let oracle = Oracle::new(&desc);
        // every system frame is a link frame or a body (at the link's G), in link axes
        let mut frame_link = vec![(usize::MAX, [0.0; 3]); built.sys.frames.len()];
        for (i, l) in desc.links.iter().enumerate() {
            frame_link[built.body[i]] = (i, l.com);
            if let Some(f) = built.link_frame[i] {
                frame_link[f] = (i, [0.0; 3]);
            }
        }
        built.sys.scene("Conservative", cons);
        built.sys.scene("Full", full.clone());
        if elements {
            // contacts and the damped bushing alone: damping and friction only dissipate
            built.sys.scene("Contacts", full[2..].to_vec());
        }
        let mut model = SymbolicModel::build(built.sys);
        assert_eq!(model.scenes.len(), 2 + elements as usize);
        for sc in 0..model.scenes.len() {
            let eq = model.scenes[sc].clone();
            if sc == 0 {
                assert!(
                    model.sys.arena.is_num(eq.power, 0.0),
                    "no power without losses"
                );
            }
            let a = &mut model.sys.arena;
            let e = a.add(eq.kinetic, eq.potential);
            let de = a.dt(e);
            let dt_kin = a.dt(eq.kinetic);
            let dt_pot = a.dt(eq.potential);
            let mut roots = vec![de, dt_kin, dt_pot, eq.power];
            for mb in [eq.vp.as_ref().expect("small model"), &eq.rec] {
                roots.extend(mb.m.iter().flatten());
                roots.extend(&mb.h);
            }
            let loads = Loads::build(&mut model.sys, &model.tree, &model.world, &eq.effects);
            let (direct, bias) = bias_wrenches(&mut model.sys, &model.tree, &model.world, &loads);
            let mut aba = Vec::new();
            for e in [Elimination::ParentAxes, Elimination::ChildAxes] {
                let f = articulated(
                    &mut model.sys,
                    &model.tree,
                    &direct,
                    Some(&bias),
                    e,
                    Outward::ReadyFirst,
                );
                aba.extend(f.map(|f| f.qdd).unwrap_or_default());
            }
            out.articulated += !aba.is_empty() as usize;
            for s in 0..STATES {
                let (t, q, qd, _) = random_state(&mut rng, n);
                let z = vec![0.0; n];
                let v = eval_charts(&model, &roots, (t, &q, &qd, &z), &charts);
                let mh = |k: usize| {
                    let o = 4 + k * (n * n + n);
                    let m: Vec<Vec<f64>> = v[o..o + n * n].chunks(n).map(|r| r.to_vec()).collect();
                    (m, v[o + n * n..o + n * n + n].to_vec())
                };
                let ((m_vp, h_vp), (m_rec, h_rec)) = (mh(0), mh(1));
                let at = || format!("seed {}, scene {sc}, state {s}, {n} dof", seed0 + seed);
                out.vp_rec.see(
                    rel_err(&m_vp.concat(), &m_rec.concat()).max(rel_err(&h_vp, &h_rec)),
                    at,
                );
                let h_ref = oracle_h(
                    &model,
                    &oracle,
                    &frame_link,
                    &eq.effects,
                    (t, &q, &qd),
                    &charts,
                    &mut out.regimes,
                );
                out.oracle
                    .see(rel_err(&h_vp, &h_ref).max(rel_err(&h_rec, &h_ref)), at);
                let qdd_ref = solve_spd(&m_rec, &h_rec);
                let v = eval_charts(&model, &aba, (t, &q, &qd, &z), &charts);
                for qdd in v.chunks(n) {
                    out.forward.see(rel_err(qdd, &qdd_ref), at);
                }
                for (m, h) in [(&m_vp, &h_vp), (&m_rec, &h_rec)] {
                    let qdd = solve_spd(m, h);
                    let v = eval_charts(&model, &roots[..4], (t, &q, &qd, &qdd), &charts);
                    let (de, dk, dp, p) = (v[0], v[1], v[2], v[3]);
                    let scale = p.abs().max(dk.abs()).max(dp.abs());
                    let err = (de - p).abs() / scale;
                    if sc == 2 {
                        out.max_power = out.max_power.max(p / scale);
                    }
                    if sc == 0 {
                        out.cons.see(err, at);
                    } else {
                        out.full.see(err, at);
                    }
                }
            }
        }
    }
    out
}

#[test]
fn energy_balance_with_loads() {
    let mut tally = [0usize; 7];
    let b = balance(3000, false, &mut tally, &mut [0; 8]);
    println!(
        "{TREES} trees x {STATES} states x 2 scenes; loads: {} springs, {} dampers, {} world \
         forces, {} body-frame forces, {} torques, {} torques with reaction, {} generalised forces",
        tally[0], tally[1], tally[2], tally[3], tally[4], tally[5], tally[6]
    );
    b.vp_rec
        .check("M, h with loads: virtual power vs recursive", 1e-10);
    b.oracle.check("h with loads vs oracle", 1e-10);
    b.forward.check(
        "forward dynamics with loads, articulated bodies on the bodies' wrenches, vs dense solve",
        1e-10,
    );
    assert!(b.articulated >= 10, "{} scenes", b.articulated);
    b.cons.check("gravity + springs: d(T+V)/dt = 0", 1e-9);
    b.full.check("all loads: d(T+V)/dt = power", 1e-9);
    assert!(tally.iter().all(|&c| c >= 5), "{tally:?}");
}

/// The same with contacts (points, spheres and ellipsoids, linear or Hunt–Crossley, damping, friction), bushings and rotational
/// springs: an undamped bushing, an undamped, frictionless contact and an undamped rotational
/// spring join the conservative scene (the bushing's elastic torque must be exactly the
/// gradient of ½ θᵀ K_r θ, the rotational spring's that of ½ k (θ − θ0)², for the balance to
/// hold), damped contacts with friction, a damped bushing and a damped rotational spring the
/// full one.
#[test]
fn energy_balance_with_contacts_and_bushings() {
    let mut el = [0usize; 8];
    let b = balance(5000, true, &mut [0; 7], &mut el);
    println!(
        "{TREES} trees x {STATES} states x 3 scenes; {} point contacts, {} sphere contacts, \
         {} ellipsoid contacts, {} Hunt–Crossley, {} bushings to the ground, {} between \
         frames, {} rotational springs about a joint's axis, {} about a random axis; contact \
         states: {} separated, {} pressing, {} penetrating with F_n clipped to 0",
        el[0],
        el[1],
        el[2],
        el[3],
        el[4],
        el[5],
        el[6],
        el[7],
        b.regimes[0],
        b.regimes[1],
        b.regimes[2]
    );
    b.vp_rec.check(
        "M, h with force elements: virtual power vs recursive",
        1e-10,
    );
    b.oracle.check("h with force elements vs oracle", 1e-10);
    b.forward.check(
        "forward dynamics with force elements, articulated bodies on the bodies' wrenches, \
         vs dense solve",
        1e-10,
    );
    assert!(b.articulated >= 10, "{} scenes", b.articulated);
    b.cons
        .check("gravity + springs + bushings: d(T+V)/dt = 0", 1e-9);
    b.full.check("with contacts: d(T+V)/dt = power", 1e-9);
    assert!(el.iter().all(|&c| c >= 5), "{el:?}");
    assert!(b.regimes.iter().all(|&c| c >= 5), "{:?}", b.regimes);
    println!(
        "power of contacts and damped bushings: max {:.3e} (relative)",
        b.max_power
    );
    assert!(b.max_power <= 1e-12, "contacts or bushings gave energy");
}
