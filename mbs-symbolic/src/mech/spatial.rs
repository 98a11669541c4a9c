//! 3-vectors and 3×3 matrices of expressions. Zeros and ones fold in the arena, so products
//! with elementary rotations cost only what their non-zero entries cost.

use crate::expr::{Arena, ExprId};

pub type V3 = [ExprId; 3];
/// Row-major: `m[i][j]`.
pub type M3 = [[ExprId; 3]; 3];
/// A dense matrix of expressions of any size, row-major.
pub type Matrix = Vec<Vec<ExprId>>;

pub fn zero3(a: &Arena) -> V3 {
    [a.zero(); 3]
}

pub fn identity(a: &Arena) -> M3 {
    let (z, o) = (a.zero(), a.one());
    [[o, z, z], [z, o, z], [z, z, o]]
}

pub fn add(a: &mut Arena, x: V3, y: V3) -> V3 {
    [a.add(x[0], y[0]), a.add(x[1], y[1]), a.add(x[2], y[2])]
}

pub fn sub(a: &mut Arena, x: V3, y: V3) -> V3 {
    [a.sub(x[0], y[0]), a.sub(x[1], y[1]), a.sub(x[2], y[2])]
}

pub fn neg(a: &mut Arena, x: V3) -> V3 {
    [a.neg(x[0]), a.neg(x[1]), a.neg(x[2])]
}

pub fn scale(a: &mut Arena, s: ExprId, x: V3) -> V3 {
    [a.mul(s, x[0]), a.mul(s, x[1]), a.mul(s, x[2])]
}

pub fn dot(a: &mut Arena, x: V3, y: V3) -> ExprId {
    a.dot(&x, &y)
}

pub fn cross(a: &mut Arena, x: V3, y: V3) -> V3 {
    let c = |a: &mut Arena, i: usize, j: usize| {
        let p = a.mul(x[i], y[j]);
        let q = a.mul(x[j], y[i]);
        a.sub(p, q)
    };
    [c(a, 1, 2), c(a, 2, 0), c(a, 0, 1)]
}

/// M x
pub fn mul_mv(a: &mut Arena, m: &M3, x: V3) -> V3 {
    [a.dot(&m[0], &x), a.dot(&m[1], &x), a.dot(&m[2], &x)]
}

/// Mᵀ x
pub fn mul_mtv(a: &mut Arena, m: &M3, x: V3) -> V3 {
    let col = |j: usize| [m[0][j], m[1][j], m[2][j]];
    [a.dot(&col(0), &x), a.dot(&col(1), &x), a.dot(&col(2), &x)]
}

/// Mᵀ
pub fn transpose(m: &M3) -> M3 {
    [
        [m[0][0], m[1][0], m[2][0]],
        [m[0][1], m[1][1], m[2][1]],
        [m[0][2], m[1][2], m[2][2]],
    ]
}

/// A B
pub fn mul_mm(a: &mut Arena, x: &M3, y: &M3) -> M3 {
    let mut r = identity(a);
    for i in 0..3 {
        for j in 0..3 {
            let col = [y[0][j], y[1][j], y[2][j]];
            r[i][j] = a.dot(&x[i], &col);
        }
    }
    r
}

/// Symmetric matrix from components xx, yy, zz, xy, xz, yz.
pub fn sym(t: &[ExprId; 6]) -> M3 {
    [[t[0], t[3], t[4]], [t[3], t[1], t[5]], [t[4], t[5], t[2]]]
}

/// The chart of rotation joint `j`: the run-time matrix `Var::Chart(9 j + 3 r + c)`.
pub fn chart(a: &mut Arena, j: u16) -> M3 {
    let e = |a: &mut Arena, r: u16, c: u16| a.var(crate::expr::Var::Chart(9 * j + 3 * r + c));
    [0, 1, 2].map(|r| [e(a, r, 0), e(a, r, 1), e(a, r, 2)])
}

/// Rotation by `angle` about the unit `axis` (columns: the rotated frame's axes). Coordinate
/// axes give the elementary matrices directly; other axes use Rodrigues' formula.
pub fn rotation(a: &mut Arena, axis: V3, angle: ExprId) -> M3 {
    let c = a.cos(angle);
    let s = a.sin(angle);
    let nums: Option<Vec<f64>> = axis.iter().map(|&e| a.as_num(e)).collect();
    if let Some(n) = nums {
        for k in 0..3 {
            if n[k].abs() == 1.0 && n[(k + 1) % 3] == 0.0 && n[(k + 2) % 3] == 0.0 {
                let s = if n[k] < 0.0 { a.neg(s) } else { s };
                let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                let ns = a.neg(s);
                let mut r = identity(a);
                r[i][i] = c;
                r[j][j] = c;
                r[i][j] = ns;
                r[j][i] = s;
                return r;
            }
        }
    }
    let one = a.one();
    let omc = a.sub(one, c);
    let mut r = identity(a);
    for i in 0..3 {
        for j in 0..3 {
            let nn = a.mul(axis[i], axis[j]);
            let mut e = a.mul(nn, omc);
            if i == j {
                e = a.add(e, c);
            } else {
                // + s [n]x (i, j): [n]x = [[0, -nz, ny], [nz, 0, -nx], [-ny, nx, 0]]
                let k = 3 - i - j;
                let sk = a.mul(s, axis[k]);
                let positive = (j + 1) % 3 == i;
                e = if positive { a.add(e, sk) } else { a.sub(e, sk) };
            }
            r[i][j] = e;
        }
    }
    r
}

/// Velocity and acceleration of a point displaced by d (d's rate ḋ, acceleration d̈, all in
/// the same axes as the motion of the frame it starts from: ω, α, v, a):
/// v' = v + ω × d + ḋ, a' = a + α × d + ω × (ω × d) + 2 ω × ḋ + d̈.
#[allow(clippy::too_many_arguments)]
pub fn displaced_motion(
    a: &mut Arena,
    w: V3,
    al: V3,
    v: V3,
    acc: V3,
    d: V3,
    dd: V3,
    ddd: V3,
) -> (V3, V3) {
    let wxd = cross(a, w, d);
    let v1 = add(a, v, wxd);
    let v1 = add(a, v1, dd);
    let t1 = cross(a, al, d);
    let t2 = cross(a, w, wxd);
    let two = a.num(2.0);
    let t3 = cross(a, w, dd);
    let t3 = scale(a, two, t3);
    let mut a1 = add(a, acc, t1);
    a1 = add(a, a1, t2);
    a1 = add(a, a1, t3);
    (v1, add(a, a1, ddd))
}
