//! Four states at once: [`F64x4`], the lanes of the batch functions' arguments and results
//! ([`Model::dynamics_x4`](crate::Model::dynamics_x4),
//! [`Model::forward_dynamics_x4`](crate::Model::forward_dynamics_x4)) that `option batch;`
//! generates.
//!
//! A batch holds coordinate `i` of four states in one `F64x4` (structure of arrays): `q[i]`
//! is `[q_i of state 0, …, q_i of state 3]`. [`pack`] and [`unpack`] convert from and to
//! one slice per state.
//!
//! Inside the generated functions the values that differ between states are [`Simd`]: on
//! x86-64 one AVX register each, every operation one AVX instruction (the functions are
//! compiled for AVX2 and entered when [`simd_available`]; otherwise [`lane_by_lane`] calls
//! the one-state functions). Each lane's parameters and charts are those of its model: the
//! `_x4` functions give the model itself to the four lanes, the `_lanes` functions
//! ([`Model::forward_dynamics_lanes`](crate::Model::forward_dynamics_lanes)) one model per
//! lane, so that the members of an ensemble may differ in their parameters and re-centre
//! their charts each on its own ([`gather`]). Constants stay `f64`; the functions of the
//! language are [`Math`] and [`Math2`], on `f64` or `Simd` alike. sin and cos are
//! polynomials on all four lanes ([`F64x4::sin_cos`], the same in AVX registers); tan, the
//! inverse functions and exp are the `wide` crate's vector polynomials (within 2 ulp of
//! `f64`'s functions); the others (hyperbolic ones, ln, powf, Rust functions of the model)
//! are applied lane by lane. `F64x4`'s own arithmetic is element by element.

use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub};
use wide::f64x4;

mod simd;
pub use simd::{Math, Math2, Simd};

/// The constants of sin and cos on lanes.
mod sincos {
    /// π/2 in three parts (fdlibm's split): k π/2 is exact in the first for |k| < 2²⁰
    pub const PIO2_1: f64 = 1.570_796_326_734_125_6;
    pub const PIO2_2: f64 = 6.077_100_506_303_966e-11;
    pub const PIO2_3: f64 = 2.022_266_248_795_950_6e-21;
    /// beyond it, `f64::sin` and `f64::cos` lane by lane
    pub const REDUCE_LIMIT: f64 = 1e5;
    /// Cephes' minimax polynomials on [−π/4, π/4]: sin r = r + r z S(z), cos r = 1 − z/2 +
    /// z² C(z), z = r², highest degree first
    pub const S: [f64; 6] = [
        1.589_623_015_765_465_7e-10,
        -2.505_074_776_285_780_7e-8,
        2.755_731_362_138_572_5e-6,
        -1.984_126_982_958_954e-4,
        8.333_333_333_322_118e-3,
        -1.666_666_666_666_663e-1,
    ];
    pub const C: [f64; 6] = [
        -1.135_853_652_138_768_2e-11,
        2.087_570_084_197_473e-9,
        -2.755_731_417_929_674e-7,
        2.480_158_728_885_170_5e-5,
        -1.388_888_888_887_305_6e-3,
        4.166_666_666_666_659_3e-2,
    ];
}

/// Number of states in a batch.
pub const LANES: usize = 4;

/// Four `f64`s, one per state of a batch.
#[derive(Clone, Copy, Default, PartialEq)]
#[repr(C, align(32))]
pub struct F64x4([f64; LANES]);

impl std::fmt::Debug for F64x4 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

/// Whether this processor runs the generated batch code: on x86-64 it is compiled for AVX2
/// (`#[target_feature]`, 256-bit registers whatever the build's target CPU) and runs where
/// the processor has it, checked once (std caches the answer); elsewhere always. Without it,
/// the batch functions call the one-state functions lane by lane.
#[inline]
pub fn simd_available() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        true
    }
}

impl F64x4 {
    /// Every lane zero.
    pub const ZERO: F64x4 = F64x4([0.0; LANES]);

    /// Every lane `v`.
    #[inline(always)]
    pub fn splat(v: f64) -> F64x4 {
        F64x4([v; LANES])
    }

    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [f64; LANES] {
        self.0
    }

    /// Lane `k` (0..4).
    #[inline(always)]
    pub fn lane(self, k: usize) -> f64 {
        self.0[k]
    }

    /// `f` applied lane by lane.
    #[inline(always)]
    pub fn map(self, f: impl Fn(f64) -> f64) -> F64x4 {
        let a = self.0;
        F64x4([f(a[0]), f(a[1]), f(a[2]), f(a[3])])
    }

