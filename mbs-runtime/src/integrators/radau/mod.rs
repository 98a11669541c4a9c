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
//! from qdd₀ at the first step. M, C_t, K_t are kept across steps while θ ≤
//! `NewtonOptions::keep_below` (RADAU5's THET: 0.001, or 0.1 where the matrices are
//! differences on 16 coordinates or more) and the factorisations too when moreover h stays
//! (h is kept when the controller proposes a factor in [1, 1.2]); after a rejection they are
//! re-evaluated unless they are already fresh.
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
//! RADAU5's, but for the tolerances: Radau5 transforms them as RADAU5 does, rtol' =
//! 0.1·rtol^((s+1)/(2s)) = 0.1·rtol^(2/3), atol' = rtol'·atol/rtol; Radau3 maps them linearly,
//! rtol' = 0.1·rtol (not below 100ε), atol' likewise, so that its global error follows rtol;
//! at index 3 both hold 3·rtol^((s+1)/s) ("What rtol means", below);
//! h_new = h/q with q = err^(1/(s+1))/fac clamped to [1/8, 5], fac = min(0.9, 0.9(1 + 2k_max)/
//! (k + 2k_max)) for k Newton iterations, and Gustafsson's predictive controller (ACM TOMS 20,
//! 1994) on accepted steps: q ← max(q, (h_acc/h)(err²/err_acc)^(1/(s+1))/0.9), err_acc and
//! h_acc those of the previous accepted step. No growth right after a
//! rejection; a rejected first step is cut by 10. Newton's tolerance κ = max(10ε/rtol',
//! min(`tolerance_factor`, √rtol')), in the same weights. Not in RADAU5: the step Newton
//! last failed to converge at (not counting evaluations that failed) caps the proposals at
//! 0.9 of it, the cap growing by 1.2 per accepted step. Where Newton rather than the error
//! limits the step (a fast rotation moves the stage accelerations further than the
//! extrapolated start values follow: the tumble), RADAU5's rule halves the step and lets the
//! controller grow it straight back, about one Newton rejection per accepted step; with the
//! cap, 1,334 rejections for 2,347 steps instead of 2,065 for 2,279 (rtol 1e-6, 10 s), and
//! 4,958 for 8,007 instead of 7,582 for 7,900 at 1e-10
//! (`tests/scheme_radau.rs::newton_limited_steps_are_remembered`).
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
//! ε/h), and the stage positions by ε max|q| itself, at every h; the weights of position,
//! velocity and λ corrections are floored at these noise levels over κ, so that Newton stops
//! at the noise instead of stalling on it (without the floors of λ and velocities the
//! pendulum's step collapsed at rtol 1e-13; without that of the positions the parallelogram's
//! under Radau5 at rtol 1e-8, 0.12 rad before its change point). Near a change point the
//! noise grows as B's smallest singular value σ falls: times σ₀/σ, and λ's times (σ₀/σ)², from
//! the ratio (σ/σ₀)² of the loops' watch at its last judgement (`Options::singularity_tol`).
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
//! (it is below the constraint tolerance). RADAU5 weighs the errors of index-2 and index-3
//! components (its NIND2, NIND3) by h and h², so that each part is O(h^(s+1)) like the
//! position part: (e_q, h e_v, h² e_λ) against atol + rtol·max(|y₀|, |y₁|) of q, qd and λ.
//! Those ratios are in seconds and seconds squared, and a mechanism in other units, or
//! larger, was judged otherwise (the four-bar by dynamic similarity at rtol 1e-7: Radau5 took
//! 146 steps at × 1, 3,074 at × 10⁶ and 188,704 at × 10⁸, λ holding most of them from × 10³;
//! Radau3 ran out of steps from × 10⁷). Here the same orders of h count what these errors move
//! the positions by in one step: the norm is taken on (e_q, h e_v + h² M_d⁻¹Bᵀe_λ), both
//! against the positions' weights atol + rtol·max(|q₀|, |q₁|) (M_d, the diagonal of M: each
//! coordinate's acceleration from Bᵀe_λ over its own inertia). Radau5 now takes 216–265 steps
//! from × 10⁻⁶ to × 10⁸, Radau3 about 4,000 (`tests/loops.rs`,
//! `the_four_bar_at_every_scale_runs_or_stops_typed`); at × 1 more steps for each rtol (146 →
//! 232 there) and, in the proportionality sweep, from 0.9 fewer digits to 2.0 more at each
//! rtol, still short of rtol (Radau5's local tolerance at index 3 has since been mapped so
//! that its velocities follow rtol: "What rtol means"). The
//! second estimate after a rejection uses f(y₀ + err): velocity row −(τ(q₀ + e_q, v₀ + e_v,
//! qdd₀) − B(q₀ + e_q)ᵀ(λ₀ + e_λ)) in place of 0, constraint row Φ(q₀ + e_q).
//!
//! Orders (Hairer, Lubich & Roche 1989; Jay 1993; Hairer & Wanner §VII.4): for index-3 systems
//! Radau IIA with s stages gives positions of order 2s − 1, velocities of order s, λ of order
//! s − 1 (Radau5: 5, 3, 2; Radau3: 3, 2, 1), as measured on the pendulum with fixed steps
//! (`tests/radau_index3.rs`; Radau3's positions 2.8–2.9 at h = 1/80..1/640). The velocity and λ
//! errors are local (those of the last step) and, since the step control weighs them by the
//! positions they move in a step (h and h²), follow the step size rather than rtol: λ within
//! 1e-6 takes h ≲ 2e-3 with Radau5;
//! with Radau3 (first order in λ, about 0.12h on the pendulum) only near h = 1e-5, where the
//! rounding noise of λ (∝ ε/h²) is already as large (fixed steps of 1/80 000: 8.9e-7; of
//! 1/160 000: 3.6e-5).
//!
//! ## Index 2
//! With `ConstraintMethod::Index2` the scheme solves the stabilized index-2 form of Gear,
//! Gupta & Leimkuhler (1985),
//!
//! ```text
//! q̇ = qd + B₀ᵀμ,   M qdd = h + Bᵀλ,   0 = Φ(q, t),   0 = B qd + Φ_t
//! ```
//!
//! whose exact solution has μ = 0 (Φ = 0 and Φ̇ = 0 give B B₀ᵀμ = 0). The correction is B₀ᵀμ
//! with B₀ = B(q₀) frozen over the step, not M⁻¹Bᵀμ: any P with B Pᵀ invertible keeps μ = 0 and
//! the index 2; Bᵀ needs no solve with M in the stage positions, and frozen it makes the
//! linearisation in μ exact. It is a DAE of index 2 in Hessenberg form with (q, qd)
//! differential and (λ, μ) algebraic, on which Radau IIA converges with order 2s − 1 in q and
//! qd and order s in the stage λ (Hairer, Lubich & Roche 1989; Hairer & Wanner §VII.4); the
//! state's λ, taken from the index-1 equations at (q, qd) (below), has the order of q and qd:
//! Radau3 3, 3, 3, Radau5 5, 5, 5, as measured with fixed steps on the pendulum
//! (`tests/radau_index2.rs`; the stage λ gave 2 and 3). The stage unknowns are (A_i, Λ_i,
//! M_i), with
//!
//! ```text
//! Q_i = q₀ + h c_i qd₀ + h² Σ_j (A²)_ij A_j + h Σ_j a_ij B₀ᵀM_j,   V_i as above,
//! τ(t_i, Q_i, V_i, A_i) − B(Q_i)ᵀΛ_i = 0,   Φ(Q_i, t_i) = 0,   B(Q_i)V_i + Φ_t(Q_i, t_i) = 0.
//! ```
//!
//! Simplified Newton freezes M, C_t, K̃, B as at index 3 and Z = ∂(B qd + Φ_t)/∂q (forward
//! differences at (q₀, qd₀): n more evaluations of B and Φ_t with each new Jacobian); with the
//! eigen-blocks of A the unknowns of block μ are (W_μ, U_μ, Z_μ/(hμ)) and the (n + 2nc)-square
//! system is
//!
//! ```text
//! [ M + hμC_t + h²μ²K̃   −Bᵀ   h²μ²K̃Bᵀ ]   [ −[(T⁻¹ ⊗ I) r]_μ          ]
//! [ B                    0     BBᵀ      ] = [ −[(T⁻¹ ⊗ I) Φ]_μ / (h²μ²) ]
//! [ B + hμZ              0     hμZBᵀ    ]   [ −[(T⁻¹ ⊗ I) Φ̇]_μ / (hμ)   ]
//! ```
//!
//! bounded as h → 0 like the index-3 blocks. Newton's norm adds the position corrections
//! h Σ a_ij B₀ᵀδM_j to the positions' and weights λ by h, as RADAU5 weights index-2 components;
//! it also requires the predicted |Φ_i| and the |Φ̇_i| before the update below
//! `ConstraintOptions::tolerance`, and |Φ̇| of the new state too (4e-11 on the pendulum at rtol
//! 1e-4 otherwise, before Z was in the matrix). These absolute tolerances do not follow rtol:
//! when the corrections have converged and only they are unmet, Newton goes on for up to
//! `max_iterations` more iterations (at index 3 too) instead of rejecting the step. Without
//! that and Z, Radau5 at index 2 was limited by Newton at loose rtol (the four-bar at rtol
//! 1e-4: 352 steps with 222 Newton rejections, 6.4 digits; fastlink 829 steps with 531; now
//! 149 with 5, 3.7 digits, and 273 with 34; `cargo run --release --example work_precision --
//! --model fourbar`). Rounding floors: velocities
//! and λ (times 1/h) not below 4ε max|qd|/κ, measured on the four-bar, where without it the
//! step collapsed at rtol 1e-9 when the rocker's velocity passed through zero.
//!
//! Error estimate: RADAU5's for the index-2 DAE, E = diag(I, M, 0, 0) on (q, v, λ, μ): the
//! real block above solves (e_v, g e_λ, e_μ) from (M r_v − gK̃ r_q, −B r_q/g, 0), e_q = r_q +
//! g(e_v + B₀ᵀe_μ), where r_q has the embedded formula's μ part h Σ (b̂ − b)_j B₀ᵀM_j. q and qd
//! are both differential components, so the norm runs over (e_q, e_v) unscaled; μ (zero on the
//! exact solution) is left out. The error test is `ErrorTest::PositionsVelocities`.
//!
//! λ in the error test. RADAU5 weighs an index-2 component's error by h, so that its order
//! matches the others'; for λ that is h e_λ against atol + rtol|λ|, a ratio in seconds: the
//! same mechanism written in other units, or larger, is judged differently (the four-bar by
//! dynamic similarity, rtol 1e-7: Radau5 took 198 steps at × 1, 383 at × 10³ and 1,506 at
//! × 10⁸, λ holding three quarters of them, and Radau3 fell below h_min from × 10⁷,
//! `tests/loops.rs`, `the_four_bar_at_every_scale_runs_or_stops_typed`). Here e_λ counts by
//! what it does to the motion in one step: the velocities h M_ii⁻¹(Bᵀe_λ)_i, each coordinate
//! by its own inertia (the diagonal of M: cheap, and in the units of qd whatever the units of
//! the model), added to e_v. Radau5 now takes 196–331 steps over that sweep and Radau3 runs at
//! every scale. At × 1 its runs take more steps for each rtol and give more digits
//! (`tests/tolerance_proportionality.rs`, Radau5: 0.3 to 1.9 digits above projection, where
//! from 0.4 below to 1.9 above; fastlink at rtol 1e-6 5.05 digits in 986 steps, where 3.40 in
//! 485, steps from `examples/work_precision.rs`); for the steps they take, about as many
//! digits on fastlink and slider-crank (a), and fewer on the four-bar with Radau5: about 0.8
//! at 400 steps, 2.4 at 1,150, where the h-weighted runs gained 1.6 digits from rtol 1e-9 to
//! 1e-10 (9.61 digits in 1,150 steps; now 8.33 in 1,924). Also measured: the
//! full M⁻¹ in place of its diagonal (within 0.3 digits of it at each rtol), and λ left out of the test
//! (nearly scale-free too, but the four-bar at rtol 1e-10 gave 7.10 digits).
//!
//! The estimate's f(y₀) takes the scheme's own
//! end values (the last stage's A_s and Λ_s); the state an accepted step hands on has qdd and λ
//! from the index-1 equations at its (q, qd) instead (`consistent_end`: one evaluation of M and
//! h and one bordered solve per step). The stage Λ_s is of order s only, and the interpolant
//! between outputs, which uses qdd at both ends, carried its error into the velocities between
//! steps: on Cash's pendulum at rtol 1e-8, 2e-9 between steps against 4e-11 at them (Radau5),
//! now 3e-10. λ so has the order of q and qd, 2s − 1, at fixed steps, and on the pendulum at
//! rtol 1e-8 q, qd and λ are within 4.8e-11, 3.0e-11, 4.3e-11 (Radau3) and 9.6e-11, 4.2e-11,
//! 8.9e-11 (Radau5), where the stage Λ_s was within 1.2e-8 and 1.0e-7.
//!
//! Against projection (the default for Radau, `ConstraintMethod::Auto`): at equal rtol, index 2
//! gives about the same mixed error over (q, qd) with Radau3 (within 0.3 digits on the
//! slider-crank and the four-bar, 0.6 better at rtol 1e-4 on the four-bar) and with Radau5
//! from 0.4 digits short (fastlink at rtol 1e-10) to 1.9 better (the four-bar at rtol 1e-10)
//! in `tests/tolerance_proportionality.rs`, with more steps (pendulum, Radau5, rtol
//! 1e-6: 16 against 13) and more work per step ((n + 2nc)-square blocks, the constraints at
//! every stage, the index-1 qdd and λ of the new state). Not better at equal work (the
//! four-bar at 3.7 digits: 2.0 ms against 1.2 ms with projection at 3.9), it is not the
//! default.
//!
//! ## What rtol means
//! The mixed error over (q, qd) (Test Set for IVP Solvers, floor 0.01, largest over 10 sampled
//! times; `mbs::work_precision::mixed_error`) as log10(error/rtol), atol = rtol/100, on
//! pendulum3 (1 s), the slider-crank (a) (2 s, three crank turns), the four-bar (2 s) and the
//! double pendulum (2 s); printed by `cargo test --release --test radau_index2
//! the_mixed_error_against_rtol -- --nocapture`. With RADAU5's transformation for both s (as
//! before Radau3's mapping, chosen below):
//!
//! ```text
//!                         rtol  1e-4   1e-5   1e-6   1e-7   1e-8   1e-9   1e-10
//! slidercrank radau3 projection 2.41   2.65   2.89   3.13   3.37   3.61   3.86
//! slidercrank radau3 index2     2.10   2.55   2.87   3.18   3.48   3.76   4.03
//! slidercrank radau5 projection 1.91   1.72   1.88   2.03   2.43   2.34   2.48
//! slidercrank radau5 index2    −0.77   0.10   1.13   1.48   1.74   1.98   2.17
//! fourbar     radau3 projection 2.38   2.61   2.83   3.07   3.32   3.56   3.81
//! fourbar     radau5 projection 1.43   1.73   1.78   1.81   1.96   2.17   2.31
//! dpend       radau3            0.71   0.99   1.23   1.47   1.71   1.96   2.21
//! dpend       radau5            0.23   0.28   0.27   0.22   0.25   0.39   0.63
//! ```
//!
//! 2–4 digits short on the loops, the shortfall growing by 0.25 (s = 2) and 0.15–0.2 (s = 3)
//! digits per decade, and digits lost as rtol tightens (four-bar, radau5 at index 2, 1e-5 →
//! 1e-6: −0.54 → 0.94, 0.5 digits lost): the estimate is O(h^(s+1)) and the global error O(h^(2s−1)), so an
//! estimate held at rtol' gives a global error ∝ rtol'^((2s−1)/(s+1)), and RADAU5's rtol' ∝
//! rtol^((s+1)/(2s)) (made for the local error O(h^(2s))) leaves it ∝ rtol^((2s−1)/(2s)). At
//! index 3 the errors do not follow rtol at all (velocities counted by h e_v): on the slider-crank
//! 2.2 → 5.2 (radau3) and 2.3 → 4.3 (radau5). The mapping that makes the global error follow
//! rtol is rtol' = c·rtol^((s+1)/(2s−1)), linear for s = 2 and rtol^0.8 for s = 3. Measured
//! with c = 0.02 (s = 2) and 0.05 (s = 3) in place of the transformation (the same runs):
//!
//! ```text
//!                         rtol  1e-4   1e-5   1e-6   1e-7   1e-8   1e-9   1e-10
//! pendulum3   radau3 projection −2.07  −2.07  −1.65  −2.00  −1.86  −1.90  −0.98
//! pendulum3   radau5 index2    −1.57  −1.35  −1.13  −0.82  −0.54  −0.39  −0.31
//! slidercrank radau3 projection 0.68   0.67   0.66   0.66   0.61   0.61   0.89
//! slidercrank radau3 index2     0.75   0.82   0.86   0.86   0.87   0.88   1.07
//! slidercrank radau5 projection 0.46   0.50   0.47   0.47   0.50   0.44   0.42
//! slidercrank radau5 index2    −0.34  −0.03   0.08   0.33   0.45   0.63   0.35
//! fourbar     radau3 index2     0.84   0.89   0.92   0.90   0.91   0.95   0.96
//! fourbar     radau5 projection 0.51   0.33   0.28   0.27   0.27   0.39   0.28
//! fourbar     radau5 index2    −0.72  −0.25   0.07   0.26   0.40   0.55   0.73
//! dpend       radau3           −0.97  −0.99  −0.99  −0.99  −0.99  −1.00  −0.70
//! dpend       radau5           −0.89  −1.56  −1.55  −1.60  −1.40  −1.21  −1.39
//! ```
//!
//! within 1.1 digits above rtol everywhere and flat in rtol, the loops within a factor 2–10,
//! the short runs (pendulum, double pendulum) 1–2 digits better than asked: the spread between
//! models (three crank turns against a third of a pendulum swing) is that of any per-step error
//! control and no mapping removes it (global error control does: `simulate_global`).
//!
//! **Chosen:** Radau3 takes the mapping with c = 0.1, RADAU5's factor (5× looser than the
//! table above: by its order, about ⅔ of a digit less accurate for 40 % fewer steps). In the
//! tolerance-proportionality sweeps (`tests/tolerance_proportionality.rs`, rtol 1e-4…1e-10 on
//! six loops) its digits now gain 0.89–1.02 per decade with projection, partitioning or at
//! index 2 (0.58–0.76 before), and its mean offset from rtol with projection is −2.2 to +1.3
//! digits (−3.9 to −0.5 before), in the band of DOPRI5, BDF and Radau5; those sweeps are
//! asserted there with theirs. It costs Radau3 the steps its order asks for: dpend to 2 s at
//! rtol 1e-6 takes 2,072 steps where RADAU5's transformation took 649
//! (`tests/scheme_radau.rs::work_counters_snapshot`). Radau5 keeps RADAU5's transformation:
//! its sweeps are already in that band (slope 0.85–0.94 with projection), and the mapping
//! would take about 2× its steps at rtol 1e-6 (its local tolerance 13× tighter, steps ∝
//! rtol'^(−1/4)) for the Radau runs users pick for speed, the gait cycle on muscles among them.
//!
//! **Index 3.** The error test counts the velocities' errors by the positions they move in a
//! step, h e_v, and at index 3 the velocities are of order s and their error is that of the
//! last step: an estimate held at rtol' leaves them ∝ rtol'^(s/(s+1)). Under RADAU5's
//! transformation Radau5's digits rose by about half a digit per decade of rtol and fell
//! 1.6 to 3.2 digits short of rtol on average over the six loops (the four-bar: 2.64 digits at
//! rtol 1e-4, 5.18 at 1e-10). Radau5 at index 3 therefore holds rtol' = 3·rtol^(4/3), the
//! exponent (s+1)/s that makes the velocities follow rtol, not below 10⁵ε (reached from rtol
//! ≈ 4.5e-9); its digits follow rtol from 1e-4 to 1e-8 in the proportionality sweeps, where
//! they are asserted. Also measured: c = 0.3 and 0.1, up to 1.3 and 1.6 digits more than
//! c = 3 (at rtol 1e-4) for 1.7× and 2.2× its steps (the four-bar at rtol 1e-6), and above
//! the other schemes, whose median they lifted; floors of 100ε and 10⁴ε, under which fastlink stopped at h_min from rtol
//! 1e-8, its velocity's error 8.3e-14 against a weight of 4.0e-14 set by rounding (the stage
//! velocities' rounding grows as ε/h); measured again once Newton weighed the stage positions
//! no finer than their rounding, 10⁴ε stopped fastlink at h_min from rtol 1e-9 and cost the
//! four-bar and slider-crank (a) 0.80 and 0.76 digits from 1e-8 to 1e-9. It costs steps: the four-bar to 2 s at rtol 1e-6
//! takes 1,243 steps where the transformation took 314 (projection: 297).
//!
//! Radau3 at index 3 holds 3·rtol^1.5 alike, not below 10⁵ε either (reached from rtol ≈
//! 3.8e-8, so that its run at 1e-8 holds the floor), and its digits follow rtol from 1e-4 to
//! 1e-8, where they are asserted; below, at the floor, they stay at 5.2–7.3. A floor of 10⁴ε
//! (reached from ≈ 8e-9) lost 0.40–0.63 digits from rtol 1e-7 to 1e-8 on the four-bar and
//! slider-crank (a) (5.10 → 4.47, 5.47 → 5.07): its multipliers are of order s − 1 = 1 at
//! index 3, and their rounding grows as ε/h² as the steps shorten. Unmapped (0.1·rtol) its
//! digits fell 1.6–2.6 short on average. Its floor was 2e-9 (reached from rtol ≈ 7.6e-7) while
//! Newton weighed the stage positions finer than their rounding: without it, it failed on
//! fastlink from rtol 1e-7 on. Since, every run reaches its end under Radau5's floor, with
//! 0.87–1.95 digits more at rtol 1e-8 than under 2e-9.
//! Also measured: 0.1·rtol^1.5 and 0.05·rtol^1.25, which stalled at 4.5–7.5 digits from
//! rtol 1e-5, 1e-6 or 1e-7 on and stopped at h_min on fastlink at 1e-6 or 1e-7.
//! A floor holds for every rtol below the one that reaches it, though it is looser than
//! rtol there (before, rtol' fell back to rtol below the floor, so that Radau3 at index 3
//! took rtol' = 1e-10 at rtol 1e-10 and stopped at h_min on fastlink at t = 4.5e-9).
//!
//! ## Files
//! Here the step (`attempt`) and its control; `newton.rs`: the simplified Newton iteration and
//! its eigen-block factorisations; `estimate.rs`: the error estimates; `index3.rs`: what index
//! 3 adds (multipliers, bordered blocks), shared with index 2; `index2.rs`: what index 2 adds
//! (μ, the blocks of the velocity constraints, the index-2 estimate); `tableau.rs`: the
//! coefficients.

