//! What every case shares: work-counter snapshots (as `tests/work_counters.rs` takes them),
//! finiteness of a trajectory, energy helpers.

use mbs::{Stats, Trajectory};

/// steps, rejected by the error test, rejected by Newton, M+h, forward dynamics, M, τ, tangents,
/// factorisations, solves, Newton iterations, Cholesky factorisations of M for the
/// singularity watch (`Stats::condition_checks`)
pub type Work = [usize; 12];

pub fn work(s: &Stats) -> Work {
    [
        s.steps,
        s.rejected_error,
        s.rejected_newton,
        s.dynamics,
        s.forward_dynamics,
        s.mass_matrix,
        s.inverse_dynamics,
        s.tangents,
        s.factorizations,
        s.solves,
        s.newton_iterations,
        s.condition_checks,
    ]
}

/// Prints every snapshot first (one run shows all the new values, in the form of the
/// expected table), then compares: a change that alters the work of a hard case fails here.
pub fn check_work(case: &str, got: &[(String, Work)], expected: &[Work]) {
    println!(
        "{case}: work (steps, rej. error, rej. Newton, M+h, forward, M, τ, tangents, factorisations, solves, Newton iterations, M checks)"
    );
    for (name, w) in got {
        println!("    {w:?}, // {name}");
    }
    assert_eq!(got.len(), expected.len(), "{case}: number of snapshots");
    for ((name, w), e) in got.iter().zip(expected) {
        assert_eq!(w, e, "{case}: work of {name}");
    }
}

/// No NaN or infinity anywhere in a trajectory (q, qd, qdd, λ, energy).
pub fn all_finite(tr: &Trajectory) -> bool {
    tr.q_data
        .iter()
        .chain(&tr.qd_data)
        .chain(&tr.qdd_data)
        .chain(&tr.lambda_data)
        .all(|x| x.is_finite())
        && tr
            .energy
            .iter()
            .all(|e| e.kinetic.is_finite() && e.potential.is_finite())
}

/// Least-squares line y = a + b x: (a, b, standard deviation of the residuals).
pub fn fit_line(x: &[f64], y: &[f64]) -> (f64, f64, f64) {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    let b = sxy / sxx;
    let a = my - b * mx;
    let ss: f64 = x.iter().zip(y).map(|(u, v)| (v - a - b * u).powi(2)).sum();
    (a, b, (ss / n).sqrt())
}
