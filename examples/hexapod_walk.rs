//! The hexapod walks: `models/src/hexapod_walker.rs` (49 bodies, 24 dof, 18 DC motors with
//! their currents as states, feet in contact with a terrain) under its 1 kHz controller: a
//! central gait generator, the legs' inverse kinematics and a PID per joint.
//!
//! Prints what the walk shows: distance, speed, heading error, the feet's slip, the base's
//! height error and oscillation, electrical energy and cost of transport, peak currents and
//! voltages, and the real-time factor. `--gait tripod|wave|ripple`, `--speed` (m/s),
//! `--turn` (rad/s, a turn on the spot with `--speed 0`), `--terrain flat|step` (a 5 cm step
//! at x = 0.6 m), `--continuous` (continuous-time PIDs instead of the sampled controller),
//! `--compare` (quick short steps against slow long ones: cost of transport, peak currents,
//! base oscillation, foot slip; with `--out`, compare_energy.svg and compare_height.svg), and
//! the shared options (`--scheme`, `--h`, `--t-end`, `--dt`,
//! `--out DIR`: trajectory.csv, figures.txt, base.svg, speed.svg, feet.svg, motors.svg,
//! animation.html, motion.gltf).
//!
//! Run with `cargo run --release --example hexapod_walk`.

use mbs::cli::RunArgs;
use mbs::plot::{Chart, Series, line_chart};
use mbs::{Model, Scheme};
use mbs_models::hexapod_walker::*;
use std::path::Path;

#[derive(clap::Parser, Debug)]
struct Args {
    #[command(flatten)]
    run: RunArgs,
    /// gait: tripod, wave or ripple
    #[arg(long, default_value = "tripod")]
    gait: String,
    /// forward speed asked of the base (m/s)
    #[arg(long, default_value_t = 0.15, allow_hyphen_values = true)]
    speed: f64,
    /// yaw rate asked of the base (rad/s)
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    turn: f64,
    /// terrain: flat, or step (a 5 cm step at x = 0.6 m)
    #[arg(long, default_value = "flat")]
    terrain: String,
    /// continuous-time PIDs (their integrals as states) instead of the 1 kHz controller
    #[arg(long)]
    continuous: bool,
    /// compare quick short steps with slow long ones
    #[arg(long)]
    compare: bool,
}

/// The walker the arguments describe.
fn walker(args: &Args) -> Result<Walker, String> {
    let gait = Gait::parse(&args.gait)
        .ok_or_else(|| format!("unknown gait `{}`: tripod, wave or ripple", args.gait))?;
    let mut g = GaitParams::new(gait, args.speed);
    g.yaw_rate = args.turn;
    let mut w = Walker::new(g);
    w.terrain = match args.terrain.as_str() {
        "flat" => Terrain::default(),
        "step" => {
            w.gait.step_height = 0.08;
            Terrain::step(0.6, 0.05)
        }
        other => return Err(format!("unknown terrain `{other}`: flat or step")),
    };
    Ok(w)
}

fn print_figures(label: &str, f: &Figures) {
    println!("{label}:");
    println!(
        "  walked {:.3} m forward, {:+.3} m sideways in {:.1} s: {:.3} m/s after the first cycle",
        f.distance, f.lateral, f.t_end, f.speed
    );
    println!(
        "  heading: turned {:+.1}°, largest error {:.2}° after the first cycle",
        f.turned_deg, f.heading_error_deg
    );
    println!(
        "  feet: {} contacts, largest slip during one {:.1} mm; lowest foot at the end {:+.4} m",
        f.contacts,
        f.max_slip * 1e3,
        f.lowest_foot_end
    );
    println!(
        "  base: height within {:.1} mm of its set point, pitch {:.2}° and roll {:.2}° peak to peak",
        f.height_error * 1e3,
        f.pitch_range_deg,
        f.roll_range_deg
    );
    let cot = if f.cost_of_transport.is_finite() {
        format!("{:.3}", f.cost_of_transport)
    } else {
        "n/a (no distance)".into()
    };
    println!(
        "  motors: {:.1} J drawn, cost of transport {cot}, peak current {:.1} A, peak voltage {:.1} V ({:.2} % of samples saturated)",
        f.energy,
        f.peak_current,
        f.peak_voltage,
        100.0 * f.saturated
    );
    println!("  real-time factor {:.1}", f.real_time_factor);
}

/// A walk that started: an unreachable start, or options refused before the first output (a
/// walk with no trajectory to read figures from), is the program's error.
fn started(w: Result<Walk, Unreachable>) -> Result<Walk, String> {
    let w = w.map_err(|e| {
        format!("{e}: the gait asks too long a stride of it; take a smaller --speed or --turn")
    })?;
    match &w.failure {
        Some(e) if w.trajectory.is_empty() => Err(mbs::cli::failure_text(e)),
        _ => Ok(w),
    }
}

