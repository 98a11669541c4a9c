//! Dense factorisations on caller-owned, column-major buffers (`a[i + n*j]`), allocation-free
//! once built: Cholesky for mass matrices, LU with partial pivoting for iteration matrices,
//! and a complex LU for the complex eigen-blocks of Radau. nalgebra's dynamic LU allocates its
//! permutation at every factorisation, and none reports which coordinate made a matrix
//! singular; these do, with a condition estimate (Hager–Higham 1-norm estimator).
//!
//! # Panics
//!
//! Every function here indexes its slices as the sizes it is given say: a matrix shorter
//! than n·n, or a vector shorter than n, panics as a slice indexed beyond its end does
//! (the runtime sizes them from the model's constants once; these functions are its inner
//! loops, which check nothing more).

use std::ops::{Add, Div, Mul, Neg, Sub};

/// Why a factorisation failed: the pivot column (a coordinate index) and an estimate of the
/// reciprocal condition number in the 1-norm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Singular {
    pub column: usize,
    pub rcond: f64,
}

/// 1-norm of a column-major n × n matrix.
pub fn norm1(a: &[f64], n: usize) -> f64 {
    (0..n)
        .map(|j| a[j * n..(j + 1) * n].iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// The smallest pivot a factorisation of M accepts, relative to the largest diagonal entry
/// (Cholesky) or pivot (forward dynamics): below it M is taken as singular.
pub const PIVOT_FLOOR: f64 = 1e-14;

/// Cholesky factor L (lower triangle of `a`, overwritten) of a symmetric positive definite
/// matrix. Only the lower triangle of `a` is read.
pub fn cholesky(a: &mut [f64], n: usize) -> Result<(), Singular> {
    let scale = (0..n).map(|i| a[i + n * i].abs()).fold(0.0, f64::max);
    for j in 0..n {
        let mut d = a[j + n * j];
        for k in 0..j {
            d -= a[j + n * k] * a[j + n * k];
        }
        if !(d > PIVOT_FLOOR * scale) || !d.is_finite() {
            let rcond = if scale > 0.0 {
                (d.max(0.0) / scale).sqrt()
            } else {
                0.0
            };
            return Err(Singular { column: j, rcond });
        }
        let d = d.sqrt();
        a[j + n * j] = d;
        for i in j + 1..n {
            let mut s = a[i + n * j];
            for k in 0..j {
                s -= a[i + n * k] * a[j + n * k];
            }
            a[i + n * j] = s / d;
        }
    }
    Ok(())
}

/// Solves L Lᵀ x = b in place, with L from [`cholesky`].
pub fn cholesky_solve(l: &[f64], n: usize, b: &mut [f64]) {
    forward(l, n, b);
    backward(l, n, b);
}

/// What a forward-dynamics solve by a dense factorisation gives: `x` ← L⁻ᵀL⁻¹x and the pivots
/// L_jj² (n of each) when the factorisation `l` succeeded (`ok`), else NaN and zeros.
pub fn solve_with_pivots(l: &[f64], n: usize, ok: bool, x: &mut [f64], pivots: &mut [f64]) {
    for (j, p) in pivots.iter_mut().enumerate() {
        *p = if ok { l[j + n * j] * l[j + n * j] } else { 0.0 };
    }
    if ok {
        cholesky_solve(l, n, x);
    } else {
        x.fill(f64::NAN);
    }
}

/// Solves L y = b in place (L lower triangular, from [`cholesky`]).
pub fn forward(l: &[f64], n: usize, b: &mut [f64]) {
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i + n * k] * b[k];
        }
        b[i] = s / l[i + n * i];
    }
}

/// Solves Lᵀ x = b in place (L from [`cholesky`]).
pub fn backward(l: &[f64], n: usize, b: &mut [f64]) {
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= l[k + n * i] * b[k];
        }
        b[i] = s / l[i + n * i];
    }
}

