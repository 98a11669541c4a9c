//! Work–precision diagrams: what accuracy costs in CPU time, per scheme, on the canonical
//! models of `tests/reference/MODELS.md` (the tool is `mbs::work_precision`).
//!
//! ```text
//! cargo run --release --example work_precision -- --model dpend --out docs/figures
//! ```
//!
//! `--model` is seed2dof, dpend, chain8, dampedchain, slidercrank, slidercrankb, hexapod,
//! fourbar, pendulum3, dpendcart, fastlink, tumble, top or all; `--out DIR` writes
//! `DIR/wp_MODEL.csv` and `DIR/wp_MODEL.svg`; `--repeats N` times each run N times and keeps
//! the best (default 5; fewer for a run past 1 s). Each model in its natural setting:
//!
//! - seed2dof to 10 s against its exact modal solution (100 samples, every 0.1 s);
//! - dpend to 2 s against `tests/reference/dpend.json` (SciPy DOP853 at rtol = atol = 1e-13)
//!   at t = 0.5, 1, 2 s, where that reference is reproducible to 1e-11;
//! - chain8 to 2 s against a self-computed reference (DOPRI5 at rtol 1e-13, checked by RK4
//!   at h = 5e-5), every 0.05 s;
//! - dampedchain (six bars, a damper in every joint: decaying modes to 3.1e3 1/s) to 2 s
//!   against a self-computed reference (DOPRI5 at rtol 1e-13, checked by Radau5 at 1e-12),
//!   every 0.05 s, with RKC (adaptive, and fixed steps from 20 ms) beside the others: the
//!   motion it is for;
//! - slidercrank, form (a) (three coordinates, two loop constraints) to 2 s: projection for
//!   the explicit schemes, BDF and Radau5, index 3 for the Newmark family and Radau5; against
//!   form (b) (θ alone, the loop in closed form) computed by DOPRI5 at rtol 1e-13 (checked by
//!   RK4 at h = 5e-5) and mapped to (θ, ψ, s) and their rates, every 0.05 s;
//! - slidercrankb, form (b) itself (θ alone, no constraint: what the closed form saves) to
//!   2 s against the same reference, every 0.05 s, with the schemes of an unconstrained model;
//! - hexapod, free-floating, no contact, to 1 s, tumbling: the declared pose with the
//!   MODELS.md test-state velocities qd_i = 0.7 cos(0.9 i + 0.2) (from rest it would fall
//!   with its legs still, exactly for every scheme of order ≥ 2); against a self-computed
//!   reference (DOPRI5 at rtol 1e-13, checked by RK4 at h = 5e-5), every 0.05 s;
//! - the loops fourbar (to 2 s, self-computed: DOPRI5 with projection at rtol 1e-13, checked by
//!   Radau5 with projection, every 0.05 s), pendulum3 (to t = 1 against
//!   `tests/reference/pendulum3.json`), dpendcart (dpend in Cartesian coordinates, each bar
//!   free in the plane and the hinges as four constraints, to 2 s against
//!   `tests/reference/dpend.json` mapped to the bars' centres and absolute angles, at t =
//!   0.5, 1, 2 s) and fastlink (to 30 ms against
//!   `tests/reference/fastlink.json`, SymPy and SciPy DOP853 at 1e-13, every 1 ms), each over
//!   rtol 1e-4 … 1e-10 with every constraint method a scheme offers: DOPRI5 and BDF with
//!   projection, Radau5 and generalized-α at index 3 and with projection, HHT at index 3, and
//!   Radau5 and generalized-α in the stabilized index-2 form where the scheme accepts it (the
//!   output says when it is refused and skipped).
//!
//! - tumble (`TumbleBall`, the body on a spherical joint) to 10 s from MODELS.md's start,
//!   every 0.25 s, against a self-computed reference (DOPRI5 at rtol 1e-13, checked by Radau5
//!   at 1e-13), with DOPRI5, Radau5, BDF and generalized-α on its ZYX twin (`Tumble`, which
//!   survives this start) measured the same way (rotations as matrices and angular
//!   velocities, `Study::euler_angles`);
//! - top (`Top`, on its spherical joint) to 2 s, every 0.05 s, likewise; its ZYX twin
//!   (`TopZyx`) stops at the axis's first passage through the vertical, and its rows say so.
//!
//! Every study prints its table (failures included), the cheapest run per scheme to 3, 5, 7
//! and 9 significant digits, and how long it took. Points with no correct digit (error ≥ 1)
//! are in the table and the CSV but not on the chart.