mod estimate;
mod index2;
mod index3;
mod newton;
mod tableau;

use super::at::At;
use super::constrained::Mode;
use super::problem::Problem;
use super::step_control::{ErrorNorm, Predictive, Tolerances};
use super::{Attempt, Control, State, Step, Stepper};
use crate::charts::Recentring;
use crate::error::Failure;
use crate::linalg::{C64, Lu};
use crate::stats::ErrorTest;
use tableau::Coefficients;

/// h is kept (and the factorisations with it) when the proposed h_new/h is in [QUOT1, QUOT2]
const QUOT1: f64 = 1.0;
const QUOT2: f64 = 1.2;

const MATRIX_C: &str = "the Radau iteration matrix M + hλC + h²λ²K (complex λ)";
const MATRIX_R: &str = "the Radau iteration matrix M + hγ₀C + h²γ₀²K (real γ₀)";
const MATRIX_C3: &str =
    "the Radau index-3 iteration matrix [M + hλC + h²λ²(K − ∂(Bᵀλ)/∂q), −Bᵀ; B, 0] (complex λ)";
const MATRIX_R3: &str =
    "the Radau index-3 iteration matrix [M + hγ₀C + h²γ₀²(K − ∂(Bᵀλ)/∂q), −Bᵀ; B, 0] (real γ₀)";
