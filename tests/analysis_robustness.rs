//! Every analysis on the repository's models, from ordinary, perturbed, huge and non-finite
//! states: statics (with and without locked coordinates, exact and differenced stiffness,
//! one Newton iteration), linearisation and modes (each way of taking K and C), the
//! sensitivities of the equilibria found, and inverse dynamics along a run (of every
//! coordinate, and of actuated sets valid or not) and along a path that turns non-finite.
//! Each returns finite results, or a typed error with a message; never a panic, never a NaN
//! in a result it returns. Also linearisation, modes and statics with each parameter at the
//! edges of its range.

#[path = "common/lcg.rs"]
mod lcg;
use lcg::Lcg;

use mbs::analysis::{
    AnalysisError, Linearization, Modes, StaticsOptions, inverse_dynamics_actuated_of,
    inverse_dynamics_along, inverse_dynamics_of, linearize, modes, pole_sensitivity,
    static_equilibrium, static_sensitivity,
};
use mbs::{ConstraintMethod, IterationMatrix, Model, Options, Output, Scheme, simulate};
use mbs_models::*;
use std::collections::BTreeMap;
use std::panic::{AssertUnwindSafe, catch_unwind};

#[path = "common/sweeps.rs"]
mod sweeps;

#[path = "common/quoted.rs"]
mod quoted;
use quoted::thousands;

fn all_finite<'a>(xs: impl IntoIterator<Item = &'a f64>) -> bool {
    xs.into_iter().all(|x| x.is_finite())
}

/// What one sweep found: results by kind, and the problems.
#[derive(Default)]
struct Tally {
    kinds: BTreeMap<String, usize>,
    problems: Vec<String>,
    calls: usize,
    /// (calls, ok results) by model and analysis
    by_model: BTreeMap<(String, String), (usize, usize)>,
    /// the models swept
    models: std::collections::BTreeSet<String>,
}

impl Tally {
    /// Counts an analysis' result; `finite` says whether an `Ok` result is wholly finite.
    fn record<T>(
        &mut self,
        tag: &str,
        r: std::thread::Result<Result<T, AnalysisError>>,
        finite: impl FnOnce(&T) -> bool,
    ) -> Option<T> {
        self.calls += 1;
        let analysis = tag.split(' ').nth(1).unwrap_or("");
        let model = tag.split(' ').next().unwrap_or("");
        let here = (self.by_model)
            .entry((model.to_string(), analysis.to_string()))
            .or_default();
        here.0 += 1;
        here.1 += usize::from(matches!(r, Ok(Ok(_))));
        match r {
            Err(_) => {
                self.problems.push(format!("{tag}: panicked"));
                None
            }
            Ok(Ok(v)) => {
                if !finite(&v) {
                    self.problems
                        .push(format!("{tag}: a non-finite value returned"));
                }
                *self.kinds.entry(format!("{analysis} ok")).or_default() += 1;
                Some(v)
            }
            Ok(Err(e)) => {
                let text = e.to_string();
                if text.trim().is_empty() {
                    self.problems.push(format!("{tag}: an empty message"));
                }
                let longest = sweeps::longest_number(&text);
                if longest > 12 {
                    self.problems
                        .push(format!("{tag}: a number of {longest} digits: {text}"));
                }
                let kind = match e.cause() {
                    AnalysisError::Failure(f) => format!("{f:?}"),
                    other => format!("{other:?}"),
                };
                let kind = kind.split([' ', '(', '{']).next().unwrap_or("").to_string();
                *self.kinds.entry(format!("{analysis} {kind}")).or_default() += 1;
                // those that name a parameter to check, counted apart too
                if text.contains("rather than") && text.contains(": check th") {
                    let named = format!("{analysis} {kind} naming a parameter");
                    *self.kinds.entry(named).or_default() += 1;
                }
                None
            }
        }
    }

    /// How many results of this kind (`"statics ok"`, `"modes SingularMatrix"`).
    fn count(&self, kind: &str) -> usize {
        self.kinds.get(kind).copied().unwrap_or(0)
    }

    /// The models swept.
    fn models(&self) -> usize {
        self.models.len()
    }

    /// (calls, ok results) of `analysis` over the models `which` accepts.
    fn of(&self, analysis: &str, which: impl Fn(&str) -> bool) -> (usize, usize) {
        (self.by_model.iter())
            .filter(|((m, a), _)| a == analysis && which(m))
            .fold((0, 0), |(c, k), (_, &(n, ok))| (c + n, k + ok))
    }
}

