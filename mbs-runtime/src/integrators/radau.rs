//! Radau IIA collocation methods in second-order form: 2 stages, order 3 (the seed's
//! "RKI 5/12"), and 3 stages, order 5 (after Hairer's RADAU5), both adaptive or fixed-step.
//! Reference: E. Hairer & G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed.,
//! Springer 1996, §IV.5 (methods), §IV.8 (implementation), and the code RADAU5 described there.
//!
//! ```text
//! s = 2:  A = [5/12 −1/12; 3/4 1/4],  c = (1/3, 1),  b = (3/4, 1/4)
//! s = 3:  c = ((4 − √6)/10, (4 + √6)/10, 1), A and b as in Hairer & Wanner §IV.5
//! ```
//!
//! Order 2s − 1, A-stable and L-stable (stability function the (s−1, s) Padé approximant):
//! high-frequency modes are damped to zero, the low ones are kept to O(h^(2s−1)). Stiffly
//! accurate (b = last row of A, c_s = 1): the last stage is the new state.
//!
//! ## Stage equations on accelerations
//! On y = (q, qd), f(y) = (qd, qdd), with the stage accelerations A_i as unknowns, the stage
//! velocities and positions are
//!
//! ```text
//! V_i = qd₀ + h Σ_j a_ij A_j,   Q_i = q₀ + h c_i qd₀ + h² Σ_j (A²)_ij A_j
//! τ(t₀ + c_i h, Q_i, V_i, A_i) = 0,   i = 1..s       (τ = M qdd − h)
//! ```
//!
//! and q₁ = Q_s, qd₁ = V_s, qdd₁ = A_s. Simplified Newton with M, C_t = ∂τ/∂qd and
//! K_t = ∂τ/∂q frozen at the start of a step solves
//! (I ⊗ M + h A ⊗ C_t + h² A² ⊗ K_t) δ = −r. With A = T Λ T⁻¹ and W = (T⁻¹ ⊗ I) δ the system
//! splits into one n × n system per eigenvalue λ of A,
//!
//! ```text
//! (M + hλ C_t + h²λ² K_t) W_λ = −[(T⁻¹ ⊗ I) r]_λ,     δ = (T ⊗ I) W.
//! ```
//!
//! Radau IIA 3 has one real eigenvalue γ₀ ≈ 0.2749 (1/3.6378, RADAU5's γ) and a complex pair
//! λ, λ̄ ≈ 0.1626 ∓ 0.1849i; Radau IIA 2 has only a pair, λ = 1/(2 ± i√2). Since r is real,
//! W_λ̄ = conj(W_λ): one real and one complex factorisation (s = 3), or one complex (s = 2), and
//! δ_i = T_i,real·W_real + 2 Re(T_i,λ W_λ). Λ and T are computed in [`Coefficients::new`]
//! (eigenvalues from the characteristic polynomial, eigenvectors as null vectors of A − λI,
//! T⁻¹ from the left eigenvectors); unit tests check T Λ T⁻¹ = A and RADAU5's constants.
//!
//! Newton follows RADAU5: the correction is measured on the stage positions and velocities
//! (h²A²δ, hAδ) in the weighted RMS norm; with the contraction θ_k = ‖δ_k‖/‖δ_{k−1}‖
//! (geometric mean of the last two from the third iteration on) and η = θ/(1 − θ), it stops
//! when η‖δ_k‖ ≤ κ; it gives up (h·½) when θ ≥ 0.99 or after `max_iterations`, and, when
//! adaptive, as soon as the predicted η‖δ‖θ^(k_max − 1 − k) exceeds κ (h·0.8·q^(−1/(4 +
//! k_max − 1 − k))). The first iteration starts from the previous step's collocation
//! polynomial (the Lagrange polynomial through its stage accelerations, extrapolated), or
//! from qdd₀ at the first step. M, C_t, K_t are kept across steps while θ ≤ 0.001 and the
//! factorisations too when moreover h stays (h is kept when the controller proposes a factor
//! in [1, 1.2]); after a rejection they are re-evaluated unless they are already fresh.
//! With `NewtonOptions::reuse = false` they are re-evaluated at every attempt.
//!
//! ## Error estimate
//! RADAU5's embedded formula (Hairer & Wanner §IV.8, "error estimation") on the first-order
//! form: ŷ₁ = y₀ + h(γ₀ f(y₀) + Σ b̂_j f(Y_j)), with b̂ such that ŷ₁ has order s
//! (Σ b̂_j c_j^(k−1) + γ₀δ_k1 = 1/k, k = 1..s), so ŷ₁ − y₁ = γ₀ h f(y₀) + Σ e_i Z_i = O(h^(s+1))
//! with Z_i = Y_i − y₀ and e = A⁻ᵀ(b̂ − b); filtered for stiff components,
//!
//! ```text
//! err = (I − hγ₀ J)⁻¹ [γ₀ h f(y₀) + Σ e_i Z_i].
//! ```
//!
//! In second-order form J = [0 I; −M⁻¹K −M⁻¹C], and the bracket is (r_q, r_v) with
//! r_q = h² Σ_j (Aᵀ(b̂ − b))_j A_j (the qd₀ terms cancel since Σ(b̂ − b) = −γ₀) and
//! r_v = h(γ₀ qdd₀ + Σ_j (b̂ − b)_j A_j). Solving (I − gJ)(e_q, e_v) = (r_q, r_v), g = hγ₀:
//! e_q = r_q + g e_v, and substituting in the second row,
//!
//! ```text
//! (M + g C + g² K) e_v = M r_v − g K r_q,     e_q = r_q + g e_v,
//! ```
//!
//! one real n × n solve. For s = 3, γ₀ is the real eigenvalue of A, so the matrix is Newton's
//! real block (no extra factorisation; e/γ₀ = RADAU5's (−(13 + 7√6)/3, (−13 + 7√6)/3, −1/3),
//! checked in a unit test). For s = 2, A has no real eigenvalue: we use the same construction
//! with γ₀ = 1/√6 = |λ| (our choice; b̂ − b = γ₀(−3/2, 1/2), so ŷ₁ − y₁ = γ₀h(f₀ − 3/2 f(Y₁) +
//! 1/2 f(Y₂)) ≈ γ₀h³y'''/6), at the price of one extra real factorisation of
//! M + hγ₀C + h²γ₀²K (only when adaptive). The estimate is O(h^(s+1)) while the local error is
//! O(h^(2s)); a unit test measures both orders. As in RADAU5, when the first step or a step
//! after a rejection fails the test, the estimate is recomputed once with f(y₀ + err) in place
//! of f(y₀) (one more evaluation of M and h), which removes its spurious O(1) part on stiff
//! components. The error is measured on (q, qd) with the plain weights atol + rtol·|y| of
//! every component (an ODE: no index-dependent scaling).
//!
//! ## Step control
//! RADAU5's: tolerances transformed as rtol' = 0.1·rtol^((s+1)/(2s)), atol' = rtol'·atol/rtol
//! (RADAU5's 2/3 for s = 3), so that the O(h^(2s)) true error follows the user's tolerance;
//! h_new = h/q with q = err^(1/(s+1))/fac clamped to [1/8, 5], fac = min(0.9, 0.9(1 + 2k_max)/
//! (k + 2k_max)) for k Newton iterations, and Gustafsson's predictive controller (ACM TOMS 20,
//! 1994) on accepted steps: q ← max(q, (h_acc/h)(err²/err_acc)^(1/(s+1))/0.9), err_acc and
//! h_acc those of the previous accepted step. No growth right after a
//! rejection; a rejected first step is cut by 10. Newton's tolerance κ = max(10ε/rtol',
//! min(`tolerance_factor`, √rtol')), in the same weights.
//!
//! Fixed steps: the same Newton (tolerance from `NewtonOptions::{atol, rtol}`, κ = 1) without
//! the early give-up, retried once with fresh matrices when stale ones fail; no error test.
//! Outputs between steps use the driver's quintic Hermite interpolant, more accurate here
//! than the collocation polynomial (degree s).

