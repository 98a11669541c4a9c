//! Emission of a [`SymbolicModel`] as Rust source: a parameter struct, one model type per scene
//! implementing `mbs::Model`, docs listing bodies, coordinates, effects and op counts.
//! The text is what the macro emits (parsed into tokens) and what `mbs expand` prints.

pub mod api;
pub mod formulas;
pub mod function;
mod ltdl;
pub mod shapes;
mod tape;

use crate::expr::emit::MissingDerivative;
use crate::expr::{ExprId, OpCount};
use crate::mech::SymbolicModel;
use crate::mech::dynamics::SceneEquations;
use crate::mech::system::{Formulation, Load, System, TangentForm};
use crate::mech::world::{self, Twist};
use api::{Sizes, args};
use formulas::Formulas;
use function::{Chunk, EmittedFn, FnSpec, Prefix, RustNames, emit_fn};
use std::fmt::Write;
use std::time::{Duration, Instant};

/// Op counts of one generated function of one scene.
#[derive(Clone, Debug)]
pub struct FunctionReport {
    /// scene type name
    pub model: String,
    pub function: String,
    pub ops: OpCount,
}

/// The generated code of one model and what it cost.
#[derive(Clone, Debug)]
pub struct Generated {
    /// Rust source of every item
    pub code: String,
    /// FNV-1a hash of the code before the hash constants were appended
    pub hash: u64,
    pub reports: Vec<FunctionReport>,
    /// time spent building the symbolic model
    pub build_time: Duration,
    /// time spent scheduling and emitting
    pub emit_time: Duration,
}

/// FNV-1a over 8-byte words (little-endian, the tail zero-padded), four lanes at a time so
/// that it stays fast without optimisation; the macro and `mbs expand` share it.
pub fn fnv1a(s: &str) -> u64 {
    const PRIME: u64 = 0x100000001b3;
    let mut lanes = [
        0xcbf29ce484222325u64,
        0x84222325cbf29ce4,
        0x9ce484222325cbf2,
        0x2325cbf29ce48422,
    ];
    let bytes = s.as_bytes();
    let blocks = bytes.chunks_exact(32);
    let tail = blocks.remainder();
    for b in blocks {
        let w: [u64; 4] = [
            u64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]),
            u64::from_le_bytes([b[8], b[9], b[10], b[11], b[12], b[13], b[14], b[15]]),
            u64::from_le_bytes([b[16], b[17], b[18], b[19], b[20], b[21], b[22], b[23]]),
            u64::from_le_bytes([b[24], b[25], b[26], b[27], b[28], b[29], b[30], b[31]]),
        ];
        lanes = [
            (lanes[0] ^ w[0]).wrapping_mul(PRIME),
            (lanes[1] ^ w[1]).wrapping_mul(PRIME),
            (lanes[2] ^ w[2]).wrapping_mul(PRIME),
            (lanes[3] ^ w[3]).wrapping_mul(PRIME),
        ];
    }
    let mut h = lanes
        .iter()
        .fold(0xcbf29ce484222325u64, |h, &l| (h ^ l).wrapping_mul(PRIME));
    for c in tail.chunks(8) {
        let mut w = [0u8; 8];
        w[..c.len()].copy_from_slice(c);
        h = (h ^ u64::from_le_bytes(w)).wrapping_mul(PRIME);
    }
    (h ^ bytes.len() as u64).wrapping_mul(PRIME)
}

fn runtime_ops(c: OpCount) -> String {
    format!(
        "::mbs::OpCount {{ adds: {}, muls: {}, divs: {}, funcs: {}, lets: {} }}",
        c.adds, c.muls, c.divs, c.funcs, c.lets
    )
}

fn str_list(v: impl IntoIterator<Item = String>) -> String {
    let items: Vec<String> = v.into_iter().map(|s| format!("{s:?}")).collect();
    format!("&[{}]", items.join(", "))
}

/// Type name of scene `s` of model `name`.
pub fn scene_type(sys: &System, s: Option<usize>) -> String {
    match s {
        None => sys.name.clone(),
        Some(i) => format!("{}{}", sys.name, sys.scenes[i].name),
    }
}

/// Generates the code of a checked system.
pub fn generate(sys: System, vis: &str) -> Result<Generated, Vec<MissingDerivative>> {
    let t0 = Instant::now();
    let model = SymbolicModel::build(sys);
    let build_time = t0.elapsed();
    let t1 = Instant::now();
    let mut code = String::new();
    let mut reports = Vec::new();
    let mut missing = Vec::new();
    let mut formulas = Formulas::new(&model.sys.name);
    let shared = emit_params(&model, vis, &mut code, &mut missing, &mut formulas);
    // forward dynamics as dynamics then the model's one LᵀDL, in the scenes where it pays
    let after: Vec<bool> = model
        .scenes
        .iter()
        .map(|eq| ltdl::after_dynamics(&model, eq))
        .collect();
    let users: Vec<&SceneEquations> = model
        .scenes
        .iter()
        .zip(&after)
        .filter_map(|(eq, &a)| a.then_some(eq))
        .collect();
    let ltdl_count = if users.is_empty() {
        None
    } else {
        collect(ltdl::emit(&model, &users), &mut missing, |e| {
            let mut items = String::new();
            let ty = format!("{}Params", model.sys.name);
            let _ = writeln!(
                code,
                "#[automatically_derived]\n#[allow(unused_variables, clippy::all)]\nimpl {ty} {{\n{}}}",
                e.full_text(&ty, &mut items, &mut formulas)
            );
            code.push_str(&items);
            e.count
        })
    };
    let mut chunks = Vec::new();
    for (eq, &after) in model.scenes.iter().zip(&after) {
        let ltdl = ltdl_count.filter(|_| after);
        let scene_chunks = emit_scene(
            &model,
            eq,
            vis,
            Shared {
                rows: &shared,
                ltdl,
            },
            &mut code,
            &mut reports,
            &mut missing,
        );
        chunks.push((scene_type(&model.sys, eq.scene), scene_chunks));
    }
    emit_chunks(&model.sys.name, &chunks, &mut code, &mut formulas);
    code.push_str(&formulas.text());
    if !missing.is_empty() {
        missing.dedup();
        return Err(missing);
    }
    let hash = fnv1a(&code);
    for eq in &model.scenes {
        let ty = scene_type(&model.sys, eq.scene);
        let _ = writeln!(
            code,
            "impl {ty} {{\n/// Hash of the code `multibody!` generated for this model (`mbs expand` prints the same).\npub const GENERATED_HASH: u64 = {hash};\n}}"
        );
    }
    Ok(Generated {
        code,
        hash,
        reports,
        build_time,
        emit_time: t1.elapsed(),
    })
}

fn collect<T>(
    r: Result<EmittedFn, Vec<MissingDerivative>>,
    missing: &mut Vec<MissingDerivative>,
    f: impl FnOnce(EmittedFn) -> T,
) -> Option<T> {
    match r {
        Ok(e) => Some(f(e)),
        Err(m) => {
            missing.extend(m);
            None
        }
    }
}