use mbs_models::chain8;
use mbs_models::damped_chain;
use mbs_models::dpend;
use mbs_models::dpend_cartesian;
use mbs_models::fastlink;
use mbs_models::fourbar;
use mbs_models::hexapod;
use mbs_models::pendulum3;
use mbs_models::seed2dof;
use mbs_models::slidercrank;
use mbs_models::top;
use mbs_models::tumble;

use clap::Parser;
use mbs::work_precision::{Reference, Setting, Study, Sweep, WorkPrecision, decades, halvings};
use mbs::{
    BdfParams, ConstraintMethod, ConstraintOptions, Failure, GenAlphaParams, HhtParams, Model,
    NewmarkParams, Options, Scheme, Simulation,
};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Parser, Debug)]
struct Args {
    /// seed2dof, dpend, chain8, dampedchain, slidercrank, slidercrankb, hexapod, fourbar,
    /// pendulum3, dpendcart, fastlink, tumble, top or all
    #[arg(long, default_value = "all")]
    model: String,
    /// write DIR/wp_MODEL.csv and DIR/wp_MODEL.svg
    #[arg(long)]
    out: Option<PathBuf>,
    /// timed repeats per run, the best kept (1 or more)
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u16).range(1..))]
    repeats: u16,
}

const MODELS: [&str; 13] = [
    "seed2dof",
    "dpend",
    "chain8",
    "dampedchain",
    "slidercrank",
    "slidercrankb",
    "hexapod",
    "fourbar",
    "pendulum3",
    "dpendcart",
    "fastlink",
    "tumble",
    "top",
];

fn newmark() -> Scheme {
    Scheme::Newmark(NewmarkParams::default())
}
fn hht() -> Scheme {
    Scheme::Hht(HhtParams::default())
}
fn gen_alpha() -> Scheme {
    Scheme::GenAlpha(GenAlphaParams::default())
}
fn bdf() -> Scheme {
    Scheme::Bdf(BdfParams::default())
}

/// Times t_end/n, 2 t_end/n, … t_end.
/// A reference computed by mbs: DOPRI5 at rtol 1e-13 at `times`, checked by `check`.
fn computed<M: Model + Clone + 'static>(
    model: &M,
    times: Vec<f64>,
    check: (Scheme, Setting),
    options: &mbs::Options,
) -> Reference {
    let dopri5 = (Scheme::Dopri5, Setting::Rtol(1e-13));
    Reference::compute(model, times, dopri5, Some(check), options).expect("reference run")
}

fn samples(t_end: f64, n: usize) -> Vec<f64> {
    (1..=n).map(|k| t_end * k as f64 / n as f64).collect()
}

/// States of `tests/reference/NAME.json` at `times` (q then qd).
fn json_reference(name: &str, times: &[f64]) -> Vec<Vec<f64>> {
    let path = format!("{}/tests/reference/{name}.json", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let json: serde_json::Value = serde_json::from_str(&text).expect("json");
    let states = json["states"].as_array().expect("states");
    times
        .iter()
        .map(|&t| {
            let s = states
                .iter()
                .find(|s| (s["t"].as_f64().expect("t") - t).abs() < 1e-12)
                .unwrap_or_else(|| panic!("{name}.json has no state at t = {t}"));
            ["q", "qd"]
                .iter()
                .flat_map(|k| s[*k].as_array().expect("array").iter())
                .map(|x| x.as_f64().expect("number"))
                .collect()
        })
        .collect()
}

/// The state of `tests/reference/pendulum3.json` at t = 1: (x, y, ẋ, ẏ).
fn pendulum3_reference() -> Vec<f64> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/reference/pendulum3.json"
    );
    let text = std::fs::read_to_string(path).expect("tests/reference/pendulum3.json");
    let json: serde_json::Value = serde_json::from_str(&text).expect("json");
    ["x", "y", "xd", "yd"]
        .iter()
        .map(|k| json["state"][*k].as_f64().expect("number"))
        .collect()
}

