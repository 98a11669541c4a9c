//! [`ModelDef`] → [`System`]: resolves names, lowers expressions into the arena and checks
//! everything that can be checked before generation. All errors are collected, each on the
//! offending tokens, naming the construct and the fix.

use super::ast::{BodyRef, DofName, EffectStmt, Item, ModelDef};
use super::names::did_you_mean;
use crate::expr::{ExprId, Func, SliceEnv, UserFn, Var};
use crate::mech::system::*;
use proc_macro2::{Span, TokenStream};
use quote::ToTokens;
use rustc_hash::FxHashMap;
use syn::spanned::Spanned;
use syn::{Expr, Ident};

/// Names that the DSL reserves.
const RESERVED: [&str; 10] = [
    "t", "q", "qd", "qdd", "u", "PI", "E", "TAU", "ground", "TOG",
];

/// What a reserved name stands for.
fn reserved_meaning(s: &str) -> &'static str {
    match s {
        "t" => "the time",
        "q" => "the coordinates q[i]",
        "qd" => "the velocities qd[i]",
        "qdd" => "the accelerations qdd[i]",
        "u" => "the inputs u[k]",
        "PI" => "the constant π",
        "E" => "the constant e",
        "TAU" => "the constant τ = 2π",
        "ground" => "the fixed world frame",
        _ => "poses, TOG[body]",
    }
}

/// Source text of tokens, spaced as people write it: `q[0]`, `sin(x)`, `a + b`.
fn text(t: &impl ToTokens) -> String {
    let raw = t.to_token_stream().to_string();
    let mut out = String::with_capacity(raw.len());
    let chars: Vec<char> = raw.chars().collect();
    for (i, &c) in chars.iter().enumerate() {
        if c == ' ' {
            let prev = out.chars().last().unwrap_or(' ');
            let next = chars.get(i + 1).copied().unwrap_or(' ');
            let glue_next = matches!(next, ')' | ']' | ',' | '.')
                || (matches!(next, '(' | '[') && (prev.is_alphanumeric() || prev == '_'));
            // a unary minus: `-x`, `(-x)`, `[-1]`
            let before = out.chars().rev().nth(1);
            let unary = prev == '-' && matches!(before, None | Some('(' | '['));
            if glue_next || unary || matches!(prev, '(' | '[' | '.') {
                continue;
            }
        }
        out.push(c);
    }
    out
}

/// Tokens whose first and last spans are those of `a` and `b`: an error on them underlines
/// everything from `a` to `b`.
fn range(a: &impl ToTokens, b: &impl ToTokens) -> TokenStream {
    let mut t = a.to_token_stream();
    t.extend(b.to_token_stream());
    t
}

