//! Rotations without gimbal lock, measured: the spherical (`Tball`) and free (`Tfree`) joints,
//! whose ZYX angles the runtime reads in a chart it re-centres before they lock
//! (`docs/rotations.md` quotes these figures).
//!
//! ```text
//! cargo run --release --example rotations
//! ```
//!
//! It prints:
//!
//! 1. op counts (flops) of M + h, M and the kinematics, each rotation model against its
//!    Euler-angle twin, and the hexapod's base written three ways (the model's `Tfree`, the
//!    Euler angles it replaced, and `Tball · Tdisp`, a translation in the base's own axes);
//! 2. the intermediate-axis tumble for 20 s at rtol 1e-10 from MODELS.md's start and from
//!    the start turned by φ0 (whose accurate flip meets the ZYX singularity), with DOPRI5,
//!    Radau5 and generalized-α (adaptive, default ρ∞): re-centrings, the largest relative
//!    drift of the energy and of the angular momentum vector, steps, CPU time; the ZYX twin
//!    beside it;
//! 3. the fast top through the vertical (2 s) and the spherical pendulum through the bottom
//!    (3 s) at rtol 1e-10, with their Euler twins;
//! 4. the hexapod thrown from 1 m somersaulting, free and landing (scene `Tumbling`);
//! 5. the sleeping top's poles, linearised where its Euler angles lock, against the closed
//!    form.
//!
//! Times are the least wall-clock time of 3 runs, outputs at every step included.

use mbs::{IterationMatrix, Model, Options, Output, Scheme, SimError, Stats, Trajectory, simulate};
use mbs_models::conserved::{drifts, energy_drift, from_vertical};
use mbs_models::hexapod::{Hexapod, HexapodStanding, HexapodTumbling, thrown};
use mbs_models::spherical_pendulum::{SphericalPendulum, SphericalPendulumZyx};
use mbs_models::top::{Top, TopZyx};
use mbs_models::tumble::{INERTIA, PHI0, Tumble, TumbleBall, turned_start};
use mbs_symbolic::expand::{Expansion, expand_models, multibody_blocks};
use std::time::{Duration, Instant};

/// Adaptive steps at `rtol` (atol = rtol/100), an output at every step.
fn adaptive(t_end: f64, rtol: f64) -> Options {
    Options {
        output: Output::Steps,
        ..Options::adaptive(t_end, rtol)
    }
}

/// A run, the least CPU time of three.
fn timed<M: Model + Clone + 'static>(
    model: &M,
    scheme: Scheme,
    o: &Options,
) -> (Result<(Trajectory, Stats), SimError>, Duration) {
    let mut best = Duration::MAX;
    let mut out = None;
    for _ in 0..3 {
        let t = Instant::now();
        let r = simulate(model.clone(), scheme, o.clone());
        best = best.min(t.elapsed());
        out = Some(r);
    }
    (out.expect("three runs"), best)
}

/// How a run ended, for the tables.
fn outcome(r: &Result<(Trajectory, Stats), SimError>) -> String {
    match r {
        Ok(_) => "completes".into(),
        Err(e) => {
            // the failure's variant name
            let kind = format!("{:?}", e.kind);
            let name = kind.split(|c: char| !c.is_alphanumeric()).next();
            format!("stops at t = {:.3} s, {}", e.t, name.unwrap_or(""))
        }
    }
}

/// The flops (and sin/cos calls) of the generated function whose label starts with `f`.
fn ops<M: Model>(model: &M, f: &str) -> String {
    match model.info().ops.iter().find(|(n, _)| n.starts_with(f)) {
        Some((_, c)) => format!("{} ({} funcs)", c.flops(), c.funcs),
        None => "—".into(),
    }
}

fn counts_row<M: Model>(label: &str, model: &M) {
    println!(
        "{label:<36} {:>16} {:>16} {:>16}",
        ops(model, "dynamics"),
        ops(model, "mass_matrix"),
        ops(model, "kinematics")
    );
}

/// M + h of every scene of the hexapod with its base written `base`, generated from
/// `models/src/hexapod.rs` with the `Tfree` statement replaced.
fn hexapod_variant(base: &str) -> Vec<(String, usize)> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/models/src/hexapod.rs");
    let text = std::fs::read_to_string(path).expect("models/src/hexapod.rs");
    let source = text.replace("Tfree(x, y, z, psi, theta, phi)", base);
    let file = syn::parse_file(&source).expect("the hexapod's source parses");
    let mut out = Vec::new();
    for tokens in multibody_blocks(&file) {
        for e in expand_models(tokens).expect("the hexapod expands") {
            if let Expansion::Ok { generated, .. } = e {
                for r in &generated.reports {
                    if r.function.starts_with("dynamics") {
                        out.push((r.model.clone(), r.ops.flops()));
                    }
                }
            }
        }
    }
    out
}