fn call<T>(
    f: impl FnOnce() -> Result<T, AnalysisError>,
) -> std::thread::Result<Result<T, AnalysisError>> {
    catch_unwind(AssertUnwindSafe(f))
}

/// A state by name: (name, q, qd).
type NamedState = (&'static str, Vec<f64>, Vec<f64>);

/// The states an analysis is asked about: a run's start and end (consistent), and the start
/// perturbed, huge, zero, with a NaN and with an infinite velocity.
fn states<M: Model + Clone + 'static>(model: &M) -> (mbs::Trajectory, Vec<NamedState>) {
    let n = M::NQ;
    let mut o = Options::adaptive(0.2, 1e-8);
    o.output = Output::Every { dt: 0.05 };
    o.energy = false;
    o.constraints.method = ConstraintMethod::Projection;
    let tr = match simulate(model.clone(), Scheme::Dopri5, o) {
        Ok((tr, _)) => tr,
        Err(e) => *e.trajectory,
    };
    let last = tr.len() - 1;
    let mut rng = Lcg(n as u64 + 7);
    let start_q = tr.q(0).to_vec();
    let perturbed: Vec<f64> = start_q.iter().map(|x| x + 0.3 * rng.next()).collect();
    let speeds: Vec<f64> = (0..n).map(|_| 2.0 * rng.next()).collect();
    let mut nan = start_q.clone();
    nan[0] = f64::NAN;
    let mut infinite = tr.qd(0).to_vec();
    infinite[n - 1] = f64::INFINITY;
    let list = vec![
        ("start", start_q.clone(), tr.qd(0).to_vec()),
        ("end", tr.q(last).to_vec(), tr.qd(last).to_vec()),
        ("perturbed", perturbed, speeds),
        ("huge", vec![1e6; n], vec![1e3; n]),
        ("zero", vec![0.0; n], vec![0.0; n]),
        ("nan", nan, tr.qd(0).to_vec()),
        ("infinite", start_q, infinite),
    ];
    (tr, list)
}

