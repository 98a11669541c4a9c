//! Force elements for efforts written in Rust ([`crate::Efforts`]): the same laws as the
//! DSL's `contact`, `bushing` and preloaded `spring` (see `mbs::language`), evaluated on the
//! generated kinematics and applied through an [`Effort`].
//!
//! - [`PlaneContact`]: a point, or a sphere of radius r centred at a frame's origin, against
//!   the plane n·x = h0: δ = h0 + r − n·x, F_n = step(δ)·pos(k δ − c n·v),
//!   F_t = −μ F_n v_t / √(v_t·v_t + eps²) with v_t the tangential velocity of the contact
//!   point x − r n; the force F_n n + F_t at the centre and the torque (−r n) × F_t.
//! - [`SpringDamper`]: tension F0 + k(l − l0) + c l̇ along the line between two anchors
//!   (declared points or body origins).
//! - [`Bushing`]: between frames A (or the ground) and B, in A's axes: force on B
//!   f = −K Δp − C Δv with Δp = R_Aᵀ(p_B − p_A), Δv its rate; torque on B
//!   m = −Eᵀ K_r θ − C_r Ω with θ = ½(R₃₂ − R₂₃, R₁₃ − R₃₁, R₂₁ − R₁₂), R = R_Aᵀ R_B,
//!   E = ½(tr R·I − R), Ω = R_Aᵀ(ω_B − ω_A); the opposite on A.
//! - [`Path`]: a path through declared points (a cable's, a muscle's): length, lengthening
//!   speed and ∂l/∂q from the points' kinematics, a tension applied along it.

use crate::efforts::Effort;
use crate::model::{Kinematics, ModelInfo};

type V3 = [f64; 3];

/// a · b
pub(crate) fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn scale(k: f64, a: V3) -> V3 {
    [k * a[0], k * a[1], k * a[2]]
}

/// a × b
pub(crate) fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Rᵀ x for a rotation stored `r[i][j]` (columns: the frame's axes in world axes).
fn rt(r: &[[f64; 3]; 3], x: V3) -> V3 {
    [
        r[0][0] * x[0] + r[1][0] * x[1] + r[2][0] * x[2],
        r[0][1] * x[0] + r[1][1] * x[1] + r[2][1] * x[2],
        r[0][2] * x[0] + r[1][2] * x[1] + r[2][2] * x[2],
    ]
}

/// R x.
fn rx(r: &[[f64; 3]; 3], x: V3) -> V3 {
    [dot(r[0], x), dot(r[1], x), dot(r[2], x)]
}

/// Regularised Coulomb friction μ f_n / √(|v_t|² + ε²), the force per unit of sliding
/// speed: 0 at rest when ε = 0 (exact Coulomb, whose direction at rest is undefined; 0/0
/// before).
pub(crate) fn friction_per_speed(mu: f64, f_n: f64, vt2: f64, eps: f64) -> f64 {
    let speed = (vt2 + eps * eps).sqrt();
    // a NaN speed (a NaN velocity or ε) gives NaN, not a silent 0
    if speed > 0.0 || speed.is_nan() {
        mu * f_n / speed
    } else {
        0.0
    }
}

/// Contact of a point or a sphere with a fixed plane (penalty, non-adhesive damping,
/// regularised Coulomb friction).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneContact {
    /// unit normal out of the ground, and the plane n·x = offset
    pub normal: V3,
    pub offset: f64,
    /// sphere radius (0: a point)
    pub radius: f64,
    /// stiffness (N/m), damping (N s/m), friction coefficient, regularising speed (m/s; 0:
    /// exact Coulomb, no friction at rest and a discontinuous force, stiff for a scheme)
    pub k: f64,
    pub c: f64,
    pub mu: f64,
    pub eps: f64,
}