/// The sweeps of a closed-loop model over `rtols`: DOPRI5 and BDF with projection, Radau5
/// and generalized-α at index 3 and with projection, HHT at index 3, and Radau5 and
/// generalized-α at stabilized index 2 where the scheme accepts it (said when skipped).
fn loop_sweeps<M: Model + Default + 'static>(rtols: &[f64]) -> Vec<Sweep> {
    let proj = ConstraintMethod::Projection;
    let idx3 = ConstraintMethod::Index3;
    let mut v = vec![
        Sweep::adaptive(Scheme::Dopri5, rtols).with_constraints(proj),
        Sweep::adaptive(bdf(), rtols).with_constraints(proj),
        Sweep::adaptive(Scheme::Radau5, rtols).with_constraints(idx3),
        Sweep::adaptive(Scheme::Radau5, rtols).with_constraints(proj),
        Sweep::adaptive(gen_alpha(), rtols).with_constraints(idx3),
        Sweep::adaptive(gen_alpha(), rtols).with_constraints(proj),
        Sweep::adaptive(hht(), rtols).with_constraints(idx3),
    ];
    for scheme in [Scheme::Radau5, gen_alpha()] {
        let probe = Options {
            constraints: ConstraintOptions {
                method: ConstraintMethod::Index2,
                ..ConstraintOptions::default()
            },
            ..Options::adaptive(1.0, 1e-6)
        };
        match Simulation::new(M::default(), scheme, probe) {
            Err(e) if matches!(e.kind, Failure::ConstraintsUnsupported { .. }) => {
                println!("skipped {} (index2): {}", scheme.name(), e.kind);
            }
            _ => v.push(Sweep::adaptive(scheme, rtols).with_constraints(ConstraintMethod::Index2)),
        }
    }
    v
}

/// The sweeps of an unconstrained model: adaptive schemes over decades of rtol, fixed-step
/// ones over halvings of h.
struct Plan {
    dopri5: (i32, i32),
    bdf: (i32, i32),
    radau3: (i32, i32),
    radau5: (i32, i32),
    order2: (i32, i32),
    rk4: (f64, usize),
    midpoint: (f64, usize),
    euler: Option<(f64, usize)>,
}

/// The plan of the chains and of the slider-crank's closed form (2 s).
fn chain_plan() -> Plan {
    Plan {
        dopri5: (3, 11),
        bdf: (3, 12),
        radau3: (3, 10),
        radau5: (3, 12),
        order2: (3, 8),
        rk4: (0.01, 7),
        midpoint: (0.005, 6),
        euler: None,
    }
}

fn sweeps(p: &Plan) -> Vec<Sweep> {
    let mut v = vec![
        Sweep::adaptive(Scheme::Dopri5, &decades(p.dopri5.0, p.dopri5.1)),
        Sweep::fixed(Scheme::Rk4, &halvings(p.rk4.0, p.rk4.1)),
        Sweep::adaptive(bdf(), &decades(p.bdf.0, p.bdf.1)),
        Sweep::adaptive(Scheme::Radau3, &decades(p.radau3.0, p.radau3.1)),
        Sweep::adaptive(Scheme::Radau5, &decades(p.radau5.0, p.radau5.1)),
        Sweep::adaptive(gen_alpha(), &decades(p.order2.0, p.order2.1)),
        Sweep::adaptive(hht(), &decades(p.order2.0, p.order2.1)),
        Sweep::adaptive(newmark(), &decades(p.order2.0, p.order2.1)),
        Sweep::fixed(
            Scheme::ImplicitMidpoint,
            &halvings(p.midpoint.0, p.midpoint.1),
        ),
    ];
    if let Some((h, n)) = p.euler {
        v.push(Sweep::fixed(Scheme::ExplicitEuler, &halvings(h, n)));
    }
    v
}

/// A study of an unconstrained model over 2 s with the chains' plan, against DOPRI5 at rtol
/// 1e-13 checked by RK4 at h = 5e-5, every 0.05 s (chain8, the slider-crank's form (b)).
fn chain_study<M: Model + Clone + 'static>(model: &M, name: &str, repeats: usize) -> WorkPrecision {
    let r = computed(
        model,
        samples(2.0, 40),
        (Scheme::Rk4, Setting::Step(5e-5)),
        &mbs::Options::default(),
    );
    let s = Study {
        sweeps: sweeps(&chain_plan()),
        repeats,
        ..Study::new(name, r)
    };
    s.run(model).expect("study")
}

