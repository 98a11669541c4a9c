//! Forward dynamics without a dense factorisation: qdd = M⁻¹ h as straight-line code, in one
//! of two forms chosen by op count (`SceneEquations::forward`):
//! - **Articulated bodies** (Featherstone's articulated-body algorithm, run at zero velocity
//!   and without gravity, so that it applies M⁻¹ to the h of the chosen formulation): an
//!   inward pass of articulated inertias and forces, an outward pass of accelerations, in node
//!   axes. Its cost grows as n on a chain. It needs every coordinate to move exactly one node
//!   of the tree (a coordinate shared by two factors couples them outside the tree).
//! - **Sparse LᵀDL** (Featherstone's LTDL): M = LᵀDL eliminated from the last coordinate to the
//!   first, so that a tree whose parents come before their children keeps its zeros (no
//!   fill-in); structural zeros fold in the arena. It serves any M, and small models, where it
//!   is the closed-form solve.
//!
//! Both also give the pivot of every coordinate (D of the factorisation: their product is
//! det M), which the runtime watches as it watches Cholesky's.

use super::spatial::{self as s, M3, V3};
use super::spin::spinning_frames;
use super::system::{Factor, System};
use super::tree::Tree;
use crate::expr::{Arena, ExprId, Var};

/// Which form a model's forward dynamics takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ForwardMethod {
    ArticulatedBody,
    SparseLtdl,
}

impl ForwardMethod {
    pub fn name(self) -> &'static str {
        match self {
            ForwardMethod::ArticulatedBody => "articulated body",
            ForwardMethod::SparseLtdl => "sparse LTDL",
        }
    }
}

/// qdd and the pivot of each coordinate, as DAG roots.
#[derive(Clone, Debug)]
pub struct Forward {
    pub method: ForwardMethod,
    pub qdd: Vec<ExprId>,
    pub pivots: Vec<ExprId>,
}

impl Forward {
    pub fn roots(&self) -> Vec<ExprId> {
        let mut v = self.qdd.clone();
        v.extend_from_slice(&self.pivots);
        v
    }
}

/// Multiply–subtract pairs sparse LᵀDL of `m` would take, from its structure alone (entries
/// that are the number 0 stay 0 unless filled): a cheap bound that spares building the
/// factorisation of a long chain, where articulated bodies win by far.
pub fn ltdl_estimate(a: &Arena, m: &[Vec<ExprId>]) -> usize {
    let n = m.len();
    let mut nz: Vec<Vec<bool>> = m
        .iter()
        .map(|row| row.iter().map(|&e| !a.is_num(e, 0.0)).collect())
        .collect();
    let mut ops = 0;
    for k in (0..n).rev() {
        for i in (0..k).rev() {
            if !nz[k][i] {
                continue;
            }
            for j in 0..=i {
                if nz[k][j] {
                    nz[i][j] = true;
                    ops += 1;
                }
            }
        }
    }
    ops
}

/// qdd = M⁻¹ h by sparse LᵀDL of the symmetric `m` (rows of expressions).
pub fn ltdl(a: &mut Arena, m: &[Vec<ExprId>], h: &[ExprId]) -> Forward {
    let n = h.len();
    let mut l: Vec<Vec<ExprId>> = m.to_vec();
    let zero = a.zero();
    let nonzero = |a: &Arena, e: ExprId| !a.is_num(e, 0.0);
    let mut d = vec![zero; n];
    for k in (0..n).rev() {
        d[k] = l[k][k];
        let one = a.one();
        let inv = a.div(one, d[k]);
        for i in (0..k).rev() {
            if !nonzero(a, l[k][i]) {
                continue;
            }
            let f = a.mul(l[k][i], inv);
            for j in 0..=i {
                if nonzero(a, l[k][j]) {
                    let p = a.mul(f, l[k][j]);
                    l[i][j] = a.sub(l[i][j], p);
                }
            }
            l[k][i] = f;
        }
    }
    // Lᵀ z = h, from the last coordinate
    let mut x = h.to_vec();
    for i in (0..n).rev() {
        for j in 0..i {
            if nonzero(a, l[i][j]) {
                let p = a.mul(l[i][j], x[i]);
                x[j] = a.sub(x[j], p);
            }
        }
    }
    for i in 0..n {
        x[i] = a.div(x[i], d[i]);
    }
    // L x = w, from the first
    for i in 0..n {
        for j in 0..i {
            if nonzero(a, l[i][j]) {
                let p = a.mul(l[i][j], x[j]);
                x[i] = a.sub(x[i], p);
            }
        }
    }
    Forward {
        method: ForwardMethod::SparseLtdl,
        qdd: x,
        pivots: d,
    }
}