    /// `f` of `wide`'s vector functions.
    #[inline(always)]
    fn wide(self, f: impl Fn(f64x4) -> f64x4) -> F64x4 {
        F64x4(f(f64x4::from(self.0)).to_array())
    }

    /// sin and cos together, element by element without branches (so in vector registers):
    /// x = k π/2 + r with π/2 in three parts (fdlibm's split: k π/2 exact for |k| < 2²⁰),
    /// |r| ≤ π/4, Cephes' minimax polynomials of sin and cos on it, the quadrant k mod 4
    /// choosing and signing them. Lanes beyond |x| = 1e5 (where the split loses digits) take
    /// `f64::sin` and `f64::cos` instead.
    #[inline(always)]
    pub fn sin_cos(self) -> (F64x4, F64x4) {
        use sincos::{C, PIO2_1, PIO2_2, PIO2_3, REDUCE_LIMIT, S};
        if self.0.iter().any(|x| !(x.abs() <= REDUCE_LIMIT)) {
            return (self.map(f64::sin), self.map(f64::cos));
        }
        let mut sin = [0.0; LANES];
        let mut cos = [0.0; LANES];
        for l in 0..LANES {
            let x = self.0[l];
            let k = (x * std::f64::consts::FRAC_2_PI).round_ties_even();
            let r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
            let z = r * r;
            let ps = S[1..].iter().fold(S[0], |p, c| p * z + c);
            let pc = C[1..].iter().fold(C[0], |p, c| p * z + c);
            let s = r + r * z * ps;
            let c = 1.0 - 0.5 * z + z * z * pc;
            // the quadrant k mod 4 ∈ {0, 1, 2, 3}
            let m = k - 4.0 * (k * 0.25).floor();
            let odd = m == 1.0 || m == 3.0;
            let (a, b) = if odd { (c, s) } else { (s, c) };
            sin[l] = if m >= 2.0 { -a } else { a };
            cos[l] = if m == 1.0 || m == 2.0 { -b } else { b };
        }
        (F64x4(sin), F64x4(cos))
    }
    #[inline(always)]
    pub fn sin(self) -> F64x4 {
        self.sin_cos().0
    }
    #[inline(always)]
    pub fn cos(self) -> F64x4 {
        self.sin_cos().1
    }
    #[inline(always)]
    pub fn tan(self) -> F64x4 {
        self.wide(f64x4::tan)
    }
    #[inline(always)]
    pub fn asin(self) -> F64x4 {
        self.wide(f64x4::asin)
    }
    #[inline(always)]
    pub fn acos(self) -> F64x4 {
        self.wide(f64x4::acos)
    }
    #[inline(always)]
    pub fn atan(self) -> F64x4 {
        self.wide(f64x4::atan)
    }
    #[inline(always)]
    pub fn atan2(self, x: F64x4) -> F64x4 {
        F64x4(f64x4::from(self.0).atan2(f64x4::from(x.0)).to_array())
    }
    #[inline(always)]
    pub fn exp(self) -> F64x4 {
        // `wide`'s exp gives 0 at NaN: NaN lanes stay NaN
        let e = self.wide(f64x4::exp).0;
        let a = self.0;
        F64x4(std::array::from_fn(
            |l| if a[l].is_nan() { a[l] } else { e[l] },
        ))
    }
    #[inline(always)]
    pub fn sinh(self) -> F64x4 {
        self.map(f64::sinh)
    }
    #[inline(always)]
    pub fn cosh(self) -> F64x4 {
        self.map(f64::cosh)
    }
    #[inline(always)]
    pub fn tanh(self) -> F64x4 {
        self.map(f64::tanh)
    }
    /// Lane by lane: `wide`'s vector logarithm is 1e-13 off near 2 and 0.3.
    #[inline(always)]
    pub fn ln(self) -> F64x4 {
        self.map(f64::ln)
    }
    #[inline(always)]
    pub fn sqrt(self) -> F64x4 {
        self.map(f64::sqrt)
    }
    #[inline(always)]
    pub fn abs(self) -> F64x4 {
        self.map(f64::abs)
    }
    /// `x^k` by repeated squaring (as `f64::powi` for the small k of generated code).
    #[inline(always)]
    pub fn powi(self, k: i32) -> F64x4 {
        simd::powi_by_squaring(self, k, F64x4::splat(1.0), |x| 1.0 / x)
    }
    /// `x^y` lane by lane.
    #[inline(always)]
    pub fn powf(self, y: F64x4) -> F64x4 {
        let (a, b) = (self.0, y.0);
        F64x4([
            a[0].powf(b[0]),
            a[1].powf(b[1]),
            a[2].powf(b[2]),
            a[3].powf(b[3]),
        ])
    }
    /// The language's `pos(x)`: max(x, 0), as the one-state code computes it.
    #[inline(always)]
    pub fn pos(self) -> F64x4 {
        self.map(|x| x.max(0.0))
    }
    /// The language's `step(x)`: 1 where x > 0, else 0.
    #[inline(always)]
    pub fn step(self) -> F64x4 {
        self.map(|x| if x > 0.0 { 1.0 } else { 0.0 })
    }
    /// The language's `sign(x)`: −1, 0 or 1 (0 at 0).
    #[inline(always)]
    pub fn sign(self) -> F64x4 {
        self.map(|x| if x == 0.0 { 0.0 } else { x.signum() })
    }
    /// Whether every lane is finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.0.iter().all(|x| x.is_finite())
    }
}