impl Default for PlaneContact {
    /// The ground z = 0, a point, k = 1e5 N/m, c = 500 N s/m, μ = 0.8, eps = 1e-4 m/s.
    fn default() -> Self {
        PlaneContact {
            normal: [0.0, 0.0, 1.0],
            offset: 0.0,
            radius: 0.0,
            k: 1e5,
            c: 500.0,
            mu: 0.8,
            eps: 1e-4,
        }
    }
}

/// What a contact did: penetration, normal force, and the force and torque (about the
/// centre) it applied, world axes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactForce {
    pub penetration: f64,
    pub normal_force: f64,
    pub force: V3,
    pub torque: V3,
}

impl PlaneContact {
    /// The contact force on a centre at `x` moving with `v`, the body turning at `w`.
    pub fn force(&self, x: V3, v: V3, w: V3) -> ContactForce {
        let n = self.normal;
        let delta = self.offset + self.radius - dot(n, x);
        let nv = dot(n, v);
        // never pulling; NaN stays NaN (a clamp by `max` would make it a silent 0)
        let push = self.k * delta - self.c * nv;
        let f_n = if delta.is_nan() || delta > 0.0 && push.is_nan() {
            f64::NAN
        } else if delta > 0.0 {
            push.max(0.0)
        } else {
            0.0
        };
        let mut force = scale(f_n, n);
        let mut torque = [0.0; 3];
        if self.mu != 0.0 {
            let arm = scale(-self.radius, n);
            let vc = add(v, cross(w, arm));
            let vt = sub(vc, scale(nv, n));
            let coef = -friction_per_speed(self.mu, f_n, dot(vt, vt), self.eps);
            let ft = scale(coef, vt);
            force = add(force, ft);
            torque = cross(arm, ft);
        }
        ContactForce {
            penetration: delta,
            normal_force: f_n,
            force,
            torque,
        }
    }

    /// A contact at declared point `i`. A point has no rotation of its own: with a radius,
    /// the sphere centred there slides without turning, its friction applied at the centre
    /// and the returned `torque` (about the centre) not applied; a sphere that rolls belongs
    /// at a frame ([`PlaneContact::apply_to_frame`]).
    pub fn apply_to_point(&self, e: &mut Effort, i: usize) -> ContactForce {
        let p = e.point(i);
        let f = self.force(p.position, p.velocity, [0.0; 3]);
        e.force_at_point(i, f.force);
        f
    }

    /// A sphere centred at frame `i`'s origin.
    pub fn apply_to_frame(&self, e: &mut Effort, i: usize) -> ContactForce {
        let k = e.frame(i);
        let (x, v, w) = (k.pose.position, k.velocity, k.angular_velocity);
        let f = self.force(x, v, w);
        e.force_on_frame(i, x, f.force);
        e.torque_on_frame(i, f.torque);
        f
    }
}

/// Where an element attaches: a declared point, or a body's (frame's) origin.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Anchor {
    Point(usize),
    Frame(usize),
}

impl Anchor {
    /// Position and velocity, world axes.
    fn state(self, e: &Effort) -> (V3, V3) {
        match self {
            Anchor::Point(i) => (e.point(i).position, e.point(i).velocity),
            Anchor::Frame(i) => (e.frame(i).pose.position, e.frame(i).velocity),
        }
    }

    fn push(self, e: &mut Effort, at: V3, f: V3) {
        match self {
            Anchor::Point(i) => e.force_at_point(i, f),
            Anchor::Frame(i) => e.force_on_frame(i, at, f),
        }
    }
}

/// `d / l` (l = |d|), or zero where the two ends coincide and the direction is undefined
/// (1/0 times 0 was NaN).
fn unit_or_zero(d: V3, l: f64) -> V3 {
    if l > 0.0 { scale(1.0 / l, d) } else { [0.0; 3] }
}

/// A spring–damper with preload between two anchors: tension F0 + k(l − l0) + c l̇. Where
/// the anchors coincide its line, and so its force, is undefined: it pulls nothing.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpringDamper {
    pub k: f64,
    pub l0: f64,
    pub c: f64,
    pub preload: f64,
}

