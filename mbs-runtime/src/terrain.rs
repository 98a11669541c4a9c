//! Terrain for contacts written in Rust ([`crate::Efforts`]): the ground plane and boxes
//! standing on it, touched by points (a walking robot's feet) or by ellipsoids fixed on bodies
//! (a human's feet), with the law of the language's `contact` statement.
//!
//! **Geometry.** The ground is the plane of height 0 along the axis `up` (z by default, y for
//! models in OpenSim's axes); a [`Block`] is a box from the ground to `height`, its footprint
//! `min`…`max` along the two other axes in increasing order (x and y when z is up, x and z
//! when y is up).
//!
//! **An ellipsoid against a surface.** For a face of outward normal n, the ellipsoid (semi-axes
//! D = diag(a, b, c) along its body's axes R, centred at x) reaches deepest through it at its
//! support point along −n, s = x − R D² m / √(mᵀ D² m) with m = Rᵀ n, as the language's
//! ellipsoid contact (`mech/effects/contact.rs`) computes symbolically against its plane; the
//! penetration δ is how far s lies behind the face. Against a box the way out that is
//! shortest decides: over every unit n, the separation s(n) = n·(x − c) − Σ hᵢ|nᵢ| − √(nᵀQn)
//! (c and h the box's centre and half-sizes, Q = R D² Rᵀ: the box's and the ellipsoid's
//! support functions) is largest along the normal of that way out, and the ellipsoid
//! overlaps the box when that largest s is negative; it touches through the plane of normal n
//! at depth −s, at its support point along −n. Along a face's normal s is minus the depth
//! behind that face; near an edge or a corner the largest s is reached between faces, at the
//! signed distance from the edge or the corner to the ellipsoid (an ellipse's, projected
//! across the edge), so an ellipsoid beside an edge, behind the planes of both faces but
//! clear of the box, does not touch it, and one pressed on the edge is pushed away from the
//! edge rather than out of a face. A point is an ellipsoid of no extent: s = x, and the rule
//! is the point's usual one (inside the box, the nearest face). The ground and every box an
//! ellipsoid overlaps each push on it; a point inside a box and below the ground is pushed
//! by both.
//!
//! **The law** ([`ContactLaw`], the language's with Hunt–Crossley's terms): δ̇ = −n·v_s with
//! v_s the velocity of the body's material point at s, F_n = pos(k δ^e (1 + d δ̇) + c δ̇) for
//! δ > 0, regularised Coulomb friction F_t = −μ F_n v_t / √(v_t·v_t + ε²) with v_t the part
//! of v_s along the face; the force F_n n + F_t acts at s.

use crate::efforts::Effort;
use crate::elements::{cross, dot};

type V3 = [f64; 3];

/// A box standing on the ground: its footprint along the two horizontal axes (in increasing
/// order of axis) and its height (m). A box that is no box (min ≥ max along an axis, a
/// height ≤ 0, or a bound not finite) makes the terrain's heights NaN and every ellipsoid
/// and point touch it at a NaN depth, so that a run stops on its first contact force: it
/// vanished silently, and what was meant to stand on it fell through.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Block {
    pub min: [f64; 2],
    pub max: [f64; 2],
    pub height: f64,
}

impl Block {
    /// Whether the box is one: min < max along both axes, a height > 0, all finite.
    pub fn is_box(&self) -> bool {
        (0..2).all(|j| {
            self.min[j] < self.max[j] && self.min[j].is_finite() && self.max[j].is_finite()
        }) && self.height > 0.0
            && self.height.is_finite()
    }
}

/// The penalty law of a contact: F_n = pos(k δ^e (1 + d δ̇) + c δ̇) in contact (δ > 0) and
/// regularised Coulomb friction (the language's `contact(…, k, c, exponent, dissipation, mu,
/// eps)`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactLaw {
    /// stiffness k (N/m^e), damping c (N·s/m), exponent e, Hunt–Crossley dissipation d (s/m)
    pub k: f64,
    pub c: f64,
    pub exponent: f64,
    pub dissipation: f64,
    /// friction coefficient μ and regularising speed ε (m/s)
    pub mu: f64,
    pub eps: f64,
}