impl From<f64> for F64x4 {
    #[inline(always)]
    fn from(v: f64) -> F64x4 {
        F64x4::splat(v)
    }
}

impl From<[f64; LANES]> for F64x4 {
    #[inline(always)]
    fn from(a: [f64; LANES]) -> F64x4 {
        F64x4(a)
    }
}

// element by element, written out so that the compiler makes one vector instruction of each
macro_rules! binary {
    ($tr:ident, $f:ident, $op:tt) => {
        impl $tr for F64x4 {
            type Output = F64x4;
            #[inline(always)]
            fn $f(self, b: F64x4) -> F64x4 {
                let (a, b) = (self.0, b.0);
                F64x4([a[0] $op b[0], a[1] $op b[1], a[2] $op b[2], a[3] $op b[3]])
            }
        }
        impl $tr<f64> for F64x4 {
            type Output = F64x4;
            #[inline(always)]
            fn $f(self, b: f64) -> F64x4 {
                self $op F64x4::splat(b)
            }
        }
        impl $tr<F64x4> for f64 {
            type Output = F64x4;
            #[inline(always)]
            fn $f(self, b: F64x4) -> F64x4 {
                F64x4::splat(self) $op b
            }
        }
    };
}
binary!(Add, add, +);
binary!(Sub, sub, -);
binary!(Mul, mul, *);
binary!(Div, div, /);

impl Neg for F64x4 {
    type Output = F64x4;
    #[inline(always)]
    fn neg(self) -> F64x4 {
        self.map(|x| -x)
    }
}

impl AddAssign for F64x4 {
    #[inline(always)]
    fn add_assign(&mut self, b: F64x4) {
        *self = *self + b;
    }
}

/// Coordinate `i` of the four states into `out[i]`: `states[k][i]` is lane `k` of `out[i]`.
pub fn pack(states: [&[f64]; LANES], out: &mut [F64x4]) {
    for (i, o) in out.iter_mut().enumerate() {
        *o = F64x4::from([states[0][i], states[1][i], states[2][i], states[3][i]]);
    }
}

/// Lane `k` of every element of `batch` into `out` (the k-th state of a batch).
pub fn unpack(batch: &[F64x4], k: usize, out: &mut [f64]) {
    for (o, b) in out.iter_mut().zip(batch) {
        *o = b.lane(k);
    }
}

/// One value of four models as lanes, the generated batch code's parameters and charts
/// (`gather::<EACH, _>(each, |m| m.params.l)`): lane `k` that of `models[k]` when `EACH`,
/// else the first model's in every lane (the models are one).
#[inline(always)]
pub fn gather<const EACH: bool, M>(models: [&M; LANES], value: impl Fn(&M) -> f64) -> F64x4 {
    if EACH {
        F64x4(models.map(value))
    } else {
        F64x4::from(value(models[0]))
    }
}

