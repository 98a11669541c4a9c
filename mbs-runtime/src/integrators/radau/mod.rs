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
//! every component (an ODE: no index-dependent scaling; for index 3 see below).
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
//! the early give-up: twice `max_iterations`; a contraction estimate ≥ 0.99 ends the
//! iteration only once it passes 2 after the third iteration, or when the correction has
//! grown 1000-fold (until then the iteration goes on, with no credit for convergence); stale
//! matrices that fail are replaced by fresh ones once; no error test. The frozen matrices of
//! simplified Newton lag a fast rotation across the step (the tumbling body at h = 1 ms,
//! rates of 10–50 rad/s where Euler angles make M ill-conditioned): the first corrections
//! can grow along a soft direction of the iteration matrix while the residual falls, and the
//! iteration then settles to a steady contraction (0.25–0.3 per iteration there).
//! Outputs between steps use the driver's quintic Hermite interpolant, more accurate here
//! than the collocation polynomial (degree s).
//!
//! ## Index 3
//! A constrained model `M qdd = h + Bᵀλ`, `Φ(q, t) = 0`, `B = ∂Φ/∂q`, run with
//! `ConstraintMethod::Index3` (or `Auto`), is solved as the index-3 DAE, as Hairer's RADAU5
//! solves it: the stage multipliers Λ_i are unknowns with the stage accelerations, and the
//! stage equations are
//!
//! ```text
//! τ(t_i, Q_i, V_i, A_i) − B(Q_i)ᵀ Λ_i = 0,   Φ(Q_i, t_i) = 0,   i = 1..s
//! ```
//!
//! with Q_i, V_i as above; q₁ = Q_s, qd₁ = V_s, qdd₁ = A_s, λ₁ = Λ_s (stiffly accurate). Simplified
//! Newton freezes M, C_t, K_t, B and K_c = ∂(Bᵀλ)/∂q at the start of the step (at λ₀; K̃ = K_t −
//! K_c, and K_c = 0 with `MassOnly`). With δA = (T ⊗ I) W and δΛ = (T ⊗ I) U the system splits
//! again, one (n + nc) × (n + nc) system per eigenvalue μ of A:
//!
//! ```text
//! [ M + hμC_t + h²μ²K̃   −Bᵀ ] [W_μ]     [ [(T⁻¹ ⊗ I) r]_μ          ]
//! [ B                    0  ] [U_μ] = − [ [(T⁻¹ ⊗ I) Φ]_μ / (h²μ²) ]
//! ```
//!
//! (complex for the pair, real for s = 3's γ₀). The constraint rows are those of h²μ²B, the
//! derivative of Φ(Q_i) through Q_i = … + h²(A² A)_i, divided by h²μ²: the scaling that keeps the
//! matrix's condition bounded as h → 0 (unscaled it grows as h⁻²), the counterpart of
//! [`super::newton`]'s 1/β' (`ConstraintOptions::scaling` concerns the Newmark family only: the
//! Radau blocks are always scaled). Start values of Λ_i: the previous step's stage multipliers
//! extrapolated like the accelerations, λ₀ at the first step.
//!
//! Newton's norm adds the λ corrections to the stage position and velocity corrections, and
//! convergence also requires the predicted max |Φ_i(Q_j)| after the update to be below
//! `ConstraintOptions::tolerance`. At index 3 rounding errors ε·max|q| in the stage values of Φ
//! move the stage λ by up to ‖A⁻²‖∞ ε max|q|/h² (22 and 125 ε/h² for s = 2, 3, with (BM⁻¹Bᵀ)⁻¹
//! taken as 1) and, through δA = M⁻¹Bᵀ δΛ, the stage velocities by ‖A⁻¹‖∞ ε max|q|/h (7 and 18
//! ε/h); the weights of λ and velocity corrections are floored at these noise levels over κ, so
//! that Newton stops at the noise instead of stalling on it (without the floors the pendulum's
//! step collapsed at rtol 1e-13).
//!
//! Error estimate: RADAU5's for E y' = f(y) with a singular E, on y = (q, v, λ), E = diag(I, M,
//! 0), f = (v, h + Bᵀλ, Φ): err = (E − gJ)⁻¹[γ₀h f(y₀) + E Σ e_i Z_i], g = hγ₀, whose λ row is
//! −gB e_q = γ₀hΦ(q₀) ≈ 0. In second-order form, with K̃ in place of K and ẽ = g e_λ,
//!
//! ```text
//! [ M + gC_t + g²K̃   −Bᵀ ] [e_v]   [ M r_v − gK̃ r_q     ]
//! [ B                 0  ] [ẽ  ] = [ −(Φ(q₀) + B r_q)/g ],    e_q = r_q + g e_v,
//! ```
//!
//! Newton's real block for s = 3 (an extra factorisation for s = 2, as before), Φ(q₀) taken as 0
//! (it is below the constraint tolerance). As RADAU5 does for index-2 and index-3 components
//! (its NIND2, NIND3), the norm weights the velocity errors by h and the λ errors by h²: it is
//! taken on (e_q, h e_v, h² e_λ) against atol + rtol·max(|y₀|, |y₁|) of q, qd and λ, so that each
//! part is O(h^(s+1)) like the position part. The second estimate after a rejection uses f(y₀ +
//! err): velocity row −(τ(q₀ + e_q, v₀ + e_v, qdd₀) − B(q₀ + e_q)ᵀ(λ₀ + e_λ)) in place of 0,
//! constraint row Φ(q₀ + e_q).
//!
//! Orders (Hairer, Lubich & Roche 1989; Jay 1993; Hairer & Wanner §VII.4): for index-3 systems
//! Radau IIA with s stages gives positions of order 2s − 1, velocities of order s, λ of order
//! s − 1 (Radau5: 5, 3, 2; Radau3: 3, 2, 1), as measured on the pendulum with fixed steps
//! (`tests/radau_index3.rs`; Radau3's positions 2.8–2.9 at h = 1/80..1/640). The velocity and λ
//! errors are local (those of the last step) and, since the step control weights them by h
//! and h², follow the step size rather than rtol: λ within 1e-6 takes h ≲ 2e-3 with Radau5;
//! with Radau3 (first order in λ, about 0.12h on the pendulum) only near h = 1e-5, where the
//! rounding noise of λ (∝ ε/h²) is already as large (fixed steps of 1/80 000: 8.9e-7; of
//! 1/160 000: 3.6e-5).