fn sweep<M: Model + Clone + 'static>(name: &str, model: M, tally: &mut Tally) {
    tally.models.insert(name.to_string());
    let (tr, list) = states(&model);
    let u = vec![0.0; M::NU];
    let ways = [
        IterationMatrix::Auto,
        IterationMatrix::Exact,
        IterationMatrix::FiniteDifferences,
        IterationMatrix::MassOnly,
    ];
    for (state, q, qd) in &list {
        for how in ways {
            let tag = format!("{name} linearize {state} {how:?}");
            let lin = tally.record(&tag, call(|| linearize(&model, 0.0, q, qd, &u, how)), |l| {
                [&l.m, &l.c, &l.k, &l.bu, &l.a, &l.b]
                    .iter()
                    .all(|m| all_finite(m.iter()))
                    && all_finite(&l.qdd)
                    && all_finite(&l.lambda)
            });
            if let Some(lin) = lin {
                let tag = format!("{name} modes {state} {how:?}");
                tally.record(&tag, call(|| modes(&lin, None)), |m| {
                    m.modes
                        .iter()
                        .all(|m| m.re.is_finite() && m.im.is_finite() && m.frequency_hz.is_finite())
                });
            }
        }
        for (variant, locked, iterations, how) in [
            ("free", vec![], 50, IterationMatrix::Auto),
            (
                "differenced",
                vec![],
                50,
                IterationMatrix::FiniteDifferences,
            ),
            ("locked", vec![0], 50, IterationMatrix::Auto),
            ("one-iteration", vec![], 1, IterationMatrix::Auto),
        ] {
            let options = StaticsOptions {
                q0: Some(q.clone()),
                u: Some(u.clone()),
                locked,
                max_iterations: iterations,
                stiffness: how,
                ..StaticsOptions::default()
            };
            let tag = format!("{name} statics {state} {variant}");
            let eq = tally.record(&tag, call(|| static_equilibrium(&model, &options)), |e| {
                all_finite(&e.q)
                    && e.residual.is_finite()
                    && all_finite(&e.stiffness_eigenvalues)
                    && all_finite(&e.lambda)
            });
            let Some(eq) = eq else { continue };
            let tag = format!("{name} static_sensitivity {state} {variant}");
            tally.record(
                &tag,
                call(|| static_sensitivity(&model, &eq, &options)),
                |s| all_finite(&s.dq_dp) && all_finite(&s.dlambda_dp),
            );
            let tag = format!("{name} pole_sensitivity {state} {variant}");
            tally.record(
                &tag,
                call(|| pole_sensitivity(&model, &eq, &options)),
                |s| {
                    s.modes
                        .modes
                        .iter()
                        .all(|p| p.re.is_finite() && p.im.is_finite())
                        && s.dpole_dp
                            .iter()
                            .all(|d| d.0.is_finite() && d.1.is_finite())
                },
            );
        }
    }
    let tag = format!("{name} inverse_dynamics recorded");
    tally.record(&tag, call(|| inverse_dynamics_of(&model, &tr, &[])), |e| {
        all_finite(&e.tau)
    });
    // actuator efforts and reactions along the run: the first and the last NQ − NC
    // coordinates actuated, and sets that are no such set (empty, repeated, out of range)
    let free = M::NQ - M::NC;
    let first: Vec<usize> = (0..free).collect();
    let last: Vec<usize> = (M::NC..M::NQ).collect();
    let repeated = vec![0; free.max(1)];
    for (set, actuated) in [
        ("first", first),
        ("last", last),
        ("empty", vec![]),
        ("repeated", repeated),
        ("beyond", vec![M::NQ + 3]),
    ] {
        let tag = format!("{name} inverse_dynamics_actuated {set}");
        tally.record(
            &tag,
            call(|| inverse_dynamics_actuated_of(&model, &tr, &[], &actuated)),
            |e| all_finite(&e.tau) && all_finite(&e.lambda),
        );
    }
    // a path that turns non-finite at its third time: the rows before it are kept
    let times = [0.0, 0.05, 0.1, 0.15];
    let tag = format!("{name} inverse_dynamics along");
    let (q0, qd0) = (tr.q(0).to_vec(), tr.qd(0).to_vec());
    let path = |t: f64| {
        let bad = if t > 0.07 { f64::NAN } else { 0.0 };
        let q = q0.iter().map(|x| x + bad).collect();
        (q, qd0.clone(), vec![0.0; M::NQ])
    };
    match call(|| inverse_dynamics_along(&model, &times, &u, path)) {
        Ok(Err(AnalysisError::AlongMotion {
            index, computed, ..
        })) => {
            tally.calls += 1;
            let rows = match *computed {
                mbs::analysis::Computed::Efforts(e) => e.t.len(),
                mbs::analysis::Computed::Actuated(a) => a.t.len(),
            };
            if index != 2 || rows != 2 {
                tally
                    .problems
                    .push(format!("{tag}: stopped at {index} with {rows} rows kept"));
            }
            *tally
                .kinds
                .entry("inverse_dynamics AlongMotion".into())
                .or_default() += 1;
        }
        other => {
            tally.calls += 1;
            let what = match other {
                Err(_) => "panicked".to_string(),
                Ok(r) => format!("{:?}", r.map(|e| e.t.len())),
            };
            tally
                .problems
                .push(format!("{tag}: not stopped at the NaN: {what}"));
        }
    }
}

#[test]
fn every_analysis_returns_finite_results_or_a_typed_error() {
    let mut tally = Tally::default();
    sweeps::silenced(|| {
        let t = &mut tally;
        sweep("dpend", dpend::DoublePendulum::default(), t);
        sweep("seed2dof", seed2dof::Seed2dof::default(), t);
        sweep("chain8", chain8::Chain8::default(), t);
        sweep("arm3d_6", arm3d_6::Arm3d6::default(), t);
        sweep("tumble", tumble::TumbleBall::default(), t);
        sweep("top", top::Top::default(), t);
        sweep(
            "spherical",
            spherical_pendulum::SphericalPendulumZyx::default(),
            t,
        );
        sweep("springpend", springpend::SpringPend::default(), t);
        sweep("fourbar", fourbar::FourBar::default(), t);
        sweep("slidercrank", slidercrank::SliderCrankClosed::default(), t);
        sweep("pendulum3", pendulum3::Pendulum3::default(), t);
        sweep("fastlink", fastlink::FastLink::default(), t);
        sweep(
            "dpend_cartesian",
            dpend_cartesian::DoublePendulumCartesian::default(),
            t,
        );
        sweep("hexapod_standing", hexapod::HexapodStanding::default(), t);
    });
    println!("{} calls: {:#?}", tally.calls, tally.kinds);
    assert!(tally.problems.is_empty(), "{}", tally.problems.join("\n"));
    quoted::says(
        "docs/analyses.md",
        &[
            format!(
                "A sweep of every analysis over {} models from seven states each",
                tally.models()
            ),
            format!(
                "with inverse dynamics of valid and invalid actuated sets, {} calls, asserts",
                thousands(tally.calls)
            ),
        ],
    );
}

