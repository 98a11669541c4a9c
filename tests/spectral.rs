//! The seed course's figures for the 2-dof system: at 20 steps per period of the 10 Hz mode and
//! 5 steps per period of the 1 Hz mode, Newmark (¼, ½) keeps the amplitude of both modes, and
//! generalized-α (ρ∞ = 0.8) damps the 10 Hz mode while keeping the 1 Hz one. The spectral
//! radius and period error are measured on the simulated motion — each modal coordinate of a
//! linear system integrated by a linear scheme obeys a linear recurrence, fitted here — and
//! compared with the eigenvalues of the amplification matrix of Chung & Hulbert's equations.
#![allow(clippy::needless_range_loop)]

mod common;
#[path = "../examples/models/seed2dof.rs"]
mod seed2dof;

use common::*;
use mbs::{GenAlphaParams, NewmarkParams, Options, Output, Scheme, simulate};
use seed2dof::Seed2dof;

#[derive(Clone, Copy, Debug, PartialEq)]
struct C {
    re: f64,
    im: f64,
}

impl C {
    fn abs(self) -> f64 {
        self.re.hypot(self.im)
    }
    fn mul(self, o: C) -> C {
        C {
            re: self.re * o.re - self.im * o.im,
            im: self.re * o.im + self.im * o.re,
        }
    }
    fn sub(self, o: C) -> C {
        C {
            re: self.re - o.re,
            im: self.im - o.im,
        }
    }
    fn div(self, o: C) -> C {
        let d = o.re * o.re + o.im * o.im;
        C {
            re: (self.re * o.re + self.im * o.im) / d,
            im: (self.im * o.re - self.re * o.im) / d,
        }
    }
}

