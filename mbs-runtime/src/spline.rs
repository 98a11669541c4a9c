//! Natural cubic splines: the `spline(x, [(x0, y0), (x1, y1), …])` built-in of the language.
//! This file has no dependencies: the runtime declares it as a module and the generator
//! includes the same file, so the coefficients the generator computes and the values
//! generated code evaluates come from one definition.
//!
//! Between knots the spline is the cubic c₀ + c₁ s + c₂ s² + c₃ s³ (s = x − xᵢ) through the
//! points with continuous first and second derivatives and zero second derivative at both
//! ends (natural end conditions). Outside [x₀, xₙ] it continues as the straight line of its
//! end value and slope, which keeps the first and second derivatives continuous there too.

use std::fmt;

/// Why a table of points makes no spline.
#[derive(Clone, Debug, PartialEq)]
pub enum SplineError {
    /// fewer than two points
    TooFewPoints { count: usize },
    /// a coordinate is NaN or infinite
    NotFinite { index: usize },
    /// the abscissae do not increase strictly at point `index`
    NotIncreasing { index: usize, previous: f64, x: f64 },
}

impl fmt::Display for SplineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SplineError::TooFewPoints { count } => write!(
                f,
                "a spline needs at least 2 points, found {count}: give its table as `[(x0, y0), (x1, y1), …]`"
            ),
            SplineError::NotFinite { index } => {
                write!(f, "point {index} of the spline is not a finite number")
            }
            SplineError::NotIncreasing { index, previous, x } => write!(
                f,
                "the abscissae of a spline must increase strictly: point {index} has x = {x:?} after {previous:?}; sort the points and merge repeated abscissae"
            ),
        }
    }
}

/// The coefficients [c₀, c₁, c₂, c₃] of each of the `points.len() − 1` intervals of the
/// natural cubic spline through `points` (abscissae strictly increasing).
pub fn natural_coefficients(points: &[(f64, f64)]) -> Result<Vec<[f64; 4]>, SplineError> {
    let n = points.len();
    if n < 2 {
        return Err(SplineError::TooFewPoints { count: n });
    }
    for (i, &(x, y)) in points.iter().enumerate() {
        if !x.is_finite() || !y.is_finite() {
            return Err(SplineError::NotFinite { index: i });
        }
        // both finite here, so `<=` is the negation of `>`
        if i > 0 && x <= points[i - 1].0 {
            return Err(SplineError::NotIncreasing {
                index: i,
                previous: points[i - 1].0,
                x,
            });
        }
    }
    let h: Vec<f64> = points.windows(2).map(|w| w[1].0 - w[0].0).collect();
    let slope: Vec<f64> = points
        .windows(2)
        .zip(&h)
        .map(|(w, h)| (w[1].1 - w[0].1) / h)
        .collect();
    // second derivatives m at the knots, m₀ = mₙ₋₁ = 0; the inner ones solve the
    // tridiagonal system hᵢ₋₁ mᵢ₋₁ + 2 (hᵢ₋₁ + hᵢ) mᵢ + hᵢ mᵢ₊₁ = 6 (slopeᵢ − slopeᵢ₋₁)
    // (Thomas algorithm: diagonally dominant, no pivoting needed)
    let mut m = vec![0.0; n];
    if n > 2 {
        let inner = n - 2;
        let mut diag = vec![0.0; inner];
        let mut rhs = vec![0.0; inner];
        for k in 0..inner {
            let i = k + 1;
            diag[k] = 2.0 * (h[i - 1] + h[i]);
            rhs[k] = 6.0 * (slope[i] - slope[i - 1]);
            if k > 0 {
                let w = h[i - 1] / diag[k - 1];
                diag[k] -= w * h[i - 1];
                rhs[k] -= w * rhs[k - 1];
            }
        }
        for k in (0..inner).rev() {
            let i = k + 1;
            let upper = if k + 1 < inner { h[i] * m[i + 1] } else { 0.0 };
            m[i] = (rhs[k] - upper) / diag[k];
        }
    }
    Ok((0..n - 1)
        .map(|i| {
            let (y, hi) = (points[i].1, h[i]);
            [
                y,
                slope[i] - hi * (2.0 * m[i] + m[i + 1]) / 6.0,
                m[i] / 2.0,
                (m[i + 1] - m[i]) / (6.0 * hi),
            ]
        })
        .collect())
}

