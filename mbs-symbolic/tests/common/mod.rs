//! Shared by the mechanics tests: a seeded RNG, random kinematic-tree descriptions, an
//! independent numeric oracle (Featherstone's spatial algebra: RNEA for h and τ, CRBA for M)
//! and the conversion of a description into a [`System`] through the builder methods.
//!
//! The oracle shares no code with the generator: it has its own link list, its own f64
//! 3-D and 6-D algebra and works in link coordinates with Plücker transforms, where the
//! generator composes elementary factors on the expression DAG.
#![allow(dead_code)]

use mbs_symbolic::expr::{Arena, ExprId, SliceEnv, Var};
use mbs_symbolic::mech::system::{Attach, Factor, Load};
use mbs_symbolic::{SymbolicModel, System};
use std::f64::consts::PI;

// ---------------------------------------------------------------------------------------
// Random numbers
// ---------------------------------------------------------------------------------------

/// SplitMix64: small, seeded, deterministic.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x2545_F491_4F6C_DD1D) ^ 0x9E37_79B9_7F4A_7C15)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f64()
    }

    /// Uniform in 0..n.
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }

    pub fn chance(&mut self, p: f64) -> bool {
        self.f64() < p
    }

    pub fn vec(&mut self, s: f64) -> V3 {
        [self.range(-s, s), self.range(-s, s), self.range(-s, s)]
    }

    /// A random unit vector (uniform on the sphere).
    pub fn unit(&mut self) -> V3 {
        loop {
            let v = self.vec(1.0);
            let n = norm(v);
            if n > 0.1 && n <= 1.0 {
                return scale(1.0 / n, v);
            }
        }
    }

    /// A coordinate axis ±e_i (40 %) or a random unit axis.
    pub fn axis(&mut self) -> V3 {
        if self.chance(0.4) {
            let mut a = [0.0; 3];
            a[self.below(3)] = if self.chance(0.5) { 1.0 } else { -1.0 };
            a
        } else {
            self.unit()
        }
    }

    pub fn shuffle<T>(&mut self, v: &mut [T]) {
        for i in (1..v.len()).rev() {
            let j = self.below(i + 1);
            v.swap(i, j);
        }
    }
}

// ---------------------------------------------------------------------------------------
// 3-D algebra (f64)
// ---------------------------------------------------------------------------------------

pub type V3 = [f64; 3];
/// Row-major.
pub type M3 = [[f64; 3]; 3];

pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn scale(s: f64, a: V3) -> V3 {
    [s * a[0], s * a[1], s * a[2]]
}

pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}

pub fn eye3() -> M3 {
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
}

pub fn mm(a: &M3, b: &M3) -> M3 {
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    r
}

pub fn mv(a: &M3, v: V3) -> V3 {
    [dot(a[0], v), dot(a[1], v), dot(a[2], v)]
}

pub fn tr(a: &M3) -> M3 {
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = a[j][i];
        }
    }
    r
}

/// [v]×
pub fn skew(v: V3) -> M3 {
    [[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]]
}

/// Active rotation by `angle` about the unit `axis` (Rodrigues): columns are the rotated axes.
pub fn rodrigues(axis: V3, angle: f64) -> M3 {
    let (s, c) = angle.sin_cos();
    let k = skew(axis);
    let mut r = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let id = if i == j { 1.0 } else { 0.0 };
            r[i][j] = c * id + s * k[i][j] + (1.0 - c) * axis[i] * axis[j];
        }
    }
    r
}

/// The symmetric tensor from (xx, yy, zz, xy, xz, yz).
pub fn sym(t: [f64; 6]) -> M3 {
    [[t[0], t[3], t[4]], [t[3], t[1], t[5]], [t[4], t[5], t[2]]]
}

// ---------------------------------------------------------------------------------------
// 6-D spatial algebra (Featherstone): motion [ω; v], force [n; f]
// ---------------------------------------------------------------------------------------

pub type V6 = [f64; 6];
pub type M6 = [[f64; 6]; 6];

fn m6_zero() -> M6 {
    [[0.0; 6]; 6]
}

fn m6v(x: &M6, v: &V6) -> V6 {
    let mut r = [0.0; 6];
    for i in 0..6 {
        r[i] = (0..6).map(|k| x[i][k] * v[k]).sum();
    }
    r
}

/// xᵀ v
fn m6tv(x: &M6, v: &V6) -> V6 {
    let mut r = [0.0; 6];
    for i in 0..6 {
        r[i] = (0..6).map(|k| x[k][i] * v[k]).sum();
    }
    r
}