impl Default for ContactLaw {
    /// Linear: k = 1e5 N/m, c = 500 N·s/m, μ = 0.8, ε = 2e-2 m/s (the walking hexapod's).
    fn default() -> Self {
        ContactLaw {
            k: 1e5,
            c: 500.0,
            exponent: 1.0,
            dissipation: 0.0,
            mu: 0.8,
            eps: 2e-2,
        }
    }
}

impl ContactLaw {
    /// The force (world axes) on a body at depth `depth` behind a face of outward unit
    /// normal `n`, its material point there moving at `v`; zero out of contact, NaN at a
    /// NaN depth.
    #[inline]
    pub fn force(&self, depth: f64, n: V3, v: V3) -> V3 {
        // a NaN depth gives a NaN force (the clamp of f_n below would make it 0)
        if depth.is_nan() {
            return [f64::NAN; 3];
        }
        if depth <= 0.0 {
            return [0.0; 3];
        }
        let vn = dot(n, v);
        let elastic = if self.exponent == 1.0 {
            self.k * depth
        } else {
            self.k * depth.powf(self.exponent)
        };
        let f_n = (elastic * (1.0 - self.dissipation * vn) - self.c * vn).max(0.0);
        let vt = [0, 1, 2].map(|j| v[j] - vn * n[j]);
        let scale = if self.mu == 0.0 {
            0.0
        } else {
            crate::elements::friction_per_speed(self.mu, f_n, dot(vt, vt), self.eps)
        };
        [0, 1, 2].map(|j| f_n * n[j] - scale * vt[j])
    }
}

/// Where a body touches a surface: the point (world axes), its depth behind the surface and
/// the surface's outward normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Touch {
    pub point: V3,
    pub depth: f64,
    pub normal: V3,
}

/// What the terrain does to one ellipsoid: the sum of its forces (world axes) and the depth
/// of the deepest surface it is behind (0 out of contact).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Pressed {
    pub force: V3,
    pub depth: f64,
}

/// An ellipsoid fixed on a body, in world axes: its centre, its body's axes (columns of
/// `rotation`) and its semi-axes along them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ellipsoid<'a> {
    pub centre: V3,
    pub rotation: &'a [[f64; 3]; 3],
    pub axes: V3,
}

impl Ellipsoid<'_> {
    /// The support point along −n: the ellipsoid's point farthest along −n.
    #[inline]
    pub fn support(&self, n: V3) -> V3 {
        if self.axes == [0.0; 3] {
            return self.centre;
        }
        let r = self.reach(n);
        [0, 1, 2].map(|i| self.centre[i] + r[i])
    }

    /// From the centre to the support point along −n: −R D² m / √(mᵀ D² m), m = Rᵀ n.
    #[inline]
    pub fn reach(&self, n: V3) -> V3 {
        let r = self.rotation;
        let m = [0, 1, 2].map(|j| r[0][j] * n[0] + r[1][j] * n[1] + r[2][j] * n[2]);
        let d2m = [0, 1, 2].map(|j| self.axes[j] * self.axes[j] * m[j]);
        let s = dot(m, d2m).sqrt();
        if s == 0.0 {
            return [0.0; 3];
        }
        [0, 1, 2].map(|i| -dot(r[i], d2m) / s)
    }
}

impl Ellipsoid<'static> {
    /// A point: an ellipsoid of no extent.
    pub fn point(centre: V3) -> Ellipsoid<'static> {
        const I: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        Ellipsoid {
            centre,
            rotation: &I,
            axes: [0.0; 3],
        }
    }
}

/// The vertical axis of a [`Terrain`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Vertical {
    X,
    Y,
    Z,
}

impl Vertical {
    /// The axis' number: 0, 1 or 2.
    pub fn index(self) -> usize {
        self as usize
    }
}

/// The ground plane along `up` and boxes on it, and the law their contacts follow.
#[derive(Clone, Debug, PartialEq)]
pub struct Terrain {
    /// the vertical axis
    pub up: Vertical,
    /// whether the ground plane is part of the terrain (false: the boxes alone, for a model
    /// whose own generated contacts meet the ground)
    pub ground: bool,
    pub blocks: Vec<Block>,
    pub law: ContactLaw,
}

impl Default for Terrain {
    /// Flat ground z = 0 with the default [`ContactLaw`].
    fn default() -> Self {
        Terrain {
            up: Vertical::Z,
            ground: true,
            blocks: Vec::new(),
            law: ContactLaw::default(),
        }
    }
}

