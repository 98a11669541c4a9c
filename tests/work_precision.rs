//! `mbs::work_precision` on seed2dof against its exact solution: two adaptive schemes at three
//! tolerances and a fixed-step run outside RK4's stability region.

mod common;
use mbs_models::seed2dof;

use common::seed2dof_exact;
use mbs::work_precision::{
    Reference, Setting, Study, StudyError, Sweep, WorkPrecision, mixed_error,
};
use mbs::{Failure, Scheme, simulate};
use seed2dof::Seed2dof;

/// Exact (q, qd) of seed2dof from q0 = (0, 1), qd0 = 0 (the model file's modal solution).
fn exact(t: f64) -> Vec<f64> {
    seed2dof::exact_state(t)
}

fn times() -> Vec<f64> {
    (1..=20).map(|k| 0.5 * k as f64).collect()
}

fn study() -> Study {
    let reference = Reference::exact("modal solution", times(), exact);
    Study {
        repeats: 1,
        ..Study::new("seed2dof", reference)
    }
    .sweep(Sweep::adaptive(Scheme::Dopri5, &[1e-4, 1e-6, 1e-8]))
    .sweep(Sweep::adaptive(Scheme::Radau5, &[1e-4, 1e-6, 1e-8]))
    // ω₂ = 62.9 rad/s: h ρ = 3.1 > 2.785, outside RK4's stability region
    .sweep(Sweep::fixed(Scheme::Rk4, &[0.05]))
}

/// Fields of a CSV line (double quotes protect commas).
fn fields(line: &str) -> Vec<String> {
    let (mut out, mut cur, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            '"' => quoted = !quoted,
            ',' if !quoted => out.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    out.push(cur);
    out
}

#[test]
fn table_csv_and_svg_of_seed2dof() {
    // the helper agrees with the tests' own exact solution
    assert!((exact(3.7)[1] - seed2dof_exact(3.7)[1]).abs() < 1e-15);
    let study = study();
    let wp: WorkPrecision = study.run(&Seed2dof::default()).unwrap();
    println!("{wp}");
    assert_eq!(wp.rows.len(), 7);

    // errors decrease with the tolerance, at t_end and over the run
    for label in ["dopri5", "radau5"] {
        let acc: Vec<_> = wp
            .rows_of(label)
            .map(|r| r.outcome.clone().unwrap())
            .collect();
        assert_eq!(acc.len(), 3);
        for w in acc.windows(2) {
            assert!(w[1].error_end < w[0].error_end / 5.0, "{label}: {w:?}");
            assert!(w[1].error_max < w[0].error_max / 5.0, "{label}: {w:?}");
            assert!(w[1].mescd > w[0].mescd + 0.7);
        }
        for a in &acc {
            assert!(a.error_max >= a.error_end && a.drift.is_none());
        }
    }

    // mescd of one row by hand: the same run, the Test Set's mixed error with floor 0.01
    let sweep = &study.sweeps[0];
    let setting = Setting::Rtol(1e-6);
    let row = wp
        .rows
        .iter()
        .find(|r| r.label == "dopri5" && r.setting == setting)
        .unwrap();
    let (tr, stats) = simulate(
        Seed2dof::default(),
        Scheme::Dopri5,
        study.options_for(sweep, setting),
    )
    .unwrap();
    let last = tr.len() - 1;
    assert_eq!(tr.t[last], 10.0);
    let y = [tr.q(last)[0], tr.q(last)[1], tr.qd(last)[0], tr.qd(last)[1]];
    let r = exact(10.0);
    let mut worst = 0.0f64;
    for i in 0..4 {
        worst = worst.max((y[i] - r[i]).abs() / (0.01 + r[i].abs()));
    }
    let by_hand = -worst.log10();
    let a = row.outcome.as_ref().unwrap();
    assert!(
        (a.mescd - by_hand).abs() < 1e-12,
        "{} vs {by_hand}",
        a.mescd
    );
    assert_eq!(a.error_end, mixed_error(&y, &r, 0.01));
    assert!(by_hand > 3.0 && by_hand < 6.0, "{by_hand}");
    assert_eq!(row.stats.steps, stats.steps);
    assert_eq!(row.stats.evaluations(), stats.evaluations());
    assert_eq!(row.repeats, 1);
    assert!(row.cpu.as_secs_f64() > 0.0);
    assert!(row.cpu.as_secs_f64() <= 1.5 * row.wall.as_secs_f64() + 1e-4);

    // the unstable run is a row of its own, with its typed failure
    let failed = wp.rows.last().unwrap();
    assert_eq!(
        (failed.scheme, failed.setting),
        (Scheme::Rk4, Setting::Step(0.05))
    );
    let f = failed.outcome.as_ref().unwrap_err();
    assert!(
        matches!(f.kind, Failure::UnstableStep { .. }),
        "{:?}",
        f.kind
    );
    assert_eq!(f.name(), "UnstableStep");
    let table = wp.to_string();
    assert!(table.contains("FAILED") && table.contains("UnstableStep"));

    // CSV: a header and one line per run, every line with the header's fields
    let csv = wp.to_csv();
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], WorkPrecision::csv_header());
    assert_eq!(lines.len(), 1 + wp.rows.len());
    let header = fields(lines[0]);
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    for line in &lines[1..] {
        assert_eq!(fields(line).len(), header.len(), "{line}");
    }
    let row2 = fields(lines[2]); // dopri5 at rtol 1e-6
    assert_eq!(row2[col("status")], "ok");
    assert_eq!(row2[col("setting")], "rtol");
    assert!((row2[col("mescd")].parse::<f64>().unwrap() - by_hand).abs() < 1e-12);
    let last = fields(lines[7]);
    assert_eq!(last[col("status")], "failed");
    assert_eq!(last[col("failure")], "UnstableStep");
    assert!(last[col("message")].contains("stability region"));

    // SVG: one line per scheme with a successful run
    let svg = wp.svg().unwrap();
    assert!(svg.starts_with("<svg"));
    assert!(svg.contains("\ndopri5\n") && svg.contains("\nradau5\n"));
    assert!(!svg.contains("\nrk4\n"));
}

