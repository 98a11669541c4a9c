//! Everything a scene's model computes, as DAG roots: M, h and τ from the cheaper formulation
//! (or the one the model forces), tangents when asked for, energies, power, static forces.

use super::effects::Loads;
use super::forward::{
    Elimination, Forward, Outward, articulated, bias_wrenches, ltdl, ltdl_estimate,
};
use super::recursive::{body_kinematics, crba, newton_euler, spinning_body_motion};
use super::spin::spinning_frames;

use super::spatial::{self as s, Matrix};
use super::system::{Factor, Formulation, Load, System};
use super::tree::Tree;
use super::virtual_power::virtual_power;
use super::world::World;
use crate::expr::{Arena, ExprId, Var};
use rustc_hash::FxHashMap;

/// M (dense, row-major) and h of one formulation.
#[derive(Clone, Debug)]
pub struct MassBias {
    pub m: Vec<Vec<ExprId>>,
    pub h: Vec<ExprId>,
}

impl MassBias {
    /// Roots of the lower triangle of M then h.
    pub fn roots(&self) -> Vec<ExprId> {
        let mut v: Vec<ExprId> = Vec::new();
        for (r, row) in self.m.iter().enumerate() {
            v.extend_from_slice(&row[..=r]);
        }
        v.extend_from_slice(&self.h);
        v
    }
}

/// The symbolic equations of one scene.
#[derive(Clone, Debug)]
pub struct SceneEquations {
    /// scene index (`None`: the model without scenes)
    pub scene: Option<usize>,
    pub effects: Vec<usize>,
    /// virtual power M, h; not built for large models ([`VP_PAIRS_LIMIT`]) or when the
    /// recursive formulation is forced
    pub vp: Option<MassBias>,
    /// recursive M (composite inertia), h (Newton–Euler)
    pub rec: MassBias,
    /// the formulation used for M and h
    pub formulation: Formulation,
    /// τ = M qdd − h by Newton–Euler
    pub tau_rec: Vec<ExprId>,
    /// τ = M qdd − h from the virtual-power M and h (when built)
    pub tau_vp: Option<Vec<ExprId>>,
    /// the formulation used for τ
    pub tau_formulation: Formulation,
    /// h with qd = 0
    pub static_h: Vec<ExprId>,
    /// ∂h/∂u (dense, row-major, NQ × NU): how inputs enter the equations
    pub input_matrix: Matrix,
    /// K_t = ∂τ/∂q and C_t = ∂τ/∂qd (dense, row-major), when the model asks for them and the
    /// scene does not take them from the model's shared parts (`shared_parts`)
    pub tangents: Option<(Matrix, Matrix)>,
    /// With parts shared by the scenes: the parts of `SymbolicModel::shared_parts` whose
    /// sums are this scene's static forces, energies, power and, with tangents, τ, K_t and C_t
    /// (the bodies' and the common effects' first, then the groups of its other effects);
    /// empty when the scene has its own
    pub shared_parts: Vec<usize>,
    /// ∂τ/∂p (NQ × NS) for the parameters marked `sensitive`, in declaration order
    pub param_tangents: Option<Matrix>,
    /// With sensitive parameters and tangents: how M, C = ∂τ/∂qd and K = ∂τ/∂q at rest
    /// (qd = qdd = 0) change, as three NQ × NQ·(1 + NS) matrices [M', C', K'] whose block 0 is
    /// the derivative along a direction δq (the variables `Qd` stand for δq, which the
    /// matrices at rest no longer contain) and block 1 + j the partial derivative by
    /// sensitive parameter j: what pole sensitivities need along the equilibria
    pub rest_tangent_derivatives: Option<[Matrix; 3]>,
    /// ∂q₀/∂p and ∂qd₀/∂p (NQ × NS each) of the declared start, for the parameters marked
    /// `sensitive`: where the sensitivities start
    pub start_sensitivities: Option<(Matrix, Matrix)>,
    pub kinetic: ExprId,
    pub potential: ExprId,
    /// power of the non-conservative effects
    pub power: ExprId,
    /// qdd = M⁻¹ h without a dense factorisation, in the cheaper form
    pub forward: Forward,
}