impl SpringDamper {
    /// Applies the tension between `a` and `b`; returns it (0 where the anchors coincide:
    /// it returned F0 − k l0 there, a tension it did not apply).
    pub fn apply(&self, e: &mut Effort, a: Anchor, b: Anchor) -> f64 {
        let ((pa, va), (pb, vb)) = (a.state(e), b.state(e));
        let d = sub(pb, pa);
        let l = dot(d, d).sqrt();
        if l == 0.0 {
            return 0.0;
        }
        let u = unit_or_zero(d, l);
        let ldot = dot(u, sub(vb, va));
        let tension = self.preload + self.k * (l - self.l0) + self.c * ldot;
        // tension pulls b towards a and a towards b
        b.push(e, pb, scale(-tension, u));
        a.push(e, pa, scale(tension, u));
        tension
    }
}

/// A 6-axis linear spring–damper between two frames, in the first frame's axes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Bushing {
    pub k: V3,
    pub kr: V3,
    pub c: V3,
    pub cr: V3,
}

impl Bushing {
    /// Applies the bushing between frame `a` (`None`: the ground) and frame `b`; returns the
    /// force and torque on `b` in `a`'s axes.
    pub fn apply(&self, e: &mut Effort, a: Option<usize>, b: usize) -> (V3, V3) {
        let ident = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let (ra, pa, va, wa) = match a {
            Some(i) => {
                let k = e.frame(i);
                (
                    k.pose.rotation,
                    k.pose.position,
                    k.velocity,
                    k.angular_velocity,
                )
            }
            None => (ident, [0.0; 3], [0.0; 3], [0.0; 3]),
        };
        let kb = e.frame(b);
        let (rb, pb, vb, wb) = (
            kb.pose.rotation,
            kb.pose.position,
            kb.velocity,
            kb.angular_velocity,
        );
        let d = sub(pb, pa);
        let dp = rt(&ra, d);
        let dv = rt(&ra, sub(sub(vb, va), cross(wa, d)));
        // R = R_Aᵀ R_B
        let mut r = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                r[i][j] = (0..3).map(|k| ra[k][i] * rb[k][j]).sum();
            }
        }
        let theta = [
            0.5 * (r[2][1] - r[1][2]),
            0.5 * (r[0][2] - r[2][0]),
            0.5 * (r[1][0] - r[0][1]),
        ];
        let omega = rt(&ra, sub(wb, wa));
        let tr = r[0][0] + r[1][1] + r[2][2];
        // Eᵀ = ½ (tr R·I − Rᵀ)
        let krt = [
            self.kr[0] * theta[0],
            self.kr[1] * theta[1],
            self.kr[2] * theta[2],
        ];
        let et_krt = [
            0.5 * (tr * krt[0] - (r[0][0] * krt[0] + r[1][0] * krt[1] + r[2][0] * krt[2])),
            0.5 * (tr * krt[1] - (r[0][1] * krt[0] + r[1][1] * krt[1] + r[2][1] * krt[2])),
            0.5 * (tr * krt[2] - (r[0][2] * krt[0] + r[1][2] * krt[1] + r[2][2] * krt[2])),
        ];
        let f: V3 = std::array::from_fn(|i| -self.k[i] * dp[i] - self.c[i] * dv[i]);
        let m: V3 = std::array::from_fn(|i| -et_krt[i] - self.cr[i] * omega[i]);
        let (fw, mw) = (rx(&ra, f), rx(&ra, m));
        e.force_on_frame(b, pb, fw);
        e.torque_on_frame(b, mw);
        if let Some(i) = a {
            e.force_on_frame(i, pb, scale(-1.0, fw));
            e.torque_on_frame(i, scale(-1.0, mw));
        }
        (f, m)
    }
}