#[test]
fn computed_references_and_bad_references() {
    // a self-computed reference is marked as such and close to the exact solution
    let times = times();
    let computed = Reference::compute(
        &Seed2dof::default(),
        times.clone(),
        (Scheme::Dopri5, Setting::Rtol(1e-12)),
        Some((Scheme::Radau5, Setting::Rtol(1e-12))),
        &mbs::Options::default(),
    )
    .unwrap();
    assert!(computed.source.to_string().starts_with("SELF-COMPUTED"));
    let (end, max) = computed.estimated_error(0.01).unwrap();
    assert!(end <= max && max < 1e-7, "{end:e} {max:e}");
    let worst = times
        .iter()
        .zip(&computed.states)
        .map(|(&t, y)| mixed_error(y, &exact(t), 0.01))
        .fold(0.0, f64::max);
    assert!(worst < 1e-8, "{worst:e}");

    // a failed run says which: the reference's own (nothing to keep), or its check's (the
    // reference computed is kept, without a check); RK4 at h = 0.05 is beyond its stability
    // on seed2dof's fast mode
    use mbs::work_precision::ReferenceError;
    let unstable = (Scheme::Rk4, Setting::Step(0.05));
    let e = Reference::compute(
        &Seed2dof::default(),
        times.clone(),
        unstable,
        None,
        &mbs::Options::default(),
    )
    .unwrap_err();
    assert!(
        matches!(e, ReferenceError::Run { scheme: "rk4", .. }),
        "{e}"
    );
    let e = Reference::compute(
        &Seed2dof::default(),
        times.clone(),
        (Scheme::Dopri5, Setting::Rtol(1e-10)),
        Some(unstable),
        &mbs::Options::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("checks the reference (rk4)"), "{e}");
    match e {
        ReferenceError::Check { reference, .. } => {
            assert_eq!(reference.states.len(), times.len());
            assert!(reference.check.is_none() && reference.estimated_error(0.01).is_none());
        }
        other => panic!("{other}"),
    }

    // a reference that does not fit the model is refused before any run
    let bad = Reference::data("two components", vec![1.0], vec![vec![0.0, 1.0]]);
    let e = Study::new("bad", bad)
        .run(&Seed2dof::default())
        .unwrap_err();
    assert!(
        matches!(e, StudyError::StateSize { expected: 4, .. }),
        "{e}"
    );
    let unsorted = Reference::exact("unsorted", vec![2.0, 1.0], exact);
    let e = Study::new("bad", unsorted)
        .run(&Seed2dof::default())
        .unwrap_err();
    assert!(matches!(e, StudyError::BadTimes { .. }), "{e}");
    // Euler angles named beyond the model's coordinates (or twice) are refused, not indexed
    for angles in [[0, 1, 5], [0, 1, 1]] {
        let sized = Reference::data("one joint", vec![1.0], vec![vec![0.0; 10]]);
        let study = Study {
            euler_angles: vec![angles],
            ..Study::new("bad", sized)
        };
        let e = study.run(&Seed2dof::default()).unwrap_err();
        assert!(
            matches!(
                e,
                StudyError::Invalid {
                    name: "euler_angles",
                    ..
                }
            ),
            "{angles:?}: {e}"
        );
    }
}