fn study(name: &str, repeats: usize) -> WorkPrecision {
    let finish = |s: Study| Study { repeats, ..s };
    match name {
        "seed2dof" => {
            let r = Reference::exact(
                "modal solution q(t) = V cos(Wt) Vᵀ q0 (models/src/seed2dof.rs)",
                samples(10.0, 100),
                seed2dof::exact_state,
            );
            let plan = Plan {
                dopri5: (3, 12),
                bdf: (3, 11),
                radau3: (3, 11),
                radau5: (3, 12),
                order2: (3, 8),
                rk4: (0.08, 9),
                midpoint: (4e-3, 6),
                euler: Some((1e-3, 3)),
            };
            let s = finish(Study {
                sweeps: sweeps(&plan),
                ..Study::new("seed2dof", r)
            });
            s.run(&seed2dof::Seed2dof::default()).expect("study")
        }
        "dpend" => {
            let times = vec![0.5, 1.0, 2.0];
            let states = json_reference("dpend", &times);
            let r = Reference::data(
                "tests/reference/dpend.json (SymPy equations, SciPy DOP853 at rtol = atol = 1e-13; reproducible to 8e-12 at t = 2 s)",
                times,
                states,
            );
            let plan = Plan {
                dopri5: (3, 12),
                bdf: (3, 12),
                radau3: (3, 12),
                radau5: (3, 12),
                order2: (3, 9),
                rk4: (0.02, 8),
                midpoint: (0.01, 7),
                euler: None,
            };
            let s = finish(Study {
                sweeps: sweeps(&plan),
                ..Study::new("dpend", r)
            });
            s.run(&dpend::DoublePendulum::default()).expect("study")
        }
        "chain8" => chain_study(&chain8::Chain8::default(), "chain8", repeats),
        "dampedchain" => {
            let model = damped_chain::DampedChain::default();
            let r = computed(
                &model,
                samples(2.0, 40),
                (Scheme::Radau5, Setting::Rtol(1e-12)),
                &mbs::Options::default(),
            );
            // RK4 below the fast modes' limit, 2.785/ρ ≈ 0.9 ms
            let plan = Plan {
                rk4: (5e-4, 6),
                ..chain_plan()
            };
            // the motion RKC is for: its decaying modes (to 3.1e3 1/s) hold the explicit
            // schemes' steps, RKC's stages grow as their square root
            let mut sweeps = sweeps(&plan);
            sweeps.insert(1, Sweep::adaptive(Scheme::Rkc, &decades(2, 8)));
            sweeps.insert(2, Sweep::fixed(Scheme::Rkc, &halvings(0.02, 7)));
            let s = finish(Study {
                sweeps,
                ..Study::new("dampedchain", r)
            });
            s.run(&model).expect("study")
        }
        "slidercrank" => {
            let closed = slidercrank::SliderCrankClosed::default();
            let r = computed(
                &closed,
                samples(2.0, 40),
                (Scheme::Rk4, Setting::Step(5e-5)),
                &mbs::Options::default(),
            )
            .map(
                "form (b) (θ alone, loop in closed form) mapped to form (a)'s (θ, ψ, s) and rates",
                |_, y| slidercrank::form_a_state(y[0], y[1]).to_vec(),
            );
            let proj = ConstraintMethod::Projection;
            let idx3 = ConstraintMethod::Index3;
            let sweeps = vec![
                Sweep::adaptive(Scheme::Dopri5, &decades(3, 11)).with_constraints(proj),
                Sweep::fixed(Scheme::Rk4, &halvings(0.01, 7)).with_constraints(proj),
                Sweep::adaptive(bdf(), &decades(3, 10)).with_constraints(proj),
                Sweep::adaptive(Scheme::Radau5, &decades(3, 11)).with_constraints(proj),
                Sweep::adaptive(Scheme::Radau5, &decades(3, 11)).with_constraints(idx3),
                Sweep::adaptive(gen_alpha(), &decades(3, 8)).with_constraints(idx3),
                Sweep::fixed(gen_alpha(), &halvings(2e-3, 6))
                    .with_constraints(idx3)
                    .labelled("gen-alpha (index3, fixed h)"),
                Sweep::adaptive(hht(), &decades(3, 8)).with_constraints(idx3),
                Sweep::fixed(newmark(), &halvings(4e-3, 6)).with_constraints(idx3),
            ];
            let s = finish(Study {
                sweeps,
                ..Study::new("slidercrank (a)", r)
            });
            s.run(&slidercrank::SliderCrank::default()).expect("study")
        }
        "slidercrankb" => chain_study(
            &slidercrank::SliderCrankClosed::default(),
            "slidercrank (b)",
            repeats,
        ),
        "hexapod" => {
            let model = hexapod::Hexapod::default();
            // tumbling: the declared pose with the MODELS.md test-state velocities (from rest
            // it would fall freely with its legs still, q quadratic in t: exact for every
            // scheme of order ≥ 2)
            let options = mbs::Options {
                qd0: Some(
                    (0..24)
                        .map(|i| 0.7 * (0.9 * i as f64 + 0.2).cos())
                        .collect(),
                ),
                ..mbs::Options::default()
            };
            let r = computed(
                &model,
                samples(1.0, 20),
                (Scheme::Rk4, Setting::Step(5e-5)),
                &options,
            );
            let plan = Plan {
                dopri5: (3, 11),
                bdf: (3, 10),
                radau3: (3, 10),
                radau5: (3, 11),
                order2: (3, 8),
                rk4: (0.08, 7),
                midpoint: (0.02, 6),
                euler: None,
            };
            let s = finish(Study {
                sweeps: sweeps(&plan),
                options,
                ..Study::new("hexapod (free, tumbling)", r)
            });
            s.run(&model).expect("study")
        }
        "fourbar" => {
            let model = fourbar::FourBar::default();
            let options = mbs::Options {
                constraints: ConstraintOptions {
                    method: ConstraintMethod::Projection,
                    ..ConstraintOptions::default()
                },
                ..mbs::Options::default()
            };
            let r = computed(
                &model,
                samples(2.0, 40),
                (Scheme::Radau5, Setting::Rtol(1e-13)),
                &options,
            );
            let s = finish(Study {
                sweeps: loop_sweeps::<fourbar::FourBar>(&decades(4, 10)),
                ..Study::new("fourbar", r)
            });
            s.run(&model).expect("study")
        }
        "pendulum3" => {
            let r = Reference::data(
                "tests/reference/pendulum3.json (the test problem's published reference at t = 1)",
                vec![1.0],
                vec![pendulum3_reference()],
            );
            let s = finish(Study {
                sweeps: loop_sweeps::<pendulum3::Pendulum3>(&decades(4, 10)),
                ..Study::new("pendulum3", r)
            });
            s.run(&pendulum3::Pendulum3::default()).expect("study")
        }
        "dpendcart" => {
            // dpend's external reference (relative angles) mapped to the bars' centres and
            // absolute angles, and their rates
            let times = vec![0.5, 1.0, 2.0];
            let states = json_reference("dpend", &times)
                .into_iter()
                .map(|y| dpend_cartesian::from_relative(&y))
                .collect();
            let r = Reference::data(
                "tests/reference/dpend.json (SymPy equations in relative angles, SciPy DOP853 at rtol = atol = 1e-13) mapped to the bars' centres and absolute angles",
                times,
                states,
            );
            let s = finish(Study {
                sweeps: loop_sweeps::<dpend_cartesian::DoublePendulumCartesian>(&decades(4, 10)),
                ..Study::new("dpendcart", r)
            });
            s.run(&dpend_cartesian::DoublePendulumCartesian::default())
                .expect("study")
        }
        "fastlink" => {
            let times = samples(0.03, 30);
            let states = json_reference("fastlink", &times);
            let r = Reference::data(
                "tests/reference/fastlink.json (SymPy in absolute coordinates, SciPy DOP853 at rtol = atol = 1e-13; SciPy Radau agrees to 2e-10)",
                times,
                states,
            );
            let s = finish(Study {
                sweeps: loop_sweeps::<fastlink::FastLink>(&decades(4, 10)),
                ..Study::new("fastlink", r)
            });
            s.run(&fastlink::FastLink::default()).expect("study")
        }
        "tumble" => {
            // its ZYX twin survives this start (closest |cos b| 0.19)
            let plan = Plan {
                dopri5: (3, 12),
                bdf: (3, 11),
                radau3: (3, 11),
                radau5: (3, 12),
                order2: (3, 9),
                rk4: (0.02, 8),
                midpoint: (0.01, 7),
                euler: None,
            };
            let twin = vec![
                Sweep::adaptive(Scheme::Dopri5, &decades(3, 12)).labelled("dopri5 ZYX"),
                Sweep::adaptive(Scheme::Radau5, &decades(3, 12)).labelled("radau5 ZYX"),
                Sweep::adaptive(bdf(), &decades(3, 11)).labelled("bdf ZYX"),
                Sweep::adaptive(gen_alpha(), &decades(3, 9)).labelled("gen-alpha ZYX"),
            ];
            let (model, zyx) = (tumble::TumbleBall::default(), tumble::Tumble::default());
            rotation_study(
                "tumble",
                (&model, &zyx),
                samples(10.0, 40),
                &plan,
                twin,
                finish,
            )
        }
        "top" => {
            // its ZYX twin stops at the first passage of the axis through the vertical (its
            // rows say so)
            let plan = Plan {
                dopri5: (3, 12),
                bdf: (3, 11),
                radau3: (3, 11),
                radau5: (3, 12),
                order2: (3, 9),
                rk4: (2e-3, 7),
                midpoint: (1e-3, 7),
                euler: None,
            };
            let twin =
                vec![Sweep::adaptive(Scheme::Dopri5, &[1e-4, 1e-7, 1e-10]).labelled("dopri5 ZYX")];
            let (model, zyx) = (top::Top::default(), top::TopZyx::default());
            rotation_study("top", (&model, &zyx), samples(2.0, 40), &plan, twin, finish)
        }
        other => {
            eprintln!("unknown model `{other}`: use {} or all", MODELS.join(", "));
            std::process::exit(2);
        }
    }
}

