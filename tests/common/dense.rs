//! A dense linear solve for the tests' independent references (no dependency for it).
#![allow(dead_code)] // each test binary uses a part

/// Solves A x = b, A column-major n × n, by Gaussian elimination with partial pivoting.
pub fn solve(a: &[f64], b: &[f64]) -> Vec<f64> {
    let n = b.len();
    let mut a = a.to_vec();
    let mut x = b.to_vec();
    for k in 0..n {
        let p = (k..n)
            .max_by(|&i, &j| a[i + n * k].abs().total_cmp(&a[j + n * k].abs()))
            .unwrap();
        for j in 0..n {
            a.swap(k + n * j, p + n * j);
        }
        x.swap(k, p);
        for i in k + 1..n {
            let f = a[i + n * k] / a[k + n * k];
            for j in k..n {
                a[i + n * j] -= f * a[k + n * j];
            }
            x[i] -= f * x[k];
        }
    }
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|j| a[i + n * j] * x[j]).sum();
        x[i] = (x[i] - s) / a[i + n * i];
    }
    x
}
