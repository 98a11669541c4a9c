//! A tour of mbs as it stands: write a machine once in the words of CAGeM, read what the
//! generator made of it, and integrate it with two schemes.
//!
//! ```text
//! cargo run --release --example tour
//! ```

use mbs::{Kinematics, Model, Parameters};

mbs::multibody! {
    /// Planar double pendulum of two uniform bars, hinged at the origin.
    pub model DoublePendulum {
        param l = 1.0; param m = 1.0; param g = 9.81; param c = 0.05;
        dof q[0] = PI / 2; dof q[1] = 0.0;
        body bar1 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        body bar2 { mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }
        point tip on bar2 at (0, -l/2, 0);
        TOG[bar1] = Trotz(q[0]) * Tdisp(0, -l/2, 0);
        TOG[bar2] = TOG[bar1] * Tdisp(0, -l/2, 0) * Trotz(q[1]) * Tdisp(0, -l/2, 0);
        effect gravity { gravity(0, -g, 0); }
        effect damping { torque(bar2, relative_to = bar1, axis = z, -c * qd[1]); }
        scene Free = []; scene Swing = [gravity]; scene Full = [gravity, damping];
        option tangents;
    }
}

fn main() {
    let model = DoublePendulumFull::default();
    let info = model.info();
    println!(
        "{} — {} coordinates, {} bodies, effects: {}",
        info.name,
        DoublePendulumFull::NQ,
        info.is_body.iter().filter(|&&b| b).count(),
        info.effects.join(", ")
    );
    println!(
        "formulation of M and h chosen by op count: {}\n",
        info.formulation
    );

    println!("operations of each generated function, per scene:");
    println!(
        "  {:<18} {:>8} {:>8} {:>8}",
        "function", "Free", "Swing", "Full"
    );
    let scenes = [
        DoublePendulumFree::default().info(),
        DoublePendulumSwing::default().info(),
        info,
    ];
    for (k, (name, _)) in info.ops.iter().enumerate() {
        let counts: Vec<String> = scenes
            .iter()
            .map(|s| s.ops.get(k).map_or("-".into(), |o| o.1.flops().to_string()))
            .collect();
        println!(
            "  {:<18} {:>8} {:>8} {:>8}",
            name, counts[0], counts[1], counts[2]
        );
    }

    // the MODELS.md test state
    let q = [0.5 * 0.4f64.sin(), 0.5 * 1.7f64.sin()];
    let qd = [0.7 * 0.2f64.cos(), 0.7 * 1.1f64.cos()];
    let (mut m, mut h) = ([0.0; 4], [0.0; 2]);
    model.dynamics(0.0, &q, &qd, &[], &mut m, &mut h);
    println!("\nat q = {q:.4?}, qd = {qd:.4?}:");
    println!(
        "  M = [{:9.6} {:9.6}; {:9.6} {:9.6}]",
        m[0], m[2], m[1], m[3]
    );
    println!("  h = [{:9.6} {:9.6}]", h[0], h[1]);

    // forward dynamics of the 2 × 2 system, then back through inverse dynamics
    let det = m[0] * m[3] - m[1] * m[2];
    let qdd = [
        (m[3] * h[0] - m[2] * h[1]) / det,
        (m[0] * h[1] - m[1] * h[0]) / det,
    ];
    let mut tau = [0.0; 2];
    model.inverse_dynamics(0.0, &q, &qd, &qdd, &[], &mut tau);
    println!(
        "  qdd = M⁻¹h = [{:9.6} {:9.6}], and τ(qdd) = [{:.1e} {:.1e}] (zero: no actuation)",
        qdd[0], qdd[1], tau[0], tau[1]
    );

    let e = model.energy(0.0, &q, &qd);
    println!(
        "  energy: kinetic {:.6} J, potential {:.6} J; damper power {:.6} W",
        e.kinetic,
        e.potential,
        model.power(0.0, &q, &qd, &[])
    );

    let mut kin = Kinematics::new::<DoublePendulumFull>();
    model.kinematics(0.0, &q, &qd, &mut kin);
    let tip = &kin.points[0];
    println!(
        "  tip at {:.4?} m, moving at {:.4?} m/s",
        tip.position, tip.velocity
    );

    let (mut k, mut c) = ([0.0; 4], [0.0; 4]);
    model
        .tangents(0.0, &q, &qd, &qdd, &[], &mut k, &mut c)
        .expect("generated with `option tangents`");
    println!(
        "  exact tangents: K_t = [{:.4} {:.4}; {:.4} {:.4}], C_t = [{:.4} {:.4}; {:.4} {:.4}]",
        k[0], k[2], k[1], k[3], c[0], c[2], c[1], c[3]
    );

    // parameters change at run time, and are checked
    let mut p = model.params().clone();
    p.set("m", -1.0).unwrap();
    let mut heavier = model.clone();
    println!("\nsetting m = -1: {}", heavier.set_params(p).unwrap_err());

    // integrate the swinging pendulum with an explicit and an implicit scheme
    println!("\nswinging for 10 s from the horizontal:");
    for (scheme, options) in [
        (mbs::Scheme::Dopri5, mbs::Options::adaptive(10.0, 1e-8)),
        (
            mbs::Scheme::GenAlpha(mbs::GenAlphaParams::from_rho_inf(0.9)),
            mbs::Options::adaptive(10.0, 1e-6),
        ),
    ] {
        match mbs::simulate(DoublePendulumSwing::default(), scheme, options) {
            Ok((tr, st)) => {
                let drift = tr.energy_drift().unwrap_or(f64::NAN);
                let last = tr.len() - 1;
                println!(
                    "  {:<9} q(10) = [{:9.5} {:9.5}], {} steps, {} evaluations, energy drift {drift:.2e} J",
                    scheme.name(),
                    tr.q(last)[0],
                    tr.q(last)[1],
                    st.steps,
                    st.evaluations()
                );
            }
            Err(e) => println!("  {:<9} failed: {e}", scheme.name()),
        }
    }
    println!(
        "  (the double pendulum is chaotic: at these tolerances the two runs part after a few"
    );
    println!("   seconds; the energy drift tells which stayed closer to the physics)");
    println!("\nread the generated code with: cargo run --bin mbs -- expand examples/tour.rs");
}
