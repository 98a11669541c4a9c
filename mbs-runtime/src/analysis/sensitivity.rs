//! Parameter sensitivities of statics: how an equilibrium moves with the parameters the model
//! marks `sensitive` (`param k = 1e4 sensitive;`), from the generated ∂τ/∂p.
//!
//! At an equilibrium τ(q, 0, 0, p) = 0 (τ = M qdd − h, so −h at rest); differentiating along
//! the equilibria, K dq/dp + ∂τ/∂p = 0 with K = ∂τ/∂q the stiffness, hence
//! dq/dp = −K⁻¹ ∂τ/∂p over the free coordinates (locked ones stay where they are). One
//! factorisation of K and one evaluation of ∂τ/∂p give every column, exact when K is (a model
//! with `option tangents;`), else to the accuracy of K's central differences.
//!
//! On a closed loop the equilibrium is τ = Bᵀλ with Φ(q, p) = 0, and along the equilibria
//!
//! ```text
//! (K − K_λ) dq/dp − Bᵀ dλ/dp = −∂τ/∂p + ∂(Bᵀλ)/∂p,    B dq/dp = −∂Φ/∂p
//! ```
//!
//! (K_λ = ∂(Bᵀλ)/∂q; rows and columns of the free coordinates), which gives dλ/dp as well.

use super::statics::{Equilibrium, StaticsOptions, stiffness};
use super::{AnalysisError, check, check_named, constraint_label};
use crate::error::Failure;
use crate::linalg::Lu;
use crate::model::Model;

/// The error refusing `model` for `reason`.
fn refusal<M: Model>(model: &M, reason: &'static str) -> AnalysisError {
    Failure::InvalidOption {
        name: "model",
        value: model.info().name.to_string(),
        reason,
    }
    .into()
}

/// dq/dp at an equilibrium: one column per sensitive parameter.
#[derive(Clone, Debug, serde::Serialize)]
pub struct StaticSensitivity {
    /// the sensitive parameters, the columns
    pub params: Vec<&'static str>,
    /// coordinate names, the rows
    pub dofs: Vec<String>,
    /// ∂q_eq/∂p, NQ × NS column-major (0 on locked coordinates)
    pub dq_dp: Vec<f64>,
    /// ∂λ_eq/∂p of the constraints' multipliers, NC × NS column-major (empty without
    /// constraints)
    pub dlambda_dp: Vec<f64>,
}

impl StaticSensitivity {
    /// ∂q_i/∂p for coordinate `i` and the parameter named `param`.
    pub fn get(&self, i: usize, param: &str) -> Option<f64> {
        let j = self.params.iter().position(|p| *p == param)?;
        self.dq_dp.get(i + self.dofs.len() * j).copied()
    }
}

