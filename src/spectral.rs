//! Spectral analysis of the integration schemes on the undamped oscillator q̈ + ω²q = 0,
//! measured on the implemented schemes themselves: no formula of any scheme is typed in here.
//!
//! A linear scheme applied to a linear system is a linear map of its state from step to step,
//! s_{n+1} = A s_n. Its eigenvalues give the **spectral radius** ρ (how much a free
//! oscillation keeps of its amplitude per step: 1 keeps it, < 1 damps it, > 1 is unstable)
//! and, from the argument φ of the principal (physical) root, the numerical period
//! T_num = 2π h / φ, reported as the **relative period error** (T_num − T)/T = ωh/φ − 1.
//! Everything is a function of ωh alone.
//!
//! How A is obtained ([`Method`]):
//!
//! - **one step** ([`Method::OneStep`]) for the schemes whose state is (q, q̇): explicit
//!   Euler, RK4, DOPRI5, Radau IIA 3 and 5, the implicit midpoint rule and Newmark. One fixed
//!   step of the integrator from the unit states (q, q̇) = (1, 0) and (0, 1) gives the two
//!   columns of the 2×2 matrix A. Newmark carries q̈ too, but it solves the equilibrium
//!   M q̈ = h at every step (and the run starts from it), so q̈ₙ = −ω²qₙ is no state of its own;
//!   a second step checks that A predicts it (`residual`).
//! - **fitted recurrence** ([`Method::Recurrence`]) for the schemes with more state:
//!   generalized-α and HHT carry the acceleration-like variable a (3×3 on (q, q̇, a)), and
//!   BDF of order k its k − 1 previous points (2k×2k). [`Options`] has no initial a (a₀ = q̈₀
//!   from M q̈ = h, as Arnold & Brüls recommend) nor a BDF history, so A cannot be built
//!   column by column. Instead, by Cayley–Hamilton every component of the state (q and q̇
//!   here) obeys xₙ₊ₖ = c₁xₙ₊ₖ₋₁ + … + cₖxₙ with the characteristic polynomial of A: it is
//!   fitted by least squares to the runs from the two unit states and its roots are A's
//!   eigenvalues (those the runs excite: a root the start never excites, such as the
//!   spurious root of generalized-α at ρ∞ = 1 where a ≡ q̈, is found missing by the rank test
//!   and the order lowered). BDF is fitted after its start-up (fixed steps raise the order by
//!   one per step up to `max_order`). The fit is made in the variable u = ζ − 1 (forward
//!   differences of the sequences), where the roots near 1 of small ωh stay well conditioned,
//!   and its relative residual is reported.
//!
//! The principal root is the complex root of largest modulus (upper half-plane); ρ is its
//! modulus; `spurious` is the largest modulus among the other roots (the spurious root of
//! generalized-α and HHT, the parasitic pair of BDF); the spectral radius of A in Chung &
//! Hulbert's sense is the larger of the two (for every scheme here, ρ). When no root is
//! complex (a principal pair split into two real roots), ρ is the largest modulus and the
//! period is undefined (NaN). A period is read from the argument in (0, π]: a sampled
//! sequence cannot show a period shorter than two steps, so past ωh = π every scheme's
//! period error is at least ωh/π − 1.
//!
//! The oscillator is any one-dof model that is linear, undamped, with constant mass and rest
//! at q = 0, generated with exact tangents (`option tangents;`, so that Newton solves each
//! implicit step exactly): [`oscillator_omega`] checks it. ω is read from the model and h =
//! ωh/ω.
//!
//! ```no_run
//! mbs::multibody! {
//!     pub model Osc {
//!         option tangents;
//!         dof x = 0.0;
//!         body b { mass = 1.0; }
//!         TOG[b] = Tdisp(x, 0, 0);
//!         spring(ground, b, k = 1.0, l0 = 0, axis = x);
//!     }
//! }
//! use mbs::spectral::{analyse, log_grid};
//! let table = analyse(&Osc::default(), mbs::Scheme::Rk4, &log_grid(0.01, 100.0, 40)).unwrap();
//! println!("{table}");
//! std::fs::write("rk4.csv", table.to_csv()).unwrap();
//! ```

