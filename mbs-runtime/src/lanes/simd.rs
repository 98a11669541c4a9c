//! [`Simd`]: the number type inside generated batch code, and [`Math`] / [`Math2`], the
//! functions generated code calls on it and on `f64` alike (parameters and constants stay
//! `f64`; whatever depends on the states is `Simd`; every operation takes either).
//!
//! On x86-64 a `Simd` is one 256-bit AVX register and each operation one AVX instruction
//! (`std::arch` intrinsics, inlined into the generated functions, which are compiled for
//! AVX2). A `Simd` value is made only by [`Simd::new`], a function compiled for AVX2 that
//! only code compiled for AVX2 calls without `unsafe` (generated code, entered after
//! [`super::simd_available`]): every operation on a `Simd` relies on that (an operand is the
//! proof). Elsewhere `Simd` is [`F64x4`] (element by element, which the compiler vectorises
//! as it can).

use super::F64x4;

#[cfg(target_arch = "x86_64")]
pub use avx::Simd;
#[cfg(not(target_arch = "x86_64"))]
pub use portable::Simd;

/// The functions of the language on `f64` and on [`Simd`] (`Math::sin(x)` is `x.sin()` on
/// either).
pub trait Math: Copy {
    fn sin(self) -> Self;
    fn cos(self) -> Self;
    fn tan(self) -> Self;
    fn asin(self) -> Self;
    fn acos(self) -> Self;
    fn atan(self) -> Self;
    fn sinh(self) -> Self;
    fn cosh(self) -> Self;
    fn tanh(self) -> Self;
    fn exp(self) -> Self;
    fn ln(self) -> Self;
    fn sqrt(self) -> Self;
    fn abs(self) -> Self;
    /// `sign(x)`: −1, 0 or 1 (0 at 0, NaN at NaN), as the one-state code computes it
    fn sign(self) -> Self;
    /// `step(x)`: 1 where x > 0, else 0
    fn step(self) -> Self;
    /// `pos(x)`: max(x, 0) (0 at NaN, as `f64::max`)
    fn pos(self) -> Self;
    fn powi(self, k: i32) -> Self;
    /// a Rust function of the model, lane by lane
    fn map(self, f: impl Fn(f64) -> f64) -> Self;
}

/// Functions of two arguments, each `f64` or [`Simd`].
pub trait Math2<B> {
    type Output;
    fn atan2(self, x: B) -> Self::Output;
    fn powf(self, y: B) -> Self::Output;
}

