//! Spectral radius and period error of the schemes, measured on the implemented integrators
//! by `mbs::spectral` (one step from the unit states, or the characteristic polynomial
//! fitted to the motion), against closed-form theory:
//!
//! - on the unit oscillator: the stability functions R(iωh) of the one-step schemes
//!   (Euler, RK4, DOPRI5, Radau IIA 3 and 5, the trapezoidal rule for Newmark (¼, ½) and
//!   the implicit midpoint rule), the roots of BDF2's characteristic equation, and Chung &
//!   Hulbert's amplification matrix for generalized-α and HHT; then the limits (ρ → ρ∞,
//!   L-stability, RK4's stability limit 2√2);
//! - the seed course's figures for the 2-dof system: at 20 steps per period of the 10 Hz mode
//!   and 5 steps per period of the 1 Hz mode, Newmark (¼, ½) keeps the amplitude of both
//!   modes, and generalized-α (ρ∞ = 0.8) damps the 10 Hz mode while keeping the 1 Hz one —
//!   measured on each modal coordinate of the simulated motion (a linear system integrated by
//!   a linear scheme obeys a linear recurrence, fitted by `mbs::spectral::fit_recurrence`).
#![allow(clippy::needless_range_loop)]

mod common;
use mbs_models::seed2dof;

#[path = "common/quoted.rs"]
mod quoted;

use common::*;
use mbs::spectral::{
    CSV_HEADER, Method, Point, SpectralError, analyse, analyse_with, fit_recurrence, log_grid,
};
use mbs::{BdfParams, GenAlphaParams, HhtParams, NewmarkParams, Options, Output, Scheme, simulate};
use seed2dof::Seed2dof;
use std::f64::consts::PI;

mbs::multibody! {
    /// The unit oscillator (ω = 1 rad/s), with exact tangents.
    pub model Unit {
        option tangents;
        dof x = 1.0;
        body mass { mass = 1.0; }
        TOG[mass] = Tdisp(x, 0, 0);
        spring(ground, mass, k = 1.0, l0 = 0.0, axis = x);
    }
}

mbs::multibody! {
    /// ω = 3 rad/s from k = 18 N/m on m = 2 kg: ωh, not h, matters.
    pub model Other {
        option tangents;
        dof x = 1.0;
        body mass { mass = 2.0; }
        TOG[mass] = Tdisp(x, 0, 0);
        spring(ground, mass, k = 18.0, l0 = 0.0, axis = x);
    }
}