impl SceneEquations {
    /// M and h of the chosen formulation.
    pub fn chosen(&self) -> &MassBias {
        pick(self.formulation, self.vp.as_ref(), &self.rec)
    }

    /// τ of the chosen formulation.
    pub fn tau(&self) -> &[ExprId] {
        pick(self.tau_formulation, self.tau_vp.as_ref(), &self.tau_rec).as_slice()
    }

    pub fn build(
        sys: &mut System,
        tree: &Tree,
        world: &World,
        scene: Option<usize>,
        common: Option<&[usize]>,
    ) -> SceneEquations {
        let nd = sys.ndof();
        let effects = sys.scene_effects(scene);
        // the scene takes its static forces, energies, power (and, with tangents, τ and its
        // tangents) from the model's shared parts when its own effects (the ones not every
        // scene has) act on the coordinates without gravity, which acts through the bodies
        let shares = common.is_some_and(|common| {
            let own = effects.iter().filter(|e| !common.contains(e));
            let loads = own.flat_map(|&e| &sys.effects[e].loads);
            !loads.into_iter().any(|l| matches!(l, Load::Gravity(_)))
        });
        let loads = Loads::build(sys, tree, world, &effects);
        let vp = build_virtual_power(sys, tree, world).then(|| {
            let (m, h) = virtual_power(sys, tree, world, &loads);
            MassBias { m, h }
        });
        let m_rec = crba(sys, tree);
        let minus_h = newton_euler(sys, tree, world, &loads, false);
        let h_rec: Vec<ExprId> = minus_h.iter().map(|&x| sys.arena.neg(x)).collect();
        let rec = MassBias { m: m_rec, h: h_rec };
        let tau_rec = newton_euler(sys, tree, world, &loads, true);
        let a = &mut sys.arena;
        let qdd: Vec<ExprId> = (0..nd).map(|k| a.var(Var::Qdd(k as u16))).collect();
        let tau_vp: Option<Vec<ExprId>> = vp.as_ref().map(|vp| {
            (0..nd)
                .map(|i| {
                    let mq = a.dot(&vp.m[i], &qdd);
                    a.sub(mq, vp.h[i])
                })
                .collect()
        });
        let cost = |a: &Arena, r: &[ExprId]| crate::expr::ops(a, r).flops();
        let formulation = match (sys.options.formulation, &vp) {
            (Some(f), _) => f,
            (None, Some(vp)) if cost(a, &vp.roots()) < cost(a, &rec.roots()) => {
                Formulation::VirtualPower
            }
            _ => Formulation::Recursive,
        };
        let tau_formulation = match (sys.options.formulation, &tau_vp) {
            (Some(f), _) => f,
            (None, Some(t)) if cost(a, t) < cost(a, &tau_rec) => Formulation::VirtualPower,
            _ => Formulation::Recursive,
        };
        let chosen_h = pick(formulation, vp.as_ref(), &rec).h.clone();
        let mut zero_qd = FxHashMap::default();
        for k in 0..nd {
            zero_qd.insert(Var::Qd(k as u16), a.zero());
        }
        let static_h = a.substitute(&chosen_h, &zero_qd);
        let nu = sys.inputs.len();
        let input_matrix: Matrix = chosen_h
            .iter()
            .map(|&e| (0..nu).map(|k| a.diff(e, Var::Input(k as u16))).collect())
            .collect();
        let tau: Vec<ExprId> = pick(tau_formulation, tau_vp.as_ref(), &tau_rec).clone();
        let a = &mut sys.arena;
        let tangents = (sys.options.tangents && !shares).then(|| tangent_matrices(a, &tau));
        // ∂τ/∂p of the parameters marked `sensitive` (NQ × NS), the derivatives flowing
        // through every `let` and derived value since those are expressions of the parameters
        let sensitive: Vec<u16> = (0..sys.params.len())
            .filter(|&i| sys.params[i].sensitive)
            .map(|i| i as u16)
            .collect();
        // ∂e/∂p of each expression e (a row each) by the sensitive parameters
        let by_params = |a: &mut Arena, exprs: &[ExprId]| -> Matrix {
            exprs
                .iter()
                .map(|&e| {
                    sensitive
                        .iter()
                        .map(|&p| a.diff(e, Var::Param(p)))
                        .collect()
                })
                .collect()
        };
        let param_tangents = (!sensitive.is_empty()).then(|| by_params(a, &tau));
        let start_sensitivities = (!sensitive.is_empty()).then(|| {
            let (q0, qd0): (Vec<ExprId>, Vec<ExprId>) =
                sys.dofs.iter().map(|d| (d.q0, d.qd0)).unzip();
            (by_params(a, &q0), by_params(a, &qd0))
        });
        let rest_tangent_derivatives = match (&tangents, param_tangents.is_some()) {
            (Some((k, c)), true) => {
                let rest = at_rest(a, nd);
                let m: Matrix = tau
                    .iter()
                    .map(|&t| (0..nd).map(|j| a.diff(t, Var::Qdd(j as u16))).collect())
                    .collect();
                let mut at_rest = |x: &Matrix| -> Matrix {
                    x.iter().map(|row| a.substitute(row, &rest)).collect()
                };
                let rested = [at_rest(&m), at_rest(c), at_rest(k)];
                Some(rested.map(|x| along_and_by(a, &x, nd, &sensitive)))
            }
            _ => None,
        };
        let forward = forward_dynamics(
            sys,
            tree,
            world,
            &loads,
            pick(formulation, vp.as_ref(), &rec),
        );
        let (kinetic, potential) = energies(sys, tree, world, &loads);
        let power = loads.power.unwrap_or(sys.arena.zero());
        SceneEquations {
            scene,
            effects,
            vp,
            rec,
            formulation,
            tau_rec,
            tau_vp,
            tau_formulation,
            static_h,
            input_matrix,
            tangents,
            shared_parts: if shares { vec![0] } else { Vec::new() },
            param_tangents,
            rest_tangent_derivatives,
            start_sensitivities,
            kinetic,
            potential,
            power,
            forward,
        }
    }
}