/// Derivative number `order` (0: the value) at `x` of the spline with `knots` x₀ < … < xₙ and
/// the `coefficients` of its n intervals from [`natural_coefficients`]. The third derivative
/// is constant on each interval and the fourth is zero; outside the knots, the spline is the
/// line of its end value and slope. NaN when `knots` and `coefficients` are not such a table
/// (no interval, or not one knot more than intervals).
pub fn evaluate(knots: &[f64], coefficients: &[[f64; 4]], order: u8, x: f64) -> f64 {
    if coefficients.is_empty() || knots.len() != coefficients.len() + 1 {
        // not a table of `natural_coefficients`: no value
        return f64::NAN;
    }
    let last = coefficients.len() - 1;
    let (i, s) = if x < knots[0] {
        // the line through the first point with its slope
        let c = &coefficients[0];
        return match order {
            // a level line stays level out to ±∞ (0·∞ would be NaN)
            0 if c[1] == 0.0 => c[0],
            0 => c[0] + c[1] * (x - knots[0]),
            1 => c[1],
            _ => 0.0,
        };
    } else if x > knots[last + 1] {
        let c = &coefficients[last];
        let h = knots[last + 1] - knots[last];
        let (y, dy) = (
            c[0] + h * (c[1] + h * (c[2] + h * c[3])),
            c[1] + h * (2.0 * c[2] + 3.0 * h * c[3]),
        );
        return match order {
            0 if dy == 0.0 => y,
            0 => y + dy * (x - knots[last + 1]),
            1 => dy,
            _ => 0.0,
        };
    } else {
        // the interval [xᵢ, xᵢ₊₁] holding x (the last one for x = xₙ); NaN falls through to
        // the first and stays NaN
        let i = knots[1..=last].partition_point(|&k| k <= x);
        (i, x - knots[i])
    };
    let c = &coefficients[i];
    match order {
        0 => c[0] + s * (c[1] + s * (c[2] + s * c[3])),
        1 => c[1] + s * (2.0 * c[2] + 3.0 * s * c[3]),
        2 => 2.0 * c[2] + 6.0 * s * c[3],
        3 => 6.0 * c[3],
        _ => 0.0,
    }
}

/// A natural cubic spline whose table is known when the model is generated: generated code
/// holds one per `spline(…)` of its `multibody!` block and evaluates it and its derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spline {
    knots: &'static [f64],
    coefficients: &'static [[f64; 4]],
}

impl Spline {
    /// The spline of `knots` and the `coefficients` [`natural_coefficients`] gives for them.
    ///
    /// # Panics
    ///
    /// When the table is empty or `knots.len() != coefficients.len() + 1` (in a `const`, at
    /// compile time: the generator writes these tables).
    pub const fn from_table(knots: &'static [f64], coefficients: &'static [[f64; 4]]) -> Spline {
        assert!(!coefficients.is_empty() && knots.len() == coefficients.len() + 1);
        Spline {
            knots,
            coefficients,
        }
    }

    /// Derivative number `order` at `x` (0: the value); see [`evaluate`].
    #[inline]
    pub fn eval(&self, order: u8, x: f64) -> f64 {
        evaluate(self.knots, self.coefficients, order, x)
    }

    /// The knots x₀ < … < xₙ.
    pub fn knots(&self) -> &'static [f64] {
        self.knots
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_level_end_stays_level_out_to_infinity() {
        let c = natural_coefficients(&[(0.0, 1.0), (1.0, 1.0)]).unwrap();
        let k = [0.0, 1.0];
        for x in [f64::NEG_INFINITY, f64::INFINITY] {
            assert_eq!(evaluate(&k, &c, 0, x), 1.0);
            assert_eq!(evaluate(&k, &c, 1, x), 0.0);
        }
    }

    #[test]
    fn reproduces_a_line_and_interpolates() {
        let pts = [(0.0, 1.0), (0.5, 2.0), (2.0, 5.0)];
        let c = natural_coefficients(&pts).unwrap();
        let k = [0.0, 0.5, 2.0];
        for x in [-1.0, 0.0, 0.3, 1.0, 2.0, 3.0] {
            assert!((evaluate(&k, &c, 0, x) - (1.0 + 2.0 * x)).abs() < 1e-14);
            assert!((evaluate(&k, &c, 1, x) - 2.0).abs() < 1e-14);
            assert!(evaluate(&k, &c, 2, x).abs() < 1e-13);
        }
    }

    #[test]
    fn natural_ends_and_continuity() {
        let pts = [(0.0, 0.0), (1.0, 1.0), (1.5, -0.5), (3.0, 2.0), (4.0, 0.0)];
        let k: Vec<f64> = pts.iter().map(|p| p.0).collect();
        let c = natural_coefficients(&pts).unwrap();
        for &(x, y) in &pts {
            assert!((evaluate(&k, &c, 0, x) - y).abs() < 1e-14);
        }
        assert!(evaluate(&k, &c, 2, 0.0).abs() < 1e-13);
        assert!(evaluate(&k, &c, 2, 4.0).abs() < 1e-13);
        for &x in &k {
            for order in 0..3 {
                let (l, r) = (
                    evaluate(&k, &c, order, x - 1e-9),
                    evaluate(&k, &c, order, x + 1e-9),
                );
                assert!((l - r).abs() < 1e-7, "order {order} at {x}: {l} vs {r}");
            }
        }
    }

    #[test]
    fn refuses_bad_tables() {
        assert_eq!(
            natural_coefficients(&[(0.0, 1.0)]),
            Err(SplineError::TooFewPoints { count: 1 })
        );
        assert!(matches!(
            natural_coefficients(&[(0.0, 1.0), (0.0, 2.0)]),
            Err(SplineError::NotIncreasing { index: 1, .. })
        ));
        assert!(matches!(
            natural_coefficients(&[(0.0, 1.0), (f64::NAN, 2.0)]),
            Err(SplineError::NotFinite { index: 1 })
        ));
    }
}
