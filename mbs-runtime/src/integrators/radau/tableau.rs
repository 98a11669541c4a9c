//! The Radau IIA tableaux (s = 2, 3): A, b, c, A², the diagonalisation A = T Λ T⁻¹ that
//! decouples the stage equations, and the weights of the embedded error estimate.

use crate::linalg::C64;

pub(super) fn re(x: f64) -> C64 {
    C64::new(x, 0.0)
}

fn conj(z: C64) -> C64 {
    C64::new(z.re, -z.im)
}

/// Coefficients of an s-stage Radau IIA method (s = 2 or 3), of its diagonalisation and of
/// its error estimate.
#[derive(Clone, Debug)]
pub(crate) struct Coefficients {
    pub s: usize,
    pub a: [[f64; 3]; 3],
    /// A²
    pub a2: [[f64; 3]; 3],
    pub c: [f64; 3],
    /// eigenvalues of A: s = 3: (γ₀, λ, λ̄); s = 2: (λ, λ̄)
    pub lambda: [C64; 3],
    /// T: column k is a right eigenvector for `lambda[k]` (`t[i][k]`)
    pub t: [[C64; 3]; 3],
    /// T⁻¹: row k is the left eigenvector for `lambda[k]`, normalised so that T⁻¹T = I
    pub ti: [[C64; 3]; 3],
    /// index of the real eigenvalue (s = 3)
    pub real: Option<usize>,
    /// index of the complex eigenvalue used (its conjugate is implied)
    pub complex: usize,
    /// γ₀ of the error estimate (the real eigenvalue for s = 3, 1/√6 for s = 2)
    pub gamma0: f64,
    /// b̂ − b
    pub db: [f64; 3],
    /// Aᵀ(b̂ − b): weights of the stage accelerations in the position part of the estimate
    pub dq: [f64; 3],
}

impl Coefficients {
    pub fn new(s: usize) -> Coefficients {
        let mut a = [[0.0; 3]; 3];
        let mut c = [0.0; 3];
        match s {
            2 => {
                a[0][0] = 5.0 / 12.0;
                a[0][1] = -1.0 / 12.0;
                a[1][0] = 3.0 / 4.0;
                a[1][1] = 1.0 / 4.0;
                c[0] = 1.0 / 3.0;
                c[1] = 1.0;
            }
            3 => {
                let r6 = 6f64.sqrt();
                a = [
                    [
                        11.0 / 45.0 - 7.0 * r6 / 360.0,
                        37.0 / 225.0 - 169.0 * r6 / 1800.0,
                        -2.0 / 225.0 + r6 / 75.0,
                    ],
                    [
                        37.0 / 225.0 + 169.0 * r6 / 1800.0,
                        11.0 / 45.0 + 7.0 * r6 / 360.0,
                        -2.0 / 225.0 - r6 / 75.0,
                    ],
                    [4.0 / 9.0 - r6 / 36.0, 4.0 / 9.0 + r6 / 36.0, 1.0 / 9.0],
                ];
                c = [(4.0 - r6) / 10.0, (4.0 + r6) / 10.0, 1.0];
            }
            _ => panic!("Radau IIA with {s} stages is not implemented"),
        }
        let mut a2 = [[0.0; 3]; 3];
        for i in 0..s {
            for j in 0..s {
                a2[i][j] = (0..s).map(|k| a[i][k] * a[k][j]).sum();
            }
        }
        let lambda = eigenvalues(&a, s);
        let (real, complex) = if s == 3 { (Some(0), 1) } else { (None, 0) };
        let mut t = [[C64::default(); 3]; 3];
        let mut ti = [[C64::default(); 3]; 3];
        for k in 0..s {
            // the conjugate eigenvalue's vectors are the conjugates
            if k > 0 && lambda[k] == conj(lambda[k - 1]) && lambda[k].im != 0.0 {
                for i in 0..s {
                    t[i][k] = conj(t[i][k - 1]);
                    ti[k][i] = conj(ti[k - 1][i]);
                }
                continue;
            }
            let mut b = [[C64::default(); 3]; 3];
            let mut bt = [[C64::default(); 3]; 3];
            for i in 0..s {
                for j in 0..s {
                    let d = if i == j { lambda[k] } else { C64::default() };
                    b[i][j] = re(a[i][j]) - d;
                    bt[j][i] = b[i][j];
                }
            }
            let right = null_vector(&b, s);
            let left = null_vector(&bt, s);
            let mut dot = C64::default();
            for i in 0..s {
                dot = dot + left[i] * right[i];
            }
            for i in 0..s {
                t[i][k] = right[i];
                ti[k][i] = left[i] / dot;
            }
        }
        let gamma0 = match real {
            Some(k) => lambda[k].re,
            None => 1.0 / 6f64.sqrt(),
        };
        // b̂ − b from the moment conditions: Σ_j (b̂ − b)_j c_j^k = −γ₀ δ_k0, k = 0..s−1
        let mut v = [[0.0; 3]; 3];
        for k in 0..s {
            for j in 0..s {
                v[k][j] = c[j].powi(k as i32);
            }
        }
        let db = solve_small(v, [-gamma0, 0.0, 0.0], s);
        let mut dq = [0.0; 3];
        for j in 0..s {
            dq[j] = (0..s).map(|i| a[i][j] * db[i]).sum();
        }
        Coefficients {
            s,
            a,
            a2,
            c,
            lambda,
            t,
            ti,
            real,
            complex,
            gamma0,
            db,
            dq,
        }
    }
}

