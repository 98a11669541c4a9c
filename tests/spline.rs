//! The language's `spline(x, [(x0, y0), …])`: a natural cubic spline through the points, with
//! its derivatives generated wherever the equations need them.
//!
//! The knee below slides along the thigh as splines of the knee angle (a roll-glide knee).
//! A twin model takes the same curves as `extern fn`s computed here by another construction
//! (the natural spline's 4(n − 1) conditions solved as one dense system), with their
//! derivatives written out; M, h, the tangents and the batch functions of the two must agree.

use mbs::lanes::{pack, unpack};
use mbs::{F64x4, LANES, Model};
use nalgebra::{DMatrix, DVector};

mbs::multibody! {
    /// A thigh about the hip and a shank whose knee centre moves with the knee angle along
    /// natural cubic splines through measured-looking points.
    pub model SplineKnee {
        param m = 3.0; param l = 0.4;
        fn gx(a) = spline(a, [(-2.1, 0.012), (-1.4, 0.006), (-0.8, -0.003), (-0.3, -0.001), (0.0, 0.0), (0.2, 0.002)]);
        fn gy(a) = spline(a, [(-2.1, -0.008), (-1.0, -0.004), (-0.4, 0.001), (0.2, 0.0)]);
        dof hip = 0.3, qd = 1.0; dof knee = -0.6, qd = 2.0;
        body thigh { mass = m; inertia = (m * l * l / 12, 0.001, m * l * l / 12); }
        body shank { mass = m / 2; inertia = (0.01, 0.002, 0.01, 0.0001, 0, 0); }
        TOG[thigh] = Trotz(hip) * Tdisp(0, -l / 2, 0);
        TOG[shank] = TOG[thigh] * Tdisp(gx(knee), -l / 2 + gy(knee), 0) * Trotz(knee) * Tdisp(0, -l / 2, 0);
        gravity(0, -9.81, 0);
        option tangents;
        option batch;
    }
}

mbs::multibody! {
    /// The same knee with the curves as Rust functions of this file.
    pub model ExternKnee {
        param m = 3.0; param l = 0.4;
        extern fn gx = [curves::gx0, curves::gx1, curves::gx2, curves::gx3];
        extern fn gy = [curves::gy0, curves::gy1, curves::gy2, curves::gy3];
        dof hip = 0.3, qd = 1.0; dof knee = -0.6, qd = 2.0;
        body thigh { mass = m; inertia = (m * l * l / 12, 0.001, m * l * l / 12); }
        body shank { mass = m / 2; inertia = (0.01, 0.002, 0.01, 0.0001, 0, 0); }
        TOG[thigh] = Trotz(hip) * Tdisp(0, -l / 2, 0);
        TOG[shank] = TOG[thigh] * Tdisp(gx(knee), -l / 2 + gy(knee), 0) * Trotz(knee) * Tdisp(0, -l / 2, 0);
        gravity(0, -9.81, 0);
        option tangents;
    }
}

const GX: [(f64, f64); 6] = [
    (-2.1, 0.012),
    (-1.4, 0.006),
    (-0.8, -0.003),
    (-0.3, -0.001),
    (0.0, 0.0),
    (0.2, 0.002),
];
const GY: [(f64, f64); 4] = [(-2.1, -0.008), (-1.0, -0.004), (-0.4, 0.001), (0.2, 0.0)];

mod curves {
    use super::*;
    use std::sync::OnceLock;

