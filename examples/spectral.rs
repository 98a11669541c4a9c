//! Spectral radius and relative period error of every scheme on the undamped oscillator
//! q̈ + ω²q = 0, against ωh from 0.01 to 100, measured on the implemented integrators
//! (`mbs::spectral`: the amplification matrix from one step, or the characteristic polynomial
//! fitted to the motion for the schemes with more state than (q, q̇)).
//!
//! Prints each scheme at ωh = 0.1, 1, 10, 100 (all 41 points with `--full`), and with
//! `--out DIR` draws the figures of the seed course's slides:
//!
//! - `spectral_rho_alpha.svg`: ρ of Newmark (¼, ½), generalized-α ρ∞ = 1, 0.8, 0.5, 0 and
//!   HHT α = −0.05, −0.3;
//! - `spectral_rho_implicit.svg`: ρ of BDF2, Radau IIA 3 and 5, the implicit midpoint rule;
//! - `spectral_rho_explicit.svg`: ρ of explicit Euler, RK4, DOPRI5 (log scale: past their
//!   stability limits ρ grows without bound);
//! - `spectral_period_alpha.svg`, `spectral_period_others.svg`: |T_num − T|/T for ωh ≤ π
//!   (past two steps per period every sampled oscillation aliases; the tables go on to 100).
//!
//! `--csv FILE` writes every table. Run with
//! `cargo run --release --example spectral -- --out docs/figures`.

use clap::Parser;
use mbs::plot::{Chart, Legend, Series, line_chart};
use mbs::spectral::{SpectralTable, analyse, log_grid, tables_to_csv};
use mbs::{BdfParams, GenAlphaParams, HhtParams, NewmarkParams, Scheme};
use std::path::PathBuf;
use std::time::Instant;

mbs::multibody! {
    /// The unit oscillator: unit mass on a unit spring along x, ω = 1 rad/s.
    pub model Oscillator {
        option tangents;
        dof x = 1.0;
        body mass { mass = 1.0; }
        TOG[mass] = Tdisp(x, 0, 0);
        spring(ground, mass, k = 1.0, l0 = 0.0, axis = x);
    }
}

#[derive(Parser, Debug)]
struct Args {
    /// write the figures (spectral_*.svg) into DIR
    #[arg(long)]
    out: Option<PathBuf>,
    /// write every table into this CSV file
    #[arg(long)]
    csv: Option<PathBuf>,
    /// points of ωh, log-spaced from 0.01 to 100 (2 to 100,000)
    #[arg(long, default_value_t = 41, value_parser = clap::value_parser!(u32).range(2..=100_000))]
    points: u32,
    /// print every point, not only ωh = 0.1, 1, 10, 100
    #[arg(long)]
    full: bool,
}

/// The Newmark family, as on the slides.
fn alpha_family() -> Vec<Scheme> {
    let mut s = vec![Scheme::Newmark(NewmarkParams::default())];
    for r in [1.0, 0.8, 0.5, 0.0] {
        s.push(Scheme::GenAlpha(GenAlphaParams::from_rho_inf(r)));
    }
    for a in [-0.05, -0.3] {
        s.push(Scheme::Hht(HhtParams { alpha: a }));
    }
    s
}

fn implicit() -> Vec<Scheme> {
    vec![
        Scheme::Bdf(BdfParams { max_order: 2 }),
        Scheme::Radau3,
        Scheme::Radau5,
        Scheme::ImplicitMidpoint,
    ]
}

fn explicit() -> Vec<Scheme> {
    vec![Scheme::ExplicitEuler, Scheme::Rk4, Scheme::Dopri5]
}

