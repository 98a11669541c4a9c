//! The human lower-limb model (`mbs_models::human`) in its two ways of running, with the
//! figures the gait literature reads and the plots and animation to look at them.
//!
//! **Mode 1, prescribed gait** (`--period`, default 1.1 s): OpenSim's normal cycle fitted with
//! 5 harmonics and made left–right symmetric (`GaitReference::symmetric`), then consistent
//! with flat ground (`GaitReference::grounded`: periodic corrections of the leg angles so
//! that the feet are level and move together in double support, the swinging foot clears
//! the standing one by up to `--clearance`, the centre of mass accelerates within the
//! normal cycle's bounds and the ground's force points at it in single support; printed
//! with what the cycle still asks of the ground: how far beyond the standing feet the centre
//! of pressure it needs lies, and the free moment it needs; with `--pressure W --free F`
//! a second pass asks the grounded cycle for that centre of pressure within the feet and a
//! small free moment, `Grounding::pressure`, 30 and 10 a choice that works), tracked by
//! stiff joint spring–dampers (`--kp`, default 3·10⁴ N·m/rad), the pelvis' translation free
//! on the contacts and its orientation held by residual torques (`--pelvis`, as OpenSim's
//! residual reduction does; 0 leaves it free; `--pelvis-axes a,b,c` their shares about the
//! fore–aft, vertical and lateral axes, default 1,1,1), the feet's Hunt–Crossley stiffness and
//! dissipation `--stiffness`, `--dissipation` (default the model's stiffness and 10 s/m), the
//! friction's slip speed `--eps` (default the model's, 0.01 m/s). With `--balance` the
//! pelvis' orientation is left to a balance controller (`Balance`, `Balanced`: an ankle
//! strategy of gain `--ankle` and time `--ankle-time`, default 1 and 0.1 s, and a foot
//! placement of gains `--place` and `--place-time`, default 1 and 0.5 s, filtered over
//! `--filter`, default 0.1 s) where the residual torques' shares leave it free, and the
//! program reports that run alone (`--pressure 30 --free 10 --pelvis-axes 0,1,0 --balance`:
//! free to pitch and roll). With `--ff H` the tracking adds a feedforward: the joint torques
//! of a first run, tracked at 3·10⁴ N·m/rad with the pelvis held, over its second cycle,
//! fitted with H harmonics (`Tracking::feedforward_of`), so that a softer `--kp` follows the
//! cycle (`--kp 1000 --ff 20`: the stiff run's forces within 0.05 body weights). With
//! `--reduce N` the residual torques are reduced with the feet's own contacts first
//! (`Tracking::reduced`: N Levenberg–Marquardt iterations over corrections of the leg
//! joints, each running the held cycle once per unknown), and the program reports the run
//! that follows alone: from the held run's state at its second cycle, nothing holding the
//! pelvis, each of `--cycles` cycles (`--pressure 30 --free 10 --reduce 8`: a normal first
//! cycle with the pelvis wholly free, about 2.5 minutes on two cores; `--refresh K` takes the
//! Jacobian by differences every K iterations only, Broyden's updates between: cheaper, but
//! the free pelvis then departs further from its reference), printing how far the pelvis
//! departs from its reference orientation.
//! The run lasts `--cycles` cycles (default 2) and the last one is reported: each foot's
//! vertical and fore–aft ground reaction forces in body weights (first peak, trough, second
//! peak, braking, propulsion, the fore–aft means over the stance's halves), the vertical
//! impulse against weight × time, the fraction of the cycle with no foot on the ground, the
//! residual torque (rms in all and about each world axis), the whole-body angular momentum
//! about the centre of mass (normalised as Herr & Popovic 2008 do), the joint moments (the
//! tracking torques) and the time the run takes.
//!
//! **Mode 1 on muscles**: the same cycle with the 18 muscles taking the sagittal moments
//! over (`muscle_cycle`: activations from static optimisation with reserves at each instant
//! of the tracked cycle, fitted over it, and the excitations under which the activations
//! follow that fit), the tracking left on as reserve actuators: the
//! reserves' torques against the tracking's alone, the forces, and the time per cycle
//! (Radau5 at `--muscle-rtol`, default 1e-4).
//!
//! **Mode 2, muscles** : the body standing on its 18 muscles with constant excitations
//! (`muscle_stance`), then pushed (pelvis pitch rate 1e-4 rad/s): the muscle forces over 1 s.
//!
//! Writes `grf.svg`, `angles.svg`, `moments.svg`, `muscles.svg`, `walk.html` and
//! `gait.csv` in `--out` (default `target/human_gait`).
//!
//! ```text
//! cargo run --release --example human_gait [-- --period 1.1 --kp 30000 --pelvis 30000 --cycles 2]
//! ```