const MATRIX_C2: &str = "the Radau index-2 iteration matrix [M + hλC + h²λ²K̃, −Bᵀ, h²λ²K̃Bᵀ; B, 0, BBᵀ; B, 0, 0] (K̃ = K − ∂(Bᵀλ)/∂q, complex λ)";
const MATRIX_R2: &str = "the Radau index-2 iteration matrix [M + hγ₀C + h²γ₀²K̃, −Bᵀ, h²γ₀²K̃Bᵀ; B, 0, BBᵀ; B, 0, 0] (K̃ = K − ∂(Bᵀλ)/∂q, real γ₀)";

/// Radau3's local tolerance per unit of the user's rtol (and atol): rtol' = 0.1·rtol,
/// RADAU5's factor with the exponent of the global error, (s+1)/(2s−1) = 1.
const RADAU3_TOL_FACTOR: f64 = 0.1;

/// Radau's local tolerance per unit of the user's rtol^((s+1)/s) at index 3: rtol' =
/// 3·rtol^(4/3) for Radau5, 3·rtol^1.5 for Radau3, the exponent (s+1)/s of velocities of
/// order s ("What rtol means").
const INDEX3_TOL_FACTOR: f64 = 3.0;

/// The least local tolerance of Radau at index 3, 10⁵ε (Radau5 reaches it from rtol ≈ 4.5e-9,
/// Radau3 from ≈ 3.8e-8): below it the rounding of the stage velocities and multipliers (∝ ε/h
/// and ε/h²) holds the error test, and fastlink's runs under Radau5 stopped at h_min ("What
/// rtol means").
const INDEX3_FLOOR: f64 = 1e5 * f64::EPSILON;

