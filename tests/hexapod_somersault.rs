//! The hexapod thrown from 1 m turning over (its base on a free joint, `Tfree`, whose ZYX
//! chart locks at a pitch of ±90°):
//!
//! - without contact (scene `Free`), it somersaults and tumbles while it falls: energy is
//!   conserved through the re-centrings of the base's chart;
//! - with the feet's and the base corners' ground contact (scene `Tumbling`), it lands on a
//!   front corner, rolls and comes to rest on its side within 4 s: no typed error, no point
//!   deeper than the penalty contact's penetration at the impact (6 cm).
//!
//! Positions are read through each output's charts (`mbs::charts::use_charts_of`): the
//! base's angles in q are relative to the chart they were integrated in.

use mbs::{Model, Options, Output, Scheme, StepControl, Trajectory, simulate};
use mbs_models::conserved::energy_drift;
use mbs_models::hexapod::{Hexapod, HexapodTumbling, thrown};

#[path = "common/quoted.rs"]
mod quoted;

/// World z of the base's z axis (1 upright, −1 on its back), from its quaternion.
fn up(tr: &Trajectory, i: usize) -> f64 {
    let q = tr.orientation(i);
    1.0 - 2.0 * (q[0] * q[0] + q[1] * q[1])
}

fn options(t_end: f64, rtol: f64, (q, qd): (Vec<f64>, Vec<f64>)) -> Options {
    Options {
        t_end,
        q0: Some(q),
        qd0: Some(qd),
        step: StepControl::Adaptive {
            rtol,
            atol: rtol * 1e-2,
            h0: None,
        },
        output: Output::Every { dt: 0.005 },
        ..Options::default()
    }
}

#[test]
fn the_free_hexapod_somersaults_keeping_its_energy() {
    let model = Hexapod::default();
    let start = thrown(&model, 16.0);
    // the re-centrings with DOPRI5 and Radau5 (the documents' energy drifts are those of
    // `examples/rotations.rs`, read at every step, where these runs are read every 5 ms)
    let mut switches = Vec::new();
    for scheme in [Scheme::Dopri5, Scheme::Radau5] {
        let (tr, st) = simulate(
            Hexapod::default(),
            scheme,
            options(1.0, 1e-9, start.clone()),
        )
        .unwrap_or_else(|e| panic!("{}: {e}", scheme.name()));
        let de = energy_drift(&tr);
        let lowest = (0..tr.len()).map(|i| up(&tr, i)).fold(1.0, f64::min);
        println!(
            "free hexapod, {}: {} re-centrings, base z axis down to {lowest:.2}, energy drift {de:.1e}; {} steps",
            scheme.name(),
            st.chart_switches,
            st.steps
        );
        assert!(st.chart_switches >= 1 && lowest < -0.9);
        assert!(de < 1e-7, "{de:e}");
        switches.push(st.chart_switches);
    }
    assert_eq!(switches[0], switches[1], "the documents quote one count");
    let s0 = switches[0];
    quoted::says(
        "docs/rotations.md",
        &[format!(
            "| hexapod thrown pitching at 16 rad/s, free, 1 s, rtol 1e-9 | {s0} re-centrings, E"
        )],
    );
    quoted::says(
        "README.md",
        &[format!(
            "| hexapod thrown from 1 m pitching at 16 rad/s | free: {s0} re-centrings, energy drift"
        )],
    );
}

#[test]
fn the_thrown_hexapod_lands_and_comes_to_rest() {
    let model = HexapodTumbling::default();
    let start = thrown(&model, 16.0);
    let (tr, st) = simulate(
        HexapodTumbling::default(),
        Scheme::Radau5,
        options(4.0, 1e-6, start),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let mut kin = mbs::Kinematics::new::<HexapodTumbling>();
    let mut deepest = f64::INFINITY;
    let mut model = model;
    for i in 0..tr.len() {
        // each output's q in the chart it was read in
        mbs::charts::use_charts_of(&mut model, &tr, i);
        model.kinematics(tr.t[i], tr.q(i), tr.qd(i), &mut kin);
        for p in &kin.points {
            deepest = deepest.min(p.position[2]);
        }
    }
    let last = tr.len() - 1;
    let fastest = tr.qd(last).iter().fold(0.0f64, |m, v| m.max(v.abs()));
    println!(
        "thrown hexapod: {} re-centrings, deepest point {deepest:.4} m, at the end base z axis {:.2}, largest |qd| {fastest:.1e}; {} steps\n{st}",
        st.chart_switches,
        up(&tr, last),
        st.steps
    );
    assert!(st.chart_switches >= 1);
    // the penalty contact's penetration at the impact (k = 1e5 N/m), nothing sinking
    assert!(deepest > -0.1, "{deepest}");
    assert!(fastest < 1e-6, "{fastest:e}");
}