impl Terrain {
    /// Flat ground with a step of `height` from the first horizontal coordinate `at` on, 3 m
    /// deep and 2 m wide (centred on the second horizontal axis).
    pub fn step(at: f64, height: f64) -> Terrain {
        Terrain {
            blocks: vec![Block {
                min: [at, -1.0],
                max: [at + 3.0, 1.0],
                height,
            }],
            ..Terrain::default()
        }
    }

    /// The two horizontal axes, in increasing order.
    pub fn horizontal(&self) -> [usize; 2] {
        match self.up {
            Vertical::X => [1, 2],
            Vertical::Y => [0, 2],
            Vertical::Z => [0, 1],
        }
    }

    /// The height of the terrain's top above the horizontal position `p`: the highest box
    /// there, or the ground; NaN where `p` is not a number (not the ground's height).
    pub fn height(&self, p: [f64; 2]) -> f64 {
        if p.iter().any(|x| x.is_nan()) || !self.blocks.iter().all(Block::is_box) {
            return f64::NAN;
        }
        self.blocks
            .iter()
            .filter(|b| (0..2).all(|j| p[j] > b.min[j] && p[j] < b.max[j]))
            .map(|b| b.height)
            .fold(0.0, f64::max)
    }

    /// [`Terrain::height`] with every box edge rounded over `width` (m) by a smooth ramp: a
    /// height to plan footholds on, which a position moving by a millimetre near an edge
    /// does not move by a box's height. A width of 0 rounds nothing ([`Terrain::height`]);
    /// a negative or NaN width, or a NaN position, gives NaN (a negative width turned the
    /// ramps inside out, and a NaN one gave the ground's height everywhere).
    pub fn planned_height(&self, p: [f64; 2], width: f64) -> f64 {
        if !(width >= 0.0) || p.iter().any(|x| x.is_nan()) || !self.blocks.iter().all(Block::is_box)
        {
            return f64::NAN;
        }
        if width == 0.0 {
            return self.height(p);
        }
        let ramp = |d: f64| {
            let u = (d / width + 0.5).clamp(0.0, 1.0);
            u * u * (3.0 - 2.0 * u)
        };
        self.blocks
            .iter()
            .map(|b| {
                let s = (0..2).map(|j| ramp(p[j] - b.min[j]).min(ramp(b.max[j] - p[j])));
                b.height * s.product::<f64>()
            })
            .fold(0.0, f64::max)
    }

    /// The unit vector along axis `j`, signed.
    fn axis(j: usize, sign: f64) -> V3 {
        let mut n = [0.0; 3];
        n[j] = sign;
        n
    }

    /// Calls `touch` for the ground and each box the ellipsoid `e` overlaps (module docs).
    /// Semi-axes count by their size; an ellipsoid whose centre or a semi-axis is not finite
    /// touches once, at a NaN depth (its force NaN: a run stops on it, naming the
    /// coordinate, where it would have fallen through the terrain unseen).
    pub fn touches(&self, e: &Ellipsoid, mut touch: impl FnMut(Touch)) {
        let up = self.up.index();
        let n = Self::axis(up, 1.0);
        if !e.axes.iter().chain(&e.centre).all(|v| v.is_finite()) {
            touch(Touch {
                point: e.centre,
                depth: f64::NAN,
                normal: n,
            });
            return;
        }
        let s = e.support(n);
        if self.ground && s[up] < 0.0 {
            touch(Touch {
                point: s,
                depth: -s[up],
                normal: n,
            });
        }
        let [u, w] = self.horizontal();
        // the box around the ellipsoid: no face of a box beyond it can be reached
        let reach = e.axes.iter().map(|a| a.abs()).fold(0.0, f64::max);
        let x = e.centre;
        for b in &self.blocks {
            if !b.is_box() {
                touch(Touch {
                    point: e.centre,
                    depth: f64::NAN,
                    normal: n,
                });
                continue;
            }
            if x[up] - reach >= b.height
                || x[u] + reach <= b.min[0]
                || x[u] - reach >= b.max[0]
                || x[w] + reach <= b.min[1]
                || x[w] - reach >= b.max[1]
            {
                continue;
            }
            if let Some(t) = Self::block_touch(e, b, up, [u, w]) {
                touch(t);
            }
        }
    }

