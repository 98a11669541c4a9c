//! The `mbs::Model` trait as generated code implements it: one table of its methods, from
//! which both a generated model's `impl` and the placeholder of a model with errors are
//! written. Compiling either against the trait is the check that the table is right
//! (`compile-fail/tests/ui/cascade` compiles placeholders, every `multibody!` model the full impl).

/// A method of `mbs::Model`: `fn {name}({receiver}, {args}) -> {ret}`.
pub struct Method {
    pub name: &'static str,
    /// `&self` or `&mut self`, or the first argument of an associated function
    pub receiver: &'static str,
    /// parameters after `&self`; `{P}` stands for the model's parameter struct
    pub args: &'static str,
    /// return type; empty for `()`; `{P}` as in `args`
    pub ret: &'static str,
}

const fn method(name: &'static str, args: &'static str, ret: &'static str) -> Method {
    Method {
        name,
        receiver: "&self",
        args,
        ret,
    }
}

/// Every method of `mbs::Model` without a default, in the order generated code lists them.
pub const METHODS: &[Method] = &[
    method("info", "", "&'static ::mbs::ModelInfo"),
    method("params", "", "&{P}"),
    Method {
        name: "set_params",
        receiver: "&mut self",
        args: "params: {P}",
        ret: "::core::result::Result<(), ::mbs::ParamError>",
    },
    method("initial_state", "q: &mut [f64], qd: &mut [f64]", ""),
    method("mass_matrix", "t: f64, q: &[f64], m: &mut [f64]", ""),
    method(
        "dynamics",
        "t: f64, q: &[f64], qd: &[f64], u: &[f64], m: &mut [f64], h: &mut [f64]",
        "",
    ),
    method(
        "inverse_dynamics",
        "t: f64, q: &[f64], qd: &[f64], qdd: &[f64], u: &[f64], tau: &mut [f64]",
        "",
    ),
    method(
        "tangents",
        "t: f64, q: &[f64], qd: &[f64], qdd: &[f64], u: &[f64], k: &mut [f64], c: &mut [f64]",
        "::core::result::Result<(), ::mbs::ModelError>",
    ),
    method(
        "static_forces",
        "t: f64, q: &[f64], u: &[f64], h: &mut [f64]",
        "",
    ),
    method(
        "input_matrix",
        "t: f64, q: &[f64], qd: &[f64], u: &[f64], b: &mut [f64]",
        "",
    ),
    method("energy", "t: f64, q: &[f64], qd: &[f64]", "::mbs::Energy"),
    method("power", "t: f64, q: &[f64], qd: &[f64], u: &[f64]", "f64"),
    method("frames", "t: f64, q: &[f64], out: &mut [::mbs::Pose]", ""),
    method("constraints", "t: f64, q: &[f64], phi: &mut [f64]", ""),
    method(
        "constraint_jacobian",
        "t: f64, q: &[f64], b: &mut [f64]",
        "",
    ),
    method(
        "constraint_rate",
        "t: f64, q: &[f64], phi_t: &mut [f64]",
        "",
    ),
    method(
        "constraint_bias",
        "t: f64, q: &[f64], qd: &[f64], gamma: &mut [f64]",
        "",
    ),
    method(
        "constraint_tangent",
        "t: f64, q: &[f64], lambda: &[f64], k: &mut [f64]",
        "",
    ),
    method(
        "kinematics",
        "t: f64, q: &[f64], qd: &[f64], out: &mut ::mbs::Kinematics",
        "",
    ),
];

/// `forward_dynamics`, which has a default in the trait (a dense solve) that every generated
/// model overrides.
pub const FORWARD_DYNAMICS: Method = method(
    "forward_dynamics",
    "t: f64, q: &[f64], qd: &[f64], u: &[f64], qdd: &mut [f64], pivots: &mut [f64]",
    "",
);

/// `forward_dynamics_forced`: forward dynamics with a generalised force `f` added to h
/// (efforts computed at run time, `mbs::WithEfforts`); the generated `forward_dynamics` is the
/// same function at f = 0. The trait's default solves densely.
pub const FORWARD_DYNAMICS_FORCED: Method = method(
    "forward_dynamics_forced",
    "t: f64, q: &[f64], qd: &[f64], u: &[f64], f: &[f64], qdd: &mut [f64], pivots: &mut [f64]",
    "",
);

/// `point_kinematics`, which has a default in the trait (all of `kinematics`) that every
/// generated model overrides with the points' part alone.
pub const POINT_KINEMATICS: Method = method(
    "point_kinematics",
    "t: f64, q: &[f64], qd: &[f64], out: &mut ::mbs::Kinematics",
    "",
);

/// `motion`, which has a default in the trait (all of `kinematics`) that models with
/// `option motion;` override with `kinematics` less its Jacobians and bias accelerations.
pub const MOTION: Method = method(
    "motion",
    "t: f64, q: &[f64], qd: &[f64], out: &mut ::mbs::Kinematics",
    "",
);