/// The scalar fields the LU runs over: f64 and [`C64`].
pub trait Field:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Default
{
    fn abs(self) -> f64;
    fn from_f64(x: f64) -> Self;
    /// A size ordered as [`Field::abs`] is, cheaper to compute: the pivots' search compares
    /// these (a complex number's squared modulus, where its modulus takes a `hypot`).
    fn pivot_size(self) -> f64 {
        self.abs()
    }
    /// |re| + |im| for a complex number, within a factor √2 of its modulus: the matrix norm
    /// the singular-pivot threshold is measured against.
    fn norm1(self) -> f64 {
        self.abs()
    }
    /// Whether the number is exactly zero.
    fn is_zero(self) -> bool;
}

impl Field for f64 {
    fn abs(self) -> f64 {
        f64::abs(self)
    }
    fn from_f64(x: f64) -> Self {
        x
    }
    fn is_zero(self) -> bool {
        self == 0.0
    }
}

/// A complex number, just what the LU needs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct C64 {
    pub re: f64,
    pub im: f64,
}

impl C64 {
    pub fn new(re: f64, im: f64) -> C64 {
        C64 { re, im }
    }
}

impl Add for C64 {
    type Output = C64;
    fn add(self, o: C64) -> C64 {
        C64::new(self.re + o.re, self.im + o.im)
    }
}

impl Sub for C64 {
    type Output = C64;
    fn sub(self, o: C64) -> C64 {
        C64::new(self.re - o.re, self.im - o.im)
    }
}

impl Mul for C64 {
    type Output = C64;
    fn mul(self, o: C64) -> C64 {
        C64::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
}

impl Div for C64 {
    type Output = C64;
    fn div(self, o: C64) -> C64 {
        let d = o.re * o.re + o.im * o.im;
        C64::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
}

impl Neg for C64 {
    type Output = C64;
    fn neg(self) -> C64 {
        C64::new(-self.re, -self.im)
    }
}

impl Field for C64 {
    fn abs(self) -> f64 {
        self.re.hypot(self.im)
    }
    fn from_f64(x: f64) -> Self {
        C64::new(x, 0.0)
    }
    fn pivot_size(self) -> f64 {
        self.re * self.re + self.im * self.im
    }
    fn norm1(self) -> f64 {
        self.re.abs() + self.im.abs()
    }
    fn is_zero(self) -> bool {
        self.re == 0.0 && self.im == 0.0
    }
}

/// An LU factorisation with partial pivoting, P A = L U, kept in its own buffers; after
/// [`Lu::factor_equilibrating`] possibly of R A C, R and C diagonal.
#[derive(Clone, Debug)]
pub struct Lu<T: Field> {
    n: usize,
    lu: Vec<T>,
    piv: Vec<usize>,
    /// scratch for the condition estimate
    work: Vec<T>,
    work2: Vec<T>,
    /// [`Lu::factor_equilibrating`]: the matrix as given, and the row and column scales (powers
    /// of two) of the factorisation when it is of R A C (empty when of A)
    given: Vec<T>,
    rows: Vec<f64>,
    cols: Vec<f64>,
}

impl<T: Field> Lu<T> {
    /// Buffers for n × n matrices (the only allocation).
    pub fn new(n: usize) -> Lu<T> {
        Lu {
            n,
            lu: vec![T::default(); n * n],
            piv: vec![0; n],
            work: vec![T::default(); n],
            work2: vec![T::default(); n],
            given: Vec::new(),
            rows: Vec::new(),
            cols: Vec::new(),
        }
    }

    /// The buffer to fill with the matrix (column-major) before [`Lu::factor`].
    pub fn matrix_mut(&mut self) -> &mut [T] {
        &mut self.lu
    }

    /// Factorises the matrix in [`Lu::matrix_mut`]. On failure, the column whose pivot
    /// vanished and a condition estimate.
    pub fn factor(&mut self) -> Result<(), Singular> {
        self.rows.clear();
        self.cols.clear();
        self.factor_with(None).map(|_| ())
    }