mod tableau;

use super::constrained::Mode;
use super::problem::Problem;
use super::step_control::{Predictive, Tolerances};
use super::{Attempt, Control, State, Stepper};
use crate::error::Failure;
use crate::linalg::{C64, Field, Lu, Singular};
use crate::model::Model;
use crate::options::IterationMatrix;
use tableau::{Coefficients, re};

/// θ below which M, C_t, K_t are kept for the next step (RADAU5's THET)
const THET: f64 = 0.001;
/// h is kept (and the factorisations with it) when the proposed h_new/h is in [QUOT1, QUOT2]
const QUOT1: f64 = 1.0;
const QUOT2: f64 = 1.2;

const MATRIX_C: &str = "the Radau iteration matrix M + hλC + h²λ²K (complex λ)";
const MATRIX_R: &str = "the Radau iteration matrix M + hγ₀C + h²γ₀²K (real γ₀)";
const MATRIX_C3: &str =
    "the Radau index-3 iteration matrix [M + hλC + h²λ²(K − ∂(Bᵀλ)/∂q), −Bᵀ; B, 0] (complex λ)";
const MATRIX_R3: &str =
    "the Radau index-3 iteration matrix [M + hγ₀C + h²γ₀²(K − ∂(Bᵀλ)/∂q), −Bᵀ; B, 0] (real γ₀)";

/// The weights of Newton and of the error test, Newton's κ and its iteration limit.
struct Tol {
    weights: Tolerances,
    kappa: f64,
    max_iterations: usize,
    adaptive: bool,
}

