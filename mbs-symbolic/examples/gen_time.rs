//! Generation time of `multibody!`, the work the proc-macro does inside the compiler each
//! time a model compiles. Cargo builds proc-macros and their dependencies at opt-level 0
//! unless a profile says otherwise; this workspace's profiles (and the README's advice for a
//! user's crate) build the generator, `mbs-symbolic`, at opt-level 3:
//!
//! ```text
//! cargo run -p mbs-symbolic --example gen_time     # the generator as the workspace builds it
//! cargo run -p mbs-symbolic --example gen_time --config 'profile.dev.package.mbs-symbolic.opt-level=0'
//!                                                  # Cargo's default for proc-macros
//! ```
//!
//! It times `expand_models` — parse, check, symbolic model, scheduling and emission: all the
//! macro does but the compiler's final tokenisation of the emitted text — on chainN written
//! out in the DSL and on the hexapod of `models/src/hexapod.rs`, with and without
//! tangents, and prints the best of several runs with the op counts. Arguments select cases
//! by name (`-- hexapod chain24`).

use mbs_symbolic::expand::{Expansion, expand_models, multibody_blocks};
use std::time::{Duration, Instant};

/// chainN of MODELS.md in the DSL.
fn chain(n: usize, tangents: bool) -> String {
    let mut s = String::from("model Chain { param l = 0.5; param m = 1.0; param g = 9.81;\n");
    for i in 0..n {
        s += &format!(
            "dof q[{i}] = 0.3; body b{i} {{ mass = m; inertia = (m*l*l/12, 0, m*l*l/12); }}\n"
        );
    }
    s += "TOG[b0] = Trotz(q[0]) * Tdisp(0, -l/2, 0);\n";
    for i in 1..n {
        s += &format!(
            "TOG[b{i}] = TOG[b{}] * Tdisp(0, -l/2, 0) * Trotz(q[{i}]) * Tdisp(0, -l/2, 0);\n",
            i - 1
        );
    }
    s += "gravity(0, -g, 0);\n";
    if tangents {
        s += "option tangents;\n";
    }
    s + "}"
}

fn hexapod(tangents: bool) -> Option<String> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../models/src/hexapod.rs");
    let src = std::fs::read_to_string(path).ok()?;
    let blocks = multibody_blocks(&syn::parse_file(&src).ok()?);
    let mut body = blocks.first()?.to_string();
    if tangents {
        let close = body.rfind('}')?;
        body.insert_str(close, " option tangents ; ");
    }
    Some(body)
}

/// Best and median of `runs` timings of the macro's work, and the flops of M+h and of K, C.
fn time(src: &str, runs: usize) -> (Duration, Duration, usize, Option<usize>) {
    let mut times = Vec::new();
    let mut flops = (0, None);
    for _ in 0..runs {
        let tokens: proc_macro2::TokenStream = src.parse().expect("model text");
        let t0 = Instant::now();
        let out = expand_models(tokens).expect("model parses");
        let dt = t0.elapsed();
        times.push(dt);
        for e in out {
            match e {
                Expansion::Ok { generated, .. } => {
                    if std::env::var("PHASES").is_ok() {
                        eprintln!(
                            "  build {:?} emit {:?}",
                            generated.build_time, generated.emit_time
                        );
                    }
                    let get = |p: &str| {
                        generated
                            .reports
                            .iter()
                            .find(|r| r.function.starts_with(p))
                            .map(|r| r.ops.flops())
                    };
                    flops = (get("dynamics").unwrap_or(0), get("tangents"));
                }
                Expansion::Err { error, .. } => panic!("model error: {error}"),
            }
        }
    }
    times.sort();
    (times[0], times[runs / 2], flops.0, flops.1)
}

fn main() {
    println!(
        "the generator at the opt-level of this build's profile for mbs-symbolic (the workspace: 3; \
         Cargo's default for proc-macros, 0: --config 'profile.dev.package.mbs-symbolic.opt-level=0')\n"
    );
    println!(
        "{:<26} {:>10} {:>10} {:>10} {:>12}",
        "model", "best ms", "median ms", "M+h flops", "K,C flops"
    );
    let mut cases: Vec<(String, String)> = Vec::new();
    for (n, tan) in [(24, false), (24, true), (48, false)] {
        cases.push((
            format!("chain{n}{}", if tan { " + tangents" } else { "" }),
            chain(n, tan),
        ));
    }
    for tan in [false, true] {
        match hexapod(tan) {
            Some(src) => cases.push((
                format!("hexapod{}", if tan { " + tangents" } else { "" }),
                src,
            )),
            None => println!("(models/src/hexapod.rs not found: hexapod skipped)"),
        }
    }
    let only: Vec<String> = std::env::args().skip(1).collect();
    for (name, src) in cases {
        if !only.is_empty() && !only.contains(&name) {
            continue;
        }
        let (best, median, mh, kc) = time(&src, 5);
        println!(
            "{:<26} {:>10.1} {:>10.1} {:>10} {:>12}",
            name,
            best.as_secs_f64() * 1e3,
            median.as_secs_f64() * 1e3,
            mh,
            kc.map_or("-".into(), |k| k.to_string())
        );
    }
}
