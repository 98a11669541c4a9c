//! What the benchmarks share.

/// The state every model is measured at: q and qd of `n` coordinates, away from any symmetry.
pub fn test_state(n: usize) -> (Vec<f64>, Vec<f64>) {
    let q = (0..n).map(|i| 0.5 * (1.3 * i as f64 + 0.4).sin()).collect();
    let qd = (0..n).map(|i| 0.7 * (0.9 * i as f64 + 0.2).cos()).collect();
    (q, qd)
}