/// The virtual-power form of something when it is the formulation and was built, else the
/// recursive one.
fn pick<'a, T>(formulation: Formulation, vp: Option<&'a T>, rec: &'a T) -> &'a T {
    match (formulation, vp) {
        (Formulation::VirtualPower, Some(vp)) => vp,
        _ => rec,
    }
}

/// Above this many products of Jacobian columns (Σ over bodies of k(k+1)/2 for the k columns
/// of J_G and of J_ω), the virtual-power formulation is not built: its M grows as the square
/// of each body's number of coordinates, the recursive one's as that number, and building it
/// is then most of the generator's time for nothing (a 200-bar chain: about 1.3 million
/// products; it was chosen only on models far below, e.g. a Cartesian double pendulum).
pub const VP_PAIRS_LIMIT: usize = 20_000;

/// K = ∂τ/∂q and C = ∂τ/∂qd, rows of τ.
pub fn tangent_matrices(a: &mut Arena, tau: &[ExprId]) -> (Matrix, Matrix) {
    let nd = tau.len();
    let k: Matrix = tau
        .iter()
        .map(|&t| (0..nd).map(|j| a.diff(t, Var::Q(j as u16))).collect())
        .collect();
    let c: Matrix = tau
        .iter()
        .map(|&t| (0..nd).map(|j| a.diff(t, Var::Qd(j as u16))).collect())
        .collect();
    (k, c)
}

/// Whether to build the virtual-power formulation: unless the recursive one is forced, or
/// the model is beyond [`VP_PAIRS_LIMIT`] without virtual power forced.
fn build_virtual_power(sys: &System, tree: &Tree, world: &World) -> bool {
    match sys.options.formulation {
        Some(Formulation::VirtualPower) => return true,
        Some(Formulation::Recursive) => return false,
        None => {}
    }
    let pairs = |k: usize| k * (k + 1) / 2;
    let mut total = 0;
    for (n, node) in tree.nodes.iter().enumerate().skip(1) {
        let bodies = node
            .frames
            .iter()
            .filter(|&&f| sys.frames[f].inertia.is_some())
            .count();
        let k = &world.nodes[n];
        total += bodies * (pairs(k.jv.len()) + pairs(k.jw.len()));
    }
    total <= VP_PAIRS_LIMIT
}