/// The hexapod released above the ground: six rigid motions with neither stiffness nor
/// damping (twelve zero eigenvalues in Jordan blocks) beside entries of A up to 4.4·10⁴/s². nalgebra's
/// QR iteration cannot deflate beside them at ε (it stopped with "A is singular"); at a
/// looser threshold it finds them, and every mode satisfies (λ²M + λC + K)φ = 0 of the
/// linearisation to rounding, the rigid motions at λ = 0.
#[test]
fn the_modes_of_a_free_body_beside_stiff_joints_are_found() {
    use mbs_models::hexapod::HexapodStanding;
    let model = HexapodStanding::default();
    let n = <HexapodStanding as Model>::NQ;
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    model.initial_state(&mut q, &mut qd);
    let u = vec![0.0; <HexapodStanding as Model>::NU];
    let lin = linearize(&model, 0.0, &q, &qd, &u, IterationMatrix::Auto).unwrap();
    let found = modes(&lin, None).unwrap();
    let largest = lin.a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    println!(
        "max|A| {largest:.3e}, deflation {:e}\n{found}",
        found.deflation
    );
    assert!(found.deflation > f64::EPSILON && found.deflation <= 1e-10);
    let said = format!("eigenvalues found deflating at {:.0e}", found.deflation);
    assert!(found.to_string().contains(&said), "{said}");
    assert_eq!(found.modes.len(), 2 * n);
    let zeros = found
        .modes
        .iter()
        .filter(|m| m.re == 0.0 && m.im == 0.0)
        .count();
    assert_eq!(zeros, 12, "the six rigid motions' twelve zero eigenvalues");
    let worst = largest_modal_residual(&lin, &found);
    println!("largest residual of (λ²M + λC + K)φ: {worst:.1e} of |K| + |λ||C| + |λ|²|M|");
    assert!(worst < 1e-11, "{worst:e}");
    quoted::says(
        "docs/analyses.md",
        &[format!(
            "every mode of the hexapod in the air satisfies (λ²M + λC + K)φ = 0 to {worst:.1e} \
             of |K| + |λ||C| + |λ|²|M| (asserted 1e-11)"
        )],
    );
}

/// The largest residual of (λ²M + λC + K)φ = 0 over the modes, relative to
/// |K| + |λ||C| + |λ|²|M| (the linearisation's matrices in its coordinates).
fn largest_modal_residual(lin: &Linearization, found: &Modes) -> f64 {
    let n = lin.mz.nrows();
    let mut worst = 0.0f64;
    for m in &found.modes {
        let l = nalgebra::Complex::new(m.re, m.im);
        let phi: Vec<_> = m
            .shape
            .iter()
            .map(|&(a, b)| nalgebra::Complex::new(a, b))
            .collect();
        let scale = lin.kz.norm() + l.norm() * lin.cz.norm() + l.norm_sqr() * lin.mz.norm();
        for i in 0..n {
            let r: nalgebra::Complex<f64> = (0..n)
                .map(|j| (l * l * lin.mz[(i, j)] + l * lin.cz[(i, j)] + lin.kz[(i, j)]) * phi[j])
                .sum();
            worst = worst.max(r.norm() / scale);
        }
    }
    worst
}