fn op_counts() {
    println!("1. Op counts (flops, and sin/cos calls)\n");
    println!(
        "{:<36} {:>16} {:>16} {:>16}",
        "model", "M + h", "M", "kinematics"
    );
    counts_row("tumble, ZYX angles", &Tumble::default());
    counts_row("tumble, Tball", &TumbleBall::default());
    counts_row("top, ZYX angles", &TopZyx::default());
    counts_row("top, Tball", &Top::default());
    counts_row("spherical pendulum, ZYX", &SphericalPendulumZyx::default());
    counts_row("spherical pendulum, Tball", &SphericalPendulum::default());
    counts_row("hexapod Free, Tfree", &Hexapod::default());
    counts_row("hexapod Standing, Tfree", &HexapodStanding::default());
    counts_row("hexapod Tumbling, Tfree", &HexapodTumbling::default());
    println!("\nthe hexapod's M + h with its base written otherwise (generated from its source):");
    for (what, base) in [
        (
            "Euler angles, Tdisp · Rz · Ry · Rx",
            "Tdisp(x, y, z) * Trotz(psi) * Troty(theta) * Trotx(phi)",
        ),
        (
            "Tball · Tdisp (translation in base axes)",
            "Tball(psi, theta, phi) * Tdisp(x, y, z)",
        ),
    ] {
        let counts: Vec<String> = hexapod_variant(base)
            .iter()
            .map(|(m, f)| format!("{m} {f}"))
            .collect();
        println!("  {what:<42} {}", counts.join(", "));
    }
}

fn tumble() {
    println!(
        "\n2. The tumble, 20 s at rtol 1e-10 (drifts: largest |E/E0 − 1| and |L − L0|/|L0| over every step)\n"
    );
    let schemes = [
        Scheme::Dopri5,
        Scheme::Radau5,
        Scheme::GenAlpha(mbs::GenAlphaParams::default()),
    ];
    for (start, turned) in [("MODELS.md's start", false), ("turned by φ0", true)] {
        let mut o = adaptive(20.0, 1e-10);
        if turned {
            let (q0, qd0) = turned_start(PHI0);
            (o.q0, o.qd0) = (Some(q0), Some(qd0));
        }
        for scheme in schemes {
            let (r, cpu) = timed(&TumbleBall::default(), scheme, &o);
            let (tr, st) = r.expect("the tumble on a ball joint runs through");
            let (de, dl) = drifts(&tr, INERTIA, None);
            let (z, _) = timed(&Tumble::default(), scheme, &o);
            let zyx = match &z {
                Ok((tz, _)) => {
                    let (de, dl) = drifts(tz, INERTIA, None);
                    format!("completes, E {de:.1e}, L {dl:.1e}")
                }
                Err(_) => outcome(&z),
            };
            println!(
                "{start:<18} {:<9} Tball: {:>2} re-centrings, E {de:.1e}, L {dl:.1e}, {:>6} steps, {:>6.1} ms | ZYX: {zyx}",
                scheme.name(),
                st.chart_switches,
                st.steps,
                cpu.as_secs_f64() * 1e3
            );
        }
    }
}