/// How the equilibrium `eq` (found with `options`, whose time, inputs, locked coordinates
/// and stiffness setting it reuses) moves with each sensitive parameter of `model`; on closed
/// loops, along the constraint manifold, with the multipliers' sensitivities.
pub fn static_sensitivity<M: Model + Clone>(
    model: &M,
    eq: &Equilibrium,
    options: &StaticsOptions,
) -> Result<StaticSensitivity, AnalysisError> {
    let n = M::NQ;
    let ns = M::SENSITIVE.len();
    let refuse = |reason| refusal(model, reason);
    if ns == 0 {
        return Err(refuse(
            "it has no sensitive parameters: mark them, `param k = 1e4 sensitive;`",
        ));
    }
    if eq.q.len() != n
        || eq.lambda.len() != M::NC
        || eq.charts.len() != model.info().rotation_joints.len()
    {
        return Err(refuse(
            "the equilibrium is not one of this model (its coordinates, multipliers or charts have other sizes): find it with static_equilibrium on this model",
        ));
    }
    let u = super::statics::checked_inputs::<M>(options)?;
    // q is read in the equilibrium's charts
    let mut m = model.clone();
    for (j, r) in eq.charts.iter().enumerate() {
        m.set_chart(j, *r);
    }
    let zero = vec![0.0; n];
    let mut dtau = vec![0.0; n * ns];
    m.parameter_tangents(options.t, &eq.q, &zero, &zero, &u, &mut dtau)
        .map_err(|e| refuse(crate::integrators::model_error_reason(&e)))?;
    check(&m, "∂τ/∂p", &dtau)?;
    let mut k = vec![0.0; n * n];
    stiffness(&m, options.t, &eq.q, &u, options.stiffness, &mut k)?;
    let free: Vec<usize> = (0..n).filter(|i| !options.locked.contains(i)).collect();
    let (nf, nc) = (free.len(), M::NC);
    // closed loops: B, K − K_λ and the right-hand side's ∂(Bᵀλ)/∂p − ∂τ/∂p, −∂Φ/∂p
    let mut b = vec![0.0; nc * n];
    let mut ct = crate::model::ConstraintTangents::new::<M>();
    if nc > 0 {
        m.constraint_jacobian(options.t, &eq.q, &mut b);
        let mut k_lambda = vec![0.0; n * n];
        m.constraint_tangent(options.t, &eq.q, &eq.lambda, &mut k_lambda);
        m.constraint_parameter_tangents(options.t, &eq.q, &zero, &zero, &eq.lambda, &mut ct)
            .map_err(|e| refuse(crate::integrators::model_error_reason(&e)))?;
        check_named("∂Φ/∂p", &ct.dphi_dp, |i| {
            constraint_label(m.info(), nc, i)
        })?;
        check(&m, "∂(Bᵀλ)/∂p", &ct.dforce_dp)?;
        for (x, g) in k.iter_mut().zip(&k_lambda) {
            *x -= g;
        }
        for (x, g) in dtau.iter_mut().zip(&ct.dforce_dp) {
            *x -= g;
        }
    }
    let na = nf + nc;
    let mut lu = Lu::<f64>::new(na);
    // the constraints' rows and columns scaled by s to the stiffness' size (their unknowns
    // dλ/s): a stiff loop's B K⁻¹ Bᵀ leaves pivots the factorisation takes for singular
    // otherwise (a four-bar held by a 2e14 N·m/rad spring was refused as neutral)
    let k_size = (free.iter())
        .flat_map(|&j| free.iter().map(move |&i| i + n * j))
        .fold(0.0f64, |m, ij| m.max(k[ij].abs()));
    let b_size = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let s = super::constraint_scale(k_size, b_size);
    {
        let a = lu.matrix_mut();
        a.fill(0.0);
        for (c, &j) in free.iter().enumerate() {
            for (r, &i) in free.iter().enumerate() {
                a[r + na * c] = k[i + n * j];
            }
            for i in 0..nc {
                a[(nf + i) + na * c] = s * b[i + nc * j];
                a[c + na * (nf + i)] = -s * b[i + nc * j];
            }
        }
    }
    lu.factor().map_err(|_| {
        refuse(if nc == 0 {
            "its stiffness is singular at the equilibrium over the free coordinates (a neutral direction): lock the coordinates without stiffness"
        } else {
            "its stiffness on the constraint manifold is singular at the equilibrium over the free coordinates (a neutral direction, or constraints that lock coordinates already locked): lock the coordinates without stiffness"
        })
    })?;
    let mut dq_dp = vec![0.0; n * ns];
    let mut dlambda_dp = vec![0.0; nc * ns];
    let mut x = vec![0.0; na];
    for p in 0..ns {
        for (r, &i) in free.iter().enumerate() {
            x[r] = -dtau[i + n * p];
        }
        for i in 0..nc {
            x[nf + i] = -s * ct.dphi_dp[i + nc * p];
        }
        lu.solve(&mut x);
        for v in &mut x[nf..] {
            *v *= s;
        }
        for (r, &i) in free.iter().enumerate() {
            dq_dp[i + n * p] = x[r];
        }
        dlambda_dp[nc * p..nc * (p + 1)].copy_from_slice(&x[nf..]);
    }
    check(&m, "∂q/∂p", &dq_dp)?;
    check_named("∂λ/∂p", &dlambda_dp, |i| {
        constraint_label(m.info(), nc, i)
    })?;
    let info = m.info();
    Ok(StaticSensitivity {
        params: M::SENSITIVE.to_vec(),
        dofs: (0..n).map(|i| info.dof_label(i).to_string()).collect(),
        dq_dp,
        dlambda_dp,
    })
}