mbs::multibody! {
    /// Damped: not an undamped oscillator.
    pub model Damped {
        option tangents;
        dof x = 1.0;
        body mass { mass = 1.0; }
        TOG[mass] = Tdisp(x, 0, 0);
        spring(ground, mass, k = 1.0, l0 = 0.0, axis = x);
        damper(ground, mass, c = 0.1, axis = x);
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct C {
    re: f64,
    im: f64,
}

const ONE: C = C { re: 1.0, im: 0.0 };

fn c(re: f64, im: f64) -> C {
    C { re, im }
}

impl C {
    fn abs(self) -> f64 {
        self.re.hypot(self.im)
    }
    fn add(self, o: C) -> C {
        c(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: C) -> C {
        c(self.re - o.re, self.im - o.im)
    }
    fn scale(self, s: f64) -> C {
        c(self.re * s, self.im * s)
    }
    fn mul(self, o: C) -> C {
        c(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    fn div(self, o: C) -> C {
        let d = o.re * o.re + o.im * o.im;
        c(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
    /// principal square root
    fn sqrt(self) -> C {
        let r = self.abs();
        let re = ((r + self.re) / 2.0).sqrt();
        let im = ((r - self.re) / 2.0).sqrt().copysign(self.im);
        c(re, im)
    }
    /// Σ z^k / k! for k ≤ n
    fn taylor(self, n: usize) -> C {
        let (mut term, mut sum) = (ONE, ONE);
        for k in 1..=n {
            term = term.mul(self).scale(1.0 / k as f64);
            sum = sum.add(term);
        }
        sum
    }
    fn powi(self, n: u32) -> C {
        (0..n).fold(ONE, |acc, _| acc.mul(self))
    }
}

/// (ρ, period error) of a principal root ζ at ωh: ρ = |ζ|, φ = |arg ζ| ∈ [0, π] (a real
/// 2×2 matrix has ζ and its conjugate), (T_num − T)/T = ωh/φ − 1.
fn of_root(z: C, wh: f64) -> (f64, f64) {
    (z.abs(), wh / z.im.atan2(z.re).abs() - 1.0)
}

/// Roots of xⁿ + c[0] xⁿ⁻¹ + … + c[n−1] (Durand–Kerner), for the theory of the α family.
fn roots(coef: &[f64]) -> Vec<C> {
    let n = coef.len();
    let eval = |x: C| coef.iter().fold(ONE, |acc, &k| acc.mul(x).add(c(k, 0.0)));
    let mut z: Vec<C> = (0..n)
        .map(|k| {
            let a = 0.4 + 0.9 * k as f64;
            c(a.cos() * 0.9, a.sin() * 0.9)
        })
        .collect();
    for _ in 0..2000 {
        for i in 0..n {
            let mut den = ONE;
            for j in 0..n {
                if i != j {
                    den = den.mul(z[i].sub(z[j]));
                }
            }
            z[i] = z[i].sub(eval(z[i]).div(den));
        }
    }
    z
}

/// Theory: the amplification matrix of generalized-α (Chung & Hulbert 1993) on ẍ = −ω²x
/// (its characteristic polynomial: `common::gen_alpha_characteristic`); the (ρ, period error)
/// of its principal (complex) pair and the modulus of its third root.
fn alpha_theory(am: f64, af: f64, beta: f64, gamma: f64, wh: f64) -> (f64, f64, f64) {
    let rs = roots(&gen_alpha_characteristic(am, af, beta, gamma, wh));
    let p = (0..3)
        .filter(|&i| rs[i].im.abs() > 1e-9)
        .max_by(|&a, &b| rs[a].abs().total_cmp(&rs[b].abs()))
        .expect("a complex pair");
    let spurious = (0..3)
        .filter(|&i| rs[i].im.abs() <= 1e-9)
        .map(|i| rs[i].abs())
        .fold(0.0, f64::max);
    let (rho, pe) = of_root(rs[p], wh);
    (rho, pe, spurious)
}

/// The ωh of the closed-form comparisons: below, at and past the stability limits, into the
/// stiff range.
const WH: [f64; 10] = [0.01, 0.1, 0.5, 1.0, 2.0, 2.7, 3.0, 5.0, 10.0, 100.0];

fn check(what: &str, p: &Point, rho: f64, pe: f64, tol: f64) {
    let ok_rho = (p.rho - rho).abs() <= tol * rho.max(1.0);
    let ok_pe = (p.period_error - pe).abs() <= tol * (1.0 + pe.abs());
    println!(
        "{what:<24} ωh {:>7.3}: ρ {:.12} theory {:.12}; ΔT/T {:+.6e} theory {:+.6e}",
        p.omega_h, p.rho, rho, p.period_error, pe
    );
    assert!(ok_rho, "{what} at ωh = {}: ρ {} vs {rho}", p.omega_h, p.rho);
    assert!(
        ok_pe,
        "{what} at ωh = {}: period error {} vs {pe}",
        p.omega_h, p.period_error
    );
}

/// The one-step schemes: A on (q, q̇) from one step of the integrator, its eigenvalue against
/// the scheme's stability function R(iωh). A is exact to rounding (linear model, exact
/// tangents: Newton solves the implicit steps exactly), so the eigenvalues are within ~1e-15
/// and the phase within ~1e-15/ωh: 1e-10 leaves a margin of 10³ at ωh = 0.01 and still sees
/// any error of the formulas (the smallest period error compared, RK4's at 0.01, is 8e-11,
/// and its next Taylor term would change it at the 1e-15 level: the comparison at 0.01 and
/// 0.1 is only meaningful for the second-order schemes, the others are compared further out).
#[test]
fn one_step_schemes_follow_their_stability_functions() {
    let model = Unit::default();
    let iz = |wh: f64| c(0.0, wh);
    type R = fn(C) -> C;
    let cases: [(Scheme, &str, R); 7] = [
        (Scheme::ExplicitEuler, "euler: 1 + z", |z| ONE.add(z)),
        (Scheme::Rk4, "rk4: Σ_{k≤4} zᵏ/k!", |z| z.taylor(4)),
        (Scheme::Dopri5, "dopri5: Σ_{k≤5} + z⁶/600", |z| {
            z.taylor(5).add(z.powi(6).scale(1.0 / 600.0))
        }),
        (Scheme::Radau3, "radau3: (1,2)-Padé", |z| {
            ONE.add(z.scale(1.0 / 3.0))
                .div(ONE.sub(z.scale(2.0 / 3.0)).add(z.mul(z).scale(1.0 / 6.0)))
        }),
        (Scheme::Radau5, "radau5: (2,3)-Padé", |z| {
            let z2 = z.mul(z);
            ONE.add(z.scale(0.4)).add(z2.scale(0.05)).div(
                ONE.sub(z.scale(0.6))
                    .add(z2.scale(0.15))
                    .sub(z2.mul(z).scale(1.0 / 60.0)),
            )
        }),
        (
            Scheme::Newmark(NewmarkParams::default()),
            "newmark (¼,½): trapezoidal",
            |z| ONE.add(z.scale(0.5)).div(ONE.sub(z.scale(0.5))),
        ),
        (Scheme::ImplicitMidpoint, "midpoint (= trapezoidal)", |z| {
            ONE.add(z.scale(0.5)).div(ONE.sub(z.scale(0.5)))
        }),
    ];
    for (scheme, what, r) in cases {
        let table = analyse(&model, scheme, &WH).unwrap();
        assert_eq!(table.method, Method::OneStep);
        for p in &table.points {
            let (rho, pe) = of_root(r(iz(p.omega_h)), p.omega_h);
            check(what, p, rho, pe, 1e-10);
            assert!(p.residual < 1e-10, "{what}: a second step off A: {p:?}");
        }
    }
    // the trapezoidal rule's closed forms: ρ = 1, φ = 2 arctan(ωh/2)
    for s in [
        Scheme::Newmark(NewmarkParams::default()),
        Scheme::ImplicitMidpoint,
    ] {
        for p in analyse(&model, s, &log_grid(0.01, 100.0, 41))
            .unwrap()
            .points
        {
            let pe = p.omega_h / (2.0 * (p.omega_h / 2.0).atan()) - 1.0;
            assert!((p.rho - 1.0).abs() < 1e-12, "{s:?}: {p:?}");
            assert!(
                (p.period_error - pe).abs() < 1e-10 * (1.0 + pe),
                "{s:?}: {p:?}"
            );
        }
    }
    // ωh, not h: ω = 3 rad/s gives the same table
    let other = analyse(&Other::default(), Scheme::Radau5, &WH).unwrap();
    let unit = analyse(&model, Scheme::Radau5, &WH).unwrap();
    for (a, b) in other.points.iter().zip(&unit.points) {
        assert!((a.rho - b.rho).abs() < 1e-12 && (a.period_error - b.period_error).abs() < 1e-9);
    }
}

/// BDF2 after its start-up, by the fitted recurrence of order 4: the roots of
/// (3 − 2z)ζ² − 4ζ + 1 = 0, ζ = (2 ± √(1 + 2z))/(3 − 2z), z = iωh, the principal root with
/// the + sign. The fit's residuals are ~1e-14 and the roots are simple, so they are within
/// ~1e-12: tolerance 1e-9.
#[test]
fn bdf2_follows_its_characteristic_roots() {
    let table = analyse(
        &Unit::default(),
        Scheme::Bdf(BdfParams { max_order: 2 }),
        &WH,
    )
    .unwrap();
    assert_eq!(table.method, Method::Recurrence { order: 4, skip: 2 });
    for p in &table.points {
        let z = c(0.0, p.omega_h);
        let s = ONE.add(z.scale(2.0)).sqrt();
        let den = c(3.0, 0.0).sub(z.scale(2.0));
        let principal = c(2.0, 0.0).add(s).div(den);
        let parasitic = c(2.0, 0.0).sub(s).div(den);
        let (rho, pe) = of_root(principal, p.omega_h);
        check("bdf2", p, rho, pe, 1e-9);
        assert_eq!(p.order, 4);
        // the parasitic pair is excited by the start-up alone (its amplitude O((ωh)²)), so
        // it is fitted less precisely at small ωh: 1.4e-9 at ωh = 0.01, 6e-12 at 100
        assert!((p.spurious - parasitic.abs()).abs() < 1e-7, "{p:?}");
        assert!(p.residual < 1e-10, "{p:?}");
    }
}

/// Generalized-α and HHT by the fitted recurrence of order 3, against the eigenvalues of
/// Chung & Hulbert's amplification matrix. At large ωh the three roots gather at −ρ∞ and a
/// root's sensitivity to the fitted coefficients grows (a near-triple root moves as the cube
/// root of a perturbation): residuals ~1e-12 allow errors up to ~1e-4 in principle; measured
/// they agree to 1e-11. Tolerance 1e-6.
#[test]
fn alpha_family_follows_chung_hulbert() {
    let model = Unit::default();
    let mut schemes: Vec<(Scheme, (f64, f64, f64, f64))> = Vec::new();
    for r in [1.0, 0.8, 0.5, 0.0] {
        let p = GenAlphaParams::from_rho_inf(r);
        schemes.push((Scheme::GenAlpha(p), (p.alpha_m, p.alpha_f, p.beta, p.gamma)));
    }
    for a in [-0.05, -0.3] {
        let hht = (0.0, -a, 0.25 * (1.0 - a) * (1.0 - a), 0.5 - a);
        schemes.push((Scheme::Hht(HhtParams { alpha: a }), hht));
    }
    for (scheme, (am, af, beta, gamma)) in schemes {
        let table = analyse(&model, scheme, &WH).unwrap();
        for p in &table.points {
            let (rho, pe, spurious) = alpha_theory(am, af, beta, gamma, p.omega_h);
            check(&table.label, p, rho, pe, 1e-6);
            assert!(p.residual < 1e-10, "{p:?}");
            if p.order == 3 {
                assert!((p.spurious - spurious).abs() < 1e-6, "{p:?} vs {spurious}");
            } else {
                // ρ∞ = 1 (α_m = α_f = ½): a₁ = q̈₁ from a₀ = q̈₀, the third root (−1) is
                // never excited and the rank test finds two roots
                assert_eq!(table.label, "gen-α ρ∞=1");
            }
        }
    }
}

/// The limits: ρ → ρ∞ for generalized-α, L-stability of Radau IIA 5 and BDF2, RK4's
/// stability limit on the imaginary axis 2√2, the implicit midpoint rule's ρ = 1.
#[test]
fn spectral_limits() {
    let model = Unit::default();
    for r in [1.0, 0.8, 0.5, 0.0] {
        let s = Scheme::GenAlpha(GenAlphaParams::from_rho_inf(r));
        let t = analyse(&model, s, &[100.0, 1e4]).unwrap();
        let (d100, d1e4) = (t.points[0].rho - r, t.points[1].rho - r);
        println!("gen-α ρ∞ = {r}: ρ(100) − ρ∞ = {d100:.3e}, ρ(1e4) − ρ∞ = {d1e4:.3e}");
        // the roots reach −ρ∞ only as (ωh)^(−2/3) (a triple root splitting): 0.035 at
        // ωh = 100 for ρ∞ = 0.8 in theory too, 1.7e-3 at 1e4
        assert!(d100.abs() < 0.05 && d1e4.abs() < 1e-2, "ρ∞ = {r}");
        if r == 0.8 {
            quoted::says(
                "README.md",
                &[format!(
                    "generalized-α tends to ρ∞ slowly, as (ωh)^(−2/3) ({:.3} at ωh = 100 for \
                     ρ∞ = 0.8)",
                    t.points[0].rho
                )],
            );
        }
    }
    // L-stable: Radau IIA 5 has R(z) ~ −3/z, BDF2 ζ ~ 1/√(2|z|)
    let radau5 = analyse(&model, Scheme::Radau5, &[100.0, 1e4]).unwrap();
    assert!(
        (radau5.points[0].rho * 100.0 - 3.0).abs() < 0.01,
        "{radau5}"
    );
    assert!(radau5.points[1].rho < 3.1e-4, "{radau5}");
    let bdf2 = analyse(
        &model,
        Scheme::Bdf(BdfParams { max_order: 2 }),
        &[100.0, 1e4],
    )
    .unwrap();
    assert!(
        bdf2.points[0].rho < 0.08 && bdf2.points[1].rho < 0.0075,
        "{bdf2}"
    );
    // RK4: stable on the imaginary axis up to 2√2 = 2.828
    let lim = 2.0 * 2f64.sqrt();
    let rk4 = analyse(
        &model,
        Scheme::Rk4,
        &[2.7, 2.8, lim - 1e-3, lim + 1e-3, 2.9],
    )
    .unwrap();
    let rho: Vec<f64> = rk4.points.iter().map(|p| p.rho).collect();
    println!("rk4 ρ at 2.7, 2.8, 2√2 ∓ 1e-3, 2.9: {rho:?}");
    assert!(rho[0] < 1.0 && rho[1] < 1.0 && rho[2] < 1.0 && rho[3] > 1.0 && rho[4] > 1.0);
    // DOPRI5 is not: ρ > 1 from ωh ≈ 0.997
    let dopri5 = analyse(&model, Scheme::Dopri5, &[0.99, 1.0, 2.0]).unwrap();
    assert!(dopri5.points[0].rho < 1.0 && dopri5.points[1].rho > 1.0);
    assert!((dopri5.points[2].rho - 1.0318).abs() < 1e-4, "{dopri5}");
    // implicit midpoint and Newmark (¼, ½): ρ = 1 at every ωh, to rounding. Newmark forms
    // q₁ = q̂ + β h² a₁ from terms of size (ωh)²|q| that cancel, so its rounding grows as
    // ε(ωh)² (measured: 1e-13 at ωh = 100, 1e-9 at 1e4); the midpoint rule stays within 1 ulp
    for s in [
        Scheme::ImplicitMidpoint,
        Scheme::Newmark(NewmarkParams::default()),
    ] {
        let t = analyse(&model, s, &log_grid(0.01, 1e4, 31)).unwrap();
        for p in &t.points {
            let tol = 1e-15 * (1.0 + p.omega_h * p.omega_h);
            assert!((p.rho - 1.0).abs() < tol, "{}: {p:?}", t.label);
        }
    }
}

/// The two methods agree where both apply (Newmark's state is (q, q̇): its q̈ is solved from
/// the equilibrium at every step), and the one-step residual exposes a scheme with more
/// state (generalized-α: A on (q, q̇) alone does not predict the second step).
#[test]
fn methods_agree_and_residuals_tell() {
    let model = Unit::default();
    let grid = log_grid(0.01, 100.0, 9);
    let newmark = Scheme::Newmark(NewmarkParams {
        beta: 0.3025,
        gamma: 0.6,
    });
    let one = analyse_with(&model, newmark, &grid, Method::OneStep).unwrap();
    let fit = analyse_with(
        &model,
        newmark,
        &grid,
        Method::Recurrence { order: 3, skip: 0 },
    )
    .unwrap();
    for (a, b) in one.points.iter().zip(&fit.points) {
        assert_eq!(b.order, 2, "Newmark's motion has two roots: {b:?}");
        assert!((a.rho - b.rho).abs() < 1e-9, "{a:?} {b:?}");
        assert!((a.period_error - b.period_error).abs() < 1e-9 * (1.0 + a.period_error.abs()));
    }
    let ga = Scheme::GenAlpha(GenAlphaParams::from_rho_inf(0.5));
    let wrong = analyse_with(&model, ga, &[1.0], Method::OneStep).unwrap();
    assert!(wrong.points[0].residual > 1e-3, "{wrong}");
    // tables print and write CSV
    let text = format!("{one}");
    assert!(text.starts_with("newmark (β=0.3025, γ=0.6) — one step"));
    let csv = one.to_csv();
    assert!(csv.starts_with(CSV_HEADER) && csv.lines().count() == grid.len() + 1);
    // not an oscillator
    let err = analyse(&Damped::default(), Scheme::Rk4, &[1.0]).unwrap_err();
    assert!(matches!(err, SpectralError::NotAnOscillator(_)), "{err}");
}

/// Grids that measure nothing or are not numbers are refused by name; a run that fails at one
/// ωh keeps the points before it in its error; a fit never takes NaN rows for data.
#[test]
fn bad_grids_are_refused_and_a_failure_keeps_the_points_before_it() {
    let model = Unit::default();
    for grid in [
        vec![],
        log_grid(0.0, 10.0, 5),
        vec![1.0, -1.0],
        vec![f64::INFINITY],
    ] {
        let err = analyse(&model, Scheme::Rk4, &grid).unwrap_err();
        assert!(
            matches!(err, SpectralError::Invalid { .. }),
            "{grid:?}: {err}"
        );
    }
    let err = analyse_with(
        &model,
        Scheme::Rk4,
        &[1.0],
        Method::Recurrence {
            order: 10_000_000,
            skip: 0,
        },
    )
    .unwrap_err();
    assert!(matches!(err, SpectralError::Invalid { .. }), "{err}");
    // a step beyond f64 at the last ωh: that run is refused
    let err = analyse(&model, Scheme::Rk4, &[0.01, 0.1, 1e308]).unwrap_err();
    match err {
        SpectralError::Simulation {
            omega_h, computed, ..
        } => {
            assert_eq!(omega_h, 1e308);
            let at: Vec<f64> = computed.iter().map(|p| p.omega_h).collect();
            assert_eq!(at, [0.01, 0.1]);
        }
        other => panic!("{other}"),
    }
    let table = analyse(&model, Scheme::Rk4, &[0.1, 1.0]).unwrap();
    assert!(table.at(0.0).is_none() && table.at(f64::NAN).is_none());
    assert_eq!(table.at(0.9).unwrap().omega_h, 1.0);
    // a NaN in the data is no row of the fit: the others fit x_{n+1} = 0.5 x_n
    let x: Vec<f64> = (0..12)
        .map(|n| if n == 5 { f64::NAN } else { 0.5f64.powi(n) })
        .collect();
    let fit = fit_recurrence(&[&x], 1);
    assert!(
        fit.as_ref()
            .is_none_or(|f| f.shifted.iter().all(|d| d.is_finite())),
        "{fit:?}"
    );
}

/// Measured (ρ, period error) of mode `k` of a seed2dof trajectory sampled at every step.
fn measured(tr: &mbs::Trajectory, k: usize, skip: usize, wh: f64) -> (f64, f64) {
    let (_, v) = seed2dof_modes();
    let eta: Vec<f64> = (skip..tr.len())
        .map(|i| v[k][0] * tr.q(i)[0] + v[k][1] * tr.q(i)[1])
        .collect();
    let fit = fit_recurrence(&[&eta], 3)
        .or_else(|| fit_recurrence(&[&eta], 2))
        .expect("a recurrence fits");
    let p = fit.point(wh);
    (p.rho, p.period_error)
}

fn run(scheme: Scheme, h: f64, steps: usize) -> mbs::Trajectory {
    let opts = Options {
        output: Output::Steps,
        energy: false,
        ..Options::fixed(h * steps as f64, h)
    };
    simulate(Seed2dof::default(), scheme, opts).unwrap().0
}

#[test]
fn newmark_keeps_and_generalized_alpha_damps_as_theory_says() {
    let (w, _) = seed2dof_modes();
    let periods = [2.0 * PI / w[0], 2.0 * PI / w[1]];
    // 20 steps per period of the 10 Hz mode, 5 per period of the 1 Hz mode
    for h in [periods[1] / 20.0, periods[0] / 5.0] {
        for (scheme, (am, af, beta, gamma)) in [
            (
                Scheme::Newmark(NewmarkParams::default()),
                (0.0, 0.0, 0.25, 0.5),
            ),
            (Scheme::GenAlpha(GenAlphaParams::from_rho_inf(0.8)), {
                let p = GenAlphaParams::from_rho_inf(0.8);
                (p.alpha_m, p.alpha_f, p.beta, p.gamma)
            }),
        ] {
            let tr = run(scheme, h, 120);
            for k in 0..2 {
                let wh = w[k] * h;
                let (rho_t, pe_t, _) = alpha_theory(am, af, beta, gamma, wh);
                let (rho_m, pe_m) = measured(&tr, k, 10, wh);
                println!(
                    "{:<9} h = {h:.4} mode {} (ωh = {wh:.3}): ρ theory {rho_t:.6} measured {rho_m:.6}; period error theory {pe_t:.5} measured {pe_m:.5}",
                    scheme.name(),
                    k + 1
                );
                assert!((rho_t - rho_m).abs() < 1e-3, "spectral radius");
                assert!(
                    (pe_t - pe_m).abs() < 1e-3 * (1.0 + pe_t.abs()),
                    "period error"
                );
                if matches!(scheme, Scheme::Newmark(_)) {
                    assert!(
                        (rho_m - 1.0).abs() < 1e-9,
                        "Newmark (¼, ½) keeps every amplitude"
                    );
                }
            }
            if matches!(scheme, Scheme::GenAlpha(_)) && h > periods[1] {
                // 5 steps per period of the 1 Hz mode: over one such period the 1 Hz mode
                // keeps more than 99 % of its amplitude, the under-resolved 10 Hz mode loses
                // more than a third of it
                let (rho1, _) = measured(&tr, 0, 10, w[0] * h);
                let (rho2, _) = measured(&tr, 1, 10, w[1] * h);
                assert!(
                    rho1.powi(5) > 0.99 && rho2.powi(5) < 0.66,
                    "ρ1 {rho1}, ρ2 {rho2}"
                );
            }
        }
    }
}