    /// Where the ellipsoid `e` touches block `b` (module docs), if it does: the largest
    /// separation s(n) = n·(x − c) − Σ hᵢ|nᵢ| − √(nᵀQn) over unit n (x the ellipsoid's
    /// centre, c and h the box's centre and half-sizes, Q = R D² Rᵀ), taken over the normal
    /// cones of the box's top, sides, upper and vertical edges and upper corners. A face's
    /// separation is its own (−depth behind it); within an edge's or a corner's cone s(n) =
    /// n·(x − f) − √(nᵀQn), f a point of the edge or the corner, whose largest value is the
    /// signed distance from f to the ellipsoid (`nearest_normal`): it counts when the normal
    /// it is reached at lies in that cone, and the maxima of s within the cone do too
    /// ([`cone_maxima`], [`octant_maxima`]). An edge or a corner is skipped where one of its
    /// faces provably beats it (`beaten`).
    fn block_touch(e: &Ellipsoid, b: &Block, up: usize, [u, w]: [usize; 2]) -> Option<Touch> {
        let (mut centre, mut half) = ([0.0; 3], [0.0; 3]);
        (centre[up], half[up]) = (0.5 * b.height, 0.5 * b.height);
        for (j, a) in [u, w].into_iter().enumerate() {
            centre[a] = 0.5 * (b.min[j] + b.max[j]);
            half[a] = 0.5 * (b.max[j] - b.min[j]);
        }
        let q = [0, 1, 2].map(|i| e.centre[i] - centre[i]);
        // Q = R D² Rᵀ, and the separation of a unit n
        let r = e.rotation;
        let d2 = e.axes.map(|a| a * a);
        let qm: [[f64; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..3).map(|k| r[i][k] * d2[k] * r[j][k]).sum())
        });
        let support = |n: V3| dot(n, [0, 1, 2].map(|i| dot(qm[i], n))).sqrt();
        let separation =
            |n: V3| dot(n, q) - (0..3).map(|i| half[i] * n[i].abs()).sum::<f64>() - support(n);
        let mut best: Option<(f64, V3)> = None;
        let mut consider = |s: f64, n: V3| {
            if best.is_none_or(|(b, _)| s > b) {
                best = Some((s, n));
            }
        };
        // the top and the sides, each as its depth behind it; per face (axis, side: 0 for
        // −, 1 for +) its separation s_f and its support point
        let mut faces = [[(f64::NAN, [f64::NAN; 3]); 2]; 3];
        let mut clear = false;
        for (j, sign) in [(up, 1.0), (u, -1.0), (u, 1.0), (w, -1.0), (w, 1.0)] {
            let n = Self::axis(j, sign);
            let face = centre[j] * sign + half[j];
            let point = e.support(n);
            let s = dot(n, point) - face;
            faces[j][usize::from(sign > 0.0)] = (s, point);
            clear |= s >= 0.0;
            consider(s, n);
        }
        if clear {
            // clear of a face's plane: clear of the box
            return None;
        }
        // An edge or a corner beats no face when a face f of it has its support point (the
        // ellipsoid's deepest behind f) at least |s_f| inside the planes of the feature's other
        // faces: over the feature's cone, n = Σ aᵢ uᵢ (its faces' normals, aᵢ ≥ 0, |n| = 1),
        // s(n) ≤ n·(support − corner) ≤ a_f s_f − (Σ_{i≠f} aᵢ)|s_f| ≤ s_f, as
        // Σ_{i≠f} aᵢ ≥ √(1 − a_f²) ≥ 1 − a_f. Otherwise it is searched (an ellipsoid may leave
        // by an edge's or a corner's way even when it lies within the planes of its faces).
        let beaten = |sides: &[(usize, f64)]| {
            sides.iter().any(|&(f, sf)| {
                let (s, point) = faces[f][usize::from(sf > 0.0)];
                (sides.iter())
                    .filter(|&&(i, _)| i != f)
                    .all(|&(i, si)| half[i] - si * (point[i] - centre[i]) >= -s)
            })
        };
        // edges along axis i (not the bottom's), then the upper corners
        for i in 0..3 {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            for (sj, sk) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
                if (j == up && sj < 0.0) || (k == up && sk < 0.0) || beaten(&[(j, sj), (k, sk)]) {
                    continue;
                }
                // the point of the edge's line in the plane of j and k, and the ellipse Q
                // projects to on that plane, in its principal axes
                let p = [q[j] - sj * half[j], q[k] - sk * half[k]];
                let (a, bb, c) = (qm[j][j], qm[j][k], qm[k][k]);
                let mean = 0.5 * (a + c);
                let radius = (0.25 * (a - c) * (a - c) + bb * bb).sqrt();
                let l = [mean + radius, (mean - radius).max(0.0)];
                let v = if bb == 0.0 {
                    if a >= c { [1.0, 0.0] } else { [0.0, 1.0] }
                } else {
                    let v = [bb, l[0] - a];
                    let norm = (v[0] * v[0] + v[1] * v[1]).sqrt();
                    [v[0] / norm, v[1] / norm]
                };
                let pp = [v[0] * p[0] + v[1] * p[1], -v[1] * p[0] + v[0] * p[1]];
                if let Some(m) = nearest_normal(l, pp) {
                    let mut n = [0.0; 3];
                    n[j] = v[0] * m[0] - v[1] * m[1];
                    n[k] = v[1] * m[0] + v[0] * m[1];
                    if sj * n[j] >= 0.0 && sk * n[k] >= 0.0 {
                        consider(separation(n), n);
                    }
                }
                // where the edge lies inside the ellipse, s has maxima within the edge's
                // cone besides the circle's largest, which may lie outside it
                cone_maxima(p, [a, bb, c], [sj, sk], |m| {
                    let mut n = [0.0; 3];
                    (n[j], n[k]) = (m[0], m[1]);
                    consider(separation(n), n);
                });
            }
        }
        for corner in 0..4 {
            let mut sign = [1.0; 3];
            sign[u] = if corner & 1 == 0 { -1.0 } else { 1.0 };
            sign[w] = if corner & 2 == 0 { -1.0 } else { 1.0 };
            if beaten(&[(0, sign[0]), (1, sign[1]), (2, sign[2])]) {
                continue;
            }
            let p = [0, 1, 2].map(|i| q[i] - sign[i] * half[i]);
            // in the ellipsoid's axes (the columns of R)
            let pp = [0, 1, 2].map(|k| (0..3).map(|i| r[i][k] * p[i]).sum::<f64>());
            let largest = nearest_normal(d2, pp).map(|m| [0, 1, 2].map(|i| dot(r[i], m)));
            match largest {
                Some(n) if (0..3).all(|i| sign[i] * n[i] >= 0.0) => consider(separation(n), n),
                // the sphere's largest outside the corner's cone: the cone's largest is
                // another of s's maxima, within it
                _ => octant_maxima(p, &qm, sign, |n| consider(separation(n), n)),
            }
        }
        let (s, n) = best?;
        (s < 0.0).then(|| Touch {
            point: e.support(n),
            depth: -s,
            normal: n,
        })
    }

    /// The deepest surface a point at `p` is behind, if any: its depth and outward normal.
    pub fn penetration(&self, p: V3) -> Option<(f64, V3)> {
        let mut best: Option<(f64, V3)> = None;
        self.touches(&Ellipsoid::point(p), |t| {
            // the deepest, a NaN depth before any
            if best.is_none_or(|(d, _)| !(t.depth <= d) && !d.is_nan()) {
                best = Some((t.depth, t.normal));
            }
        });
        best
    }

    /// The force (world axes) on a point at `p` moving at `v`: the sum over the surfaces it
    /// is behind.
    #[inline]
    pub fn point_force(&self, p: V3, v: V3) -> V3 {
        let mut f = [0.0; 3];
        self.touches(&Ellipsoid::point(p), |t| {
            let g = self.law.force(t.depth, t.normal, v);
            f = [0, 1, 2].map(|j| f[j] + g[j]);
        });
        f
    }

    /// The contact forces on an ellipsoid of semi-axes `axes` along the axes `rotation` of
    /// its body, centred at `centre` (world axes) moving at `centre_velocity`, the body
    /// turning at `angular_velocity`: each as (where it touches, the force), to `out`.
    pub fn ellipsoid_forces(
        &self,
        rotation: &[[f64; 3]; 3],
        angular_velocity: V3,
        (centre, centre_velocity): (V3, V3),
        axes: V3,
        mut out: impl FnMut(&Touch, V3),
    ) {
        let e = Ellipsoid {
            centre,
            rotation,
            axes,
        };
        self.touches(&e, |t| {
            let arm = [0, 1, 2].map(|j| t.point[j] - centre[j]);
            let wxr = cross(angular_velocity, arm);
            let v = [0, 1, 2].map(|j| centre_velocity[j] + wxr[j]);
            out(&t, self.law.force(t.depth, t.normal, v));
        });
    }

    /// Applies the contact forces on an ellipsoid of semi-axes `axes` along frame `frame`'s
    /// axes, centred at declared point `point` (a point of the frame's body), to `e`; returns
    /// their sum (world axes) and the largest depth (0 out of contact). The user part must
    /// read frames ([`crate::Efforts::FRAMES`]).
    pub fn apply_ellipsoid(&self, e: &mut Effort, frame: usize, point: usize, axes: V3) -> Pressed {
        let p = e.point(point);
        let centre = (p.position, p.velocity);
        let k = e.frame(frame);
        let (rotation, w) = (k.pose.rotation, k.angular_velocity);
        let mut pressed = Pressed::default();
        self.ellipsoid_forces(&rotation, w, centre, axes, |t, f| {
            // NaN stays NaN (`f64::max` would drop it and say "out of contact")
            pressed.depth = if t.depth.is_nan() || pressed.depth.is_nan() {
                f64::NAN
            } else {
                pressed.depth.max(t.depth)
            };
            pressed.force = [0, 1, 2].map(|j| pressed.force[j] + f[j]);
            e.force_on_frame(frame, t.point, f);
        });
        pressed
    }

    /// Applies the contact force on declared point `point` to `e` (nothing out of contact);
    /// returns it (world axes).
    pub fn apply_point(&self, e: &mut Effort, point: usize) -> V3 {
        let p = e.point(point);
        let f = self.point_force(p.position, p.velocity);
        if f != [0.0; 3] {
            e.force_at_point(point, f);
        }
        f
    }
}