/// A spatial inertia [[A, B], [Bᵀ, C]] about a node's origin in its axes (A, C symmetric),
/// acting on motions (ω, v) and giving forces (moment, force).
#[derive(Clone, Copy)]
struct Art {
    a: M3,
    b: M3,
    c: M3,
}

/// A spatial vector (angular, linear).
type Sv = (V3, V3);

fn sym_from_upper(a: &mut Arena, f: impl Fn(&mut Arena, usize, usize) -> ExprId) -> M3 {
    let mut m = s::identity(a);
    for r in 0..3 {
        for c in r..3 {
            let e = f(a, r, c);
            m[r][c] = e;
            m[c][r] = e;
        }
    }
    m
}

fn madd(a: &mut Arena, x: &M3, y: &M3) -> M3 {
    let mut m = *x;
    for r in 0..3 {
        for c in 0..3 {
            m[r][c] = a.add(x[r][c], y[r][c]);
        }
    }
    m
}

impl Art {
    fn zero(a: &Arena) -> Art {
        let z = [s::zero3(a); 3];
        Art { a: z, b: z, c: z }
    }

    fn add(&self, ar: &mut Arena, o: &Art) -> Art {
        let a = sym_from_upper(ar, |ar, r, c| ar.add(self.a[r][c], o.a[r][c]));
        let c = sym_from_upper(ar, |ar, r, c| ar.add(self.c[r][c], o.c[r][c]));
        Art {
            a,
            b: madd(ar, &self.b, &o.b),
            c,
        }
    }

    /// A rigid body of mass `m` and inertia `phi` about its centre, at the origin.
    fn body(a: &mut Arena, m: ExprId, phi: M3) -> Art {
        let z = a.zero();
        let mut c = [s::zero3(a); 3];
        for (k, row) in c.iter_mut().enumerate() {
            row[k] = m;
        }
        Art {
            a: phi,
            b: [[z; 3]; 3],
            c,
        }
    }

    /// U = I S.
    fn apply(&self, ar: &mut Arena, (w, v): Sv) -> Sv {
        let aw = s::mul_mv(ar, &self.a, w);
        let bv = s::mul_mv(ar, &self.b, v);
        let btw = s::mul_mtv(ar, &self.b, w);
        let cv = s::mul_mv(ar, &self.c, v);
        (s::add(ar, aw, bv), s::add(ar, btw, cv))
    }

    /// I − U Uᵀ / D, given W = U / D.
    fn reduce(&self, ar: &mut Arena, (ua, ul): Sv, (wa, wl): Sv) -> Art {
        let a = sym_from_upper(ar, |ar, r, c| {
            let p = ar.mul(wa[r], ua[c]);
            ar.sub(self.a[r][c], p)
        });
        let c = sym_from_upper(ar, |ar, r, c| {
            let p = ar.mul(wl[r], ul[c]);
            ar.sub(self.c[r][c], p)
        });
        let mut b = self.b;
        for r in 0..3 {
            for c in 0..3 {
                let p = ar.mul(wa[r], ul[c]);
                b[r][c] = ar.sub(self.b[r][c], p);
            }
        }
        Art { a, b, c }
    }