/// A rotation model on its spherical joint and its twin on ZYX Euler angles (angles q[0..3]),
/// the same motion: the model's sweeps of `plan` and the twin's `twin_sweeps`, both measured
/// by rotation matrices and angular velocities against one reference (DOPRI5 on the model
/// at rtol 1e-13, checked by Radau5 at 1e-13), in one table.
fn rotation_study<M, Z>(
    name: &str,
    (model, twin): (&M, &Z),
    times: Vec<f64>,
    plan: &Plan,
    twin_sweeps: Vec<Sweep>,
    finish: impl Fn(Study) -> Study,
) -> WorkPrecision
where
    M: Model + Clone + 'static,
    Z: Model + Clone + 'static,
{
    let r = computed(
        model,
        times,
        (Scheme::Radau5, Setting::Rtol(1e-13)),
        &mbs::Options::default(),
    );
    let s = finish(Study {
        sweeps: sweeps(plan),
        ..Study::new(format!("{name} (Tball)"), r.clone())
    });
    let mut wp = s.run(model).expect("study");
    let euler = finish(Study {
        sweeps: twin_sweeps,
        euler_angles: vec![[0, 1, 2]],
        ..Study::new(format!("{name} (ZYX)"), r)
    });
    wp.rows.extend(euler.run(twin).expect("study").rows);
    wp.title = format!("{name} (Tball, and ZYX angles)");
    wp
}