/// The local tolerance rtol' the error test holds for the user's `rtol`, with the floor when
/// it set it (`Stats::tolerance_floor`). Radau5: RADAU5's transformation 0.1·rtol^((s+1)/(2s));
/// Radau3: the global error's mapping c·rtol^((s+1)/(2s−1)), linear for s = 2, not below 100ε,
/// where rounding would hold the error test; at index 3 3·rtol^((s+1)/s), not below 10⁵ε.
/// All but RADAU5's transformation are never looser than rtol,
/// but for their floors: the least rtol' the scheme holds, for every rtol below.
fn local_rtol(rtol: f64, s: usize, index3: bool) -> (f64, Option<f64>) {
    let (mapped, floor) = match (s, index3) {
        (_, true) => (
            INDEX3_TOL_FACTOR * rtol.powf((s + 1) as f64 / s as f64),
            INDEX3_FLOOR,
        ),
        (2, _) => (RADAU3_TOL_FACTOR * rtol, 100.0 * f64::EPSILON),
        // looser than rtol below rtol 1e-3, as in RADAU5
        _ => return (0.1 * rtol.powf((s + 1) as f64 / (2 * s) as f64), None),
    };
    let r = mapped.min(rtol);
    if r < floor {
        (floor, Some(floor))
    } else {
        (r, None)
    }
}

