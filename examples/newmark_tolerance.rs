//! What rtol buys the Newmark family: the mixed error over (q, qd) (Test Set for IVP Solvers,
//! floor 0.01, at the last sampled time: `mbs::work_precision`) of gen-alpha (ρ∞ = 0.8), hht
//! (α = −0.05) and trapezoidal newmark at rtol 1e-4 … 1e-10, with the constraints at index 3,
//! index 2 and by projection, on pendulum3 (to t = 1, `tests/reference/pendulum3.json`),
//! slider-crank form (a) (to 2 s, reference from form (b)), the four-bar (to 2 s,
//! self-computed reference: DOPRI5 at rtol 1e-13, checked by RK4 at h = 5e-5) and dpend (to
//! 2 s, `tests/reference/dpend.json`).
//!
//! ```text
//! cargo run --release --example newmark_tolerance [-- MODEL]
//! ```
//!
//! MODEL is pendulum3, slidercrank, fourbar, dpend or all (default). Each row prints the
//! digits (−log10 of the mixed error), the digits minus −log10 rtol ("short", positive when
//! the run falls short of rtol), the steps and the rejections.

use mbs::work_precision::{Reference, Setting, Study, Sweep, WorkPrecision, decades};
use mbs::{ConstraintMethod, GenAlphaParams, HhtParams, NewmarkParams, Scheme};
use mbs_models::{dpend, fourbar, pendulum3, slidercrank};

fn schemes() -> [(&'static str, Scheme); 3] {
    [
        ("gen-alpha", Scheme::GenAlpha(GenAlphaParams::default())),
        ("hht", Scheme::Hht(HhtParams::default())),
        ("newmark", Scheme::Newmark(NewmarkParams::default())),
    ]
}

fn samples(t_end: f64, n: usize) -> Vec<f64> {
    (1..=n).map(|k| t_end * k as f64 / n as f64).collect()
}

fn json(name: &str) -> serde_json::Value {
    let path = format!("{}/tests/reference/{name}.json", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).expect("reference file");
    serde_json::from_str(&text).expect("reference JSON")
}

fn pendulum3_reference() -> Reference {
    let s = &json("pendulum3")["state"];
    let y = ["x", "y", "xd", "yd"].map(|k| s[k].as_f64().expect("number"));
    Reference::data(
        "tests/reference/pendulum3.json",
        vec![1.0],
        vec![y.to_vec()],
    )
}

fn dpend_reference() -> Reference {
    let j = json("dpend");
    let times = vec![0.5, 1.0, 2.0];
    let states = j["states"].as_array().expect("states");
    let ys = times
        .iter()
        .map(|&t| {
            let s = states
                .iter()
                .find(|s| (s["t"].as_f64().expect("t") - t).abs() < 1e-12)
                .expect("state at t");
            ["q", "qd"]
                .iter()
                .flat_map(|k| s[*k].as_array().expect("array").iter())
                .map(|x| x.as_f64().expect("number"))
                .collect()
        })
        .collect();
    Reference::data("tests/reference/dpend.json", times, ys)
}

fn slidercrank_reference() -> Reference {
    let closed = slidercrank::SliderCrankClosed::default();
    Reference::compute(
        &closed,
        samples(2.0, 40),
        (Scheme::Dopri5, Setting::Rtol(1e-13)),
        None,
        &mbs::Options::default(),
    )
    .expect("reference run")
    .map("form (b) mapped to form (a)", |_, y| {
        slidercrank::form_a_state(y[0], y[1]).to_vec()
    })
}

fn fourbar_reference() -> Reference {
    Reference::compute(
        &fourbar::FourBar::default(),
        samples(2.0, 40),
        (Scheme::Dopri5, Setting::Rtol(1e-13)),
        Some((Scheme::Rk4, Setting::Step(5e-5))),
        &mbs::Options::default(),
    )
    .expect("reference run")
}

fn study(title: &str, reference: Reference, constrained: bool) -> Study {
    let methods: &[Option<ConstraintMethod>] = if constrained {
        &[
            Some(ConstraintMethod::Index3),
            Some(ConstraintMethod::Index2),
            Some(ConstraintMethod::Projection),
        ]
    } else {
        &[None]
    };
    let mut s = Study::new(title, reference);
    s.repeats = 1;
    for (name, scheme) in schemes() {
        for m in methods {
            let mut sw = Sweep::adaptive(scheme, &decades(4, 10));
            if let Some(m) = m {
                sw = sw.with_constraints(*m).labelled(format!("{name} {m:?}"));
            }
            s = s.sweep(sw);
        }
    }
    s
}

fn print(wp: &WorkPrecision) {
    println!("## {}", wp.title);
    println!(
        "{:<28} {:>8} {:>7} {:>7} {:>7} {:>5}",
        "run", "rtol", "digits", "short", "steps", "rej"
    );
    for r in &wp.rows {
        let rtol = r.setting.value();
        match &r.outcome {
            Ok(a) => println!(
                "{:<28} {:>8.0e} {:>7.2} {:>7.2} {:>7} {:>5}",
                r.label,
                rtol,
                a.mescd,
                -rtol.log10() - a.mescd,
                r.stats.steps,
                r.stats.rejected_error + r.stats.rejected_newton
            ),
            Err(f) => println!("{:<28} {:>8.0e} failed: {}", r.label, rtol, f.name()),
        }
    }
}

fn main() {
    let which = std::env::args().nth(1).unwrap_or_else(|| "all".into());
    let all = which == "all";
    let models = ["pendulum3", "slidercrank", "fourbar", "dpend"];
    if !all && !models.contains(&which.as_str()) {
        eprintln!(
            "error: unknown model `{which}`: name one of {} or `all` (the default)",
            models.join(", ")
        );
        std::process::exit(1);
    }
    if all || which == "pendulum3" {
        let s = study("pendulum3", pendulum3_reference(), true);
        print(&s.run(&pendulum3::Pendulum3::default()).expect("study"));
    }
    if all || which == "slidercrank" {
        let s = study("slidercrank (a)", slidercrank_reference(), true);
        print(&s.run(&slidercrank::SliderCrank::default()).expect("study"));
    }
    if all || which == "fourbar" {
        let s = study("fourbar", fourbar_reference(), true);
        print(&s.run(&fourbar::FourBar::default()).expect("study"));
    }
    if all || which == "dpend" {
        let s = study("dpend", dpend_reference(), false);
        print(&s.run(&dpend::DoublePendulum::default()).expect("study"));
    }
}