/// The parameter struct with its derived values, the poses and kinematics of frames and
/// points and the constraint functions (shared by every scene); returns the op counts of the
/// kinematics, and of the constraint functions when there are any.
fn emit_params(
    model: &SymbolicModel,
    vis: &str,
    code: &mut String,
    missing: &mut Vec<MissingDerivative>,
    formulas: &mut Formulas,
) -> Vec<(String, OpCount, Option<usize>)> {
    let sys = &model.sys;
    let a = &sys.arena;
    let ty = format!("{}Params", sys.name);
    let _ = writeln!(
        code,
        "/// Parameters of [`{}`]-generated models; `Default` gives the values written in the model.",
        sys.name
    );
    let _ = writeln!(
        code,
        "#[derive(Clone, Debug, PartialEq, ::mbs::__private::serde::Serialize, ::mbs::__private::serde::Deserialize)]\n#[serde(crate = \"::mbs::__private::serde\", default, deny_unknown_fields)]\n{vis} struct {ty} {{"
    );
    for p in &sys.params {
        let _ = writeln!(
            code,
            "/// default {}\npub {}: f64,",
            crate::expr::emit::literal(p.default),
            p.name
        );
    }
    code.push_str("}\n");
    let fields: Vec<String> = sys
        .params
        .iter()
        .map(|p| format!("{}: {}", p.name, crate::expr::emit::literal(p.default)))
        .collect();
    let _ = writeln!(
        code,
        "impl ::core::default::Default for {ty} {{\nfn default() -> Self {{\nSelf {{ {} }}\n}}\n}}",
        fields.join(", ")
    );
    if !a.splines().is_empty() {
        let list = |v: Vec<String>| format!("[{}]", v.join(", "));
        let lit = |x: &f64| crate::expr::emit::literal(*x);
        let tables: Vec<String> = a
            .splines()
            .iter()
            .map(|s| {
                format!(
                    "::mbs::Spline::from_table(&{}, &{})",
                    list(s.knots.iter().map(lit).collect()),
                    list(
                        s.coefficients
                            .iter()
                            .map(|c| list(c.iter().map(lit).collect()))
                            .collect()
                    )
                )
            })
            .collect();
        let _ = writeln!(
            code,
            "#[allow(clippy::all)]\nimpl {ty} {{\n/// The natural cubic splines of the model's `spline(x, [(x0, y0), …])`: knots, and the coefficients c0 + c1 s + c2 s² + c3 s³ of each interval.\npub const SPLINES: [::mbs::Spline; {}] = [{}];\n}}",
            tables.len(),
            tables.join(",\n")
        );
    }
    if model.assembled {
        let _ = writeln!(
            code,
            "#[allow(clippy::all)]\nimpl {ty} {{\n{}\n}}",
            twist_tree(model)
        );
    }
    // validation: masses, inertias, spring stiffnesses as functions of the parameters
    let mut spec = FnSpec::new("__derived", "v: &mut [f64]");
    let mut checks = Vec::new();
    let mut k = 0;
    for f in &sys.frames {
        if let Some(inr) = f.inertia {
            spec.outputs.push((format!("v[{k}]"), inr.mass));
            checks.push(format!(
                "if !(v[{k}] > 0.0) {{ return Err(::mbs::ParamError::NonPositiveMass {{ body: {:?}, value: v[{k}] }}); }}",
                f.name
            ));
            k += 1;
            let first = k;
            for &e in &inr.tensor {
                spec.outputs.push((format!("v[{k}]"), e));
                k += 1;
            }
            let arr: Vec<String> = (first..first + 6).map(|i| format!("v[{i}]")).collect();
            checks.push(format!(
                "::mbs::check_inertia({:?}, [{}])?;",
                f.name,
                arr.join(", ")
            ));
        }
    }
    let (mut spring, mut contact, mut bushing, mut rotational) = (0, 0, 0, 0);
    for e in &sys.effects {
        for l in &e.loads {
            // coefficients that parameters may make unphysical: (element, name, value, strict)
            let mut coefficients: Vec<(String, &str, ExprId, bool)> = Vec::new();
            match l {
                Load::Spring { k: stiff, .. } => {
                    spec.outputs.push((format!("v[{k}]"), *stiff));
                    checks.push(format!(
                        "if v[{k}] < 0.0 {{ return Err(::mbs::ParamError::NegativeStiffness {{ index: {spring}, value: v[{k}] }}); }}"
                    ));
                    k += 1;
                    spring += 1;
                }
                Load::Contact {
                    radius,
                    ellipsoid,
                    dissipation,
                    k: stiff,
                    c,
                    mu,
                    eps,
                    ..
                } => {
                    let el = format!("contact {contact}");
                    contact += 1;
                    coefficients.push((el.clone(), "k", *stiff, true));
                    coefficients.push((el.clone(), "c", *c, false));
                    coefficients.push((el.clone(), "mu", *mu, false));
                    coefficients.push((el.clone(), "eps", *eps, true));
                    coefficients.push((el.clone(), "dissipation", *dissipation, false));
                    for axis in ellipsoid.iter().flatten() {
                        coefficients.push((el.clone(), "ellipsoid", *axis, true));
                    }
                    coefficients.push((el, "radius", *radius, false));
                }
                Load::Bushing {
                    k: kk, kr, c, cr, ..
                } => {
                    let el = format!("bushing {bushing}");
                    bushing += 1;
                    for (name, v) in [("k", kk), ("kr", kr), ("c", c), ("cr", cr)] {
                        for e in v {
                            coefficients.push((el.clone(), name, *e, false));
                        }
                    }
                }
                Load::RotationalSpring { k: kk, c, .. } => {
                    // rotational springs and dampers, numbered together
                    let el = format!("rotational spring {rotational}");
                    rotational += 1;
                    coefficients.push((el.clone(), "k", *kk, false));
                    coefficients.push((el, "c", *c, false));
                }
                _ => {}
            }
            for (el, name, value, strict) in coefficients {
                if a.is_const(value) {
                    // checked at compile time
                    continue;
                }
                spec.outputs.push((format!("v[{k}]"), value));
                let (bad, rule) = if strict {
                    ("!(v[{k}] > 0.0)", "must be positive")
                } else {
                    ("!(v[{k}] >= 0.0)", "must not be negative")
                };
                checks.push(format!(
                    "if {} {{ return Err(::mbs::ParamError::InvalidCoefficient {{ element: {el:?}, name: {name:?}, value: v[{k}], rule: {rule:?} }}); }}",
                    bad.replace("{k}", &k.to_string())
                ));
                k += 1;
            }
        }
    }
    let splines = format!("{ty}::SPLINES");
    let names = RustNames {
        params: &sys.params,
        params_path: "self",
        charts_path: "charts",
        splines_path: &splines,
    };
    let mut items = String::new();
    let mut derived = collect(emit_fn(a, &spec, &names), missing, |e| {
        e.full_text(&ty, &mut items, formulas)
    })
    .unwrap_or_default();
    // the constraints are the same in every scene: emitted once, here
    // ... and read the charts of rotation joints, which the models hold, as an argument
    let c = &model.constraints;
    let with_charts = |name: &str| format!("charts: &[[[f64; 3]; 3]], {}", args(name));
    let mut specs = vec![FnSpec::new("__constraints", &with_charts("constraints"))];
    specs[0].vector("phi", &c.phi);
    let mut f = FnSpec::new("__constraint_jacobian", &with_charts("constraint_jacobian"));
    f.matrix(a, "b", &c.b);
    specs.push(f);
    let mut f = FnSpec::new("__constraint_rate", &with_charts("constraint_rate"));
    f.vector("phi_t", &c.phi_t);
    specs.push(f);
    let mut f = FnSpec::new("__constraint_bias", &with_charts("constraint_bias"));
    f.vector("gamma", &c.gamma);
    specs.push(f);
    let mut f = FnSpec::new("__constraint_tangent", &with_charts("constraint_tangent"));
    f.matrix(a, "k", &c.tangent);
    specs.push(f);
    let mut labels = vec![
        "constraints Φ",
        "constraint_jacobian B",
        "constraint_rate Φ_t",
        "constraint_bias γ",
        "constraint_tangent",
    ];
    if let Some(cs) = &c.sensitivity {
        let mut f = FnSpec::new(
            "__constraint_parameter_tangents",
            &format!(
                "charts: &[[[f64; 3]; 3]], {}",
                api::CONSTRAINT_PARAMETER_TANGENTS_INNER
            ),
        );
        f.matrix(a, "dphi_dp", &cs.dphi_dp);
        f.matrix(a, "drate_dq", &cs.drate_dq);
        f.matrix(a, "drate_dp", &cs.drate_dp);
        f.matrix(a, "dacc_dq", &cs.dacc_dq);
        f.matrix(a, "dacc_dqd", &cs.dacc_dqd);
        f.matrix(a, "dacc_dp", &cs.dacc_dp);
        f.matrix(a, "dforce_dp", &cs.dforce_dp);
        specs.push(f);
        labels.push("constraint_parameter_tangents (∂Φ/∂p, …)");
        if let Some([db, dk]) = &cs.rest {
            // the direction δq is passed as `qd`, which B and K_λ do not depend on
            let mut f = FnSpec::new(
                "__constraint_rest_derivatives",
                "charts: &[[[f64; 3]; 3]], t: f64, q: &[f64], qd: &[f64], lambda: &[f64], db: &mut [f64], dk: &mut [f64]",
            );
            f.matrix(a, "db", db);
            f.matrix(a, "dk", dk);
            specs.push(f);
            labels.push("constraint_rest_derivatives (B', K_λ')");
        }
    }
    let mut shared: Vec<(FnSpec, String, Option<usize>)> = kinematics_specs(model, with_charts)
        .into_iter()
        .map(|(f, label)| (f, label.to_string(), None))
        .collect();
    // the parts the scenes share (static forces, energies, power and, with tangents, τ, K
    // and C): of the bodies and the effects every scene has (written), then of each group of
    // other effects (added); τ only with tangents (see the scenes' τ in `emit_scene`)
    for (i, part) in model.shared_parts.iter().enumerate() {
        let names: Vec<&str> = part
            .effects
            .iter()
            .filter_map(|&e| sys.effects[e].name.as_deref())
            .collect();
        let which = if i == 0 {
            "common part".to_string()
        } else {
            format!("effects {}", names.join(", "))
        };
        let tau = sys.options.tangents.then(|| {
            let args = with_charts("inverse_dynamics");
            ("inverse_dynamics", args, "tau", part.tau.clone())
        });
        let vectors = tau.into_iter().chain([
            (
                "static_forces",
                with_charts("static_forces"),
                "h",
                part.static_h.clone(),
            ),
            (
                "energy",
                format!("{}, e: &mut [f64]", with_charts("energy")),
                "e",
                vec![part.kinetic, part.potential],
            ),
            (
                "power",
                format!("{}, e: &mut [f64]", with_charts("power")),
                "e",
                vec![part.power],
            ),
        ]);
        for (function, args, target, v) in vectors {
            let mut f = FnSpec::new(&shared_part_fn(function, i), &args);
            if i == 0 {
                f.vector(target, &v);
            } else {
                f.vector_added(a, target, &v);
            }
            shared.push((f, format!("{function}, {which}"), Some(i)));
        }
        if sys.options.tangents {
            let mut f = FnSpec::new(&shared_part_fn("tangents", i), &with_charts("tangents"));
            f.table = tangents_as_table(sys);
            if i == 0 {
                f.matrix(a, "k", &part.k);
                f.matrix(a, "c", &part.c);
            } else {
                f.matrix_added(a, "k", &part.k);
                f.matrix_added(a, "c", &part.c);
            }
            shared.push((f, format!("tangents (K, C), {which}"), Some(i)));
        }
    }
    let mut ops = Vec::new();
    for (spec, label, part) in shared {
        if let Some((s, count)) = collect(emit_fn(a, &spec, &names), missing, |e| {
            (e.full_text(&ty, &mut items, formulas), e.count)
        }) {
            derived.push_str(&s);
            ops.push((label, count, part));
        }
    }
    for (spec, label) in specs.iter().zip(labels) {
        if let Some((s, count)) = collect(emit_fn(a, spec, &names), missing, |e| {
            (e.full_text(&ty, &mut items, formulas), e.count)
        }) {
            derived.push_str(&s);
            if !c.phi.is_empty() {
                ops.push((label.to_string(), count, None));
            }
        }
    }
    let _ = writeln!(
        code,
        "#[automatically_derived]\n#[allow(unused_variables, clippy::all)]\nimpl {ty} {{\n{derived}}}"
    );
    code.push_str(&items);
    let values: Vec<String> = sys
        .params
        .iter()
        .map(|p| format!("self.{}", p.name))
        .collect();
    let sets: Vec<String> = sys
        .params
        .iter()
        .map(|p| format!("{:?} => {{ self.{} = value; Ok(()) }}", p.name, p.name))
        .collect();
    let _ = writeln!(
        code,
        "#[automatically_derived]
impl ::mbs::Parameters for {ty} {{
const NAMES: &'static [&'static str] = {names};
fn values(&self) -> ::std::vec::Vec<f64> {{ ::std::vec![{values}] }}
fn set(&mut self, name: &str, value: f64) -> ::core::result::Result<(), ::mbs::ParamError> {{
match name {{
{sets}
_ => Err(::mbs::ParamError::Unknown {{ name: name.to_string(), known: Self::NAMES.join(\", \") }}),
}}
}}
#[allow(clippy::neg_cmp_op_on_partial_ord)]
fn validate(&self) -> ::core::result::Result<(), ::mbs::ParamError> {{
for (name, value) in Self::NAMES.iter().zip(self.values()) {{
if !value.is_finite() {{ return Err(::mbs::ParamError::NonFinite {{ name, value }}); }}
}}
let mut v = [0.0f64; {k}];
self.__derived(&mut v);
{checks}
Ok(())
}}
}}",
        names = str_list(sys.params.iter().map(|p| p.name.clone())),
        values = values.join(", "),
        sets = sets.join("\n"),
        checks = checks.join("\n"),
    );
    ops
}

/// The method on the parameter struct of shared part `i` of `function` (`static_forces`,
/// `energy`, `power`, `inverse_dynamics`, `tangents`): `__tangents_common`,
/// `__tangents_effects1`, …
fn shared_part_fn(function: &str, i: usize) -> String {
    match i {
        0 => format!("__{function}_common"),
        _ => format!("__{function}_effects{i}"),
    }
}

/// The twists of every node in tree order, with the node each belongs to.
fn twist_list(model: &SymbolicModel) -> Vec<(usize, Twist)> {
    model
        .world
        .twists
        .iter()
        .enumerate()
        .flat_map(|(n, t)| t.iter().map(move |&t| (n, t)))
        .collect()
}

/// The six numbers of a twist in the runtime's buffers: ω, then v₀.
fn twist_values(t: &Twist) -> [ExprId; 6] {
    [t.w[0], t.w[1], t.w[2], t.v0[0], t.v0[1], t.v0[2]]
}

/// The associated constant `TWISTS` of the parameter struct: the tree and the coordinate of
/// each twist, which `::mbs::__private::TwistTree::assemble` sums into the Jacobians.
fn twist_tree(model: &SymbolicModel) -> String {
    let sys = &model.sys;
    let list = |v: Vec<String>| format!("&[{}]", v.join(", "));
    let tree = &model.tree;
    let mut first = vec![0usize];
    for t in &model.world.twists {
        first.push(first.last().unwrap() + t.len());
    }
    let point_node: Vec<String> = sys
        .points
        .iter()
        .map(|p| p.frame.map_or(0, |f| tree.frame_node[f]).to_string())
        .collect();
    // the nearest ancestor with twists (parents come before their children)
    let mut up = vec![0usize; tree.nodes.len()];
    for n in 1..tree.nodes.len() {
        let p = tree.nodes[n].parent;
        up[n] = if p == 0 || !model.world.twists[p].is_empty() {
            p
        } else {
            up[p]
        };
    }
    format!(
        "/// The tree of the twists the Jacobians of `kinematics`, and M, are assembled from.\npub const TWISTS: ::mbs::__private::TwistTree = ::mbs::__private::TwistTree {{ up: {}, first: {}, coordinate: {}, frame_node: {}, point_node: {} }};",
        list(up.iter().map(|n| n.to_string()).collect()),
        list(first.iter().map(|f| f.to_string()).collect()),
        list(
            twist_list(model)
                .iter()
                .map(|(_, t)| t.coordinate.to_string())
                .collect()
        ),
        list(tree.frame_node.iter().map(|n| n.to_string()).collect()),
        list(point_node),
    )
}

/// The outputs M is assembled from at run time (`TwistTree::mass_matrix`), into `mw`: the
/// twists (6 each, as in `kinematics`), then 13 numbers per node with twists (its origin and
/// composite inertia, `world::composite_inertias`).
fn mass_outputs(model: &SymbolicModel, f: &mut FnSpec) {
    let twists = twist_list(model);
    let values = twists.iter().flat_map(|(_, t)| twist_values(t));
    let values = values.chain(model.composites.iter().flatten().copied());
    for (k, v) in values.enumerate() {
        f.outputs.push((format!("mw[{k}]"), v));
    }
}

/// Numbers `mw` holds for the assembly of M: 6 per twist, 13 per node with twists.
fn mass_workspace(model: &SymbolicModel) -> usize {
    6 * model.world.twist_count() + 13 * model.composites.len()
}

/// The poses and kinematics of frames and points, the same in every scene: emitted once on
/// the parameter struct, the charts of rotation joints an argument (`with_charts` makes the
/// parameter lists). With the Jacobians assembled, the two kinematics functions write the
/// coordinates' twists into `tw` (6 per twist: ω, then v₀) in place of the Jacobians' columns.
fn kinematics_specs(
    model: &SymbolicModel,
    with_charts: impl Fn(&str) -> String,
) -> Vec<(FnSpec, &'static str)> {
    let a = &model.sys.arena;
    let n = model.sys.ndof();
    let assembled = model.assembled;
    let kin_args = if assembled {
        format!("{}, tw: &mut [f64]", with_charts("kinematics"))
    } else {
        with_charts("kinematics")
    };
    let mut frames = FnSpec::new("__frames", &with_charts("frames"));
    let mut fk = FnSpec::new("__kinematics", &kin_args);
    // `kinematics` less the Jacobians, for what reads the motion of frames and points alone
    let mut fm = FnSpec::new("__motion", &with_charts("kinematics"));
    for (i, &node) in model.tree.frame_node.iter().enumerate() {
        let k = &model.world.nodes[node];
        for r in 0..3 {
            for c in 0..3 {
                frames
                    .outputs
                    .push((format!("out[{i}].rotation[{r}][{c}]"), k.r[r][c]));
                for g in [&mut fk, &mut fm] {
                    g.outputs.push((
                        format!("out.frames[{i}].pose.rotation[{r}][{c}]"),
                        k.r[r][c],
                    ));
                }
            }
            frames
                .outputs
                .push((format!("out[{i}].position[{r}]"), k.p[r]));
            for g in [&mut fk, &mut fm] {
                g.outputs
                    .push((format!("out.frames[{i}].pose.position[{r}]"), k.p[r]));
                g.outputs
                    .push((format!("out.frames[{i}].velocity[{r}]"), k.v[r]));
                g.outputs
                    .push((format!("out.frames[{i}].angular_velocity[{r}]"), k.w[r]));
            }
            fk.outputs
                .push((format!("out.frames[{i}].bias_acceleration[{r}]"), k.ab[r]));
            fk.outputs.push((
                format!("out.frames[{i}].bias_angular_acceleration[{r}]"),
                k.alb[r],
            ));
        }
        if !assembled {
            fk.matrix(a, &format!("out.frames[{i}].jv"), &dense3(a, &k.jv, n));
            fk.matrix(a, &format!("out.frames[{i}].jw"), &dense3(a, &k.jw, n));
        }
    }
    // the points' positions, velocities and Jacobians again alone, for efforts that read
    // only points (their bias accelerations only in `kinematics`)
    let mut fp = FnSpec::new("__point_kinematics", &kin_args);
    for (i, pk) in model.points.iter().enumerate() {
        for r in 0..3 {
            fk.outputs.push((
                format!("out.points[{i}].bias_acceleration[{r}]"),
                pk.bias[r],
            ));
            fm.outputs
                .push((format!("out.points[{i}].position[{r}]"), pk.position[r]));
            fm.outputs
                .push((format!("out.points[{i}].velocity[{r}]"), pk.velocity[r]));
        }
        for g in [&mut fk, &mut fp] {
            for r in 0..3 {
                g.outputs
                    .push((format!("out.points[{i}].position[{r}]"), pk.position[r]));
                g.outputs
                    .push((format!("out.points[{i}].velocity[{r}]"), pk.velocity[r]));
            }
            if !assembled {
                g.matrix(
                    a,
                    &format!("out.points[{i}].jv"),
                    &dense3(a, &pk.jacobian, n),
                );
            }
        }
    }
    if assembled {
        // every twist in `kinematics`; in `point_kinematics` those on the points' paths
        let mut on_points = vec![false; model.tree.nodes.len()];
        for p in &model.sys.points {
            let mut node = p.frame.map_or(0, |f| model.tree.frame_node[f]);
            while node != 0 && !on_points[node] {
                on_points[node] = true;
                node = model.tree.nodes[node].parent;
            }
        }
        for (t, (node, tw)) in twist_list(model).into_iter().enumerate() {
            for (c, v) in twist_values(&tw).into_iter().enumerate() {
                fk.outputs.push((format!("tw[{}]", 6 * t + c), v));
                if on_points[node] {
                    fp.outputs.push((format!("tw[{}]", 6 * t + c), v));
                }
            }
        }
    }
    let mut specs = vec![
        (frames, "frames"),
        (fk, "kinematics"),
        (fp, "point_kinematics"),
    ];
    if let Some(q) = &model.transmission {
        specs.push((fm, "motion"));
        let mut ft = FnSpec::new(
            "__transmit",
            &format!("charts: &[[[f64; 3]; 3]], {}", api::TRANSMIT.args),
        );
        ft.vector("qg", q);
        specs.push((ft, "transmit"));
    }
    specs
}

fn dense3(a: &crate::expr::Arena, cols: &world::Cols, n: usize) -> Vec<Vec<ExprId>> {
    // rows i = 0..3 of a 3 × n matrix
    let d = world::dense(a, cols, n);
    (0..3).map(|i| d.iter().map(|c| c[i]).collect()).collect()
}

/// What a scene takes from the code emitted once for the model: the op-count rows of the
/// functions on the parameter struct (with the tangents' part, when it is one), and the op
/// count of the LᵀDL when the scene's forward dynamics is `dynamics` then that LᵀDL.
struct Shared<'a> {
    rows: &'a [(String, OpCount, Option<usize>)],
    ltdl: Option<OpCount>,
}

fn emit_scene(
    model: &SymbolicModel,
    eq: &SceneEquations,
    vis: &str,
    shared: Shared,
    code: &mut String,
    reports: &mut Vec<FunctionReport>,
    missing: &mut Vec<MissingDerivative>,
) -> Vec<Chunk> {
    let sys = &model.sys;
    let a = &sys.arena;
    let n = sys.ndof();
    let ty = scene_type(sys, eq.scene);
    let splines = format!("{}Params::SPLINES", sys.name);
    let names = RustNames {
        params: &sys.params,
        params_path: "self.params",
        charts_path: "self.charts",
        splines_path: &splines,
    };
    // the methods to emit, with the label of their op-count row (none for initial_state)
    let mut specs: Vec<(FnSpec, Option<&str>)> = Vec::new();
    let mb = eq.chosen();
    // M whole, or what the runtime assembles it from: the twists and the composite inertias
    // (`mw`, see `mass_outputs`)
    let with_mw = |name: &str| {
        if model.assembled {
            format!("{}, mw: &mut [f64]", args(name))
        } else {
            args(name).to_string()
        }
    };
    let mass_of = |f: &mut FnSpec| {
        if model.assembled {
            mass_outputs(model, f)
        } else {
            f.matrix(a, "m", &mb.m)
        }
    };
    let mut f = FnSpec::new("__dynamics", &with_mw("dynamics"));
    mass_of(&mut f);
    let split = f.outputs.len();
    f.vector("h", &mb.h);
    // mass_matrix as the first chunks of dynamics when dynamics is split into chunks anyway:
    // the code of M then exists once (a long chain's M is most of its code, and compile time
    // grows with the code); a small model keeps two functions of one chunk each
    let chunked = {
        let roots: Vec<ExprId> = f.outputs.iter().map(|o| o.1).collect();
        crate::expr::cse::Schedule::new(a, &roots).chunks.len() > 1
    };
    f.prefix = chunked.then(|| Prefix {
        name: "__mass_matrix".into(),
        args: with_mw("mass_matrix"),
        split,
        bind: vec![format!(
            "let (qd, u, h) = (&[0.0f64; {n}], &[0.0f64; {}], &mut [0.0f64; {n}]);",
            sys.inputs.len()
        )],
        prelude: f.prelude.clone(),
    });
    specs.push((f, Some("dynamics (M, h)")));
    // fused, or dynamics then the model's LᵀDL (`ltdl`: written below, counted after dynamics)
    let forward_label = match shared.ltdl {
        None => format!("forward_dynamics ({})", eq.forward.method.name()),
        Some(_) => format!(
            "forward_dynamics (dynamics, then {})",
            eq.forward.method.name()
        ),
    };
    if shared.ltdl.is_none() {
        let mut f = FnSpec::new("__forward_dynamics", api::FORWARD_DYNAMICS_FORCED.args);
        f.vector("qdd", &eq.forward.qdd);
        f.vector("pivots", &eq.forward.pivots);
        specs.push((f, Some(&forward_label)));
    }
    if sys.options.batch {
        // the same outputs on lanes of four states, no op-count rows of their own
        let mut f = FnSpec::lanes("__dynamics_x4", args("dynamics"));
        f.matrix(a, "m", &mb.m);
        f.vector("h", &mb.h);
        specs.push((f, None));
        let mut f = FnSpec::lanes("__forward_dynamics_x4", api::FORWARD_DYNAMICS_FORCED.args);
        f.vector("qdd", &eq.forward.qdd);
        f.vector("pivots", &eq.forward.pivots);
        specs.push((f, None));
    }
    // (its outputs only when it is a function of its own: see the emission below)
    let mut f = FnSpec::new("__mass_matrix", &with_mw("mass_matrix"));
    if !chunked {
        mass_of(&mut f);
    }
    specs.push((f, Some("mass_matrix")));
    let mass_matrix_spec = specs.len() - 1;
    // the static forces, energy and power of the shared parts when the scene has them; τ as
    // their sum too when the scene takes its tangents from them, else its own in one
    // function: without generated tangents the implicit schemes difference τ, and as the sum
    // of parts (which no longer share subexpressions) it takes 8–9 % more operations on the
    // hexapod, 16–18 % more time in a Radau5 run of its `Standing`
    let own = eq.shared_parts.is_empty();
    let shared_tau = !own && sys.options.tangents;
    if !shared_tau {
        let mut f = FnSpec::new("__inverse_dynamics", args("inverse_dynamics"));
        f.vector("tau", eq.tau());
        specs.push((f, Some("inverse_dynamics")));
    }
    if let Some((kt, ct)) = &eq.tangents {
        let mut f = FnSpec::new("__tangents", args("tangents"));
        f.table = tangents_as_table(sys);
        f.matrix(a, "k", kt);
        f.matrix(a, "c", ct);
        specs.push((f, Some("tangents (K, C)")));
    }
    if let Some(dp) = &eq.param_tangents {
        let mut f = FnSpec::new("__parameter_tangents", api::PARAMETER_TANGENTS.args);
        f.matrix(a, "dtau", dp);
        specs.push((f, Some("parameter_tangents (∂τ/∂p)")));
    }
    if let Some((sq, sqd)) = &eq.start_sensitivities {
        let mut f = FnSpec::new("__start_sensitivities", api::START_SENSITIVITIES.args);
        f.matrix(a, "sq", sq);
        f.matrix(a, "sqd", sqd);
        specs.push((f, None));
    }
    if let Some([dm, dc, dk]) = &eq.rest_tangent_derivatives {
        // the direction δq is passed as `qd`, the variables the matrices at rest are free of
        let mut f = FnSpec::new(
            "__rest_tangent_derivatives",
            "t: f64, q: &[f64], qd: &[f64], u: &[f64], dm: &mut [f64], dc: &mut [f64], dk: &mut [f64]",
        );
        f.matrix(a, "dm", dm);
        f.matrix(a, "dc", dc);
        f.matrix(a, "dk", dk);
        specs.push((f, Some("rest_tangent_derivatives (M', C', K')")));
    }
    if own {
        let mut f = FnSpec::new("__static_forces", args("static_forces"));
        f.vector("h", &eq.static_h);
        specs.push((f, Some("static_forces")));
    }
    let mut f = FnSpec::new("__input_matrix", args("input_matrix"));
    f.matrix(a, "b", &eq.input_matrix);
    specs.push((f, Some("input_matrix")));
    if own {
        let mut f = FnSpec::new("__energy", &format!("{}, e: &mut [f64]", args("energy")));
        f.vector("e", &[eq.kinetic, eq.potential]);
        specs.push((f, Some("energy")));
        let mut f = FnSpec::new("__power", &format!("{}, e: &mut [f64]", args("power")));
        f.vector("e", &[eq.power]);
        specs.push((f, Some("power")));
    }
    let mut f = FnSpec::new("__initial_state", args("initial_state"));
    let q0: Vec<ExprId> = sys.dofs.iter().map(|d| d.q0).collect();
    let qd0: Vec<ExprId> = sys.dofs.iter().map(|d| d.qd0).collect();
    f.vector("q", &q0);
    f.vector("qd", &qd0);
    specs.push((f, None));

    // the methods are independent and the arena is read-only: emit them in parallel, then
    // assemble in order so that the text does not depend on scheduling
    // (mass_matrix is not emitted on its own when dynamics emits it as its first chunks)
    let names = &names;
    let emitted: Vec<_> = std::thread::scope(|scope| {
        let handles: Vec<_> = specs
            .iter()
            .enumerate()
            .map(|(i, (spec, _))| {
                let own = !(chunked && i == mass_matrix_spec);
                scope.spawn(move || own.then(|| emit_fn(a, spec, names)))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("emission does not panic"))
            .collect()
    });
    let mut methods = String::new();
    let mut chunks = Vec::new();
    let mut ops: Vec<(String, OpCount)> = Vec::new();
    let mut prefix_count = None;
    for ((_, label), result) in specs.iter().zip(emitted) {
        let count = match result {
            // mass_matrix, counted as the first chunks of dynamics
            None => prefix_count,
            Some(result) => collect(result, missing, |e| {
                methods.push_str(&e.text);
                chunks.extend(e.chunks);
                prefix_count = prefix_count.or(e.prefix);
                e.count
            }),
        };
        let mut rows = vec![];
        if let (Some(c), Some(label)) = (count, label) {
            rows.push((label.to_string(), c));
            // forward dynamics as dynamics then the LᵀDL: its row follows dynamics'
            if let (Some(l), true) = (shared.ltdl, *label == "dynamics (M, h)") {
                methods.push_str(&ltdl::forward_method(n));
                rows.push((forward_label.clone(), ltdl::forward_count(n, c, l)));
            }
        }
        for (label, c) in rows {
            reports.push(FunctionReport {
                model: ty.clone(),
                function: label.clone(),
                ops: c,
            });
            ops.push((label, c));
        }
    }
    // the kinematics and constraint functions, emitted once on the parameters, serve every
    // scene; the shared parts those that add them
    for (label, c, part) in shared.rows {
        if part.is_some_and(|p| !eq.shared_parts.contains(&p)) {
            continue;
        }
        ops.push((label.clone(), *c));
        reports.push(FunctionReport {
            model: ty.clone(),
            function: label.clone(),
            ops: *c,
        });
    }

    // the type, its docs and the trait impl
    let scene_name = eq
        .scene
        .map(|s| sys.scenes[s].name.clone())
        .unwrap_or_default();
    let effect_names: Vec<String> = eq
        .effects
        .iter()
        .map(|&e| {
            sys.effects[e]
                .name
                .clone()
                .unwrap_or_else(|| "(always on)".into())
        })
        .collect();
    let form = match eq.formulation {
        Formulation::Recursive => "recursive",
        Formulation::VirtualPower => "virtual power",
    };
    let mut doc = String::new();
    // a block comment `/** … */` is one doc attribute of several lines; a carriage return
    // (`#[doc = "a\rb"]`) ends a line too, which a `///` comment cannot hold
    for line in sys.docs.iter().flat_map(|d| d.split(['\n', '\r'])) {
        let _ = writeln!(doc, "///{line}");
    }
    if !sys.docs.is_empty() {
        doc.push_str("///\n");
    }
    let _ = writeln!(
        doc,
        "/// Generated by `multibody!`{}.",
        if scene_name.is_empty() {
            String::new()
        } else {
            format!(", scene `{scene_name}`")
        }
    );
    let _ = writeln!(
        doc,
        "///\n/// - coordinates: {}",
        sys.dofs
            .iter()
            .map(|d| format!("`{}`", d.name))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let bodies: Vec<String> = sys
        .frames
        .iter()
        .map(|f| {
            format!(
                "`{}`{}",
                f.name,
                if f.inertia.is_some() { "" } else { " (frame)" }
            )
        })
        .collect();
    let _ = writeln!(doc, "/// - bodies: {}", bodies.join(", "));
    if !sys.points.is_empty() {
        let _ = writeln!(
            doc,
            "/// - points: {}",
            sys.points
                .iter()
                .map(|p| format!("`{}`", p.name))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let _ = writeln!(
        doc,
        "/// - effects: {}",
        if effect_names.is_empty() {
            "none".into()
        } else {
            effect_names.join(", ")
        }
    );
    let _ = writeln!(
        doc,
        "/// - formulation of M and h: {form}\n///\n/// | function | flops | adds | muls | divs | funcs | lets |\n/// |---|---|---|---|---|---|---|"
    );
    for (name, c) in &ops {
        let [flops, adds, muls, divs, funcs, lets] = c.columns();
        let _ = writeln!(
            doc,
            "/// | {name} | {flops} | {adds} | {muls} | {divs} | {funcs} | {lets} |"
        );
    }
    let pty = format!("{}Params", sys.name);
    let info = format!(
        "static INFO: ::mbs::ModelInfo = ::mbs::ModelInfo {{ name: {name:?}, scene: {scene:?}, dofs: {dofs}, inputs: {inputs}, frames: {frames}, is_body: &[{is_body}], points: {points}, params: {params}, effects: {effects}, constraints: {constraints}, independent: &[{independent}], formulation: {form:?}, has_tangents: {tan}, ops: &[{ops}], shapes: {shapes}, rotation_joints: &[{joints}] }};",
        name = ty,
        scene = scene_name,
        dofs = str_list(sys.dofs.iter().map(|d| d.name.clone())),
        inputs = str_list(sys.inputs.iter().cloned()),
        frames = str_list(sys.frames.iter().map(|f| f.name.clone())),
        is_body = sys
            .frames
            .iter()
            .map(|f| f.inertia.is_some().to_string())
            .collect::<Vec<_>>()
            .join(", "),
        points = str_list(sys.points.iter().map(|p| p.name.clone())),
        params = str_list(sys.params.iter().map(|p| p.name.clone())),
        effects = str_list(effect_names.iter().cloned()),
        constraints = str_list(sys.constraints.iter().map(|c| c.name.clone())),
        independent = sys
            .dofs
            .iter()
            .map(|d| d.independent.to_string())
            .collect::<Vec<_>>()
            .join(", "),
        tan = eq.tangents.is_some() || shared_tau,
        shapes = shapes::literal(&shapes::shapes(sys)),
        joints = sys
            .rotation_joints
            .iter()
            .map(|j| format!(
                "::mbs::RotationJoint {{ frame: {}, angles: {:?}, translation: {:?} }}",
                j.frame, j.angles, j.translation
            ))
            .collect::<Vec<_>>()
            .join(", "),
        ops = ops
            .iter()
            .map(|(n, c)| format!("({n:?}, {})", runtime_ops(*c)))
            .collect::<Vec<_>>()
            .join(", "),
    );
    // the calls of the shared parts a scene adds
    let part_calls = |function: &str| -> String {
        let mut call = api::method_named(function).call();
        if matches!(function, "energy" | "power") {
            call.push_str(", &mut e");
        }
        eq.shared_parts
            .iter()
            .map(|&i| {
                format!(
                    "self.params.{}(&self.charts, {call});\n",
                    shared_part_fn(function, i)
                )
            })
            .collect()
    };
    // the methods whose bodies are these calls
    let mut shared_bodies: Vec<(&str, String)> = Vec::new();
    if shared_tau {
        shared_bodies.push(("inverse_dynamics", part_calls("inverse_dynamics")));
    }
    if !own {
        shared_bodies.push(("static_forces", part_calls("static_forces")));
        shared_bodies.push((
            "energy",
            format!(
                "let mut e = [0.0f64; 2];\n{}::mbs::Energy {{ kinetic: e[0], potential: e[1] }}",
                part_calls("energy")
            ),
        ));
        shared_bodies.push((
            "power",
            format!("let mut e = [0.0f64; 1];\n{}e[0]", part_calls("power")),
        ));
    }
    let tangents_body = if shared_tau {
        part_calls("tangents") + "Ok(())"
    } else if eq.tangents.is_some() {
        "self.__tangents(t, q, qd, qdd, u, k, c);\nOk(())".to_string()
    } else {
        format!(
            "let _ = (t, q, qd, qdd, u, k, c);\nErr(::mbs::ModelError::TangentsNotGenerated {{ model: {ty:?} }})"
        )
    };
    let sizes = Sizes {
        nq: n,
        nu: sys.inputs.len(),
        nframes: sys.frames.len(),
        npoints: sys.points.len(),
        nc: sys.constraints.len(),
        charts: sys.rotation_joints.len(),
        batch: sys.options.batch,
        motion: sys.options.motion,
        sensitive: sys
            .params
            .iter()
            .filter(|p| p.sensitive)
            .map(|p| p.name.clone())
            .collect(),
        rest_derivatives: sys.options.tangents && sys.params.iter().any(|p| p.sensitive),
        constraint_sensitivity: model.constraints.sensitivity.is_some(),
        constraint_rest_derivatives: model
            .constraints
            .sensitivity
            .as_ref()
            .is_some_and(|c| c.rest.is_some()),
    };
    let assembled = model.assembled;
    let model_impl = api::model_impl(&ty, &pty, &sizes, |m| {
        if let Some((_, body)) = shared_bodies.iter().find(|(name, _)| *name == m.name) {
            return body.clone();
        }
        match m.name {
            "info" => format!("{info}\n&INFO"),
            "params" => "&self.params".into(),
            "set_params" => {
                "::mbs::Parameters::validate(&params)?;\nself.params = params;\nOk(())".into()
            }
            "tangents" => tangents_body.clone(),
            "parameter_tangents" => {
                format!("self.__parameter_tangents({})", m.call()) + ";\nOk(())"
            }
            "rest_tangent_derivatives" => {
                format!("self.__rest_tangent_derivatives({})", m.call()) + ";\nOk(())"
            }
            "start_sensitivities" => format!("self.__start_sensitivities({})", m.call()),
            "constraint_parameter_tangents" => {
                format!(
                    "self.params.__constraint_parameter_tangents(&self.charts, t, q, qd, qdd, lambda, {})",
                    [
                        "dphi_dp",
                        "drate_dq",
                        "drate_dp",
                        "dacc_dq",
                        "dacc_dqd",
                        "dacc_dp",
                        "dforce_dp"
                    ]
                    .map(|f| format!("&mut out.{f}"))
                    .join(", ")
                ) + ";\nOk(())"
            }
            "constraint_rest_derivatives" => {
                format!(
                    "self.params.__constraint_rest_derivatives(&self.charts, {})",
                    m.call()
                ) + ";\nOk(())"
            }
            "energy" => "let mut e = [0.0f64; 2];\nself.__energy(t, q, qd, &mut e);\n::mbs::Energy { kinetic: e[0], potential: e[1] }".into(),
            "power" => "let mut e = [0.0f64; 1];\nself.__power(t, q, qd, u, &mut e);\ne[0]".into(),
            // the constraint functions live on the parameter struct, shared by every scene
            name if name.starts_with("constraint") => {
                format!("self.params.__{name}(&self.charts, {})", m.call())
            }
            // ... and so do the poses and kinematics of frames and points, whose Jacobians may be
            // assembled from the twists the generated code writes
            name @ ("kinematics" | "point_kinematics") if assembled => format!(
                "let mut tw = [0.0f64; {}];\nself.params.__{name}(&self.charts, {}, &mut tw);\n{pty}::TWISTS.assemble(&tw, out, {});",
                6 * model.world.twist_count(),
                m.call(),
                name == "kinematics"
            ),
            name @ ("frames" | "kinematics" | "point_kinematics" | "motion" | "transmit") => {
                format!("self.params.__{name}(&self.charts, {})", m.call())
            }
            // M assembled from the twists and composite inertias the generated code writes
            name @ ("dynamics" | "mass_matrix") if assembled => format!(
                "let mut mw = [0.0f64; {}];\nself.__{name}({}, &mut mw);\n{pty}::TWISTS.mass_matrix(&mw, {n}, m);",
                mass_workspace(model),
                m.call()
            ),
            // SIMD code where the processor runs it, else the one-state function lane by lane
            // one function with the added generalised force f, at f = 0 or given
            "forward_dynamics" => {
                format!("self.__forward_dynamics(t, q, qd, u, &[0.0; {n}], qdd, pivots)")
            }
            "forward_dynamics_forced" => format!("self.__forward_dynamics({})", m.call()),
            // one batch function per output, whose lanes take their parameters and charts
            // from `each`: four times the model itself, or the four models of `_lanes`
            name @ ("dynamics_x4"
            | "forward_dynamics_x4"
            | "dynamics_lanes"
            | "forward_dynamics_lanes") => {
                // (the batch body's `EACH`: whether the four lanes' models differ)
                let (one, this, differ, each, model) = match name.strip_suffix("_x4") {
                    Some(one) => (one, "self", false, "[self; 4]", "self"),
                    None => (name.trim_end_matches("_lanes"), "each[0]", true, "each", "each[k]"),
                };
                let (a, b) = if one == "dynamics" {
                    ("m", "h")
                } else {
                    ("qdd", "pivots")
                };
                let call = if one == "dynamics" {
                    "t, q, qd, u, m, h".to_string()
                } else {
                    format!("t, q, qd, u, &[::mbs::F64x4::ZERO; {n}], qdd, pivots")
                };
                format!(
                "if ::mbs::lanes::simd_available() {{
#[allow(unused_unsafe)]
// SAFETY: the processor has the features the batch code is compiled for
unsafe {{ {this}.__{one}_x4::<{differ}>({each}, {call}) }}
}} else {{
::mbs::lanes::lane_by_lane(t, [q, qd, u], [{a}, {b}], |k, t, [q, qd, u], [{a}, {b}]| ::mbs::Model::{one}({model}, t, q, qd, u, {a}, {b}))
}}"
            )
            }
            name => format!("self.__{name}({})", m.call()),
        }
    });
    let nj = sys.rotation_joints.len();
    let _ = write!(
        code,
        "{doc}#[derive(Clone, Debug, PartialEq)]
{vis} struct {ty} {{
params: {pty},
/// the chart of each rotation joint ([`::mbs::Model::chart`])
charts: [[[f64; 3]; 3]; {nj}],
}}
impl ::core::default::Default for {ty} {{
fn default() -> Self {{
Self {{ params: ::core::default::Default::default(), charts: [::mbs::IDENTITY3; {nj}] }}
}}
}}
impl {ty} {{
/// The model with `params`, after checking them.
pub fn new(params: {pty}) -> ::core::result::Result<Self, ::mbs::ParamError> {{
::mbs::Parameters::validate(&params)?;
Ok(Self {{ params, charts: [::mbs::IDENTITY3; {nj}] }})
}}
}}
#[automatically_derived]
#[allow(unused_variables, clippy::all)]
impl {ty} {{
{methods}}}
#[automatically_derived]
#[allow(unused_variables, clippy::all)]
{model_impl}"
    );
    chunks
}

/// The scenes' chunk methods: a chunk whose text is the same in several scenes (the first
/// chunks of dynamics, where M is computed, on a model with scenes) is emitted once on the
/// parameter struct, the charts an argument, and each scene's method calls it; the others
/// as they are, in an `impl` of their scene type.
fn emit_chunks(
    model: &str,
    scenes: &[(String, Vec<Chunk>)],
    code: &mut String,
    formulas: &mut Formulas,
) {
    // a scene's chunk reads the parameters and the charts through `self` and nothing else
    let movable = |c: &Chunk| {
        c.simd.is_empty()
            && c.body.matches("self.").count()
                == c.body.matches("self.params.").count() + c.body.matches("self.charts").count()
    };
    // (one scene shares nothing: its chunks are not compared)
    let repeated = |c: &Chunk| {
        scenes.len() > 1 && movable(c) && scenes.iter().filter(|(_, cs)| cs.contains(c)).count() > 1
    };
    let mut shared: Vec<&Chunk> = Vec::new();
    for (_, cs) in scenes {
        for c in cs {
            if repeated(c) && !shared.contains(&c) {
                shared.push(c);
            }
        }
    }
    let header = "#[automatically_derived]\n#[allow(unused_variables, clippy::all)]\n";
    let mut items = String::new();
    if !shared.is_empty() {
        let ty = format!("{model}Params");
        let _ = writeln!(code, "{header}impl {ty} {{");
        for c in &shared {
            let on_params = Chunk {
                name: format!("__scenes{}", c.name),
                args: format!("charts: &[[[f64; 3]; 3]], {}", c.args),
                call: format!("charts, {}", c.call),
                body: c
                    .body
                    .replace("self.params.", "self.")
                    .replace("self.charts", "charts"),
                ..(*c).clone()
            };
            code.push_str(&on_params.text(&ty, &mut items, formulas));
        }
        code.push_str("}\n");
    }
    for (ty, cs) in scenes {
        if cs.is_empty() {
            continue;
        }
        let _ = writeln!(code, "{header}impl {ty} {{");
        for c in cs {
            if shared.contains(&c) {
                let _ = writeln!(
                    code,
                    "#[inline]\nfn {}(&self, {}, w: &mut [{}; {}]) {{\nself.params.__scenes{}(&self.charts, {}, w)\n}}",
                    c.name, c.args, c.number, c.workspace, c.name, c.call
                );
            } else {
                code.push_str(&c.text(ty, &mut items, formulas));
            }
        }
        code.push_str("}\n");
    }
    code.push_str(&items);
}

/// Whether the tangents K and C are written as tables of operations (`codegen::tape`).
fn tangents_as_table(sys: &System) -> bool {
    sys.options.tangent_form == TangentForm::Table
}