/// A study that would measure nothing, or not what its label says, is refused by name; a
/// reference that is not finite is refused (its NaN made every run look exact: the mixed
/// error dropped it); a sweep with one tolerance has no slope rather than a NaN one.
#[test]
fn studies_that_measure_nothing_and_references_that_are_not_finite_are_refused() {
    use mbs::work_precision::Proportionality;
    let model = Seed2dof::default();
    let reference = || Reference::exact("modal solution", times(), exact);
    let one = |s: Study| Study { repeats: 1, ..s };
    let e = one(Study::new("none", reference()))
        .run(&model)
        .unwrap_err();
    assert!(matches!(e, StudyError::NoSweeps), "{e}");
    let e = one(Study::new("empty", reference()))
        .sweep(Sweep::adaptive(Scheme::Dopri5, &[]))
        .run(&model)
        .unwrap_err();
    assert!(
        matches!(&e, StudyError::EmptySweep { label } if label == "dopri5"),
        "{e}"
    );
    let e = one(Study::new("fixed", reference()))
        .sweep(Sweep::fixed(Scheme::Rk4, &[1e-3]).global())
        .run(&model)
        .unwrap_err();
    assert!(matches!(e, StudyError::GlobalNeedsRtol { .. }), "{e}");
    for bad in [f64::NAN, f64::INFINITY] {
        let r = Reference::data("bad", vec![1.0], vec![vec![0.0, bad, 0.0, 0.0]]);
        let e = one(Study::new("bad", r))
            .sweep(Sweep::adaptive(Scheme::Dopri5, &[1e-6]))
            .run(&model)
            .unwrap_err();
        assert!(
            matches!(
                e,
                StudyError::NonFiniteReference {
                    index: 0,
                    component: 1,
                    ..
                }
            ),
            "{e}"
        );
    }
    // the mixed error of a state it cannot compare is NaN, never 0
    assert!(mixed_error(&[1.0, 2.0], &[1.0, f64::NAN], 0.01).is_nan());
    assert!(mixed_error(&[f64::NAN, 2.0], &[1.0, 2.0], 0.01).is_nan());
    assert!(mixed_error(&[1.0], &[1.0, 2.0], 0.01).is_nan());
    assert_eq!(mixed_error(&[1.0, 2.0], &[1.0, 2.0], 0.01), 0.0);
    // slopes: none from one run, or from a failed and an exact one
    let p = |digits: Vec<Option<f64>>| Proportionality {
        label: "x".into(),
        rtols: vec![1e-4, 1e-6][..digits.len()].to_vec(),
        digits,
    };
    assert_eq!(p(vec![Some(4.0)]).slope(), None);
    assert_eq!(p(vec![None, Some(f64::INFINITY)]).slope(), None);
    assert_eq!(p(vec![Some(3.0), Some(5.0)]).slope(), Some(1.0));
    assert_eq!(p(vec![Some(3.0), Some(f64::INFINITY)]).largest_loss(), 0.0);
}

/// Sweeps over different tolerances share the proportionality table's columns: each digit
/// under its own rtol, blanks elsewhere. The first sweep's rtols headed every row, so a
/// sweep over others had its digits, slope, offset and loss under the wrong headers.
#[test]
fn the_proportionality_table_puts_each_digit_under_its_rtol() {
    let reference = Reference::exact("modal solution", times(), exact);
    let wp = Study {
        repeats: 1,
        ..Study::new("seed2dof", reference)
    }
    .sweep(Sweep::adaptive(Scheme::Dopri5, &[1e-3, 1e-4]))
    .sweep(Sweep::adaptive(Scheme::Radau5, &[1e-4, 1e-5, 1e-6]))
    .run(&Seed2dof::default())
    .unwrap();
    let table = wp.proportionality_table();
    println!("{table}");
    let lines: Vec<&str> = table.lines().collect();
    let header = fields_of(lines[1]);
    assert_eq!(
        header,
        [
            "scheme", "1e-3", "1e-4", "1e-5", "1e-6", "slope", "offset", "loss"
        ]
    );
    // the columns are 7 characters wide after the label's: DOPRI5's row is blank under
    // 1e-5 and 1e-6, Radau5's under 1e-3
    let width = lines[1].find("   1e-3").unwrap();
    let cell = |line: &str, k: usize| line[width + 7 * k..width + 7 * (k + 1)].trim().to_string();
    let (dopri, radau) = (lines[2], lines[3]);
    assert!(dopri.starts_with("dopri5") && radau.starts_with("radau5"));
    assert!(!cell(dopri, 0).is_empty() && !cell(dopri, 1).is_empty());
    assert!(
        cell(dopri, 2).is_empty() && cell(dopri, 3).is_empty(),
        "{dopri}"
    );
    assert!(cell(radau, 0).is_empty(), "{radau}");
    for k in 1..4 {
        assert!(cell(radau, k).parse::<f64>().is_ok(), "{radau}");
    }
}

fn fields_of(line: &str) -> Vec<&str> {
    line.split_whitespace().collect()
}