/// How the poles of the motion about an equilibrium move with each sensitive parameter.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PoleSensitivity {
    /// the sensitive parameters
    pub params: Vec<&'static str>,
    /// the modes at the equilibrium, as [`modes`](super::modes) gives them (one per conjugate
    /// pair or real pole, by frequency)
    pub modes: super::Modes,
    /// dλ/dp of each mode's pole (Im λ ≥ 0), `(re, im)`, mode-major: entry `i * NS + j` is
    /// mode i and parameter j; NaN for the modes of `repeated`
    pub dpole_dp: Vec<(f64, f64)>,
    /// the modes whose pole is repeated (another mode's within 1e-8 of its magnitude; a
    /// symmetric machine's twin legs) or defective: a repeated pole splits as the parameters
    /// move, and has no derivative of its own ([`PoleSensitivity::dpole`] gives none)
    pub repeated: Vec<usize>,
    /// each mode's distance to the nearest other pole (another mode's, either of its pair,
    /// or its own conjugate), relative to the larger of their magnitudes (infinite for a
    /// system of one real pole): how far its derivative reaches. Two simple poles s apart
    /// (relative) veer or cross as a parameter moves them by about that much, so dλ/dp
    /// predicts a pole's motion only over changes of p that move it by much less than s·|λ|.
    /// A pole within 1e-8 of another mode's counts as repeated; one within 1e-8 of its own
    /// conjugate only (a nearly critically damped pair) keeps its derivative, which its
    /// separation then says reaches little
    pub separation: Vec<f64>,
}

impl PoleSensitivity {
    /// dλ/dp of mode `i` and the parameter named `param`, `(re, im)` (1/s per unit of p).
    pub fn dpole(&self, i: usize, param: &str) -> Option<(f64, f64)> {
        let j = self.params.iter().position(|p| *p == param)?;
        (i < self.modes.modes.len() && !self.repeated.contains(&i))
            .then(|| self.dpole_dp[i * self.params.len() + j])
    }

    /// d f/dp of mode `i`'s natural frequency f = |λ|/2π (Hz per unit of p).
    pub fn dfrequency(&self, i: usize, param: &str) -> Option<f64> {
        let (dre, dim) = self.dpole(i, param)?;
        let mode = &self.modes.modes[i];
        let mag = mode.re.hypot(mode.im);
        (mag > 0.0).then(|| (mode.re * dre + mode.im * dim) / mag / (2.0 * std::f64::consts::PI))
    }

    /// d ζ/dp of mode `i`'s damping ratio ζ = −Re λ/|λ|.
    pub fn ddamping(&self, i: usize, param: &str) -> Option<f64> {
        let (dre, dim) = self.dpole(i, param)?;
        let mode = &self.modes.modes[i];
        let mag = mode.re.hypot(mode.im);
        let dmag = (mode.re * dre + mode.im * dim) / mag;
        (mag > 0.0).then(|| -(dre * mag - mode.re * dmag) / (mag * mag))
    }
}