/// Eigenvalues of the s × s matrix `a` (s = 2: a complex pair; s = 3: one real root and a pair),
/// from the characteristic polynomial.
fn eigenvalues(a: &[[f64; 3]; 3], s: usize) -> [C64; 3] {
    if s == 2 {
        let tr = a[0][0] + a[1][1];
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        let im = (det - tr * tr / 4.0).sqrt();
        assert!(im > 0.0, "Radau IIA 2 has complex eigenvalues");
        return [
            C64::new(tr / 2.0, im),
            C64::new(tr / 2.0, -im),
            C64::default(),
        ];
    }
    let tr = a[0][0] + a[1][1] + a[2][2];
    let m2 = a[0][0] * a[1][1] - a[0][1] * a[1][0] + a[0][0] * a[2][2] - a[0][2] * a[2][0]
        + a[1][1] * a[2][2]
        - a[1][2] * a[2][1];
    let det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
        - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
        + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    // p(x) = x³ − tr x² + m2 x − det, convex right of its inflection point tr/3 and concave
    // left of it: Newton from beyond every root, on the side of the real root, is monotone
    let p = |x: f64| ((x - tr) * x + m2) * x - det;
    let dp = |x: f64| (3.0 * x - 2.0 * tr) * x + m2;
    let xi = tr / 3.0;
    let bound = 1.0 + tr.abs().max(m2.abs()).max(det.abs()) + xi.abs();
    let mut x = if p(xi) < 0.0 { xi + bound } else { xi - bound };
    for _ in 0..200 {
        let next = x - p(x) / dp(x);
        if next == x || !next.is_finite() {
            break;
        }
        x = next;
    }
    // deflate: p(x) = (x − r)(x² + βx + γ), β = r − tr, γ = det/r
    let beta = x - tr;
    let gamma = det / x;
    let im = (gamma - beta * beta / 4.0).sqrt();
    assert!(im > 0.0, "Radau IIA 3 has a complex pair of eigenvalues");
    [re(x), C64::new(-beta / 2.0, im), C64::new(-beta / 2.0, -im)]
}