    /// [`Lu::factor`], and where a pivot falls below nε‖A‖₁ the factorisation of R A C
    /// instead, R scaling each row's largest entry and then C each column's to [½, 1] by powers
    /// of two (exact, as LAPACK's xGEEQUB chooses them), refused only if a pivot of R A C falls
    /// below nε‖R A C‖₁. The pivot test against the whole matrix's norm reads a matrix whose
    /// blocks come in different units as singular: a loop's iteration matrix
    /// [M + γ'C + β'K, −Bᵀ; B, 0] 10⁶ times larger, its M block ~4·10¹⁶ beside B's 4·10⁵, has a
    /// pivot BM⁻¹Bᵀ ~ 2·10⁻⁶ in the constraints' rows, 6·10⁻²³ of ‖A‖₁. Where A's own pivots
    /// pass, the result is [`Lu::factor`]'s, bit for bit (A is kept to try again: one copy of
    /// it per factorisation, and the memory for it).
    pub fn factor_equilibrating(&mut self) -> Result<(), Singular> {
        // the first call reserves what a retry needs: no allocation in later ones
        self.given.clear();
        self.given.extend_from_slice(&self.lu);
        self.rows.reserve(self.n);
        self.cols.reserve(self.n);
        match self.factor() {
            Err(_) => {
                let n = self.n;
                self.lu.copy_from_slice(&self.given);
                let pow2 = |largest: f64| match largest > 0.0 && largest.is_finite() {
                    // 2^-e with 2^(e-1) ≤ largest < 2^e
                    true => 2f64.powi(-(largest.log2().floor() as i32 + 1)),
                    false => 1.0,
                };
                let a = &mut self.lu;
                self.rows.clear();
                self.rows.extend(
                    (0..n).map(|i| pow2((0..n).map(|j| a[i + n * j].abs()).fold(0.0, f64::max))),
                );
                for j in 0..n {
                    for i in 0..n {
                        a[i + n * j] = a[i + n * j] * T::from_f64(self.rows[i]);
                    }
                }
                self.cols.clear();
                self.cols.extend((0..n).map(|j| {
                    pow2(
                        a[j * n..(j + 1) * n]
                            .iter()
                            .map(|x| x.abs())
                            .fold(0.0, f64::max),
                    )
                }));
                for j in 0..n {
                    let c = T::from_f64(self.cols[j]);
                    for x in &mut a[j * n..(j + 1) * n] {
                        *x = *x * c;
                    }
                }
                let scaled = self.factor_with(None).map(|_| ());
                if scaled.is_err() {
                    self.rows.clear();
                    self.cols.clear();
                }
                scaled
            }
            ok => ok,
        }
    }

    /// Factorises the matrix in [`Lu::matrix_mut`] for inverse iteration, where a matrix
    /// A − μI nearly singular is what is wanted: a pivot smaller than ε‖A‖₁ is replaced by
    /// ε‖A‖₁ (in its own direction; EISPACK's INVIT does so with its ε₃), so that a solve
    /// grows the component of the eigenvector by about 1/ε rather than failing. Returns the
    /// number of pivots replaced. Fails only where the matrix is not finite.
    pub fn factor_for_inverse_iteration(&mut self) -> Result<usize, Singular> {
        self.rows.clear();
        self.cols.clear();
        self.factor_with(Some(f64::EPSILON))
    }

    /// The factorisation: `floor` None refuses a pivot below nε‖A‖₁; Some(f) replaces a
    /// pivot below f‖A‖₁ by f‖A‖₁ and counts it.
    fn factor_with(&mut self, floor: Option<f64>) -> Result<usize, Singular> {
        let n = self.n;
        let mut replaced = 0;
        let a = &mut self.lu;
        let anorm = (0..n)
            .map(|j| a[j * n..(j + 1) * n].iter().map(|x| x.norm1()).sum::<f64>())
            .fold(0.0, f64::max);
        for k in 0..n {
            let (mut p, mut size) = (k, a[k + n * k].pivot_size());
            for i in k + 1..n {
                let v = a[i + n * k].pivot_size();
                if v > size {
                    size = v;
                    p = i;
                }
            }
            self.piv[k] = p;
            let best = a[p + n * k].abs();
            let refused = floor.is_none() && !(best > f64::EPSILON * anorm * n as f64);
            if refused || !best.is_finite() || !anorm.is_finite() {
                let rcond = if anorm > 0.0 { best / anorm } else { 0.0 };
                return Err(Singular { column: k, rcond });
            }
            if p != k {
                for j in 0..n {
                    a.swap(k + n * j, p + n * j);
                }
            }
            if let Some(f) = floor {
                let least = (f * anorm).max(f64::MIN_POSITIVE);
                if best < least {
                    let d = a[k + n * k];
                    a[k + n * k] = if best > 0.0 {
                        d * T::from_f64(least / best)
                    } else {
                        T::from_f64(least)
                    };
                    replaced += 1;
                }
            }
            let d = a[k + n * k];
            for i in k + 1..n {
                a[i + n * k] = a[i + n * k] / d;
            }
            for j in k + 1..n {
                let akj = a[k + n * j];
                if akj.is_zero() {
                    continue;
                }
                for i in k + 1..n {
                    a[i + n * j] = a[i + n * j] - a[i + n * k] * akj;
                }
            }
        }
        Ok(replaced)
    }