/// `transmit`, which has a default in the trait (through the Jacobians of `kinematics`) that
/// models with `option motion;` override with one inward pass of the tree: the generalised
/// forces of wrenches on the frames and forces at the points (`f`, world axes) into `qg`.
pub const TRANSMIT: Method = method(
    "transmit",
    "t: f64, q: &[f64], f: &[f64], qg: &mut [f64]",
    "",
);

/// `parameter_tangents`, which has a default in the trait (an error) that models with
/// parameters marked `sensitive` override.
pub const PARAMETER_TANGENTS: Method = method(
    "parameter_tangents",
    "t: f64, q: &[f64], qd: &[f64], qdd: &[f64], u: &[f64], dtau: &mut [f64]",
    "::core::result::Result<(), ::mbs::ModelError>",
);

/// `start_sensitivities`, which has a default in the trait (zero: a start that no parameter
/// moves) that models with parameters marked `sensitive` override.
pub const START_SENSITIVITIES: Method =
    method("start_sensitivities", "sq: &mut [f64], sqd: &mut [f64]", "");

/// `rest_tangent_derivatives`, which has a default in the trait (an error) that models with
/// parameters marked `sensitive` and `option tangents;` override.
pub const REST_TANGENT_DERIVATIVES: Method = method(
    "rest_tangent_derivatives",
    "t: f64, q: &[f64], dq: &[f64], u: &[f64], dm: &mut [f64], dc: &mut [f64], dk: &mut [f64]",
    "::core::result::Result<(), ::mbs::ModelError>",
);

/// `constraint_parameter_tangents`, which has a default in the trait (an error) that models
/// with constraints and parameters marked `sensitive` override.
pub const CONSTRAINT_PARAMETER_TANGENTS: Method = method(
    "constraint_parameter_tangents",
    "t: f64, q: &[f64], qd: &[f64], qdd: &[f64], lambda: &[f64], out: &mut ::mbs::ConstraintTangents",
    "::core::result::Result<(), ::mbs::ModelError>",
);

/// `constraint_rest_derivatives`, which has a default in the trait (an error) that models with
/// constraints, parameters marked `sensitive` and `option tangents;` override.
pub const CONSTRAINT_REST_DERIVATIVES: Method = method(
    "constraint_rest_derivatives",
    "t: f64, q: &[f64], dq: &[f64], lambda: &[f64], db: &mut [f64], dk: &mut [f64]",
    "::core::result::Result<(), ::mbs::ModelError>",
);

/// The arguments of the inner function behind [`CONSTRAINT_PARAMETER_TANGENTS`], one slice per
/// field of `ConstraintTangents`.
pub const CONSTRAINT_PARAMETER_TANGENTS_INNER: &str = "t: f64, q: &[f64], qd: &[f64], qdd: &[f64], lambda: &[f64], dphi_dp: &mut [f64], drate_dq: &mut [f64], drate_dp: &mut [f64], dacc_dq: &mut [f64], dacc_dqd: &mut [f64], dacc_dp: &mut [f64], dforce_dp: &mut [f64]";

const DYNAMICS_LANES: &str = "t: ::mbs::F64x4, q: &[::mbs::F64x4], qd: &[::mbs::F64x4], u: &[::mbs::F64x4], m: &mut [::mbs::F64x4], h: &mut [::mbs::F64x4]";
const FORWARD_DYNAMICS_LANES: &str = "t: ::mbs::F64x4, q: &[::mbs::F64x4], qd: &[::mbs::F64x4], u: &[::mbs::F64x4], qdd: &mut [::mbs::F64x4], pivots: &mut [::mbs::F64x4]";

/// The batch methods (four states at once on `::mbs::F64x4` lanes), which have defaults in
/// the trait (lane by lane) that models with `option batch;` override; the arguments are
/// those of `dynamics` and `forward_dynamics` with lanes for `f64`, after the four models
/// (`each`) of the `_lanes` methods, whose parameters and charts the lanes take.
pub const BATCH: [Method; 4] = [
    method("dynamics_x4", DYNAMICS_LANES, ""),
    method("forward_dynamics_x4", FORWARD_DYNAMICS_LANES, ""),
    Method {
        name: "dynamics_lanes",
        receiver: "each: [&Self; 4]",
        args: DYNAMICS_LANES,
        ret: "",
    },
    Method {
        name: "forward_dynamics_lanes",
        receiver: "each: [&Self; 4]",
        args: FORWARD_DYNAMICS_LANES,
        ret: "",
    },
];

/// The method `name` of the table.
pub fn method_named(name: &str) -> &'static Method {
    METHODS
        .iter()
        .find(|m| m.name == name)
        .unwrap_or_else(|| panic!("`{name}` is not a method of mbs::Model"))
}

/// The parameter list of method `name` (for the inner functions that share it).
pub fn args(name: &str) -> &'static str {
    method_named(name).args
}

impl Method {
    /// The argument names as a call passes them: `t, q, m`.
    pub fn call(&self) -> String {
        call_of(self.args)
    }
}