/// A vector v ≠ 0 with B v = 0 for a singular s × s complex matrix B (rank s − 1): for s = 3
/// the (bilinear, unconjugated) cross product of the two rows that span most.
fn null_vector(b: &[[C64; 3]; 3], s: usize) -> [C64; 3] {
    let norm = |v: &[C64; 3]| v.iter().map(|z| z.re * z.re + z.im * z.im).sum::<f64>();
    if s == 2 {
        let v0 = [b[0][1], -b[0][0], C64::default()];
        let v1 = [b[1][1], -b[1][0], C64::default()];
        return if norm(&v0) >= norm(&v1) { v0 } else { v1 };
    }
    let cross = |u: &[C64; 3], v: &[C64; 3]| {
        [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ]
    };
    let cands = [
        cross(&b[0], &b[1]),
        cross(&b[0], &b[2]),
        cross(&b[1], &b[2]),
    ];
    let mut best = cands[0];
    for v in &cands[1..] {
        if norm(v) > norm(&best) {
            best = *v;
        }
    }
    best
}

/// Solves the s × s real system m x = rhs (s ≤ 3) by Gaussian elimination with pivoting.
fn solve_small(mut m: [[f64; 3]; 3], mut rhs: [f64; 3], s: usize) -> [f64; 3] {
    for k in 0..s {
        let p = (k..s)
            .max_by(|&i, &j| m[i][k].abs().total_cmp(&m[j][k].abs()))
            .unwrap_or(k);
        m.swap(k, p);
        rhs.swap(k, p);
        for i in k + 1..s {
            let f = m[i][k] / m[k][k];
            for j in k..s {
                m[i][j] -= f * m[k][j];
            }
            rhs[i] -= f * rhs[k];
        }
    }
    let mut x = [0.0; 3];
    for i in (0..s).rev() {
        let mut v = rhs[i];
        for j in i + 1..s {
            v -= m[i][j] * x[j];
        }
        x[i] = v / m[i][i];
    }
    x
}