    /// Solves A x = b in place.
    pub fn solve(&self, b: &mut [T]) {
        let n = self.n;
        let a = &self.lu;
        // (R A C)⁻¹ = C⁻¹ A⁻¹ R⁻¹: A⁻¹ b = C (R A C)⁻¹ R b
        for (x, r) in b.iter_mut().zip(&self.rows) {
            *x = *x * T::from_f64(*r);
        }
        for k in 0..n {
            b.swap(k, self.piv[k]);
        }
        for i in 0..n {
            let mut s = b[i];
            for k in 0..i {
                s = s - a[i + n * k] * b[k];
            }
            b[i] = s;
        }
        for i in (0..n).rev() {
            let mut s = b[i];
            for k in i + 1..n {
                s = s - a[i + n * k] * b[k];
            }
            b[i] = s / a[i + n * i];
        }
        for (x, c) in b.iter_mut().zip(&self.cols) {
            *x = *x * T::from_f64(*c);
        }
    }

    /// Solves Aᵀ x = b in place (for the condition estimate).
    fn solve_transpose(&self, b: &mut [T]) {
        let n = self.n;
        let a = &self.lu;
        // A⁻ᵀ b = R (R A C)⁻ᵀ C b
        for (x, c) in b.iter_mut().zip(&self.cols) {
            *x = *x * T::from_f64(*c);
        }
        for i in 0..n {
            let mut s = b[i];
            for k in 0..i {
                s = s - a[k + n * i] * b[k];
            }
            b[i] = s / a[i + n * i];
        }
        for i in (0..n).rev() {
            let mut s = b[i];
            for k in i + 1..n {
                s = s - a[k + n * i] * b[k];
            }
            b[i] = s;
        }
        for k in (0..n).rev() {
            b.swap(k, self.piv[k]);
        }
        for (x, r) in b.iter_mut().zip(&self.rows) {
            *x = *x * T::from_f64(*r);
        }
    }