// matrix code reads best with explicit indices
#![allow(clippy::needless_range_loop)]

use crate::plot::Series;
use crate::{
    BdfParams, GenAlphaParams, HhtParams, IterationMatrix, Model, NewmarkParams, Options, Output,
    Scheme, SimError, StepControl, Trajectory, simulate,
};
use std::fmt;

/// How the amplification matrix of a scheme is obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// the 2×2 matrix on (q, q̇) from one step from each unit state
    OneStep,
    /// the characteristic polynomial of degree `order` fitted to the motion, after `skip`
    /// start-up steps
    Recurrence { order: usize, skip: usize },
}

impl Method {
    /// The method for a scheme: one step for the schemes whose state is (q, q̇), a fitted
    /// recurrence of order 3 for generalized-α and HHT, of order 2k after k start-up steps
    /// for BDF k.
    pub fn for_scheme(scheme: &Scheme) -> Method {
        match *scheme {
            Scheme::Hht(_) | Scheme::GenAlpha(_) => Method::Recurrence { order: 3, skip: 0 },
            Scheme::Bdf(p) => Method::Recurrence {
                order: 2 * p.max_order,
                skip: p.max_order,
            },
            _ => Method::OneStep,
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Method::OneStep => write!(f, "one step from the unit states (2×2 on (q, q̇))"),
            Method::Recurrence { order, skip } => write!(
                f,
                "recurrence of order {order} fitted to the motion after {skip} start-up steps"
            ),
        }
    }
}

/// The spectral quantities at one ωh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    pub omega_h: f64,
    /// modulus of the principal root (largest modulus if no root is complex)
    pub rho: f64,
    /// (T_num − T)/T = ωh/φ − 1, φ = arg of the principal root in (0, π]; NaN without a
    /// complex root
    pub period_error: f64,
    /// largest modulus of the other roots (NaN when there are none)
    pub spurious: f64,
    /// degree of the characteristic polynomial measured (2 for one step; the recurrence's
    /// order after the rank test)
    pub order: usize,
    /// relative residual of the measurement: the recurrence's least-squares fit, or for one
    /// step how far a second step is from A times the first
    pub residual: f64,
}

/// The spectral quantities of one scheme over a range of ωh.
#[derive(Clone, Debug)]
pub struct SpectralTable {
    pub scheme: Scheme,
    /// legend: the scheme with its parameters
    pub label: String,
    pub method: Method,
    pub points: Vec<Point>,
}

/// Why an analysis could not be made.
#[derive(Debug, thiserror::Error)]
pub enum SpectralError {
    #[error("not an undamped linear oscillator: {0}")]
    NotAnOscillator(String),
    /// A run failed at one ωh; `computed` holds the points of the ωh before it.
    #[error("{label} at ωh = {omega_h}: {error}")]
    Simulation {
        label: String,
        omega_h: f64,
        error: Box<SimError>,
        computed: Vec<Point>,
    },
    /// No recurrence fits the motion at one ωh; `computed` holds the points before it.
    #[error("{label} at ωh = {omega_h}: no recurrence of order ≤ {order} fits the motion")]
    Fit {
        label: String,
        omega_h: f64,
        order: usize,
        computed: Vec<Point>,
    },
    #[error("ωh = {omega_h} is invalid: {reason}")]
    Invalid { omega_h: f64, reason: &'static str },
}

/// The largest recurrence order [`Method::Recurrence`] may fit (its runs take 3·order + 6
/// steps beyond `skip`, and the fit a system of that size).
pub const MAX_RECURRENCE_ORDER: usize = 64;

/// `n` values from `lo` to `hi`, equally spaced in log (`lo` and `hi` > 0 and finite: other
/// bounds give NaN values, which [`analyse`] refuses).
pub fn log_grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    if n < 2 {
        return vec![lo];
    }
    let (a, b) = (lo.ln(), hi.ln());
    (0..n)
        .map(|i| (a + (b - a) * i as f64 / (n - 1) as f64).exp())
        .collect()
}

