//! Forward dynamics without a dense factorisation: qdd = M⁻¹ h as straight-line code, in one
//! of two forms (five, counting the articulated bodies' two places of elimination and two
//! right-hand sides), the quickest by the generator's time estimate
//! (`SceneEquations::forward`, chosen in `mech::dynamics`):
//! - **Articulated bodies** (Featherstone's articulated-body algorithm, run at zero velocity
//!   and without gravity): an inward pass of articulated inertias and forces, an outward pass
//!   of accelerations, in node axes. Its cost grows as n on a chain. It applies M⁻¹ to the h
//!   of the chosen formulation, or to the bodies' wrenches of Newton–Euler's outward pass at
//!   qdd = 0 (gravity in them, the loads taken off) with only the generalized loads as h
//!   (`bias_wrenches`): the inward pass then carries the wrenches with the articulated
//!   forces, where h computed first has carried them once already (Newton–Euler's inward
//!   pass), 6 % fewer operations on spatial arms (9–10 % on planar chains, where
//!   `mech::dynamics` keeps h: the same latency, measured no faster). It needs every
//!   coordinate to move exactly one node of the tree (a coordinate shared by two factors
//!   couples them outside the tree). Four things keep a spatial arm's joint at 205–230
//!   flops, where a full spatial transform per elementary factor cost about 300: translations
//!   that no coordinate moves and no branch separates are taken in one step; a rotation about
//!   a coordinate axis turns a 3×3 block by the double angle (`Turn`); the zeros an
//!   elimination leaves are set (`Art::clear_along`); and products keep the coefficient of a
//!   factor of parameters alone (`Arena::keep_fixed`, set by `mech::dynamics` while it
//!   builds forward dynamics: an inertia m (a² + b²)/12 times a state value is one product,
//!   not 1/12 floated out times two; 6 % of the arms' operations). The recursion is a chain
//!   of dependent steps through a division per coordinate, so its time on a planar chain is
//!   its latency, not its operation count: `Elimination` says where a rotation's coordinate
//!   is eliminated, and both are built. The outward pass, one chain through every
//!   coordinate with no other work beside it, combines each coordinate's terms in the order
//!   their values are ready (`Outward::ReadyFirst`, once the form is chosen).
//! - **Sparse LᵀDL** (Featherstone's LTDL): M = LᵀDL eliminated from the last coordinate to the
//!   first, so that a tree whose parents come before their children keeps its zeros (no
//!   fill-in); structural zeros fold in the arena. It serves any M, and small models, where it
//!   is the closed-form solve.
//!
//! Both also give the pivot of every coordinate (D of the factorisation: their product is
//! det M), which the runtime watches as it watches Cholesky's.