fn through_the_vertical() {
    println!("\n3. Through the Euler angles' singular direction, rtol 1e-10\n");
    let (m, l, i1, i3) = (0.1, 0.04, 2e-5, 4e-5);
    let top_inertia = [i3, i1 + m * l * l, i1 + m * l * l];
    let ig = 0.4 * 0.05 * 0.05;
    let ball_inertia = [ig, ig + 1.0, ig + 1.0];
    for scheme in [Scheme::Dopri5, Scheme::Radau5] {
        let (r, cpu) = timed(&Top::default(), scheme, &adaptive(2.0, 1e-10));
        let (tr, st) = r.expect("the top runs through");
        let (de, dlz) = drifts(&tr, top_inertia, Some(2));
        let theta = from_vertical(&tr, false);
        let passages = (1..theta.len() - 1)
            .filter(|&i| theta[i] < 0.05 && theta[i] <= theta[i - 1] && theta[i] < theta[i + 1])
            .count();
        let closest = theta.iter().copied().fold(f64::INFINITY, f64::min);
        let (z, _) = timed(&TopZyx::default(), scheme, &adaptive(2.0, 1e-10));
        println!(
            "top, 2 s, {:<7} {passages} passages through the vertical (closest {closest:.1e} rad), {} re-centrings, E {de:.1e}, L_z {dlz:.1e}, {} steps, {:.1} ms | ZYX: {}",
            scheme.name(),
            st.chart_switches,
            st.steps,
            cpu.as_secs_f64() * 1e3,
            outcome(&z)
        );
        let (r, cpu) = timed(&SphericalPendulum::default(), scheme, &adaptive(3.0, 1e-10));
        let (tr, st) = r.expect("the pendulum runs through");
        let (de, dlz) = drifts(&tr, ball_inertia, Some(2));
        let closest = from_vertical(&tr, true)
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        let (z, _) = timed(
            &SphericalPendulumZyx::default(),
            scheme,
            &adaptive(3.0, 1e-10),
        );
        println!(
            "spherical pendulum, 3 s, {:<7} closest to the bottom {closest:.1e} rad, {} re-centrings, E {de:.1e}, L_z {dlz:.1e}, {} steps, {:.1} ms | ZYX: {}",
            scheme.name(),
            st.chart_switches,
            st.steps,
            cpu.as_secs_f64() * 1e3,
            outcome(&z)
        );
    }
}

fn hexapod() {
    println!("\n4. The hexapod thrown from 1 m, pitching at 16 rad/s and rolling at 1 rad/s\n");
    let model = Hexapod::default();
    let (q, qd) = thrown(&model, 16.0);
    for scheme in [Scheme::Dopri5, Scheme::Radau5] {
        let o = Options {
            q0: Some(q.clone()),
            qd0: Some(qd.clone()),
            ..adaptive(1.0, 1e-9)
        };
        let (r, cpu) = timed(&model, scheme, &o);
        let (tr, st) = r.expect("the free hexapod somersaults");
        let de = energy_drift(&tr);
        println!(
            "free, 1 s, rtol 1e-9, {:<7}: {} re-centrings, energy drift {de:.1e}, {} steps, {:.1} ms",
            scheme.name(),
            st.chart_switches,
            st.steps,
            cpu.as_secs_f64() * 1e3
        );
    }
    let model = HexapodTumbling::default();
    let o = Options {
        q0: Some(q),
        qd0: Some(qd),
        output: Output::Every { dt: 0.005 },
        ..adaptive(4.0, 1e-6)
    };
    let (r, cpu) = timed(&model, Scheme::Radau5, &o);
    let (tr, st) = r.expect("the thrown hexapod lands");
    let last = tr.len() - 1;
    let w = tr.orientation(last);
    let up = 1.0 - 2.0 * (w[0] * w[0] + w[1] * w[1]);
    let fastest = tr.qd(last).iter().fold(0.0f64, |m, v| m.max(v.abs()));
    println!(
        "landing (scene Tumbling), 4 s, rtol 1e-6, radau5: {} re-centrings, at rest (largest |qd| {fastest:.0e}) the base's z axis · world z = {up:.2} (1 upright, 0 on its side), {} steps ({} rejected), {:.0} ms",
        st.chart_switches,
        st.steps,
        st.rejected_error + st.rejected_newton,
        cpu.as_secs_f64() * 1e3
    );
}

fn sleeping_top() {
    println!(
        "\n5. The sleeping top (upright, spinning at 200 rad/s) linearised where its ZYX angles lock\n"
    );
    let (m, l, i1, i3, g, w3) = (0.1, 0.04, 2e-5, 4e-5, 9.81, 200.0);
    let it = i1 + m * l * l;
    let q = [0.0, -std::f64::consts::FRAC_PI_2, 0.0];
    let lin = mbs::linearize(
        &Top::default(),
        0.0,
        &q,
        &[0.0, 0.0, w3],
        &[],
        IterationMatrix::Auto,
    )
    .expect("the linearisation");
    let modes = mbs::modes(&lin, None).expect("the poles");
    let poles: Vec<String> = modes
        .modes
        .iter()
        .map(|p| format!("{:.6}{:+.6}i", p.re, p.im))
        .collect();
    let l3 = i3 * w3;
    let disc = (l3 * l3 - 4.0 * it * m * g * l).sqrt();
    println!(
        "poles {}; closed form ±{:.6}i, ±{:.6}i (I1' ω² − L3 ω + m g l = 0)",
        poles.join(", "),
        (l3 - disc) / (2.0 * it),
        (l3 + disc) / (2.0 * it)
    );
}

fn main() {
    op_counts();
    tumble();
    through_the_vertical();
    hexapod();
    sleeping_top();
}