/// "1 coordinate", "2 coordinates"
fn count(n: usize, what: &str) -> String {
    if n == 1 {
        format!("1 {what}")
    } else {
        format!("{n} {what}s")
    }
}

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
    /// parameters whose default could not be computed (an error was reported): checks of
    /// values that depend on them are skipped rather than fail in cascade
    bad_params: Vec<bool>,
    /// "body", "frame" or "point" for each declared name of those kinds
    kinds: FxHashMap<String, &'static str>,
    /// a TOG[…] target could not be resolved (then "has no pose" would be a cascade)
    tog_target_error: bool,
    /// a body or frame was named `ground` (reported; then TOG[ground] is a cascade)
    ground_declared: bool,
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
        bad_params: Vec::new(),
        kinds: FxHashMap::default(),
        tog_target_error: false,
        ground_declared: false,
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

    /// An error underlining all of `tokens` (an expression, a call, …).
    /// Whether a call of `name` has the `expected` number of arguments; reports it if not.
    fn arity_ok(
        &mut self,
        call: &impl ToTokens,
        name: &(impl std::fmt::Display + ?Sized),
        found: usize,
        expected: usize,
        usage: &str,
    ) -> bool {
        if found != expected {
            self.error_at(
                call,
                format!(
                    "`{name}` takes {}, found {found}: write `{usage}`",
                    count(expected, "argument")
                ),
            );
        }
        found == expected
    }

    fn error_at(&mut self, tokens: &impl ToTokens, msg: impl std::fmt::Display) {
        self.errors
            .push(syn::Error::new_spanned(tokens, msg.to_string()));
    }

    /// `what`: the construct being named ("parameter", "body", …)
    fn reserved(&mut self, name: &Ident, what: &str) -> bool {
        let s = name.to_string();
        if RESERVED.contains(&s.as_str()) {
            self.error(
                name.span(),
                format!(
                    "`{s}` is reserved for {}: give this {what} another name",
                    reserved_meaning(&s)
                ),
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
                    if self.reserved(name, "parameter") || self.duplicate_scalar(name) {
                        continue;
                    }
                    let before = self.errors.len();
                    let e = self.lower(value, CONSTANT);
                    let mut bad = self.errors.len() > before;
                    let v = match self.sys.arena.as_num(e) {
                        Some(v) => v,
                        None => self.sys.arena.eval(&[e], &SliceEnv::default())[0],
                    };
                    let default = if bad {
                        0.0
                    } else if v.is_finite() {
                        v
                    } else {
                        self.error_at(
                            value,
                            format!(
                                "the default of parameter `{name}` is {v}: give it a finite value"
                            ),
                        );
                        bad = true;
                        0.0
                    };
                    self.bad_params.push(bad);
                    self.scalars
                        .insert(name.to_string(), Scalar::Param(self.sys.params.len()));
                    self.sys.params.push(ParamDef {
                        name: name.to_string(),
                        default,
                    });
                    self.defaults.push(default);
                }
                Item::Let { name, value } => {
                    let ok = !self.reserved(name, "`let`") && !self.duplicate_scalar(name);
                    if ok {
                        self.scalars
                            .insert(name.to_string(), Scalar::Let(value.clone()));
                    }
                }
                Item::Dof { name, span, .. } => {
                    let i = self.sys.dofs.len();
                    let display = match name {
                        DofName::Indexed(k, s) => {
                            if *k != i {
                                self.error(*s, format!("`dof q[{k}]` is out of order: coordinates are numbered in declaration order and this one is q[{i}]; write `dof q[{i}]` (or give it a name: `dof knee;`)"));
                            }
                            format!("q[{i}]")
                        }
                        DofName::Named(id) => {
                            if self.reserved(id, "coordinate") || self.duplicate_scalar(id) {
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
                    let ok = !self.reserved(name, "input") && !self.duplicate_scalar(name);
                    if ok {
                        self.scalars
                            .insert(name.to_string(), Scalar::Input(self.sys.inputs.len()));
                        self.sys.inputs.push(name.to_string());
                    }
                }
                Item::Body { name, .. } | Item::Frame { name } => {
                    let kind = if matches!(item, Item::Body { .. }) {
                        "body"
                    } else {
                        "frame"
                    };
                    self.ground_declared |= name == "ground";
                    if self.reserved(name, kind) || self.duplicate_frame_or_point(name) {
                        continue;
                    }
                    self.kinds.insert(name.to_string(), kind);
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
                    if self.reserved(name, "point") || self.duplicate_frame_or_point(name) {
                        continue;
                    }
                    self.kinds.insert(name.to_string(), "point");
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
                    for (k, a) in args.iter().enumerate() {
                        if args[..k].iter().any(|b| b == a) {
                            self.error(
                                a.span(),
                                format!(
                                    "`fn {name}` has two arguments named `{a}`: rename one of them"
                                ),
                            );
                        } else {
                            self.reserved(a, "argument");
                        }
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
                        self.error(name.span(), format!("duplicate effect `{name}`: each `effect` block needs its own name; rename one of them or merge their statements"));
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

    fn duplicate_frame_or_point(&mut self, name: &Ident) -> bool {
        match self.kinds.get(&name.to_string()) {
            Some(kind) => {
                self.error(name.span(), format!("duplicate name `{name}`: it already names a {kind}; each body, frame and point needs its own name"));
                true
            }
            None => false,
        }
    }

    fn duplicate_fn(&mut self, name: &Ident) -> bool {
        let s = name.to_string();
        if Func::from_name(&s).is_some() || matches!(s.as_str(), "atan2" | "powi" | "pow") {
            self.error(
                name.span(),
                format!("`{name}` is a built-in function: give yours another name"),
            );
            return true;
        }
        if self.fns.contains_key(&s) {
            self.error(
                name.span(),
                format!("duplicate function `{name}`: rename one of the two"),
            );
            return true;
        }
        false
    }

    /// Pass 2: lower every statement in order.
    fn lower_items(&mut self, def: &ModelDef) {
        // points first: effects may name points declared after them
        for item in &def.items {
            if let Item::Point { name, body, at } = item {
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
        }
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
                        self.error(name.span(), format!("duplicate scene `{name}`: each scene is a type (`{}{name}`) and needs its own name; rename one of them", def.name));
                        continue;
                    }
                    let mut list = Vec::new();
                    for e in effects {
                        match self.effects.get(&e.to_string()) {
                            Some(&i) => {
                                if list.contains(&i) {
                                    self.error(
                                        e.span(),
                                        format!("effect `{e}` is listed twice in scene `{name}`: remove one"),
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
                                            &format!("declare it with `effect {e} {{ … }}`")
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
                    if let Some(mv) = self.eval_default(m) {
                        if mv <= 0.0 || !mv.is_finite() {
                            let how = self.with_defaults(m);
                            self.error_at(value, format!("the mass of body `{name}` must be positive, it is {mv}{how}: give it a positive mass, or declare a massless `frame {name};`"));
                        }
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
                        let found = if matches!(value, Expr::Tuple(_)) { format!("{} values", elems.len()) } else { format!("`{}`", text(value)) };
                        self.error_at(value, format!("the inertia of body `{name}` is `(Ixx, Iyy, Izz)` or `(Ixx, Iyy, Izz, Ixy, Ixz, Iyz)`, about G in body axes; found {found}"));
                        continue;
                    }
                    let mut t = [self.sys.arena.zero(); 6];
                    for (i, e) in elems.iter().enumerate() {
                        t[i] = self.lower(e, a);
                    }
                    let vals: Option<Vec<f64>> = t.iter().map(|&e| self.eval_default(e)).collect();
                    if let Some(v) = vals {
                        if let Some(msg) = super::inertia::inertia_problem([v[0], v[1], v[2], v[3], v[4], v[5]]) {
                            let how = self.with_defaults_all(&t);
                            let fix = if msg.contains("triangle") {
                                "; each principal moment must be at most the sum of the other two (a thin plate in the xy plane has Izz = Ixx + Iyy)"
                            } else {
                                ""
                            };
                            self.error_at(value, format!("the inertia of body `{name}` is impossible{how}: {msg}{fix}"));
                        }
                    }
                    tensor = Some(t);
                }
                other => self.error(key.span(), format!("unknown property `{other}` of body `{name}`: a body has `mass = …;` and `inertia = (Ixx, Iyy, Izz[, Ixy, Ixz, Iyz]);`")),
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

    /// The value of a parameter expression with the default parameters; `None` when it
    /// depends on a parameter whose default is in error (already reported).
    fn eval_default(&self, e: ExprId) -> Option<f64> {
        let bad = self.sys.arena.vars_of(&[e]).into_iter().any(|v| {
            matches!(v, Var::Param(i) if self.bad_params.get(i as usize).copied().unwrap_or(false))
        });
        if bad {
            return None;
        }
        let env = SliceEnv {
            params: &self.defaults,
            ..SliceEnv::default()
        };
        Some(self.sys.arena.eval(&[e], &env)[0])
    }

    /// " with the default parameters" when `e` depends on parameters.
    fn with_defaults(&self, e: ExprId) -> &'static str {
        self.with_defaults_all(&[e])
    }

    fn with_defaults_all(&self, e: &[ExprId]) -> &'static str {
        if e.iter().all(|&x| self.sys.arena.is_const(x)) {
            ""
        } else {
            " with the default parameters"
        }
    }

    /// A body/frame reference: `Some(None)` is the ground, `None` an error already reported.
    fn body_ref(&mut self, r: &BodyRef) -> Option<Option<usize>> {
        match r {
            BodyRef::Name(id) if id == "ground" => Some(None),
            BodyRef::Name(id) => match self.frame_names.get(&id.to_string()) {
                Some(&i) => Some(Some(i)),
                None if self.points.contains_key(&id.to_string()) => {
                    self.error(
                        id.span(),
                        format!("`{id}` is a point, not a body or frame: name the body it is on, or the ground"),
                    );
                    None
                }
                None => {
                    let names: Vec<String> = self.frame_names.keys().cloned().collect();
                    self.error(
                        id.span(),
                        format!(
                            "unknown body `{id}`{}",
                            did_you_mean(
                                &id.to_string(),
                                names.iter().map(String::as_str),
                                &format!("declare it with `body {id} {{ … }}` or `frame {id};`")
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
                    let n = self.sys.frames.len();
                    let listed: Vec<String> = self
                        .sys
                        .frames
                        .iter()
                        .enumerate()
                        .take(8)
                        .map(|(k, f)| format!("{k} is `{}`", f.name))
                        .collect();
                    let more = if n > 8 { ", …" } else { "" };
                    let numbering = if n == 0 {
                        "the model declares no body or frame".to_string()
                    } else {
                        format!(
                            "bodies and frames are numbered from 0 in declaration order ({}{more})",
                            listed.join(", ")
                        )
                    };
                    self.error(
                        *s,
                        format!(
                            "TOG[{i}] is out of range: {numbering}; or write the name, TOG[name]"
                        ),
                    );
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
                self.error_at(
                    e,
                    format!(
                        "expected the name of a body, a frame or `ground`, found `{}`",
                        text(e)
                    ),
                );
                None
            }
        }
    }

    fn lower_tog(&mut self, target: &BodyRef, chain: &Expr, span: Span) {
        let Some(t) = self.body_ref(target) else {
            self.tog_target_error = true;
            return;
        };
        let Some(fi) = t else {
            if !self.ground_declared {
                self.error(
                    target.span(),
                    "the ground is fixed: TOG[ground] cannot be assigned; for a fixed frame elsewhere, declare `frame base;` and `TOG[base] = Tdisp(x, y, z);`",
                );
            }
            return;
        };
        if self.tog_defined[fi] {
            self.error(
                span,
                format!(
                    "TOG[{}] is defined twice: each body and frame has one pose; remove one of the two",
                    self.sys.frames[fi].name
                ),
            );
            return;
        }
        let mut leaves = Vec::new();
        if !self.flatten_product(chain, &mut leaves) {
            // counts as defined: its children and the final checks should not fail in cascade
            self.tog_defined[fi] = true;
            return;
        }
        let what: &'static str = "a transform (TOG)";
        let mut parent = None;
        let mut factors = Vec::new();
        for (k, leaf) in leaves.iter().enumerate() {
            if let Expr::Index(ix) = leaf {
                if matches!(&*ix.expr, Expr::Path(p) if p.path.is_ident("TOG")) {
                    if k != 0 {
                        self.error_at(
                            leaf,
                            format!(
                                "`{}` may only start a product: write `{} * Tdisp(…) * …`",
                                text(leaf),
                                text(leaf)
                            ),
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
                            self.error_at(other, "expected a body name or number in TOG[…]");
                            continue;
                        }
                    };
                    match self.body_ref(&r) {
                        Some(Some(p)) if p == fi => self.error(r.span(), format!("TOG[{}] cannot refer to itself: start from its parent's pose, `TOG[parent] * …`, or from the ground", self.sys.frames[fi].name)),
                        Some(Some(p)) if !self.tog_defined[p] => self.error(r.span(), format!("TOG[{}] is used before it is defined: move `TOG[{}] = …;` above this line (a pose may refer only to poses defined earlier)", self.sys.frames[p].name, self.sys.frames[p].name)),
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
                self.error(b.op.span(), format!("transforms combine by products only, not `{}`: write `TOG[parent] * Trotz(q[0]) * Tdisp(x, y, z)`", text(&b.op)));
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
        const TRANSFORMS: &str =
            "Tdisp(x, y, z), Trotx(a), Troty(a), Trotz(a) and Trotn(nx, ny, nz, a)";
        let not_a_transform = |c: &mut Checker, found: &str| {
            c.error_at(
                e,
                format!("expected a transform, found {found}: a pose (TOG) is a product of {TRANSFORMS}, possibly starting with TOG[parent]"),
            );
        };
        let name = match e {
            Expr::Call(call) => match &*call.func {
                Expr::Path(p) => p.path.get_ident(),
                _ => None,
            },
            _ => None,
        };
        let (Expr::Call(call), Some(name)) = (e, name) else {
            let found = match e {
                Expr::Lit(_) => format!("the number `{}`", text(e)),
                Expr::Path(_) => format!("`{}`", text(e)),
                _ => format!("the expression `{}`", text(e)),
            };
            not_a_transform(self, &found);
            return None;
        };
        let args: Vec<&Expr> = call.args.iter().collect();
        let a = Allow { what, ..POSITION };
        let arity =
            |c: &mut Checker, n: usize, usage: &str| c.arity_ok(call, name, args.len(), n, usage);
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
                if !arity(self, 3, "Tdisp(x, y, z)") {
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
            "Trotx" => arity(self, 1, "Trotx(angle)")
                .then(|| rot(self, [o, z, z]))
                .flatten(),
            "Troty" => arity(self, 1, "Troty(angle)")
                .then(|| rot(self, [z, o, z]))
                .flatten(),
            "Trotz" => arity(self, 1, "Trotz(angle)")
                .then(|| rot(self, [z, z, o]))
                .flatten(),
            "Trotn" => {
                if !arity(self, 4, "Trotn(nx, ny, nz, angle)") {
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
                let axis_tokens = range(args[0], args[2]);
                if !self.unit_axis(&n, &axis_tokens, "Trotn", "Trotn(nx, ny, nz, angle)") {
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
                        did_you_mean(
                            other,
                            known.into_iter(),
                            &format!("the transforms are {TRANSFORMS}")
                        )
                    ),
                );
                None
            }
        }
    }

    /// Checks that an axis (parameters only) is a unit vector with the default parameters;
    /// `usage` shows where it goes, with `nx, ny, nz` in it.
    /// `axis = x | y | z | (nx, ny, nz)` of an effect: a unit vector (`axes` says in which axes).
    fn axis_arg(
        &mut self,
        axis: &Expr,
        of: &'static str,
        usage: &str,
        axes: &str,
    ) -> Option<[ExprId; 3]> {
        let z = self.sys.arena.zero();
        let o = self.sys.arena.one();
        match axis {
            Expr::Path(p) if p.path.is_ident("x") => Some([o, z, z]),
            Expr::Path(p) if p.path.is_ident("y") => Some([z, o, z]),
            Expr::Path(p) if p.path.is_ident("z") => Some([z, z, o]),
            Expr::Tuple(_) => {
                let what = Allow {
                    what: "an axis",
                    ..PARAMS_ONLY
                };
                self.triple(axis, what, "an axis").filter(|n| {
                    self.unit_axis(n, &axis.to_token_stream(), &format!("the {of}"), usage)
                })
            }
            _ => {
                self.error_at(axis, format!("unknown {of} axis `{}`: write `axis = x`, `y`, `z` or a unit vector `(nx, ny, nz)`, {axes}", text(axis)));
                None
            }
        }
    }

    fn unit_axis(&mut self, n: &[ExprId; 3], at: &TokenStream, of: &str, usage: &str) -> bool {
        let (Some(x), Some(y), Some(z)) = (
            self.eval_default(n[0]),
            self.eval_default(n[1]),
            self.eval_default(n[2]),
        ) else {
            return true;
        };
        let how = self.with_defaults_all(n);
        let n2 = x * x + y * y + z * z;
        if n2 == 0.0 {
            self.error_at(
                at,
                format!(
                    "the axis of {of} is zero{how}: give a unit vector, e.g. `{}`",
                    usage.replace("nx, ny, nz", "0, 0, 1")
                ),
            );
            return false;
        }
        if (n2.sqrt() - 1.0).abs() > 1e-9 {
            let norm = n2.sqrt();
            let integers = [x, y, z].iter().all(|v| v.fract() == 0.0);
            let example = if integers && how.is_empty() {
                let c = |v: f64| {
                    if v == 0.0 {
                        "0".to_string()
                    } else if norm.fract() == 0.0 {
                        format!("{}", v / norm)
                    } else {
                        format!("{v} / sqrt({n2})")
                    }
                };
                format!(
                    ": `{}`",
                    usage.replace("nx, ny, nz", &format!("{}, {}, {}", c(x), c(y), c(z)))
                )
            } else {
                String::new()
            };
            self.error_at(
                at,
                format!("the axis of {of} must be a unit vector, but ({x}, {y}, {z}) has norm {norm}{how}: divide it by its norm{example}"),
            );
            return false;
        }
        true
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
                self.error_at(
                    e,
                    format!("{what} is a vector `(x, y, z)`, found `{}`", text(e)),
                );
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
                            &format!("declare it with `point {s} on BODY at (x, y, z);`")
                        )
                    ),
                );
                return None;
            }
        }
        self.error_at(
            e,
            format!(
                "expected the name of a point, a body or `ground`, found `{}`",
                text(e)
            ),
        );
        None
    }

    fn lower_effect(&mut self, s: &EffectStmt) -> Vec<Load> {
        let kind = s.kind.to_string();
        let named = |key: &str| s.named.iter().find(|(k, _)| k == key).map(|(_, v)| v);
        let known_named: &[&str] = match kind.as_str() {
            "spring" => &["k", "l0", "c", "axis"],
            "damper" => &["c", "axis"],
            "force" => &["frame"],
            "torque" => &["frame", "relative_to", "axis"],
            _ => &[],
        };
        for (i, (k, _)) in s.named.iter().enumerate() {
            if s.named[..i].iter().any(|(j, _)| j == k) {
                self.error(
                    k.span(),
                    format!("argument `{k}` is given twice: remove one"),
                );
            } else if !known_named.contains(&k.to_string().as_str()) {
                let list = match known_named {
                    [] => format!("`{kind}` takes no named argument"),
                    [one] => format!("its only named argument is `{one}`"),
                    [init @ .., last] => format!(
                        "its named arguments are {} and `{last}`",
                        init.iter()
                            .map(|a| format!("`{a}`"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                };
                self.error(k.span(), format!("`{kind}` has no argument `{k}`; {list}"));
            }
        }
        let npos = |c: &mut Checker, n: usize, usage: &str| {
            if s.positional.len() != n {
                c.error(
                    s.kind.span(),
                    format!(
                        "`{kind}` takes {}, found {}: write `{usage}`",
                        count(n, "positional argument"),
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
                if a.frame == b.frame && a.pos == b.pos {
                    self.error_at(
                        &range(&s.positional[0], &s.positional[1]),
                        format!(
                            "this {kind} joins `{}` to itself, so it has no length or direction: attach its ends to two different points",
                            text(&s.positional[0])
                        ),
                    );
                    return out;
                }
                // along a fixed direction of the world (linear), or along the line of its ends
                let axis = match named("axis") {
                    Some(e) => match self.axis_arg(
                        e,
                        kind_static(&kind),
                        &format!("{kind}(a, b, …, axis = (nx, ny, nz))"),
                        "in world axes",
                    ) {
                        Some(n) => Some(n),
                        None => return out,
                    },
                    None => None,
                };
                if kind == "spring" {
                    let Some(k) = named("k") else {
                        self.error(
                            s.kind.span(),
                            "a spring needs its stiffness: add `k = …`, as in `spring(a, b, k = …, l0 = …)`",
                        );
                        return out;
                    };
                    let k_expr = k;
                    let k = self.lower(
                        k,
                        Allow {
                            what: "a spring stiffness",
                            ..pa
                        },
                    );
                    self.not_negative(k, k_expr, "the stiffness `k` of a spring");
                    let l0 = match named("l0") {
                        Some(e) => {
                            let l0 = self.lower(
                                e,
                                Allow {
                                    what: "a rest length",
                                    ..pa
                                },
                            );
                            self.not_negative(l0, e, "the rest length `l0` of a spring");
                            l0
                        }
                        None => self.sys.arena.zero(),
                    };
                    out.push(Load::Spring { a, b, k, l0, axis });
                }
                let c_expr = named("c");
                if kind == "damper" && c_expr.is_none() {
                    self.error(
                        s.kind.span(),
                        "a damper needs its coefficient: add `c = …`, as in `damper(a, b, c = …)`",
                    );
                }
                if let Some(e) = c_expr {
                    let c = self.lower(
                        e,
                        Allow {
                            what: "a damping coefficient",
                            ..pa
                        },
                    );
                    self.not_negative(c, e, &format!("the damping coefficient `c` of a {kind}"));
                    out.push(Load::Damper { a, b, c, axis });
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
                    if let Some((k, _)) = s.named.iter().find(|(k, _)| k == "frame") {
                        self.error(k.span(), "`frame` does not go with `axis`: the axis is in the axes of the body the torque acts on; remove `frame = …`");
                    }
                    let dir = self.axis_arg(
                        axis,
                        "torque",
                        "torque(body, axis = (nx, ny, nz), value)",
                        "in the axes of the body",
                    );
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
                        let msg = match reaction {
                            Some(Some(r)) => format!(
                                "a torque on the ground does nothing, the ground does not move: put it on `{}` with the opposite sign",
                                self.sys.frames[r].name
                            ),
                            _ => "a torque on the ground does nothing, the ground does not move: apply it to a body".to_string(),
                        };
                        self.error(s.positional[0].span(), msg);
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

    /// Reports `value` (on `at`) if it is negative with the default parameters.
    fn not_negative(&mut self, value: ExprId, at: &Expr, what: &str) {
        if let Some(v) = self.eval_default(value) {
            if v < 0.0 {
                let how = self.with_defaults(value);
                self.error_at(
                    at,
                    format!("{what} must not be negative, it is {v}{how}: give a value ≥ 0"),
                );
            }
        }
    }

    /// `q[2]` or a coordinate name.
    fn dof_ref(&mut self, e: &Expr) -> Option<usize> {
        match e {
            Expr::Index(ix) if matches!(&*ix.expr, Expr::Path(p) if p.path.is_ident("q")) => {
                self.index_of(&ix.index, "q", e)
            }
            Expr::Path(p) if p.path.get_ident().is_some() => {
                let id = p.path.get_ident().unwrap();
                match self.scalars.get(&id.to_string()) {
                    Some(Scalar::Dof(i)) => Some(*i),
                    other => {
                        let is = self.describe(id, other);
                        self.error(
                            id.span(),
                            format!("{is}, not a coordinate: write `q[i]` or a coordinate's name"),
                        );
                        None
                    }
                }
            }
            _ => {
                self.error_at(
                    e,
                    format!(
                        "expected a coordinate, found `{}`: write `q[i]` or a coordinate's name",
                        text(e)
                    ),
                );
                None
            }
        }
    }

    /// "`k` is a parameter", "`foo` is unknown", … for messages.
    fn describe(&self, id: &Ident, s: Option<&Scalar>) -> String {
        let what = match s {
            Some(Scalar::Param(_)) => "is a parameter",
            Some(Scalar::Let(_)) => "is a `let`",
            Some(Scalar::Dof(_)) => "is a coordinate",
            Some(Scalar::Input(_)) => "is an input",
            Some(Scalar::Bound(_)) => "is a function argument",
            None if self.kinds.contains_key(&id.to_string()) => {
                return format!("`{id}` is a {}", self.kinds[&id.to_string()]);
            }
            None => "is not declared",
        };
        format!("`{id}` {what}")
    }

    /// The index in `v[idx]`: a number in range or a name of the right kind. `whole` is the
    /// indexing expression, for messages.
    fn index_of(&mut self, idx: &Expr, v: &str, whole: &Expr) -> Option<usize> {
        let (n, kind) = if v == "u" {
            (self.sys.inputs.len(), "input")
        } else {
            (self.sys.dofs.len(), "coordinate")
        };
        match idx {
            Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Int(l),
                ..
            }) => {
                let i = l.base10_parse::<usize>().unwrap_or(usize::MAX);
                if i >= n {
                    let has = match n {
                        0 => format!("the model has no {kind}"),
                        1 => format!("the model has 1 {kind}, {v}[0]"),
                        _ => format!("the model has {}, {v}[0] to {v}[{}]", count(n, kind), n - 1),
                    };
                    let fix = if v == "u" {
                        "declare inputs with `input NAME;`".to_string()
                    } else {
                        format!("declare coordinates with `dof q[{n}] = 0.0;`")
                    };
                    self.error_at(
                        whole,
                        format!("`{v}[{}]` is out of range: {has}; {fix}", l.base10_digits()),
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
                    (other, _) => {
                        let is = self.describe(id, other);
                        self.error(
                            id.span(),
                            format!(
                                "{is}, not {}: index `{v}[…]` with a number or the name of {}",
                                if kind == "input" {
                                    "an input"
                                } else {
                                    "a coordinate"
                                },
                                if kind == "input" {
                                    "an input"
                                } else {
                                    "a coordinate"
                                }
                            ),
                        );
                        None
                    }
                }
            }
            other => {
                self.error_at(
                    other,
                    format!(
                        "the index of `{v}[…]` is a number or a name, found `{}`",
                        text(other)
                    ),
                );
                None
            }
        }
    }

    /// `thing` (as written: "velocity `qd[0]`") may not appear where `a` says.
    fn not_allowed(&mut self, at: &impl ToTokens, thing: &str, kind: &str, a: Allow) -> ExprId {
        let what = if a.what.is_empty() {
            "this expression"
        } else {
            a.what
        };
        let hint = match kind {
            "qd" | "qdd" => {
                if a.q {
                    "a pose depends only on q, t and parameters; velocities and accelerations belong in the values of forces, torques and generalized forces".to_string()
                } else {
                    "velocities and accelerations belong in the values of forces, torques and generalized forces".to_string()
                }
            }
            "u" => "inputs belong in the values of forces, torques and generalized forces".to_string(),
            _ if !a.params => "a parameter default is a number; to derive a quantity from parameters, use `let NAME = …;`".to_string(),
            _ => format!("{what} is constant during the motion, so it may use numbers and parameters only"),
        };
        self.error_at(at, format!("{thing} cannot appear in {what}: {hint}"));
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
                    self.error_at(other, format!("expected a number, found `{}`", text(other)));
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
                    self.error(u.op.span(), format!("`{}` is not an operator of multibody! expressions: the only unary operator is `-`", text(&u.op)));
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
                            self.error_at(&b.right, "division by zero: the divisor is zero");
                            return self.sys.arena.zero();
                        }
                        ar.div(x, y)
                    }
                    syn::BinOp::BitXor(_) => {
                        // `^` binds more loosely than `* /`: `l^2 / 12` is `l ^ (2 / 12)`; the
                        // power meant is between the operands next to the `^`
                        let mut base = &*b.left;
                        while let Expr::Binary(l) = base {
                            base = &l.right;
                        }
                        let mut exp = &*b.right;
                        while let Expr::Binary(r) = exp {
                            exp = &r.left;
                        }
                        let int = matches!(
                            exp,
                            Expr::Lit(syn::ExprLit {
                                lit: syn::Lit::Int(_),
                                ..
                            })
                        );
                        let (x, y) = (text(base), text(exp));
                        let fix = if int {
                            format!("powi({x}, {y})")
                        } else {
                            format!("pow({x}, {y})")
                        };
                        self.error_at(
                            &range(base, exp),
                            format!(
                                "`^` is not a power (in Rust it is the bitwise xor): write `{fix}`"
                            ),
                        );
                        self.sys.arena.zero()
                    }
                    op => {
                        self.error(
                            b.op.span(),
                            format!("`{}` is not an operator of multibody! expressions: they use `+ - * /`, parentheses and functions", text(&op)),
                        );
                        self.sys.arena.zero()
                    }
                }
            }
            Expr::Path(p) => {
                let Some(id) = p.path.get_ident() else {
                    self.error_at(
                        p,
                        format!("expected a name, found the path `{}`: paths are allowed only in `extern fn NAME = [path, …];`", text(p)),
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
                        self.error_at(
                            ix,
                            format!("`{}` is a pose, not a number: it can only start the product of a `TOG[…] = …;`", text(ix)),
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
                if !allowed {
                    let thing = match v.as_str() {
                        "q" => "coordinate",
                        "qd" => "velocity",
                        "qdd" => "acceleration",
                        _ => "input",
                    };
                    return self.not_allowed(ix, &format!("{thing} `{}`", text(ix)), &v, a);
                }
                let Some(i) = self.index_of(&ix.index, &v, e) else {
                    return self.sys.arena.zero();
                };
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
                self.error_at(other, format!("`{}` is not a multibody! expression: use numbers, names, q[i], qd[i], u[i], t, + - * /, parentheses and functions", text(other)));
                self.sys.arena.zero()
            }
        }
    }

    fn lower_name(&mut self, id: &Ident, a: Allow) -> ExprId {
        let s = id.to_string();
        match s.as_str() {
            "t" => {
                if !a.t {
                    return self.not_allowed(id, "the time `t`", "t", a);
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
                    return self.not_allowed(id, &format!("parameter `{s}`"), "param", a);
                }
                self.sys.arena.var(Var::Param(i as u16))
            }
            Some(Scalar::Dof(i)) => {
                if !a.q {
                    return self.not_allowed(id, &format!("coordinate `{s}`"), "q", a);
                }
                self.sys.arena.var(Var::Q(i as u16))
            }
            Some(Scalar::Input(i)) => {
                if !a.u {
                    return self.not_allowed(id, &format!("input `{s}`"), "u", a);
                }
                self.sys.arena.var(Var::Input(i as u16))
            }
            Some(Scalar::Let(body)) => {
                if let Some(&e) = self.let_done.get(&s) {
                    return self.check_allowed(e, id, a);
                }
                if self.let_busy.contains(&s) {
                    let via =
                        &self.let_busy[self.let_busy.iter().position(|b| *b == s).unwrap_or(0)..];
                    let cycle = if via.len() > 1 {
                        format!(
                            " (through {})",
                            via[1..]
                                .iter()
                                .map(|b| format!("`{b}`"))
                                .collect::<Vec<_>>()
                                .join(", ")
                        )
                    } else {
                        String::new()
                    };
                    self.error(id.span(), format!("`let {s}` refers to itself{cycle}: a `let` cannot be defined in terms of itself"));
                    return self.sys.arena.zero();
                }
                self.let_busy.push(s.clone());
                let e = self.lower(&body, ANY);
                self.let_busy.pop();
                self.let_done.insert(s, e);
                self.check_allowed(e, id, a)
            }
            None => {
                if let Some(kind) = self.kinds.get(&s) {
                    let fix = if *kind == "point" {
                        "points appear in effects such as `spring(…)` and `force(…)`".to_string()
                    } else {
                        format!("its pose TOG[{s}] may start a transform product")
                    };
                    self.error(id.span(), format!("`{s}` is a {kind}, not a number: {fix}"));
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
                            &format!("declare it with `param {s} = …;` or `let {s} = …;`")
                        )
                    ),
                );
                self.sys.arena.zero()
            }
        }
    }

    /// A `let` used where some variables are not allowed.
    fn check_allowed(&mut self, e: ExprId, id: &Ident, a: Allow) -> ExprId {
        for v in self.sys.arena.vars_of(&[e]) {
            let bad = match v {
                Var::Q(_) if !a.q => Some(("q", "the coordinates")),
                Var::Qd(_) if !a.qd => Some(("qd", "the velocities")),
                Var::Qdd(_) if !a.qd => Some(("qdd", "the accelerations")),
                Var::T if !a.t => Some(("t", "the time")),
                Var::Input(_) if !a.u => Some(("u", "the inputs")),
                Var::Param(_) if !a.params => Some(("param", "parameters")),
                _ => None,
            };
            if let Some((kind, on)) = bad {
                return self.not_allowed(
                    id,
                    &format!("`{id}` (a `let` that depends on {on})"),
                    kind,
                    a,
                );
            }
        }
        e
    }

    fn lower_call(&mut self, c: &syn::ExprCall, a: Allow) -> ExprId {
        let Expr::Path(p) = &*c.func else {
            self.error_at(
                &c.func,
                format!("expected a function name, found `{}`", text(&c.func)),
            );
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
        let arity =
            |ch: &mut Checker, n: usize, usage: &str| ch.arity_ok(c, &name, args.len(), n, usage);
        if let Some(f) = Func::from_name(&name) {
            if !arity(self, 1, &format!("{name}(x)")) {
                return self.sys.arena.zero();
            }
            let x = self.lower(args[0], a);
            return self.sys.arena.func(f, x);
        }
        match name.as_str() {
            "atan2" | "pow" => {
                let usage = if name == "atan2" {
                    "atan2(y, x)"
                } else {
                    "pow(x, y)"
                };
                if !arity(self, 2, usage) {
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
                if !arity(self, 2, "powi(x, n)") {
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
                    self.error_at(args[1], format!("the exponent of `powi` is an integer literal, found `{}`: use `pow(x, y)` for a real exponent", text(args[1])));
                    return self.sys.arena.zero();
                };
                return self.sys.arena.powi(x, n);
            }
            "Tdisp" | "Trotx" | "Troty" | "Trotz" | "Trotn" => {
                self.error(id.span(), format!("`{name}` is a transform, not a number: transforms appear only in the products of `TOG[…] = …;`"));
                return self.sys.arena.zero();
            }
            _ => {}
        }
        match self.fns.get(&name).cloned() {
            Some(FnSym::Inline { args: params, body }) => {
                let usage = format!(
                    "{name}({})",
                    params
                        .iter()
                        .map(|p| p.to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                );
                if !arity(self, params.len(), &usage) {
                    return self.sys.arena.zero();
                }
                if self.depth > 64 {
                    self.error_at(
                        c,
                        format!(
                            "`{name}` calls itself without end: an inline `fn` cannot be recursive"
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
                if !arity(self, 1, &format!("{name}(x)")) {
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
                            &format!("declare it with `fn {name}(x) = …;` or `extern fn {name} = [path::to::{name}, …];`")
                        )
                    ),
                );
                self.sys.arena.zero()
            }
        }
    }

    fn final_checks(&mut self) {
        for (i, f) in self.sys.frames.iter().enumerate() {
            if !self.tog_defined[i] && !self.tog_target_error {
                let kind = if f.inertia.is_some() { "body" } else { "frame" };
                self.errors.push(err(
                    self.frame_spans[i],
                    format!(
                        "{kind} `{}` has no pose: add `TOG[{}] = …;`",
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
        let frames = &self.sys.frames;
        let unmoved: Vec<usize> = (0..n)
            .filter(|&k| {
                !frames
                    .iter()
                    .zip(&moves)
                    .any(|(f, m)| f.inertia.is_some() && m[k])
            })
            .collect();
        for k in unmoved {
            self.errors.push(err(self.dof_spans[k], format!("coordinate `{}` moves no body with mass, so the mass matrix would be singular: use it in the TOG of a body with mass (or of a frame that carries one), or remove it", self.sys.dofs[k].name)));
        }
    }
}

/// The name of an effect kind that takes an axis, as a static string for messages.
fn kind_static(kind: &str) -> &'static str {
    match kind {
        "spring" => "spring",
        "damper" => "damper",
        _ => "effect",
    }
}