/// The cheapest run per label reaching `digits` (mescd), sorted by CPU time.
fn summary(wp: &WorkPrecision, digits: f64) {
    let list: Vec<String> = wp
        .cheapest_per_label(digits)
        .iter()
        .map(|r| {
            format!(
                "{} {:.2} ms ({})",
                r.label,
                r.cpu.as_secs_f64() * 1e3,
                r.setting
            )
        })
        .collect();
    println!(
        "  {digits} digits: {}",
        if list.is_empty() {
            "none".into()
        } else {
            list.join(", ")
        }
    );
}

fn main() {
    let args = Args::parse();
    let names: Vec<&str> = if args.model == "all" {
        MODELS.to_vec()
    } else {
        vec![args.model.as_str()]
    };
    fn fail(path: &std::path::Path, e: impl std::fmt::Display) -> ! {
        eprintln!("error: cannot write {}: {e}", path.display());
        std::process::exit(1);
    }
    if let Some(dir) = &args.out {
        if let Err(e) = std::fs::create_dir_all(dir) {
            eprintln!("error: cannot create {}: {e}", dir.display());
            std::process::exit(1);
        }
        // every file writable before the studies run, not after
        for name in &names {
            for file in [format!("wp_{name}.csv"), format!("wp_{name}.svg")] {
                let path = dir.join(file);
                let open = std::fs::OpenOptions::new()
                    .append(true)
                    .create(true)
                    .open(&path);
                if let Err(e) = open {
                    fail(&path, e);
                }
            }
        }
    }
    for name in names {
        let start = Instant::now();
        let wp = study(name, args.repeats.into());
        println!("{wp}");
        println!("cheapest run per scheme to d significant digits at t_end:");
        for d in [3.0, 5.0, 7.0, 9.0] {
            summary(&wp, d);
        }
        if let Some(dir) = &args.out {
            let csv = dir.join(format!("wp_{name}.csv"));
            std::fs::write(&csv, wp.to_csv()).unwrap_or_else(|e| fail(&csv, e));
            let svg = dir.join(format!("wp_{name}.svg"));
            wp.write_svg(&svg).unwrap_or_else(|e| fail(&svg, e));
            println!("wrote {} and {}", csv.display(), svg.display());
        }
        println!(
            "{name}: study done in {:.1} s\n",
            start.elapsed().as_secs_f64()
        );
    }
}
