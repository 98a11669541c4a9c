//! Bodies, options and poses: mass and inertia, references to bodies, TOG products and
//! their elementary transforms, axes.

use super::*;

impl Checker {
    pub(super) fn lower_option(&mut self, key: &Ident, value: Option<&Expr>) {
        match (key.to_string().as_str(), value) {
            ("tangents", None) => self.sys.options.tangents = true,
            ("tangents", Some(Expr::Path(p))) if p.path.get_ident().is_some() => {
                let v = p.path.get_ident().unwrap();
                self.sys.options.tangents = true;
                match v.to_string().as_str() {
                    "code" => self.sys.options.tangent_form = TangentForm::Code,
                    "table" => self.sys.options.tangent_form = TangentForm::Table,
                    other => self.error(v.span(), format!("unknown form of tangents `{other}`: write `option tangents;`, `option tangents = code;` or `option tangents = table;`")),
                }
            }
            ("batch", None) => self.sys.options.batch = true,
            ("motion", None) => self.sys.options.motion = true,
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
            ("jacobians", Some(Expr::Path(p))) if p.path.get_ident().is_some() => {
                let v = p.path.get_ident().unwrap();
                self.sys.options.jacobians = match v.to_string().as_str() {
                    "generated" => Some(Jacobians::Generated),
                    "assembled" => Some(Jacobians::Assembled),
                    other => {
                        self.error(v.span(), format!("unknown form of Jacobians `{other}`: write `option jacobians = generated;` or `option jacobians = assembled;`"));
                        None
                    }
                }
            }
            ("jacobians", _) => self.error(key.span(), "write `option jacobians = generated;` or `option jacobians = assembled;`"),
            ("tangents", Some(v)) => self.error(v.span(), "write `option tangents;`, `option tangents = code;` or `option tangents = table;`"),
            ("batch", Some(v)) => self.error(v.span(), "write `option batch;` (it takes no value)"),
            ("motion", Some(v)) => self.error(v.span(), "write `option motion;` (it takes no value)"),
            (other, _) => self.error(key.span(), format!("unknown option `{other}`: the options are `tangents [= code | table]`, `batch`, `motion`, `formulation = recursive | virtual_power` and `jacobians = generated | assembled`")),
        }
    }