/// The unit normals n = (s_j cos θ, s_k sin θ), 0 < θ < π/2 (an edge's cone, `signs` its
/// faces' sides) at which s(θ) = n·p − √(nᵀQn) has a local maximum, Q = [[a, b], [b, c]]
/// the ellipse `q` = [a, b, c], each handed to `found`: where s′ falls through zero between
/// 32 samples of the cone, to 1e-15 rad by bisection. The largest over the whole circle (`nearest_normal`)
/// is one of the maxima of s; where it lies outside the cone, another inside it may be the
/// cone's largest (an ellipsoid elongated across the edge pressed on it deeper than half
/// its semi-axis: the edge was skipped, and the top's depth taken, 20 mm where the
/// shortest way out is 15.3 mm, 26° above the side's normal).
fn cone_maxima(
    p: [f64; 2],
    [a, b, c]: [f64; 3],
    [sj, sk]: [f64; 2],
    mut found: impl FnMut([f64; 2]),
) {
    let normal = |th: f64| {
        let (sn, cs) = th.sin_cos();
        [sj * cs, sk * sn]
    };
    // s′(θ) = t·p − tᵀQn/√(nᵀQn), t = dn/dθ
    let slope = |th: f64| {
        let (sn, cs) = th.sin_cos();
        let (n, t) = ([sj * cs, sk * sn], [-sj * sn, sk * cs]);
        let qn = [a * n[0] + b * n[1], b * n[0] + c * n[1]];
        let support = (n[0] * qn[0] + n[1] * qn[1]).sqrt();
        let bend = if support > 0.0 {
            (t[0] * qn[0] + t[1] * qn[1]) / support
        } else {
            0.0
        };
        t[0] * p[0] + t[1] * p[1] - bend
    };
    const SAMPLES: usize = 32;
    let at = |i: usize| std::f64::consts::FRAC_PI_2 * i as f64 / SAMPLES as f64;
    let mut before = slope(at(0));
    for i in 1..=SAMPLES {
        let after = slope(at(i));
        if before > 0.0 && after <= 0.0 {
            let (mut lo, mut hi) = (at(i - 1), at(i));
            while hi - lo > 1e-15 {
                let mid = 0.5 * (lo + hi);
                if slope(mid) > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            found(normal(0.5 * (lo + hi)));
        }
        before = after;
    }
}

/// The unit normals n within a corner's cone (the octant sign_i n_i > 0) at which
/// s(n) = n·p − √(nᵀQn) has a local maximum, each handed to `found`: the samples of a
/// 17 × 17 grid of the octant (n = (sin θ cos φ, sin θ sin φ, cos θ) by sign, θ and φ in
/// [0, π/2]) that no neighbour exceeds, each refined by Newton's steps on the sphere (along
/// the gradient where s is not concave), kept in the octant, until none gains; those that
/// end on the octant's boundary are left to the edges and faces. The 3D counterpart of
/// [`cone_maxima`], for where the sphere's largest (`nearest_normal`) lies outside the
/// corner's cone: an ellipsoid pressed on a corner took a face's or an edge's way out,
/// 25.04 mm, where the corner's is 24.51 mm.
fn octant_maxima(p: V3, q: &[[f64; 3]; 3], sign: V3, mut found: impl FnMut(V3)) {
    let s = |n: V3| dot(n, p) - dot(n, [0, 1, 2].map(|i| dot(q[i], n))).max(0.0).sqrt();
    const N: usize = 16;
    let angle = |i: usize| std::f64::consts::FRAC_PI_2 * i as f64 / N as f64;
    let normal = |a: usize, b: usize| {
        let ((st, ct), (sp, cp)) = (angle(a).sin_cos(), angle(b).sin_cos());
        [sign[0] * st * cp, sign[1] * st * sp, sign[2] * ct]
    };
    let mut grid = [[0.0; N + 1]; N + 1];
    for (a, row) in grid.iter_mut().enumerate() {
        for (b, v) in row.iter_mut().enumerate() {
            *v = s(normal(a, b));
        }
    }
    // onto the sphere, within the octant
    let unit = |m: V3| {
        let m = [0, 1, 2].map(|i| if sign[i] * m[i] < 0.0 { 0.0 } else { m[i] });
        let norm = dot(m, m).sqrt();
        (norm > 0.0).then(|| m.map(|x| x / norm))
    };
    for a in 0..=N {
        for b in 0..=N {
            let v = grid[a][b];
            let peak = (a.saturating_sub(1)..=(a + 1).min(N))
                .flat_map(|i| (b.saturating_sub(1)..=(b + 1).min(N)).map(move |j| (i, j)))
                .all(|(i, j)| grid[i][j] <= v);
            // at θ = 0 every φ is the same normal: one of them
            if !peak || (a == 0 && b > 0) {
                continue;
            }
            let (mut n, mut best) = (normal(a, b), v);
            // Newton's steps on the sphere where s is concave there, else along its
            // gradient by a grid spacing; each halved until it gains, and done when ten
            // halvings gain nothing (at the maximum, to rounding)
            for _ in 0..50 {
                let qn = [0, 1, 2].map(|i| dot(q[i], n));
                let sigma = dot(n, qn).sqrt();
                if !(sigma > 0.0) {
                    break;
                }
                let grad = [0, 1, 2].map(|i| p[i] - qn[i] / sigma);
                let along = dot(grad, n);
                let g = [0, 1, 2].map(|i| grad[i] - along * n[i]);
                let size = dot(g, g).sqrt();
                if !(size > 0.0) {
                    break;
                }
                // tangent axes: along the gradient, and across it
                let t1 = g.map(|x| x / size);
                let t2 = cross(n, t1);
                // s's Hessian on the sphere: tᵀ(−(Q − Qn nᵀQ/σ²)/σ)t' − (∇s·n) tᵀt'
                let hess = |x: V3, y: V3| {
                    let qy = [0, 1, 2].map(|i| dot(q[i], y));
                    -(dot(x, qy) - dot(x, qn) * dot(qn, y) / (sigma * sigma)) / sigma
                        - along * dot(x, y)
                };
                let (h11, h12, h22) = (hess(t1, t1), hess(t1, t2), hess(t2, t2));
                // where s is not concave, H shifted to below zero by its spread of
                // eigenvalues (a trust region's step); the step at most a grid spacing
                let (mean, spread) = (
                    0.5 * (h11 + h22),
                    (0.25 * (h11 - h22).powi(2) + h12 * h12).sqrt(),
                );
                let shift = if mean + spread >= 0.0 {
                    mean + 2.0 * spread
                } else {
                    0.0
                };
                let (h11, h22) = (h11 - shift, h22 - shift);
                let det = h11 * h22 - h12 * h12;
                // H d = −(size, 0)
                let mut d = if det > 0.0 && h11 < 0.0 {
                    [-size * h22 / det, size * h12 / det]
                } else {
                    [angle(1), 0.0]
                };
                let length = d[0].hypot(d[1]);
                if !(length <= angle(1)) {
                    d = [angle(1) * d[0] / length, angle(1) * d[1] / length];
                }
                let along_d = |scale: f64| {
                    unit([0, 1, 2].map(|i| n[i] + scale * (d[0] * t1[i] + d[1] * t2[i])))
                };
                let mut scale = 1.0;
                let mut gained = None;
                for _ in 0..10 {
                    if let Some(m) = along_d(scale)
                        && s(m) > best
                    {
                        gained = Some((m, s(m)));
                        break;
                    }
                    scale *= 0.5;
                }
                // a full step that gains: longer ones while they gain more (across a
                // region where s is not concave)
                if scale == 1.0 {
                    for _ in 0..6 {
                        scale *= 2.0;
                        match (along_d(scale), gained) {
                            (Some(m), Some((_, b))) if s(m) > b => gained = Some((m, s(m))),
                            _ => break,
                        }
                    }
                }
                let Some((m, b)) = gained else {
                    break;
                };
                (n, best) = (m, b);
                // on the boundary, where the clamp holds it: an edge's or a face's
                if (0..3).any(|i| n[i] == 0.0) {
                    break;
                }
            }
            // a maximum on the cone's boundary (or within rounding of it: cos(π/2) is not
            // 0) is an edge's or a face's, which they give exactly
            if (0..3).all(|i| sign[i] * n[i] > 1e-12) {
                found(n);
            }
        }
    }
}

/// For a centred ellipsoid (K = 3) or ellipse (K = 2) of squared semi-axes `l` along its
/// principal axes and a point `q` in those axes, the unit n (same axes) at which
/// n·q − √(Σ lᵢnᵢ²) is largest: the direction from the surface's point nearest q toward q
/// (outside) or away from it (inside), both the outward normal there, nᵢ ∝ qᵢ/(lᵢ + t) with t
/// the root of g(t) = Σ lᵢqᵢ²/(lᵢ + t)² − 1 (decreasing and convex for t > −min l: Newton's
/// steps from the left of the root, kept in a bracket). `None` for q at the centre. For q inside and on a principal
/// plane, deeper than that plane's own way out (a box's corner sunk past the ellipsoid's
/// medial axis, beyond what a contact model resolves), the root may give a stationary
/// direction rather than the largest: the face and edge candidates then bound the answer.
fn nearest_normal<const K: usize>(l: [f64; K], q: [f64; K]) -> Option<[f64; K]> {
    let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
    if norm == 0.0 {
        return None;
    }
    let largest = l.iter().copied().fold(0.0, f64::max);
    if largest == 0.0 {
        return Some(q.map(|x| x / norm));
    }
    let g = |t: f64| {
        let (mut v, mut d) = (-1.0, 0.0);
        for i in 0..K {
            let a = l[i] + t;
            let r = l[i] * q[i] * q[i] / (a * a);
            v += r;
            d -= 2.0 * r / a;
        }
        (v, d)
    };
    let smallest = l.iter().copied().fold(f64::INFINITY, f64::min);
    // g(hi) ≤ 0: each term is at most l_max q²/hi²
    let (mut lo, mut hi) = (-smallest, largest.sqrt() * norm);
    // g ≥ 0 where one term is 1, at t = √lᵢ|qᵢ| − lᵢ: from the largest of these Newton's
    // steps stay left of the root (g convex) and do not overshoot
    let left = (0..K)
        .map(|i| l[i].sqrt() * q[i].abs() - l[i])
        .fold(f64::NEG_INFINITY, f64::max);
    let mut t = if left > lo { left } else { hi };
    for _ in 0..100 {
        let (v, d) = g(t);
        if v == 0.0 {
            break;
        }
        if v > 0.0 {
            lo = t;
        } else {
            hi = t;
        }
        let step = -v / d;
        // converged: Newton's step is at the rounding of t and the axes
        if step.abs() <= 4.0 * f64::EPSILON * (t.abs() + largest) {
            break;
        }
        let newton = t + step;
        t = if newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if hi - lo <= 4.0 * f64::EPSILON * hi.abs().max(lo.abs()) {
            break;
        }
    }
    let m: [f64; K] = std::array::from_fn(|i| q[i] / (l[i] + t));
    let size = m.iter().map(|x| x * x).sum::<f64>().sqrt();
    (size > 0.0 && size.is_finite()).then(|| m.map(|x| x / size))
}
