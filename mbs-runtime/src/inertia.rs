//! Physical admissibility of an inertia tensor. Dependency-free: the generator includes this
//! file too, so compile-time and run-time checks are the same code.

/// Why the tensor (xx, yy, zz, xy, xz, yz) about G is not a rigid body's, if it is not:
/// principal moments must be finite, non-negative and satisfy the triangle inequality.
pub fn inertia_problem(t: [f64; 6]) -> Option<String> {
    if t.iter().any(|x| !x.is_finite()) {
        return Some("its components must be finite".into());
    }
    let p = principal_moments(t);
    let scale = p.iter().fold(0.0f64, |m, y| m.max(y.abs()));
    if p.iter().any(|&x| x < -1e-12 * scale) {
        return Some(format!("principal moments {p:?} must not be negative"));
    }
    for i in 0..3 {
        let (a, b, c) = (p[i], p[(i + 1) % 3], p[(i + 2) % 3]);
        if a > b + c + 1e-12 * scale {
            return Some(format!(
                "principal moments {p:?} violate the triangle inequality ({a} > {b} + {c}): no rigid body has this inertia"
            ));
        }
    }
    None
}

/// Eigenvalues of the symmetric tensor (xx, yy, zz, xy, xz, yz).
pub fn principal_moments(t: [f64; 6]) -> [f64; 3] {
    principal_axes(t).0
}

/// Eigenvalues of the symmetric tensor (xx, yy, zz, xy, xz, yz) and its eigenvectors as the
/// columns of a rotation (determinant +1), by cyclic Jacobi rotations; a diagonal tensor
/// gives the identity.
pub fn principal_axes(t: [f64; 6]) -> ([f64; 3], [[f64; 3]; 3]) {
    let mut a = [[t[0], t[3], t[4]], [t[3], t[1], t[5]], [t[4], t[5], t[2]]];
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..50 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        let diag = a[0][0].abs() + a[1][1].abs() + a[2][2].abs();
        if off == 0.0 || off <= 1e-17 * diag {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let tt = if theta == 0.0 {
                1.0
            } else {
                theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt())
            };
            let c = 1.0 / (tt * tt + 1.0).sqrt();
            let s = tt * c;
            for row in a.iter_mut() {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - s * akq;
                row[q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let (apk, aqk) = (a[p][k], a[q][k]);
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            for row in v.iter_mut() {
                let (vkp, vkq) = (row[p], row[q]);
                row[p] = c * vkp - s * vkq;
                row[q] = s * vkp + c * vkq;
            }
        }
    }
    let det = v[0][0] * (v[1][1] * v[2][2] - v[1][2] * v[2][1])
        - v[0][1] * (v[1][0] * v[2][2] - v[1][2] * v[2][0])
        + v[0][2] * (v[1][0] * v[2][1] - v[1][1] * v[2][0]);
    if det < 0.0 {
        for row in v.iter_mut() {
            row[2] = -row[2];
        }
    }
    ([a[0][0], a[1][1], a[2][2]], v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn principal_moments_of_a_rotated_box() {
        // diag(1, 2, 2.5) rotated by 30° about z
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let xx = c * c * 1.0 + s * s * 2.0;
        let yy = s * s * 1.0 + c * c * 2.0;
        let xy = c * s * (1.0 - 2.0);
        let mut p = principal_moments([xx, yy, 2.5, xy, 0.0, 0.0]);
        p.sort_by(f64::total_cmp);
        for (a, b) in p.iter().zip([1.0, 2.0, 2.5]) {
            assert!((a - b).abs() < 1e-12, "{p:?}");
        }
    }

    #[test]
    fn triangle_inequality_is_enforced() {
        assert!(inertia_problem([1.0, 1.0, 1.5, 0.0, 0.0, 0.0]).is_none());
        assert!(
            inertia_problem([1.0, 1.0, 2.5, 0.0, 0.0, 0.0])
                .unwrap()
                .contains("triangle")
        );
        assert!(
            inertia_problem([-1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
                .unwrap()
                .contains("negative")
        );
        // a thin rod (m l²/12, 0, m l²/12) is on the edge and valid
        assert!(inertia_problem([1.0 / 12.0, 0.0, 1.0 / 12.0, 0.0, 0.0, 0.0]).is_none());
    }
}