impl Tol {
    fn new(ctl: &Control, s: usize) -> Tol {
        match ctl.adaptive {
            Some(Tolerances { rtol, atol }) => {
                // RADAU5's transformation, generalised: the estimate is O(h^(s+1)), the error
                // O(h^(2s))
                let expm = (s + 1) as f64 / (2 * s) as f64;
                let r = 0.1 * rtol.powf(expm);
                Tol {
                    weights: Tolerances {
                        rtol: r,
                        atol: r * atol / rtol,
                    },
                    kappa: (10.0 * f64::EPSILON / r).max(ctl.newton.kappa.min(r.sqrt())),
                    max_iterations: ctl.newton.max_iterations,
                    adaptive: true,
                }
            }
            None => Tol {
                weights: Tolerances {
                    rtol: ctl.newton.rtol,
                    atol: ctl.newton.atol,
                },
                kappa: ctl.newton.kappa,
                // a failure is final at a fixed step: twice the iterations before giving up
                max_iterations: 2 * ctl.newton.max_iterations,
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
    control: Predictive,
    /// index 3 (enabled in `start`): the number of constraints (0 otherwise) and |Φ_i| to
    /// reach in Newton
    nc: usize,
    tol_phi: f64,
    /// ‖A⁻¹‖∞ and ‖A⁻²‖∞: the stage λ's response to stage values of Φ is
    /// (h²A²)⁻¹ ⊗ (BM⁻¹Bᵀ)⁻¹, the stage velocities' (hA)⁻¹ ⊗ M⁻¹Bᵀ(BM⁻¹Bᵀ)⁻¹
    ainv: f64,
    a2inv: f64,
    /// B (nc × n) and ∂(Bᵀλ)/∂q frozen with M, C_t, K_t (`km` then holds K_t − ∂(Bᵀλ)/∂q)
    bm: Vec<f64>,
    kc: Vec<f64>,
    /// stage multipliers (stage i at i·nc..), those of the last accepted step, Φ at the
    /// stages, Newton's λ corrections and their weights, the largest |Φ_i| of the iteration
    lam: Vec<f64>,
    lam_prev: Vec<f64>,
    phis: Vec<f64>,
    dlam: Vec<f64>,
    scl: Vec<f64>,
    phi_max: f64,
    /// error estimate: the velocity row's bracket, Φ in the constraint row, λ₀ + e_λ
    bv: Vec<f64>,
    phix: Vec<f64>,
    lx: Vec<f64>,
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
            control: Predictive::new(s),
            nc: 0,
            tol_phi: f64::INFINITY,
            ainv: 0.0,
            a2inv: 0.0,
            bm: Vec::new(),
            kc: Vec::new(),
            lam: Vec::new(),
            lam_prev: Vec::new(),
            phis: Vec::new(),
            dlam: Vec::new(),
            scl: Vec::new(),
            phi_max: 0.0,
            bv: Vec::new(),
            phix: Vec::new(),
            lx: Vec::new(),
        }
    }

    /// Solves for (A_i, Λ_i) at index 3 from now on: `nc` constraints, |Φ_i| ≤ `tol_phi` at
    /// convergence. The only allocation: the augmented matrices and their buffers.
    fn enable_index3(&mut self, nc: usize, tol_phi: f64) {
        let (n, s) = (self.n, self.k.s);
        self.tol_phi = tol_phi;
        if self.nc == nc {
            // a restart (after a controller's sample): the buffers are there
            self.h_c = f64::NAN;
            self.h_r = f64::NAN;
            return;
        }
        let z = |k: usize| vec![0.0; k];
        self.nc = nc;
        self.tol_phi = tol_phi;
        self.ainv = inverse_row_norm(&self.k.a, s);
        self.a2inv = inverse_row_norm(&self.k.a2, s);
        self.lu_r = Lu::new(n + nc);
        self.lu_c = Lu::new(n + nc);
        self.h_c = f64::NAN;
        self.h_r = f64::NAN;
        self.rho_r = z(n + nc);
        self.rho_c = vec![C64::default(); n + nc];
        self.tmp = z(n + nc);
        self.bm = z(nc * n);
        self.kc = z(n * n);
        self.lam = z(s * nc);
        self.lam_prev = z(s * nc);
        self.phis = z(s * nc);
        self.dlam = z(s * nc);
        self.scl = z(nc);
        self.err = z(2 * n + nc);
        self.y0 = z(2 * n + nc);
        self.y1 = z(2 * n + nc);
        self.bv = z(n);
        self.phix = z(nc);
        self.lx = z(nc);
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
    /// factorised for this h already. At index 3 the blocks are bordered by −Bᵀ and B.
    fn factor<M: Model>(&mut self, p: &mut Problem<M>, h: f64, real: bool) -> Result<(), Failure> {
        let close = |x: f64, y: f64| (x - y).abs() <= 1e-10 * x.abs().max(y.abs());
        let (n, nc) = (self.n, self.nc);
        let big = n + nc;
        if !close(self.h_c, h) {
            self.h_c = f64::NAN;
            let lam = self.k.lambda[self.k.complex];
            let g1 = lam * re(h);
            let g2 = lam * lam * re(h * h);
            let a = self.lu_c.matrix_mut();
            for j in 0..n {
                for i in 0..n {
                    let x = i + n * j;
                    a[i + big * j] = C64::new(
                        self.m[x] + g1.re * self.cm[x] + g2.re * self.km[x],
                        g1.im * self.cm[x] + g2.im * self.km[x],
                    );
                }
            }
            border(a, &self.bm, n, nc);
            p.stats.factorizations += 1;
            if let Err(e) = self.lu_c.factor() {
                return Err(self.singular(p, e, MATRIX_C, MATRIX_C3));
            }
            self.h_c = h;
        }
        if real && !close(self.h_r, h) {
            self.h_r = f64::NAN;
            let g = self.k.gamma0 * h;
            let a = self.lu_r.matrix_mut();
            for j in 0..n {
                for i in 0..n {
                    let x = i + n * j;
                    a[i + big * j] = self.m[x] + g * self.cm[x] + g * g * self.km[x];
                }
            }
            border(a, &self.bm, n, nc);
            p.stats.factorizations += 1;
            if let Err(e) = self.lu_r.factor() {
                return Err(self.singular(p, e, MATRIX_R, MATRIX_R3));
            }
            self.h_r = h;
        }
        Ok(())
    }

    /// The failure for a singular iteration matrix: its pivot column names a coordinate, or
    /// (index 3) the multiplier of a constraint.
    fn singular<M: Model>(
        &self,
        p: &Problem<M>,
        e: Singular,
        plain: &'static str,
        index3: &'static str,
    ) -> Failure {
        p.singular(if self.nc == 0 { plain } else { index3 }, e)
    }

    /// Index 3: ∂(Bᵀλ)/∂q and B at the start of the step (with λ₀), frozen with M, C_t, K_t;
    /// K_t − ∂(Bᵀλ)/∂q replaces K_t in `km`.
    fn constraint_matrices<M: Model>(
        &mut self,
        p: &mut Problem<M>,
        cur: &State,
    ) -> Result<(), Failure> {
        let (n, nc) = (self.n, self.nc);
        if p.iteration != IterationMatrix::MassOnly {
            p.model
                .constraint_tangent(cur.t, &cur.q, &cur.lambda, &mut self.kc);
            p.stats.constraints += 1;
            p.check("∂(Bᵀλ)/∂q", &self.kc)?;
            for (k, c) in self.km.iter_mut().zip(&self.kc) {
                *k -= c;
            }
        }
        if let Some(c) = p.con.as_mut() {
            c.eval_b(&p.model, &mut p.stats, cur.t, &cur.q);
            self.bm.copy_from_slice(&c.b);
        }
        match self.bm.iter().position(|x| !x.is_finite()) {
            None => Ok(()),
            Some(i) => Err(Failure::NonFinite {
                quantity: "B = ∂Φ/∂q",
                coordinate: p.label((i / nc).min(n - 1)),
            }),
        }
    }

    /// Starting stage accelerations (and multipliers): the previous step's collocation
    /// polynomial of the acceleration (degree s − 1 through its stages), extrapolated; qdd₀
    /// (λ₀) at the first step.
    fn start_values(&mut self, cur: &State, h: f64) {
        let (s, n, nc) = (self.k.s, self.n, self.nc);
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
                for r in 0..nc {
                    self.lam[i * nc + r] = (0..s).map(|j| w[j] * self.lam_prev[j * nc + r]).sum();
                }
            }
        } else {
            for i in 0..s {
                self.acc[i * n..(i + 1) * n].copy_from_slice(&cur.qdd);
                self.lam[i * nc..(i + 1) * nc].copy_from_slice(&cur.lambda[..nc]);
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

    /// Newton's correction δ = −(I ⊗ M + hA ⊗ C + h²A² ⊗ K)⁻¹ r through the eigen-blocks; at
    /// index 3 also the λ corrections, the constraint rows of block μ being
    /// B W_μ = −[(T⁻¹ ⊗ I) Φ]_μ / (h²μ²).
    fn correction<M: Model>(&mut self, p: &mut Problem<M>, h: f64) {
        let (s, n, nc) = (self.k.s, self.n, self.nc);
        let (t, ti, kc) = (&self.k.t, &self.k.ti, self.k.complex);
        if let Some(kr) = self.k.real {
            for r in 0..n {
                self.rho_r[r] = -(0..s)
                    .map(|j| ti[kr][j].re * self.res[j * n + r])
                    .sum::<f64>();
            }
            if nc > 0 {
                let g = self.k.lambda[kr].re * h;
                let scale = 1.0 / (g * g);
                for r in 0..nc {
                    self.rho_r[n + r] = -scale
                        * (0..s)
                            .map(|j| ti[kr][j].re * self.phis[j * nc + r])
                            .sum::<f64>();
                }
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
        if nc > 0 {
            let lam = self.k.lambda[kc];
            let g2 = lam * lam * re(h * h);
            for r in 0..nc {
                let mut z = C64::default();
                for j in 0..s {
                    z = z - ti[kc][j] * re(self.phis[j * nc + r]);
                }
                self.rho_c[n + r] = z / g2;
            }
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
            for r in 0..nc {
                let mut d = 2.0 * (t[i][kc] * self.rho_c[n + r]).re;
                if let Some(kr) = self.k.real {
                    d += t[i][kr].re * self.rho_r[n + r];
                }
                self.dlam[i * nc + r] = d;
            }
        }
    }

    /// Weighted RMS norm of the stage position and velocity corrections h²A²δ, hAδ (and, at
    /// index 3, of the λ corrections).
    fn correction_norm(&self, h: f64) -> f64 {
        let (s, n, nc) = (self.k.s, self.n, self.nc);
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
            for r in 0..nc {
                let el = self.dlam[i * nc + r] / self.scl[r];
                sum += el * el;
            }
        }
        (sum / (2 * s * n + s * nc).max(1) as f64).sqrt()
    }

    /// Index 3, stage i: r_i −= B(Q_i)ᵀΛ_i, Φ(Q_i, t) into `phis`, the largest |Φ_i| kept.
    fn constraint_residual<M: Model>(
        &mut self,
        p: &mut Problem<M>,
        i: usize,
        t: f64,
    ) -> Result<(), Failure> {
        let (n, nc) = (self.n, self.nc);
        let (lo, hi) = (i * n, (i + 1) * n);
        if let Some(c) = p.con.as_mut() {
            c.eval_b(&p.model, &mut p.stats, t, &self.qs[lo..hi]);
            c.eval_phi(&p.model, &mut p.stats, t, &self.qs[lo..hi]);
            let lam = &self.lam[i * nc..(i + 1) * nc];
            for j in 0..n {
                self.res[lo + j] -= (0..nc).map(|k| c.b[k + nc * j] * lam[k]).sum::<f64>();
            }
            self.phis[i * nc..(i + 1) * nc].copy_from_slice(&c.phi);
            self.phi_max = self.phi_max.max(c.worst().0);
        }
        p.check("τ − Bᵀλ", &self.res[lo..hi])
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
        let mut dyn1 = f64::INFINITY;
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
            self.phi_max = 0.0;
            for i in 0..s {
                let (lo, hi) = (i * n, (i + 1) * n);
                let ti = cur.t + self.k.c[i] * h;
                let mut r = p.residual(
                    ti,
                    &self.qs[lo..hi],
                    &self.vs[lo..hi],
                    &self.acc[lo..hi],
                    &mut self.res[lo..hi],
                );
                if self.nc > 0 && r.is_ok() {
                    r = self.constraint_residual(p, i, ti);
                }
                if let Err(e) = r {
                    return Err(fail(0.5 * h, newt, last, Some(e)));
                }
            }
            self.correction(p, h);
            newt += 1;
            p.stats.newton_iterations += 1;
            let dyno = self.correction_norm(h);
            last = dyno;
            if newt == 1 {
                dyn1 = dyno;
            }
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
                } else if tol.adaptive || (self.theta >= 2.0 && newt > 3) || dyno > 1e3 * dyn1 {
                    return Err(fail(0.5 * h, newt, last, None));
                } else {
                    // a fixed step cannot shrink: keep iterating through an early transient,
                    // without credit for a contraction not yet seen. The ratio of corrections
                    // is a poor guide early on when the frozen matrices lag a fast rotation:
                    // on the tumbling body at h = 1 ms the residual falls 40× in the first
                    // iteration while the correction, along a soft direction of the
                    // iteration matrix, does not, and the third iteration falls 300×
                    self.faccon = 1.0;
                }
            }
            dynold = dyno.max(f64::EPSILON);
            for (x, d) in self.acc.iter_mut().zip(&self.delta) {
                *x += d;
            }
            for (x, d) in self.lam.iter_mut().zip(&self.dlam) {
                *x += d;
            }
            // index 3: the largest |Φ_i| after this update, predicted from its value before
            let phi_ok = self.nc == 0 || self.phi_max * self.faccon.min(1.0) <= self.tol_phi;
            if self.faccon * dyno <= tol.kappa && phi_ok {
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
        let mut err = tol.weights.error_norm(&self.err, &self.y0, &self.y1);
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
                err = tol.weights.error_norm(&self.err, &self.y0, &self.y1);
            }
        }
        err.max(1e-10)
    }

    /// Index 3: the filter (E − gJ)⁻¹ on y = (q, v, λ), E = diag(I, M, 0), in second-order
    /// form with the real block: [M + gC + g²K̃, −Bᵀ; B, 0] (e_v, g e_λ) =
    /// (b_v − gK̃ r_q, −(Φ + B r_q)/g), e_q = r_q + g e_v; into `err` as (e_q, h e_v, h² e_λ).
    fn filter3<M: Model>(&mut self, p: &mut Problem<M>, g: f64, h: f64) {
        let (n, nc) = (self.n, self.nc);
        for i in 0..n {
            let mut x = self.bv[i];
            for j in 0..n {
                x -= g * self.km[i + n * j] * self.rq[j];
            }
            self.tmp[i] = x;
        }
        for k in 0..nc {
            let brq: f64 = (0..n).map(|j| self.bm[k + nc * j] * self.rq[j]).sum();
            self.tmp[n + k] = -(self.phix[k] + brq) / g;
        }
        self.lu_r.solve(&mut self.tmp);
        p.stats.solves += 1;
        for i in 0..n {
            self.err[i] = self.rq[i] + g * self.tmp[i];
            self.err[n + i] = h * self.tmp[i];
        }
        for k in 0..nc {
            self.err[2 * n + k] = h * h * self.tmp[n + k] / g;
        }
    }

    /// Index 3: RADAU5's estimate for the DAE E y' = f(y), y = (q, v, λ), f = (v, h + Bᵀλ,
    /// Φ), with the velocity errors weighted by h and the multipliers' by h² (RADAU5's
    /// scaling of index-2 and index-3 components).
    fn estimate3<M: Model>(
        &mut self,
        p: &mut Problem<M>,
        cur: &State,
        next: &State,
        h: f64,
        tol: &Tol,
    ) -> f64 {
        let (s, n, nc) = (self.k.s, self.n, self.nc);
        let g0 = self.k.gamma0;
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
        // the velocity row's bracket M r_v (γ₀h f_v(y₀) = g M qdd₀ with qdd₀, λ₀ consistent);
        // the constraint row's γ₀h Φ(q₀) ≈ 0 (|Φ(q₀)| is within the Newton tolerance)
        for i in 0..n {
            self.bv[i] = (0..n).map(|j| self.m[i + n * j] * self.rv[j]).sum();
        }
        self.phix.fill(0.0);
        self.filter3(p, g, h);
        self.y0[..n].copy_from_slice(&cur.q);
        self.y0[n..2 * n].copy_from_slice(&cur.qd);
        self.y0[2 * n..].copy_from_slice(&cur.lambda[..nc]);
        self.y1[..n].copy_from_slice(&next.q);
        self.y1[n..2 * n].copy_from_slice(&next.qd);
        self.y1[2 * n..].copy_from_slice(&next.lambda[..nc]);
        let mut err = tol.weights.error_norm(&self.err, &self.y0, &self.y1);
        if err >= 1.0 && (self.first || self.reject) {
            // RADAU5: f(y₀ + err) in place of f(y₀); its velocity row, less M qdd₀, is
            // −(τ(q₀ + e_q, v₀ + e_v, qdd₀) − Bᵀ(λ₀ + e_λ)) up to O(e_q) terms
            let hr = 1.0 / h;
            for r in 0..n {
                self.qx[r] = cur.q[r] + self.err[r];
                self.vx[r] = cur.qd[r] + self.err[n + r] * hr;
            }
            for k in 0..nc {
                self.lx[k] = cur.lambda[k] + self.err[2 * n + k] * hr * hr;
            }
            if self.residual_at(p, cur) {
                for r in 0..n {
                    self.rq[r] += g * self.err[n + r] * hr;
                    self.bv[r] -= g * self.ax[r];
                }
                self.filter3(p, g, h);
                err = tol.weights.error_norm(&self.err, &self.y0, &self.y1);
            }
        }
        err.max(1e-10)
    }

    /// τ(t₀, qx, vx, qdd₀) − B(qx)ᵀ lx into `ax` and Φ(qx) into `phix`; false when an
    /// evaluation fails or is not finite.
    fn residual_at<M: Model>(&mut self, p: &mut Problem<M>, cur: &State) -> bool {
        let (n, nc) = (self.n, self.nc);
        if p.residual(cur.t, &self.qx, &self.vx, &cur.qdd, &mut self.ax)
            .is_err()
        {
            return false;
        }
        if let Some(c) = p.con.as_mut() {
            c.eval_b(&p.model, &mut p.stats, cur.t, &self.qx);
            c.eval_phi(&p.model, &mut p.stats, cur.t, &self.qx);
            for j in 0..n {
                self.ax[j] -= (0..nc).map(|k| c.b[k + nc * j] * self.lx[k]).sum::<f64>();
            }
            self.phix.copy_from_slice(&c.phi);
        }
        self.ax.iter().chain(&self.phix).all(|x| x.is_finite())
    }
}

impl<M: Model> Stepper<M> for Radau {
    fn start(&mut self, p: &mut Problem<M>, _s: &State, _ctl: &Control) -> Result<(), Failure> {
        if let Some(c) = p.con.as_ref().filter(|c| c.mode == Mode::Index3) {
            self.enable_index3(c.nc, c.tol);
        }
        self.jac_valid = false;
        self.need_jac = true;
        self.h_prev = 0.0;
        self.first = true;
        self.reject = false;
        self.control.restart();
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
            self.scq[r] = tol.weights.atol + tol.weights.rtol * cur.q[r].abs();
            self.scv[r] = tol.weights.atol + tol.weights.rtol * cur.qd[r].abs();
        }
        if self.nc > 0 {
            // λ and the velocities to the Newton tolerance, but not below their rounding
            // noise (Newton stops when its predicted error is below κ times the weights):
            // rounding errors ε·max|q| in the stage values of Φ move the stage λ by up to
            // ‖A⁻²‖∞ ε max|q|/h² (times (BM⁻¹Bᵀ)⁻¹, taken as 1) and, through
            // δA = M⁻¹Bᵀ δΛ, the stage velocities by up to ‖A⁻¹‖∞ ε max|q|/h
            let qmax = cur.q.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            let noise = f64::EPSILON * qmax / (tol.kappa * h);
            for r in 0..n {
                self.scv[r] += noise * self.ainv;
            }
            for r in 0..self.nc {
                self.scl[r] = tol.weights.atol
                    + tol.weights.rtol * cur.lambda[r].abs()
                    + noise * self.a2inv / h;
            }
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
                if self.nc > 0 {
                    self.constraint_matrices(p, cur)?;
                }
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
        let nc = self.nc;
        next.lambda[..nc].copy_from_slice(&self.lam[(s - 1) * nc..]);
        let keep_matrices = ctl.newton.reuse && self.theta <= THET;
        if !tol.adaptive {
            self.first = false;
            self.jac_fresh = false;
            self.need_jac = !keep_matrices;
            return Ok(Attempt::Accepted { h_next: h });
        }
        let err = if nc > 0 {
            self.estimate3(p, cur, next, h, &tol)
        } else {
            self.estimate(p, cur, next, h, &tol)
        };
        let nit = tol.max_iterations as f64;
        let safe = Predictive::SAFETY;
        let fac = safe.min(safe * (1.0 + 2.0 * nit) / (newt as f64 + 2.0 * nit));
        let quot = self.control.quotient(err, fac);
        if err < 1.0 {
            let mut h_new = self.control.accept(h, err, quot);
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
            let h_next = if self.first { 0.1 * h } else { h / quot };
            self.reject = true;
            self.need_jac = !self.jac_fresh;
            Ok(Attempt::RejectedError { h_next })
        }
    }