/// A legend for a scheme with its parameters: `newmark (β=0.25, γ=0.5)`, `gen-α ρ∞=0.8`,
/// `hht α=-0.05`, `bdf2`.
pub fn label(scheme: &Scheme) -> String {
    match *scheme {
        Scheme::Newmark(NewmarkParams { beta, gamma }) => {
            format!("newmark (β={beta}, γ={gamma})")
        }
        Scheme::Hht(HhtParams { alpha }) => format!("hht α={alpha}"),
        Scheme::GenAlpha(p) if p.rho_inf.is_finite() => format!("gen-α ρ∞={}", p.rho_inf),
        Scheme::GenAlpha(GenAlphaParams {
            alpha_m,
            alpha_f,
            beta,
            gamma,
            ..
        }) => format!("gen-α (αm={alpha_m}, αf={alpha_f}, β={beta}, γ={gamma})"),
        Scheme::Bdf(BdfParams { max_order }) => format!("bdf{max_order}"),
        s => s.name().to_string(),
    }
}

/// ω of a one-dof undamped linear oscillator with rest at q = 0, checked: one coordinate, no
/// constraints, exact tangents, h(q, 0) = −ω² M q with M constant, h independent of q̇.
pub fn oscillator_omega<M: Model>(model: &M) -> Result<f64, SpectralError> {
    let bad = |s: String| Err(SpectralError::NotAnOscillator(s));
    if M::NQ != 1 || M::NC != 0 {
        return bad(format!(
            "{} coordinates and {} constraints (one coordinate, no constraint)",
            M::NQ,
            M::NC
        ));
    }
    if !model.info().has_tangents {
        return bad("generate it with `option tangents;`: the implicit steps must be solved exactly, not to the Newton tolerance".into());
    }
    let u = vec![0.0; M::NU];
    let eval = |q: f64, qd: f64| {
        let (mut m, mut h) = ([0.0], [0.0]);
        model.dynamics(0.0, &[q], &[qd], &u, &mut m, &mut h);
        (m[0], h[0])
    };
    let (m1, h1) = eval(1.0, 0.0);
    let (m2, h2) = eval(2.0, 0.0);
    let (m0, h0) = eval(0.0, 0.0);
    let (_, hv) = eval(0.0, 1.0);
    let w2 = -h1 / m1;
    let tol = 1e-12 * h1.abs();
    if w2 <= 0.0 || !w2.is_finite() {
        return bad(format!("h(q = 1)/M = {} is not −ω² < 0", -w2));
    }
    if h0.abs() > tol || (h2 - 2.0 * h1).abs() > 2.0 * tol {
        return bad(format!(
            "h(q) is not −ω²M q: h(0) = {h0}, h(1) = {h1}, h(2) = {h2}"
        ));
    }
    if hv.abs() > tol {
        return bad(format!("h depends on q̇ (damping): h(q = 0, q̇ = 1) = {hv}"));
    }
    if (m0 - m1).abs() > 1e-12 * m1 || (m2 - m1).abs() > 1e-12 * m1 {
        return bad(format!("M varies with q: {m0}, {m1}, {m2}"));
    }
    Ok(w2.sqrt())
}

/// Fixed steps of `h` from (q0, qd0), every step recorded.
fn run<M: Model + Clone + 'static>(
    model: &M,
    scheme: Scheme,
    h: f64,
    steps: usize,
    start: (f64, f64),
) -> Result<Trajectory, Box<SimError>> {
    let options = Options {
        t_end: steps as f64 * h,
        q0: Some(vec![start.0]),
        qd0: Some(vec![start.1]),
        step: StepControl::Fixed { h },
        output: Output::Steps,
        energy: false,
        // record ρ > 1 rather than stop at the explicit schemes' stability limit
        stability_check: false,
        iteration_matrix: IterationMatrix::Exact,
        ..Options::default()
    };
    match simulate(model.clone(), scheme, options) {
        Ok((tr, _)) => Ok(tr),
        Err(e) => Err(Box::new(e)),
    }
}

