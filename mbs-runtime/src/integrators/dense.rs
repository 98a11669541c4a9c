//! Dense output between two accepted states: the quintic Hermite interpolant the driver
//! uses by default, and λ's linear one.

use super::State;

/// Quintic Hermite interpolation of q between two states (qd and qdd from its derivatives).
pub(crate) fn hermite5(s0: &State, s1: &State, t: f64, out: &mut State) {
    let h = s1.t - s0.t;
    out.t = t;
    if h == 0.0 {
        out.copy_from(s1);
        return;
    }
    let s = (t - s0.t) / h;
    let (s2, s3, s4, s5) = (s * s, s * s * s, s * s * s * s, s * s * s * s * s);
    // basis and its first and second derivatives in s
    let b = [
        1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5,
        s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5,
        0.5 * s2 - 1.5 * s3 + 1.5 * s4 - 0.5 * s5,
        0.5 * s3 - s4 + 0.5 * s5,
        -4.0 * s3 + 7.0 * s4 - 3.0 * s5,
        10.0 * s3 - 15.0 * s4 + 6.0 * s5,
    ];
    let d = [
        -30.0 * s2 + 60.0 * s3 - 30.0 * s4,
        1.0 - 18.0 * s2 + 32.0 * s3 - 15.0 * s4,
        s - 4.5 * s2 + 6.0 * s3 - 2.5 * s4,
        1.5 * s2 - 4.0 * s3 + 2.5 * s4,
        -12.0 * s2 + 28.0 * s3 - 15.0 * s4,
        30.0 * s2 - 60.0 * s3 + 30.0 * s4,
    ];
    let dd = [
        -60.0 * s + 180.0 * s2 - 120.0 * s3,
        -36.0 * s + 96.0 * s2 - 60.0 * s3,
        1.0 - 9.0 * s + 18.0 * s2 - 10.0 * s3,
        3.0 * s - 12.0 * s2 + 10.0 * s3,
        -24.0 * s + 84.0 * s2 - 60.0 * s3,
        60.0 * s - 180.0 * s2 + 120.0 * s3,
    ];
    for i in 0..s0.q.len() {
        let c = [
            s0.q[i],
            h * s0.qd[i],
            h * h * s0.qdd[i],
            h * h * s1.qdd[i],
            h * s1.qd[i],
            s1.q[i],
        ];
        let dot = |w: &[f64; 6]| w.iter().zip(&c).map(|(a, b)| a * b).sum::<f64>();
        out.q[i] = dot(&b);
        out.qd[i] = dot(&d) / h;
        out.qdd[i] = dot(&dd) / (h * h);
    }
    lerp_lambda(s0, s1, t, out);
}

/// λ between two states: linear (the states carry no derivative of λ).
pub(crate) fn lerp_lambda(s0: &State, s1: &State, t: f64, out: &mut State) {
    let h = s1.t - s0.t;
    let s = if h == 0.0 { 1.0 } else { (t - s0.t) / h };
    for i in 0..s0.lambda.len() {
        out.lambda[i] = (1.0 - s) * s0.lambda[i] + s * s1.lambda[i];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quintic_hermite_reproduces_quintics() {
        let f = |t: f64| {
            (
                1.0 - 2.0 * t + 0.5 * t * t - t.powi(3) + 0.25 * t.powi(4) - 0.1 * t.powi(5),
                -2.0 + t - 3.0 * t * t + t.powi(3) - 0.5 * t.powi(4),
                1.0 - 6.0 * t + 3.0 * t * t - 2.0 * t.powi(3),
            )
        };
        let st = |t: f64| {
            let (q, v, a) = f(t);
            State {
                t,
                q: vec![q],
                qd: vec![v],
                qdd: vec![a],
                lambda: vec![],
            }
        };
        let (s0, s1) = (st(0.3), st(1.1));
        let mut out = State::zeros(1, 0);
        for t in [0.3, 0.5, 0.77, 1.1] {
            hermite5(&s0, &s1, t, &mut out);
            let (q, v, a) = f(t);
            assert!(
                (out.q[0] - q).abs() < 1e-13
                    && (out.qd[0] - v).abs() < 1e-12
                    && (out.qdd[0] - a).abs() < 1e-11
            );
        }
    }
}