/// Tolerances of one attempt: the weights atol + rtol·|y| of Newton and of the error test,
#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: C64, b: C64, tol: f64) -> bool {
        (a - b).re.hypot((a - b).im) <= tol
    }

    #[test]
    fn transformation_diagonalises_a() {
        for s in [2, 3] {
            let k = Coefficients::new(s);
            for i in 0..s {
                for j in 0..s {
                    // T Λ T⁻¹ = A and T⁻¹ T = I
                    let mut x = C64::default();
                    let mut y = C64::default();
                    for l in 0..s {
                        x = x + k.t[i][l] * k.lambda[l] * k.ti[l][j];
                        y = y + k.ti[i][l] * k.t[l][j];
                    }
                    assert!(
                        close(x, re(k.a[i][j]), 1e-14),
                        "s = {s}: TΛT⁻¹ ≠ A at {i},{j}"
                    );
                    let id = if i == j { 1.0 } else { 0.0 };
                    assert!(close(y, re(id), 1e-14), "s = {s}: T⁻¹T ≠ I at {i},{j}");
                }
                // stiffly accurate, c = A·1
                let row: f64 = k.a[i].iter().sum();
                assert!((row - k.c[i]).abs() < 1e-15);
            }
        }
        // eigenvalues of A⁻¹: 2 ± i√2 (s = 2) and RADAU5's γ, α ± iβ (s = 3)
        let inv = |z: C64| re(1.0) / z;
        let k2 = Coefficients::new(2);
        assert!(close(inv(k2.lambda[0]), C64::new(2.0, -2f64.sqrt()), 1e-14));
        let k3 = Coefficients::new(3);
        assert!((1.0 / k3.lambda[0].re - 3.637834252744496).abs() < 1e-14);
        assert_eq!(k3.lambda[0].im, 0.0);
        assert!(close(
            inv(k3.lambda[1]),
            C64::new(2.681082873627752, -3.05043019924741),
            1e-14
        ));
    }

    #[test]
    fn error_weights_are_radau5s() {
        let k = Coefficients::new(3);
        // e = A⁻ᵀ(b̂ − b), i.e. Aᵀe = b̂ − b; RADAU5's DD = e/γ₀
        let r6 = 6f64.sqrt();
        let dd = [
            -(13.0 + 7.0 * r6) / 3.0,
            (-13.0 + 7.0 * r6) / 3.0,
            -1.0 / 3.0,
        ];
        for j in 0..3 {
            let ate: f64 = (0..3).map(|i| k.a[i][j] * dd[i] * k.gamma0).sum();
            assert!((ate - k.db[j]).abs() < 1e-13, "{j}: {ate} vs {}", k.db[j]);
        }
        // ŷ₁ of order s: Σ b̂_j c_j^(m−1) + γ₀δ_m1 = 1/m, m = 1..s
        for s in [2, 3] {
            let k = Coefficients::new(s);
            let b = k.a[s - 1];
            for m in 1..=s {
                let sum: f64 = (0..s)
                    .map(|j| (b[j] + k.db[j]) * k.c[j].powi(m as i32 - 1))
                    .sum::<f64>()
                    + if m == 1 { k.gamma0 } else { 0.0 };
                assert!((sum - 1.0 / m as f64).abs() < 1e-14, "s = {s}, m = {m}");
            }
        }
        let k2 = Coefficients::new(2);
        let g = k2.gamma0;
        assert!((k2.db[0] + 1.5 * g).abs() < 1e-15 && (k2.db[1] - 0.5 * g).abs() < 1e-15);
    }

    /// One step of the method on the scalar ODE y'' = −sin(y) (pendulum), by fixed-point
    /// iteration on the stage accelerations (h small): the local error of y₁ is O(h^(2s)) and
    /// the unfiltered estimate (ŷ₁ − y₁, position and velocity parts) O(h^(s+1)).
    fn one_step(k: &Coefficients, h: f64) -> ([f64; 2], [f64; 2]) {
        let s = k.s;
        let (q0, v0) = (1.0f64, 0.3f64);
        let mut acc = [-q0.sin(); 3];
        for _ in 0..200 {
            let mut next = [0.0; 3];
            for i in 0..s {
                let q =
                    q0 + h * k.c[i] * v0 + h * h * (0..s).map(|j| k.a2[i][j] * acc[j]).sum::<f64>();
                next[i] = -q.sin();
            }
            acc = next;
        }
        let v1 = v0 + h * (0..s).map(|j| k.a[s - 1][j] * acc[j]).sum::<f64>();
        let q1 = q0 + h * v0 + h * h * (0..s).map(|j| k.a2[s - 1][j] * acc[j]).sum::<f64>();
        let eq = h * h * (0..s).map(|j| k.dq[j] * acc[j]).sum::<f64>();
        let ev = h * (k.gamma0 * -q0.sin() + (0..s).map(|j| k.db[j] * acc[j]).sum::<f64>());
        // reference: RK4 with 2000 substeps
        let (mut q, mut v) = (q0, v0);
        let m = 2000;
        let dt = h / m as f64;
        for _ in 0..m {
            let f = |q: f64, v: f64| (v, -q.sin());
            let k1 = f(q, v);
            let k2 = f(q + 0.5 * dt * k1.0, v + 0.5 * dt * k1.1);
            let k3 = f(q + 0.5 * dt * k2.0, v + 0.5 * dt * k2.1);
            let k4 = f(q + dt * k3.0, v + dt * k3.1);
            q += dt / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
            v += dt / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
        }
        let local = (q1 - q).abs().max((v1 - v).abs());
        let est = eq.abs().max(ev.abs());
        ([local, est], [q1, v1])
    }

    #[test]
    fn local_error_and_estimate_orders() {
        for s in [2, 3] {
            let k = Coefficients::new(s);
            let (h1, h2) = (0.2, 0.1);
            let (a, _) = one_step(&k, h1);
            let (b, _) = one_step(&k, h2);
            let local = (a[0] / b[0]).log2();
            let est = (a[1] / b[1]).log2();
            assert!(
                (local - 2.0 * s as f64).abs() < 0.3,
                "s = {s}: local error order {local:.2} (errors {:e}, {:e})",
                a[0],
                b[0]
            );
            assert!(
                (est - (s + 1) as f64).abs() < 0.3,
                "s = {s}: estimate order {est:.2}"
            );
        }
    }
}