/// The quickest of articulated bodies (when the tree allows it, with a rotation's coordinates
/// eliminated in the parent's or the child's axes) and sparse LᵀDL, applied to `mb`'s h plus
/// a generalised force given at run time (`Var::Force`, zero in the generated
/// `forward_dynamics`, the efforts of `mbs::WithEfforts` in `forward_dynamics_forced`).
///
/// Quickest by [`time_estimate`]: the articulated-body recursion is a chain of dependent
/// steps through a division per coordinate, so on a planar chain its latency, not its
/// operation count, sets its time; on a spatial arm its operations do.
fn forward_dynamics(
    sys: &mut System,
    tree: &Tree,
    world: &World,
    loads: &Loads,
    mb: &MassBias,
) -> Forward {
    let h = forced(&mut sys.arena, &mb.h);
    // products keep their parameter-only factors' coefficients: the articulated bodies'
    // inertias (m (a² + b²)/12 and the like) multiply state values many times over, and
    // floating the coefficient out (for the sums' like terms, which M and h need) would
    // cost a product each time (arm3d_12: 2,648 → 2,483 flops)
    let kept = std::mem::replace(&mut sys.arena.keep_fixed, true);
    let f = forward_forms(sys, tree, world, loads, mb, &h);
    sys.arena.keep_fixed = kept;
    f
}

/// h + f, f the generalised forces `Var::Force` of the runtime's efforts.
fn forced(a: &mut Arena, h: &[ExprId]) -> Vec<ExprId> {
    (0..h.len())
        .map(|i| {
            let f = a.var(Var::Force(i as u16));
            a.add(h[i], f)
        })
        .collect()
}

fn forward_forms(
    sys: &mut System,
    tree: &Tree,
    world: &World,
    loads: &Loads,
    mb: &MassBias,
    h: &[ExprId],
) -> Forward {
    let plain = Outward::AsBuilt;
    let Some(parent) = articulated(sys, tree, h, None, Elimination::ParentAxes, plain) else {
        return ltdl(&mut sys.arena, &mb.m, h);
    };
    // the articulated bodies also take the bodies' wrenches of Newton–Euler's outward pass,
    // with only what acts on the coordinates directly as h
    let (direct, bias) = bias_wrenches(sys, tree, world, loads);
    let direct = forced(&mut sys.arena, &direct);
    // the quickest by the time estimate, the first on a tie: on the planar chains the
    // wrenches save operations (9–10 %) but not latency, and measured no faster. The forms
    // are compared with their outward pass as built, on which the estimate's choices were
    // measured; the chosen one is then built with its terms in ready order (`Outward`).
    let time = |a: &Arena, f: &Forward| time_estimate(a, &f.roots());
    let candidates = [
        (h, None, Elimination::ParentAxes),
        (h, None, Elimination::ChildAxes),
        (&direct[..], Some(&bias[..]), Elimination::ParentAxes),
        (&direct[..], Some(&bias[..]), Elimination::ChildAxes),
    ];
    let mut best = (time(&sys.arena, &parent), 0, parent);
    for (i, &(rhs, bias, order)) in candidates.iter().enumerate().skip(1) {
        let f = articulated(sys, tree, rhs, bias, order, plain).expect("the same tree");
        let t = time(&sys.arena, &f);
        if t < best.0 {
            best = (t, i, f);
        }
    }
    let (aba_time, chosen, aba) = best;
    let aba_flops = crate::expr::ops(&sys.arena, &aba.roots()).flops();
    let ordered = |sys: &mut System| {
        let (rhs, bias, order) = candidates[chosen];
        articulated(sys, tree, rhs, bias, order, Outward::ReadyFirst).expect("the same tree")
    };
    // two flops per multiply–subtract: far above, LᵀDL is not worth building (long chains)
    if 2 * ltdl_estimate(&sys.arena, &mb.m) > 4 * aba_flops {
        return ordered(sys);
    }
    let sparse = ltdl(&mut sys.arena, &mb.m, h);
    if aba_time < time(&sys.arena, &sparse) {
        ordered(sys)
    } else {
        sparse
    }
}