    pub(super) fn lower_body(&mut self, name: &Ident, props: &[(Ident, Expr)]) {
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
                    if tensor.is_some() {
                        self.error(key.span(), format!("body `{name}` has its inertia twice: give either `inertia = (…);` or one moment `inertia_z = …;`"));
                        continue;
                    }
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
                        if let Some(msg) = crate::dsl::inertia::inertia_problem([v[0], v[1], v[2], v[3], v[4], v[5]]) {
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
                axis @ ("inertia_x" | "inertia_y" | "inertia_z") => {
                    // the moment about one axis, for a body that turns only about it: the
                    // tensor of a thin plate across that axis (the two other moments half of
                    // it), so that it is a possible tensor
                    if tensor.is_some() {
                        self.error(key.span(), format!("body `{name}` has its inertia twice: give either `inertia = (…);` or one moment `{axis} = …;`"));
                        continue;
                    }
                    let i = self.lower(value, Allow { what: "an inertia", ..PARAMS_ONLY });
                    self.not_negative(i, value, &format!("the moment of inertia `{axis}` of body `{name}`"));
                    let a = &mut self.sys.arena;
                    let (half, z) = (a.scale(0.5, i), a.zero());
                    tensor = Some(match axis {
                        "inertia_x" => [i, half, half, z, z, z],
                        "inertia_y" => [half, i, half, z, z, z],
                        _ => [half, half, i, z, z, z],
                    });
                }
                other => self.error(key.span(), format!("unknown property `{other}` of body `{name}`: a body has `mass = …;` and `inertia = (Ixx, Iyy, Izz[, Ixy, Ixz, Iyz]);` or, turning about one axis only, `inertia_z = Izz;` (`inertia_x`, `inertia_y`)")),
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

    /// `mass NAME on BODY at (x, y, z) = m;`: a frame at that point of the body, with the
    /// mass m and no inertia of its own.
    pub(super) fn lower_mass(&mut self, name: &Ident, body: &BodyRef, at: &Expr, value: &Expr) {
        let Some(&fi) = self.frame_names.get(&name.to_string()) else {
            return;
        };
        let on = self.body_ref(body);
        let pos = self.triple(
            at,
            Allow {
                what: "the position of a point mass",
                ..PARAMS_ONLY
            },
            "the position of a point mass",
        );
        let m = self.lower(
            value,
            Allow {
                what: "a mass",
                ..PARAMS_ONLY
            },
        );
        if let Some(mv) = self.eval_default(m) {
            if mv <= 0.0 || !mv.is_finite() {
                let how = self.with_defaults(m);
                self.error_at(value, format!("the point mass `{name}` must be positive, it is {mv}{how}: give it a positive mass"));
            }
        }
        let (Some(on), Some(pos)) = (on, pos) else {
            return;
        };
        let Some(parent) = on else {
            self.error(body.span(), format!("a mass on the ground never moves, so it changes nothing: put `{name}` on a body"));
            return;
        };
        if self.lumped.contains(&parent) {
            let p = &self.sys.frames[parent].name;
            self.error(
                body.span(),
                format!("`{p}` is a point mass: put `{name}` on the body `{p}` is on"),
            );
            return;
        }
        let z = self.sys.arena.zero();
        let frame = &mut self.sys.frames[fi];
        frame.parent = Some(parent);
        frame.factors = vec![Factor::Disp(pos)];
        frame.inertia = Some(Inertia {
            mass: m,
            tensor: [z; 6],
        });
    }

    /// The value of a parameter expression with the default parameters; `None` when it
    /// depends on a parameter whose default is in error (already reported).
    pub(super) fn eval_default(&self, e: ExprId) -> Option<f64> {
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
    pub(super) fn with_defaults(&self, e: ExprId) -> &'static str {
        self.with_defaults_all(&[e])
    }

    pub(super) fn with_defaults_all(&self, e: &[ExprId]) -> &'static str {
        if e.iter().all(|&x| self.sys.arena.is_const(x)) {
            ""
        } else {
            " with the default parameters"
        }
    }

    /// A body/frame reference: `Some(None)` is the ground, `None` an error already reported.
    pub(super) fn body_ref(&mut self, r: &BodyRef) -> Option<Option<usize>> {
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
                None if self.taken_reserved.contains(&id.to_string()) => None,
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

    pub(super) fn ident_body_ref(&mut self, e: &Expr) -> Option<Option<usize>> {
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

    pub(super) fn lower_tog(&mut self, target: &BodyRef, chain: &Expr, span: Span) {
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
            let name = &self.sys.frames[fi].name;
            let message = if self.lumped.contains(&fi) {
                format!(
                    "`{name}` is a point mass, placed by its `mass {name} on … at (…)` statement: it has no TOG; move it there"
                )
            } else {
                format!(
                    "TOG[{name}] is defined twice: each body and frame has one pose; remove one of the two"
                )
            };
            self.error(span, message);
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
                        Some(Some(p)) if self.lumped.contains(&p) => self.error(r.span(), format!("`{}` is a point mass, not a pose to start from: start from the body it is on, or make it a body with its own pose, `body {} {{ mass = …; }}`", self.sys.frames[p].name, self.sys.frames[p].name)),
                        Some(Some(p)) if p == fi => self.error(r.span(), format!("TOG[{}] cannot refer to itself: start from its parent's pose, `TOG[parent] * …`, or from the ground", self.sys.frames[fi].name)),
                        Some(Some(p)) if !self.tog_defined[p] => {
                            let msg = match self.pose_cycle(fi, p) {
                                Some(cycle) => format!("the poses form a cycle, {cycle}: each starts from the next, so none is ever placed; start one of them from the ground or from another body's pose"),
                                None => format!("TOG[{}] is used before it is defined: move `TOG[{}] = …;` above this line (a pose may refer only to poses defined earlier)", self.sys.frames[p].name, self.sys.frames[p].name),
                            };
                            self.error(r.span(), msg);
                        }
                        Some(p) => parent = p,
                        None => {}
                    }
                    continue;
                }
            }
            if let Some(f) = self.lower_factor(leaf, what, fi) {
                factors.extend(f);
            }
        }
        let frame = &mut self.sys.frames[fi];
        frame.parent = parent;
        frame.factors = factors;
        self.tog_defined[fi] = true;
    }

    /// Notes the frame each TOG statement starts from (no errors: `lower_tog` reports them).
    pub(super) fn note_tog_starts(&mut self, def: &ModelDef) {
        let frame = |c: &Self, r: &BodyRef| match r {
            BodyRef::Name(id) => c.frame_names.get(&id.to_string()).copied(),
            BodyRef::Index(i, _) => (*i < c.sys.frames.len()).then_some(*i),
        };
        for item in &def.items {
            let Item::Tog { target, chain, .. } = item else {
                continue;
            };
            let mut first = chain;
            loop {
                match first {
                    Expr::Binary(b) if matches!(b.op, syn::BinOp::Mul(_)) => first = &b.left,
                    Expr::Paren(p) => first = &p.expr,
                    Expr::Group(g) => first = &g.expr,
                    _ => break,
                }
            }
            let Expr::Index(ix) = first else { continue };
            if !matches!(&*ix.expr, Expr::Path(p) if p.path.is_ident("TOG")) {
                continue;
            }
            let start = match &*ix.index {
                Expr::Path(p) => p.path.get_ident().map(|id| BodyRef::Name(id.clone())),
                Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::Int(l),
                    ..
                }) => l.base10_parse().ok().map(|v| BodyRef::Index(v, l.span())),
                _ => None,
            };
            if let (Some(t), Some(s)) = (frame(self, target), start.and_then(|s| frame(self, &s))) {
                self.tog_start.entry(t).or_insert(s);
            }
        }
    }

    /// `TOG[from]` starts from `TOG[to]`, not yet defined: "`a → b → a`" when `to`'s pose
    /// leads back to `from`.
    fn pose_cycle(&self, from: usize, to: usize) -> Option<String> {
        let mut path = vec![from, to];
        let mut cur = to;
        while path.len() <= self.sys.frames.len() + 1 {
            cur = *self.tog_start.get(&cur)?;
            path.push(cur);
            if cur == from {
                let names: Vec<&str> = path
                    .iter()
                    .map(|&f| self.sys.frames[f].name.as_str())
                    .collect();
                return Some(format!("`{}`", names.join(" → ")));
            }
        }
        None
    }

    /// Splits `a * b * c` into its factors; anything but products is an error.
    pub(super) fn flatten_product<'e>(&mut self, e: &'e Expr, out: &mut Vec<&'e Expr>) -> bool {
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

    /// The angle coordinates of every `Tball`/`Tfree` of the TOG products (no errors:
    /// `lower_factor` reports them), so that their uses elsewhere are refused wherever they
    /// come in the source.
    pub(super) fn note_joint_angles(&mut self, def: &ModelDef) {
        for item in &def.items {
            let Item::Tog { chain, .. } = item else {
                continue;
            };
            let mut leaves = Vec::new();
            let before = self.errors.len();
            self.flatten_product(chain, &mut leaves);
            self.errors.truncate(before);
            for leaf in leaves {
                let Expr::Call(call) = leaf else { continue };
                let Expr::Path(p) = &*call.func else { continue };
                let joint = match p.path.get_ident().map(|i| i.to_string()).as_deref() {
                    Some("Tball") => 0,
                    Some("Tfree") => 3,
                    _ => continue,
                };
                for arg in call.args.iter().skip(joint) {
                    if let Some(k) = self.coordinate_silent(arg) {
                        self.joint_angles.insert(k, text(leaf));
                    }
                }
            }
        }
    }

    /// The coordinate `e` names (`q[2]`, `knee`, `q[knee]`), without reporting anything.
    fn coordinate_silent(&self, e: &Expr) -> Option<usize> {
        let named = |id: &Ident| match self.scalar(&id.to_string()) {
            Some(Scalar::Dof(i)) => Some(i),
            _ => None,
        };
        match e {
            Expr::Path(p) => named(p.path.get_ident()?),
            Expr::Index(ix) if matches!(&*ix.expr, Expr::Path(p) if p.path.is_ident("q")) => {
                match &*ix.index {
                    Expr::Lit(syn::ExprLit {
                        lit: syn::Lit::Int(l),
                        ..
                    }) => l
                        .base10_parse::<usize>()
                        .ok()
                        .filter(|&i| i < self.sys.dofs.len()),
                    Expr::Path(p) => named(p.path.get_ident()?),
                    _ => None,
                }
            }
            _ => None,
        }
    }

    /// A use of coordinate `k` (or its rate) outside its `Tball`/`Tfree`, on `at`: an error
    /// when `k` is the angle of such a joint. Returns whether it was refused.
    pub(super) fn joint_angle_used(&mut self, k: usize, at: &impl ToTokens, what: &str) -> bool {
        let Some(joint) = self.joint_angles.get(&k).cloned() else {
            return false;
        };
        let name = repeat::display(&self.sys.dofs[k].name);
        let what = if what.is_empty() {
            "forces, poses or constraints"
        } else {
            what
        };
        self.error_at(
            at,
            format!("`{name}` is an angle of `{joint}`, measured from a chart that the runtime moves to stay clear of gimbal lock, so it has no fixed meaning and cannot appear in {what}: act on the orientation instead (a `torque`, a `bushing` or a `rotational_spring` between frames, a force at a point)"),
        );
        true
    }

    /// `Tball(a, b, c)` or `Tfree(x, y, z, a, b, c)` on frame `frame`: the factors of the
    /// joint, registered in `sys.rotation_joints` (the same arguments again are the same
    /// joint: absolute poses repeat it).
    fn lower_joint(
        &mut self,
        call: &syn::ExprCall,
        name: &Ident,
        frame: usize,
    ) -> Option<Vec<Factor>> {
        let free = name == "Tfree";
        let usage = if free {
            "Tfree(x, y, z, a, b, c)"
        } else {
            "Tball(a, b, c)"
        };
        let args: Vec<&Expr> = call.args.iter().collect();
        if !self.arity_ok(call, name, args.len(), if free { 6 } else { 3 }, usage) {
            return None;
        }
        let mut ks: Vec<usize> = Vec::new();
        for arg in &args {
            let Some(k) = self.coordinate_silent(arg) else {
                let kind = if free {
                    "a free joint's translation and ZYX angles"
                } else {
                    "a spherical joint's ZYX angles"
                };
                self.error_at(
                    *arg,
                    format!("the arguments of `{usage}` are coordinates, {kind} (`dof` names or `q[i]`), found `{}`: declare a coordinate, `dof a = 0.0;`, and pass it", text(*arg)),
                );
                return None;
            };
            if let Some(p) = ks.iter().position(|&j| j == k) {
                self.error_at(
                    *arg,
                    format!("`{}` is argument {} and {} of `{}`: the joint needs {} different coordinates", text(*arg), p + 1, ks.len() + 1, text(call), args.len()),
                );
                return None;
            }
            ks.push(k);
        }
        let angles = [ks[ks.len() - 3], ks[ks.len() - 2], ks[ks.len() - 1]];
        let translation = free.then(|| [ks[0], ks[1], ks[2]]);
        let joints = &self.sys.rotation_joints;
        if let Some(j) = joints
            .iter()
            .position(|d| d.angles == angles && d.translation == translation)
        {
            return Some(self.joint_factors(j));
        }
        // a coordinate of another joint
        for d in joints {
            let theirs: Vec<usize> = d
                .angles
                .iter()
                .chain(d.translation.iter().flatten())
                .copied()
                .collect();
            if let Some(&k) = ks.iter().find(|k| theirs.contains(k)) {
                let dof = repeat::display(&self.sys.dofs[k].name);
                let body = repeat::display(&self.sys.frames[d.frame].name);
                let joint = self
                    .joint_angles
                    .get(&d.angles[0])
                    .cloned()
                    .unwrap_or_default();
                self.error_at(
                    call,
                    format!("`{dof}` already belongs to `{joint}` in the pose of `{body}`: a coordinate belongs to one `Tball` or `Tfree` (write that joint again, with the same arguments, to share it)"),
                );
                return None;
            }
        }
        self.sys.rotation_joints.push(RotationJointDef {
            frame,
            angles,
            translation,
        });
        Some(self.joint_factors(self.sys.rotation_joints.len() - 1))
    }

    /// The factors of rotation joint `j`: its translation, its chart, Rz(a)·Ry(b)·Rx(c).
    fn joint_factors(&mut self, j: usize) -> Vec<Factor> {
        let d = self.sys.rotation_joints[j];
        let a = &mut self.sys.arena;
        let (z, o) = (a.zero(), a.one());
        let mut f = Vec::new();
        if let Some(t) = d.translation {
            f.push(Factor::Disp(t.map(|k| a.var(Var::Q(k as u16)))));
        }
        f.push(Factor::Chart(j as u16));
        for (axis, k) in [[z, z, o], [z, o, z], [o, z, z]].into_iter().zip(d.angles) {
            f.push(Factor::Rot {
                axis,
                angle: a.var(Var::Q(k as u16)),
            });
        }
        f
    }

    /// One transform factor; `None` after an error, an empty list for an identity. `frame`
    /// is the frame whose pose it is part of.
    pub(super) fn lower_factor(
        &mut self,
        e: &Expr,
        what: &'static str,
        frame: usize,
    ) -> Option<Vec<Factor>> {
        const TRANSFORMS: &str = "Tdisp(x, y, z), Trotx(a), Troty(a), Trotz(a), Trotn(nx, ny, nz, a), Tball(a, b, c) and Tfree(x, y, z, a, b, c)";
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
            "Tball" | "Tfree" => self.lower_joint(call, name, frame),
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
                if !self.unit_axis(
                    &n,
                    &axis_tokens,
                    "the axis of Trotn",
                    "Trotn(nx, ny, nz, angle)",
                ) {
                    return None;
                }
                rot(self, n)
            }
            other => {
                let known = [
                    "Tdisp", "Trotx", "Troty", "Trotz", "Trotn", "Tball", "Tfree",
                ];
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
    pub(super) fn axis_arg(
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
                    self.unit_axis(
                        n,
                        &axis.to_token_stream(),
                        &format!("the axis of the {of}"),
                        usage,
                    )
                })
            }
            _ => {
                self.error_at(axis, format!("unknown {of} axis `{}`: write `axis = x`, `y`, `z` or a unit vector `(nx, ny, nz)`, {axes}", text(axis)));
                None
            }
        }
    }

    /// Whether `n` is a unit vector (with the default parameters); reports it on `at` if not.
    /// `of` names the vector: "the axis of Trotn".
    pub(super) fn unit_axis(
        &mut self,
        n: &[ExprId; 3],
        at: &TokenStream,
        of: &str,
        usage: &str,
    ) -> bool {
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
                    "{of} is zero{how}: give a unit vector, e.g. `{}`",
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
                format!("{of} must be a unit vector, but ({x}, {y}, {z}) has norm {norm}{how}: divide it by its norm{example}"),
            );
            return false;
        }
        true
    }
}
