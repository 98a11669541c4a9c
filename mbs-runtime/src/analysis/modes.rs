//! Poles and modes of a linearisation (EasyDyn's ComputePoles): the eigenvalues λ of A,
//! one mode per complex pair (Im λ > 0) or real eigenvalue, with natural frequency |λ|/2π,
//! damping ratio −Re λ/|λ|, the mode shape (the position part of the eigenvector, scaled so
//! that its largest component is 1) named by coordinate, and the modal mass φᴴMφ of that shape.
//! A real eigenvalue is no oscillation: [`Mode::time_constant`] gives 1/|λ|, and the table
//! ([`Modes`]' Display) shows it as a real pole, unstable or decaying, with that time constant.
//! Eigenvalues come from nalgebra's Schur decomposition of A scaled and balanced, eigenvectors from
//! inverse iteration on the balanced A.
//! First-order states ([`crate::Model::first_order_states`], the extra states of
//! [`crate::WithEfforts`]) ride as the velocities of coordinates whose positions, their
//! integrals, nothing reads: each adds an eigenvalue 0 to A that is no mode, left out here,
//! and a shape's entry for such a coordinate is the state's own amplitude.
//! For a constrained model the shapes are in the independent coordinates z of the
//! linearisation (named by [`Linearization::coordinates`], modal mass φᴴM_zφ), and also given
//! in every coordinate as N φ.

use super::AnalysisError;
use super::linearize::Linearization;
use crate::error::Failure;
use crate::linalg::{C64, Field, Lu};
use nalgebra::DMatrix;
use serde::Serialize;
use std::fmt;
use std::io::{self, Write};

/// One mode.
#[derive(Clone, Debug, Serialize)]
#[non_exhaustive]
pub struct Mode {
    /// the eigenvalue λ (1/s)
    pub re: f64,
    pub im: f64,
    /// |λ|/2π (Hz)
    pub frequency_hz: f64,
    /// −Re λ/|λ| (0 for undamped, negative for unstable oscillations, ±1 for real λ)
    pub damping_ratio: f64,
    /// φᴴ M φ for the shape below (φᴴ M_z φ with constraints)
    pub modal_mass: f64,
    /// shape: per coordinate of [`Modes::dof_names`], (real, imaginary) parts, largest
    /// magnitude 1
    pub shape: Vec<(f64, f64)>,
    /// the same shape in every coordinate q (N φ; equal to `shape` without constraints),
    /// named by the linearisation's `dof_names`
    pub shape_q: Vec<(f64, f64)>,
}

/// The modes of a linearised model, sorted by frequency.
#[derive(Clone, Debug, Serialize)]
pub struct Modes {
    /// names of the coordinates of the shapes: the linearisation's `coordinates` (the
    /// independent ones of a constrained model)
    pub dof_names: Vec<String>,
    pub modes: Vec<Mode>,
    /// the threshold, relative to A's largest entry, below which the Schur decomposition set
    /// a subdiagonal entry to zero: ε, or a looser one where its QR iteration could not
    /// reach ε (several zero eigenvalues beside large ones: a free body's rigid motions); the
    /// eigenvalues are those of a matrix within about this much of A's largest entry, and a
    /// repeated eigenvalue is split by about the square root of it
    pub deflation: f64,
}

/// The deflation thresholds tried, in turn, relative to the largest entry of A (see
/// [`eigenvalues`]).
const DEFLATIONS: [f64; 6] = [f64::EPSILON, 1e-14, 1e-13, 1e-12, 1e-11, 1e-10];