/// A spectrum spread over many decades: the top spun at 2·10⁶ and 2·10⁸ rad/s (its
/// nutation at about I3 ω3 / I1' beside poles of a few per second, five and seven decades
/// apart), and on a 40 km rod (A's entries of 1e-4 and 1e-11/s²). The slow poles' shapes come
/// from inverse iteration on A − μI, whose pivot near a slow pole is far below nε‖A‖: the
/// factorisation refused it, the shift moved off until another pole was as near, and modes
/// failed with "A − μI is singular"; the 40 km rod's Schur form kept a real pair in a 2 × 2
/// block, whose eigenvalues nalgebra took for a complex pair (NaN). Every mode is now found,
/// and satisfies (λ²M + λC + K)φ = 0; the nutation scales with the spin.
#[test]
fn a_slow_mode_beside_a_fast_one_gets_its_shape() {
    let found = |param: &str, value: f64| {
        let model = sweeps::with_params(top::Top::default(), &[(param, value)]);
        let (mut q, mut qd) = ([0.0; 3], [0.0; 3]);
        model.initial_state(&mut q, &mut qd);
        let lin = linearize(&model, 0.0, &q, &qd, &[], IterationMatrix::Auto).unwrap();
        let modes = modes(&lin, None).unwrap_or_else(|e| panic!("{param} = {value:e}: {e}"));
        let worst = largest_modal_residual(&lin, &modes);
        println!("top, {param} = {value:e}: residual {worst:.1e}\n{modes}");
        // on the 40 km rod the two axes' poles are split by the gyroscopic coupling
        // (I3 ω3 / I1' ≈ 5e-11/s beside 0.014/s), within what the table takes for one repeated
        // pole, whose shapes are then mixes of the two: a residual of that split's size
        let within = if param == "l" { 1e-8 } else { 1e-12 };
        assert!(worst < within, "{param} = {value:e}: {worst:e}");
        let poles: usize = (modes.modes.iter())
            .map(|m| if m.im != 0.0 { 2 } else { 1 })
            .sum();
        assert_eq!(poles, 6, "{param} = {value:e}: every eigenvalue of A");
        (modes, worst)
    };
    // the nutation, the fastest pole, over the spin, and the largest residual
    let nutation = |w3: f64| {
        let (modes, worst) = found("w3", w3);
        let fast = modes.modes.last().unwrap();
        assert!(fast.re.abs() < 1e-9 * fast.im, "{fast:?}");
        (fast.im / w3, worst)
    };
    let ((n6, worst6), (n8, worst8)) = (nutation(2e6), nutation(2e8));
    quoted::says(
        "docs/analyses.md",
        &[format!(
            "its nutation five and seven decades above its slowest poles, to {:.1e} (asserted 1e-12",
            worst6.max(worst8)
        )],
    );
    // I3 / I1' with I1' = I1 + m l² (the default top: 4e-5 / 1.8e-4), as a fast top's
    // nutation is about I3 ω3 / I1' (the precession's share moves it by a few per cent)
    let ratio = 4e-5 / (2e-5 + 0.1 * 0.04 * 0.04);
    println!("nutation / ω3: {n6:.9} at 2e6, {n8:.9} at 2e8; I3 / I1' = {ratio:.6}");
    assert!((n6 - n8).abs() < 1e-6 * n8, "{n6} {n8}");
    assert!((n8 / ratio - 1.0).abs() < 0.1, "{n8} against {ratio}");
    found("l", 4e4);
}

/// Statics from a start where the stiffness is singular but the forces are not zero: the
/// double pendulum's default start, both bars horizontal (K = 0: gravity's moment is at its
/// largest), and the 6-joint arm's, every joint at 0.2 rad about a first axis along gravity
/// (no stiffness about it ever). Newton's step does not exist there; a step of Levenberg–Marquardt (K + μ diag M) takes it on, and Newton converges from
/// where it leads (dpend in 6 iterations to hanging, the arm in 8). Before, both stopped with
/// "the stiffness K is singular near q[0]".
#[test]
fn statics_start_where_the_stiffness_is_singular() {
    use mbs::analysis::Stability;
    let eq = static_equilibrium(
        &dpend::DoublePendulum::default(),
        &StaticsOptions::default(),
    )
    .unwrap();
    println!(
        "dpend: {:?} in {} iterations, {:?}",
        eq.q, eq.iterations, eq.stability
    );
    assert!(eq.q.iter().all(|q| q.abs() < 1e-9), "{:?}", eq.q);
    assert_eq!(eq.stability, Stability::Stable);
    assert!(eq.residual <= 1e-9);
    let dpend_iterations = eq.iterations;
    let arm = arm3d_6::Arm3d6::default();
    let eq = static_equilibrium(&arm, &StaticsOptions::default()).unwrap();
    println!(
        "arm3d_6: {:?} in {} iterations, {:?} {:?}",
        eq.q, eq.iterations, eq.stability, eq.stiffness_eigenvalues
    );
    assert!(eq.residual <= 1e-9);
    // hanging straight down, the first joint left where it was: neutral about it
    assert!((eq.q[0] - 0.2).abs() < 1e-9 && (eq.q[1] - std::f64::consts::FRAC_PI_2).abs() < 1e-9);
    assert!(eq.q[2..].iter().all(|q| q.abs() < 1e-9));
    assert_eq!(eq.stability, Stability::Neutral);
    quoted::says(
        "README.md",
        &[format!(
            "reaches the hanging equilibrium in {dpend_iterations} iterations, the 6-joint arm's \
             (its first axis along gravity, neutral) in {},",
            eq.iterations
        )],
    );
}