    /// R I Rᵀ blockwise: child axes to parent axes.
    fn rotate(&self, ar: &mut Arena, r: &M3) -> Art {
        let rt = s::transpose(r);
        let a = congruence_sym(ar, r, &self.a);
        let c = congruence_sym(ar, r, &self.c);
        let rb = s::mul_mm(ar, r, &self.b);
        let b = s::mul_mm(ar, &rb, &rt);
        Art { a, b, c }
    }

    /// Moved to the parent's origin, the child's origin being at `d` (same axes):
    /// A' = A − BD − (BD)ᵀ − DCD, B' = B + DC, C' = C, with D = [d]×.
    fn translate(&self, ar: &mut Arena, d: V3) -> Art {
        let dx = skew(ar, d);
        let bd = s::mul_mm(ar, &self.b, &dx);
        let dc = s::mul_mm(ar, &dx, &self.c);
        let dcd = s::mul_mm(ar, &dc, &dx);
        let a = sym_from_upper(ar, |ar, r, c| {
            let x = ar.sub(self.a[r][c], bd[r][c]);
            let x = ar.sub(x, bd[c][r]);
            ar.sub(x, dcd[r][c])
        });
        Art {
            a,
            b: madd(ar, &self.b, &dc),
            c: self.c,
        }
    }
}

fn skew(a: &mut Arena, d: V3) -> M3 {
    let z = a.zero();
    let n = |a: &mut Arena, x| a.neg(x);
    [
        [z, n(a, d[2]), d[1]],
        [d[2], z, n(a, d[0])],
        [n(a, d[1]), d[0], z],
    ]
}

/// R S Rᵀ for symmetric S, upper triangle computed.
fn congruence_sym(a: &mut Arena, r: &M3, sm: &M3) -> M3 {
    let rs = s::mul_mm(a, r, sm);
    sym_from_upper(a, |a, i, j| a.dot(&rs[i], &r[j]))
}

fn sv_dot(a: &mut Arena, x: Sv, y: Sv) -> ExprId {
    let p = s::dot(a, x.0, y.0);
    let q = s::dot(a, x.1, y.1);
    a.add(p, q)
}

fn sv_axpy(a: &mut Arena, x: Sv, k: ExprId, y: Sv) -> Sv {
    let p = s::scale(a, k, y.0);
    let q = s::scale(a, k, y.1);
    (s::add(a, x.0, p), s::add(a, x.1, q))
}

/// One coordinate of a node: its unit motion S and, after the inward pass, U, D⁻¹ and u.
struct Joint {
    k: u16,
    s: Sv,
    u_vec: Sv,
    inv_d: ExprId,
    u: ExprId,
}