/// The eigenvalues of A from its Schur form, and the deflation threshold that found them.
/// nalgebra's QR iteration can cycle on matrices of exact structure (seen on the sleeping
/// top's: zeros and equal entries where the exceptional shifts never break the tie) and
/// `complex_eigenvalues` iterates without bound; here the iterations are bounded, and a
/// matrix the iteration cannot reduce is tried again after a similarity by a fixed
/// Householder reflection (same eigenvalues, no structure). Its test deflates a subdiagonal
/// entry below ε times its two diagonal neighbours, or below ε² of A's largest entry: beside
/// several zero eigenvalues, whose diagonal entries are zero, only the second, which the
/// rounding of a large A never reaches (the hexapod released above the ground: six rigid
/// motions without stiffness or damping, twelve zero eigenvalues in Jordan blocks, beside
/// entries of A up to 4.4·10⁴/s²). Both matrices are then tried at the looser
/// thresholds of [`DEFLATIONS`]: an entry below one of them, relative to its neighbours, is
/// set to zero, and the eigenvalues are those of a matrix within about that much of A's
/// largest entry; the threshold used is returned ([`Modes::deflation`]). Past the last, an
/// error rather than a hang.
fn eigenvalues(
    balanced: &DMatrix<f64>,
    a: &DMatrix<f64>,
) -> Result<(Vec<nalgebra::Complex<f64>>, f64), AnalysisError> {
    let n = a.nrows();
    let schur = |m: &DMatrix<f64>, eps| nalgebra::linalg::Schur::try_new(m.clone(), eps, 200 * n);
    let v = nalgebra::DVector::from_fn(n, |i, _| 1.0 + (i as f64 * 0.618_034).fract());
    let h = DMatrix::identity(n, n) - (&v * v.transpose()) * (2.0 / v.norm_squared());
    // the balanced matrix first, then A itself: balancing can give the iteration a structure
    // it cycles on (the top on a 40 km rod)
    let tried = [balanced.clone(), &h * balanced * &h, a.clone(), &h * a * &h];
    for eps in DEFLATIONS {
        if let Some(s) = tried.iter().find_map(|m| schur(m, eps)) {
            return Ok((block_eigenvalues(&s.unpack().1), eps));
        }
    }
    Err(AnalysisError::EigenvaluesNotFound {
        matrix: "A",
        size: n,
        deflation: DEFLATIONS[DEFLATIONS.len() - 1],
    })
}

/// The eigenvalues of a real Schur form T: its 1 × 1 blocks, and each 2 × 2 block's pair.
/// nalgebra's `complex_eigenvalues` takes every 2 × 2 block for a complex pair and gave NaN
/// for a block whose pair is real, which its QR iteration leaves where it deflates such a
/// block undivided (the top on a 40 km rod: A's entries of 1e-4 and 1e-11, a real pair near
/// zero); here the discriminant decides.
fn block_eigenvalues(t: &DMatrix<f64>) -> Vec<nalgebra::Complex<f64>> {
    let n = t.nrows();
    let mut out = Vec::with_capacity(n);
    let mut m = 0;
    while m < n {
        if m + 1 == n || t[(m + 1, m)] == 0.0 {
            out.push(nalgebra::Complex::new(t[(m, m)], 0.0));
            m += 1;
            continue;
        }
        let (a, b, c, d) = (t[(m, m)], t[(m, m + 1)], t[(m + 1, m)], t[(m + 1, m + 1)]);
        let half_trace = 0.5 * (a + d);
        let half_diff = 0.5 * (a - d);
        let discriminant = half_diff * half_diff + b * c;
        if discriminant >= 0.0 {
            // real: the larger root from the sum without cancellation, the other from the
            // determinant's product (a d − b c = λ₁ λ₂)
            let root = discriminant.sqrt();
            let big = half_trace + root.copysign(half_trace);
            let det = a * d - b * c;
            let small = if big != 0.0 {
                det / big
            } else {
                half_trace - root
            };
            out.push(nalgebra::Complex::new(big, 0.0));
            out.push(nalgebra::Complex::new(small, 0.0));
        } else {
            let im = (-discriminant).sqrt();
            out.push(nalgebra::Complex::new(half_trace, im));
            out.push(nalgebra::Complex::new(half_trace, -im));
        }
        m += 2;
    }
    out
}