    /// The natural cubic spline's pieces a + b s + c s² + d s³ from its conditions as one
    /// dense system: interpolation at both ends of each piece, C¹ and C² at inner knots,
    /// zero curvature at both ends.
    fn pieces(p: &[(f64, f64)]) -> Vec<[f64; 4]> {
        let n = p.len() - 1;
        let mut a = DMatrix::<f64>::zeros(4 * n, 4 * n);
        let mut b = DVector::<f64>::zeros(4 * n);
        let mut row = 0;
        for i in 0..n {
            let h = p[i + 1].0 - p[i].0;
            a[(row, 4 * i)] = 1.0;
            b[row] = p[i].1;
            row += 1;
            for k in 0..4 {
                a[(row, 4 * i + k)] = h.powi(k as i32);
            }
            b[row] = p[i + 1].1;
            row += 1;
            if i + 1 < n {
                // slope and curvature continuous at knot i + 1
                for k in 1..4 {
                    a[(row, 4 * i + k)] = k as f64 * h.powi(k as i32 - 1);
                }
                a[(row, 4 * (i + 1) + 1)] = -1.0;
                row += 1;
                a[(row, 4 * i + 2)] = 2.0;
                a[(row, 4 * i + 3)] = 6.0 * h;
                a[(row, 4 * (i + 1) + 2)] = -2.0;
                row += 1;
            }
        }
        a[(row, 2)] = 2.0;
        row += 1;
        let h = p[n].0 - p[n - 1].0;
        a[(row, 4 * (n - 1) + 2)] = 2.0;
        a[(row, 4 * (n - 1) + 3)] = 6.0 * h;
        let x = a
            .lu()
            .solve(&b)
            .expect("the spline's conditions are regular");
        (0..n)
            .map(|i| [x[4 * i], x[4 * i + 1], x[4 * i + 2], x[4 * i + 3]])
            .collect()
    }

    /// Derivative `order` at `x` (the knots' range only: the test stays inside it).
    fn eval(p: &[(f64, f64)], c: &[[f64; 4]], order: usize, x: f64) -> f64 {
        let i = (0..c.len())
            .rev()
            .find(|&i| x >= p[i].0)
            .expect("inside the table");
        let s = x - p[i].0;
        let c = c[i];
        match order {
            0 => c[0] + c[1] * s + c[2] * s * s + c[3] * s * s * s,
            1 => c[1] + 2.0 * c[2] * s + 3.0 * c[3] * s * s,
            2 => 2.0 * c[2] + 6.0 * c[3] * s,
            _ => 6.0 * c[3],
        }
    }

    fn gx(order: usize, x: f64) -> f64 {
        static C: OnceLock<Vec<[f64; 4]>> = OnceLock::new();
        eval(&GX, C.get_or_init(|| pieces(&GX)), order, x)
    }

    fn gy(order: usize, x: f64) -> f64 {
        static C: OnceLock<Vec<[f64; 4]>> = OnceLock::new();
        eval(&GY, C.get_or_init(|| pieces(&GY)), order, x)
    }

    pub fn gx0(x: f64) -> f64 {
        gx(0, x)
    }
    pub fn gx1(x: f64) -> f64 {
        gx(1, x)
    }
    pub fn gx2(x: f64) -> f64 {
        gx(2, x)
    }
    pub fn gx3(x: f64) -> f64 {
        gx(3, x)
    }
    pub fn gy0(x: f64) -> f64 {
        gy(0, x)
    }
    pub fn gy1(x: f64) -> f64 {
        gy(1, x)
    }
    pub fn gy2(x: f64) -> f64 {
        gy(2, x)
    }
    pub fn gy3(x: f64) -> f64 {
        gy(3, x)
    }
}

/// States across the table's intervals, with knee angles on knots too.
fn states() -> Vec<([f64; 2], [f64; 2])> {
    let knees = [-2.0, -1.4, -0.95, -0.4, -0.3, -0.05, 0.0, 0.15];
    knees
        .iter()
        .enumerate()
        .map(|(i, &k)| {
            (
                [0.2 - 0.1 * i as f64, k],
                [1.0 - 0.3 * i as f64, 2.5 - 0.7 * i as f64],
            )
        })
        .collect()
}

fn close(a: f64, b: f64, scale: f64) -> bool {
    (a - b).abs() <= 1e-12 * scale.max(1.0)
}