/// The weights of Newton and of the error test, Newton's κ and its iteration limit.
struct Tol {
    weights: Tolerances,
    kappa: f64,
    max_iterations: usize,
    adaptive: bool,
    /// θ below which M, C_t, K_t are kept for the next step (RADAU5's THET,
    /// `NewtonOptions::keep_below`)
    keep_below: f64,
}

impl Tol {
    fn new(ctl: &Control, s: usize, index3: bool, p: &Problem) -> Tol {
        use crate::options::{COSTLY_COORDINATES, COSTLY_KEEP_BELOW, RADAU5_KEEP_BELOW};
        let keep_below = ctl.newton.keep_below.unwrap_or(
            if p.n >= COSTLY_COORDINATES && p.matrices_by_differences() {
                COSTLY_KEEP_BELOW
            } else {
                RADAU5_KEEP_BELOW
            },
        );
        match ctl.adaptive {
            Some(Tolerances { rtol, atol, groups }) => {
                let r = local_rtol(rtol, s, index3).0;
                Tol {
                    weights: Tolerances {
                        rtol: r,
                        atol: r * atol / rtol,
                        groups,
                    },
                    kappa: (10.0 * f64::EPSILON / r).max(ctl.newton.kappa.min(r.sqrt())),
                    max_iterations: ctl.newton.max_iterations,
                    adaptive: true,
                    keep_below,
                }
            }
            None => Tol {
                weights: Tolerances {
                    rtol: ctl.newton.rtol,
                    atol: ctl.newton.atol,
                    groups: 1,
                },
                kappa: ctl.newton.kappa,
                // a failure is final at a fixed step: twice the iterations before giving up
                max_iterations: 2 * ctl.newton.max_iterations,
                adaptive: false,
                keep_below,
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
    /// the last step Newton could not converge at, grown by `NEWTON_RELAX` per accepted step:
    /// the error controller's proposals are held below it (infinite before any failure)
    h_newton: f64,
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
    /// what rounding leaves of the stages' Φ and (index 2) Φ̇, the largest over the stages
    /// (`closure_floor`, `rate_floor`): each closes to the tolerance or to this
    phi_floor: f64,
    psi_floor: f64,
    /// error estimate: the velocity row's bracket, Φ in the constraint row, λ₀ + e_λ
    bv: Vec<f64>,
    phix: Vec<f64>,
    lx: Vec<f64>,
    /// the stabilized index-2 form (enabled in `start`): stage multipliers μ of the velocity
    /// constraints and Newton's corrections of them (stage i at i·nc..), the stage position
    /// corrections B₀ᵀM_i (stage i at i·n..), Φ̇ at the stages and its largest |Φ̇_i|, Φ_t,
    /// K̃Bᵀ and BBᵀ with the frozen matrices, Φ̇ in the error estimate's constraint row
    index2: bool,
    mu: Vec<f64>,
    dmu: Vec<f64>,
    bmu: Vec<f64>,
    psis: Vec<f64>,
    psi_max: f64,
    phit: Vec<f64>,
    /// index 2: the frozen blocks that border the iteration matrix
    i2: index2::Blocks,
    /// index 2: the scheme's own qdd and λ at the end of the last accepted step (its last
    /// stage), which the error estimate's f(y₀) needs; the state holds the index-1 ones
    own_end: Vec<f64>,
    psix: Vec<f64>,
    /// the last error test
    test: ErrorNorm,
    /// the component of Newton's last correction with the largest weighted term (block,
    /// index), set by `correction_norm`
    newton_largest: std::cell::Cell<Option<(usize, usize)>>,
}

impl Radau {
    fn new(n: usize, s: usize) -> Radau {
        let z = || vec![0.0; n];
        let zs = || vec![0.0; s * n];
        Radau {
            test: ErrorNorm::default(),
            newton_largest: std::cell::Cell::new(None),
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
            theta: crate::options::RADAU5_KEEP_BELOW,
            first: true,
            h_newton: f64::INFINITY,
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
            phi_floor: 0.0,
            psi_floor: 0.0,
            bv: Vec::new(),
            phix: Vec::new(),
            lx: Vec::new(),
            index2: false,
            mu: Vec::new(),
            dmu: Vec::new(),
            bmu: Vec::new(),
            psis: Vec::new(),
            psi_max: 0.0,
            phit: Vec::new(),
            i2: index2::Blocks::default(),
            own_end: Vec::new(),
            psix: Vec::new(),
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

    /// Whether the run integrates a closed loop at index 3 (its own tolerance map and floor).
    fn index3(&self) -> bool {
        self.nc > 0 && !self.index2
    }
}

/// The growth of the Newton-limited step per accepted step, and the fraction of it the error
/// controller may propose (see `Radau::h_newton`).
const NEWTON_RELAX: f64 = 1.2;
const NEWTON_MARGIN: f64 = 0.9;

impl Stepper for Radau {
    fn last_test(&self) -> ErrorNorm {
        self.test
    }

    fn newton_largest(&self) -> Option<(usize, usize)> {
        self.newton_largest.get()
    }

    fn tolerance_floor(&self, rtol: f64) -> Option<f64> {
        local_rtol(rtol, self.k.s, self.index3()).1
    }

    fn error_test(&self, _p: &Problem) -> ErrorTest {
        if self.index3() {
            ErrorTest::PositionsScaledVelocities
        } else {
            // the ODE, the index-1 forms, and the stabilized index-2 form, where positions
            // and velocities are both differential components
            ErrorTest::PositionsVelocities
        }
    }

    fn start(&mut self, p: &mut Problem, _s: &State, _ctl: &Control) -> Result<(), Failure> {
        if let Some(c) = p.loops.closed() {
            match c.mode {
                Mode::Index3 => self.enable_constraints(c.nc, c.tol, false),
                Mode::Index2 => self.enable_constraints(c.nc, c.tol, true),
                _ => {}
            }
        }
        self.jac_valid = false;
        self.need_jac = true;
        self.h_prev = 0.0;
        self.first = true;
        self.reject = false;
        self.control.restart();
        self.h_newton = f64::INFINITY;
        self.faccon = 1.0;
        Ok(())
    }

    /// Fresh matrices and no extrapolation of the last step's stages (they are of the old
    /// chart); the step-size controller keeps its history.
    fn rechart(
        &mut self,
        _p: &mut Problem,
        _s: &State,
        _ctl: &Control,
        _moved: &[Recentring],
        _evaluated: bool,
    ) -> Result<(), Failure> {
        self.jac_valid = false;
        self.need_jac = true;
        self.h_prev = 0.0;
        Ok(())
    }

    fn attempt(&mut self, step: Step<'_>) -> Result<Attempt, Failure> {
        let Step(p, cur, h, ctl, next) = step;
        let (s, n) = (self.k.s, self.n);
        let tol = Tol::new(ctl, s, self.index3(), p);
        // Newton's weights, like the error test's, not below the rounding of the values the
        // stages handle: 100ε (or rtol', if tighter) times the largest position
        // |q| + h|qd| + h²|qdd| and the largest velocity |qd| + h|qdd|. Without it a start at
        // rest under a tiny atol weighted its velocities by atol alone: under atol = 1e-30 the
        // rounding of the stage velocities (1e-29) failed Newton down to h_min at t = 0.
        let largest = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let (qmax, vmax, amax) = (largest(&cur.q), largest(&cur.qd), largest(&cur.qdd));
        let f = Tolerances::transformed_floor(tol.weights.rtol);
        let (floor_q, floor_v) = (f * (qmax + h * (vmax + h * amax)), f * (vmax + h * amax));
        for r in 0..n {
            self.scq[r] = (tol.weights.atol + tol.weights.rtol * cur.q[r].abs()).max(floor_q);
            self.scv[r] = (tol.weights.atol + tol.weights.rtol * cur.qd[r].abs()).max(floor_v);
        }
        // (BM⁻¹Bᵀ)⁻¹ B below, taken as σ from M and B at the last Jacobian
        let sigma = || super::constrained::multiplier_scale(largest(&self.m), &self.bm);
        // Rounding floors of Newton's weights where it iterates on the loops (index 3 and 2;
        // Newton stops when its predicted error is below κ times the weights, so a weight
        // below a value's rounding over κ asks for digits no iteration gives). The stage
        // positions solve Φ = 0, so rounding errors ε·max|q| in the stage values of Φ move
        // them by as much at every h (the stages' sums alone leave h²‖A²δ‖): without this
        // floor Newton saw no contraction in that noise at small steps, each failure halving
        // h (the parallelogram under Radau5 at index 3 at rtol 1e-8, κ = 3.4e-5, went down
        // to h_min 0.12 rad before its change point, where the loop's watch now stops it).
        // Near a change point B's smallest singular value σ falls, and the positions,
        // velocities and multipliers that solve Φ and Φ̇ take their rounding errors times
        // σ₀/σ (λ times (σ₀/σ)²), the watch's ratio (σ/σ₀)² (Radau3 at index 2, same run:
        // Newton at h_min 0.035 rad before it, now its error test 0.010 rad before it)
        let q_scale = qmax.max(1.0);
        let amplified = p
            .loops
            .closed()
            .map_or(1.0, |c| 1.0 / c.fallen.clamp(1e-12, 1.0).sqrt());
        let noise_q = if self.nc > 0 {
            amplified * f64::EPSILON * q_scale / tol.kappa
        } else {
            0.0
        };
        if self.index2 {
            // λ, an index-2 component, weighted by h in Newton as RADAU5 weights them (the
            // error test counts it by the velocities it moves, module notes); neither λ nor
            // the velocities below their rounding noise (Newton stops when its predicted
            // error is below κ times the weights): rounding
            // errors in the stage values of Φ̇ move the stage velocities by a few ε max|qd|
            // (4 ε max|qd| here: measured about 3 on the four-bar, where the floor matters
            // when the rocker's velocity passes through zero with rtol' near 1e-11) and the
            // stage λ by that over h (times (BM⁻¹Bᵀ)⁻¹, taken as 1)
            let noise = amplified * 4.0 * f64::EPSILON * vmax.max(1.0) / tol.kappa;
            let sigma = sigma();
            for r in 0..n {
                self.scq[r] += noise_q;
                self.scv[r] += noise;
            }
            for r in 0..self.nc {
                self.scl[r] = (tol.weights.atol
                    + tol.weights.rtol * cur.lambda[r].abs()
                    + noise * sigma * amplified)
                    / h;
            }
        } else if self.nc > 0 {
            // λ and the velocities to the Newton tolerance, but not below their rounding
            // noise (Newton stops when its predicted error is below κ times the weights):
            // rounding errors ε·max|q| in the stage values of Φ move the stage λ by up to
            // ‖A⁻²‖∞ ε max|q|/h² (times (BM⁻¹Bᵀ)⁻¹, taken as 1) and, through
            // δA = M⁻¹Bᵀ δΛ, the stage velocities by up to ‖A⁻¹‖∞ ε max|q|/h
            let noise = noise_q / h;
            let sigma = sigma();
            for r in 0..n {
                self.scq[r] += noise_q;
                self.scv[r] += noise * self.ainv;
            }
            for r in 0..self.nc {
                self.scl[r] = tol.weights.atol
                    + tol.weights.rtol * cur.lambda[r].abs()
                    + noise * self.a2inv * sigma * amplified / h;
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
                    At::new(cur.t, &cur.q, &cur.qd),
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
                    if f.cause.is_none() {
                        self.h_newton = self.h_newton.min(h);
                    }
                    // the step shrank for Newton's sake, not its error's: the predictive
                    // correction would read that shrinking as the error's trend and shrink
                    // the step after the next acceptance by up to 5 more (the fast
                    // mechanism at index 3, rtol 1e-9: from h_min to below it, which stopped
                    // the run blaming an error test whose error was 6e-4 of its tolerance)
                    self.control.restart();
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
        let keep_matrices = ctl.newton.reuse && self.theta <= tol.keep_below;
        if !tol.adaptive {
            self.consistent_end(p, cur.t + h, next)?;
            self.first = false;
            self.jac_fresh = false;
            self.need_jac = !keep_matrices;
            return Ok(Attempt::Accepted { h_next: h });
        }
        let err = if self.index2 {
            self.estimate2(p, cur, next, h, &tol)
        } else if nc > 0 {
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
            // below the step Newton last failed at, which relaxes as steps succeed
            self.h_newton = (self.h_newton * NEWTON_RELAX).max(h);
            h_new = h_new.min(NEWTON_MARGIN * self.h_newton).max(h.min(h_new));
            self.reject = false;
            self.first = false;
            if keep_matrices && (QUOT1..=QUOT2).contains(&(h_new / h)) {
                h_new = h;
            }
            self.consistent_end(p, cur.t + h, next)?;
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

    fn accepted(&mut self, _p: &mut Problem, _prev: &State, _cur: &State) {
        std::mem::swap(&mut self.acc, &mut self.acc_prev);
        std::mem::swap(&mut self.lam, &mut self.lam_prev);
        self.h_prev = self.h_try;
        if self.index2 {
            // the accepted step's last stage: the scheme's own end values
            let (s, n, nc) = (self.k.s, self.n, self.nc);
            self.own_end[..n].copy_from_slice(&self.acc_prev[(s - 1) * n..]);
            self.own_end[n..].copy_from_slice(&self.lam_prev[(s - 1) * nc..]);
        }
    }
}
