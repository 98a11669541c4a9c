//! [`ModelDef`] → [`System`]: resolves names, lowers expressions into the arena and checks
//! everything that can be checked before generation. All errors are collected, each on the
//! offending tokens, naming the construct and the fix.

use super::ast::{BodyRef, DofName, EffectStmt, Item, ModelDef};
use super::names::did_you_mean;
use super::repeat::{self, Origin};
use crate::expr::{ExprId, Func, SliceEnv, SplineError, SplineTable, UserFn, Var};
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
pub(crate) fn text(t: &impl ToTokens) -> String {
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
    Let(Box<Expr>),
    Dof(usize),
    Input(usize),
    /// inline-function argument, bound to an expression (only in [`Checker::args`], the
    /// innermost call's: never in `scalars`)
    Bound(ExprId),
}

#[derive(Clone)]
enum FnSym {
    Inline { args: Vec<Ident>, body: Box<Expr> },
    Extern { id: u16 },
}

struct Checker {
    sys: System,
    errors: Vec<syn::Error>,
    scalars: FxHashMap<String, Scalar>,
    /// each parameter's field in the parameter struct, and the parameter's name
    param_fields: FxHashMap<String, String>,
    /// the arguments of the inline `fn` whose body is being lowered: its own only (names are
    /// lexical: a `let` or another `fn` it uses sees the model's names, not these)
    args: Vec<(String, ExprId)>,
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
    /// the inline functions being expanded, outermost first: a function met again among
    /// them calls itself
    calling: Vec<String>,
    /// reserved names a declaration tried to take (reported there; their uses would only
    /// repeat it as "unknown name")
    taken_reserved: rustc_hash::FxHashSet<String>,
    /// the frame each TOG statement's product starts from (`TOG[b] = TOG[a] * …`: b → a),
    /// to name a cycle of poses
    tog_start: FxHashMap<usize, usize>,
    /// frames declared by `mass NAME on BODY at (…) = m;`
    lumped: rustc_hash::FxHashSet<usize>,
    /// the loop iteration or part instance of the statement being checked, appended to its
    /// errors; and those of each frame's and coordinate's declaration
    origin: Origin,
    frame_origins: Vec<Origin>,
    dof_origins: Vec<Origin>,
    /// the angle coordinates of every `Tball`/`Tfree`, found before lowering (a pass over
    /// the TOG products), with the joint as written: they may appear nowhere else
    joint_angles: FxHashMap<usize, String>,
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
        param_fields: FxHashMap::default(),
        args: Vec::new(),
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
        calling: Vec::new(),
        taken_reserved: Default::default(),
        tog_start: FxHashMap::default(),
        lumped: Default::default(),
        origin: None,
        frame_origins: Vec::new(),
        dof_origins: Vec::new(),
        joint_angles: FxHashMap::default(),
    };
    c.sys.docs = def.docs.clone();
    c.declare(def);
    c.lower_items(def);
    c.final_checks();
    c.show_names();
    let mut errs = repeat::dedupe(c.errors).into_iter();
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
    syn::Error::new(span, repeat::display(&msg.to_string()))
}

impl Checker {
    fn error(&mut self, span: Span, msg: impl std::fmt::Display) {
        let msg = repeat::with_origin(&msg.to_string(), &self.origin);
        self.errors.push(err(span, msg));
    }

    /// Indexed names as written (`bar[3]`) in what the model reports, once every name has
    /// been resolved; parameters keep their Rust field names (`k_3`).
    fn show_names(&mut self) {
        let s = &mut self.sys;
        for f in &mut s.frames {
            f.name = repeat::display(&f.name);
        }
        for d in &mut s.dofs {
            d.name = repeat::display(&d.name);
        }
        for p in &mut s.points {
            p.name = repeat::display(&p.name);
        }
        for c in &mut s.constraints {
            c.name = repeat::display(&c.name);
        }
        for e in &mut s.effects {
            e.name = e.name.as_deref().map(repeat::display);
        }
        for i in &mut s.inputs {
            *i = repeat::display(i);
        }
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
        let msg = repeat::with_origin(&msg.to_string(), &self.origin);
        self.errors.push(syn::Error::new_spanned(tokens, msg));
    }