fn main() {
    let args = Args::parse();
    if let Err(e) = run(&args) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    let model = Oscillator::default();
    let grid = log_grid(0.01, 100.0, args.points as usize);
    let groups = [alpha_family(), implicit(), explicit()];
    let start = Instant::now();
    let mut tables: Vec<Vec<SpectralTable>> = Vec::new();
    for g in &groups {
        let mut row = Vec::new();
        for &s in g {
            let t0 = Instant::now();
            let table = analyse(&model, s, &grid)?;
            if args.full {
                println!("{table}");
            }
            eprintln!(
                "{:<28} {} points in {:.1} ms",
                table.label,
                grid.len(),
                t0.elapsed().as_secs_f64() * 1e3
            );
            row.push(table);
        }
        tables.push(row);
    }
    let elapsed = start.elapsed();
    println!(
        "{:<28} {:>6}  {:>11}  {:>12}  {:>11}  {:>6}  {:>8}",
        "scheme", "ωh", "ρ", "(T_num−T)/T", "spurious ρ", "order", "residual"
    );
    for t in tables.iter().flatten() {
        for wh in [0.1, 1.0, 10.0, 100.0] {
            let p = t.at(wh).expect("a point");
            let f = |v: f64, prec: usize| {
                if v.is_nan() {
                    "—".to_string()
                } else {
                    format!("{v:.prec$e}")
                }
            };
            println!(
                "{:<28} {:>6.3}  {:>11.8}  {:>12}  {:>11}  {:>6}  {:>8.1e}",
                t.label,
                p.omega_h,
                p.rho,
                f(p.period_error, 4),
                f(p.spurious, 4),
                p.order,
                p.residual
            );
        }
    }
    let n_tables: usize = tables.iter().map(|g| g.len()).sum();
    println!(
        "{n_tables} schemes × {} values of ωh in {:.3} s",
        grid.len(),
        elapsed.as_secs_f64()
    );
    if let Some(path) = &args.csv {
        let all: Vec<SpectralTable> = tables.iter().flatten().cloned().collect();
        std::fs::write(path, tables_to_csv(&all))?;
        println!("wrote {}", path.display());
    }
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir)?;
        let rho_chart = |title: &str, log_y: bool| Chart {
            title: title.into(),
            x_label: "ω·h".into(),
            y_label: "spectral radius ρ".into(),
            log_x: true,
            log_y,
            ..Chart::default()
        };
        let period_chart = |title: &str| Chart {
            title: title.into(),
            x_label: "ω·h".into(),
            y_label: "|T_num − T| / T".into(),
            log_x: true,
            log_y: true,
            ..Chart::default()
        };
        let rho = |g: &[SpectralTable]| g.iter().map(|t| t.rho_series()).collect::<Vec<_>>();
        // below 1e-13 the period error is rounding, not the scheme; past ωh = π (two steps
        // per period) a sampled oscillation aliases, whatever the scheme
        let period = |g: &[SpectralTable]| {
            g.iter()
                .map(|t| t.period_series(1e-13, std::f64::consts::PI))
                .collect::<Vec<_>>()
        };
        let explicit_rho = {
            let mut s = rho(&tables[2]);
            s.push(Series {
                name: "ρ = 1".into(),
                points: vec![(grid[0], 1.0), (grid[grid.len() - 1], 1.0)],
            });
            s
        };
        let figures = [
            (
                "spectral_rho_alpha.svg",
                rho_chart(
                    "Spectral radius: Newmark (¼, ½), generalized-α, HHT-α",
                    false,
                ),
                rho(&tables[0]),
            ),
            (
                "spectral_rho_implicit.svg",
                rho_chart("Spectral radius: BDF2, Radau IIA, implicit midpoint", false),
                rho(&tables[1]),
            ),
            (
                "spectral_rho_explicit.svg",
                rho_chart("Spectral radius: explicit Euler, RK4, DOPRI5", true),
                explicit_rho,
            ),
            (
                "spectral_period_alpha.svg",
                period_chart(
                    "Relative period error (ωh ≤ π): Newmark (¼, ½), generalized-α, HHT-α",
                ),
                period(&tables[0]),
            ),
            (
                "spectral_period_others.svg",
                period_chart("Relative period error (ωh ≤ π): BDF2, Radau IIA, midpoint, explicit"),
                period(&[&tables[1][..], &tables[2][..]].concat()),
            ),
        ];
        for (i, (name, chart, series)) in figures.into_iter().enumerate() {
            let path = dir.join(name);
            // every ρ starts at 1 and every period error grows with ωh: the linear ρ charts
            // are empty at the lower left, the others at the upper left
            let chart = Chart {
                legend: if i < 2 {
                    Legend::LowerLeft
                } else {
                    Legend::UpperLeft
                },
                ..chart
            };
            line_chart(&path, &chart, &series)?;
            println!("wrote {}", path.display());
        }
    }
    Ok(())
}