/// Computes the modes of `lin` whose frequency is within `window` (Hz, inclusive), or all.
pub fn modes(lin: &Linearization, window: Option<(f64, f64)>) -> Result<Modes, AnalysisError> {
    if let Some((lo, hi)) = window
        && !(lo <= hi && !lo.is_nan() && !hi.is_nan())
    {
        return Err(Failure::InvalidOption {
            name: "window",
            value: format!("({lo}, {hi}) Hz"),
            reason: "must be (low, high) with low ≤ high, neither NaN (an infinite bound: no limit)",
        }
        .into());
    }
    let n2 = lin.a.nrows();
    let n = n2 / 2;
    if lin.a.iter().any(|x| !x.is_finite()) {
        return Err(Failure::NonFinite {
            quantity: "A",
            coordinate: String::new(),
            cause: String::new(),
        }
        .into());
    }
    if n2 == 0 {
        // no degree of freedom (every coordinate fixed by the constraints)
        return Ok(Modes {
            dof_names: lin.coordinates.clone(),
            modes: Vec::new(),
            deflation: f64::EPSILON,
        });
    }
    // the integrals of first-order states are read by nothing: their columns of A are zero
    // and each adds an eigenvalue 0 that is no mode; A without them (`kept` of its states)
    // has the others
    let kept: Vec<usize> = (0..n2).filter(|i| !lin.first_order.contains(i)).collect();
    let a = lin.a.select_rows(&kept).select_columns(&kept);
    let m2 = kept.len();
    // the eigenvalues and shapes are found on A scaled by a power of two to a largest entry
    // in [1, 2) (exactly: the same digits), λ scaled back: entries near 1e300 overflowed in
    // the factorisation and the discriminants, and the Schur form's absolute deflation test
    // (ε² of the scaled entries) is then relative to A's largest entry
    let largest = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let scale = largest.max(1.0);
    let unit = if largest > 0.0 {
        largest.log2().floor().exp2()
    } else {
        1.0
    };
    let a = a / unit;
    let mut balanced = a.clone();
    // balanced (Parlett–Reinsch, by powers of two: D⁻¹ A D, the same eigenvalues, the
    // eigenvectors D w), as LAPACK's dgeev does: a first-order A whose entries span many
    // decades is far from normal, and its eigenvectors by inverse iteration far less
    // accurate than the matrix (the top spun at 2e6 rad/s: K/M of 2e10 beside the identity's
    // 1, a slow pole's shape 9 % off, its components of 3e-5 of the wrong sign)
    let balance = nalgebra::linalg::balancing::balance_parlett_reinsch(&mut balanced);
    let (mut eig, deflation) = eigenvalues(&balanced, &a)?;
    let balanced_scale = unit * balanced.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for l in eig.iter_mut() {
        *l *= unit;
    }
    // A repeated zero eigenvalue (a free body's rigid motions: Jordan blocks, no stiffness and
    // no damping) comes out split by the rounding into a cluster of radius up to about
    // √(deflation·max|A|), as real pairs ±x that the table would call unstable and decaying
    // with time constants of months (the hexapod in the air: ±1.7e-7/s). Where two or more
    // eigenvalues lie within ten times that of zero they are that zero, and are set to it.
    let zero_within = 10.0 * (deflation * scale).sqrt();
    if eig.iter().filter(|l| l.norm() <= zero_within).count() >= 2 {
        for l in eig.iter_mut().filter(|l| l.norm() <= zero_within) {
            *l = nalgebra::Complex::new(0.0, 0.0);
        }
    }
    let mut out = Vec::new();
    let mut lu = Lu::<C64>::new(m2);
    for (k, lambda) in eig.iter().enumerate() {
        // A pair is real where its imaginary part is within what rounding splits a double
        // real eigenvalue into: ±√(δ γ) for a perturbation δ ≈ ε max|A| of a Jordan block
        // of coupling γ ≈ |λ| (at least 1/s), here ten times that. The threshold was 1e-12
        // of max|A|, which beside a stiff spring (max|A| = 1e13/s²) was 10 rad/s: a mode of
        // 1 rad/s was listed as two real poles.
        // (ε being the deflation threshold the eigenvalues were found with). Eigenvalues
        // within this of each other are one repeated eigenvalue, split by the rounding.
        let real_within = 10.0 * (deflation * scale * lambda.norm().max(1.0)).sqrt();
        // one mode per conjugate pair
        if lambda.im < -real_within {
            continue;
        }
        let (re, im) = (
            lambda.re,
            if lambda.im <= real_within {
                0.0
            } else {
                lambda.im
            },
        );
        let mag = re.hypot(im);
        let frequency_hz = mag / (2.0 * std::f64::consts::PI);
        if let Some((lo, hi)) = window {
            if frequency_hz < lo || frequency_hz > hi {
                continue;
            }
        }
        // inverse iteration on A − μI, μ a hair off λ: by a part in 10⁹ of λ, or by what the
        // rounding of λ may be (1000 ε of the balanced A's largest entry), not by a part in 10⁹ of that
        // entry: beside a stiff mode (a gear of 1e10/s²) that shift was 10/s, and a mode at
        // 1/s converged to its neighbour at 1.2/s, or to neither
        let shift = (1e-9 * mag).max(1e3 * f64::EPSILON * balanced_scale);
        let mu = C64::new(re + shift, im + shift);
        let mu_unit = C64::new(mu.re / unit, mu.im / unit);
        // A − μI nearly singular is what inverse iteration wants: its pivots below ε‖A‖ are
        // raised to that (as EISPACK's INVIT does) rather than refused. A slow mode beside a
        // fast one (the top spun at 2e6 rad/s: its poles of 4.4/s and nutation at
        // 4.7e5/s) leaves a pivot near |λ − μ|, far below nε‖A‖; refused, the shift was moved
        // off until another eigenvalue was as near, and the mode had no shape
        let f = lu.matrix_mut();
        for j in 0..m2 {
            for i in 0..m2 {
                let d = if i == j { mu_unit } else { C64::default() };
                f[i + m2 * j] = C64::new(balanced[(i, j)], 0.0) - d;
            }
        }
        lu.factor_for_inverse_iteration()
            .map_err(|_| -> AnalysisError {
                Failure::NonFinite {
                    quantity: "A − μI (a mode's shape by inverse iteration; its entries overflow)",
                    coordinate: String::new(),
                    cause: String::new(),
                }
                .into()
            })?;
        // each iteration leaves r = |λ − μ| / |λ' − μ| of the nearest other eigenvalue λ':
        // iterated until r^k is below rounding (at least three, at most 100: a repeated
        // eigenvalue, r ≈ 1, keeps the start's mix of its eigenvectors, a valid one)
        let nearest = (eig.iter().enumerate())
            .filter(|&(j, o)| j != k && (o - lambda).norm() > real_within)
            .map(|(_, o)| (C64::new(o.re, o.im) - mu).abs())
            .fold(f64::INFINITY, f64::min);
        let r = (C64::new(re, im) - mu).abs() / nearest;
        let iterations = super::inverse_iterations(r, 100);
        // the start differs from mode to mode, so that two modes of one repeated eigenvalue
        // get two of its eigenvectors, not one twice
        let mut w: Vec<C64> = (0..m2)
            .map(|i| {
                let turn = 0.7 * ((i + 1) * (k + 1)) as f64;
                C64::new(1.0 + 0.1 * i as f64 + 0.3 * turn.sin(), 0.05 * i as f64)
            })
            .collect();
        // then on until the vector, scaled by its largest component, stops changing: r
        // leaves out eigenvalues within `real_within`, which it takes for one repeated
        // eigenvalue, and where they are split (the hexapod's legs: −1037.9261/s twice beside
        // −1037.9278/s) three iterations left a mix of their vectors (a residual of 2e-10)
        let mut previous = w.clone();
        for done in 1..=100 {
            lu.solve(&mut w);
            let big = (0..m2)
                .max_by(|&i, &j| w[i].abs().total_cmp(&w[j].abs()))
                .unwrap_or(0);
            let pivot = w[big];
            if !(pivot.abs() > 0.0) || !pivot.abs().is_finite() {
                break;
            }
            let mut change = 0.0f64;
            for (z, p) in w.iter_mut().zip(previous.iter_mut()) {
                *z = *z / pivot;
                change = change.max((*z - *p).abs());
                *p = *z;
            }
            if done >= iterations && change <= 1e-14 {
                break;
            }
        }
        // the whole state, a first-order state's position entry its own amplitude δx (the
        // velocity entry n + i) rather than its integral's
        let mut v = vec![C64::default(); n2];
        for (r, &i) in kept.iter().enumerate() {
            v[i] = w[r] * C64::new(balance[r], 0.0);
        }
        for &i in &lin.first_order {
            v[i] = v[n + i];
        }
        // the q part, scaled to a largest component of 1 (real, positive)
        let big = (0..n)
            .max_by(|&i, &j| v[i].abs().total_cmp(&v[j].abs()))
            .unwrap_or(0);
        let pivot = v[big];
        let shape: Vec<C64> = (0..n)
            .map(|i| {
                if pivot.abs() > 0.0 {
                    v[i] / pivot
                } else {
                    v[i]
                }
            })
            .collect();
        let mut modal_mass = 0.0;
        for i in 0..n {
            for j in 0..n {
                let p =
                    C64::new(shape[i].re, -shape[i].im) * C64::new(lin.mz[(i, j)], 0.0) * shape[j];
                modal_mass += p.re;
            }
        }
        let damping_ratio = if mag > 0.0 { -re / mag } else { 0.0 };
        let shape_q = (0..lin.basis.nrows())
            .map(|i| {
                (0..n).fold((0.0, 0.0), |(re, im), k| {
                    let w = lin.basis[(i, k)];
                    (re + w * shape[k].re, im + w * shape[k].im)
                })
            })
            .collect();
        out.push(Mode {
            re,
            im,
            frequency_hz,
            damping_ratio,
            modal_mass,
            shape: shape.iter().map(|z| (z.re, z.im)).collect(),
            shape_q,
        });
    }
    out.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    Ok(Modes {
        dof_names: lin.coordinates.clone(),
        modes: out,
        deflation,
    })
}

