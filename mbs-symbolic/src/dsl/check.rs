//! [`ModelDef`] → [`System`]: resolves names, lowers expressions into the arena and checks
//! everything that can be checked before generation. All errors are collected, each on the
//! offending tokens, naming the construct and the fix.

use super::ast::{BodyRef, DofName, EffectStmt, Item, ModelDef};
use super::names::did_you_mean;
use crate::expr::{ExprId, Func, SliceEnv, UserFn, Var};
use crate::mech::system::*;
use proc_macro2::Span;
use rustc_hash::FxHashMap;
use syn::spanned::Spanned;
use syn::{Expr, Ident};

/// Names that the DSL reserves.
const RESERVED: [&str; 10] = [
    "t", "q", "qd", "qdd", "u", "PI", "E", "TAU", "ground", "TOG",
];

/// What an expression may depend on, and how to say so when it does not.
#[derive(Clone, Copy)]
struct Allow {
    q: bool,
    qd: bool,
    t: bool,
    u: bool,
    params: bool,
    /// the construct, for messages: "a parameter default", "TOG[bar]", …
    what: &'static str,
}

const CONSTANT: Allow = Allow {
    q: false,
    qd: false,
    t: false,
    u: false,
    params: false,
    what: "a parameter default",
};
const PARAMS_ONLY: Allow = Allow {
    q: false,
    qd: false,
    t: false,
    u: false,
    params: true,
    what: "",
};
const POSITION: Allow = Allow {
    q: true,
    qd: false,
    t: true,
    u: false,
    params: true,
    what: "a transform",
};
const ANY: Allow = Allow {
    q: true,
    qd: true,
    t: true,
    u: true,
    params: true,
    what: "",
};

#[derive(Clone)]
enum Scalar {
    Param(usize),
    Let(Expr),
    Dof(usize),
    Input(usize),
    /// inline-function argument, bound to an expression
    Bound(ExprId),
}

#[derive(Clone)]
enum FnSym {
    Inline { args: Vec<Ident>, body: Expr },
    Extern { id: u16 },
}

struct Checker {
    sys: System,
    errors: Vec<syn::Error>,
    scalars: FxHashMap<String, Scalar>,
    fns: FxHashMap<String, FnSym>,
    /// lets being lowered (cycle detection) and lowered lets
    let_busy: Vec<String>,
    let_done: FxHashMap<String, ExprId>,
    /// frames by name, declaration order (numbers in TOG[2] refer to it)
    frame_names: FxHashMap<String, usize>,
    frame_spans: Vec<Span>,
    /// whether TOG[i] is defined yet
    tog_defined: Vec<bool>,
    points: FxHashMap<String, usize>,
    effects: FxHashMap<String, usize>,
    dof_spans: Vec<Span>,
    extern_spans: Vec<(String, Span)>,
    defaults: Vec<f64>,
    /// inline-function call depth, against runaway recursion
    depth: usize,
}

/// A checked model and the spans that generation-time errors point at.
pub struct Checked {
    pub system: System,
    /// `extern fn` names and their spans (for missing derivatives)
    pub extern_spans: Vec<(String, Span)>,
}

/// Checks one model; on failure, every error found, combined.
pub fn check(def: &ModelDef) -> Result<Checked, syn::Error> {
    let mut c = Checker {
        sys: System::new(&def.name.to_string()),
        errors: Vec::new(),
        scalars: FxHashMap::default(),
        fns: FxHashMap::default(),
        let_busy: Vec::new(),
        let_done: FxHashMap::default(),
        frame_names: FxHashMap::default(),
        frame_spans: Vec::new(),
        tog_defined: Vec::new(),
        points: FxHashMap::default(),
        effects: FxHashMap::default(),
        dof_spans: Vec::new(),
        extern_spans: Vec::new(),
        defaults: Vec::new(),
        depth: 0,
    };
    c.sys.docs = def.docs.clone();
    c.declare(def);
    c.lower_items(def);
    c.final_checks();
    let mut errs = c.errors.into_iter();
    match errs.next() {
        None => Ok(Checked {
            system: c.sys,
            extern_spans: c.extern_spans,
        }),
        Some(mut first) => {
            for e in errs {
                first.combine(e);
            }
            Err(first)
        }
    }
}

fn err(span: Span, msg: impl std::fmt::Display) -> syn::Error {
    syn::Error::new(span, msg.to_string())
}

impl Checker {
    fn error(&mut self, span: Span, msg: impl std::fmt::Display) {
        self.errors.push(err(span, msg));
    }

    fn reserved(&mut self, name: &Ident) -> bool {
        let s = name.to_string();
        if RESERVED.contains(&s.as_str()) {
            self.error(
                name.span(),
                format!("`{s}` is a reserved name in multibody!; choose another name"),
            );
            return true;
        }
        false
    }