fn m6m(a: &M6, b: &M6) -> M6 {
    let mut r = m6_zero();
    for i in 0..6 {
        for j in 0..6 {
            r[i][j] = (0..6).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    r
}

fn m6t(a: &M6) -> M6 {
    let mut r = m6_zero();
    for i in 0..6 {
        for j in 0..6 {
            r[i][j] = a[j][i];
        }
    }
    r
}

fn v6add(a: V6, b: V6) -> V6 {
    let mut r = a;
    for i in 0..6 {
        r[i] += b[i];
    }
    r
}

fn v6dot(a: V6, b: V6) -> f64 {
    (0..6).map(|i| a[i] * b[i]).sum()
}

fn v6scale(s: f64, a: V6) -> V6 {
    a.map(|x| s * x)
}

fn blocks(a: &M3, b: &M3, c: &M3, d: &M3) -> M6 {
    let mut r = m6_zero();
    for i in 0..3 {
        for j in 0..3 {
            r[i][j] = a[i][j];
            r[i][j + 3] = b[i][j];
            r[i + 3][j] = c[i][j];
            r[i + 3][j + 3] = d[i][j];
        }
    }
    r
}

/// Plücker transform of motion vectors from frame A to frame B, where B's origin is `r`
/// and `e` maps A coordinates to B coordinates: X = [E 0; −E r× E].
pub fn plucker(e: &M3, r: V3) -> M6 {
    let erx = mm(e, &skew(r));
    let nerx = erx.map(|row| row.map(|x| -x));
    blocks(e, &[[0.0; 3]; 3], &nerx, e)
}

/// Motion cross product v×.
pub fn crm(v: &V6) -> M6 {
    let w = skew([v[0], v[1], v[2]]);
    let l = skew([v[3], v[4], v[5]]);
    blocks(&w, &[[0.0; 3]; 3], &l, &w)
}

/// Force cross product v×* = −(v×)ᵀ.
pub fn crf(v: &V6) -> M6 {
    m6t(&crm(v)).map(|row| row.map(|x| -x))
}

/// Spatial inertia about a frame origin of a body of mass `m`, centre of mass `c` and
/// inertia `ig` about the centre of mass (frame axes).
pub fn mci(m: f64, c: V3, ig: &M3) -> M6 {
    let cx = skew(c);
    let cxt = tr(&cx);
    let ccxt = mm(&cx, &cxt);
    let mut i = *ig;
    for r in 0..3 {
        for s in 0..3 {
            i[r][s] += m * ccxt[r][s];
        }
    }
    let mcx = cx.map(|row| row.map(|x| m * x));
    let mcxt = cxt.map(|row| row.map(|x| m * x));
    let m1 = [[m, 0.0, 0.0], [0.0, m, 0.0], [0.0, 0.0, m]];
    blocks(&i, &mcx, &mcxt, &m1)
}

// ---------------------------------------------------------------------------------------
// Random tree descriptions
// ---------------------------------------------------------------------------------------

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Revolute,
    Prismatic,
}

/// A joint variable θ = scale·q[dof] + bias + amp·sin(omega·t + phase).
#[derive(Clone, Debug)]
pub struct Drive {
    pub dof: Option<usize>,
    pub scale: f64,
    pub bias: f64,
    pub amp: f64,
    pub omega: f64,
    pub phase: f64,
}

impl Drive {
    fn qk(&self, x: &[f64]) -> f64 {
        self.dof.map_or(0.0, |k| self.scale * x[k])
    }

    pub fn value(&self, q: &[f64], t: f64) -> f64 {
        self.qk(q) + self.bias + self.amp * (self.omega * t + self.phase).sin()
    }

    pub fn rate(&self, qd: &[f64], t: f64) -> f64 {
        self.qk(qd) + self.amp * self.omega * (self.omega * t + self.phase).cos()
    }

    pub fn accel(&self, qdd: &[f64], t: f64) -> f64 {
        self.qk(qdd) - self.amp * self.omega * self.omega * (self.omega * t + self.phase).sin()
    }

    pub fn rheonomic(&self) -> bool {
        self.amp != 0.0
    }
}

/// One link: a fixed offset and fixed rotations from its parent's link frame, then the joint;
/// the link frame is the frame after the joint. The body's centre of mass is at `com` in the
/// link frame and its inertia about G is given in link axes.
#[derive(Clone, Debug)]
pub struct Link {
    pub parent: Option<usize>,
    pub offset: V3,
    /// (unit axis, angle), applied in order after the offset
    pub fixed: Vec<(V3, f64)>,
    /// the fixed rotations are given to the generator as a chart (`Factor::Chart`): a
    /// rotation matrix it reads at run time, as a `Tball`'s (the oracle sees the same
    /// rotations); drawn for links with two fixed rotations
    pub chart: bool,
    pub kind: Kind,
    pub axis: V3,
    pub drive: Drive,
    pub mass: f64,
    pub com: V3,
    /// xx, yy, zz, xy, xz, yz about G, link axes
    pub inertia: [f64; 6],
}

#[derive(Clone, Debug)]
pub struct Desc {
    pub links: Vec<Link>,
    pub ndof: usize,
    pub gravity: V3,
}

impl Desc {
    /// True when some link has two or more children, or several links hang from the ground.
    pub fn branching(&self) -> bool {
        let mut count = vec![0usize; self.links.len() + 1];
        for l in &self.links {
            count[l.parent.map_or(0, |p| p + 1)] += 1;
        }
        count.iter().any(|&c| c >= 2)
    }
}

#[derive(Clone, Copy, Debug)]
pub struct GenOpts {
    pub min_dof: usize,
    pub max_dof: usize,
    pub rheonomic: bool,
    pub gravity: bool,
}

/// A physically valid inertia tensor: R·diag(p)·Rᵀ with strict triangle inequalities.
pub fn random_inertia(rng: &mut Rng, m: f64) -> [f64; 6] {
    let p1 = m * rng.range(0.005, 0.08);
    let p2 = m * rng.range(0.005, 0.08);
    let lo = (p1 - p2).abs();
    let p3 = lo + rng.range(0.1, 0.9) * (p1 + p2 - lo);
    let r = rodrigues(rng.unit(), rng.range(-PI, PI));
    let d = [[p1, 0.0, 0.0], [0.0, p2, 0.0], [0.0, 0.0, p3]];
    let i = mm(&mm(&r, &d), &tr(&r));
    [i[0][0], i[1][1], i[2][2], i[0][1], i[0][2], i[1][2]]
}

pub fn random_desc(rng: &mut Rng, o: GenOpts) -> Desc {
    let ndof = o.min_dof + rng.below(o.max_dof - o.min_dof + 1);
    let mut drives: Vec<Drive> = Vec::new();
    let plain = |dof| Drive {
        dof,
        scale: 1.0,
        bias: 0.0,
        amp: 0.0,
        omega: 0.0,
        phase: 0.0,
    };
    for k in 0..ndof {
        drives.push(plain(Some(k)));
    }
    // a coordinate that drives a second joint (coupled joints)
    if rng.chance(0.2) {
        drives.push(plain(Some(rng.below(ndof))));
    }
    // purely time-driven joints
    if o.rheonomic {
        for _ in 0..rng.below(3) {
            let mut d = plain(None);
            d.bias = rng.range(-1.0, 1.0);
            d.amp = rng.range(0.2, 0.6);
            d.omega = rng.range(0.5, 3.0);
            d.phase = rng.range(0.0, 2.0 * PI);
            drives.push(d);
        }
    }
    rng.shuffle(&mut drives);
    for d in drives.iter_mut().filter(|d| d.dof.is_some()) {
        if rng.chance(0.25) {
            d.scale = rng.range(0.5, 1.5) * if rng.chance(0.5) { 1.0 } else { -1.0 };
        }
        if rng.chance(0.3) {
            d.bias = rng.range(-0.5, 0.5);
        }
        if o.rheonomic && rng.chance(0.35) {
            d.amp = rng.range(0.1, 0.5);
            d.omega = rng.range(0.5, 3.0);
            d.phase = rng.range(0.0, 2.0 * PI);
        }
    }
    let mut links = Vec::new();
    for (i, drive) in drives.into_iter().enumerate() {
        let parent = if i == 0 || rng.chance(0.12) {
            None
        } else if rng.chance(0.5) {
            Some(i - 1)
        } else {
            Some(rng.below(i))
        };
        let offset = if rng.chance(0.85) {
            rng.vec(0.6)
        } else {
            [0.0; 3]
        };
        let fixed: Vec<(V3, f64)> = (0..rng.below(3))
            .map(|_| (rng.axis(), rng.range(-PI, PI)))
            .collect();
        // no draw of its own, so that the trees of every seed stay what they were
        let chart = fixed.len() == 2;
        let kind = if rng.chance(0.3) {
            Kind::Prismatic
        } else {
            Kind::Revolute
        };
        let mass = rng.range(0.3, 3.0);
        let com = if rng.chance(0.8) {
            rng.vec(0.4)
        } else {
            [0.0; 3]
        };
        links.push(Link {
            parent,
            offset,
            fixed,
            chart,
            kind,
            axis: rng.axis(),
            drive,
            mass,
            com,
            inertia: random_inertia(rng, mass),
        });
    }
    let gravity = if o.gravity {
        scale(rng.range(5.0, 12.0), rng.unit())
    } else {
        [0.0; 3]
    };
    Desc {
        links,
        ndof,
        gravity,
    }
}

/// A random state: (t, q, qd, qdd).
pub fn random_state(rng: &mut Rng, n: usize) -> (f64, Vec<f64>, Vec<f64>, Vec<f64>) {
    let t = rng.range(0.0, 5.0);
    let q = (0..n).map(|_| rng.range(-1.5, 1.5)).collect();
    let qd = (0..n).map(|_| rng.range(-2.0, 2.0)).collect();
    let qdd = (0..n).map(|_| rng.range(-3.0, 3.0)).collect();
    (t, q, qd, qdd)
}

// ---------------------------------------------------------------------------------------
// The oracle
// ---------------------------------------------------------------------------------------

struct OLink {
    parent: Option<usize>,
    offset: V3,
    /// product of the fixed rotations
    r0: M3,
    kind: Kind,
    axis: V3,
    drive: Drive,
    /// spatial inertia about the link origin, link axes
    inertia: M6,
    /// motion subspace of the joint variable θ, link coordinates
    s: V6,
    com: V3,
}

/// Numeric multibody dynamics of a [`Desc`], independent of the generator.
pub struct Oracle {
    links: Vec<OLink>,
    ndof: usize,
    gravity: V3,
}

impl Oracle {
    pub fn new(d: &Desc) -> Oracle {
        let links = d
            .links
            .iter()
            .map(|l| {
                let r0 = l
                    .fixed
                    .iter()
                    .fold(eye3(), |r, &(ax, an)| mm(&r, &rodrigues(ax, an)));
                let a = l.axis;
                let s = match l.kind {
                    Kind::Revolute => [a[0], a[1], a[2], 0.0, 0.0, 0.0],
                    Kind::Prismatic => [0.0, 0.0, 0.0, a[0], a[1], a[2]],
                };
                OLink {
                    parent: l.parent,
                    offset: l.offset,
                    r0,
                    kind: l.kind,
                    axis: a,
                    drive: l.drive.clone(),
                    inertia: mci(l.mass, l.com, &sym(l.inertia)),
                    s,
                    com: l.com,
                }
            })
            .collect();
        Oracle {
            links,
            ndof: d.ndof,
            gravity: d.gravity,
        }
    }

    /// Orientation (columns: link axes in the parent's) and origin of link `i` in its
    /// parent's link frame.
    fn local(&self, i: usize, q: &[f64], t: f64) -> (M3, V3) {
        let l = &self.links[i];
        let th = l.drive.value(q, t);
        match l.kind {
            Kind::Revolute => (mm(&l.r0, &rodrigues(l.axis, th)), l.offset),
            Kind::Prismatic => (l.r0, add(l.offset, mv(&l.r0, scale(th, l.axis)))),
        }
    }

    fn transforms(&self, q: &[f64], t: f64) -> Vec<M6> {
        (0..self.links.len())
            .map(|i| {
                let (r, p) = self.local(i, q, t);
                plucker(&tr(&r), p)
            })
            .collect()
    }

    /// World pose of every link frame: (orientation, origin).
    pub fn link_poses(&self, q: &[f64], t: f64) -> Vec<(M3, V3)> {
        let mut out: Vec<(M3, V3)> = Vec::with_capacity(self.links.len());
        for i in 0..self.links.len() {
            let (r, p) = self.local(i, q, t);
            let (rp, pp) = match self.links[i].parent {
                Some(k) => out[k],
                None => (eye3(), [0.0; 3]),
            };
            out.push((mm(&rp, &r), add(pp, mv(&rp, p))));
        }
        out
    }

    /// World position of every centre of mass.
    pub fn com_positions(&self, q: &[f64], t: f64) -> Vec<V3> {
        self.link_poses(q, t)
            .iter()
            .zip(&self.links)
            .map(|((r, p), l)| add(*p, mv(r, l.com)))
            .collect()
    }

    /// τ = M qdd − h by recursive Newton–Euler; gravity enters as a base acceleration −g.
    pub fn rnea(&self, q: &[f64], qd: &[f64], qdd: &[f64], t: f64, gravity: bool) -> Vec<f64> {
        let ext = vec![[0.0; 6]; self.links.len()];
        self.rnea_ext(q, qd, qdd, t, gravity, &ext)
    }

    /// Spatial velocity of every link, link coordinates: [ω; velocity of the link origin].
    pub fn link_velocities(&self, q: &[f64], qd: &[f64], t: f64) -> Vec<V6> {
        let xs = self.transforms(q, t);
        let mut v: Vec<V6> = Vec::with_capacity(self.links.len());
        for (i, l) in self.links.iter().enumerate() {
            let vp = l.parent.map_or([0.0; 6], |p| v[p]);
            let vj = v6scale(l.drive.rate(qd, t), l.s);
            v.push(v6add(m6v(&xs[i], &vp), vj));
        }
        v
    }

    /// Kinetic energy ½ Σ vᵢ·Iᵢvᵢ (spatial velocities and inertias).
    pub fn kinetic(&self, q: &[f64], qd: &[f64], t: f64) -> f64 {
        self.link_velocities(q, qd, t)
            .iter()
            .zip(&self.links)
            .map(|(v, l)| 0.5 * v6dot(*v, m6v(&l.inertia, v)))
            .sum()
    }

    /// Potential energy of gravity, −Σ m g·G (zero at the world origin).
    pub fn potential(&self, q: &[f64], t: f64) -> f64 {
        self.com_positions(q, t)
            .iter()
            .zip(&self.links)
            .map(|(p, l)| -l.inertia[3][3] * dot(self.gravity, *p))
            .sum()
    }

    /// [`Oracle::rnea`] with external spatial forces `ext` acting on the links (link
    /// coordinates, moments about the link origin).
    pub fn rnea_ext(
        &self,
        q: &[f64],
        qd: &[f64],
        qdd: &[f64],
        t: f64,
        gravity: bool,
        ext: &[V6],
    ) -> Vec<f64> {
        let xs = self.transforms(q, t);
        let n = self.links.len();
        let g = if gravity { self.gravity } else { [0.0; 3] };
        let a0: V6 = [0.0, 0.0, 0.0, -g[0], -g[1], -g[2]];
        let mut v = vec![[0.0; 6]; n];
        let mut a = vec![[0.0; 6]; n];
        let mut f = vec![[0.0; 6]; n];
        for i in 0..n {
            let l = &self.links[i];
            let (vp, ap) = match l.parent {
                Some(p) => (v[p], a[p]),
                None => ([0.0; 6], a0),
            };
            let vj = v6scale(l.drive.rate(qd, t), l.s);
            v[i] = v6add(m6v(&xs[i], &vp), vj);
            a[i] = v6add(
                v6add(m6v(&xs[i], &ap), v6scale(l.drive.accel(qdd, t), l.s)),
                m6v(&crm(&v[i]), &vj),
            );
            let iv = m6v(&l.inertia, &v[i]);
            f[i] = v6add(m6v(&l.inertia, &a[i]), m6v(&crf(&v[i]), &iv));
            f[i] = v6add(f[i], v6scale(-1.0, ext[i]));
        }
        let mut tau = vec![0.0; self.ndof];
        for i in (0..n).rev() {
            let l = &self.links[i];
            if let Some(k) = l.drive.dof {
                tau[k] += l.drive.scale * v6dot(l.s, f[i]);
            }
            if let Some(p) = l.parent {
                let fp = m6tv(&xs[i], &f[i]);
                f[p] = v6add(f[p], fp);
            }
        }
        tau
    }

    /// h(q, qd, t) = −τ(q, qd, 0, t).
    pub fn bias(&self, q: &[f64], qd: &[f64], t: f64) -> Vec<f64> {
        let z = vec![0.0; self.ndof];
        self.rnea(q, qd, &z, t, true)
            .into_iter()
            .map(|x| -x)
            .collect()
    }

    /// Mass matrix by composite rigid bodies.
    pub fn crba(&self, q: &[f64], t: f64) -> Vec<Vec<f64>> {
        let xs = self.transforms(q, t);
        let n = self.links.len();
        let mut ic: Vec<M6> = self.links.iter().map(|l| l.inertia).collect();
        for i in (0..n).rev() {
            if let Some(p) = self.links[i].parent {
                let moved = m6m(&m6t(&xs[i]), &m6m(&ic[i], &xs[i]));
                for r in 0..6 {
                    for c in 0..6 {
                        ic[p][r][c] += moved[r][c];
                    }
                }
            }
        }
        let mut m = vec![vec![0.0; self.ndof]; self.ndof];
        for (i, (li, ici)) in self.links.iter().zip(&ic).enumerate() {
            let Some(ki) = li.drive.dof else { continue };
            let mut f = m6v(ici, &li.s);
            m[ki][ki] += li.drive.scale * li.drive.scale * v6dot(li.s, f);
            let mut j = i;
            while let Some(p) = self.links[j].parent {
                f = m6tv(&xs[j], &f);
                j = p;
                let lj = &self.links[j];
                if let Some(kj) = lj.drive.dof {
                    let x = li.drive.scale * lj.drive.scale * v6dot(lj.s, f);
                    m[ki][kj] += x;
                    m[kj][ki] += x;
                }
            }
        }
        m
    }
}

// ---------------------------------------------------------------------------------------
// Description → System
// ---------------------------------------------------------------------------------------

/// A system built from a description, with the frame indices of each link.
pub struct Built {
    pub sys: System,
    /// body (at G, link axes) of each link
    pub body: Vec<usize>,
    /// massless frame at the link frame, when one was declared
    pub link_frame: Vec<Option<usize>>,
    /// index of the always-on gravity effect
    pub gravity_effect: Option<usize>,
    /// the values of the charts (`Link::chart`), 9 per chart, row-major
    pub charts: Vec<f64>,
}

fn is_zero(v: V3) -> bool {
    v == [0.0; 3]
}

/// Builds the system of `d`. How each frame's product is written (from a massless link frame,
/// from the parent's body frame, or CAGeM's absolute style from the ground) is drawn at random:
/// all describe the same motion and exercise prefix sharing and factor fusion.
pub fn to_system(d: &Desc, rng: &mut Rng) -> Built {
    let mut sys = System::new("RandomTree");
    let gs = sys.param("gs", 1.0);
    for k in 0..d.ndof {
        sys.dof(&format!("q{k}"), 0.0, 0.0);
    }
    let t = sys.t();
    let mut paths: Vec<Vec<Factor>> = Vec::new();
    let mut body = Vec::new();
    let mut link_frame = Vec::new();
    let mut charts = Vec::new();
    for (i, l) in d.links.iter().enumerate() {
        // the joint variable
        let a = &mut sys.arena;
        let mut th = match l.drive.dof {
            Some(k) => {
                let q = a.var(mbs_symbolic::expr::Var::Q(k as u16));
                if l.drive.scale == 1.0 {
                    q
                } else {
                    a.scale(l.drive.scale, q)
                }
            }
            None => a.zero(),
        };
        if l.drive.bias != 0.0 {
            let b = a.num(l.drive.bias);
            th = a.add(th, b);
        }
        if l.drive.amp != 0.0 {
            let wt = a.scale(l.drive.omega, t);
            let ph = a.num(l.drive.phase);
            let arg = a.add(wt, ph);
            let s = a.sin(arg);
            let s = a.scale(l.drive.amp, s);
            th = a.add(th, s);
        }
        let mut own: Vec<Factor> = Vec::new();
        if !is_zero(l.offset) {
            own.push(sys.disp(l.offset));
        }
        if l.chart {
            let r = l
                .fixed
                .iter()
                .fold(eye3(), |r, &(ax, an)| mm(&r, &rodrigues(ax, an)));
            own.push(Factor::Chart((charts.len() / 9) as u16));
            charts.extend(r.iter().flatten());
        } else {
            for &(ax, an) in &l.fixed {
                let an = sys.num(an);
                own.push(sys.rot(ax, an));
            }
        }
        own.push(match l.kind {
            Kind::Revolute => sys.rot(l.axis, th),
            Kind::Prismatic => {
                let a = &mut sys.arena;
                Factor::Disp(l.axis.map(|c| a.scale(c, th)))
            }
        });
        let mut path = l.parent.map_or(Vec::new(), |p| paths[p].clone());
        path.extend_from_slice(&own);
        // where the product starts
        let mut starts: Vec<(Option<usize>, Vec<Factor>)> = vec![(None, path.clone())];
        if let Some(p) = l.parent {
            if let Some(jf) = link_frame[p] {
                starts.push((Some(jf), own.clone()));
            }
            let mut f = Vec::new();
            let cp = d.links[p].com;
            if !is_zero(cp) {
                f.push(sys.disp(scale(-1.0, cp)));
            }
            f.extend_from_slice(&own);
            starts.push((Some(body[p]), f));
        }
        let (start, mut factors) = starts.swap_remove(rng.below(starts.len()));
        let com: Vec<Factor> = if is_zero(l.com) {
            Vec::new()
        } else {
            vec![sys.disp(l.com)]
        };
        let inertia = sys.inertia(l.mass, l.inertia);
        if rng.chance(0.35) {
            let jf = sys.frame(&format!("J{i}"), start, factors, None);
            link_frame.push(Some(jf));
            body.push(sys.frame(&format!("B{i}"), Some(jf), com, Some(inertia)));
        } else {
            factors.extend(com);
            link_frame.push(None);
            body.push(sys.frame(&format!("B{i}"), start, factors, Some(inertia)));
        }
        paths.push(path);
    }
    let gravity_effect = (!is_zero(d.gravity)).then(|| {
        let a = &mut sys.arena;
        let g = d.gravity.map(|c| a.scale(c, gs));
        sys.effect(None, vec![Load::Gravity(g)])
    });
    Built {
        sys,
        body,
        link_frame,
        gravity_effect,
        charts,
    }
}

// ---------------------------------------------------------------------------------------
// Random loads
// ---------------------------------------------------------------------------------------

pub fn attach(rng: &mut Rng, sys: &mut System, ground: bool) -> Attach {
    let frame = if ground && rng.chance(0.2) {
        None
    } else {
        Some(rng.below(sys.frames.len()))
    };
    let pos = rng.vec(0.4);
    Attach {
        frame,
        pos: sys.vec3(pos),
    }
}

/// c0 + c1·qd[a] + c2·sin(q[b]) + c3·q[c]·qd[d], with random coefficients and coordinates.
pub fn value(rng: &mut Rng, a: &mut Arena, n: usize) -> ExprId {
    let mut e = a.num(rng.range(-2.0, 2.0));
    let qd = a.var(Var::Qd(rng.below(n) as u16));
    let t1 = a.scale(rng.range(-1.0, 1.0), qd);
    e = a.add(e, t1);
    let q = a.var(Var::Q(rng.below(n) as u16));
    let s = a.sin(q);
    let t2 = a.scale(rng.range(-2.0, 2.0), s);
    e = a.add(e, t2);
    if rng.chance(0.5) {
        let q = a.var(Var::Q(rng.below(n) as u16));
        let qd = a.var(Var::Qd(rng.below(n) as u16));
        let p = a.mul(q, qd);
        let t3 = a.scale(rng.range(-1.0, 1.0), p);
        e = a.add(e, t3);
    }
    e
}

pub fn value3(rng: &mut Rng, a: &mut Arena, n: usize) -> [ExprId; 3] {
    [value(rng, a, n), value(rng, a, n), value(rng, a, n)]
}

/// A random unit vector as expressions.
pub fn random_unit(rng: &mut Rng, sys: &mut System) -> [ExprId; 3] {
    let v = [
        rng.range(-1.0, 1.0),
        rng.range(-1.0, 1.0),
        rng.range(0.2, 1.0),
    ];
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    sys.vec3([v[0] / n, v[1] / n, v[2] / n])
}

/// Adds random loads to a system of `n` coordinates: an effect `springs` (conservative) and
/// an effect `losses` (dampers, forces, torques, generalised forces). Returns their indices;
/// `tally` counts springs, dampers, world forces, body-frame forces, torques, torques with
/// reaction and generalised forces.
pub fn add_loads(
    rng: &mut Rng,
    sys: &mut System,
    n: usize,
    tally: &mut [usize; 7],
) -> (usize, usize) {
    let mut cons = Vec::new();
    for _ in 0..1 + rng.below(2) {
        let a = attach(rng, sys, true);
        let b = attach(rng, sys, false);
        let (kv, l0v) = (rng.range(5.0, 50.0), rng.range(0.1, 0.8));
        let (k, l0) = (sys.num(kv), sys.num(l0v));
        // a preload of either sign, from the values drawn (no draw of its own, so the random
        // sequence of the tests sharing this function is unchanged)
        let preload = sys.num(kv * (0.45 - l0v));
        // half the springs act along a fixed unit direction (linear springs)
        let axis = (rng.below(2) == 0).then(|| random_unit(rng, sys));
        cons.push(Load::Spring {
            a,
            b,
            k,
            l0,
            axis,
            preload,
        });
        tally[0] += 1;
    }
    let mut nc = Vec::new();
    {
        let a = attach(rng, sys, true);
        let b = attach(rng, sys, false);
        let c = sys.num(rng.range(0.5, 3.0));
        let axis = (rng.below(2) == 0).then(|| random_unit(rng, sys));
        nc.push(Load::Damper { a, b, c, axis });
        tally[1] += 1;
    }
    for _ in 0..1 + rng.below(2) {
        let at = attach(rng, sys, false);
        let force = value3(rng, &mut sys.arena, n);
        let frame = if rng.chance(0.5) {
            tally[3] += 1;
            Some(rng.below(sys.frames.len()))
        } else {
            tally[2] += 1;
            None
        };
        nc.push(Load::Force { at, force, frame });
    }
    for _ in 0..1 + rng.below(2) {
        let nf = sys.frames.len();
        let on = Some(rng.below(nf));
        let torque = value3(rng, &mut sys.arena, n);
        let frame = rng.chance(0.5).then(|| rng.below(nf));
        let reaction = match rng.below(3) {
            0 => None,
            1 => Some(None),
            _ => Some(Some(rng.below(nf))),
        };
        tally[if reaction.is_some() { 5 } else { 4 }] += 1;
        nc.push(Load::Torque {
            on,
            torque,
            frame,
            reaction,
        });
    }
    for _ in 0..1 + rng.below(2) {
        let dof = rng.below(n);
        let v = value(rng, &mut sys.arena, n);
        nc.push(Load::GenForce { dof, value: v });
        tally[6] += 1;
    }
    (
        sys.effect(Some("springs"), cons),
        sys.effect(Some("losses"), nc),
    )
}

/// Adds random force elements: an effect `elastic` (a bushing without damping, a contact
/// without damping or friction and an undamped rotational spring, conservative) and an effect
/// `contacts` (1 to 3 penalty contacts of points, spheres or ellipsoids with friction, linear
/// or Hunt–Crossley, a damped bushing and a damped rotational spring). The planes are placed
/// so that most contacts penetrate at the random states. Returns the two effects; `tally`
/// counts point contacts, sphere contacts, ellipsoid contacts, Hunt–Crossley contacts,
/// bushings to the ground, bushings between two frames, rotational springs about a joint's
/// axis and rotational springs about a random axis.
pub fn add_force_elements(
    rng: &mut Rng,
    sys: &mut System,
    tally: &mut [usize; 8],
) -> (usize, usize) {
    let nf = sys.frames.len();
    let mut bushing = |rng: &mut Rng, sys: &mut System, damped: bool| {
        let a = (!rng.chance(0.25)).then(|| rng.below(nf));
        let b = loop {
            let b = (!rng.chance(0.25)).then(|| rng.below(nf));
            if b != a {
                break b;
            }
        };
        tally[if a.is_none() || b.is_none() { 4 } else { 5 }] += 1;
        let mut v = |lo: f64, hi: f64| {
            let x = [rng.range(lo, hi), rng.range(lo, hi), rng.range(lo, hi)];
            sys.vec3(x)
        };
        let (k, kr) = (v(5.0, 60.0), v(1.0, 20.0));
        let (c, cr) = if damped {
            (v(0.2, 3.0), v(0.05, 1.0))
        } else {
            let z = [sys.arena.zero(); 3];
            (z, z)
        };
        Load::Bushing { a, b, k, kr, c, cr }
    };
    let mut elastic = vec![bushing(rng, sys, false)];
    let mut lossy = vec![bushing(rng, sys, true)];
    // the first contact without damping and friction: conservative
    for i in 0..2 + rng.below(3) {
        let at = attach(rng, sys, false);
        let shape = rng.below(3);
        tally[shape] += 1;
        let radius = if shape == 1 {
            sys.num(rng.range(0.05, 0.3))
        } else {
            sys.arena.zero()
        };
        let ellipsoid = (shape == 2).then(|| {
            let ax = [
                rng.range(0.05, 0.3),
                rng.range(0.05, 0.3),
                rng.range(0.05, 0.3),
            ];
            sys.vec3(ax)
        });
        // Hunt–Crossley: Hertz's exponent, and a dissipation in damped contacts
        let hertz = rng.chance(0.5);
        if hertz {
            tally[3] += 1;
        }
        let exponent = sys.num(if hertz { 1.5 } else { 1.0 });
        let dissipation = sys.num(if hertz && i > 0 {
            rng.range(0.1, 2.0)
        } else {
            0.0
        });
        let normal = random_unit(rng, sys);
        let offset = sys.num(rng.range(-0.3, 1.5));
        let k = sys.num(rng.range(50.0, 500.0));
        let c = sys.num(rng.range(5.0, 300.0));
        let mu = sys.num(if rng.chance(0.2) {
            0.0
        } else {
            rng.range(0.1, 0.8)
        });
        let eps = sys.num(rng.range(0.01, 0.3));
        let (c, mu, to) = if i == 0 {
            let z = sys.arena.zero();
            (z, z, &mut elastic)
        } else {
            (c, mu, &mut lossy)
        };
        to.push(Load::Contact {
            at,
            radius,
            ellipsoid,
            exponent,
            dissipation,
            normal,
            offset,
            k,
            c,
            mu,
            eps,
        });
    }
    // a rotational spring (elastic) and a damped one (lossy): about the axis of the one
    // rotation between a frame and its parent (θ is then that angle), or about a random axis
    // between two random frames (θ from their rotations)
    for damped in [false, true] {
        let one_rotation = |f: &usize| {
            let rots = sys.frames[*f]
                .factors
                .iter()
                .filter_map(|x| match x {
                    Factor::Rot { axis, .. } => Some(Some(*axis)),
                    // a chart turns about every axis
                    Factor::Chart(_) => Some(None),
                    Factor::Disp(_) => None,
                })
                .collect::<Vec<_>>();
            (rots.len() == 1).then(|| rots[0]).flatten()
        };
        let joints: Vec<(usize, [ExprId; 3])> = (0..nf)
            .filter_map(|f| one_rotation(&f).map(|n| (f, n)))
            .collect();
        let (a, b, axis) = if !joints.is_empty() && rng.chance(0.5) {
            tally[6] += 1;
            let (f, n) = joints[rng.below(joints.len())];
            (sys.frames[f].parent, Some(f), n)
        } else {
            tally[7] += 1;
            let a = (!rng.chance(0.25)).then(|| rng.below(nf));
            let b = loop {
                let b = (!rng.chance(0.25)).then(|| rng.below(nf));
                if b != a {
                    break b;
                }
            };
            (a, b, random_unit(rng, sys))
        };
        let k = sys.num(rng.range(1.0, 20.0));
        let angle0 = sys.num(rng.range(-0.5, 0.5));
        let c = if damped {
            sys.num(rng.range(0.05, 1.0))
        } else {
            sys.arena.zero()
        };
        let load = Load::RotationalSpring {
            a,
            b,
            axis,
            k,
            c,
            angle0,
        };
        if damped {
            lossy.push(load);
        } else {
            elastic.push(load);
        }
    }
    (
        sys.effect(Some("elastic"), elastic),
        sys.effect(Some("contacts"), lossy),
    )
}

// ---------------------------------------------------------------------------------------
// Evaluation and numerics
// ---------------------------------------------------------------------------------------

/// Values of `roots` at a state (parameters at their defaults, charts the identity).
pub fn eval(
    model: &SymbolicModel,
    roots: &[ExprId],
    t: f64,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
) -> Vec<f64> {
    eval_charts(model, roots, (t, q, qd, qdd), &[])
}

/// [`eval`] with the values of the charts (9 each, row-major).
pub fn eval_charts(
    model: &SymbolicModel,
    roots: &[ExprId],
    (t, q, qd, qdd): (f64, &[f64], &[f64], &[f64]),
    charts: &[f64],
) -> Vec<f64> {
    let params = model.sys.param_defaults();
    let env = SliceEnv {
        t,
        q,
        qd,
        qdd,
        params: &params,
        u: &[],
        lambda: &[],
        charts,
    };
    model.sys.arena.eval(roots, &env)
}

/// max |x − r| / max |r| (absolute when the reference is all zero).
pub fn rel_err(x: &[f64], r: &[f64]) -> f64 {
    assert_eq!(x.len(), r.len());
    let scale = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = x
        .iter()
        .zip(r)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    if scale > 0.0 { diff / scale } else { diff }
}

/// Like [`rel_err`] with a floor on the normalisation.
pub fn rel_err_floor(x: &[f64], r: &[f64], floor: f64) -> f64 {
    let scale = r.iter().fold(floor, |m, v| m.max(v.abs()));
    let diff = x
        .iter()
        .zip(r)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    diff / scale
}

/// Lower Cholesky factor, or `None` when the matrix is not positive definite.
pub fn cholesky(m: &[Vec<f64>]) -> Option<Vec<Vec<f64>>> {
    let n = m.len();
    let mut l = vec![vec![0.0; n]; n];
    for i in 0..n {
        for j in 0..=i {
            let s: f64 = m[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            if i == j {
                if s <= 0.0 || !s.is_finite() {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    Some(l)
}

/// Solves M x = b for a symmetric positive definite M.
pub fn solve_spd(m: &[Vec<f64>], b: &[f64]) -> Vec<f64> {
    let l = cholesky(m).expect("M positive definite");
    let n = b.len();
    let mut y = vec![0.0; n];
    for i in 0..n {
        y[i] = (b[i] - (0..i).map(|k| l[i][k] * y[k]).sum::<f64>()) / l[i][i];
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        x[i] = (y[i] - ((i + 1)..n).map(|k| l[k][i] * x[k]).sum::<f64>()) / l[i][i];
    }
    x
}

pub fn mat_vec(m: &[Vec<f64>], x: &[f64]) -> Vec<f64> {
    m.iter()
        .map(|row| row.iter().zip(x).map(|(a, b)| a * b).sum())
        .collect()
}

/// Running maximum of an error, with the case that produced it.
#[derive(Clone, Debug, Default)]
pub struct Worst {
    pub err: f64,
    pub at: String,
    pub count: usize,
}

impl Worst {
    pub fn see(&mut self, err: f64, at: impl FnOnce() -> String) {
        self.count += 1;
        if err > self.err || err.is_nan() {
            self.err = err;
            self.at = at();
        }
    }

    /// Prints and asserts the bound.
    pub fn check(&self, what: &str, bound: f64) {
        println!(
            "{what}: max rel. error {:.3e} over {} checks (worst: {})",
            self.err, self.count, self.at
        );
        assert!(
            self.err <= bound,
            "{what}: relative error {:.3e} > {bound:.0e} at {}",
            self.err,
            self.at
        );
    }
}