use mbs::plot::{Chart, Series, line_chart};
use mbs::{Efforts, Kinematics, Model, Options, Output, Scheme, Trajectory, WithEfforts};
use mbs_models::human::*;
use std::path::PathBuf;

fn main() -> std::process::ExitCode {
    match gait() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}

/// The options, each with its value's form and default (the module's documentation says
/// what each does).
const USAGE: &str = "\
usage: human_gait [options]
  --period S         the cycle's period (1.1 s)
  --kp K             the joints' tracking stiffness (3e4 N·m/rad)
  --pelvis K         the residual torques' stiffness on the pelvis (3e4 N·m/rad; 0: free)
  --pelvis-axes a,b,c  their shares about the fore–aft, vertical and lateral axes (1,1,1)
  --cycles N         cycles run; the last is reported (2)
  --clearance M      the swinging foot's clearance at mid-swing (0.02 m)
  --pressure W       the second pass' weight on the centre of pressure (0: no second pass)
  --free W           its weight on the free moment (0)
  --dissipation D    the feet's Hunt–Crossley dissipation (10 s/m)
  --stiffness K      the feet's Hunt–Crossley stiffness (the model's)
  --eps V            the friction's slip speed (the model's, 0.01 m/s)
  --balance          the balance controller where the residual torques leave the pelvis free
  --ankle G          its ankle strategy's gain (1)
  --ankle-time T     its ankle strategy's time (0.1 s)
  --place C          its foot placement's gain on position (1)
  --place-time T     its foot placement's gain on velocity (0.5 s)
  --filter T         the placement's filter time (0.1 s)
  --muscle-rtol R    Radau5's rtol on the muscles (1e-4)
  --ff H             feedforward torques: the held cycle's joint torques, H harmonics (0: none)
  --reduce N         residual reduction with the feet's contacts, N iterations, then the
                     pelvis wholly free (0: none)
  --refresh K        its Jacobian by differences every K iterations, Broyden's updates
                     between (1)
  --out DIR          where the plots, animation and CSV go (target/human_gait)
  --help             this text";

/// The options that take a value; `--balance` and `--help` take none.
const VALUED: [&str; 21] = [
    "--period",
    "--kp",
    "--pelvis",
    "--pelvis-axes",
    "--cycles",
    "--clearance",
    "--pressure",
    "--free",
    "--dissipation",
    "--stiffness",
    "--eps",
    "--ankle",
    "--ankle-time",
    "--place",
    "--place-time",
    "--filter",
    "--muscle-rtol",
    "--ff",
    "--reduce",
    "--refresh",
    "--out",
];