/// Cycles straight-line code of `roots` may take on a core that retires two floating-point
/// operations per cycle: its operations' throughput or its critical path, whichever is
/// longer (a rough model, enough to choose between forms of one computation).
fn time_estimate(a: &Arena, roots: &[ExprId]) -> u32 {
    let flops = crate::expr::ops(a, roots).flops() as u32;
    (flops / 2).max(crate::expr::critical_path(a, roots))
}

/// The substitution of a state at rest, qd = 0 and qdd = 0 (n coordinates).
pub fn at_rest(a: &mut Arena, n: usize) -> FxHashMap<Var, ExprId> {
    let mut rest = FxHashMap::default();
    for k in 0..n {
        rest.insert(Var::Qd(k as u16), a.zero());
        rest.insert(Var::Qdd(k as u16), a.zero());
    }
    rest
}

/// Kinetic energy Σ ½ m v_G² + ½ ωᵀ Φ ω, and potential energy of gravity, springs, contacts
/// and bushings (gravity's measured from the world origin).
pub fn energies(sys: &mut System, tree: &Tree, world: &World, loads: &Loads) -> (ExprId, ExprId) {
    let bk = body_kinematics(&mut sys.arena, tree, None, false);
    let spinning = spinning_frames(sys, tree);
    let a = &mut sys.arena;
    let half = a.num(0.5);
    let mut t = a.zero();
    let mut v = loads.elastic_potential.unwrap_or(a.zero());
    for (n, node) in tree.nodes.iter().enumerate().skip(1) {
        for &f in &node.frames {
            let Some(inr) = sys.frames[f].inertia else {
                continue;
            };
            let mut k = bk[n];
            if spinning[f] {
                // in the parent's axes, the spin leaves the inertia unchanged
                let Some(Factor::Rot { axis, angle }) = node.factor else {
                    unreachable!()
                };
                let p = bk[node.parent];
                k.v = p.v;
                k.w = spinning_body_motion(a, &p, axis, angle, false).0;
            }
            let vv = s::dot(a, k.v, k.v);
            let mvv = a.mul(inr.mass, vv);
            let phi = s::sym(&inr.tensor);
            let iw = s::mul_mv(a, &phi, k.w);
            let wiw = s::dot(a, k.w, iw);
            let sum = a.add(mvv, wiw);
            let e = a.mul(half, sum);
            t = a.add(t, e);
            if let Some(g) = loads.gravity {
                let gp = s::dot(a, g, world.nodes[n].p);
                let mgp = a.mul(inr.mass, gp);
                v = a.sub(v, mgp);
            }
        }
    }
    (t, v)
}

/// The derivatives of each row of `x` (functions of q free of qd), in blocks of the row's
/// width: block 0 along the direction given as `Var::Qd` (Σₖ ∂x/∂qₖ qdₖ, for n coordinates),
/// block 1 + j by sensitive parameter j.
pub(super) fn along_and_by(a: &mut Arena, x: &Matrix, n: usize, sensitive: &[u16]) -> Matrix {
    x.iter()
        .map(|row| {
            let mut out = Vec::with_capacity(row.len() * (1 + sensitive.len()));
            for &e in row {
                let terms: Vec<ExprId> = (0..n)
                    .map(|k| {
                        let d = a.diff(e, Var::Q(k as u16));
                        let v = a.var(Var::Qd(k as u16));
                        a.mul(d, v)
                    })
                    .collect();
                out.push(a.sum(terms));
            }
            for &p in sensitive {
                for &e in row {
                    out.push(a.diff(e, Var::Param(p)));
                }
            }
            out
        })
        .collect()
}