use super::problem::Problem;
use super::{Attempt, Control, State, Stepper};
use crate::error::Failure;
use crate::linalg::{C64, Lu};
use crate::model::Model;

/// θ below which M, C_t, K_t are kept for the next step (RADAU5's THET)
const THET: f64 = 0.001;
/// h is kept (and the factorisations with it) when the proposed h_new/h is in [QUOT1, QUOT2]
const QUOT1: f64 = 1.0;
const QUOT2: f64 = 1.2;
const SAFE: f64 = 0.9;
/// bounds of q = h/h_new: h shrinks by at most 5 and grows by at most 8 per step
const FACL: f64 = 5.0;
const FACR: f64 = 0.125;

const MATRIX_C: &str = "the Radau iteration matrix M + hλC + h²λ²K (complex λ)";
const MATRIX_R: &str = "the Radau iteration matrix M + hγ₀C + h²γ₀²K (real γ₀)";

fn re(x: f64) -> C64 {
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
/// Newton's κ and its iteration limit.
struct Tol {
    rtol: f64,
    atol: f64,
    kappa: f64,
    max_iterations: usize,
    adaptive: bool,
}

impl Tol {
    fn new(ctl: &Control, s: usize) -> Tol {
        match ctl.adaptive {
            Some((rtol, atol)) => {
                // RADAU5's transformation, generalised: the estimate is O(h^(s+1)), the error
                // O(h^(2s))
                let expm = (s + 1) as f64 / (2 * s) as f64;
                let r = 0.1 * rtol.powf(expm);
                Tol {
                    rtol: r,
                    atol: r * atol / rtol,
                    kappa: (10.0 * f64::EPSILON / r).max(ctl.newton.kappa.min(r.sqrt())),
                    max_iterations: ctl.newton.max_iterations,
                    adaptive: true,
                }
            }
            None => Tol {
                rtol: ctl.newton.rtol,
                atol: ctl.newton.atol,
                kappa: ctl.newton.kappa,
                max_iterations: ctl.newton.max_iterations,
                adaptive: false,
            },
        }
    }
}

/// Why Newton stopped without converging, and the step it suggests.
struct NewtonFail {
    h_next: f64,
    iterations: usize,
    correction: f64,
    cause: Option<Failure>,
}

pub(crate) struct Radau {
    k: Coefficients,
    n: usize,
    /// M, C_t, K_t frozen at the start of the step they were evaluated at
    m: Vec<f64>,
    cm: Vec<f64>,
    km: Vec<f64>,
    /// M + hγ₀C + h²γ₀²K (Newton's real block for s = 3; the error filter for both)
    lu_r: Lu<f64>,
    /// M + hλC + h²λ²K
    lu_c: Lu<C64>,
    jac_valid: bool,
    /// the matrices were evaluated at the start of the current step
    jac_fresh: bool,
    /// re-evaluate them before the next attempt
    need_jac: bool,
    /// h of the current complex and real factorisations (NaN: none)
    h_c: f64,
    h_r: f64,
    /// stage accelerations (stage i at i·n..), and those of the last accepted step
    acc: Vec<f64>,
    acc_prev: Vec<f64>,
    /// the last accepted step (0 before the first) and the step being attempted
    h_prev: f64,
    h_try: f64,
    qs: Vec<f64>,
    vs: Vec<f64>,
    res: Vec<f64>,
    delta: Vec<f64>,
    rho_r: Vec<f64>,
    rho_c: Vec<C64>,
    scq: Vec<f64>,
    scv: Vec<f64>,
    rq: Vec<f64>,
    rv: Vec<f64>,
    tmp: Vec<f64>,
    qx: Vec<f64>,
    vx: Vec<f64>,
    ax: Vec<f64>,
    err: Vec<f64>,
    y0: Vec<f64>,
    y1: Vec<f64>,
    /// Newton: η = θ/(1 − θ) carried across steps, and the last contraction θ
    faccon: f64,
    theta: f64,
    /// step control
    first: bool,
    reject: bool,
    naccpt: usize,
    hacc: f64,
    erracc: f64,
}

impl Radau {
    fn new(n: usize, s: usize) -> Radau {
        let z = || vec![0.0; n];
        let zs = || vec![0.0; s * n];
        Radau {
            k: Coefficients::new(s),
            n,
            m: vec![0.0; n * n],
            cm: vec![0.0; n * n],
            km: vec![0.0; n * n],
            lu_r: Lu::new(n),
            lu_c: Lu::new(n),
            jac_valid: false,
            jac_fresh: false,
            need_jac: true,
            h_c: f64::NAN,
            h_r: f64::NAN,
            acc: zs(),
            acc_prev: zs(),
            h_prev: 0.0,
            h_try: 0.0,
            qs: zs(),
            vs: zs(),
            res: zs(),
            delta: zs(),
            rho_r: z(),
            rho_c: vec![C64::default(); n],
            scq: z(),
            scv: z(),
            rq: z(),
            rv: z(),
            tmp: z(),
            qx: z(),
            vx: z(),
            ax: z(),
            err: vec![0.0; 2 * n],
            y0: vec![0.0; 2 * n],
            y1: vec![0.0; 2 * n],
            faccon: 1.0,
            theta: THET,
            first: true,
            reject: false,
            naccpt: 0,
            hacc: 0.0,
            erracc: 1e-2,
        }
    }

    /// Radau IIA, 2 stages, order 3.
    pub fn radau3(n: usize) -> Radau {
        Radau::new(n, 2)
    }

    /// Radau IIA, 3 stages, order 5.
    pub fn radau5(n: usize) -> Radau {
        Radau::new(n, 3)
    }

    /// Factorises the complex block (and the real one when `real`) for step h, unless
    /// factorised for this h already.
    fn factor<M: Model>(&mut self, p: &mut Problem<M>, h: f64, real: bool) -> Result<(), Failure> {
        let close = |x: f64, y: f64| (x - y).abs() <= 1e-10 * x.abs().max(y.abs());
        if !close(self.h_c, h) {
            self.h_c = f64::NAN;
            let lam = self.k.lambda[self.k.complex];
            let g1 = lam * re(h);
            let g2 = lam * lam * re(h * h);
            let a = self.lu_c.matrix_mut();
            for i in 0..a.len() {
                a[i] = C64::new(
                    self.m[i] + g1.re * self.cm[i] + g2.re * self.km[i],
                    g1.im * self.cm[i] + g2.im * self.km[i],
                );
            }
            p.stats.factorizations += 1;
            self.lu_c.factor().map_err(|e| p.singular(MATRIX_C, e))?;
            self.h_c = h;
        }
        if real && !close(self.h_r, h) {
            self.h_r = f64::NAN;
            let g = self.k.gamma0 * h;
            let a = self.lu_r.matrix_mut();
            for i in 0..a.len() {
                a[i] = self.m[i] + g * self.cm[i] + g * g * self.km[i];
            }
            p.stats.factorizations += 1;
            self.lu_r.factor().map_err(|e| p.singular(MATRIX_R, e))?;
            self.h_r = h;
        }
        Ok(())
    }

    /// Starting stage accelerations: the previous step's collocation polynomial of the
    /// acceleration (degree s − 1 through its stages), extrapolated; qdd₀ at the first step.
    fn start_values(&mut self, cur: &State, h: f64) {
        let (s, n) = (self.k.s, self.n);
        let c = self.k.c;
        if self.h_prev > 0.0 {
            for i in 0..s {
                let x = 1.0 + c[i] * h / self.h_prev;
                let mut w = [0.0; 3];
                for j in 0..s {
                    w[j] = (0..s)
                        .filter(|&m| m != j)
                        .map(|m| (x - c[m]) / (c[j] - c[m]))
                        .product();
                }
                for r in 0..n {
                    self.acc[i * n + r] = (0..s).map(|j| w[j] * self.acc_prev[j * n + r]).sum();
                }
            }
        } else {
            for i in 0..s {
                self.acc[i * n..(i + 1) * n].copy_from_slice(&cur.qdd);
            }
        }
    }

    /// Stage positions and velocities of the current stage accelerations.
    fn stages(&mut self, cur: &State, h: f64) {
        let (s, n) = (self.k.s, self.n);
        let (a, a2, c) = (&self.k.a, &self.k.a2, &self.k.c);
        for i in 0..s {
            for r in 0..n {
                let (mut v, mut q) = (0.0, 0.0);
                for j in 0..s {
                    v += a[i][j] * self.acc[j * n + r];
                    q += a2[i][j] * self.acc[j * n + r];
                }
                self.vs[i * n + r] = cur.qd[r] + h * v;
                self.qs[i * n + r] = cur.q[r] + h * c[i] * cur.qd[r] + h * h * q;
            }
        }
    }

    /// Newton's correction δ = −(I ⊗ M + hA ⊗ C + h²A² ⊗ K)⁻¹ r through the eigen-blocks.
    fn correction<M: Model>(&mut self, p: &mut Problem<M>) {
        let (s, n) = (self.k.s, self.n);
        let (t, ti, kc) = (&self.k.t, &self.k.ti, self.k.complex);
        if let Some(kr) = self.k.real {
            for r in 0..n {
                self.rho_r[r] = -(0..s)
                    .map(|j| ti[kr][j].re * self.res[j * n + r])
                    .sum::<f64>();
            }
            self.lu_r.solve(&mut self.rho_r);
            p.stats.solves += 1;
        }
        for r in 0..n {
            let mut z = C64::default();
            for j in 0..s {
                z = z - ti[kc][j] * re(self.res[j * n + r]);
            }
            self.rho_c[r] = z;
        }
        self.lu_c.solve(&mut self.rho_c);
        p.stats.solves += 1;
        for i in 0..s {
            for r in 0..n {
                let mut d = 2.0 * (t[i][kc] * self.rho_c[r]).re;
                if let Some(kr) = self.k.real {
                    d += t[i][kr].re * self.rho_r[r];
                }
                self.delta[i * n + r] = d;
            }
        }
    }

    /// Weighted RMS norm of the stage position and velocity corrections h²A²δ, hAδ.
    fn correction_norm(&self, h: f64) -> f64 {
        let (s, n) = (self.k.s, self.n);
        let (a, a2) = (&self.k.a, &self.k.a2);
        let mut sum = 0.0;
        for i in 0..s {
            for r in 0..n {
                let (mut dv, mut dq) = (0.0, 0.0);
                for j in 0..s {
                    dv += a[i][j] * self.delta[j * n + r];
                    dq += a2[i][j] * self.delta[j * n + r];
                }
                let (eq, ev) = (h * h * dq / self.scq[r], h * dv / self.scv[r]);
                sum += eq * eq + ev * ev;
            }
        }
        (sum / (2 * s * n).max(1) as f64).sqrt()
    }

    /// Simplified Newton on the stage accelerations (RADAU5's iteration and stopping rules).
    fn newton<M: Model>(
        &mut self,
        p: &mut Problem<M>,
        cur: &State,
        h: f64,
        tol: &Tol,
    ) -> Result<usize, NewtonFail> {
        let (s, n) = (self.k.s, self.n);
        let nit = tol.max_iterations;
        self.faccon = self.faccon.max(f64::EPSILON).powf(0.8);
        self.theta = THET;
        let (mut newt, mut dynold, mut thqold) = (0usize, 1.0, 1.0);
        let mut last = f64::INFINITY;
        let fail = |h_next: f64, newt: usize, last: f64, cause: Option<Failure>| NewtonFail {
            h_next,
            iterations: newt,
            correction: last,
            cause,
        };
        loop {
            if newt >= nit {
                return Err(fail(0.5 * h, newt, last, None));
            }
            self.stages(cur, h);
            for i in 0..s {
                let (lo, hi) = (i * n, (i + 1) * n);
                if let Err(e) = p.residual(
                    cur.t + self.k.c[i] * h,
                    &self.qs[lo..hi],
                    &self.vs[lo..hi],
                    &self.acc[lo..hi],
                    &mut self.res[lo..hi],
                ) {
                    return Err(fail(0.5 * h, newt, last, Some(e)));
                }
            }
            self.correction(p);
            newt += 1;
            p.stats.newton_iterations += 1;
            let dyno = self.correction_norm(h);
            last = dyno;
            if !dyno.is_finite() {
                return Err(fail(0.5 * h, newt, last, None));
            }
            if newt > 1 && newt < nit {
                let thq = dyno / dynold;
                self.theta = if newt == 2 {
                    thq
                } else {
                    (thq * thqold).sqrt()
                };
                thqold = thq;
                if self.theta < 0.99 {
                    self.faccon = self.theta / (1.0 - self.theta);
                    let left = (nit - 1 - newt) as i32;
                    let dyth = self.faccon * dyno * self.theta.powi(left) / tol.kappa;
                    if tol.adaptive && dyth >= 1.0 {
                        // predicted not to converge in the iterations left: a smaller step
                        let qnewt = dyth.clamp(1e-4, 20.0);
                        let hhfac = 0.8 * qnewt.powf(-1.0 / (4.0 + left as f64));
                        return Err(fail(hhfac * h, newt, last, None));
                    }
                } else {
                    return Err(fail(0.5 * h, newt, last, None));
                }
            }
            dynold = dyno.max(f64::EPSILON);
            for (x, d) in self.acc.iter_mut().zip(&self.delta) {
                *x += d;
            }
            if self.faccon * dyno <= tol.kappa {
                self.stages(cur, h);
                return Ok(newt);
            }
        }
    }

    /// err = (I − gJ)⁻¹ (r_q, r_v) in second-order form, into `err` = (e_q, e_v):
    /// (M + gC + g²K) e_v = M r_v − g K r_q, e_q = r_q + g e_v.
    fn filter<M: Model>(&mut self, p: &mut Problem<M>, g: f64) {
        let n = self.n;
        for i in 0..n {
            let mut x = 0.0;
            for j in 0..n {
                x += self.m[i + n * j] * self.rv[j] - g * self.km[i + n * j] * self.rq[j];
            }
            self.tmp[i] = x;
        }
        self.lu_r.solve(&mut self.tmp);
        p.stats.solves += 1;
        for i in 0..n {
            self.err[n + i] = self.tmp[i];
            self.err[i] = self.rq[i] + g * self.tmp[i];
        }
    }

    /// RADAU5's error estimate of the converged step (`next` holds y₁), as a weighted norm.
    fn estimate<M: Model>(
        &mut self,
        p: &mut Problem<M>,
        cur: &State,
        next: &State,
        h: f64,
        ctl: &Control,
        tol: &Tol,
    ) -> f64 {
        let (s, n) = (self.k.s, self.n);
        let g0 = self.k.gamma0;
        // the filter matrix was factorised with h_r (equal to h up to rounding)
        let g = g0 * self.h_r;
        for r in 0..n {
            let (mut x, mut y) = (0.0, 0.0);
            for j in 0..s {
                x += self.k.dq[j] * self.acc[j * n + r];
                y += self.k.db[j] * self.acc[j * n + r];
            }
            self.rq[r] = h * h * x;
            self.rv[r] = h * (g0 * cur.qdd[r] + y);
        }
        self.filter(p, g);
        self.y0[..n].copy_from_slice(&cur.q);
        self.y0[n..].copy_from_slice(&cur.qd);
        self.y1[..n].copy_from_slice(&next.q);
        self.y1[n..].copy_from_slice(&next.qd);
        let norm_ctl = Control {
            adaptive: Some((tol.rtol, tol.atol)),
            ..*ctl
        };
        let mut err = norm_ctl.error_norm(&self.err, &self.y0, &self.y1);
        if err >= 1.0 && (self.first || self.reject) {
            // RADAU5: replace f(y₀) by f(y₀ + err), which damps the estimate's stiff part
            for r in 0..n {
                self.qx[r] = cur.q[r] + self.err[r];
                self.vx[r] = cur.qd[r] + self.err[n + r];
            }
            if p.accel(cur.t, &self.qx, &self.vx, &mut self.ax).is_ok() {
                for r in 0..n {
                    self.rq[r] += g * self.err[n + r];
                    self.rv[r] += g * (self.ax[r] - cur.qdd[r]);
                }
                self.filter(p, g);
                err = norm_ctl.error_norm(&self.err, &self.y0, &self.y1);
            }
        }
        err.max(1e-10)
    }
}

impl<M: Model> Stepper<M> for Radau {
    fn start(&mut self, _p: &mut Problem<M>, _s: &State, _ctl: &Control) -> Result<(), Failure> {
        self.jac_valid = false;
        self.need_jac = true;
        self.h_prev = 0.0;
        self.first = true;
        self.reject = false;
        self.naccpt = 0;
        self.faccon = 1.0;
        Ok(())
    }

    fn attempt(
        &mut self,
        p: &mut Problem<M>,
        cur: &State,
        h: f64,
        ctl: &Control,
        next: &mut State,
    ) -> Result<Attempt, Failure> {
        let (s, n) = (self.k.s, self.n);
        let tol = Tol::new(ctl, s);
        for r in 0..n {
            self.scq[r] = tol.atol + tol.rtol * cur.q[r].abs();
            self.scv[r] = tol.atol + tol.rtol * cur.qd[r].abs();
        }
        self.h_try = h;
        // the real factorisation: Newton's block (s = 3) or only the error filter (s = 2)
        let real = s == 3 || tol.adaptive;
        let mut retried = false;
        let newt = loop {
            if self.need_jac || !self.jac_valid || !ctl.newton.reuse {
                // independent of h: a failure here ends the simulation
                self.jac_valid = false;
                p.tangent_matrices(
                    cur.t,
                    &cur.q,
                    &cur.qd,
                    &cur.qdd,
                    &mut self.m,
                    &mut self.cm,
                    &mut self.km,
                )?;
                self.jac_valid = true;
                self.jac_fresh = true;
                self.need_jac = false;
                self.h_c = f64::NAN;
                self.h_r = f64::NAN;
            }
            let result = match self.factor(p, h, real) {
                Err(e) => Err(NewtonFail {
                    h_next: 0.5 * h,
                    iterations: 0,
                    correction: f64::INFINITY,
                    cause: Some(e),
                }),
                Ok(()) => {
                    self.start_values(cur, h);
                    self.newton(p, cur, h, &tol)
                }
            };
            match result {
                Ok(newt) => break newt,
                Err(f) => {
                    if !tol.adaptive && !self.jac_fresh && !retried {
                        // a fixed step cannot shrink: first try fresh matrices
                        retried = true;
                        self.need_jac = true;
                        continue;
                    }
                    self.need_jac = !self.jac_fresh;
                    self.reject = true;
                    return Ok(Attempt::RejectedNewton {
                        h_next: f.h_next,
                        iterations: f.iterations,
                        correction: f.correction,
                        cause: f.cause,
                    });
                }
            }
        };
        let last = (s - 1) * n;
        next.q.copy_from_slice(&self.qs[last..]);
        next.qd.copy_from_slice(&self.vs[last..]);
        next.qdd.copy_from_slice(&self.acc[last..]);
        let keep_matrices = ctl.newton.reuse && self.theta <= THET;
        if !tol.adaptive {
            self.first = false;
            self.jac_fresh = false;
            self.need_jac = !keep_matrices;
            return Ok(Attempt::Accepted { h_next: h });
        }
        let err = self.estimate(p, cur, next, h, ctl, &tol);
        let nit = tol.max_iterations as f64;
        let expo = 1.0 / (s as f64 + 1.0);
        let fac = SAFE.min(SAFE * (1.0 + 2.0 * nit) / (newt as f64 + 2.0 * nit));
        let mut quot = (err.powf(expo) / fac).clamp(FACR, FACL);
        let mut h_new = h / quot;
        if err < 1.0 {
            self.naccpt += 1;
            if self.naccpt > 1 {
                // Gustafsson's predictive controller
                let facgus = (self.hacc / h) * (err * err / self.erracc).powf(expo) / SAFE;
                quot = quot.max(facgus.clamp(FACR, FACL));
                h_new = h / quot;
            }
            self.hacc = h;
            self.erracc = err.max(1e-2);
            if self.reject {
                h_new = h_new.min(h);
            }
            self.reject = false;
            self.first = false;
            if keep_matrices && (QUOT1..=QUOT2).contains(&(h_new / h)) {
                h_new = h;
            }
            self.jac_fresh = false;
            self.need_jac = !keep_matrices;
            Ok(Attempt::Accepted { h_next: h_new })
        } else {
            let h_next = if self.first { 0.1 * h } else { h_new };
            self.reject = true;
            self.need_jac = !self.jac_fresh;
            Ok(Attempt::RejectedError { h_next })
        }
    }

    fn accepted(&mut self, _p: &mut Problem<M>, _prev: &State, _cur: &State) {
        std::mem::swap(&mut self.acc, &mut self.acc_prev);
        self.h_prev = self.h_try;
    }
}

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