/// The names of a parameter list as a call's arguments: `t: f64, q: &[f64]` → `t, q`.
pub fn call_of(args: &str) -> String {
    args.split(',')
        .filter_map(|a| a.split(':').next())
        .map(str::trim)
        .filter(|a| !a.is_empty())
        .collect::<Vec<_>>()
        .join(", ")
}

/// The sizes of a model, its associated constants.
pub struct Sizes {
    pub nq: usize,
    pub nu: usize,
    pub nframes: usize,
    pub npoints: usize,
    pub nc: usize,
    /// rotation joints: when there are any, the model overrides `chart` and `set_chart`,
    /// reading and writing its field `charts`
    pub charts: usize,
    /// `option batch;`: the model overrides the methods of [`BATCH`]
    pub batch: bool,
    /// `option motion;`: the model overrides [`MOTION`] and [`TRANSMIT`]
    pub motion: bool,
    /// the parameters marked `sensitive` (field names): the model overrides
    /// [`PARAMETER_TANGENTS`] and [`START_SENSITIVITIES`] and sets `SENSITIVE`
    pub sensitive: Vec<String>,
    /// the model overrides [`REST_TANGENT_DERIVATIVES`] (sensitive parameters and tangents)
    pub rest_derivatives: bool,
    /// the model overrides [`CONSTRAINT_PARAMETER_TANGENTS`] (sensitive parameters and
    /// constraints)
    pub constraint_sensitivity: bool,
    /// the model overrides [`CONSTRAINT_REST_DERIVATIVES`] (sensitive parameters,
    /// constraints and tangents)
    pub constraint_rest_derivatives: bool,
}

/// `impl ::mbs::Model for {ty}` with parameter struct `pty`: the constants, then every method
/// of [`METHODS`], [`FORWARD_DYNAMICS`] and [`FORWARD_DYNAMICS_FORCED`] (and [`BATCH`] with `sizes.batch`,
/// [`PARAMETER_TANGENTS`] with sensitive parameters) with the body `body(method)`.
pub fn model_impl(
    ty: &str,
    pty: &str,
    sizes: &Sizes,
    mut body: impl FnMut(&Method) -> String,
) -> String {
    let Sizes {
        nq,
        nu,
        nframes,
        npoints,
        nc,
        charts,
        batch,
        motion,
        sensitive,
        rest_derivatives,
        constraint_sensitivity,
        constraint_rest_derivatives,
    } = sizes;
    let mut s = format!(
        "impl ::mbs::Model for {ty} {{
type Params = {pty};
const NQ: usize = {nq};
const NU: usize = {nu};
const NFRAMES: usize = {nframes};
const NPOINTS: usize = {npoints};
const NC: usize = {nc};
const FORWARD_DYNAMICS_GENERATED: bool = true;
const BATCH_GENERATED: bool = {batch};
const MOTION_GENERATED: bool = {motion};
"
    );
    if !sensitive.is_empty() {
        let names: Vec<String> = sensitive.iter().map(|n| format!("{n:?}")).collect();
        s.push_str(&format!(
            "const SENSITIVE: &'static [&'static str] = &[{}];\n",
            names.join(", ")
        ));
    }
    let batch_methods = if *batch { &BATCH[..] } else { &[] };
    let motion_methods = if *motion {
        &[MOTION, TRANSMIT][..]
    } else {
        &[]
    };
    let sensitivity_methods = match (sensitive.is_empty(), rest_derivatives) {
        (true, _) => &[][..],
        (false, false) => &[PARAMETER_TANGENTS, START_SENSITIVITIES][..],
        (false, true) => &[
            PARAMETER_TANGENTS,
            START_SENSITIVITIES,
            REST_TANGENT_DERIVATIVES,
        ][..],
    };
    let constraint_methods = match (constraint_sensitivity, constraint_rest_derivatives) {
        (false, _) => &[][..],
        (true, false) => std::slice::from_ref(&CONSTRAINT_PARAMETER_TANGENTS),
        (true, true) => &[CONSTRAINT_PARAMETER_TANGENTS, CONSTRAINT_REST_DERIVATIVES][..],
    };
    for m in METHODS
        .iter()
        .chain([
            &FORWARD_DYNAMICS,
            &FORWARD_DYNAMICS_FORCED,
            &POINT_KINEMATICS,
        ])
        .chain(motion_methods)
        .chain(batch_methods)
        .chain(sensitivity_methods)
        .chain(constraint_methods)
    {
        let args = m.args.replace("{P}", pty);
        let ret = if m.ret.is_empty() {
            String::new()
        } else {
            format!(" -> {}", m.ret.replace("{P}", pty))
        };
        let sep = if args.is_empty() { "" } else { ", " };
        s.push_str(&format!(
            "fn {}({}{sep}{args}){ret} {{\n{}\n}}\n",
            m.name,
            m.receiver,
            body(m)
        ));
    }
    if *charts > 0 {
        s.push_str(
            "fn chart(&self, joint: usize) -> [[f64; 3]; 3] {\nself.charts[joint]\n}\n\
             fn set_chart(&mut self, joint: usize, r: [[f64; 3]; 3]) {\nself.charts[joint] = r;\n}\n",
        );
    }
    s.push_str("}\n");
    s
}