    /// Pass 1: every declared name, so statements may refer to names declared later.
    fn declare(&mut self, def: &ModelDef) {
        for item in &def.items {
            match item {
                Item::Param { name, value } => {
                    if self.reserved(name) || self.duplicate_scalar(name) {
                        continue;
                    }
                    let e = self.lower(value, CONSTANT);
                    let v = self.sys.arena.as_num(e);
                    let default = match v {
                        Some(v) if v.is_finite() => v,
                        Some(_) => {
                            self.error(
                                value.span(),
                                format!("the default of parameter `{name}` is not finite"),
                            );
                            0.0
                        }
                        None => 0.0,
                    };
                    self.scalars
                        .insert(name.to_string(), Scalar::Param(self.sys.params.len()));
                    self.sys.params.push(ParamDef {
                        name: name.to_string(),
                        default,
                    });
                    self.defaults.push(default);
                }
                Item::Let { name, value } => {
                    if !self.reserved(name) && !self.duplicate_scalar(name) {
                        self.scalars
                            .insert(name.to_string(), Scalar::Let(value.clone()));
                    }
                }
                Item::Dof { name, span, .. } => {
                    let i = self.sys.dofs.len();
                    let display = match name {
                        DofName::Indexed(k, s) => {
                            if *k != i {
                                self.error(*s, format!("coordinates are numbered in declaration order: this is the coordinate number {i}, write `dof q[{i}]` (or declare q[{k}] in its place)"));
                            }
                            format!("q[{i}]")
                        }
                        DofName::Named(id) => {
                            if self.reserved(id) || self.duplicate_scalar(id) {
                                continue;
                            }
                            self.scalars.insert(id.to_string(), Scalar::Dof(i));
                            id.to_string()
                        }
                    };
                    let z = self.sys.arena.zero();
                    self.sys.dofs.push(DofDef {
                        name: display,
                        q0: z,
                        qd0: z,
                    });
                    self.dof_spans.push(*span);
                }
                Item::Input { name } => {
                    if !self.reserved(name) && !self.duplicate_scalar(name) {
                        self.scalars
                            .insert(name.to_string(), Scalar::Input(self.sys.inputs.len()));
                        self.sys.inputs.push(name.to_string());
                    }
                }
                Item::Body { name, .. } | Item::Frame { name } => {
                    if self.reserved(name) {
                        continue;
                    }
                    if self.frame_names.contains_key(&name.to_string())
                        || self.points.contains_key(&name.to_string())
                    {
                        self.error(name.span(), format!("duplicate body or frame `{name}`: each body, frame and point needs its own name"));
                        continue;
                    }
                    self.frame_names
                        .insert(name.to_string(), self.sys.frames.len());
                    self.frame_spans.push(name.span());
                    self.tog_defined.push(false);
                    self.sys.frames.push(FrameDef {
                        name: name.to_string(),
                        parent: None,
                        factors: Vec::new(),
                        inertia: None,
                    });
                }
                Item::Point { name, .. } => {
                    if self.reserved(name) {
                        continue;
                    }
                    if self.frame_names.contains_key(&name.to_string())
                        || self.points.contains_key(&name.to_string())
                    {
                        self.error(name.span(), format!("duplicate point `{name}`: each body, frame and point needs its own name"));
                        continue;
                    }
                    self.points.insert(name.to_string(), self.sys.points.len());
                    let z = self.sys.arena.zero();
                    self.sys.points.push(PointDef {
                        name: name.to_string(),
                        frame: None,
                        pos: [z; 3],
                    });
                }
                Item::Fn { name, args, body } => {
                    if self.duplicate_fn(name) {
                        continue;
                    }
                    self.fns.insert(
                        name.to_string(),
                        FnSym::Inline {
                            args: args.clone(),
                            body: body.clone(),
                        },
                    );
                }
                Item::ExternFn { name, paths } => {
                    if self.duplicate_fn(name) {
                        continue;
                    }
                    if paths.is_empty() {
                        self.error(name.span(), format!("`extern fn {name}` needs at least the function: `extern fn {name} = [path::to::{name}, path::to::{name}_d, …];`"));
                        continue;
                    }
                    let uf = UserFn {
                        name: name.to_string(),
                        paths: paths
                            .iter()
                            .map(|p| quote::quote!(#p).to_string().replace(' ', ""))
                            .collect(),
                    };
                    let id = self.sys.arena.user_fn(uf);
                    self.extern_spans.push((name.to_string(), name.span()));
                    self.fns.insert(name.to_string(), FnSym::Extern { id });
                }
                Item::EffectBlock { name, .. } => {
                    if self.effects.contains_key(&name.to_string()) {
                        self.error(name.span(), format!("duplicate effect `{name}`"));
                        continue;
                    }
                    self.effects
                        .insert(name.to_string(), self.sys.effects.len());
                    self.sys.effects.push(EffectDef {
                        name: Some(name.to_string()),
                        loads: Vec::new(),
                    });
                }
                _ => {}
            }
        }
    }

    fn duplicate_scalar(&mut self, name: &Ident) -> bool {
        if self.scalars.contains_key(&name.to_string()) {
            self.error(name.span(), format!("duplicate name `{name}`: parameters, lets, coordinates and inputs share one namespace; rename one of them"));
            return true;
        }
        false
    }

    fn duplicate_fn(&mut self, name: &Ident) -> bool {
        let s = name.to_string();
        if self.fns.contains_key(&s)
            || Func::from_name(&s).is_some()
            || matches!(s.as_str(), "atan2" | "powi" | "pow")
        {
            self.error(
                name.span(),
                format!(
                    "duplicate function `{name}`: it is already defined (or built in); rename it"
                ),
            );
            return true;
        }
        false
    }

    /// Pass 2: lower every statement in order.
    fn lower_items(&mut self, def: &ModelDef) {
        let mut dof_i = 0;
        let mut scene_names: FxHashMap<String, ()> = FxHashMap::default();
        for item in &def.items {
            match item {
                Item::Dof { q0, qd0, name, .. } => {
                    if let DofName::Named(id) = name {
                        if !matches!(self.scalars.get(&id.to_string()), Some(Scalar::Dof(i)) if *i == dof_i)
                        {
                            continue;
                        }
                    }
                    let a = Allow {
                        what: "an initial value",
                        ..PARAMS_ONLY
                    };
                    if let Some(e) = q0 {
                        self.sys.dofs[dof_i].q0 = self.lower(e, a);
                    }
                    if let Some(e) = qd0 {
                        self.sys.dofs[dof_i].qd0 = self.lower(e, a);
                    }
                    dof_i += 1;
                }
                Item::Body { name, props } => self.lower_body(name, props),
                Item::Point { name, body, at } => {
                    let Some(&pi) = self.points.get(&name.to_string()) else {
                        continue;
                    };
                    let frame = self.body_ref(body);
                    let pos = self.triple(
                        at,
                        Allow {
                            what: "a point position",
                            ..PARAMS_ONLY
                        },
                        "a point position",
                    );
                    self.sys.points[pi].frame = frame.flatten();
                    if let Some(p) = pos {
                        self.sys.points[pi].pos = p;
                    }
                }
                Item::Tog {
                    target,
                    chain,
                    span,
                } => self.lower_tog(target, chain, *span),
                Item::Effect(stmt) => {
                    let loads = self.lower_effect(stmt);
                    match self.sys.effects.iter_mut().find(|e| e.name.is_none()) {
                        Some(e) => e.loads.extend(loads),
                        None => self.sys.effects.push(EffectDef { name: None, loads }),
                    }
                }
                Item::EffectBlock { name, stmts } => {
                    let Some(&ei) = self.effects.get(&name.to_string()) else {
                        continue;
                    };
                    for s in stmts {
                        let loads = self.lower_effect(s);
                        self.sys.effects[ei].loads.extend(loads);
                    }
                }
                Item::Scene { name, effects } => {
                    if scene_names.insert(name.to_string(), ()).is_some() {
                        self.error(name.span(), format!("duplicate scene `{name}`"));
                        continue;
                    }
                    let mut list = Vec::new();
                    for e in effects {
                        match self.effects.get(&e.to_string()) {
                            Some(&i) => {
                                if list.contains(&i) {
                                    self.error(
                                        e.span(),
                                        format!("effect `{e}` is listed twice in scene `{name}`"),
                                    );
                                }
                                list.push(i);
                            }
                            None => {
                                let names: Vec<String> = self.effects.keys().cloned().collect();
                                self.error(
                                    e.span(),
                                    format!(
                                        "unknown effect `{e}` in scene `{name}`{}",
                                        did_you_mean(
                                            &e.to_string(),
                                            names.iter().map(String::as_str),
                                            "declare it with `effect NAME { … }`"
                                        )
                                    ),
                                );
                            }
                        }
                    }
                    self.sys.scenes.push(SceneDef {
                        name: name.to_string(),
                        effects: list,
                    });
                }
                Item::Option { key, value } => self.lower_option(key, value.as_ref()),
                _ => {}
            }
        }
    }

    fn lower_option(&mut self, key: &Ident, value: Option<&Expr>) {
        match (key.to_string().as_str(), value) {
            ("tangents", None) => self.sys.options.tangents = true,
            ("formulation", Some(Expr::Path(p))) if p.path.get_ident().is_some() => {
                let v = p.path.get_ident().unwrap();
                self.sys.options.formulation = match v.to_string().as_str() {
                    "recursive" => Some(Formulation::Recursive),
                    "virtual_power" => Some(Formulation::VirtualPower),
                    other => {
                        self.error(v.span(), format!("unknown formulation `{other}`: write `option formulation = recursive;` or `option formulation = virtual_power;`"));
                        None
                    }
                }
            }
            ("formulation", _) => self.error(key.span(), "write `option formulation = recursive;` or `option formulation = virtual_power;`"),
            ("tangents", Some(v)) => self.error(v.span(), "write `option tangents;` (it takes no value)"),
            (other, _) => self.error(key.span(), format!("unknown option `{other}`: the options are `tangents` and `formulation = recursive | virtual_power`")),
        }
    }

    fn lower_body(&mut self, name: &Ident, props: &[(Ident, Expr)]) {
        let Some(&fi) = self.frame_names.get(&name.to_string()) else {
            return;
        };
        let mut mass = None;
        let mut tensor = None;
        for (key, value) in props {
            match key.to_string().as_str() {
                "mass" => {
                    let m = self.lower(value, Allow { what: "a mass", ..PARAMS_ONLY });
                    let mv = self.eval_default(m);
                    if mv <= 0.0 || !mv.is_finite() {
                        let how = if self.sys.arena.is_const(m) { "" } else { " with the default parameters" };
                        self.error(value.span(), format!("the mass of body `{name}` must be positive, it is {mv}{how}: give it a positive mass, or declare a massless `frame {name};`"));
                    }
                    mass = Some(m);
                }
                "inertia" => {
                    let a = Allow { what: "an inertia", ..PARAMS_ONLY };
                    let elems: Vec<&Expr> = match value {
                        Expr::Tuple(t) => t.elems.iter().collect(),
                        _ => Vec::new(),
                    };
                    if elems.len() != 3 && elems.len() != 6 {
                        self.error(value.span(), "inertia is `(Ixx, Iyy, Izz)` or `(Ixx, Iyy, Izz, Ixy, Ixz, Iyz)`, about G in body axes");
                        continue;
                    }
                    let mut t = [self.sys.arena.zero(); 6];
                    for (i, e) in elems.iter().enumerate() {
                        t[i] = self.lower(e, a);
                    }
                    let vals: Vec<f64> = t.iter().map(|&e| self.eval_default(e)).collect();
                    let vals6 = [vals[0], vals[1], vals[2], vals.get(3).copied().unwrap_or(0.0), vals.get(4).copied().unwrap_or(0.0), vals.get(5).copied().unwrap_or(0.0)];
                    if let Some(msg) = super::inertia::inertia_problem(vals6) {
                        self.error(value.span(), format!("inertia of body `{name}`: {msg}"));
                    }
                    tensor = Some(t);
                }
                other => self.error(key.span(), format!("unknown body property `{other}`: a body has `mass = …;` and `inertia = (Ixx, Iyy, Izz[, Ixy, Ixz, Iyz]);`")),
            }
        }
        match (mass, tensor) {
            (Some(m), Some(t)) => self.sys.frames[fi].inertia = Some(Inertia { mass: m, tensor: t }),
            (Some(m), None) => {
                // a point mass
                let z = self.sys.arena.zero();
                self.sys.frames[fi].inertia = Some(Inertia { mass: m, tensor: [z; 6] });
            }
            (None, _) => self.error(name.span(), format!("body `{name}` has no mass: add `mass = …;` (or declare a massless `frame {name};`)")),
        }
    }

    fn eval_default(&self, e: ExprId) -> f64 {
        let env = SliceEnv {
            params: &self.defaults,
            ..SliceEnv::default()
        };
        self.sys.arena.eval(&[e], &env)[0]
    }

    /// A body/frame reference: `Some(None)` is the ground, `None` an error already reported.
    fn body_ref(&mut self, r: &BodyRef) -> Option<Option<usize>> {
        match r {
            BodyRef::Name(id) if id == "ground" => Some(None),
            BodyRef::Name(id) => match self.frame_names.get(&id.to_string()) {
                Some(&i) => Some(Some(i)),
                None => {
                    let names: Vec<String> = self.frame_names.keys().cloned().collect();
                    self.error(
                        id.span(),
                        format!(
                            "unknown body `{id}`{}",
                            did_you_mean(
                                &id.to_string(),
                                names.iter().map(String::as_str),
                                "declare it with `body NAME { … }` or `frame NAME;`"
                            )
                        ),
                    );
                    None
                }
            },
            BodyRef::Index(i, s) => {
                if *i < self.sys.frames.len() {
                    Some(Some(*i))
                } else {
                    self.error(*s, format!("TOG[{i}] is out of range: the model declares {} bodies and frames, numbered from 0", self.sys.frames.len()));
                    None
                }
            }
        }
    }

    fn ident_body_ref(&mut self, e: &Expr) -> Option<Option<usize>> {
        match e {
            Expr::Path(p) if p.path.get_ident().is_some() => {
                self.body_ref(&BodyRef::Name(p.path.get_ident().unwrap().clone()))
            }
            _ => {
                self.error(e.span(), "expected a body or frame name");
                None
            }
        }
    }

    fn lower_tog(&mut self, target: &BodyRef, chain: &Expr, span: Span) {
        let Some(t) = self.body_ref(target) else {
            return;
        };
        let Some(fi) = t else {
            self.error(
                target.span(),
                "the ground does not move: TOG[ground] cannot be assigned",
            );
            return;
        };
        if self.tog_defined[fi] {
            self.error(
                span,
                format!(
                    "TOG[{}] is defined twice: each body and frame has one TOG",
                    self.sys.frames[fi].name
                ),
            );
            return;
        }
        let mut leaves = Vec::new();
        if !self.flatten_product(chain, &mut leaves) {
            return;
        }
        let what: &'static str = "a transform (TOG)";
        let mut parent = None;
        let mut factors = Vec::new();
        for (k, leaf) in leaves.iter().enumerate() {
            if let Expr::Index(ix) = leaf {
                if matches!(&*ix.expr, Expr::Path(p) if p.path.is_ident("TOG")) {
                    if k != 0 {
                        self.error(
                            leaf.span(),
                            "TOG[…] may only start a product: write `TOG[parent] * Tdisp(…) * …`",
                        );
                        continue;
                    }
                    let r = match &*ix.index {
                        Expr::Path(p) if p.path.get_ident().is_some() => {
                            BodyRef::Name(p.path.get_ident().unwrap().clone())
                        }
                        Expr::Lit(syn::ExprLit {
                            lit: syn::Lit::Int(l),
                            ..
                        }) => match l.base10_parse() {
                            Ok(v) => BodyRef::Index(v, l.span()),
                            Err(e) => {
                                self.errors.push(e);
                                continue;
                            }
                        },
                        other => {
                            self.error(other.span(), "expected a body name or number in TOG[…]");
                            continue;
                        }
                    };
                    match self.body_ref(&r) {
                        Some(Some(p)) if p == fi => self.error(r.span(), format!("TOG[{}] cannot refer to itself: start from its parent's TOG", self.sys.frames[fi].name)),
                        Some(Some(p)) if !self.tog_defined[p] => self.error(r.span(), format!("TOG[{}] is used before it is defined: define TOG[{}] earlier (a product may refer only to earlier bodies)", self.sys.frames[p].name, self.sys.frames[p].name)),
                        Some(p) => parent = p,
                        None => {}
                    }
                    continue;
                }
            }
            if let Some(f) = self.lower_factor(leaf, what) {
                factors.extend(f);
            }
        }
        let frame = &mut self.sys.frames[fi];
        frame.parent = parent;
        frame.factors = factors;
        self.tog_defined[fi] = true;
    }

    /// Splits `a * b * c` into its factors; anything but products is an error.
    fn flatten_product<'e>(&mut self, e: &'e Expr, out: &mut Vec<&'e Expr>) -> bool {
        match e {
            Expr::Binary(b) if matches!(b.op, syn::BinOp::Mul(_)) => {
                self.flatten_product(&b.left, out) && self.flatten_product(&b.right, out)
            }
            Expr::Binary(b) => {
                self.error(b.op.span(), "transforms combine by products only: write `TOG[parent] * Trotz(q[0]) * Tdisp(x, y, z)`");
                false
            }
            Expr::Paren(p) => self.flatten_product(&p.expr, out),
            Expr::Group(g) => self.flatten_product(&g.expr, out),
            _ => {
                out.push(e);
                true
            }
        }
    }

    /// One transform factor; `None` after an error, an empty list for an identity.
    fn lower_factor(&mut self, e: &Expr, what: &'static str) -> Option<Vec<Factor>> {
        let bad = "expected a transform: Tdisp(x, y, z), Trotx(a), Troty(a), Trotz(a), Trotn(nx, ny, nz, a) or TOG[body]";
        let Expr::Call(call) = e else {
            self.error(e.span(), bad);
            return None;
        };
        let Expr::Path(p) = &*call.func else {
            self.error(e.span(), bad);
            return None;
        };
        let Some(name) = p.path.get_ident() else {
            self.error(e.span(), bad);
            return None;
        };
        let args: Vec<&Expr> = call.args.iter().collect();
        let a = Allow { what, ..POSITION };
        let arity = |c: &mut Checker, n: usize| {
            if args.len() != n {
                c.error(
                    call.span(),
                    format!(
                        "`{name}` takes {n} argument{}, found {}",
                        if n == 1 { "" } else { "s" },
                        args.len()
                    ),
                );
                false
            } else {
                true
            }
        };
        let z = self.sys.arena.zero();
        let o = self.sys.arena.one();
        let rot = |c: &mut Checker, axis: [ExprId; 3]| -> Option<Vec<Factor>> {
            let angle = c.lower(args[args.len() - 1], a);
            if c.sys.arena.is_num(angle, 0.0) {
                return Some(Vec::new());
            }
            Some(vec![Factor::Rot { axis, angle }])
        };
        match name.to_string().as_str() {
            "Tdisp" => {
                if !arity(self, 3) {
                    return None;
                }
                let d = [
                    self.lower(args[0], a),
                    self.lower(args[1], a),
                    self.lower(args[2], a),
                ];
                if d.iter().all(|&x| self.sys.arena.is_num(x, 0.0)) {
                    return Some(Vec::new());
                }
                Some(vec![Factor::Disp(d)])
            }
            "Trotx" => arity(self, 1).then(|| rot(self, [o, z, z])).flatten(),
            "Troty" => arity(self, 1).then(|| rot(self, [z, o, z])).flatten(),
            "Trotz" => arity(self, 1).then(|| rot(self, [z, z, o])).flatten(),
            "Trotn" => {
                if !arity(self, 4) {
                    return None;
                }
                let pa = Allow {
                    what: "the axis of Trotn",
                    ..PARAMS_ONLY
                };
                let n = [
                    self.lower(args[0], pa),
                    self.lower(args[1], pa),
                    self.lower(args[2], pa),
                ];
                let v: Vec<f64> = n.iter().map(|&x| self.eval_default(x)).collect();
                let norm = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                let span = args[0]
                    .span()
                    .join(args[2].span())
                    .unwrap_or(args[0].span());
                if norm == 0.0 {
                    self.error(
                        span,
                        "the axis of Trotn is zero: give a unit axis, e.g. Trotn(0, 0, 1, a)",
                    );
                    return None;
                }
                if (norm - 1.0).abs() > 1e-9 {
                    self.error(span, format!("Trotn needs a unit axis; ({}, {}, {}) has norm {norm}: divide it by its norm", v[0], v[1], v[2]));
                    return None;
                }
                rot(self, n)
            }
            other => {
                let known = ["Tdisp", "Trotx", "Troty", "Trotz", "Trotn"];
                self.error(
                    name.span(),
                    format!(
                        "unknown transform `{other}`{}",
                        did_you_mean(other, known.into_iter(), bad)
                    ),
                );
                None
            }
        }
    }

    /// `(x, y, z)` → three expressions.
    fn triple(&mut self, e: &Expr, a: Allow, what: &str) -> Option<[ExprId; 3]> {
        match e {
            Expr::Tuple(t) if t.elems.len() == 3 => {
                let v: Vec<ExprId> = t.elems.iter().map(|x| self.lower(x, a)).collect();
                Some([v[0], v[1], v[2]])
            }
            Expr::Paren(p) => self.triple(&p.expr, a, what),
            _ => {
                self.error(e.span(), format!("{what} is a vector `(x, y, z)`"));
                None
            }
        }
    }

    fn attach(&mut self, e: &Expr) -> Option<Attach> {
        let z = self.sys.arena.zero();
        if let Expr::Path(p) = e {
            if let Some(id) = p.path.get_ident() {
                let s = id.to_string();
                if let Some(&pi) = self.points.get(&s) {
                    let pt = &self.sys.points[pi];
                    return Some(Attach {
                        frame: pt.frame,
                        pos: pt.pos,
                    });
                }
                if s == "ground" {
                    return Some(Attach {
                        frame: None,
                        pos: [z; 3],
                    });
                }
                if let Some(&fi) = self.frame_names.get(&s) {
                    return Some(Attach {
                        frame: Some(fi),
                        pos: [z; 3],
                    });
                }
                let names: Vec<String> = self
                    .points
                    .keys()
                    .chain(self.frame_names.keys())
                    .cloned()
                    .collect();
                self.error(
                    id.span(),
                    format!(
                        "unknown point or body `{s}`{}",
                        did_you_mean(
                            &s,
                            names.iter().map(String::as_str),
                            "declare it with `point NAME on BODY at (x, y, z);`"
                        )
                    ),
                );
                return None;
            }
        }
        self.error(e.span(), "expected a point or body name");
        None
    }

    fn lower_effect(&mut self, s: &EffectStmt) -> Vec<Load> {
        let kind = s.kind.to_string();
        let named = |key: &str| s.named.iter().find(|(k, _)| k == key).map(|(_, v)| v);
        let known_named: &[&str] = match kind.as_str() {
            "spring" => &["k", "l0", "c"],
            "damper" => &["c"],
            "force" => &["frame"],
            "torque" => &["frame", "relative_to", "axis"],
            _ => &[],
        };
        for (k, _) in &s.named {
            if !known_named.contains(&k.to_string().as_str()) {
                let list = if known_named.is_empty() {
                    "none".to_string()
                } else {
                    known_named.join(", ")
                };
                self.error(
                    k.span(),
                    format!("`{kind}` has no argument `{k}`; its named arguments: {list}"),
                );
            }
        }
        let npos = |c: &mut Checker, n: usize, usage: &str| {
            if s.positional.len() != n {
                c.error(
                    s.kind.span(),
                    format!(
                        "`{kind}` takes {n} positional argument{}, found {}: write `{usage}`",
                        if n == 1 { "" } else { "s" },
                        s.positional.len()
                    ),
                );
                false
            } else {
                true
            }
        };
        let pa = Allow {
            what: "",
            ..PARAMS_ONLY
        };
        let mut out = Vec::new();
        match kind.as_str() {
            "gravity" => {
                if npos(self, 3, "gravity(gx, gy, gz)") {
                    let g = [0, 1, 2].map(|i| {
                        self.lower(
                            &s.positional[i],
                            Allow {
                                what: "gravity",
                                ..PARAMS_ONLY
                            },
                        )
                    });
                    out.push(Load::Gravity(g));
                }
            }
            "spring" | "damper" => {
                let usage = if kind == "spring" {
                    "spring(a, b, k = …, l0 = …)"
                } else {
                    "damper(a, b, c = …)"
                };
                if !npos(self, 2, usage) {
                    return out;
                }
                let (Some(a), Some(b)) =
                    (self.attach(&s.positional[0]), self.attach(&s.positional[1]))
                else {
                    return out;
                };
                if kind == "spring" {
                    let Some(k) = named("k") else {
                        self.error(
                            s.kind.span(),
                            "a spring needs its stiffness: `spring(a, b, k = …, l0 = …)`",
                        );
                        return out;
                    };
                    let k = self.lower(
                        k,
                        Allow {
                            what: "a spring stiffness",
                            ..pa
                        },
                    );
                    if self.eval_default(k) < 0.0 {
                        self.error(
                            named("k").unwrap().span(),
                            "a spring stiffness must not be negative",
                        );
                    }
                    let l0 = match named("l0") {
                        Some(e) => self.lower(
                            e,
                            Allow {
                                what: "a rest length",
                                ..pa
                            },
                        ),
                        None => self.sys.arena.zero(),
                    };
                    out.push(Load::Spring { a, b, k, l0 });
                }
                let c_expr = named("c");
                if kind == "damper" && c_expr.is_none() {
                    self.error(
                        s.kind.span(),
                        "a damper needs its coefficient: `damper(a, b, c = …)`",
                    );
                }
                if let Some(c) = c_expr {
                    let c = self.lower(
                        c,
                        Allow {
                            what: "a damping coefficient",
                            ..pa
                        },
                    );
                    out.push(Load::Damper { a, b, c });
                }
            }
            "force" => {
                if !npos(self, 2, "force(point, (fx, fy, fz)[, frame = body])") {
                    return out;
                }
                let at = self.attach(&s.positional[0]);
                let f = self.triple(&s.positional[1], ANY, "a force");
                let frame = match named("frame") {
                    Some(e) => self.ident_body_ref(e),
                    None => Some(None),
                };
                if let (Some(at), Some(force), Some(frame)) = (at, f, frame) {
                    out.push(Load::Force { at, force, frame });
                }
            }
            "torque" => {
                let on = s.positional.first().and_then(|e| self.ident_body_ref(e));
                let reaction = match named("relative_to") {
                    Some(e) => self.ident_body_ref(e).map(Some),
                    None => Some(None),
                };
                let (torque, frame) = if let Some(axis) = named("axis") {
                    if !npos(
                        self,
                        2,
                        "torque(body, axis = z, value[, relative_to = other])",
                    ) {
                        return out;
                    }
                    let z = self.sys.arena.zero();
                    let o = self.sys.arena.one();
                    let dir = match axis {
                        Expr::Path(p) if p.path.is_ident("x") => Some([o, z, z]),
                        Expr::Path(p) if p.path.is_ident("y") => Some([z, o, z]),
                        Expr::Path(p) if p.path.is_ident("z") => Some([z, z, o]),
                        Expr::Tuple(_) => self.triple(
                            axis,
                            Allow {
                                what: "a torque axis",
                                ..pa
                            },
                            "a torque axis",
                        ),
                        _ => {
                            self.error(axis.span(), "the axis is x, y, z or a unit vector (nx, ny, nz), in the body's axes");
                            None
                        }
                    };
                    let v = self.lower(&s.positional[1], ANY);
                    let t = dir.map(|d| d.map(|c| self.sys.arena.mul(c, v)));
                    (t, on)
                } else {
                    if !npos(
                        self,
                        2,
                        "torque(body, (mx, my, mz)[, frame = body][, relative_to = other])",
                    ) {
                        return out;
                    }
                    let t = self.triple(&s.positional[1], ANY, "a torque");
                    let frame = match named("frame") {
                        Some(e) => self.ident_body_ref(e),
                        None => Some(None),
                    };
                    (t, frame)
                };
                if let (Some(on), Some(torque), Some(frame), Some(reaction)) =
                    (on, torque, frame, reaction)
                {
                    if on.is_none() {
                        self.error(
                            s.positional[0].span(),
                            "a torque on the ground does nothing: apply it to a body",
                        );
                        return out;
                    }
                    out.push(Load::Torque {
                        on,
                        torque,
                        frame,
                        reaction,
                    });
                }
            }
            "generalized_force" => {
                if !npos(self, 2, "generalized_force(q[i], value)") {
                    return out;
                }
                let dof = self.dof_ref(&s.positional[0]);
                let v = self.lower(&s.positional[1], ANY);
                if let Some(dof) = dof {
                    out.push(Load::GenForce { dof, value: v });
                }
            }
            other => {
                let known = [
                    "gravity",
                    "spring",
                    "damper",
                    "force",
                    "torque",
                    "generalized_force",
                ];
                self.error(s.kind.span(), format!("unknown effect `{other}`{}", did_you_mean(other, known.into_iter(), "the effects are gravity, spring, damper, force, torque and generalized_force")));
            }
        }
        out
    }

    /// `q[2]` or a coordinate name.
    fn dof_ref(&mut self, e: &Expr) -> Option<usize> {
        match e {
            Expr::Index(ix) if matches!(&*ix.expr, Expr::Path(p) if p.path.is_ident("q")) => {
                self.index_of(&ix.index, "q")
            }
            Expr::Path(p) if p.path.get_ident().is_some() => {
                let id = p.path.get_ident().unwrap();
                match self.scalars.get(&id.to_string()) {
                    Some(Scalar::Dof(i)) => Some(*i),
                    _ => {
                        self.error(
                            id.span(),
                            format!(
                                "`{id}` is not a coordinate: write `q[i]` or a coordinate's name"
                            ),
                        );
                        None
                    }
                }
            }
            _ => {
                self.error(
                    e.span(),
                    "expected a coordinate: `q[i]` or a coordinate's name",
                );
                None
            }
        }
    }

    /// The index in `v[idx]`: a number in range or a name of the right kind.
    fn index_of(&mut self, idx: &Expr, v: &str) -> Option<usize> {
        let (count, kind) = if v == "u" {
            (self.sys.inputs.len(), "inputs")
        } else {
            (self.sys.dofs.len(), "coordinates")
        };
        match idx {
            Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Int(l),
                ..
            }) => {
                let i: usize = l.base10_parse().ok()?;
                if i >= count {
                    let fix = if v == "u" {
                        format!("declare it with `input NAME;`")
                    } else {
                        format!("declare it with `dof q[{i}] = 0.0;`")
                    };
                    self.error(
                        l.span(),
                        format!("`{v}[{i}]` is out of range: the model has {count} {kind}; {fix}"),
                    );
                    return None;
                }
                Some(i)
            }
            Expr::Path(p) if p.path.get_ident().is_some() => {
                let id = p.path.get_ident().unwrap();
                match (self.scalars.get(&id.to_string()), v) {
                    (Some(Scalar::Input(i)), "u") => Some(*i),
                    (Some(Scalar::Dof(i)), "q" | "qd" | "qdd") => Some(*i),
                    _ => {
                        self.error(id.span(), format!("`{id}` is not one of the {kind}: write `{v}[i]` with a number or a name of the {kind}"));
                        None
                    }
                }
            }
            other => {
                self.error(
                    other.span(),
                    format!("the index of `{v}[…]` is a number or a name"),
                );
                None
            }
        }
    }

    fn not_allowed(&mut self, span: Span, thing: &str, a: Allow) -> ExprId {
        let what = if a.what.is_empty() {
            "this expression"
        } else {
            a.what
        };
        let hint = match thing {
            "qd" | "qdd" => {
                "positions and constants cannot depend on velocities or accelerations; use them in effects"
            }
            "u" => "inputs act through effects (forces, torques), not here",
            "q" | "t" => {
                "this value must be constant during the motion: use parameters and numbers"
            }
            _ => "use numbers and parameters only",
        };
        self.error(span, format!("`{thing}` cannot appear in {what}: {hint}"));
        self.sys.arena.zero()
    }

    /// Lowers a scalar expression.
    fn lower(&mut self, e: &Expr, a: Allow) -> ExprId {
        match e {
            Expr::Lit(l) => match &l.lit {
                syn::Lit::Int(i) => match i.base10_parse::<f64>() {
                    Ok(v) => self.sys.arena.num(v),
                    Err(er) => {
                        self.errors.push(er);
                        self.sys.arena.zero()
                    }
                },
                syn::Lit::Float(f) => match f.base10_parse::<f64>() {
                    Ok(v) => self.sys.arena.num(v),
                    Err(er) => {
                        self.errors.push(er);
                        self.sys.arena.zero()
                    }
                },
                other => {
                    self.error(other.span(), "expected a number");
                    self.sys.arena.zero()
                }
            },
            Expr::Paren(p) => self.lower(&p.expr, a),
            Expr::Group(g) => self.lower(&g.expr, a),
            Expr::Unary(u) => match u.op {
                syn::UnOp::Neg(_) => {
                    let x = self.lower(&u.expr, a);
                    self.sys.arena.neg(x)
                }
                _ => {
                    self.error(u.op.span(), "only `-` is a unary operator in expressions");
                    self.sys.arena.zero()
                }
            },
            Expr::Binary(b) => {
                let x = self.lower(&b.left, a);
                let y = self.lower(&b.right, a);
                let ar = &mut self.sys.arena;
                match b.op {
                    syn::BinOp::Add(_) => ar.add(x, y),
                    syn::BinOp::Sub(_) => ar.sub(x, y),
                    syn::BinOp::Mul(_) => ar.mul(x, y),
                    syn::BinOp::Div(_) => {
                        if ar.is_num(y, 0.0) {
                            self.error(b.right.span(), "division by zero");
                            return self.sys.arena.zero();
                        }
                        ar.div(x, y)
                    }
                    syn::BinOp::BitXor(_) => {
                        let e = err(
                            b.op.span(),
                            "`^` is not a power in Rust: write `powi(x, 2)` for an integer power or `pow(x, y)`",
                        );
                        self.errors.push(e);
                        self.sys.arena.zero()
                    }
                    _ => {
                        let e = err(b.op.span(), "expressions use `+ - * /` and functions");
                        self.errors.push(e);
                        self.sys.arena.zero()
                    }
                }
            }
            Expr::Path(p) => {
                let Some(id) = p.path.get_ident() else {
                    self.error(
                        p.span(),
                        "expected a name: paths are allowed only in `extern fn`",
                    );
                    return self.sys.arena.zero();
                };
                self.lower_name(id, a)
            }
            Expr::Index(ix) => {
                let Expr::Path(p) = &*ix.expr else {
                    self.error(
                        ix.expr.span(),
                        "only `q[i]`, `qd[i]`, `qdd[i]` and `u[i]` can be indexed",
                    );
                    return self.sys.arena.zero();
                };
                let v = p
                    .path
                    .get_ident()
                    .map(|i| i.to_string())
                    .unwrap_or_default();
                let (allowed, mk): (bool, fn(u16) -> Var) = match v.as_str() {
                    "q" => (a.q, Var::Q),
                    "qd" => (a.qd, Var::Qd),
                    "qdd" => (a.qd, Var::Qdd),
                    "u" => (a.u, Var::Input),
                    "TOG" => {
                        self.error(
                            ix.span(),
                            "TOG[…] is a transform, not a number: it can only start a TOG product",
                        );
                        return self.sys.arena.zero();
                    }
                    _ => {
                        self.error(
                            ix.expr.span(),
                            format!(
                                "`{v}[…]`: only `q[i]`, `qd[i]`, `qdd[i]` and `u[i]` can be indexed"
                            ),
                        );
                        return self.sys.arena.zero();
                    }
                };
                let Some(i) = self.index_of(&ix.index, &v) else {
                    return self.sys.arena.zero();
                };
                if !allowed {
                    return self.not_allowed(ix.span(), &v, a);
                }
                self.sys.arena.var(mk(i as u16))
            }
            Expr::Call(c) => self.lower_call(c, a),
            Expr::MethodCall(m) => {
                // x.sin() reads as sin(x)
                let mut args: Vec<Expr> = vec![(*m.receiver).clone()];
                args.extend(m.args.iter().cloned());
                let f = Expr::Path(syn::ExprPath {
                    attrs: vec![],
                    qself: None,
                    path: m.method.clone().into(),
                });
                let call = syn::ExprCall {
                    attrs: vec![],
                    func: Box::new(f),
                    paren_token: m.paren_token,
                    args: args.into_iter().collect(),
                };
                self.lower_call(&call, a)
            }
            other => {
                self.error(other.span(), "unsupported expression: use numbers, names, q[i], qd[i], u[i], t, + - * / and functions");
                self.sys.arena.zero()
            }
        }
    }

    fn lower_name(&mut self, id: &Ident, a: Allow) -> ExprId {
        let s = id.to_string();
        match s.as_str() {
            "t" => {
                if !a.t {
                    return self.not_allowed(id.span(), "t", a);
                }
                return self.sys.arena.var(Var::T);
            }
            "PI" => return self.sys.arena.num(std::f64::consts::PI),
            "E" => return self.sys.arena.num(std::f64::consts::E),
            "TAU" => return self.sys.arena.num(std::f64::consts::TAU),
            _ => {}
        }
        match self.scalars.get(&s).cloned() {
            Some(Scalar::Bound(e)) => e,
            Some(Scalar::Param(i)) => {
                if !a.params {
                    self.error(
                        id.span(),
                        format!(
                            "`{s}` is a parameter; {} must be a constant number",
                            if a.what.is_empty() { "this" } else { a.what }
                        ),
                    );
                    return self.sys.arena.zero();
                }
                self.sys.arena.var(Var::Param(i as u16))
            }
            Some(Scalar::Dof(i)) => {
                if !a.q {
                    return self.not_allowed(id.span(), "q", a);
                }
                self.sys.arena.var(Var::Q(i as u16))
            }
            Some(Scalar::Input(i)) => {
                if !a.u {
                    return self.not_allowed(id.span(), "u", a);
                }
                self.sys.arena.var(Var::Input(i as u16))
            }
            Some(Scalar::Let(body)) => {
                if let Some(&e) = self.let_done.get(&s) {
                    return self.check_allowed(e, id.span(), a);
                }
                if self.let_busy.contains(&s) {
                    self.error(id.span(), format!("`let {s}` refers to itself"));
                    return self.sys.arena.zero();
                }
                self.let_busy.push(s.clone());
                let e = self.lower(&body, ANY);
                self.let_busy.pop();
                self.let_done.insert(s, e);
                self.check_allowed(e, id.span(), a)
            }
            None => {
                if self.frame_names.contains_key(&s) {
                    self.error(
                        id.span(),
                        format!(
                            "`{s}` is a body, not a number: write TOG[{s}] in a transform product"
                        ),
                    );
                    return self.sys.arena.zero();
                }
                let names: Vec<String> = self
                    .scalars
                    .keys()
                    .cloned()
                    .chain(["t", "PI"].map(String::from))
                    .collect();
                self.error(
                    id.span(),
                    format!(
                        "unknown name `{s}`{}",
                        did_you_mean(
                            &s,
                            names.iter().map(String::as_str),
                            "declare it with `param NAME = value;` or `let NAME = expr;`"
                        )
                    ),
                );
                self.sys.arena.zero()
            }
        }
    }

    /// A `let` used where some variables are not allowed.
    fn check_allowed(&mut self, e: ExprId, span: Span, a: Allow) -> ExprId {
        for v in self.sys.arena.vars_of(&[e]) {
            let bad = match v {
                Var::Q(_) if !a.q => Some("q"),
                Var::Qd(_) if !a.qd => Some("qd"),
                Var::Qdd(_) if !a.qd => Some("qdd"),
                Var::T if !a.t => Some("t"),
                Var::Input(_) if !a.u => Some("u"),
                Var::Param(_) if !a.params => Some("a parameter"),
                _ => None,
            };
            if let Some(b) = bad {
                return self.not_allowed(span, b, a);
            }
        }
        e
    }

    fn lower_call(&mut self, c: &syn::ExprCall, a: Allow) -> ExprId {
        let Expr::Path(p) = &*c.func else {
            self.error(c.func.span(), "expected a function name");
            return self.sys.arena.zero();
        };
        let Some(id) = p.path.get_ident() else {
            self.error(
                p.span(),
                "call user functions by name: declare `extern fn NAME = [path, …];`",
            );
            return self.sys.arena.zero();
        };
        let name = id.to_string();
        let args: Vec<&Expr> = c.args.iter().collect();
        let arity = |ch: &mut Checker, n: usize| {
            if args.len() != n {
                ch.error(
                    c.span(),
                    format!(
                        "`{name}` takes {n} argument{}, found {}",
                        if n == 1 { "" } else { "s" },
                        args.len()
                    ),
                );
                false
            } else {
                true
            }
        };
        if let Some(f) = Func::from_name(&name) {
            if !arity(self, 1) {
                return self.sys.arena.zero();
            }
            let x = self.lower(args[0], a);
            return self.sys.arena.func(f, x);
        }
        match name.as_str() {
            "atan2" | "pow" => {
                if !arity(self, 2) {
                    return self.sys.arena.zero();
                }
                let x = self.lower(args[0], a);
                let y = self.lower(args[1], a);
                return if name == "atan2" {
                    self.sys.arena.atan2(x, y)
                } else {
                    self.sys.arena.pow(x, y)
                };
            }
            "powi" => {
                if !arity(self, 2) {
                    return self.sys.arena.zero();
                }
                let x = self.lower(args[0], a);
                let n = match args[1] {
                    Expr::Lit(syn::ExprLit {
                        lit: syn::Lit::Int(l),
                        ..
                    }) => l.base10_parse::<i32>().ok(),
                    Expr::Unary(u) if matches!(u.op, syn::UnOp::Neg(_)) => match &*u.expr {
                        Expr::Lit(syn::ExprLit {
                            lit: syn::Lit::Int(l),
                            ..
                        }) => l.base10_parse::<i32>().ok().map(|v| -v),
                        _ => None,
                    },
                    _ => None,
                };
                let Some(n) = n else {
                    self.error(args[1].span(), "the exponent of `powi` is an integer literal; use `pow(x, y)` for a real exponent");
                    return self.sys.arena.zero();
                };
                return self.sys.arena.powi(x, n);
            }
            "Tdisp" | "Trotx" | "Troty" | "Trotz" | "Trotn" => {
                self.error(id.span(), format!("`{name}` is a transform, not a number: transforms appear only in TOG[…] = … products"));
                return self.sys.arena.zero();
            }
            _ => {}
        }
        match self.fns.get(&name).cloned() {
            Some(FnSym::Inline { args: params, body }) => {
                if !arity(self, params.len()) {
                    return self.sys.arena.zero();
                }
                if self.depth > 64 {
                    self.error(
                        c.span(),
                        format!(
                            "`{name}` calls itself too deeply: inline functions cannot recurse"
                        ),
                    );
                    return self.sys.arena.zero();
                }
                let vals: Vec<ExprId> = args.iter().map(|e| self.lower(e, a)).collect();
                let saved: Vec<(String, Option<Scalar>)> = params
                    .iter()
                    .zip(&vals)
                    .map(|(p, &v)| {
                        (
                            p.to_string(),
                            self.scalars.insert(p.to_string(), Scalar::Bound(v)),
                        )
                    })
                    .collect();
                self.depth += 1;
                let r = self.lower(&body, a);
                self.depth -= 1;
                for (k, old) in saved {
                    match old {
                        Some(o) => self.scalars.insert(k, o),
                        None => self.scalars.remove(&k),
                    };
                }
                r
            }
            Some(FnSym::Extern { id: fid }) => {
                if !arity(self, 1) {
                    return self.sys.arena.zero();
                }
                let x = self.lower(args[0], a);
                self.sys.arena.call(fid, 0, x)
            }
            None => {
                let mut names: Vec<String> = self.fns.keys().cloned().collect();
                names.extend(Func::ALL.iter().map(|f| f.name().to_string()));
                names.extend(["atan2", "pow", "powi"].map(String::from));
                self.error(
                    id.span(),
                    format!(
                        "unknown function `{name}`{}",
                        did_you_mean(
                            &name,
                            names.iter().map(String::as_str),
                            "declare it with `fn NAME(x) = …;` or `extern fn NAME = [path, …];`"
                        )
                    ),
                );
                self.sys.arena.zero()
            }
        }
    }

    fn final_checks(&mut self) {
        for (i, f) in self.sys.frames.iter().enumerate() {
            if !self.tog_defined[i] {
                let kind = if f.inertia.is_some() { "body" } else { "frame" };
                self.errors.push(err(
                    self.frame_spans[i],
                    format!(
                        "{kind} `{}` has no position: add `TOG[{}] = …;`",
                        f.name, f.name
                    ),
                ));
            }
        }
        if !self.errors.is_empty() {
            return;
        }
        // every coordinate must move some mass, or M is singular
        let n = self.sys.dofs.len();
        let mut moves = vec![vec![false; n]; self.sys.frames.len()];
        for (i, f) in self.sys.frames.iter().enumerate() {
            if let Some(p) = f.parent {
                moves[i] = moves[p].clone();
            }
            for fac in &f.factors {
                let roots: Vec<ExprId> = match *fac {
                    Factor::Disp(d) => d.to_vec(),
                    Factor::Rot { angle, .. } => vec![angle],
                };
                for v in self.sys.arena.vars_of(&roots) {
                    if let Var::Q(k) = v {
                        moves[i][k as usize] = true;
                    }
                }
            }
        }
        for k in 0..n {
            let moved = self
                .sys
                .frames
                .iter()
                .enumerate()
                .any(|(i, f)| f.inertia.is_some() && moves[i][k]);
            if !moved {
                self.errors.push(err(self.dof_spans[k], format!("coordinate {} moves no body with mass, so the mass matrix would be singular: use it in the TOG of a body with mass (or of a frame that carries one), or remove it", self.sys.dofs[k].name)));
            }
        }
    }
}