    /// Estimate of ‖A⁻¹‖₁ (Hager 1984, Higham 1988) after a successful factorisation, and
    /// the index of the largest component of the vector that attains it: the direction in
    /// which A is nearest to singular.
    pub fn inverse_norm_estimate(&mut self) -> (f64, usize) {
        let n = self.n;
        if n == 0 {
            return (0.0, 0);
        }
        let mut x = std::mem::take(&mut self.work);
        let mut z = std::mem::take(&mut self.work2);
        for v in x.iter_mut() {
            *v = T::from_f64(1.0 / n as f64);
        }
        let mut est = 0.0;
        let mut arg = 0;
        for _ in 0..5 {
            self.solve(&mut x);
            let norm: f64 = x.iter().map(|v| v.abs()).sum();
            arg = (0..n)
                .max_by(|&i, &j| x[i].abs().total_cmp(&x[j].abs()))
                .unwrap_or(0);
            if norm <= est {
                break;
            }
            est = norm;
            for (zi, xi) in z.iter_mut().zip(x.iter()) {
                let a = xi.abs();
                *zi = if a > 0.0 {
                    *xi / T::from_f64(a)
                } else {
                    T::from_f64(1.0)
                };
            }
            self.solve_transpose(&mut z);
            let j = (0..n)
                .max_by(|&i, &j| z[i].abs().total_cmp(&z[j].abs()))
                .unwrap_or(0);
            for v in x.iter_mut() {
                *v = T::default();
            }
            x[j] = T::from_f64(1.0);
        }
        self.work = x;
        self.work2 = z;
        (est, arg)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn matrix(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed;
        (0..n * n)
            .map(|_| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect()
    }

    /// For inverse iteration a singular matrix factorises, its vanishing pivot raised to
    /// ε‖A‖₁, and a solve then gives the null vector's direction; a non-finite one does not.
    #[test]
    fn a_singular_matrix_factorises_for_inverse_iteration() {
        // column-major [[1, 2], [2, 4]]: null vector (2, −1)
        let mut lu = Lu::<f64>::new(2);
        lu.matrix_mut().copy_from_slice(&[1.0, 2.0, 2.0, 4.0]);
        assert!(lu.clone().factor().is_err());
        assert_eq!(lu.factor_for_inverse_iteration(), Ok(1));
        let mut x = vec![1.0, 0.3];
        lu.solve(&mut x);
        let ratio = x[0] / x[1];
        assert!((ratio + 2.0).abs() < 1e-12, "{x:?}");
        assert!(x[0].abs() > 1e12, "{x:?}");
        lu.matrix_mut().copy_from_slice(&[1.0, f64::NAN, 2.0, 4.0]);
        assert!(lu.factor_for_inverse_iteration().is_err());
    }

    #[test]
    fn lu_solves_like_nalgebra() {
        for n in [1, 3, 7, 12] {
            let a = matrix(n, n as u64);
            let b: Vec<f64> = (0..n).map(|i| i as f64 - 1.5).collect();
            let mut lu = Lu::<f64>::new(n);
            lu.matrix_mut().copy_from_slice(&a);
            lu.factor().unwrap();
            let mut x = b.clone();
            lu.solve(&mut x);
            let na = nalgebra::DMatrix::from_column_slice(n, n, &a);
            let xr = na
                .lu()
                .solve(&nalgebra::DVector::from_column_slice(&b))
                .unwrap();
            for i in 0..n {
                assert!(
                    (x[i] - xr[i]).abs() < 1e-10 * (1.0 + xr[i].abs()),
                    "n = {n}"
                );
            }
            // condition estimate vs the exact 1-norm of the inverse
            let (est, _) = lu.inverse_norm_estimate();
            let inv = nalgebra::DMatrix::from_column_slice(n, n, &a)
                .try_inverse()
                .unwrap();
            let exact = norm1(inv.as_slice(), n);
            assert!(
                est <= exact * (1.0 + 1e-12) && est >= exact / 10.0,
                "{est} vs {exact}"
            );
        }
    }

    /// A loop's index-3 matrix in large units: [M, −Bᵀ; B, 0] with M ~ 4·10¹⁶ beside B ~ 4·10⁵
    /// (the four-bar 10⁶ times larger) has a pivot BM⁻¹Bᵀ ~ 10⁻²² of ‖A‖₁, which the plain
    /// factorisation refuses; equilibrated it solves as nalgebra does, its condition estimate
    /// (through the transposed solve) bounds the inverse's norm, a singular matrix is still
    /// refused and a well-scaled one is factorised bit for bit as by `factor`.
    #[test]
    fn equilibration_factorises_blocks_in_different_units() {
        let (n, nc) = (3, 2);
        let big = n + nc;
        let r = matrix(n, 5);
        let mut a = vec![0.0; big * big];
        for i in 0..n {
            for j in 0..n {
                // M = 4·10¹⁶ (RᵀR + I)
                let m: f64 = (0..n).map(|k| r[k + n * i] * r[k + n * j]).sum();
                a[i + big * j] = 4e16 * (m + if i == j { 1.0 } else { 0.0 });
            }
        }
        let b = matrix(nc.max(n), 6);
        for k in 0..nc {
            for j in 0..n {
                let bkj = 4e5 * b[k + nc * j];
                a[n + k + big * j] = bkj;
                a[j + big * (n + k)] = -bkj;
            }
        }
        let mut lu = Lu::<f64>::new(big);
        lu.matrix_mut().copy_from_slice(&a);
        let plain = lu.factor().unwrap_err();
        assert!(plain.rcond < 1e-20, "{}", plain.rcond);
        lu.matrix_mut().copy_from_slice(&a);
        lu.factor_equilibrating().unwrap();
        let rhs: Vec<f64> = (0..big).map(|i| 1e10 * (i as f64 - 1.5)).collect();
        let mut x = rhs.clone();
        lu.solve(&mut x);
        let na = nalgebra::DMatrix::from_column_slice(big, big, &a);
        let xr = na
            .clone()
            .lu()
            .solve(&nalgebra::DVector::from_column_slice(&rhs))
            .unwrap();
        for i in 0..big {
            assert!((x[i] - xr[i]).abs() < 1e-9 * xr[i].abs(), "{x:?} vs {xr}");
        }
        let (est, _) = lu.inverse_norm_estimate();
        let exact = norm1(na.try_inverse().unwrap().as_slice(), big);
        assert!(
            est <= exact * (1.0 + 1e-9) && est >= exact / 10.0,
            "{est} vs {exact}"
        );
        // still singular: column 2 twice column 0
        let s = [1.0, 2.0, 3.0, 0.0, 1.0, 4.0, 2.0, 4.0, 6.0];
        let mut lu3 = Lu::<f64>::new(3);
        lu3.matrix_mut().copy_from_slice(&s);
        assert_eq!(lu3.factor_equilibrating().unwrap_err().column, 2);
        // well scaled: factor's result, bit for bit
        let w = matrix(7, 3);
        let (mut p, mut q) = (Lu::<f64>::new(7), Lu::<f64>::new(7));
        p.matrix_mut().copy_from_slice(&w);
        q.matrix_mut().copy_from_slice(&w);
        p.factor().unwrap();
        q.factor_equilibrating().unwrap();
        let (mut xp, mut xq) = (vec![1.0; 7], vec![1.0; 7]);
        p.solve(&mut xp);
        q.solve(&mut xq);
        assert_eq!(xp, xq);
    }

    #[test]
    fn singular_matrices_name_their_column() {
        // column 2 is twice column 0
        let n = 3;
        let a = vec![1.0, 2.0, 3.0, 0.0, 1.0, 4.0, 2.0, 4.0, 6.0];
        let mut lu = Lu::<f64>::new(n);
        lu.matrix_mut().copy_from_slice(&a);
        let e = lu.factor().unwrap_err();
        assert_eq!(e.column, 2);
        assert!(e.rcond < 1e-14);
    }

    #[test]
    fn cholesky_of_a_mass_matrix() {
        let n = 4;
        let r = matrix(n, 9);
        let mut m = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                m[i + n * j] = (0..n).map(|k| r[i + n * k] * r[j + n * k]).sum::<f64>()
                    + if i == j { 1.0 } else { 0.0 };
            }
        }
        let b = vec![1.0, -2.0, 0.5, 3.0];
        let mut l = m.clone();
        cholesky(&mut l, n).unwrap();
        let mut x = b.clone();
        cholesky_solve(&l, n, &mut x);
        for i in 0..n {
            let r: f64 = (0..n).map(|j| m[i + n * j] * x[j]).sum();
            assert!((r - b[i]).abs() < 1e-12);
        }
        // a zero row and column: not positive definite, named
        let mut z = m.clone();
        for k in 0..n {
            z[2 + n * k] = 0.0;
            z[k + n * 2] = 0.0;
        }
        assert_eq!(cholesky(&mut z, n).unwrap_err().column, 2);
    }

    #[test]
    fn complex_lu() {
        let n = 2;
        let a = [
            C64::new(1.0, 1.0),
            C64::new(0.0, 2.0),
            C64::new(3.0, 0.0),
            C64::new(1.0, -1.0),
        ];
        let mut lu = Lu::<C64>::new(n);
        lu.matrix_mut().copy_from_slice(&a);
        lu.factor().unwrap();
        let b = [C64::new(1.0, 0.0), C64::new(0.0, 1.0)];
        let mut x = b;
        lu.solve(&mut x);
        for i in 0..n {
            let r = a[i] * x[0] + a[i + n] * x[1];
            assert!((r - b[i]).abs() < 1e-14);
        }
    }
}