    fn accepted(&mut self, _p: &mut Problem<M>, _prev: &State, _cur: &State) {
        std::mem::swap(&mut self.acc, &mut self.acc_prev);
        std::mem::swap(&mut self.lam, &mut self.lam_prev);
        self.h_prev = self.h_try;
    }
}

/// Borders the n × n block of the (n + nc) × (n + nc) column-major matrix `a` with −Bᵀ
/// (columns n..) and B (rows n..), and zeroes the corner (B nc × n, column-major).
fn border<T: Field>(a: &mut [T], b: &[f64], n: usize, nc: usize) {
    let big = n + nc;
    for j in 0..n {
        for k in 0..nc {
            let bkj = b[k + nc * j];
            a[j + big * (n + k)] = T::from_f64(-bkj);
            a[(n + k) + big * j] = T::from_f64(bkj);
        }
    }
    for j in n..big {
        for i in n..big {
            a[i + big * j] = T::default();
        }
    }
}

/// ‖X⁻¹‖∞ (largest absolute row sum) of an invertible s × s matrix X, s ≤ 3 (Gauss–Jordan).
fn inverse_row_norm(x: &[[f64; 3]; 3], s: usize) -> f64 {
    let mut a = *x;
    let mut inv = [[0.0; 3]; 3];
    for (i, row) in inv.iter_mut().enumerate().take(s) {
        row[i] = 1.0;
    }
    for k in 0..s {
        let p = (k..s)
            .max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))
            .unwrap_or(k);
        a.swap(k, p);
        inv.swap(k, p);
        let d = a[k][k];
        for j in 0..s {
            a[k][j] /= d;
            inv[k][j] /= d;
        }
        for i in (0..s).filter(|&i| i != k) {
            let f = a[i][k];
            for j in 0..s {
                a[i][j] -= f * a[k][j];
                inv[i][j] -= f * inv[k][j];
            }
        }
    }
    (0..s)
        .map(|i| (0..s).map(|j| inv[i][j].abs()).sum::<f64>())
        .fold(0.0, f64::max)
}
