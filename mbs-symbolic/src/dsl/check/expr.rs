//! Scalar expressions: names, indices, operators, functions, and what each place allows.

use super::*;

impl Checker {
    /// `q[2]` or a coordinate name.
    pub(super) fn dof_ref(&mut self, e: &Expr) -> Option<usize> {
        let k = self.dof_ref_inner(e)?;
        (!self.joint_angle_used(k, e, "a generalised force")).then_some(k)
    }

    fn dof_ref_inner(&mut self, e: &Expr) -> Option<usize> {
        match e {
            Expr::Index(ix) if matches!(&*ix.expr, Expr::Path(p) if p.path.is_ident("q")) => {
                self.index_of(&ix.index, "q", e)
            }
            Expr::Path(p) if p.path.get_ident().is_some() => {
                let id = p.path.get_ident().unwrap();
                match self.scalar(&id.to_string()) {
                    Some(Scalar::Dof(i)) => Some(i),
                    other => {
                        let is = self.describe(id, other.as_ref());
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

    /// What `name` stands for here: an argument of the inline `fn` being lowered, else the
    /// model's name.
    pub(super) fn scalar(&self, name: &str) -> Option<Scalar> {
        match self.args.iter().rev().find(|(n, _)| n == name) {
            Some(&(_, e)) => Some(Scalar::Bound(e)),
            None => self.scalars.get(name).cloned(),
        }
    }

    /// "`k` is a parameter", "`foo` is unknown", … for messages.
    pub(super) fn describe(&self, id: &Ident, s: Option<&Scalar>) -> String {
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
    pub(super) fn index_of(&mut self, idx: &Expr, v: &str, whole: &Expr) -> Option<usize> {
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
                match (self.scalar(&id.to_string()), v) {
                    (Some(Scalar::Input(i)), "u") => Some(i),
                    (Some(Scalar::Dof(i)), "q" | "qd" | "qdd") => Some(i),
                    (None, _) if self.taken_reserved.contains(&id.to_string()) => None,
                    (other, _) => {
                        let is = self.describe(id, other.as_ref());
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
    pub(super) fn not_allowed(
        &mut self,
        at: &impl ToTokens,
        thing: &str,
        kind: &str,
        a: Allow,
    ) -> ExprId {
        let what = if a.what.is_empty() {
            "this expression"
        } else {
            a.what
        };
        let hint = match kind {
            "qd" | "qdd" if a.what.starts_with("a constraint") => {
                "constraints are holonomic, Φ(q, t) = 0; velocity constraints (rolling without slipping) are not supported, model them with a stiff damper or force instead".to_string()
            }
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

    /// Lowers a scalar expression. An operation or function of constants that folds to a
    /// non-finite number (`sqrt(-1.0)`, `ln(0)`) is reported on its tokens.
    pub(super) fn lower(&mut self, e: &Expr, a: Allow) -> ExprId {
        let r = self.lower_inner(e, a);
        if !matches!(
            e,
            Expr::Binary(_) | Expr::Call(_) | Expr::MethodCall(_) | Expr::Lit(_)
        ) {
            return r;
        }
        match self.sys.arena.as_num(r) {
            Some(v) if !v.is_finite() => {
                let what = if v.is_nan() {
                    "is NaN (not a number): an argument is outside the domain of the function or operation, and every equation using it would be NaN".to_string()
                } else {
                    format!("is {v}: every equation using it would be infinite or NaN")
                };
                self.error_at(e, format!("`{}` {what}; correct the constant", text(e)));
                self.sys.arena.zero()
            }
            _ => r,
        }
    }

    fn lower_inner(&mut self, e: &Expr, a: Allow) -> ExprId {
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
                if v != "u" && self.joint_angle_used(i, ix, a.what) {
                    return self.sys.arena.zero();
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
                self.error_at(other, format!("`{}` is not a multibody! expression: use numbers, names, q[i], qd[i], u[i], t, + - * /, parentheses and functions", text(other)));
                self.sys.arena.zero()
            }
        }
    }

    pub(super) fn lower_name(&mut self, id: &Ident, a: Allow) -> ExprId {
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
        match self.scalar(&s) {
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
                if self.joint_angle_used(i, id, a.what) {
                    return self.sys.arena.zero();
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
                // a `let` is the model's: lowered without the arguments of a call it is
                // first used in (and then cached for every use)
                let outer = std::mem::take(&mut self.args);
                let e = self.lower(&body, ANY);
                self.args = outer;
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
                if self.taken_reserved.contains(&s) {
                    // its declaration was reported as taking a reserved name
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
    pub(super) fn check_allowed(&mut self, e: ExprId, id: &Ident, a: Allow) -> ExprId {
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

    /// The table of `spline(x, [(x0, y0), …])`: numbers known when the model is generated,
    /// abscissae strictly increasing; registered in the arena, its number returned.
    fn spline_table(&mut self, e: &Expr, a: Allow, usage: &str) -> Option<u16> {
        let Expr::Array(arr) = e else {
            self.error_at(
                e,
                format!(
                    "the points of a spline are an array of pairs, found `{}`: write `{usage}`",
                    text(e)
                ),
            );
            return None;
        };
        let mut points = Vec::with_capacity(arr.elems.len());
        for el in &arr.elems {
            let pair = match el {
                Expr::Tuple(t) if t.elems.len() == 2 => [&t.elems[0], &t.elems[1]],
                _ => {
                    self.error_at(
                        el,
                        format!(
                            "each point of a spline is a pair `(x, y)`, found `{}`: write `{usage}`",
                            text(el)
                        ),
                    );
                    return None;
                }
            };
            let mut xy = [0.0; 2];
            for (v, c) in xy.iter_mut().zip(pair) {
                let id = self.lower(c, a);
                match self.sys.arena.as_num(id) {
                    Some(n) => *v = n,
                    None => {
                        self.error_at(
                            c,
                            format!(
                                "the points of a spline are numbers known when the model is generated, found `{}`: write the value (parameters cannot move a spline's points)",
                                text(c)
                            ),
                        );
                        return None;
                    }
                }
            }
            points.push((xy[0], xy[1]));
        }
        match SplineTable::natural(&points) {
            Ok(t) => Some(self.sys.arena.spline_table(t)),
            Err(err) => {
                let at: &dyn ToTokens = match &err {
                    SplineError::NotFinite { index } | SplineError::NotIncreasing { index, .. } => {
                        &arr.elems[*index]
                    }
                    SplineError::TooFewPoints { .. } => arr,
                };
                self.error_at(&at.to_token_stream(), err);
                None
            }
        }
    }

    pub(super) fn lower_call(&mut self, c: &syn::ExprCall, a: Allow) -> ExprId {
        let Expr::Path(p) = &*c.func else {
            self.error_at(
                &c.func,
                format!(
                    "`{}` is followed by parentheses as a function would be: a product is written with `*`, `a * (b)`, and a call `name(arguments)`",
                    text(&c.func)
                ),
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
                // an integer literal, negated or not, in parentheses or not (a loop variable
                // or a part's argument of −2 is pasted as `(-2)`)
                fn literal(e: &Expr) -> Option<i32> {
                    match e {
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
                        Expr::Paren(p) => literal(&p.expr),
                        Expr::Group(g) => literal(&g.expr),
                        _ => None,
                    }
                }
                let n = literal(args[1]);
                let Some(n) = n else {
                    self.error_at(args[1], format!("the exponent of `powi` is an integer literal, found `{}`: use `pow(x, y)` for a real exponent", text(args[1])));
                    return self.sys.arena.zero();
                };
                if n.unsigned_abs() > 64 {
                    self.error_at(args[1], format!("the exponent of `powi` is at most 64 in magnitude, found {n}: use `pow(x, y)` for a larger one"));
                    return self.sys.arena.zero();
                }
                return self.sys.arena.powi(x, n);
            }
            "spline" => {
                const USAGE: &str = "spline(x, [(x0, y0), (x1, y1), …])";
                if !arity(self, 2, USAGE) {
                    return self.sys.arena.zero();
                }
                let x = self.lower(args[0], a);
                return match self.spline_table(args[1], a, USAGE) {
                    Some(s) => self.sys.arena.spline(s, 0, x),
                    None => self.sys.arena.zero(),
                };
            }
            "Tdisp" | "Trotx" | "Troty" | "Trotz" | "Trotn" | "Tball" | "Tfree" => {
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
                if let Some(k) = self.calling.iter().position(|f| *f == name) {
                    let how = crate::dsl::names::through(&self.calling[k + 1..]);
                    self.error_at(
                        c,
                        format!("`{name}` calls itself{how}: an inline `fn` cannot be recursive"),
                    );
                    return self.sys.arena.zero();
                }
                let vals: Vec<ExprId> = args.iter().map(|e| self.lower(e, a)).collect();
                // the body sees its own arguments and the model's names, not the caller's
                // arguments (lexical, not dynamic, scope)
                let own = params.iter().map(|p| p.to_string()).zip(vals).collect();
                let outer = std::mem::replace(&mut self.args, own);
                self.calling.push(name.clone());
                let r = self.lower(&body, a);
                self.calling.pop();
                self.args = outer;
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
                names.extend(["atan2", "pow", "powi", "spline"].map(String::from));
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
}