fn gait() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    // every argument an option of `USAGE` (a misspelt one would leave its default in
    // place, and the run would not be the one asked for)
    let mut rest = args.iter().skip(1);
    while let Some(a) = rest.next() {
        if a == "--help" || a == "-h" {
            println!("{USAGE}");
            return Ok(());
        }
        if VALUED.contains(&a.as_str()) {
            if rest.next().is_none() {
                return Err(format!("{a} takes a value\n{USAGE}").into());
            }
        } else if a != "--balance" {
            return Err(format!("unknown argument `{a}`\n{USAGE}").into());
        }
    }
    let value = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
    };
    // a number within [low, high] (finite), or the default
    let number = |name: &str, default: f64, low: f64, high: f64| -> Result<f64, String> {
        let x = match value(name) {
            None => return Ok(default),
            Some(v) => v
                .parse::<f64>()
                .map_err(|_| format!("{name} takes a number, not `{v}`"))?,
        };
        if x.is_finite() && (low..=high).contains(&x) {
            Ok(x)
        } else {
            Err(format!(
                "{name} {x} is out of range: take a number in [{}, {}]",
                mbs::error::short(low),
                mbs::error::short(high)
            ))
        }
    };
    let period = number("--period", 1.1, 0.5, 3.0)?;
    let kp = number("--kp", GAIT_KP, 1.0, 1e8)?;
    let pelvis_kp = number("--pelvis", GAIT_PELVIS_KP, 0.0, 1e8)?;
    let cycles = number("--cycles", 2.0, 1.0, 100.0)?.round();
    let clearance = number("--clearance", 0.02, 0.0, 0.2)?;
    let pressure = number("--pressure", 0.0, 0.0, 1e4)?;
    let free = number("--free", 0.0, 0.0, 1e4)?;
    let dissipation = number("--dissipation", GAIT_DISSIPATION, 0.0, 1e3)?;
    let stiffness = number("--stiffness", Human::default().params().k_foot, 1.0, 1e12)?;
    // the residual torques' shares about the three world axes, each in [0, 1]
    let axes: [f64; 3] = match value("--pelvis-axes") {
        None => [1.0; 3],
        Some(v) => {
            let bad = || format!("--pelvis-axes takes three numbers in [0, 1] as a,b,c, not `{v}`");
            let parts = v
                .split(',')
                .map(|x| x.trim().parse::<f64>().map_err(|_| bad()))
                .collect::<Result<Vec<f64>, String>>()?;
            match parts[..] {
                [a, b, c] if [a, b, c].iter().all(|x| (0.0..=1.0).contains(x)) => [a, b, c],
                _ => return Err(bad().into()),
            }
        }
    };
    let balance = args.iter().any(|a| a == "--balance");
    let ankle = [
        number("--ankle", 1.0, 0.0, 100.0)?,
        number("--ankle-time", 0.1, 0.0, 10.0)?,
    ];
    let placement = [
        number("--place", 1.0, 0.0, 100.0)?,
        number("--place-time", 0.5, 0.0, 10.0)?,
    ];
    let filter = number("--filter", 0.1, 1e-3, 10.0)?;
    let eps = number("--eps", Human::default().params().eps_foot, 1e-6, 1.0)?;
    let muscle_rtol = number("--muscle-rtol", 1e-4, 1e-12, 0.1)?;
    let ff = number("--ff", 0.0, 0.0, 100.0)?.round() as usize;
    let reduce = number("--reduce", 0.0, 0.0, 1000.0)?.round() as usize;
    let refresh = number("--refresh", 1.0, 1.0, 1000.0)?.round() as usize;
    let out = PathBuf::from(value("--out").map_or("target/human_gait", |s| s.as_str()));
    std::fs::create_dir_all(&out)?;

    let mut model = Human::default();
    let mut params = model.params().clone();
    params.d_foot = dissipation;
    params.k_foot = stiffness;
    params.eps_foot = eps;
    model.set_params(params)?;
    let info = model.info();
    let mass = total_mass(&model);
    let weight = mass * 9.80665;

    // ---- mode 1: the prescribed cycle
    let table = GaitTable::normal();
    let fitted = GaitReference::fit(&table, info, period, FIT_HARMONICS)?;
    let fitted = fitted.symmetric(info)?;
    let how = Grounding {
        clearance,
        ..Grounding::default()
    };
    let raw = fitted.grounded(
        &model,
        &Grounding {
            iterations: 0,
            ..how.clone()
        },
    )?;
    let clock = std::time::Instant::now();
    let mut grounded = fitted.grounded(&model, &how)?;
    let mut stages = vec![("grounded", grounded.clone())];
    if pressure > 0.0 || free > 0.0 {
        // what the cycle asks of the ground, asked of the grounded cycle
        let then = Grounding {
            pressure: [pressure, free],
            ..how.clone()
        };
        let pressed = grounded.reference.grounded(&model, &then)?;
        // the two passes' iterations, and at most the sum of their largest corrections
        grounded = Grounded {
            largest_change: grounded.largest_change + pressed.largest_change,
            iterations: grounded.iterations + pressed.iterations,
            ..pressed
        };
        stages.push(("pressed", grounded.clone()));
    }
    println!(
        "mode 1: normal cycle of {period} s, {FIT_HARMONICS} harmonics, symmetric, made consistent with the ground \
         (angles corrected by up to {:.1}°, {} iterations, {:.1} s):",
        grounded.largest_change.to_degrees(),
        grounded.iterations,
        clock.elapsed().as_secs_f64()
    );
    stages.insert(0, ("published", raw));
    for (what, g) in &stages {
        let a = g.acceleration;
        println!(
            "  {what:>9}: {:.2} m/s; in double support the feet level within {:.1} mm, sliding apart at up to {:.2} m/s; \
             swing clearance {:+.1} mm from the asked; centre of mass accelerating within \
             [{:.2}, {:.2}] g fore–aft, [{:.2}, {:.2}] g vertically, [{:.2}, {:.2}] g laterally; \
             the centre of pressure the motion needs up to {:.2} m beyond the standing feet fore–aft and {:.2} m \
             laterally, a free moment up to {:.0} N·m",
            g.speed,
            1e3 * g.level,
            g.slip,
            1e3 * g.clearance,
            a[0][0],
            a[0][1],
            a[1][0],
            a[1][1],
            a[2][0],
            a[2][1],
            g.pressure_beyond[0],
            g.pressure_beyond[1],
            g.free_moment
        );
    }
    let reference = grounded.reference;
    let mut feedforward = Vec::new();
    let (q0, qd0) = cycle_start(&model, &reference);
    if ff > 0 {
        // the held cycle's joint torques, as the feedforward of a softer tracking
        let mut held = Tracking::new(reference.clone(), info, GAIT_KP, GAIT_KP / 100.0)?;
        held.pelvis_kp = GAIT_PELVIS_KP;
        held.pelvis_kd = GAIT_PELVIS_KP / 10.0;
        let options = Options {
            q0: Some(q0.clone()),
            qd0: Some(qd0.clone()),
            output: Output::Every { dt: 0.005 },
            ..Options::adaptive(2.0 * period, 1e-5)
        };
        let tr = run(
            WithEfforts::new(model.clone(), held.clone()),
            options,
            "held for the feedforward",
            2.0,
        );
        feedforward = held.feedforward_of(&tr, ff)?;
    }
    if reduce > 0 {
        // residual reduction with the feet's own contacts, then the pelvis wholly free:
        // report that run alone
        let mut held = Tracking::new(reference.clone(), info, kp, kp / 100.0)?;
        held.pelvis_kp = GAIT_PELVIS_KP;
        held.pelvis_kd = GAIT_PELVIS_KP / 10.0;
        let clock = std::time::Instant::now();
        let how = Reduction {
            iterations: reduce,
            refresh,
            ..Reduction::default()
        };
        let reduced = held.reduced(&model, &how)?;
        println!(
            "residual reduction with the feet's contacts ({} iterations, {:.0} s on {} threads): the residual torques \
             holding the pelvis {:.1} → {:.1} N·m rms over the held second cycle, angles corrected by up to {:.1}° more",
            reduced.iterations,
            clock.elapsed().as_secs_f64(),
            std::thread::available_parallelism().map_or(1, |n| n.get()),
            reduced.residual_rms[0],
            reduced.residual_rms[1],
            reduced.largest_change.to_degrees()
        );
        let changes: Vec<String> = reduced
            .changes
            .iter()
            .map(|(joint, c)| format!("{joint} {:.1}°", c.to_degrees()))
            .collect();
        println!(
            "  the largest correction of each leg joint: {}",
            changes.join(", ")
        );
        let mut free = held.clone();
        free.reference = reduced.reference.clone();
        free.pelvis_kp = 0.0;
        free.pelvis_kd = 0.0;
        let (t0, q0, qd0) = reduced.start.clone();
        let options = Options {
            t0,
            q0: Some(q0),
            qd0: Some(qd0),
            output: Output::Every { dt: 0.005 },
            frames: true,
            ..Options::adaptive(t0 + cycles * period, 1e-5)
        };
        let wrapped = WithEfforts::new(model.clone(), free.clone());
        let what = format!(
            "{cycles} cycles with the pelvis wholly free, from the held run's second cycle"
        );
        let tr = run(wrapped.clone(), options, &what, cycles);
        let mut first = None;
        for k in 1..=cycles as usize {
            let end = t0 + k as f64 * period;
            let mut part = tr.clone();
            part.clear_outputs();
            for i in (0..tr.len()).filter(|i| tr.t[*i] <= end + 1e-9) {
                part.push_output(&tr, i);
            }
            println!(
                "  cycle {k} with the pelvis free: the pelvis up to {:.3} rad from its reference orientation so far",
                free.reference.pelvis_departure(&model, &part)
            );
            let forces = CycleForces::of(&model, &free, &part, weight);
            print(&forces, mass);
            first.get_or_insert(forces);
            if tr.t.last().is_none_or(|t| *t < end - 1e-9) {
                break;
            }
        }
        if let Some(forces) = first {
            plots(&forces, mass, &out, &tr, &free, info)?;
        }
        mbs::anim::write_html(&out.join("walk.html"), wrapped.info(), &tr)?;
        tr.write_csv(std::fs::File::create(out.join("gait.csv"))?)?;
        println!(
            "plots of the first free cycle, animation and CSV in {}",
            out.display()
        );
        return Ok(());
    }
    let mut tracking = Tracking::new(reference.clone(), info, kp, kp / 100.0)?;
    tracking.feedforward = feedforward;
    tracking.pelvis_kp = pelvis_kp;
    tracking.pelvis_kd = pelvis_kp / 10.0;
    tracking.pelvis_axes = axes;
    if balance {
        // the pelvis free to pitch and roll on the balance controller: report this run alone
        tracking.balance = Some(Balance::new(&model, &reference, ankle, placement)?);
        let balanced = Balanced::new(&model, tracking.clone(), filter)?;
        let options = Options {
            q0: Some([q0.clone(), vec![0.0; Balanced::NX]].concat()),
            qd0: Some([qd0.clone(), vec![0.0; Balanced::NX]].concat()),
            output: Output::Every { dt: 0.005 },
            frames: true,
            ..Options::adaptive(cycles * period, 1e-5)
        };
        let what = format!("{cycles} cycles balanced");
        let tr = run(
            WithEfforts::new(model.clone(), balanced),
            options,
            &what,
            cycles,
        );
        print(&CycleForces::of(&model, &tracking, &tr, weight), mass);
        tr.write_csv(std::fs::File::create(out.join("gait.csv"))?)?;
        println!("CSV in {}", out.display());
        return Ok(());
    }
    let options = Options {
        q0: Some(q0),
        qd0: Some(qd0),
        output: Output::Every { dt: 0.005 },
        frames: true,
        ..Options::adaptive(cycles * period, 1e-5)
    };
    let wrapped = WithEfforts::new(model.clone(), tracking.clone());
    let tr = run(
        wrapped.clone(),
        options,
        &format!("{cycles} cycles"),
        cycles,
    );
    let forces = CycleForces::of(&model, &tracking, &tr, weight);
    print(&forces, mass);
    if let Some((h, [m, v, height])) = normalised_angular_momentum(&model, &tr, period) {
        println!(
            "  whole-body angular momentum about the centre of mass over the cycle, / (M V H) = / ({m:.1} kg × {v:.2} m/s × {height:.2} m): \
             fore–aft axis [{:+.3}, {:+.3}], vertical [{:+.3}, {:+.3}], lateral [{:+.3}, {:+.3}]",
            h[0][0], h[0][1], h[1][0], h[1][1], h[2][0], h[2][1]
        );
    }
    plots(&forces, mass, &out, &tr, &tracking, info)?;
    mbs::anim::write_html(&out.join("walk.html"), wrapped.info(), &tr)?;
    tr.write_csv(std::fs::File::create(out.join("gait.csv"))?)?;

    // ---- mode 1 on muscles: the muscles take the sagittal moments over, the tracking
    // stays as reserves
    // (from the moments of the tracked run's last whole cycle: none when it fell before)
    match muscle_cycle(&model, &tracking, &tr, &[0.0; NM], 8) {
        Err(why) => println!(
            "mode 1 on 18 muscles: skipped, without a whole tracked cycle to take the moments of ({why})"
        ),
        Ok(cycle) => {
            let (q0, qd0) = cycle.start(&model)?;
            let options = Options {
                q0: Some(q0),
                qd0: Some(qd0),
                output: Output::Every { dt: 0.005 },
                ..Options::adaptive(cycles * period, muscle_rtol)
            };
            let on_muscles = WithEfforts::new(model.clone(), cycle.driven.clone());
            println!(
                "mode 1 on 18 muscles (excitations from static optimisation of the cycle's moments, the tracking as reserves): \
             at rest, the muscles would supply {:.0} % of the moments over the cycle (1 − rms of the reserves' part / rms of the moments), the reserves up to {:.0} N·m",
                100.0 * cycle.share(),
                cycle.moments.iter().map(|m| m[1]).fold(0.0, f64::max)
            );
            let tr_m = run(on_muscles, options, &format!("{cycles} cycles"), cycles);
            let reserves = cycle
                .driven
                .passive
                .tracking
                .as_ref()
                .ok_or("the cycle has no reserves")?;
            println!(
                "  reserve torques at hip flexion, knee and ankle: rms {:.1} N·m, against {:.1} N·m with no muscles",
                reserves.rms_over_last_cycle(info, &tr_m, &MUSCLE_JOINTS)?,
                tracking.rms_over_last_cycle(info, &tr, &MUSCLE_JOINTS)?
            );
            let forces_m = CycleForces::of(&model, &tracking, &tr_m, weight);
            print(&forces_m, mass);
        }
    }

    // ---- mode 2: standing on the muscles, then pushed
    let stance = muscle_stance(&model, 0.1, &[0.5; NM])?;
    let e = &stance.driven.muscles.excitation;
    println!(
        "mode 2: standing on 18 muscles, excitations {:.2}–{:.2}; the equilibrium is {}",
        e.iter().copied().fold(f64::INFINITY, f64::min),
        e.iter().copied().fold(0.0, f64::max),
        format!("{:?}", stance.equilibrium.stability).to_lowercase()
    );
    let mut qd = stance.qd.clone();
    qd[3] += 1e-4;
    let options = Options {
        q0: Some(stance.q.clone()),
        qd0: Some(qd),
        output: Output::Every { dt: 0.01 },
        ..Options::adaptive(1.0, 1e-6)
    };
    let driven = WithEfforts::new(model.clone(), stance.driven.clone());
    let tr = run(driven, options, "pushed, 1 s", 0.0);
    muscle_plot(&model, &out, &stance, &tr)?;
    println!("plots, animation and CSV in {}", out.display());
    Ok(())
}