/// Roots of xⁿ + c[0] xⁿ⁻¹ + … + c[n−1] (Durand–Kerner).
fn roots(c: &[f64]) -> Vec<C> {
    let n = c.len();
    let eval = |x: C| {
        c.iter().fold(C { re: 1.0, im: 0.0 }, |acc, &k| {
            acc.mul(x).sub(C { re: -k, im: 0.0 })
        })
    };
    let mut z: Vec<C> = (0..n)
        .map(|k| {
            let a = 0.4 + 0.9 * k as f64;
            C {
                re: a.cos() * 0.9,
                im: a.sin() * 0.9,
            }
        })
        .collect();
    for _ in 0..500 {
        for i in 0..n {
            let mut den = C { re: 1.0, im: 0.0 };
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

/// The principal pair of a scheme's characteristic roots: (spectral radius, phase per step).
fn principal(rs: &[C]) -> (f64, f64) {
    let r = rs
        .iter()
        .filter(|r| r.im.abs() > 1e-12)
        .max_by(|a, b| a.abs().total_cmp(&b.abs()))
        .copied()
        .unwrap_or(rs[0]);
    (r.abs(), r.im.atan2(r.re).abs())
}

/// Theory: the amplification matrix of generalized-α (Chung & Hulbert 1993) on ẍ = −ω²x,
/// state (d, v, a): (1 − α_m) a₁ + α_m a₀ = −ω²((1 − α_f) d₁ + α_f d₀) with Newmark's
/// d₁ = d₀ + h v₀ + h²((½ − β) a₀ + β a₁), v₁ = v₀ + h((1 − γ) a₀ + γ a₁); its characteristic
/// polynomial's principal roots.
fn theory(am: f64, af: f64, beta: f64, gamma: f64, wh: f64) -> (f64, f64) {
    // with h = 1 and ω = wh: eliminate a₁ from the equilibrium
    let w2 = wh * wh;
    let den = (1.0 - am) + (1.0 - af) * w2 * beta;
    // a₁ = (−α_m a₀ − ω²((1 − α_f)(d₀ + v₀ + (½ − β) a₀) + α_f d₀)) / den
    let a1 = [
        -w2 / den,
        -(1.0 - af) * w2 / den,
        (-am - (1.0 - af) * w2 * (0.5 - beta)) / den,
    ];
    let mut m = [[0.0; 3]; 3];
    for j in 0..3 {
        let unit = |k: usize| if j == k { 1.0 } else { 0.0 };
        m[0][j] = unit(0) + unit(1) + (0.5 - beta) * unit(2) + beta * a1[j];
        m[1][j] = unit(1) + (1.0 - gamma) * unit(2) + gamma * a1[j];
        m[2][j] = a1[j];
    }
    let tr = m[0][0] + m[1][1] + m[2][2];
    let minors = m[0][0] * m[1][1] - m[0][1] * m[1][0] + m[0][0] * m[2][2] - m[0][2] * m[2][0]
        + m[1][1] * m[2][2]
        - m[1][2] * m[2][1];
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    principal(&roots(&[-tr, minors, -det]))
}

/// Least squares of x_{n+1} = c₁ x_n + … + c_k x_{n−k+1} over a sequence (Householder QR).
fn fit_recurrence(x: &[f64], k: usize) -> Option<Vec<f64>> {
    let rows = x.len() - k;
    let mut a: Vec<Vec<f64>> = (0..rows)
        .map(|r| (0..k).map(|j| x[r + k - 1 - j]).collect())
        .collect();
    let mut b: Vec<f64> = (0..rows).map(|r| x[r + k]).collect();
    let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for j in 0..k {
        let norm = (j..rows).map(|r| a[r][j] * a[r][j]).sum::<f64>().sqrt();
        if norm < 1e-9 * scale {
            return None;
        }
        let alpha = if a[j][j] > 0.0 { -norm } else { norm };
        let mut v: Vec<f64> = (j..rows).map(|r| a[r][j]).collect();
        v[0] -= alpha;
        let vn: f64 = v.iter().map(|t| t * t).sum();
        for c in j..k {
            let s: f64 = (j..rows).map(|r| v[r - j] * a[r][c]).sum::<f64>() * 2.0 / vn;
            for r in j..rows {
                a[r][c] -= s * v[r - j];
            }
        }
        let s: f64 = (j..rows).map(|r| v[r - j] * b[r]).sum::<f64>() * 2.0 / vn;
        for r in j..rows {
            b[r] -= s * v[r - j];
        }
    }
    let mut c = vec![0.0; k];
    for j in (0..k).rev() {
        c[j] = (b[j] - (j + 1..k).map(|i| a[j][i] * c[i]).sum::<f64>()) / a[j][j];
    }
    Some(c)
}

/// Measured (ρ, phase per step) of mode `k` from a trajectory sampled at every step.
fn measured(tr: &mbs::Trajectory, k: usize, skip: usize) -> (f64, f64) {
    let (_, v) = seed2dof_modes();
    let eta: Vec<f64> = (skip..tr.len())
        .map(|i| v[k][0] * tr.q(i)[0] + v[k][1] * tr.q(i)[1])
        .collect();
    let c = fit_recurrence(&eta, 3).or_else(|| fit_recurrence(&eta, 2));
    let c = c.expect("a recurrence fits");
    let poly: Vec<f64> = c.iter().map(|x| -x).collect();
    principal(&roots(&poly))
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
    let periods = [
        2.0 * std::f64::consts::PI / w[0],
        2.0 * std::f64::consts::PI / w[1],
    ];
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
                let (rho_t, psi_t) = theory(am, af, beta, gamma, wh);
                let (rho_m, psi_m) = measured(&tr, k, 10);
                let (pe_t, pe_m) = (wh / psi_t - 1.0, wh / psi_m - 1.0);
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
                let (rho1, _) = measured(&tr, 0, 10);
                let (rho2, _) = measured(&tr, 1, 10);
                assert!(
                    rho1.powi(5) > 0.99 && rho2.powi(5) < 0.66,
                    "ρ1 {rho1}, ρ2 {rho2}"
                );
            }
        }
    }
}