/// The same on a closed loop: pendulum3 (a mass on a rod, Cartesian x, y and the rod's
/// constraint) starts with the rod horizontal, where the reduced stiffness is zero. The damped
/// step moves along the manifold's tangent and back onto it, and Newton converges to the
/// mass hanging below the pivot, its λ the weight's pull along the rod.
#[test]
fn statics_of_a_loop_start_where_the_reduced_stiffness_is_singular() {
    use mbs::analysis::Stability;
    let model = pendulum3::Pendulum3::default();
    let eq = static_equilibrium(&model, &StaticsOptions::default()).unwrap();
    println!(
        "pendulum3: {:?}, λ {:?} in {} iterations, {:?}",
        eq.q, eq.lambda, eq.iterations, eq.stability
    );
    assert!(
        eq.q[0].abs() < 1e-9 && (eq.q[1] + 1.0).abs() < 1e-9,
        "{:?}",
        eq.q
    );
    assert_eq!(eq.stability, Stability::Stable);
    assert!(eq.residual <= 1e-9 && eq.constraint_residual <= 1e-11);
    quoted::says(
        "README.md",
        &[format!(
            "pendulum3's default start (the rod horizontal) the mass hanging below the pivot in {} \
             iterations;",
            eq.iterations
        )],
    );
}

/// Each parameter of the models at the edges of its range, one at a time (zero, its opposite,
/// 10⁻⁶ and 10⁶ times its default, ±1e300, 1e-300), where `set_params` accepts it: the
/// linearisation at the declared start, its modes, the statics from there and, for models
/// with parameters marked `sensitive`, the sensitivities at the equilibrium found return
/// finite results or a typed error, never a panic.
fn at_parameter_edges<M: Model + Clone + 'static>(name: &str, model: M, tally: &mut Tally) {
    use mbs::Parameters;
    tally.models.insert(name.to_string());
    let defaults = model.params().values();
    let n = M::NQ;
    let u = vec![0.0; M::NU];
    for (k, &param) in M::Params::NAMES.iter().enumerate() {
        let v = defaults[k];
        for &value in &sweeps::parameter_edges(v)[..sweeps::PARAMETER_EDGES_FINITE] {
            let mut p = model.params().clone();
            p.set(param, value).expect("a known name");
            let mut m = model.clone();
            if m.set_params(p).is_err() {
                continue;
            }
            let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
            m.initial_state(&mut q, &mut qd);
            let tag = format!("{name} linearize {param} = {value:e}");
            let lin = tally.record(
                &tag,
                call(|| linearize(&m, 0.0, &q, &qd, &u, IterationMatrix::Auto)),
                |l| {
                    [&l.m, &l.c, &l.k, &l.a]
                        .iter()
                        .all(|x| all_finite(x.iter()))
                },
            );
            if let Some(lin) = lin {
                let tag = format!("{name} modes {param} = {value:e}");
                tally.record(&tag, call(|| modes(&lin, None)), |m| {
                    m.modes.iter().all(|m| m.re.is_finite() && m.im.is_finite())
                });
            }
            let tag = format!("{name} statics {param} = {value:e}");
            let options = StaticsOptions::default();
            let eq = tally.record(&tag, call(|| static_equilibrium(&m, &options)), |e| {
                all_finite(&e.q) && e.residual.is_finite() && all_finite(&e.lambda)
            });
            // the sensitivities at that equilibrium, for the models with parameters marked
            // `sensitive`
            let Some(eq) = eq.filter(|_| !M::SENSITIVE.is_empty()) else {
                continue;
            };
            let tag = format!("{name} static_sensitivity {param} = {value:e}");
            tally.record(&tag, call(|| static_sensitivity(&m, &eq, &options)), |s| {
                all_finite(&s.dq_dp) && all_finite(&s.dlambda_dp)
            });
            let tag = format!("{name} pole_sensitivity {param} = {value:e}");
            tally.record(&tag, call(|| pole_sensitivity(&m, &eq, &options)), |s| {
                let repeated = |i: usize| s.repeated.contains(&(i / s.params.len()));
                s.modes
                    .modes
                    .iter()
                    .all(|p| p.re.is_finite() && p.im.is_finite())
                    && (s.dpole_dp.iter().enumerate())
                        .all(|(i, d)| repeated(i) || d.0.is_finite() && d.1.is_finite())
            });
        }
    }
}