/// The 2×2 amplification matrix on (q, q̇) of one fixed step `h` of `scheme` (columns: the
/// states after one step from (1, 0) and from (0, 1)), with the relative residual of a second
/// step against A times the first.
pub fn amplification_matrix<M: Model + Clone + 'static>(
    model: &M,
    scheme: Scheme,
    h: f64,
) -> Result<([[f64; 2]; 2], f64), Box<SimError>> {
    let a = run(model, scheme, h, 2, (1.0, 0.0))?;
    let b = run(model, scheme, h, 2, (0.0, 1.0))?;
    let m = [[a.q(1)[0], b.q(1)[0]], [a.qd(1)[0], b.qd(1)[0]]];
    let mut residual: f64 = 0.0;
    for tr in [&a, &b] {
        let (q1, v1, q2, v2) = (tr.q(1)[0], tr.qd(1)[0], tr.q(2)[0], tr.qd(2)[0]);
        let p = [m[0][0] * q1 + m[0][1] * v1, m[1][0] * q1 + m[1][1] * v1];
        let scale = q2.abs().max(v2.abs()).max(1e-300);
        residual = residual.max((p[0] - q2).abs().max((p[1] - v2).abs()) / scale);
    }
    Ok((m, residual))
}

/// The spectral table of `scheme` on the oscillator `model` at each ωh, by
/// [`Method::for_scheme`].
pub fn analyse<M: Model + Clone + 'static>(
    model: &M,
    scheme: Scheme,
    omega_h: &[f64],
) -> Result<SpectralTable, SpectralError> {
    analyse_with(model, scheme, omega_h, Method::for_scheme(&scheme))
}

/// [`analyse`] by the method given (a recurrence also measures the two-state schemes; one
/// step on a scheme with more state is wrong, and its `residual` shows it).
pub fn analyse_with<M: Model + Clone + 'static>(
    model: &M,
    scheme: Scheme,
    omega_h: &[f64],
    method: Method,
) -> Result<SpectralTable, SpectralError> {
    let invalid = |omega_h, reason| Err(SpectralError::Invalid { omega_h, reason });
    if omega_h.is_empty() {
        return invalid(
            f64::NAN,
            "give at least one ωh (an empty grid measures nothing)",
        );
    }
    if let Some(&wh) = omega_h.iter().find(|w| !(**w > 0.0 && w.is_finite())) {
        return invalid(wh, "every ωh must be > 0 and finite");
    }
    if let Method::Recurrence { order, skip } = method
        && (order == 0 || order > MAX_RECURRENCE_ORDER || skip > 1_000_000)
    {
        return invalid(
            f64::NAN,
            "a recurrence's order must be in 1..=64 and its skip at most 10⁶ steps",
        );
    }
    let omega = oscillator_omega(model)?;
    let label = label(&scheme);
    let mut points = Vec::with_capacity(omega_h.len());
    for &wh in omega_h {
        let h = wh / omega;
        let sim_err = |error: Box<SimError>| SpectralError::Simulation {
            label: label.clone(),
            omega_h: wh,
            error,
            computed: points.clone(),
        };
        let point = match method {
            Method::OneStep => {
                let (a, residual) = amplification_matrix(model, scheme, h).map_err(sim_err)?;
                // the characteristic polynomial of B = A − I: u² − tr B u + det B
                let (b00, b11) = (a[0][0] - 1.0, a[1][1] - 1.0);
                let poly = [b00 * b11 - a[0][1] * a[1][0], -(b00 + b11)];
                measure(&roots_shifted(&poly), wh, 2, residual)
            }
            Method::Recurrence { order, skip } => {
                let steps = skip + 3 * order + 6;
                let a = run(model, scheme, h, steps, (1.0, 0.0)).map_err(sim_err)?;
                let b = run(model, scheme, h, steps, (0.0, 1.0)).map_err(sim_err)?;
                let seqs: Vec<Vec<f64>> = [&a, &b]
                    .iter()
                    .flat_map(|tr| {
                        [
                            (skip..tr.len()).map(|i| tr.q(i)[0]).collect(),
                            (skip..tr.len()).map(|i| tr.qd(i)[0]).collect(),
                        ]
                    })
                    .collect();
                let refs: Vec<&[f64]> = seqs.iter().map(|s| s.as_slice()).collect();
                let fit = (1..=order)
                    .rev()
                    .find_map(|k| fit_recurrence(&refs, k))
                    .ok_or_else(|| SpectralError::Fit {
                        label: label.clone(),
                        omega_h: wh,
                        order,
                        computed: points.clone(),
                    })?;
                fit.point(wh)
            }
        };
        points.push(point);
    }
    Ok(SpectralTable {
        scheme,
        label,
        method,
        points,
    })
}