/// Runs `model` with Radau5 and says how long it took; a run that stops is reported and its
/// trajectory so far kept.
fn run<M: Model + 'static>(model: M, options: Options, what: &str, cycles: f64) -> Trajectory {
    let clock = std::time::Instant::now();
    let tolerance = match options.step {
        mbs::StepControl::Adaptive { rtol, .. } => format!(" at rtol {rtol:.0e}"),
        _ => String::new(),
    };
    match mbs::simulate(model, Scheme::Radau5, options) {
        Ok((tr, stats)) => {
            let time = clock.elapsed().as_secs_f64();
            let per = if cycles > 0.0 {
                format!(", {:.3} s per cycle", time / cycles)
            } else {
                String::new()
            };
            println!(
                "  {what}: {} Radau5 steps{tolerance}, {time:.3} s on one thread{per}",
                stats.steps,
            );
            tr
        }
        Err(e) => {
            println!("  {what}: the run stopped: {e}");
            *e.trajectory
        }
    }
}

/// The printed report of a cycle's forces.
fn print(c: &CycleForces, mass: f64) {
    if c.covered < 0.99 {
        println!(
            "  (the run covers {:.0} % of the cycle: the figures are of that part only)",
            100.0 * c.covered
        );
    }
    let f = |x: Option<f64>| x.map_or("—".to_string(), |v| format!("{v:+.2}"));
    for (k, foot) in ["right", "left"].iter().enumerate() {
        let g = c.figures(k);
        println!(
            "  {foot:>5} foot, vertical: first peak {}, trough {}, second peak {}; fore–aft: braking {}, propulsion {}, \
             mean {} over the stance's first half, {} over its second (body weights)",
            f(g.first_peak),
            f(g.trough),
            f(g.second_peak),
            f(g.braking),
            f(g.propulsion),
            f(g.first_half.map(|v| (v * 100.0).round() / 100.0)),
            f(g.second_half.map(|v| (v * 100.0).round() / 100.0)),
        );
    }
    println!(
        "        [normal gait: peaks 1.0–1.3, trough 0.6–0.9; braking in the first half, propulsion in the second]"
    );
    let landing = |v: Option<[f64; 3]>| {
        v.map_or("—".to_string(), |[x, y, z]| {
            format!("{y:+.2} vertically, {x:+.2} fore–aft, {z:+.2} laterally")
        })
    };
    println!(
        "  the feet came down at (their lowest point's velocity before they touched, m/s): right {}; left {}",
        landing(c.landing[0]),
        landing(c.landing[1])
    );
    println!(
        "  vertical impulse / (weight × time) = {:.3} [within 5 % of 1]; no foot on the ground during {:.0} % of the cycle",
        c.impulse_ratio,
        100.0 * c.airborne
    );
    println!(
        "  residual torque on the pelvis: rms {:.0} N·m, peak {:.0} N·m ({:.2} and {:.2} N·m/kg); \
         rms about the fore–aft axis {:.0}, the vertical {:.0}, the lateral {:.0} N·m",
        c.residual_rms,
        c.residual_peak,
        c.residual_rms / mass,
        c.residual_peak / mass,
        c.residual_axes[0],
        c.residual_axes[1],
        c.residual_axes[2]
    );
}