/// `Math` for a type from its inherent functions of the same names (`<T>::sin(x)`…), and
/// the items it writes out itself.
macro_rules! math_by_name {
    ($ty:ty; $($f:ident),*; $($own:item)*) => {
        impl $crate::lanes::Math for $ty {
            $(#[inline(always)] fn $f(self) -> $ty { <$ty>::$f(self) })*
            $($own)*
        }
    };
}
math_by_name!(
    f64; sin, cos, tan, asin, acos, atan, sinh, cosh, tanh, exp, ln, sqrt, abs;
    #[inline(always)]
    fn sign(self) -> f64 {
        if self == 0.0 { 0.0 } else { self.signum() }
    }
    #[inline(always)]
    fn step(self) -> f64 {
        if self > 0.0 { 1.0 } else { 0.0 }
    }
    #[inline(always)]
    fn pos(self) -> f64 {
        self.max(0.0)
    }
    #[inline(always)]
    fn powi(self, k: i32) -> f64 {
        f64::powi(self, k)
    }
    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> f64 {
        f(self)
    }
);

impl Math2<f64> for f64 {
    type Output = f64;
    #[inline(always)]
    fn atan2(self, x: f64) -> f64 {
        f64::atan2(self, x)
    }
    #[inline(always)]
    fn powf(self, y: f64) -> f64 {
        f64::powf(self, y)
    }
}

/// `x^k` by repeated squaring, on any type with a product (`f64::powi` for the small k of
/// generated code).
#[inline(always)]
pub(super) fn powi_by_squaring<T: Copy + std::ops::Mul<Output = T>>(
    x: T,
    k: i32,
    one: T,
    inv: impl Fn(T) -> T,
) -> T {
    let mut base = if k < 0 { inv(x) } else { x };
    let mut e = k.unsigned_abs();
    let mut acc = one;
    while e > 0 {
        if e & 1 == 1 {
            acc = acc * base;
        }
        base = base * base;
        e >>= 1;
    }
    acc
}

#[cfg(not(target_arch = "x86_64"))]
mod portable {
    use super::{F64x4, Math2};

    /// [`F64x4`] itself where there are no AVX registers.
    pub type Simd = F64x4;

    impl F64x4 {
        /// The lanes `v` as generated code holds them (the same type here).
        #[inline(always)]
        pub fn new(v: F64x4) -> F64x4 {
            v
        }
    }

    math_by_name!(
        F64x4; sin, cos, tan, asin, acos, atan, sinh, cosh, tanh, exp, ln, sqrt, abs,
        sign, step, pos;
        #[inline(always)]
        fn powi(self, k: i32) -> F64x4 {
            F64x4::powi(self, k)
        }
        #[inline(always)]
        fn map(self, f: impl Fn(f64) -> f64) -> F64x4 {
            F64x4::map(self, f)
        }
    );

    macro_rules! two {
        ($a:ty, $b:ty) => {
            impl Math2<$b> for $a {
                type Output = F64x4;
                #[inline(always)]
                fn atan2(self, x: $b) -> F64x4 {
                    F64x4::from(self).atan2(F64x4::from(x))
                }
                #[inline(always)]
                fn powf(self, y: $b) -> F64x4 {
                    F64x4::from(self).powf(F64x4::from(y))
                }
            }
        };
    }
    two!(F64x4, F64x4);
    two!(F64x4, f64);
    two!(f64, F64x4);
}

#[cfg(target_arch = "x86_64")]
mod avx {
    use super::{F64x4, Math, Math2, powi_by_squaring};
    use std::arch::x86_64::*;
    use std::ops::{Add, Div, Mul, Neg, Sub};

    /// Four lanes in one AVX register. Made only by [`Simd::new`], whose caller promises
    /// that the processor has AVX2; every operation relies on it.
    #[derive(Clone, Copy)]
    #[repr(transparent)]
    pub struct Simd(__m256d);

    impl Simd {
        /// The lanes `v` in a register: callable (without `unsafe`) from code compiled for
        /// AVX2, as generated batch code is.
        ///
        /// # Safety
        /// Elsewhere, the processor must have AVX2 ([`super::super::simd_available`]).
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn new(v: F64x4) -> Simd {
            // SAFETY: an unaligned load from a valid array
            Simd(unsafe { _mm256_loadu_pd(v.to_array().as_ptr()) })
        }

        /// Every lane `v`, in a register like `self` (which proves AVX).
        #[inline(always)]
        fn splat_like(self, v: f64) -> Simd {
            // SAFETY: `self` exists, so the processor has AVX2
            Simd(unsafe { _mm256_set1_pd(v) })
        }

        #[inline(always)]
        fn lanes(self) -> F64x4 {
            let mut a = [0.0; 4];
            // SAFETY: `self` proves AVX; the store fills a valid array
            unsafe { _mm256_storeu_pd(a.as_mut_ptr(), self.0) };
            F64x4::from(a)
        }

        /// The lanes `v` in a register like `self` (which proves AVX2).
        #[inline(always)]
        fn load(self, v: F64x4) -> Simd {
            // SAFETY: `self` proves AVX2; an unaligned load from a valid array
            Simd(unsafe { _mm256_loadu_pd(v.to_array().as_ptr()) })
        }

        /// A function of [`F64x4`] (lane by lane or `wide`'s).
        #[inline(always)]
        fn via(self, f: impl Fn(F64x4) -> F64x4) -> Simd {
            self.load(f(self.lanes()))
        }

        /// sin and cos together, as [`F64x4::sin_cos`] in AVX registers.
        #[inline(always)]
        fn sin_cos(self) -> (Simd, Simd) {
            use super::super::sincos::{C, PIO2_1, PIO2_2, PIO2_3, REDUCE_LIMIT, S};
            let x = self.0;
            // SAFETY: `self` proves AVX2; the intrinsics are arithmetic on registers
            unsafe {
                let abs = _mm256_andnot_pd(_mm256_set1_pd(-0.0), x);
                let ok = _mm256_cmp_pd::<_CMP_LE_OQ>(abs, _mm256_set1_pd(REDUCE_LIMIT));
                if _mm256_movemask_pd(ok) != 0b1111 {
                    return (self.via(|s| s.map(f64::sin)), self.via(|s| s.map(f64::cos)));
                }
                // written without closures: everything inlines into the AVX2 caller
                macro_rules! set {
                    ($v:expr) => {
                        _mm256_set1_pd($v)
                    };
                }
                macro_rules! horner {
                    ($c:expr, $z:expr) => {{
                        let mut p = set!($c[0]);
                        let mut i = 1;
                        while i < 6 {
                            p = _mm256_add_pd(_mm256_mul_pd(p, $z), set!($c[i]));
                            i += 1;
                        }
                        p
                    }};
                }
                let k = _mm256_round_pd::<{ _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC }>(
                    _mm256_mul_pd(x, set!(std::f64::consts::FRAC_2_PI)),
                );
                let r = _mm256_sub_pd(x, _mm256_mul_pd(k, set!(PIO2_1)));
                let r = _mm256_sub_pd(r, _mm256_mul_pd(k, set!(PIO2_2)));
                let r = _mm256_sub_pd(r, _mm256_mul_pd(k, set!(PIO2_3)));
                let z = _mm256_mul_pd(r, r);
                let (ps, pc) = (horner!(S, z), horner!(C, z));
                let s = _mm256_add_pd(r, _mm256_mul_pd(_mm256_mul_pd(r, z), ps));
                let c = _mm256_add_pd(
                    _mm256_sub_pd(set!(1.0), _mm256_mul_pd(set!(0.5), z)),
                    _mm256_mul_pd(_mm256_mul_pd(z, z), pc),
                );
                // the quadrant m = k mod 4
                let m = _mm256_sub_pd(
                    k,
                    _mm256_mul_pd(set!(4.0), _mm256_floor_pd(_mm256_mul_pd(k, set!(0.25)))),
                );
                let (m1, m2, m3) = (
                    _mm256_cmp_pd::<_CMP_EQ_OQ>(m, set!(1.0)),
                    _mm256_cmp_pd::<_CMP_EQ_OQ>(m, set!(2.0)),
                    _mm256_cmp_pd::<_CMP_EQ_OQ>(m, set!(3.0)),
                );
                let odd = _mm256_or_pd(m1, m3);
                let a = _mm256_blendv_pd(s, c, odd);
                let b = _mm256_blendv_pd(c, s, odd);
                let neg_a = _mm256_or_pd(m2, m3);
                let neg_b = _mm256_or_pd(m1, m2);
                let sign = set!(-0.0);
                let sin = _mm256_xor_pd(a, _mm256_and_pd(neg_a, sign));
                let cos = _mm256_xor_pd(b, _mm256_and_pd(neg_b, sign));
                (Simd(sin), Simd(cos))
            }
        }
    }

    impl From<Simd> for F64x4 {
        #[inline(always)]
        fn from(v: Simd) -> F64x4 {
            v.lanes()
        }
    }

    macro_rules! binary {
        ($tr:ident, $f:ident, $intr:ident) => {
            impl $tr for Simd {
                type Output = Simd;
                #[inline(always)]
                fn $f(self, b: Simd) -> Simd {
                    // SAFETY: an operand proves AVX2
                    Simd(unsafe { $intr(self.0, b.0) })
                }
            }
            impl $tr<f64> for Simd {
                type Output = Simd;
                #[inline(always)]
                fn $f(self, b: f64) -> Simd {
                    self.$f(self.splat_like(b))
                }
            }
            impl $tr<Simd> for f64 {
                type Output = Simd;
                #[inline(always)]
                fn $f(self, b: Simd) -> Simd {
                    b.splat_like(self).$f(b)
                }
            }
        };
    }
    binary!(Add, add, _mm256_add_pd);
    binary!(Sub, sub, _mm256_sub_pd);
    binary!(Mul, mul, _mm256_mul_pd);
    binary!(Div, div, _mm256_div_pd);

    impl Neg for Simd {
        type Output = Simd;
        #[inline(always)]
        fn neg(self) -> Simd {
            // SAFETY: `self` proves AVX2
            Simd(unsafe { _mm256_xor_pd(self.0, _mm256_set1_pd(-0.0)) })
        }
    }

    impl Math for Simd {
        #[inline(always)]
        fn sin(self) -> Simd {
            self.sin_cos().0
        }
        #[inline(always)]
        fn cos(self) -> Simd {
            self.sin_cos().1
        }
        #[inline(always)]
        fn tan(self) -> Simd {
            self.via(F64x4::tan)
        }
        #[inline(always)]
        fn asin(self) -> Simd {
            self.via(F64x4::asin)
        }
        #[inline(always)]
        fn acos(self) -> Simd {
            self.via(F64x4::acos)
        }
        #[inline(always)]
        fn atan(self) -> Simd {
            self.via(F64x4::atan)
        }
        #[inline(always)]
        fn sinh(self) -> Simd {
            self.via(F64x4::sinh)
        }
        #[inline(always)]
        fn cosh(self) -> Simd {
            self.via(F64x4::cosh)
        }
        #[inline(always)]
        fn tanh(self) -> Simd {
            self.via(F64x4::tanh)
        }
        #[inline(always)]
        fn exp(self) -> Simd {
            self.via(F64x4::exp)
        }
        #[inline(always)]
        fn ln(self) -> Simd {
            self.via(F64x4::ln)
        }
        #[inline(always)]
        fn sqrt(self) -> Simd {
            // SAFETY: `self` proves AVX2
            Simd(unsafe { _mm256_sqrt_pd(self.0) })
        }
        #[inline(always)]
        fn abs(self) -> Simd {
            // SAFETY: `self` proves AVX2
            Simd(unsafe { _mm256_andnot_pd(_mm256_set1_pd(-0.0), self.0) })
        }
        #[inline(always)]
        fn sign(self) -> Simd {
            let x = self.0;
            // SAFETY: `self` proves AVX2
            unsafe {
                let zero = _mm256_setzero_pd();
                let unit =
                    _mm256_or_pd(_mm256_and_pd(x, _mm256_set1_pd(-0.0)), _mm256_set1_pd(1.0));
                let nonzero = _mm256_cmp_pd::<_CMP_NEQ_UQ>(x, zero);
                let nan = _mm256_cmp_pd::<_CMP_UNORD_Q>(x, x);
                Simd(_mm256_blendv_pd(_mm256_and_pd(unit, nonzero), x, nan))
            }
        }
        #[inline(always)]
        fn step(self) -> Simd {
            // SAFETY: `self` proves AVX2
            unsafe {
                let gt = _mm256_cmp_pd::<_CMP_GT_OQ>(self.0, _mm256_setzero_pd());
                Simd(_mm256_and_pd(gt, _mm256_set1_pd(1.0)))
            }
        }
        #[inline(always)]
        fn pos(self) -> Simd {
            // SAFETY: `self` proves AVX2; maxpd gives its second operand (0) at NaN
            Simd(unsafe { _mm256_max_pd(self.0, _mm256_setzero_pd()) })
        }
        #[inline(always)]
        fn powi(self, k: i32) -> Simd {
            powi_by_squaring(self, k, self.splat_like(1.0), |x| 1.0 / x)
        }
        #[inline(always)]
        fn map(self, f: impl Fn(f64) -> f64) -> Simd {
            self.via(|v| v.map(&f))
        }
    }

    macro_rules! two {
        ($a:ty, $b:ty, $like:ident) => {
            impl Math2<$b> for $a {
                type Output = Simd;
                #[inline(always)]
                fn atan2(self, x: $b) -> Simd {
                    let like = $like(&self, &x);
                    like.load(F64x4::from(self).atan2(F64x4::from(x)))
                }
                #[inline(always)]
                fn powf(self, y: $b) -> Simd {
                    let like = $like(&self, &y);
                    like.load(F64x4::from(self).powf(F64x4::from(y)))
                }
            }
        };
    }
    fn first(a: &Simd, _: &impl Copy) -> Simd {
        *a
    }
    fn second(_: &f64, b: &Simd) -> Simd {
        *b
    }
    two!(Simd, Simd, first);
    two!(Simd, f64, first);
    two!(f64, Simd, second);
}

#[cfg(test)]
mod tests {
    use super::{F64x4, Math, Math2, Simd};

    /// Every function on lanes in registers against `f64` lane by lane (exactly where the
    /// operation is correctly rounded, within 2.3e-16 for sin and cos).
    #[cfg_attr(target_arch = "x86_64", target_feature(enable = "avx2"))]
    fn check() {
        let xs = F64x4::from([-2.5, 0.0, 0.7, f64::NAN]);
        let ys = F64x4::from([1.5, -0.3, -0.0, 31.0]);
        let (x, y) = (Simd::new(xs), Simd::new(ys));
        let lanes = |v: Simd| F64x4::from(v).to_array();
        let same = |a: f64, b: f64| a == b || (a.is_nan() && b.is_nan());
        type Pair = (fn(Simd) -> Simd, fn(f64) -> f64, f64);
        let unary: [Pair; 18] = [
            (|v| Math::asin(v * 0.3), |v| Math::asin(v * 0.3), 1e-15),
            (|v| Math::acos(v * 0.3), |v| Math::acos(v * 0.3), 1e-15),
            (Math::sin, Math::sin, 2.3e-16),
            (Math::cos, Math::cos, 2.3e-16),
            (Math::tan, Math::tan, 1e-15),
            (Math::atan, Math::atan, 1e-15),
            (Math::exp, Math::exp, 1e-15),
            (Math::ln, Math::ln, 0.0),
            (Math::sinh, Math::sinh, 0.0),
            (Math::sqrt, Math::sqrt, 0.0),
            (Math::abs, Math::abs, 0.0),
            (Math::sign, Math::sign, 0.0),
            (Math::step, Math::step, 0.0),
            (Math::pos, Math::pos, 0.0),
            (|v| Math::powi(v, 3), |v| Math::powi(v, 3), 1e-15),
            (|v| Math::powi(v, -2), |v| Math::powi(v, -2), 1e-15),
            (
                |v| -v * 2.0 + 1.0 / v - (v - 3.0),
                |v| -v * 2.0 + 1.0 / v - (v - 3.0),
                0.0,
            ),
            (|v| Math::map(v, |a| a.cbrt()), f64::cbrt, 0.0),
        ];
        for (k, (fv, fs, tol)) in unary.iter().enumerate() {
            for v in [xs, ys] {
                let got = lanes(fv(Simd::new(v)));
                for (l, a) in v.to_array().into_iter().enumerate() {
                    let want = fs(a);
                    assert!(
                        same(got[l], want) || (got[l] - want).abs() <= tol * want.abs().max(1.0),
                        "function {k} at {a}: {} vs {want}",
                        got[l]
                    );
                }
            }
        }
        let at = lanes(Math2::atan2(x, y));
        let pf = lanes(Math2::powf(2.0, y));
        let mixed = lanes(3.0 * x - y / 2.0);
        for l in 0..4 {
            let (a, b) = (xs.lane(l), ys.lane(l));
            assert!(same(at[l], a.atan2(b)) || (at[l] - a.atan2(b)).abs() < 1e-15);
            assert!(same(pf[l], 2f64.powf(b)));
            assert!(same(mixed[l], 3.0 * a - b / 2.0));
        }
    }

    #[test]
    fn lanes_in_registers_compute_as_f64() {
        if super::super::simd_available() {
            #[allow(unused_unsafe)]
            // SAFETY: the processor has AVX2
            unsafe {
                check()
            }
        }
    }
}