/// A linear recurrence fitted to sequences: its characteristic polynomial written in
/// u = ζ − 1, uᵏ + d\[k−1\] uᵏ⁻¹ + … + d\[0\] (so Δᵏxₙ + d\[k−1\] Δᵏ⁻¹xₙ + … + d\[0\] xₙ = 0).
#[derive(Clone, Debug, PartialEq)]
pub struct Recurrence {
    pub shifted: Vec<f64>,
    /// largest residual of a row relative to its largest entry
    pub residual: f64,
}

impl Recurrence {
    /// The roots ζ of the characteristic polynomial, as (re, im).
    pub fn roots(&self) -> Vec<(f64, f64)> {
        roots_shifted(&self.shifted)
            .into_iter()
            .map(|u| (1.0 + u.re, u.im))
            .collect()
    }

    /// The spectral quantities at ωh (ωh the phase per step of the exact motion).
    pub fn point(&self, omega_h: f64) -> Point {
        measure(
            &roots_shifted(&self.shifted),
            omega_h,
            self.shifted.len(),
            self.residual,
        )
    }
}

/// Least squares of the recurrence of order `k` common to every sequence, in forward
/// differences (Householder QR, rows scaled to their largest entry, columns to unit norm).
/// `None` when the sequences are too short or do not determine it (a numerically
/// rank-deficient system: fewer than `k` modes excited).
pub fn fit_recurrence(sequences: &[&[f64]], k: usize) -> Option<Recurrence> {
    if k == 0 {
        return None;
    }
    // rows: (Δ⁰xₙ, …, Δᵏ⁻¹xₙ | Δᵏxₙ)
    let mut rows: Vec<Vec<f64>> = Vec::new();
    for x in sequences {
        if x.len() <= k {
            continue;
        }
        // diffs[j] = Δʲx
        let mut diffs: Vec<Vec<f64>> = vec![x.to_vec()];
        for j in 1..=k {
            let p = &diffs[j - 1];
            let d: Vec<f64> = p.windows(2).map(|w| w[1] - w[0]).collect();
            diffs.push(d);
        }
        for n in 0..diffs[k].len() {
            let row: Vec<f64> = (0..=k).map(|j| diffs[j][n]).collect();
            let s = row.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            if s > 0.0 && row.iter().all(|v| v.is_finite()) {
                rows.push(row.iter().map(|v| v / s).collect());
            }
        }
    }
    if rows.len() < k + 1 {
        return None;
    }
    let nr = rows.len();
    let mut a: Vec<Vec<f64>> = rows.iter().map(|r| r[..k].to_vec()).collect();
    let mut b: Vec<f64> = rows.iter().map(|r| -r[k]).collect();
    // unit columns
    let mut cs = vec![0.0; k];
    for j in 0..k {
        cs[j] = (0..nr).map(|r| a[r][j] * a[r][j]).sum::<f64>().sqrt();
        if cs[j] == 0.0 {
            return None;
        }
        for r in a.iter_mut() {
            r[j] /= cs[j];
        }
    }
    for j in 0..k {
        let norm = (j..nr).map(|r| a[r][j] * a[r][j]).sum::<f64>().sqrt();
        // a column (of unit norm) nearly in the span of the previous ones: rank deficient
        if norm < 1e-10 {
            return None;
        }
        let alpha = if a[j][j] > 0.0 { -norm } else { norm };
        let mut v: Vec<f64> = (j..nr).map(|r| a[r][j]).collect();
        v[0] -= alpha;
        let vn: f64 = v.iter().map(|t| t * t).sum();
        if vn == 0.0 {
            continue;
        }
        for c in j..k {
            let s: f64 = (j..nr).map(|r| v[r - j] * a[r][c]).sum::<f64>() * 2.0 / vn;
            for r in j..nr {
                a[r][c] -= s * v[r - j];
            }
        }
        let s: f64 = (j..nr).map(|r| v[r - j] * b[r]).sum::<f64>() * 2.0 / vn;
        for r in j..nr {
            b[r] -= s * v[r - j];
        }
    }
    let mut d = vec![0.0; k];
    for j in (0..k).rev() {
        d[j] = (b[j] - (j + 1..k).map(|i| a[j][i] * d[i]).sum::<f64>()) / a[j][j];
    }
    for j in 0..k {
        d[j] /= cs[j];
    }
    if !d.iter().all(|x| x.is_finite()) {
        return None;
    }
    let residual = rows
        .iter()
        .map(|r| (r[k] + (0..k).map(|j| d[j] * r[j]).sum::<f64>()).abs())
        .fold(0.0f64, f64::max);
    Some(Recurrence {
        shifted: d,
        residual,
    })
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct C {
    re: f64,
    im: f64,
}

impl C {
    fn new(re: f64, im: f64) -> C {
        C { re, im }
    }
    fn abs(self) -> f64 {
        self.re.hypot(self.im)
    }
    fn add(self, o: C) -> C {
        C::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: C) -> C {
        C::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: C) -> C {
        C::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    fn div(self, o: C) -> C {
        let d = o.re * o.re + o.im * o.im;
        C::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
}

/// Value and derivative of the monic uᵏ + d[k−1]uᵏ⁻¹ + … + d[0] at u.
fn eval_monic(d: &[f64], u: C) -> (C, C) {
    let mut p = C::new(1.0, 0.0);
    let mut dp = C::new(0.0, 0.0);
    for &c in d.iter().rev() {
        dp = dp.mul(u).add(p);
        p = p.mul(u).add(C::new(c, 0.0));
    }
    (p, dp)
}

/// The roots u of the monic uᵏ + d[k−1]uᵏ⁻¹ + … + d[0]: closed form up to degree 2,
/// Durand–Kerner then Newton polishing beyond.
fn roots_shifted(d: &[f64]) -> Vec<C> {
    let k = d.len();
    match k {
        0 => return Vec::new(),
        1 => return vec![C::new(-d[0], 0.0)],
        2 => {
            let (b, c) = (d[1], d[0]);
            let disc = 0.25 * b * b - c;
            if disc < 0.0 {
                let s = (-disc).sqrt();
                return vec![C::new(-0.5 * b, s), C::new(-0.5 * b, -s)];
            }
            // real roots, the larger first computed without cancellation
            let s = disc.sqrt();
            let r1 = -0.5 * b - s.copysign(b);
            let r2 = if r1 != 0.0 { c / r1 } else { 0.0 };
            return vec![C::new(r1, 0.0), C::new(r2, 0.0)];
        }
        _ => {}
    }
    // Fujiwara's bound on the moduli
    let bound = (0..k)
        .map(|j| (d[j].abs() / if j == 0 { 2.0 } else { 1.0 }).powf(1.0 / (k - j) as f64))
        .fold(0.0f64, f64::max)
        * 2.0;
    let r = if bound > 0.0 { 0.5 * bound } else { 1.0 };
    let mut z: Vec<C> = (0..k)
        .map(|i| {
            let a = 0.4 + std::f64::consts::TAU * i as f64 / k as f64;
            C::new(r * a.cos(), r * a.sin())
        })
        .collect();
    for _ in 0..2000 {
        let mut change: f64 = 0.0;
        for i in 0..k {
            let mut den = C::new(1.0, 0.0);
            for j in 0..k {
                if i != j {
                    den = den.mul(z[i].sub(z[j]));
                }
            }
            if den.abs() == 0.0 {
                continue;
            }
            let step = eval_monic(d, z[i]).0.div(den);
            if step.re.is_finite() && step.im.is_finite() {
                z[i] = z[i].sub(step);
                change = change.max(step.abs() / z[i].abs().max(r * 1e-6));
            }
        }
        if change < 1e-15 {
            break;
        }
    }
    // Newton polishing (stops if it does not improve the residual)
    for zi in z.iter_mut() {
        for _ in 0..4 {
            let (p, dp) = eval_monic(d, *zi);
            if dp.abs() == 0.0 {
                break;
            }
            let next = zi.sub(p.div(dp));
            if eval_monic(d, next).0.abs() < p.abs() {
                *zi = next;
            } else {
                break;
            }
        }
    }
    z
}

/// ρ, period error and spurious modulus from the roots u = ζ − 1.
fn measure(us: &[C], omega_h: f64, order: usize, residual: f64) -> Point {
    let zeta = |u: C| C::new(1.0 + u.re, u.im);
    let modulus = |u: C| zeta(u).abs();
    let complex = |u: C| u.im.abs() > 1e-8 * modulus(u).max(f64::MIN_POSITIVE);
    let by_modulus = |a: &usize, b: &usize| modulus(us[*a]).total_cmp(&modulus(us[*b]));
    let principal = (0..us.len())
        .filter(|&i| complex(us[i]) && us[i].im > 0.0)
        .max_by(by_modulus);
    let (rho, period_error, excluded) = match principal {
        Some(i) => {
            let u = us[i];
            let phase = u.im.atan2(1.0 + u.re);
            // its conjugate: the nearest root in the lower half-plane
            let conj = C::new(u.re, -u.im);
            let j = (0..us.len())
                .filter(|&j| j != i)
                .min_by(|&a, &b| us[a].sub(conj).abs().total_cmp(&us[b].sub(conj).abs()))
                .unwrap_or(i);
            (modulus(u), omega_h / phase - 1.0, vec![i, j])
        }
        None => {
            let i = (0..us.len()).max_by(by_modulus).unwrap_or(0);
            (
                us.get(i).map_or(f64::NAN, |&u| modulus(u)),
                f64::NAN,
                vec![i],
            )
        }
    };
    let spurious = (0..us.len())
        .filter(|i| !excluded.contains(i))
        .map(|i| modulus(us[i]))
        .fold(f64::NAN, f64::max);
    Point {
        omega_h,
        rho,
        period_error,
        spurious,
        order,
        residual,
    }
}

/// The CSV header of [`SpectralTable::to_csv`].
pub const CSV_HEADER: &str = "scheme,omega_h,rho,period_error,spurious_rho,order,residual";

impl SpectralTable {
    /// The point nearest to `omega_h` (in log); `None` for an ωh that is not > 0 and finite.
    pub fn at(&self, omega_h: f64) -> Option<&Point> {
        if !(omega_h > 0.0 && omega_h.is_finite()) {
            return None;
        }
        self.points.iter().min_by(|a, b| {
            (a.omega_h / omega_h)
                .ln()
                .abs()
                .total_cmp(&(b.omega_h / omega_h).ln().abs())
        })
    }

    /// CSV with [`CSV_HEADER`] (one row per ωh; empty fields for NaN).
    pub fn to_csv(&self) -> String {
        let mut out = format!("{CSV_HEADER}\n");
        self.csv_rows(&mut out);
        out
    }

    fn csv_rows(&self, out: &mut String) {
        let num = |v: f64| {
            if v.is_nan() {
                String::new()
            } else {
                format!("{v:e}")
            }
        };
        for p in &self.points {
            out.push_str(&format!(
                "{},{},{},{},{},{},{}\n",
                self.label,
                num(p.omega_h),
                num(p.rho),
                num(p.period_error),
                num(p.spurious),
                p.order,
                num(p.residual)
            ));
        }
    }

    /// ρ against ωh, for [`crate::plot::line_chart`].
    pub fn rho_series(&self) -> Series {
        Series {
            name: self.label.clone(),
            points: self.points.iter().map(|p| (p.omega_h, p.rho)).collect(),
        }
    }

    /// |T_num − T|/T against ωh up to `max_omega_h` (points without a period, or below
    /// `floor`, left out: on a log axis, rounding noise would draw as data).
    pub fn period_series(&self, floor: f64, max_omega_h: f64) -> Series {
        Series {
            name: self.label.clone(),
            points: self
                .points
                .iter()
                .filter(|p| p.period_error.abs() >= floor && p.omega_h <= max_omega_h)
                .map(|p| (p.omega_h, p.period_error.abs()))
                .collect(),
        }
    }
}

/// Several tables in one CSV (one header).
pub fn tables_to_csv(tables: &[SpectralTable]) -> String {
    let mut out = format!("{CSV_HEADER}\n");
    for t in tables {
        t.csv_rows(&mut out);
    }
    out
}

impl fmt::Display for SpectralTable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{} — {}", self.label, self.method)?;
        writeln!(
            f,
            "{:>10}  {:>12}  {:>13}  {:>12}  {:>5}  {:>9}",
            "ωh", "ρ", "(T_num−T)/T", "spurious ρ", "order", "residual"
        )?;
        for p in &self.points {
            let opt = |v: f64| {
                if v.is_nan() {
                    "—".to_string()
                } else {
                    format!("{v:.6}")
                }
            };
            let pe = if p.period_error.is_nan() {
                "—".to_string()
            } else {
                format!("{:.5e}", p.period_error)
            };
            writeln!(
                f,
                "{:>10.4}  {:>12.8}  {:>13}  {:>12}  {:>5}  {:>9.1e}",
                p.omega_h,
                p.rho,
                pe,
                opt(p.spurious),
                p.order,
                p.residual
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_of_known_polynomials() {
        // (u − 0.5)(u² + 0.02u + 0.0002): roots 0.5, −0.01 ± 0.01i
        let d = [-0.0001, 0.0002 - 0.01, 0.02 - 0.5];
        let mut r = roots_shifted(&d);
        r.sort_by(|a, b| a.im.total_cmp(&b.im));
        assert!((r[0].re + 0.01).abs() < 1e-14 && (r[0].im + 0.01).abs() < 1e-14);
        assert!((r[1].re - 0.5).abs() < 1e-14 && r[1].im.abs() < 1e-14);
        assert!((r[2].re + 0.01).abs() < 1e-14 && (r[2].im - 0.01).abs() < 1e-14);
        // a double root: (u + 1.5)²(u − 2)
        let d = [-4.5, -3.75, 1.0];
        let r = roots_shifted(&d);
        assert!(r.iter().all(|z| (eval_monic(&d, *z).0).abs() < 1e-12));
    }

    #[test]
    fn fits_a_known_recurrence() {
        // xₙ = 0.9ⁿ cos(0.3n) + 0.5 (−0.4)ⁿ: roots 0.9e^{±0.3i}, −0.4
        let x: Vec<f64> = (0..20)
            .map(|n| {
                let n = n as f64;
                0.9f64.powf(n) * (0.3 * n).cos() + 0.5 * (-0.4f64).powf(n)
            })
            .collect();
        let fit = fit_recurrence(&[&x], 3).unwrap();
        let p = fit.point(0.3);
        assert!((p.rho - 0.9).abs() < 1e-10, "{p:?}");
        assert!(p.period_error.abs() < 1e-10, "{p:?}");
        assert!((p.spurious - 0.4).abs() < 1e-10, "{p:?}");
        // only two modes: order 3 is rank deficient
        let y: Vec<f64> = (0..20).map(|n| (0.3 * n as f64).cos()).collect();
        assert!(fit_recurrence(&[&y], 3).is_none());
        assert!(fit_recurrence(&[&y], 2).is_some());
    }
}