#[test]
fn every_analysis_at_the_edges_of_the_parameters_returns_finite_results_or_a_typed_error() {
    let mut tally = Tally::default();
    sweeps::silenced(|| {
        let t = &mut tally;
        at_parameter_edges("dpend", dpend::DoublePendulum::default(), t);
        at_parameter_edges("seed2dof", seed2dof::Seed2dof::default(), t);
        at_parameter_edges("chain8", chain8::Chain8::default(), t);
        at_parameter_edges("arm3d_6", arm3d_6::Arm3d6::default(), t);
        at_parameter_edges("tumble", tumble::TumbleBall::default(), t);
        at_parameter_edges("top", top::Top::default(), t);
        at_parameter_edges("springpend", springpend::SpringPend::default(), t);
        at_parameter_edges("sprung_arm", sprung_arm::SprungArm::default(), t);
        at_parameter_edges("fourbar", fourbar::FourBar::default(), t);
        at_parameter_edges("sensitive_fourbar", fourbar::SensitiveFourBar::default(), t);
        at_parameter_edges("slidercrank", slidercrank::SliderCrankClosed::default(), t);
        at_parameter_edges("pendulum3", pendulum3::Pendulum3::default(), t);
        at_parameter_edges("fastlink", fastlink::FastLink::default(), t);
        at_parameter_edges(
            "dpend_cartesian",
            dpend_cartesian::DoublePendulumCartesian::default(),
            t,
        );
        at_parameter_edges("hexapod_standing", hexapod::HexapodStanding::default(), t);
    });
    println!("{} calls: {:#?}", tally.calls, tally.kinds);
    assert!(tally.problems.is_empty(), "{}", tally.problems.join("\n"));
    let ok: usize = (tally.kinds.iter())
        .filter(|(k, _)| k.ends_with(" ok"))
        .map(|(_, n)| n)
        .sum();
    let (modes_calls, modes_ok) = tally.of("modes", |_| true);
    assert_eq!(modes_ok, modes_calls, "every modes call returns its modes");
    let (statics, statics_ok) = tally.of("statics", |_| true);
    let others = |m: &str| m != "sensitive_fourbar";
    let (statics_others, statics_others_ok) = tally.of("statics", others);
    let (poles, poles_ok) = tally.of("pole_sensitivity", |_| true);
    quoted::says(
        "docs/robustness.md",
        &[format!(
            "{} of the {} singular stiffnesses left in the statics sweep (analyses.md) name one",
            tally.count("statics SingularMatrix naming a parameter"),
            tally.count("statics SingularMatrix")
        )],
    );
    quoted::says(
        "docs/analyses.md",
        &[
            format!(
                "so does a second over each parameter of {} models at the edges of its range",
                tally.models()
            ),
            format!(
                "{} calls, {} of them ok (every one of the {} modes calls:",
                thousands(tally.calls),
                thousands(ok),
                thousands(modes_calls)
            ),
            format!(
                "statics {statics_ok} of {statics}, and on the {} models other than the sensitive \
                 four-bar {statics_others_ok} of {statics_others}, where 165 did before",
                tally.models() - 1
            ),
            format!("the pole sensitivities {poles_ok} of {poles}, the others typed"),
        ],
    );
}

/// A linearisation whose mass matrix a parameter made singular names the parameter, as a
/// run's start does (`tests/step_messages.rs`): bars of no length move no inertia.
#[test]
fn a_mass_matrix_made_singular_by_a_parameter_is_named_by_linearize() {
    let model = sweeps::with_params(dpend::DoublePendulum::default(), &[("l", 0.0)]);
    let (mut q, mut qd) = ([0.0; 2], [0.0; 2]);
    model.initial_state(&mut q, &mut qd);
    let e = linearize(&model, 0.0, &q, &qd, &[], IterationMatrix::Auto).unwrap_err();
    let msg = e.to_string();
    println!("{msg}");
    assert!(
        msg.contains(
            "with `l` at its default 1 rather than 0 M is regular there: check that parameter"
        ),
        "{msg}"
    );
}

