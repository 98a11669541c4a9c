//! Energy balance on random scleronomic trees with gravity, springs, dampers, forces, torques
//! and generalised forces: along the motion qdd = M⁻¹ h, the exact time derivative of the
//! generated T + V equals the generated power of the non-conservative effects. The energy
//! balance cannot see a load that is wrong but consistently so in h and in the power (a
//! reaction torque's sign, a force's axes), so h with every load is also checked against the
//! independent oracle, which applies the loads to its own kinematics.

mod common;

use common::*;
use mbs_symbolic::SymbolicModel;
use mbs_symbolic::expr::ExprId;
use mbs_symbolic::mech::system::{Attach, Load};

const TREES: u64 = 40;
const STATES: usize = 3;

/// Generalised forces h(q, qd, t) of a scene by the oracle: the loads' values (expressions of
/// q and qd) are evaluated, then applied as external spatial forces on the oracle's links.
fn oracle_h(
    model: &SymbolicModel,
    oracle: &Oracle,
    frame_link: &[(usize, V3)],
    effects: &[usize],
    t: f64,
    q: &[f64],
    qd: &[f64],
) -> Vec<f64> {
    let poses = oracle.link_poses(q, t);
    let vels = oracle.link_velocities(q, qd, t);
    let mut ext = vec![[0.0; 6]; poses.len()];
    let mut qgen = vec![0.0; q.len()];
    let ev = |e: &[ExprId]| eval(model, e, t, q, qd, &[]);
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
                Load::Spring { a, b, k, l0, axis } => {
                    let (pa, _, la) = point(a);
                    let (pb, _, lb) = point(b);
                    let d = sub(pb, pa);
                    let kv = ev(&[*k, *l0]);
                    // along the line of the ends, or a fixed axis (signed length)
                    let f = match axis {
                        None => scale(kv[0] * (norm(d) - kv[1]) / norm(d), d),
                        Some(n) => {
                            let n = ev3(n);
                            scale(kv[0] * (dot(n, d) - kv[1]), n)
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
            }
        }
    }
    let z = vec![0.0; q.len()];
    let tau = oracle.rnea_ext(q, qd, &z, t, true, &ext);
    tau.iter().zip(&qgen).map(|(a, b)| b - a).collect()
}

#[test]
fn energy_balance_with_loads() {
    let mut w_cons = Worst::default();
    let mut w_full = Worst::default();
    let mut w_vp_rec = Worst::default();
    let mut w_oracle = Worst::default();
    let mut tally = [0usize; 7];
    for seed in 0..TREES {
        let mut rng = Rng::new(3000 + seed);
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
        let (springs, losses) = add_loads(&mut rng, &mut built.sys, n, &mut tally);
        let oracle = Oracle::new(&desc);
        // every system frame is a link frame or a body (at the link's G), in link axes
        let mut frame_link = vec![(usize::MAX, [0.0; 3]); built.sys.frames.len()];
        for (i, l) in desc.links.iter().enumerate() {
            frame_link[built.body[i]] = (i, l.com);
            if let Some(f) = built.link_frame[i] {
                frame_link[f] = (i, [0.0; 3]);
            }
        }
        built.sys.scene("Conservative", vec![springs]);
        built.sys.scene("Full", vec![springs, losses]);
        let mut model = SymbolicModel::build(built.sys);
        assert_eq!(model.scenes.len(), 2);
        for sc in 0..2 {
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
            for mb in [&eq.vp, &eq.rec] {
                roots.extend(mb.m.iter().flatten());
                roots.extend(&mb.h);
            }
            for s in 0..STATES {
                let (t, q, qd, _) = random_state(&mut rng, n);
                let z = vec![0.0; n];
                let v = eval(&model, &roots, t, &q, &qd, &z);
                let mh = |k: usize| {
                    let o = 4 + k * (n * n + n);
                    let m: Vec<Vec<f64>> = v[o..o + n * n].chunks(n).map(|r| r.to_vec()).collect();
                    (m, v[o + n * n..o + n * n + n].to_vec())
                };
                let ((m_vp, h_vp), (m_rec, h_rec)) = (mh(0), mh(1));
                let at = || format!("seed {}, scene {sc}, state {s}, {n} dof", 3000 + seed);
                w_vp_rec.see(
                    rel_err(&m_vp.concat(), &m_rec.concat()).max(rel_err(&h_vp, &h_rec)),
                    at,
                );
                let h_ref = oracle_h(&model, &oracle, &frame_link, &eq.effects, t, &q, &qd);
                w_oracle.see(rel_err(&h_vp, &h_ref).max(rel_err(&h_rec, &h_ref)), at);
                for (m, h) in [(&m_vp, &h_vp), (&m_rec, &h_rec)] {
                    let qdd = solve_spd(m, h);
                    let v = eval(&model, &roots[..4], t, &q, &qd, &qdd);
                    let (de, dk, dp, p) = (v[0], v[1], v[2], v[3]);
                    let scale = p.abs().max(dk.abs()).max(dp.abs());
                    let err = (de - p).abs() / scale;
                    if sc == 0 {
                        w_cons.see(err, at);
                    } else {
                        w_full.see(err, at);
                    }
                }
            }
        }
    }
    println!(
        "{TREES} trees x {STATES} states x 2 scenes; loads: {} springs, {} dampers, {} world \
         forces, {} body-frame forces, {} torques, {} torques with reaction, {} generalised forces",
        tally[0], tally[1], tally[2], tally[3], tally[4], tally[5], tally[6]
    );
    w_vp_rec.check("M, h with loads: virtual power vs recursive", 1e-10);
    w_oracle.check("h with loads vs oracle", 1e-10);
    w_cons.check("gravity + springs: d(T+V)/dt = 0", 1e-9);
    w_full.check("all loads: d(T+V)/dt = power", 1e-9);
    assert!(tally.iter().all(|&c| c >= 5), "{tally:?}");
}