fn plots(
    c: &CycleForces,
    mass: f64,
    out: &std::path::Path,
    tr: &Trajectory,
    tracking: &Tracking,
    info: &mbs::ModelInfo,
) -> Result<(), Box<dyn std::error::Error>> {
    let pick = |k: usize, j: usize| -> Vec<(f64, f64)> {
        c.grf
            .iter()
            .map(|(p, r, l)| (*p, if k == 0 { r[j] } else { l[j] }))
            .collect()
    };
    line_chart(
        &out.join("grf.svg"),
        &chart("Ground reaction forces", "force (body weights)"),
        &[
            Series::new("right, vertical", pick(0, 1)),
            Series::new("right, fore-aft", pick(0, 0)),
            Series::new("left, vertical", pick(1, 1)),
            Series::new("left, fore-aft", pick(1, 0)),
        ],
    )?;
    let n = Human::NQ;
    let period = tracking.reference.period;
    let joints = ["hip_flexion[0]", "knee[0]", "ankle[0]"];
    let mut angles = Vec::new();
    let mut moments = Vec::new();
    for name in joints {
        let i = info
            .dofs
            .iter()
            .position(|d| *d == name)
            .ok_or("no joint")?;
        let k = tracking
            .reference
            .joints
            .iter()
            .position(|(c, _)| *c == i)
            .ok_or("not tracked")?;
        let cycle = |t: f64| 100.0 * t / period;
        angles.push(Series::new(
            format!("{name}, simulated"),
            (0..tr.len())
                .map(|s| (cycle(tr.t[s]), tr.q(s)[i].to_degrees()))
                .collect(),
        ));
        angles.push(Series::new(
            format!("{name}, reference"),
            (0..tr.len())
                .map(|s| {
                    (
                        cycle(tr.t[s]),
                        tracking.reference.joint(k, tr.t[s])[0].to_degrees(),
                    )
                })
                .collect(),
        ));
        moments.push(Series::new(
            name,
            (0..tr.len())
                .map(|s| {
                    let tau = tracking
                        .torques(tr.t[s], &tr.q(s)[..n], &tr.qd(s)[..n])
                        .find(|(c, _)| *c == i)
                        .map_or(0.0, |(_, v)| v);
                    (cycle(tr.t[s]), tau / mass)
                })
                .collect(),
        ));
    }
    line_chart(
        &out.join("angles.svg"),
        &chart("Joint angles, right leg", "angle (°)"),
        &angles,
    )?;
    line_chart(
        &out.join("moments.svg"),
        &chart(
            "Joint moments, right leg (tracking torques)",
            "moment (N·m/kg)",
        ),
        &moments,
    )?;
    Ok(())
}