/// Statics beside a stiff spring: the sprung arm with its first spring 10⁶ to 10¹⁰ times
/// stiffer, whose forces' rounding (k q ε ≈ 1e-9 to 1e-5 N) is above the absolute tolerance of
/// 1e-9 N. Newton stalls there with its correction at q's own rounding, or with forces
/// backtracking cannot lower; statics said "no static equilibrium found". It now returns
/// the equilibrium, which is the spring's deflection under its load: (q₀ − 0.6)·k₁, the
/// load, is the same for every stiffness. And the poles' sensitivities beside it, whose
/// inverse iteration refused the small pivot of the slow pole (`λ²M + λC + K is singular`).
#[test]
fn statics_beside_a_stiff_spring_converge_at_the_rounding_of_the_forces() {
    use mbs_models::sprung_arm::SprungArm;
    let options = StaticsOptions::default();
    let mut loads = Vec::new();
    for k1 in [4e7, 4e9, 4e11] {
        let model = sweeps::with_params(SprungArm::default(), &[("k1", k1)]);
        let eq =
            static_equilibrium(&model, &options).unwrap_or_else(|e| panic!("k1 = {k1:e}: {e}"));
        let load = (eq.q[0] - 0.6) * k1;
        println!(
            "k1 = {k1:e}: q = {:?}, forces left {:.1e}, load (q0 − 0.6) k1 = {load:.6}",
            eq.q, eq.residual
        );
        loads.push((load, eq.q[1]));
        if k1 <= 4e9 {
            let s = pole_sensitivity(&model, &eq, &options)
                .unwrap_or_else(|e| panic!("k1 = {k1:e}: {e}"));
            assert!(s.repeated.is_empty());
            assert!(
                s.dpole_dp
                    .iter()
                    .all(|(a, b)| a.is_finite() && b.is_finite())
            );
        }
    }
    let mut spread = 0.0f64;
    for (load, _) in &loads[1..] {
        assert!((load / loads[0].0 - 1.0).abs() < 1e-5, "{loads:?}");
        spread = spread.max((load / loads[0].0 - 1.0).abs());
    }
    quoted::says(
        "docs/analyses.md",
        &[format!(
            "(q₀ − 0.6)·k₁ = {} N at every stiffness to {spread:.0e} of it (asserted 1e-5;",
            quoted::minus(format!("{:.4}", loads[0].0))
        )],
    );
    // the second joint moves with 1/k₁ too: its steps from 4e7 to 4e9 and from 4e9 to 4e11
    // in the ratio (1/4e7 − 1/4e9) / (1/4e9 − 1/4e11) = 100 (within the 1.7e-11 rad the
    // stiffest one's rounding leaves)
    let ratio = (loads[0].1 - loads[1].1) / (loads[1].1 - loads[2].1);
    println!("second joint's steps in the ratio {ratio:.2} (100 for 1/k1)");
    assert!((ratio / 100.0 - 1.0).abs() < 0.1, "{ratio}");
}

/// Statics whose stiffness a parameter made singular names the parameter: without gravity
/// the four-bar has no restoring force, and from its start (not on its loop) no equilibrium
/// is found; with gravity one is.
#[test]
fn a_stiffness_made_singular_by_a_parameter_is_named_by_statics() {
    let model = sweeps::with_params(fourbar::FourBar::default(), &[("g", 0.0)]);
    let e = static_equilibrium(&model, &StaticsOptions::default()).unwrap_err();
    let msg = e.to_string();
    println!("{msg}");
    assert!(
        msg.contains("is singular")
            && msg.contains(
                "with `g` at its default 9.81 rather than 0 an equilibrium is found from this start: check that parameter"
            ),
        "{msg}"
    );
}

/// Statics of a heavy machine: the 6-joint arm, its first axis along gravity (neutral about
/// it), with a million times its mass or its gravity. Its forces' rounding, 2e-15 of its
/// weight's moments, is then above the absolute tolerance of 1e-9 N·m, and where its
/// stiffness is singular statics said that no equilibrium was found; the equilibrium is the
/// light arm's, as a pure scaling of the forces leaves it.
#[test]
fn statics_of_a_heavy_machine_converge_at_the_rounding_of_its_forces() {
    let equilibrium = |param: &str, value: f64| {
        let model = sweeps::with_params(arm3d_6::Arm3d6::default(), &[(param, value)]);
        let eq = static_equilibrium(&model, &StaticsOptions::default())
            .unwrap_or_else(|e| panic!("{param} = {value:e}: {e}"));
        println!(
            "{param} = {value:e}: forces left {:.1e}, {:?}",
            eq.residual, eq.stability
        );
        eq.q
    };
    let light = equilibrium("m", 1.0);
    for (param, value) in [("m", 1e6), ("g", 9.81e6)] {
        let heavy = equilibrium(param, value);
        for (a, b) in light.iter().zip(&heavy) {
            assert!((a - b).abs() < 1e-9, "{param}: {light:?} against {heavy:?}");
        }
    }
}