/// The poles of `model`'s motion about the equilibrium `eq` (found with `options`) and their
/// derivatives by each sensitive parameter, along the equilibria: the equilibrium moves
/// (dq/dp from [`static_sensitivity`]) and M, C, K with it and with p.
///
/// With Q(λ) = λ²M + λC + K (C = ∂τ/∂qd, K = ∂τ/∂q at rest), a simple pole λ with right
/// and left eigenvectors Q(λ)x = 0, yᴴQ(λ) = 0 moves by
/// dλ/dp = −yᴴ(λ²M' + λC' + K')x / yᴴ(2λM + C)x, where X' = dX/dp along the equilibria comes
/// from the generated second derivatives ([`Model::rest_tangent_derivatives`]).
///
/// On a closed loop the motion about the equilibrium is M δq̈ + C δq̇ + (K − K_λ) δq = Bᵀ δλ,
/// B δq = 0 (K_λ = ∂(Bᵀλ)/∂q), whose poles are the finite eigenvalues of
/// A(λ) = [Q(λ) − K_λ, −Bᵀ; B, 0]: with right and left eigenvectors (x, ℓ) and (y, m),
/// dλ/dp = −(yᴴ(λ²M' + λC' + K' − K_λ')x − yᴴB'ᵀℓ + mᴴB'x) / yᴴ(2λM + C)x, B' and K_λ' along
/// the equilibria from [`Model::constraint_rest_derivatives`] and dλ_eq/dp.
///
/// Exact to rounding for simple poles; a repeated pole (or a defective one) has no
/// derivative: its modes are listed in [`PoleSensitivity::repeated`], the others' derivatives
/// given as for simple poles (a symmetric machine's twin modes no longer stop the rest; before,
/// a repeated pole that was not defective passed the test on yᴴ(2λM + C)x and got a
/// derivative that depended on the eigenvectors inverse iteration happened to find). Needs
/// `option tangents;`; equilibria with locked coordinates (not at rest on
/// them) are refused.
pub fn pole_sensitivity<M: Model + Clone>(
    model: &M,
    eq: &Equilibrium,
    options: &StaticsOptions,
) -> Result<PoleSensitivity, AnalysisError> {
    use crate::linalg::{C64, Field};
    let n = M::NQ;
    let ns = M::SENSITIVE.len();
    let refuse = |reason| refusal(model, reason);
    if !options.locked.is_empty() {
        return Err(Failure::InvalidOption {
            name: "locked",
            value: format!("{:?}", options.locked),
            reason: "poles are those of a free equilibrium: a locked coordinate is not at rest",
        }
        .into());
    }
    let dq = static_sensitivity(model, eq, options)?;
    let mut m = model.clone();
    for (j, r) in eq.charts.iter().enumerate() {
        m.set_chart(j, *r);
    }
    let u = options.u.clone().unwrap_or_else(|| vec![0.0; M::NU]);
    let zero = vec![0.0; n];
    // M, C, K at rest
    let (mut mass, mut h) = (vec![0.0; n * n], vec![0.0; n]);
    m.dynamics(options.t, &eq.q, &zero, &u, &mut mass, &mut h);
    let (mut k, mut c) = (vec![0.0; n * n], vec![0.0; n * n]);
    m.tangents(options.t, &eq.q, &zero, &zero, &u, &mut k, &mut c)
        .map_err(|e| refuse(crate::integrators::model_error_reason(&e)))?;
    check(&m, "M", &mass)?;
    check(&m, "K", &k)?;
    check(&m, "C", &c)?;
    // closed loops: B, and K − K_λ in place of K
    let nc = M::NC;
    let mut b = vec![0.0; nc * n];
    let mut k_lambda = vec![0.0; n * n];
    if nc > 0 {
        m.constraint_jacobian(options.t, &eq.q, &mut b);
        m.constraint_tangent(options.t, &eq.q, &eq.lambda, &mut k_lambda);
        check(&m, "B", &b)?;
        check(&m, "∂(Bᵀλ)/∂q", &k_lambda)?;
        for (x, g) in k.iter_mut().zip(&k_lambda) {
            *x -= g;
        }
    }
    // M', C', K' (less K_λ') and B' along the equilibria, one block per parameter
    let nb = n * n;
    let (mut dm, mut dc, mut dk) = (
        vec![0.0; nb * (1 + ns)],
        vec![0.0; nb * (1 + ns)],
        vec![0.0; nb * (1 + ns)],
    );
    let (mut db, mut dkl) = (vec![0.0; nc * n * (1 + ns)], vec![0.0; nb * (1 + ns)]);
    let mut kl_of_dlambda = vec![0.0; nb];
    let mut along: Vec<Vec<f64>> = Vec::with_capacity(4 * ns);
    for p in 0..ns {
        let dir = &dq.dq_dp[n * p..n * (p + 1)];
        m.rest_tangent_derivatives(options.t, &eq.q, dir, &u, &mut dm, &mut dc, &mut dk)
            .map_err(|e| refuse(crate::integrators::model_error_reason(&e)))?;
        for x in [&dm, &dc, &dk] {
            check(&m, "∂(M, C, K)/∂p", x)?;
        }
        let total = |x: &[f64], size: usize| -> Vec<f64> {
            (0..size).map(|i| x[i] + x[size * (1 + p) + i]).collect()
        };
        let (mp, cp, mut kp) = (total(&dm, nb), total(&dc, nb), total(&dk, nb));
        let mut bp = Vec::new();
        if nc > 0 {
            m.constraint_rest_derivatives(options.t, &eq.q, dir, &eq.lambda, &mut db, &mut dkl)
                .map_err(|e| refuse(crate::integrators::model_error_reason(&e)))?;
            check(&m, "∂(B, K_λ)/∂p", &db)?;
            check(&m, "∂(B, K_λ)/∂p", &dkl)?;
            // K_λ is linear in λ, which moves by dλ_eq/dp
            let dlambda = &dq.dlambda_dp[nc * p..nc * (p + 1)];
            m.constraint_tangent(options.t, &eq.q, dlambda, &mut kl_of_dlambda);
            let klp = total(&dkl, nb);
            for i in 0..nb {
                kp[i] -= klp[i] + kl_of_dlambda[i];
            }
            bp = total(&db, nc * n);
        }
        along.extend([mp, cp, kp, bp]);
    }
    let lin = super::linearize(
        &m,
        options.t,
        &eq.q,
        &zero,
        &u,
        crate::options::IterationMatrix::Auto,
    )?;
    let modes = super::modes(&lin, None)?;
    let real = |x: f64| C64::new(x, 0.0);
    let conj = |z: C64| C64::new(z.re, -z.im);
    let scale = [&mass, &c, &k]
        .iter()
        .flat_map(|x| x.iter())
        .fold(1.0f64, |s, x| s.max(x.abs()));
    let na = n + nc;
    let mut dpole_dp = Vec::with_capacity(modes.modes.len() * ns);
    let mut repeated = Vec::new();
    let magnitude = |m: &super::Mode| m.re.hypot(m.im);
    let twin = |i: usize, m: &super::Mode| {
        modes.modes.iter().enumerate().any(|(j, o)| {
            j != i && (m.re - o.re).hypot(m.im - o.im) <= 1e-8 * magnitude(m).max(magnitude(o))
        })
    };
    let mut a_right = Lu::<C64>::new(na);
    let mut a_left = Lu::<C64>::new(na);
    for (index, mode) in modes.modes.iter().enumerate() {
        if twin(index, mode) {
            repeated.push(index);
            dpole_dp.extend(std::iter::repeat_n((f64::NAN, f64::NAN), ns));
            continue;
        }
        let lambda = C64::new(mode.re, mode.im);
        // A(μ) and A(μ)ᴴ with μ a hair off λ, for inverse iteration
        let mag = mode.re.hypot(mode.im);
        // by a part in 10⁹ of the pole (of 1/s at the origin), well inside the separation of
        // 1e-8 from which a pole counts as simple, so that λ stays the nearest pole to μ
        let off = if mag > 0.0 { 1e-9 * mag } else { 1e-9 };
        let mu = lambda + C64::new(off, off);
        // the constraints' rows and columns scaled by s to the size of Q(μ)'s entries, so
        // that the factorisation does not take the small pivots a stiff loop's Schur
        // complement B Q⁻¹ Bᵀ leaves for singular (a four-bar with a 2e6 N·m/rad spring, its
        // pole at 30,553 rad/s: Q ~ 1e9, B ~ 1); the multipliers' parts are then ℓ/s and m/s
        let qb = |i: usize, j: usize| {
            mu * mu * real(mass[i + n * j]) + mu * real(c[i + n * j]) + real(k[i + n * j])
        };
        let q_size = (0..n * n).fold(0.0f64, |m, ij| m.max(qb(ij % n, ij / n).abs()));
        let b_size = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let s = super::constraint_scale(q_size, b_size);
        {
            let (ar, al) = (a_right.matrix_mut(), a_left.matrix_mut());
            ar.fill(C64::default());
            for j in 0..n {
                for i in 0..n {
                    ar[i + na * j] = qb(i, j);
                }
                for i in 0..nc {
                    let bij = s * b[i + nc * j];
                    ar[(n + i) + na * j] = real(bij);
                    ar[j + na * (n + i)] = real(-bij);
                }
            }
            for j in 0..na {
                for i in 0..na {
                    al[j + na * i] = conj(ar[i + na * j]);
                }
            }
        }
        // nearly singular is what inverse iteration wants: small pivots raised to ε‖A‖
        // rather than refused (a slow pole beside a stiff spring's, the sprung arm with a
        // 4e9 N/m spring, was refused)
        let overflow = || -> AnalysisError {
            Failure::NonFinite {
                quantity: "λ²M + λC + K at the pole (the pole's eigenvectors; its entries overflow)",
                coordinate: String::new(),
                cause: String::new(),
            }
            .into()
        };
        a_right
            .factor_for_inverse_iteration()
            .map_err(|_| overflow())?;
        a_left
            .factor_for_inverse_iteration()
            .map_err(|_| overflow())?;
        let start = |i: usize| C64::new(1.0 + 0.1 * i as f64, 0.05 * i as f64);
        let (mut x, mut y): (Vec<C64>, Vec<C64>) =
            ((0..na).map(start).collect(), (0..na).map(start).collect());
        // each iteration leaves r = |λ − μ| / |λ' − μ| of the nearest other pole λ' in the
        // vectors: iterated until r^k is below rounding (at least three, enough beyond 2.3e-4
        // of the pole's size; a pole 5e-8 of its size away, r ≈ 0.03, needs eleven, and
        // three left 5e-5 of its derivative wrong)
        let nearest = (modes.modes.iter())
            .flat_map(|o| [C64::new(o.re, o.im), C64::new(o.re, -o.im)])
            .filter(|p| (p.re, p.im) != (mode.re, mode.im))
            .map(|p| (p - mu).abs())
            .fold(f64::INFINITY, f64::min);
        let r = (lambda - mu).abs() / nearest;
        let iterations = super::inverse_iterations(r, 3);
        for _ in 0..iterations {
            a_right.solve(&mut x);
            a_left.solve(&mut y);
            for v in [&mut x, &mut y] {
                let nv = v.iter().map(|z| z.abs()).fold(0.0, f64::max);
                for z in v.iter_mut() {
                    *z = *z / real(nv);
                }
            }
        }
        // yᴴ A x for a real n × n matrix A, over the coordinates' parts
        let form = |a: &dyn Fn(usize) -> C64| -> C64 {
            let mut s = C64::default();
            for j in 0..n {
                for i in 0..n {
                    s = s + conj(y[i]) * a(i + n * j) * x[j];
                }
            }
            s
        };
        let denom = form(&|ij| real(2.0) * lambda * real(mass[ij]) + real(c[ij]));
        // against the sizes of the vectors' coordinate parts: on a closed loop they are
        // scaled with their multipliers' parts, forces that may be far larger
        let size = |v: &[C64]| v[..n].iter().map(|z| z.abs()).fold(0.0, f64::max);
        if denom.abs() <= 1e-10 * scale * size(&x) * size(&y) {
            // defective: no derivative either
            repeated.push(index);
            dpole_dp.extend(std::iter::repeat_n((f64::NAN, f64::NAN), ns));
            continue;
        }
        for p in 0..ns {
            let [dmp, dcp, dkp, dbp] = [0, 1, 2, 3].map(|i| &along[4 * p + i]);
            let mut num = form(&|ij| {
                lambda * lambda * real(dmp[ij]) + lambda * real(dcp[ij]) + real(dkp[ij])
            });
            // − yᴴB'ᵀℓ + mᴴB'x, ℓ and m s times the vectors' parts
            for i in 0..nc {
                for j in 0..n {
                    let bij = real(s * dbp[i + nc * j]);
                    num = num - conj(y[j]) * bij * x[n + i] + conj(y[n + i]) * bij * x[j];
                }
            }
            let d = C64::default() - num / denom;
            // a real pole moves along the real axis
            let im = if mode.im == 0.0 { 0.0 } else { d.im };
            dpole_dp.push((d.re, im));
        }
    }
    // the simple poles' derivatives checked (the repeated ones are NaN by design)
    let per_mode = 2 * M::SENSITIVE.len();
    let values: Vec<f64> = (dpole_dp.iter().enumerate())
        .flat_map(|(k, &(a, b))| {
            let own = !repeated.contains(&(k / ns.max(1)));
            [a, b].map(|x| if own { x } else { 0.0 })
        })
        .collect();
    check_named("dλ/dp", &values, |i| {
        format!("mode {}", i / per_mode.max(1))
    })?;
    let separation = separations(&modes.modes);
    Ok(PoleSensitivity {
        params: M::SENSITIVE.to_vec(),
        modes,
        dpole_dp,
        repeated,
        separation,
    })
}

/// Each mode's distance to the nearest other pole (the other modes' poles and their
/// conjugates, and its own conjugate when it is complex), relative to the larger magnitude of
/// the two; 0 between two poles at the origin.
fn separations(modes: &[super::Mode]) -> Vec<f64> {
    let poles: Vec<(usize, f64, f64)> = (modes.iter().enumerate())
        .flat_map(|(j, m)| {
            let pair = (m.im != 0.0).then_some((j, m.re, -m.im));
            std::iter::once((j, m.re, m.im)).chain(pair)
        })
        .collect();
    (modes.iter().enumerate())
        .map(|(i, m)| {
            let size = m.re.hypot(m.im);
            (poles.iter())
                // the mode's own pole (Im ≥ 0) is not its neighbour; its conjugate is
                .filter(|&&(j, re, im)| !(j == i && re == m.re && im == m.im))
                .map(|&(_, re, im)| {
                    let scale = size.max(re.hypot(im));
                    let d = (re - m.re).hypot(im - m.im);
                    if scale > 0.0 { d / scale } else { 0.0 }
                })
                .fold(f64::INFINITY, f64::min)
        })
        .collect()
}