fn main() {
    use clap::{CommandFactory, FromArgMatches};
    // this program's defaults: RKC (at 0.5 ms unless --h: two steps per control period),
    // outputs every 5 ms
    let command = Args::command()
        .mut_arg("scheme", |a| a.default_value("rkc"))
        .mut_arg("dt", |a| a.default_value("0.005"));
    let args = Args::from_arg_matches(&command.get_matches()).unwrap_or_else(|e| e.exit());
    if let Err(e) = run(&args) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run(args: &Args) -> Result<(), String> {
    // the shared run arguments this program does not act on are refused, not ignored
    let r = &args.run;
    let unsupported = [
        ("--global-error", r.global_error),
        ("--scene", r.scene.is_some()),
        ("--sweep", r.sweep.is_some()),
        ("--shard", r.shard.is_some()),
        ("--slurm", r.slurm),
        ("--merge", r.merge),
        ("--threads", r.threads.is_some()),
    ];
    if let Some((flag, _)) = unsupported.iter().find(|(_, given)| *given) {
        return Err(format!(
            "{flag} is not taken by this program (one walk, or `--compare`): run the `hexapod` example for sweeps and scenes"
        ));
    }
    for (flag, v) in [("--speed", args.speed), ("--turn", args.turn)] {
        if !v.is_finite() {
            return Err(format!("{flag} must be a finite number, found {v}"));
        }
    }
    let walker = walker(args)?;
    let scheme = Scheme::from_name(&args.run.scheme)
        .ok_or_else(|| format!("unknown scheme `{}`", args.run.scheme))?;
    let mut options = args.run.options(16.0);
    if args.run.h.is_none() {
        // a fixed step, a whole number per control period. RKC: two (0.5 ms), its stages
        // from the fastest modes; one (1 ms) walks the README's runs with energies within
        // 1 % but the wave gait's peak current, a 0.3 ms electrical transient, at 5.7 A
        // instead of 13.5. RK4: five (0.2 ms); four (0.25 ms) stop in the quick gait of
        // --compare with UnstableStep (ρ ≈ 1.1e4/s: h < 0.247 ms)
        match scheme {
            Scheme::Rkc => options.step = mbs::StepControl::Fixed { h: 5e-4 },
            Scheme::Rk4 => options.step = mbs::StepControl::Fixed { h: 2e-4 },
            _ => {}
        }
    }
    let control = if args.continuous {
        Control::Continuous
    } else {
        Control::Sampled
    };
    if args.compare {
        return compare(&walker, scheme, options, args.run.out.as_deref());
    }
    let w = started(walk(&walker, control, scheme, options))?;
    let f = w.figures();
    let label = format!(
        "{} gait at {} m/s{} on {} ground, {} control, {}",
        args.gait,
        args.speed,
        if args.turn != 0.0 {
            format!(" turning at {} rad/s", args.turn)
        } else {
            String::new()
        },
        args.terrain,
        if args.continuous {
            "continuous"
        } else {
            "1 kHz"
        },
        scheme.name()
    );
    // --quiet: nothing but errors
    let quiet = args.run.quiet;
    if !quiet {
        print_figures(&label, &f);
        println!(
            "  {} steps, {} evaluations, {} samples",
            w.stats.steps, w.stats.forward_dynamics, w.stats.samples
        );
        println!();
    }
    if let Some((t, e)) = &w.log.failure {
        println!();
        println!("  the controller held its voltages from t = {t:.3} s: {e}");
    }
    if let Some(out) = &args.run.out {
        write_outputs(out, &w, &f).map_err(|e| e.to_string())?;
        if !quiet {
            println!("  outputs in {}", out.display());
        }
    }
    if let Some(e) = &w.failure {
        return Err(format!("the walk stopped: {}", mbs::cli::failure_text(e)));
    }
    Ok(())
}

/// Two parameter sets of the gait at the same speed: quick short steps (duty factor 0.5,
/// period 0.6 s, 8 cm high) against slow long ones (duty factor 0.6, period 1.2 s, 4 cm).
fn compare(
    base: &Walker,
    scheme: Scheme,
    options: mbs::Options,
    out: Option<&Path>,
) -> Result<(), String> {
    let mut quick = base.clone();
    quick.gait.duty = 0.5;
    quick.gait.period = 0.6;
    quick.gait.step_height = 0.08;
    let mut slow = base.clone();
    slow.gait.duty = 0.6;
    slow.gait.period = 1.2;
    slow.gait.step_height = 0.04;
    println!(
        "{:<8} {:>6} {:>6} {:>8} {:>9} {:>9} {:>8} {:>8} {:>8} {:>8}",
        "gait", "duty", "T (s)", "d (m)", "E (J)", "CoT", "I_max", "z ±mm", "pitch°", "slip mm"
    );
    let (mut energy, mut height) = (Vec::new(), Vec::new());
    for (name, w) in [("quick", &quick), ("slow", &slow)] {
        let r = started(walk(w, Control::Sampled, scheme, options.clone()))?;
        let f = r.figures();
        let tr = &r.trajectory;
        let n = HexapodWalker::NQ;
        energy.push(Series::new(
            name,
            (0..tr.len())
                .map(|i| (tr.t[i], tr.qd(i)[n + ENERGY]))
                .collect(),
        ));
        height.push(Series::new(
            name,
            (0..tr.len()).map(|i| (tr.t[i], tr.q(i)[2])).collect(),
        ));
        println!(
            "{:<8} {:>6.2} {:>6.2} {:>8.3} {:>9.1} {:>9.3} {:>8.1} {:>8.1} {:>8.2} {:>8.1}",
            name,
            w.gait.duty,
            w.gait.period,
            f.distance,
            f.energy,
            f.cost_of_transport,
            f.peak_current,
            f.height_error * 1e3,
            f.pitch_range_deg,
            f.max_slip * 1e3
        );
        if let Some(e) = &r.failure {
            println!("  ({name} stopped: {})", mbs::cli::failure_text(e));
        }
    }
    if let Some(out) = out {
        let draw = || -> Result<(), Box<dyn std::error::Error>> {
            std::fs::create_dir_all(out)?;
            line_chart(
                &out.join("compare_energy.svg"),
                &chart("electrical energy drawn", "E (J)"),
                &energy,
            )?;
            line_chart(
                &out.join("compare_height.svg"),
                &chart("base height", "z (m)"),
                &height,
            )?;
            Ok(())
        };
        draw().map_err(|e| e.to_string())?;
        println!("plots in {}", out.display());
    }
    Ok(())
}

fn chart(title: &str, y: &str) -> Chart {
    Chart::linear(title, "t (s)", y)
}

fn write_outputs(out: &Path, w: &Walk, f: &Figures) -> Result<(), Box<dyn std::error::Error>> {
    std::fs::create_dir_all(out)?;
    let tr = &w.trajectory;
    tr.write_csv(std::fs::File::create(out.join("trajectory.csv"))?)?;
    std::fs::write(out.join("figures.txt"), format!("{f:#?}\n"))?;
    let n = HexapodWalker::NQ;
    let t = &tr.t;
    let base = |k: usize, scale: f64| -> Vec<(f64, f64)> {
        (0..tr.len()).map(|i| (t[i], tr.q(i)[k] * scale)).collect()
    };
    line_chart(
        &out.join("base.svg"),
        &chart("base height (m) and pitch (deg/100)", "z (m), pitch"),
        &[
            Series::new("z", base(2, 1.0)),
            Series::new("pitch / 100", base(4, 180.0 / std::f64::consts::PI / 100.0)),
        ],
    )?;
    line_chart(
        &out.join("speed.svg"),
        &chart("forward speed", "ẋ (m/s)"),
        &[Series::new(
            "ẋ",
            (0..tr.len()).map(|i| (t[i], tr.qd(i)[0])).collect(),
        )],
    )?;
    let mut model = HexapodWalker::default();
    let mut kin = mbs::Kinematics::new::<HexapodWalker>();
    let mut feet = vec![Vec::new(); LEGS];
    for (i, &ti) in t.iter().enumerate() {
        mbs::charts::use_charts_of(&mut model, tr, i);
        model.point_kinematics(ti, &tr.q(i)[..n], &tr.qd(i)[..n], &mut kin);
        for (leg, s) in feet.iter_mut().enumerate() {
            let p = &kin.points[leg];
            s.push((ti, w.terrain.point_force(p.position, p.velocity)[2]));
        }
    }
    let names = ["FL", "FR", "ML", "MR", "RL", "RR"];
    line_chart(
        &out.join("feet.svg"),
        &chart("normal force of each foot", "F (N)"),
        &feet
            .into_iter()
            .enumerate()
            .map(|(k, p)| Series::new(names[k], p))
            .collect::<Vec<_>>(),
    )?;
    // the middle left leg's motors: currents, and the voltages the controller held
    let mut motors = Vec::new();
    for (j, joint) in ["a", "b", "c"].iter().enumerate() {
        let col = n + 3 * 2 + j;
        motors.push(Series::new(
            format!("i {joint}2 (A)"),
            (0..tr.len()).map(|i| (t[i], tr.qd(i)[col])).collect(),
        ));
        motors.push(Series::new(
            format!("V {joint}2 (V)"),
            w.log
                .samples
                .iter()
                .step_by(5)
                .map(|(ts, v)| (*ts, v[6 + j]))
                .collect(),
        ));
    }
    line_chart(
        &out.join("motors.svg"),
        &chart("middle left leg: motor currents and voltages", "A, V"),
        &motors,
    )?;
    if !tr.poses_at(0).is_empty() {
        mbs::anim::write_html(&out.join("animation.html"), model.info(), tr)?;
        mbs::gltf::write_gltf(&out.join("motion.gltf"), model.info(), tr)?;
    }
    Ok(())
}