/// A batch function by its one-state form: each lane's inputs unpacked, `f` called with the
/// lane's number, its outputs packed (allocates): the batch functions of models without
/// `option batch;`, and of generated ones on a processor without the SIMD they are compiled
/// for.
pub fn lane_by_lane(
    t: F64x4,
    inputs: [&[F64x4]; 3],
    outputs: [&mut [F64x4]; 2],
    mut f: impl FnMut(usize, f64, [&[f64]; 3], [&mut [f64]; 2]),
) {
    let mut ins: Vec<Vec<f64>> = inputs.iter().map(|x| vec![0.0; x.len()]).collect();
    let [o0, o1] = outputs;
    let (mut a, mut b) = (vec![0.0; o0.len()], vec![0.0; o1.len()]);
    for k in 0..LANES {
        for (v, x) in ins.iter_mut().zip(inputs) {
            unpack(x, k, v);
        }
        f(k, t.lane(k), [&ins[0], &ins[1], &ins[2]], [&mut a, &mut b]);
        for (o, v) in o0.iter_mut().zip(&a).chain(o1.iter_mut().zip(&b)) {
            let mut l = o.to_array();
            l[k] = *v;
            *o = F64x4::from(l);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lanes() -> F64x4 {
        F64x4::from([-2.5, 0.0, 0.7, 31.0])
    }

    #[test]
    fn functions_agree_with_f64_lane_by_lane() {
        let x = lanes();
        let y = F64x4::from([1.5, -0.3, 2.0, 0.25]);
        type Pair = (fn(F64x4) -> F64x4, fn(f64) -> f64);
        let unary: [Pair; 10] = [
            (F64x4::sin, f64::sin),
            (F64x4::cos, f64::cos),
            (F64x4::tan, f64::tan),
            (F64x4::atan, f64::atan),
            (F64x4::sinh, f64::sinh),
            (F64x4::tanh, f64::tanh),
            (F64x4::exp, f64::exp),
            (F64x4::abs, f64::abs),
            (|v| v.powi(3), |v| v.powi(3)),
            (|v| v.powi(-2), |v| v.powi(-2)),
        ];
        for (k, (fv, fs)) in unary.iter().enumerate() {
            for (l, &a) in x.to_array().iter().enumerate() {
                let (v, s) = (fv(x).lane(l), fs(a));
                assert!(
                    v == s || (v - s).abs() <= 1e-14 * s.abs().max(1.0),
                    "function {k} at {a}: {v} vs {s}"
                );
            }
        }
        let r = (y * 0.5).asin().to_array();
        let a = (y * 0.5).acos().to_array();
        let p = y.abs().sqrt().to_array();
        let t = x.atan2(y).to_array();
        let l = y.abs().ln().to_array();
        let w = y.abs().powf(x).to_array();
        for (i, &b) in y.to_array().iter().enumerate() {
            let c = x.lane(i);
            assert!((r[i] - (b * 0.5).asin()).abs() < 1e-15);
            assert!((a[i] - (b * 0.5).acos()).abs() < 1e-15);
            assert_eq!(p[i], b.abs().sqrt());
            assert!((t[i] - c.atan2(b)).abs() < 1e-15);
            assert_eq!(l[i], b.abs().ln());
            assert!((w[i] - b.abs().powf(c)).abs() <= 1e-15 * w[i].abs());
        }
    }

    #[test]
    fn sin_and_cos_within_two_ulp_over_the_reduced_range_and_beyond() {
        let mut worst = 0.0f64;
        for i in 0..200_001 {
            let x = -60.0 + 120.0 * i as f64 / 200_000.0;
            let v = F64x4::from([x, -x, x * 1e3, x * 1.7e3 + 0.1]);
            let (s, c) = v.sin_cos();
            for l in 0..LANES {
                let y = v.lane(l);
                worst = worst
                    .max((s.lane(l) - y.sin()).abs())
                    .max((c.lane(l) - y.cos()).abs());
            }
        }
        assert!(worst <= 2.3e-16, "{worst:e}");
        let huge = F64x4::from([1e300, f64::NAN, f64::INFINITY, 3.0]);
        let (s, c) = huge.sin_cos();
        assert_eq!(s.lane(0), 1e300f64.sin());
        assert!(s.lane(1).is_nan() && c.lane(2).is_nan());
        assert_eq!(c.lane(3), 3.0f64.cos());
    }

    #[test]
    fn piecewise_functions_of_the_language() {
        let x = lanes();
        assert_eq!(x.pos().to_array(), [0.0, 0.0, 0.7, 31.0]);
        assert_eq!(x.step().to_array(), [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(x.sign().to_array(), [-1.0, 0.0, 1.0, 1.0]);
    }

    #[test]
    fn mixed_arithmetic_and_packing() {
        let x = lanes();
        assert_eq!(
            (2.0 * x - x / 2.0 + 1.0).to_array(),
            [-2.75, 1.0, 2.05, 47.5]
        );
        assert_eq!((-x).lane(3), -31.0);
        let (a, b, c, d) = ([1.0, 2.0], [3.0, 4.0], [5.0, 6.0], [7.0, 8.0]);
        let mut batch = [F64x4::ZERO; 2];
        pack([&a, &b, &c, &d], &mut batch);
        assert_eq!(batch[1].to_array(), [2.0, 4.0, 6.0, 8.0]);
        let mut out = [0.0; 2];
        unpack(&batch, 2, &mut out);
        assert_eq!(out, c);
        assert!(x.is_finite() && !(x / 0.0).is_finite());
    }
}