fn muscle_plot(
    model: &Human,
    out: &std::path::Path,
    stance: &MuscleStance,
    tr: &Trajectory,
) -> Result<(), Box<dyn std::error::Error>> {
    let n = Human::NQ;
    let muscles = &stance.driven.muscles;
    let mut kin = Kinematics::new::<Human>();
    let mut lines: Vec<Series> = muscles.units[..NM / 2]
        .iter()
        .map(|(u, _)| Series::new(&u.name, Vec::new()))
        .collect();
    let mut model = model.clone();
    for s in 0..tr.len() {
        mbs::charts::use_charts_of(&mut model, tr, s);
        model.motion(tr.t[s], &tr.q(s)[..n], &tr.qd(s)[..n], &mut kin);
        let x = &tr.qd(s)[n..];
        for (i, line) in lines.iter_mut().enumerate() {
            let (unit, path) = &muscles.units[i];
            let (a, lm) = (x[17 + i], x[17 + NM + i]);
            if let Ok(f) = unit.fibre(path.length(&kin).0, a, lm) {
                line.points.push((tr.t[s], f.tendon_force));
            }
        }
    }
    let mut c = chart(
        "Muscle forces, right leg: standing, pushed",
        "tendon force (N)",
    );
    c.x_label = "t (s)".into();
    line_chart(&out.join("muscles.svg"), &c, &lines)?;
    Ok(())
}

fn chart(title: &str, y: &str) -> Chart {
    Chart::linear(title, "gait cycle (%)", y)
}