#[test]
fn spline_models_equal_an_independent_construction() {
    let (s, e) = (SplineKnee::default(), ExternKnee::default());
    let n = SplineKnee::NQ;
    for (q, qd) in states() {
        let (mut ms, mut hs) = (vec![0.0; n * n], vec![0.0; n]);
        let (mut me, mut he) = (vec![0.0; n * n], vec![0.0; n]);
        s.dynamics(0.0, &q, &qd, &[], &mut ms, &mut hs);
        e.dynamics(0.0, &q, &qd, &[], &mut me, &mut he);
        let scale = me.iter().chain(&he).fold(0.0f64, |m, v| m.max(v.abs()));
        for (x, y) in ms.iter().chain(&hs).zip(me.iter().chain(&he)) {
            assert!(close(*x, *y, scale), "M, h at q = {q:?}: {x} vs {y}");
        }
        // tangents: the curves' third derivatives enter through ∂h/∂q
        let qdd = [0.7, -1.3];
        let (mut ks, mut cs) = (vec![0.0; n * n], vec![0.0; n * n]);
        let (mut ke, mut ce) = (vec![0.0; n * n], vec![0.0; n * n]);
        s.tangents(0.0, &q, &qd, &qdd, &[], &mut ks, &mut cs)
            .unwrap();
        e.tangents(0.0, &q, &qd, &qdd, &[], &mut ke, &mut ce)
            .unwrap();
        let scale = ke.iter().chain(&ce).fold(0.0f64, |m, v| m.max(v.abs()));
        for (x, y) in ks.iter().chain(&cs).zip(ke.iter().chain(&ce)) {
            assert!(close(*x, *y, scale), "tangents at q = {q:?}: {x} vs {y}");
        }
    }
}

#[test]
fn spline_interpolates_its_points_in_the_kinematics() {
    // at knee angles on GX's knots, the shank's origin sits at the tabulated offset: with
    // the hip at 0 the knee centre is (gx, −l + gy) in the thigh's axes
    let model = SplineKnee::default();
    let l = model.params().l;
    let mut kin = mbs::Kinematics::new::<SplineKnee>();
    for &(x, y) in &GX {
        let q = [0.0, x];
        model.kinematics(0.0, &q, &[0.0, 0.0], &mut kin);
        let shank = &kin.frames[1].pose;
        // the shank's origin is l/2 below the knee centre along its own rotated axis
        let (s, c) = x.sin_cos();
        let expect = [y + l / 2.0 * s, -l + curves::gy0(x) - l / 2.0 * c];
        assert!((shank.position[0] - expect[0]).abs() < 1e-14, "x at {x}");
        assert!((shank.position[1] - expect[1]).abs() < 1e-14, "y at {x}");
    }
}

#[test]
fn spline_in_batch_code_equals_one_state_code() {
    const { assert!(SplineKnee::BATCH_GENERATED) };
    let model = SplineKnee::default();
    let n = SplineKnee::NQ;
    let st = states();
    let (mut q, mut qd) = (vec![F64x4::splat(0.0); n], vec![F64x4::splat(0.0); n]);
    pack([&st[0].0, &st[1].0, &st[2].0, &st[3].0], &mut q);
    pack([&st[0].1, &st[1].1, &st[2].1, &st[3].1], &mut qd);
    let mut m4 = vec![F64x4::splat(0.0); n * n];
    let mut h4 = vec![F64x4::splat(0.0); n];
    model.dynamics_x4(F64x4::splat(0.0), &q, &qd, &[], &mut m4, &mut h4);
    for (k, (q, qd)) in st.iter().take(LANES).enumerate() {
        let (mut m, mut h) = (vec![0.0; n * n], vec![0.0; n]);
        model.dynamics(0.0, q, qd, &[], &mut m, &mut h);
        let (mut mk, mut hk) = (vec![0.0; n * n], vec![0.0; n]);
        unpack(&m4, k, &mut mk);
        unpack(&h4, k, &mut hk);
        let scale = m.iter().chain(&h).fold(0.0f64, |a, v| a.max(v.abs()));
        for (x, y) in mk.iter().chain(&hk).zip(m.iter().chain(&h)) {
            // the lanes' sin and cos are within an ulp or two of the standard library's
            assert!((x - y).abs() <= 1e-13 * scale, "lane {k}: {x} vs {y}");
        }
    }
}