impl Modes {
    /// Frequencies (Hz) in ascending order.
    pub fn frequencies(&self) -> Vec<f64> {
        self.modes.iter().map(|m| m.frequency_hz).collect()
    }

    /// One row per mode: frequency, damping ratio, eigenvalue, modal mass, then the shape
    /// (real and imaginary parts per coordinate).
    pub fn write_csv(&self, mut w: impl Write) -> io::Result<()> {
        let mut header = vec![
            "frequency_hz".to_string(),
            "damping_ratio".into(),
            "re".into(),
            "im".into(),
            "modal_mass".into(),
        ];
        for n in &self.dof_names {
            header.push(format!("{n}.re"));
            header.push(format!("{n}.im"));
        }
        writeln!(w, "{}", header.join(","))?;
        for m in &self.modes {
            write!(
                w,
                "{:e},{:e},{:e},{:e},{:e}",
                m.frequency_hz, m.damping_ratio, m.re, m.im, m.modal_mass
            )?;
            for (re, im) in &m.shape {
                write!(w, ",{re:e},{im:e}")?;
            }
            writeln!(w)?;
        }
        Ok(())
    }
}

impl Mode {
    /// Whether λ is real: a pole that does not oscillate, which grows or decays as e^(λt).
    /// Its `frequency_hz` (|λ|/2π) is then no frequency of any motion, and `damping_ratio` is
    /// ±1 by definition; [`Mode::time_constant`] says more.
    pub fn is_real(&self) -> bool {
        self.im == 0.0
    }