/// qdd = M⁻¹ h by articulated bodies; `None` when a coordinate moves no node or more than
/// one.
pub fn articulated(sys: &mut System, tree: &Tree, h: &[ExprId]) -> Option<Forward> {
    let nd = sys.ndof();
    let nn = tree.nodes.len();
    let dofs: Vec<Vec<u16>> = (0..nn).map(|n| tree.factor_dofs(&sys.arena, n)).collect();
    let mut owner = vec![usize::MAX; nd];
    for (n, ks) in dofs.iter().enumerate() {
        for &k in ks {
            if owner[k as usize] != usize::MAX {
                return None;
            }
            owner[k as usize] = n;
        }
    }
    if owner.contains(&usize::MAX) {
        return None;
    }
    let spinning = spinning_frames(sys, tree);
    let a = &mut sys.arena;
    let rots = super::recursive::rotations(a, tree);
    let z3 = s::zero3(a);
    let mut inertia = vec![Art::zero(a); nn];
    let mut force: Vec<Sv> = vec![(z3, z3); nn];
    // bodies spinning about their node's axis are added in the parent's axes, where their
    // inertia is the same expression (no trigonometry of the spin angle)
    let mut spin = vec![Art::zero(a); nn];
    for (n, node) in tree.nodes.iter().enumerate().skip(1) {
        for &f in &node.frames {
            if let Some(inr) = sys.frames[f].inertia {
                let body = Art::body(a, inr.mass, s::sym(&inr.tensor));
                if spinning[f] {
                    spin[n] = spin[n].add(a, &body);
                } else {
                    inertia[n] = inertia[n].add(a, &body);
                }
            }
        }
    }
    let mut joints: Vec<Vec<Joint>> = (0..nn).map(|_| Vec::new()).collect();
    let mut pivots = vec![a.zero(); nd];
    for n in (1..nn).rev() {
        let fac = tree.nodes[n]
            .factor
            .expect("a node below the ground has a factor");
        let (mut ia, mut p) = (inertia[n], force[n]);
        // a rotation's coordinates are eliminated in the parent's axes, a displacement's in
        // the child's (the same there)
        if let Some(r) = rots[n] {
            ia = ia.rotate(a, &r);
            p = (s::mul_mv(a, &r, p.0), s::mul_mv(a, &r, p.1));
            ia = ia.add(a, &spin[n]);
        }
        for &k in dofs[n].iter().rev() {
            let sk: Sv = match fac {
                Factor::Rot { axis, angle } => {
                    let d = a.diff(angle, Var::Q(k));
                    (s::scale(a, d, axis), z3)
                }
                Factor::Disp(dv) => (z3, dv.map(|e| a.diff(e, Var::Q(k)))),
                Factor::Chart(_) => unreachable!("a chart moves with no coordinate"),
            };
            let u_vec = ia.apply(a, sk);
            let d = sv_dot(a, sk, u_vec);
            pivots[k as usize] = d;
            let one = a.one();
            let inv_d = a.div(one, d);
            let sp = sv_dot(a, sk, p);
            let u = a.sub(h[k as usize], sp);
            let w = (s::scale(a, inv_d, u_vec.0), s::scale(a, inv_d, u_vec.1));
            ia = ia.reduce(a, u_vec, w);
            p = sv_axpy(a, p, u, w);
            joints[n].push(Joint {
                k,
                s: sk,
                u_vec,
                inv_d,
                u,
            });
        }
        joints[n].reverse();
        if let Factor::Disp(d) = fac {
            ia = ia.translate(a, d);
            let dxf = s::cross(a, d, p.1);
            p = (s::add(a, p.0, dxf), p.1);
        }
        let parent = tree.nodes[n].parent;
        if parent != 0 {
            inertia[parent] = inertia[parent].add(a, &ia);
            force[parent] = (
                s::add(a, force[parent].0, p.0),
                s::add(a, force[parent].1, p.1),
            );
        }
    }
    let mut acc: Vec<Sv> = vec![(z3, z3); nn];
    let mut qdd = vec![a.zero(); nd];
    for n in 1..nn {
        let fac = tree.nodes[n]
            .factor
            .expect("a node below the ground has a factor");
        let mut x = acc[tree.nodes[n].parent];
        if let Factor::Disp(d) = fac {
            // v_child = v_parent + α × d
            let axd = s::cross(a, x.0, d);
            x = (x.0, s::add(a, x.1, axd));
        }
        for j in &joints[n] {
            let ua = sv_dot(a, j.u_vec, x);
            let num = a.sub(j.u, ua);
            let qk = a.mul(num, j.inv_d);
            qdd[j.k as usize] = qk;
            x = sv_axpy(a, x, qk, j.s);
        }
        if let Some(r) = rots[n] {
            x = (s::mul_mtv(a, &r, x.0), s::mul_mtv(a, &r, x.1));
        }
        acc[n] = x;
    }
    Some(Forward {
        method: ForwardMethod::ArticulatedBody,
        qdd,
        pivots,
    })
}