    /// `what`: the construct being named ("parameter", "body", …)
    fn reserved(&mut self, name: &Ident, what: &str) -> bool {
        let s = name.to_string();
        if RESERVED.contains(&s.as_str()) {
            self.taken_reserved.insert(s.clone());
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
        for (item, origin) in def.items.iter().zip(&def.origins) {
            self.origin = origin.clone();
            match item {
                Item::Param {
                    name,
                    value,
                    sensitive,
                } => {
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
                    // an indexed parameter `k[3]` is the field `k_3`
                    let field = repeat::rust_ident(&name.to_string());
                    if let Some(other) = self.param_fields.get(&field) {
                        self.error(name.span(), format!("parameters `{other}` and `{name}` are both the field `{field}` of the parameter struct (an indexed parameter `k[3]` is the field `k_3`): rename one of them"));
                        continue;
                    }
                    if self.too_many(name.span(), "parameters", self.sys.params.len()) {
                        continue;
                    }
                    self.bad_params.push(bad);
                    self.param_fields.insert(field.clone(), name.to_string());
                    self.scalars
                        .insert(name.to_string(), Scalar::Param(self.sys.params.len()));
                    self.sys.params.push(ParamDef {
                        name: field,
                        default,
                        sensitive: *sensitive,
                    });
                    self.defaults.push(default);
                }
                Item::Let { name, value } => {
                    let ok = !self.reserved(name, "`let`") && !self.duplicate_scalar(name);
                    if ok {
                        self.scalars
                            .insert(name.to_string(), Scalar::Let(Box::new(value.clone())));
                    }
                }
                Item::Dof {
                    name,
                    span,
                    independent,
                    ..
                } => {
                    let i = self.sys.dofs.len();
                    if self.too_many(*span, "coordinates", i) {
                        continue;
                    }
                    let display = match name {
                        DofName::Indexed(k, s) => {
                            if *k != i {
                                self.error(*s, format!("`dof q[{k}]` is out of order: coordinates are numbered in declaration order and this one is q[{i}]; write `dof q[{i}]` (or give it a name: `dof knee;`)"));
                            }
                            format!("q[{i}]")
                        }
                        DofName::Named(id) => {
                            if self.reserved(id, "coordinate") {
                                // still the coordinate q[i]: the next ones keep their numbers
                                format!("q[{i}]")
                            } else if self.duplicate_scalar(id) {
                                continue;
                            } else {
                                self.scalars.insert(id.to_string(), Scalar::Dof(i));
                                id.to_string()
                            }
                        }
                    };
                    let z = self.sys.arena.zero();
                    self.sys.dofs.push(DofDef {
                        name: display,
                        q0: z,
                        qd0: z,
                        independent: *independent,
                    });
                    self.dof_spans.push(*span);
                    self.dof_origins.push(origin.clone());
                }
                Item::Input { name } => {
                    let ok = !self.too_many(name.span(), "inputs", self.sys.inputs.len())
                        && !self.reserved(name, "input")
                        && !self.duplicate_scalar(name);
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
                    self.frame_origins.push(origin.clone());
                    self.tog_defined.push(false);
                    self.sys.frames.push(FrameDef {
                        name: name.to_string(),
                        parent: None,
                        factors: Vec::new(),
                        inertia: None,
                    });
                }
                Item::Mass { name, .. } => {
                    if self.reserved(name, "point mass") || self.duplicate_frame_or_point(name) {
                        continue;
                    }
                    self.kinds.insert(name.to_string(), "point mass");
                    self.lumped.insert(self.sys.frames.len());
                    self.frame_names
                        .insert(name.to_string(), self.sys.frames.len());
                    self.frame_spans.push(name.span());
                    self.frame_origins.push(origin.clone());
                    // its pose is the statement's
                    self.tog_defined.push(true);
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
                            body: Box::new(body.clone()),
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

    /// Whether one more of `what` (`count` declared) is beyond what the generator numbers
    /// (65,536: its variables are numbered in 16 bits, and the 65,537th read as the first),
    /// said once at the first one beyond.
    fn too_many(&mut self, span: Span, what: &str, count: usize) -> bool {
        const MAX: usize = u16::MAX as usize + 1;
        if count == MAX {
            self.error(
                span,
                format!("more than {MAX} {what}: the generator numbers at most {MAX}; split the model, or make some of them inputs or constants"),
            );
        }
        count >= MAX
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
        if Func::from_name(&s).is_some()
            || matches!(s.as_str(), "atan2" | "powi" | "pow" | "spline")
        {
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
        self.note_tog_starts(def);
        self.note_joint_angles(def);
        // points first: effects may name points declared after them
        for (item, origin) in def.items.iter().zip(&def.origins) {
            self.origin = origin.clone();
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
        for (item, origin) in def.items.iter().zip(&def.origins) {
            self.origin = origin.clone();
            match item {
                Item::Dof { q0, qd0, name, .. } => {
                    if let DofName::Named(id) = name {
                        if self.taken_reserved.contains(&id.to_string()) {
                            dof_i += 1;
                            continue;
                        }
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
                Item::Mass {
                    name,
                    body,
                    at,
                    value,
                } => self.lower_mass(name, body, at, value),
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
                Item::EffectBlock {
                    name,
                    stmts,
                    origins,
                } => {
                    let Some(&ei) = self.effects.get(&name.to_string()) else {
                        continue;
                    };
                    for (s, o) in stmts.iter().zip(origins) {
                        self.origin = o.clone().or_else(|| origin.clone());
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
                Item::Constraint { name, body } => self.lower_constraint(name, body),
                Item::Option { key, value } => self.lower_option(key, value.as_ref()),
                Item::Shape { body, shape } => self.lower_shape(body, shape),
                _ => {}
            }
        }
    }

    fn final_checks(&mut self) {
        for i in 0..self.sys.frames.len() {
            let f = &self.sys.frames[i];
            if !self.tog_defined[i] && !self.tog_target_error {
                let kind = if f.inertia.is_some() { "body" } else { "frame" };
                let msg = format!(
                    "{kind} `{}` has no pose: add `TOG[{}] = …;`",
                    f.name, f.name
                );
                self.origin = self.frame_origins[i].clone();
                self.error(self.frame_spans[i], msg);
            }
        }
        if !self.errors.is_empty() {
            return;
        }
        // every coordinate must move some mass, or M is singular
        let n = self.sys.dofs.len();
        let mut moves = vec![vec![false; n]; self.sys.frames.len()];
        for i in self.sys.frames_parents_first() {
            let f = &self.sys.frames[i];
            if let Some(p) = f.parent {
                moves[i] = moves[p].clone();
            }
            for fac in &f.factors {
                let roots: Vec<ExprId> = match *fac {
                    Factor::Disp(d) => d.to_vec(),
                    Factor::Rot { angle, .. } => vec![angle],
                    Factor::Chart(_) => Vec::new(),
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
            self.origin = self.dof_origins[k].clone();
            self.error(self.dof_spans[k], format!("coordinate `{}` moves no body with mass, so the mass matrix would be singular: use it in the TOG of a body with mass (or of a frame that carries one), or remove it", self.sys.dofs[k].name));
        }
    }
}

mod bodies;
mod constraints;
mod effects;
mod expr;
mod shapes;