use super::effects::Loads;
use super::recursive::{body_wrenches, subtract_loads};
use super::spatial::{self as s, M3, V3};
use super::spin::spinning_frames;
use super::system::{Factor, System};
use super::tree::Tree;
use super::world::World;
use crate::expr::ready::{Ready, ready_combination};
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
    let mut inv_d = vec![zero; n];
    for k in (0..n).rev() {
        d[k] = l[k][k];
        let one = a.one();
        let inv = a.div(one, d[k]);
        inv_d[k] = inv;
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
    // by the pivots' reciprocals, which the factorisation has computed: a product where a
    // division would wait on its numerator again
    for i in 0..n {
        x[i] = a.mul(x[i], inv_d[i]);
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
pub type Sv = (V3, V3);

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

    fn is_zero(&self, ar: &Arena) -> bool {
        [self.a, self.b, self.c]
            .iter()
            .flatten()
            .flatten()
            .all(|&e| ar.is_num(e, 0.0))
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

    /// After a reduction along `s`, I s = 0 exactly: when s is a multiple of one axis (of
    /// rotation or of translation), the row and column of that axis are zero, and so set,
    /// which the arena cannot see from the expressions (D − U D⁻¹ U).
    fn clear_along(&mut self, ar: &Arena, (w, v): Sv) {
        let nonzero =
            |x: &V3| -> Vec<usize> { (0..3).filter(|&i| !ar.is_num(x[i], 0.0)).collect() };
        let z = ar.zero();
        match (nonzero(&w).as_slice(), nonzero(&v).as_slice()) {
            (&[i], []) => {
                for j in 0..3 {
                    self.a[i][j] = z;
                    self.a[j][i] = z;
                    self.b[i][j] = z;
                }
            }
            ([], &[i]) => {
                for j in 0..3 {
                    self.c[i][j] = z;
                    self.c[j][i] = z;
                    self.b[j][i] = z;
                }
            }
            _ => {}
        }
    }

    /// R I Rᵀ blockwise: child axes to parent axes.
    fn rotate(&self, ar: &mut Arena, r: &M3) -> Art {
        if let Some(turn) = Turn::of(ar, r) {
            let a = turn.sym(ar, &self.a);
            let c = turn.sym(ar, &self.c);
            let b = turn.general(ar, &self.b);
            return Art { a, b, c };
        }
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

/// A rotation about coordinate axis k, R = [[c, −s], [s, c]] in the plane (i, j) = (k + 1,
/// k + 2), applied to 3×3 matrices by the double angle: in that plane R P Rᵀ keeps the skew
/// part of P and turns its symmetric part's deviator by 2θ, which costs about two thirds of
/// the two products, in fewer dependent steps (the angle's terms depend on q alone).
struct Turn {
    k: usize,
    c: ExprId,
    s: ExprId,
    /// cos 2θ and sin 2θ
    c2: ExprId,
    s2: ExprId,
}

impl Turn {
    /// `r` as `spatial::rotation` builds it about a coordinate axis, or `None`.
    fn of(a: &mut Arena, r: &M3) -> Option<Turn> {
        let k = (0..3).find(|&k| {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            a.is_num(r[k][k], 1.0)
                && [r[k][i], r[k][j], r[i][k], r[j][k]]
                    .iter()
                    .all(|&e| a.is_num(e, 0.0))
                && r[i][i] == r[j][j]
        })?;
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        let (c, s) = (r[i][i], r[j][i]);
        if a.neg(s) != r[i][j] {
            return None;
        }
        let cc = a.mul(c, c);
        let ss = a.mul(s, s);
        let c2 = a.sub(cc, ss);
        let cs = a.mul(c, s);
        let s2 = a.add(cs, cs);
        Some(Turn { k, c, s, c2, s2 })
    }

    fn plane(&self) -> (usize, usize) {
        ((self.k + 1) % 3, (self.k + 2) % 3)
    }

    /// R (x, y) in the plane.
    fn vec(&self, a: &mut Arena, x: ExprId, y: ExprId) -> (ExprId, ExprId) {
        let (cx, sy) = (a.mul(self.c, x), a.mul(self.s, y));
        let (sx, cy) = (a.mul(self.s, x), a.mul(self.c, y));
        (a.sub(cx, sy), a.add(sx, cy))
    }

    /// R [[p, m], [m, q]] Rᵀ = [[μ + t, m'], [m', μ − t]] with μ = (p + q)/2, δ = (p − q)/2,
    /// t = δ cos 2θ − m sin 2θ, m' = δ sin 2θ + m cos 2θ.
    fn block(&self, a: &mut Arena, p: ExprId, q: ExprId, m: ExprId) -> [ExprId; 3] {
        let half = a.num(0.5);
        let sum = a.add(p, q);
        let mu = a.mul(half, sum);
        let diff = a.sub(p, q);
        let delta = a.mul(half, diff);
        let dc = a.mul(delta, self.c2);
        let ms = a.mul(m, self.s2);
        let t = a.sub(dc, ms);
        let ds = a.mul(delta, self.s2);
        let mc = a.mul(m, self.c2);
        [a.add(mu, t), a.add(ds, mc), a.sub(mu, t)]
    }

    /// R S Rᵀ for symmetric S.
    fn sym(&self, a: &mut Arena, m: &M3) -> M3 {
        let (i, j, k) = (self.plane().0, self.plane().1, self.k);
        let mut r = *m;
        let (x, y) = self.vec(a, m[i][k], m[j][k]);
        let [pi, pij, pj] = self.block(a, m[i][i], m[j][j], m[i][j]);
        (r[i][k], r[k][i], r[j][k], r[k][j]) = (x, x, y, y);
        (r[i][i], r[i][j], r[j][i], r[j][j]) = (pi, pij, pij, pj);
        r
    }

    /// R B Rᵀ for any B.
    fn general(&self, a: &mut Arena, m: &M3) -> M3 {
        let (i, j, k) = (self.plane().0, self.plane().1, self.k);
        let mut r = *m;
        (r[i][k], r[j][k]) = self.vec(a, m[i][k], m[j][k]);
        (r[k][i], r[k][j]) = self.vec(a, m[k][i], m[k][j]);
        let half = a.num(0.5);
        let up = a.add(m[i][j], m[j][i]);
        let sym = a.mul(half, up);
        let dn = a.sub(m[i][j], m[j][i]);
        let skew = a.mul(half, dn);
        let [pi, pij, pj] = self.block(a, m[i][i], m[j][j], sym);
        r[i][i] = pi;
        r[j][j] = pj;
        r[i][j] = a.add(pij, skew);
        r[j][i] = a.sub(pij, skew);
        r
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

/// How the outward pass of [`articulated`] sums each coordinate's u D⁻¹ − (U D⁻¹)·a.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outward {
    /// (u − U·a)·D⁻¹, U·a summed component by component
    AsBuilt,
    /// u D⁻¹ − Σ (U D⁻¹)ᵢ aᵢ, the values ready first combined first: the outward pass is one
    /// chain through every coordinate with no other work beside it, and a's components wait
    /// on the previous coordinate's qdd, so its latest terms come last (arm3d_12: the
    /// critical path of `mbs expand`'s text 886 → 804 cycles, the same operations)
    ReadyFirst,
}

/// One coordinate of a node: its unit motion S and, after the inward pass, U, D⁻¹, U D⁻¹
/// and u.
struct Joint {
    k: u16,
    s: Sv,
    u_vec: Sv,
    inv_d: ExprId,
    w: Sv,
    u: ExprId,
}

/// Where the articulated-body recursion eliminates a rotation's coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Elimination {
    /// in the parent's axes, after the rotation: the rotation runs beside the division
    /// (D = I_kk does not change under a rotation about the axis), a shorter critical path
    ParentAxes,
    /// in the child's axes, before the rotation: the zeros the elimination leaves
    /// (`Art::clear_along`) make the rotation cheaper, fewer operations
    ChildAxes,
}

/// The right-hand side of [`articulated`] with `bias`: what acts on the coordinates directly
/// (the generalized loads, less the spinning bodies' axial moments) and the bodies' wrenches
/// of Newton–Euler's outward pass at qdd = 0, the loads taken off; with them the recursion
/// solves M qdd = h of every formulation.
pub fn bias_wrenches(
    sys: &mut System,
    tree: &Tree,
    world: &World,
    loads: &Loads,
) -> (Vec<ExprId>, Vec<Sv>) {
    let mut w = body_wrenches(sys, tree, loads, false);
    let a = &mut sys.arena;
    subtract_loads(a, world, loads, &mut w.force, &mut w.moment);
    let mut direct: Vec<ExprId> = w.tau.iter().map(|&t| a.neg(t)).collect();
    for &(k, q) in &loads.generalized {
        direct[k] = a.add(direct[k], q);
    }
    (direct, w.moment.into_iter().zip(w.force).collect())
}

/// qdd = M⁻¹ h by articulated bodies; `None` when a coordinate moves no node or more than
/// one.
///
/// With `bias`, the bodies' wrenches of Newton–Euler's outward pass at qdd = 0 (per node, in
/// its axes: (moment, force), loads taken off), `h` holds only what acts on the coordinates
/// directly, and the recursion solves M qdd = h − Σ Jᵀ bias: the inward pass carries the
/// wrenches with the articulated forces, where h computed first would have carried them once
/// more (Newton–Euler's own inward pass).
pub fn articulated(
    sys: &mut System,
    tree: &Tree,
    h: &[ExprId],
    bias: Option<&[Sv]>,
    order: Elimination,
    outward: Outward,
) -> Option<Forward> {
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
    let disp_of = |n: usize| match tree.nodes[n].factor {
        Some(Factor::Disp(d)) => Some(d),
        _ => None,
    };
    // A translation no coordinate moves, whose node has one child, itself a translation no
    // coordinate moves, is taken together with that child's: the child's articulated inertia
    // (full matrices) is moved once by the sum, and the skipped node's bodies (rigid: a few
    // terms) are moved to the child's origin. On an arm, whose links are Tdisp·Trot·Tdisp,
    // this is one translation per link where there were two.
    let skip: Vec<bool> = (0..nn)
        .map(|n| {
            let node = &tree.nodes[n];
            n > 0
                && disp_of(n).is_some()
                && dofs[n].is_empty()
                && node.children.len() == 1
                && disp_of(node.children[0]).is_some()
                && dofs[node.children[0]].is_empty()
                && node.frames.iter().all(|&f| !spinning[f])
        })
        .collect();
    let a = &mut sys.arena;
    // each kept node's parent among the kept ones, and its translation from there
    let mut up = vec![0; nn];
    let mut disp: Vec<Option<V3>> = vec![None; nn];
    for n in 1..nn {
        let (mut p, mut d) = (tree.nodes[n].parent, disp_of(n));
        while skip[p] {
            let dp = disp_of(p).expect("a skipped node is a translation");
            d = d.map(|d| s::add(a, dp, d));
            p = tree.nodes[p].parent;
        }
        up[n] = p;
        disp[n] = d;
    }
    let rots = super::recursive::rotations(a, tree);
    let z3 = s::zero3(a);
    let mut inertia = vec![Art::zero(a); nn];
    let mut force: Vec<Sv> = vec![(z3, z3); nn];
    // bodies spinning about their node's axis are added in the parent's axes, where their
    // inertia is the same expression (no trigonometry of the spin angle)
    let mut spin = vec![Art::zero(a); nn];
    // a skipped node's bodies and wrench go down to the first kept node, `offset` beyond them
    let sinks: Vec<(usize, Option<V3>)> = (0..nn)
        .map(|n| {
            let (mut target, mut offset) = (n, None);
            while skip[target] {
                target = tree.nodes[target].children[0];
                let d = disp_of(target).expect("a skipped node's child is a translation");
                offset = Some(offset.map_or(d, |o| s::add(a, o, d)));
            }
            (target, offset)
        })
        .collect();
    for (n, &(m, f)) in bias.iter().flat_map(|w| w.iter().enumerate().skip(1)) {
        let (target, offset) = sinks[n];
        // the moment about the target's origin
        let m = match offset {
            Some(o) => {
                let oxf = s::cross(a, o, f);
                s::sub(a, m, oxf)
            }
            None => m,
        };
        force[target] = (s::add(a, force[target].0, m), s::add(a, force[target].1, f));
    }
    for (n, node) in tree.nodes.iter().enumerate().skip(1) {
        let (target, offset) = sinks[n];
        for &f in &node.frames {
            if let Some(inr) = sys.frames[f].inertia {
                let mut body = Art::body(a, inr.mass, s::sym(&inr.tensor));
                if let Some(o) = offset {
                    let back = s::neg(a, o);
                    body = body.translate(a, back);
                }
                if spinning[f] {
                    spin[n] = spin[n].add(a, &body);
                } else {
                    inertia[target] = inertia[target].add(a, &body);
                }
            }
        }
    }
    // A displacement's coordinates are eliminated in the child's axes (the same as the
    // parent's); a rotation's in the axes `order` says, its axis being the same vector in
    // both. With a spinning body they are eliminated in the parent's axes, where that body's
    // inertia is the same expression.
    let in_child: Vec<bool> = spin
        .iter()
        .map(|sp| order == Elimination::ChildAxes && sp.is_zero(a))
        .collect();
    let to_parent = |a: &mut Arena, (ia, p): (Art, Sv), r: &M3| {
        let ia = ia.rotate(a, r);
        (ia, (s::mul_mv(a, r, p.0), s::mul_mv(a, r, p.1)))
    };
    let to_child = |a: &mut Arena, x: Sv, r: &M3| (s::mul_mtv(a, r, x.0), s::mul_mtv(a, r, x.1));
    let mut joints: Vec<Vec<Joint>> = (0..nn).map(|_| Vec::new()).collect();
    let mut pivots = vec![a.zero(); nd];
    for n in (1..nn).rev() {
        if skip[n] {
            continue;
        }
        let fac = tree.nodes[n]
            .factor
            .expect("a node below the ground has a factor");
        let (mut ia, mut p) = (inertia[n], force[n]);
        if let Some(r) = rots[n].filter(|_| !in_child[n]) {
            (ia, p) = to_parent(a, (ia, p), &r);
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
            ia.clear_along(a, sk);
            p = sv_axpy(a, p, u, w);
            joints[n].push(Joint {
                k,
                s: sk,
                u_vec,
                inv_d,
                w,
                u,
            });
        }
        joints[n].reverse();
        if let Some(r) = rots[n].filter(|_| in_child[n]) {
            (ia, p) = to_parent(a, (ia, p), &r);
        }
        if let Some(d) = disp[n] {
            ia = ia.translate(a, d);
            let dxf = s::cross(a, d, p.1);
            p = (s::add(a, p.0, dxf), p.1);
        }
        let parent = up[n];
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
    let mut ready = Ready::default();
    for n in 1..nn {
        if skip[n] {
            continue;
        }
        let mut x = acc[up[n]];
        if let Some(d) = disp[n] {
            // v_child = v_parent + α × d
            let axd = s::cross(a, x.0, d);
            x = (x.0, s::add(a, x.1, axd));
        }
        if let Some(r) = rots[n].filter(|_| in_child[n]) {
            x = to_child(a, x, &r);
        }
        for j in &joints[n] {
            let qk = match outward {
                Outward::AsBuilt => {
                    let ua = sv_dot(a, j.u_vec, x);
                    let num = a.sub(j.u, ua);
                    a.mul(num, j.inv_d)
                }
                Outward::ReadyFirst => {
                    let mut signed = vec![(a.mul(j.u, j.inv_d), false)];
                    for i in 0..3 {
                        for (wi, xi) in [(j.w.0[i], x.0[i]), (j.w.1[i], x.1[i])] {
                            signed.push((a.mul(wi, xi), true));
                        }
                    }
                    ready_combination(a, &mut ready, signed)
                }
            };
            qdd[j.k as usize] = qk;
            x = sv_axpy(a, x, qk, j.s);
        }
        if let Some(r) = rots[n].filter(|_| !in_child[n]) {
            x = to_child(a, x, &r);
        }
        acc[n] = x;
    }
    Some(Forward {
        method: ForwardMethod::ArticulatedBody,
        qdd,
        pivots,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::SliceEnv;

    /// Matrices of parameters, so that nothing folds.
    fn params(a: &mut Arena, first: u16, symmetric: bool) -> M3 {
        let mut m = s::identity(a);
        let mut k = first;
        for r in 0..3 {
            for c in 0..3 {
                if symmetric && c < r {
                    m[r][c] = m[c][r];
                    continue;
                }
                m[r][c] = a.var(Var::Param(k));
                k += 1;
            }
        }
        m
    }

    #[test]
    fn turns_about_each_axis_equal_the_two_products() {
        let values: Vec<f64> = (0..30).map(|i| (0.37 * i as f64).sin() + 0.1).collect();
        for k in 0..3 {
            for sign in [1.0, -1.0] {
                let mut a = Arena::new();
                let theta = a.var(Var::Q(0));
                let mut axis = [0.0; 3];
                axis[k] = sign;
                let axis = axis.map(|c| a.num(c));
                let r = s::rotation(&mut a, axis, theta);
                let turn = Turn::of(&mut a, &r).expect("a coordinate axis");
                assert_eq!(turn.k, k);
                let sym = params(&mut a, 0, true);
                let any = params(&mut a, 9, false);
                let (fast_s, fast_g) = (turn.sym(&mut a, &sym), turn.general(&mut a, &any));
                let slow_s = congruence_sym(&mut a, &r, &sym);
                let rg = s::mul_mm(&mut a, &r, &any);
                let slow_g = s::mul_mm(&mut a, &rg, &s::transpose(&r));
                let roots: Vec<ExprId> = [fast_s, fast_g, slow_s, slow_g]
                    .iter()
                    .flatten()
                    .flatten()
                    .copied()
                    .collect();
                let env = SliceEnv {
                    q: &[0.7],
                    params: &values,
                    ..SliceEnv::default()
                };
                let v = a.eval(&roots, &env);
                for i in 0..18 {
                    assert!((v[i] - v[i + 18]).abs() < 1e-14, "axis {k} {sign}: {i}");
                }
            }
        }
        // a rotation about a general axis is not a turn
        let mut a = Arena::new();
        let theta = a.var(Var::Q(0));
        let axis = [0.6, 0.0, 0.8].map(|c| a.num(c));
        let r = s::rotation(&mut a, axis, theta);
        assert!(Turn::of(&mut a, &r).is_none());
    }

    /// A spatial arm with joints about z, y, −x and a slider along y, links offset along x:
    /// both eliminations give the same qdd for any h.
    #[test]
    fn both_eliminations_agree() {
        let mut sys = System::new("arm");
        for i in 0..4 {
            sys.dof(&format!("q{i}"), 0.0, 0.0);
        }
        let axes = [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]];
        let mut parent = None;
        for (i, axis) in axes.iter().enumerate() {
            let q = sys.q(i);
            let factors = vec![
                sys.disp([0.15, 0.0, 0.0]),
                sys.rot(*axis, q),
                sys.disp([0.15, 0.02, 0.0]),
            ];
            let inr = sys.inertia(1.0 + i as f64, [0.01, 0.02, 0.03, 0.001, 0.0, 0.002]);
            parent = Some(sys.frame(&format!("l{i}"), parent, factors, Some(inr)));
        }
        let q = sys.q(3);
        let z = sys.arena.zero();
        let slide = Factor::Disp([z, q, z]);
        let inr = sys.inertia(0.5, [0.01, 0.01, 0.01, 0.0, 0.0, 0.0]);
        sys.frame("slider", parent, vec![slide], Some(inr));
        let tree = Tree::build(&mut sys);
        let h: Vec<ExprId> = (0..4).map(|k| sys.arena.var(Var::Param(k))).collect();
        // both places of elimination, and both ways of summing the outward pass
        let fwd = [
            (Elimination::ParentAxes, Outward::AsBuilt),
            (Elimination::ChildAxes, Outward::AsBuilt),
            (Elimination::ParentAxes, Outward::ReadyFirst),
            (Elimination::ChildAxes, Outward::ReadyFirst),
        ]
        .map(|(e, o)| articulated(&mut sys, &tree, &h, None, e, o).expect("a tree"));
        let env = SliceEnv {
            q: &[0.3, -0.8, 1.1, 0.05],
            params: &[1.0, -2.0, 0.5, 3.0],
            ..SliceEnv::default()
        };
        let x = sys.arena.eval(&fwd[0].roots(), &env);
        for other in &fwd[1..] {
            let y = sys.arena.eval(&other.roots(), &env);
            for (i, (x, y)) in x.iter().zip(&y).enumerate() {
                assert!(
                    (x - y).abs() <= 1e-12 * x.abs().max(1.0),
                    "{i}: {x} against {y}"
                );
            }
        }
        // about the same operations (U D⁻¹ is the elimination's, but a product of a number
        // of U by D⁻¹ may be new: one per coordinate at most); the outward pass's chain shorter
        let ops = |f: &Forward| crate::expr::ops(&sys.arena, &f.roots()).flops();
        let path = |f: &Forward| crate::expr::critical_path(&sys.arena, &f.roots());
        for (built, ready) in [(&fwd[0], &fwd[2]), (&fwd[1], &fwd[3])] {
            assert!(
                ops(ready) <= ops(built) + 4,
                "{} {}",
                ops(ready),
                ops(built)
            );
            assert!(path(ready) < path(built), "{} {}", path(ready), path(built));
        }
    }
}