/// Why [`Path::through`] could not build a path.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum PathError {
    #[error(
        "model `{model}` has no point `{name}`: declare it in the multibody! block, `point {name} on BODY at (x, y, z);`"
    )]
    NoPoint { model: &'static str, name: String },
    #[error("a path needs at least two points, its origin and its insertion; {found} given")]
    TooShort { found: usize },
}

/// A path through declared points (origin, via points, insertion) along which a cable or a
/// muscle pulls: its length l = Σ |p_{i+1} − p_i|, lengthening speed l̇ and gradient ∂l/∂q
/// from the generated kinematics of the points (exact: the gradient is Σ u_iᵀ (J_{i+1} − J_i)
/// with u_i the unit vector of segment i and J the points' Jacobians), so the moment arms
/// −∂l/∂q are those of the kinematics, not of differences. A tension T acts at each point
/// along its segments, pulling consecutive points together; its generalised force is
/// −T ∂l/∂q. A segment whose two points coincide has no direction: it adds its length (0)
/// and nothing to l̇, ∂l/∂q or the forces.
///
/// Build it with [`Path::through`], which checks the names. Its methods index the
/// kinematics' points by `points`, and panic on an index the model does not have (a path
/// built by hand for another model).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Path {
    /// the declared points (`ModelInfo::point_index`), from origin to insertion
    pub points: Vec<usize>,
}

impl Path {
    /// The path through the declared points named `names` of the model `info`, from origin
    /// to insertion: a typed error for a name the model does not declare, or fewer than two.
    pub fn through(info: &ModelInfo, names: &[&str]) -> Result<Path, PathError> {
        if names.len() < 2 {
            return Err(PathError::TooShort { found: names.len() });
        }
        let points = names
            .iter()
            .map(|&name| {
                info.point_index(name).ok_or_else(|| PathError::NoPoint {
                    model: info.name,
                    name: name.to_string(),
                })
            })
            .collect::<Result<_, _>>()?;
        Ok(Path { points })
    }

    fn segments<'a>(&'a self, kin: &'a Kinematics) -> impl Iterator<Item = (V3, V3, f64)> + 'a {
        self.points.windows(2).map(|w| {
            let (a, b) = (&kin.points[w[0]], &kin.points[w[1]]);
            let d = sub(b.position, a.position);
            let l = dot(d, d).sqrt();
            (unit_or_zero(d, l), sub(b.velocity, a.velocity), l)
        })
    }

    /// Length and lengthening speed at the kinematics `kin`.
    pub fn length(&self, kin: &Kinematics) -> (f64, f64) {
        self.segments(kin)
            .fold((0.0, 0.0), |(l, ld), (u, dv, s)| (l + s, ld + dot(u, dv)))
    }

    /// ∂l/∂q into `out` (one entry per coordinate of the model whose kinematics `kin` are:
    /// the wrapped model's, without a `WithEfforts` model's extra states); the moment arm
    /// about coordinate i is `−out[i]`. Panics when `out` is longer than that.
    pub fn gradient(&self, kin: &Kinematics, out: &mut [f64]) {
        out.fill(0.0);
        for (w, (u, _, _)) in self.points.windows(2).zip(self.segments(kin)) {
            let (ja, jb) = (&kin.points[w[0]].jv, &kin.points[w[1]].jv);
            for (i, g) in out.iter_mut().enumerate() {
                *g += (0..3)
                    .map(|r| u[r] * (jb[3 * i + r] - ja[3 * i + r]))
                    .sum::<f64>();
            }
        }
    }

    /// Applies the tension `tension` (N) along the path: each segment pulls its two ends
    /// toward each other.
    pub fn apply(&self, e: &mut Effort, tension: f64) {
        let kin = e.kin;
        for (w, (u, _, _)) in self.points.windows(2).zip(self.segments(kin)) {
            e.force_at_point(w[0], scale(tension, u));
            e.force_at_point(w[1], scale(-tension, u));
        }
    }
}