    /// 1/|λ| (s) of a real pole: the time in which the motion grows (λ > 0, unstable) or
    /// decays (λ < 0) by the factor e; `None` for an oscillating mode and for λ = 0.
    pub fn time_constant(&self) -> Option<f64> {
        (self.is_real() && self.re != 0.0).then(|| 1.0 / self.re.abs())
    }
}

/// Below this |λ| (1/s) a real pole is shown as zero (a time constant above 30 years).
const ZERO_POLE: f64 = 1e-9;

impl fmt::Display for Modes {
    /// A pole list like EasyDyn's: one line per mode, then its shape by coordinate. A real pole
    /// has no frequency and no damping ratio to speak of: its line says whether it grows or
    /// decays, and its time constant.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{:>4} {:>14} {:>12} {:>14} {:>14} {:>12}",
            "mode", "frequency Hz", "damping", "Re λ (1/s)", "Im λ (1/s)", "modal mass"
        )?;
        for (k, m) in self.modes.iter().enumerate() {
            if m.is_real() {
                let what = if m.re.abs() < ZERO_POLE {
                    "real pole λ ≈ 0: neutral, no restoring force".to_string()
                } else {
                    format!(
                        "real pole {:+.3} s⁻¹, {}, time constant {:.3} s",
                        m.re,
                        if m.re > 0.0 { "unstable" } else { "decaying" },
                        1.0 / m.re.abs()
                    )
                };
                writeln!(
                    f,
                    "{:>4} {:>14} {:>12} {:>14.6e} {:>14.6e} {:>12.4e}   {what}",
                    k + 1,
                    "-",
                    "-",
                    m.re,
                    m.im,
                    m.modal_mass
                )?;
            } else {
                writeln!(
                    f,
                    "{:>4} {:>14.6} {:>12.4e} {:>14.6e} {:>14.6e} {:>12.4e}",
                    k + 1,
                    m.frequency_hz,
                    m.damping_ratio,
                    m.re,
                    m.im,
                    m.modal_mass
                )?;
            }
            let parts: Vec<String> = self
                .dof_names
                .iter()
                .zip(&m.shape)
                .map(|(n, (re, im))| {
                    if im.abs() < 1e-9 {
                        format!("{n} {re:+.4}")
                    } else {
                        format!("{n} {re:+.4}{im:+.4}i")
                    }
                })
                .collect();
            writeln!(f, "     shape: {}", parts.join(", "))?;
        }
        if self.deflation > f64::EPSILON {
            writeln!(
                f,
                "(eigenvalues found deflating at {:.0e} of max|A|, where the QR iteration stalled at ε: they are those of a matrix within about that much of A)",
                self.deflation
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mode(re: f64, im: f64) -> Mode {
        let mag = re.hypot(im);
        Mode {
            re,
            im,
            frequency_hz: mag / (2.0 * std::f64::consts::PI),
            damping_ratio: -re / mag,
            modal_mass: 1.0,
            shape: vec![(1.0, 0.0)],
            shape_q: vec![(1.0, 0.0)],
        }
    }

    #[test]
    fn real_poles_are_shown_with_their_time_constant() {
        let modes = Modes {
            dof_names: vec!["a".into()],
            modes: vec![
                mode(-0.5, 6.0),
                mode(5.62, 0.0),
                mode(-2.0, 0.0),
                mode(0.0, 0.0),
            ],
            deflation: f64::EPSILON,
        };
        let table = modes.to_string();
        print!("{table}");
        let rows: Vec<&str> = table.lines().filter(|l| !l.contains("shape:")).collect();
        assert_eq!(rows.len(), 5);
        // an oscillation: frequency and damping ratio
        assert!(
            rows[1].contains("0.958") && rows[1].contains("8.3045e-2"),
            "{}",
            rows[1]
        );
        assert!(!rows[1].contains("real pole"));
        // real poles: no frequency, no damping ratio of ±1
        assert!(
            rows[2].ends_with("real pole +5.620 s⁻¹, unstable, time constant 0.178 s"),
            "{}",
            rows[2]
        );
        assert!(!rows[2].contains("0.894") && !rows[2].contains("-1.0000e0"));
        assert!(
            rows[3].ends_with("real pole -2.000 s⁻¹, decaying, time constant 0.500 s"),
            "{}",
            rows[3]
        );
        assert!(rows[4].ends_with("real pole λ ≈ 0: neutral, no restoring force"));
        assert_eq!(modes.modes[1].time_constant(), Some(1.0 / 5.62));
        assert_eq!(modes.modes[0].time_constant(), None);
        assert_eq!(modes.modes[3].time_constant(), None);
    }

    /// A 2 × 2 block of a Schur form whose pair is real (left undivided by the iteration) gives
    /// its two real eigenvalues, a complex block its conjugate pair, 1 × 1 blocks themselves.
    #[test]
    fn a_schur_block_with_a_real_pair_gives_real_eigenvalues() {
        let t = DMatrix::from_row_slice(
            5,
            5,
            &[
                2.0, 1.0, 0.3, 0.0, 0.1, //
                4.0, 2.0, 0.2, 0.5, 0.0, //
                0.0, 0.0, -1.0, 3.0, 0.0, //
                0.0, 0.0, -3.0, -1.0, 0.0, //
                0.0, 0.0, 0.0, 0.0, 7.0,
            ],
        );
        let got = block_eigenvalues(&t);
        let want = [
            (4.0, 0.0),
            (0.0, 0.0),
            (-1.0, 3.0),
            (-1.0, -3.0),
            (7.0, 0.0),
        ];
        assert_eq!(got.len(), want.len());
        for (g, (re, im)) in got.iter().zip(want) {
            assert!(
                (g.re - re).abs() < 1e-15 && (g.im - im).abs() < 1e-15,
                "{g} against {re} {im}"
            );
        }
        // a tiny real pair beside rounding: the smaller root from the determinant, not lost
        // to cancellation
        let t = DMatrix::from_row_slice(2, 2, &[1.0, 1e-10, 1e-10, 0.0]);
        let got = block_eigenvalues(&t);
        assert!((got[0].re - 1.0).abs() < 1e-15 && got[0].im == 0.0);
        assert!(
            (got[1].re + 1e-20).abs() < 1e-30 && got[1].im == 0.0,
            "{}",
            got[1]
        );
    }
}
