//! One generated method: outputs scheduled, emitted, and split into chunk methods when there
//! are more than [`MAX_LETS`] temporaries.

use super::formulas::Formulas;
use crate::expr::cse::{MAX_LETS, Schedule};
use crate::expr::emit::{LANES_TYPE, MissingDerivative, Naming, Numbers, emit};
use crate::expr::{Arena, ExprId, OpCount, Var};
use crate::mech::system::ParamDef;
use std::fmt::Write;

/// How leaves are bound in generated code: coordinates from slices, parameters from a struct.
pub struct RustNames<'a> {
    pub params: &'a [ParamDef],
    /// path of the parameter struct: `self.params` in models, `self` in the parameter struct
    pub params_path: &'a str,
    /// path of the charts of rotation joints (`[[[f64; 3]; 3]; K]`): `self.charts` in models,
    /// the argument `charts` of the constraint functions on the parameter struct
    pub charts_path: &'a str,
    /// path of the model's splines (`[::mbs::Spline; K]`), an associated constant of the
    /// parameter struct
    pub splines_path: &'a str,
}

impl Naming for RustNames<'_> {
    fn var(&self, v: Var) -> String {
        match v {
            Var::Q(i) => format!("q_{i}"),
            Var::Qd(i) => format!("qd_{i}"),
            Var::Qdd(i) => format!("qdd_{i}"),
            Var::T => "t".into(),
            // a raw identifier (`r#type`) keeps its `r#` as the field, not in the local's name
            Var::Param(i) => format!("p_{}", raw_stripped(&self.params[i as usize].name)),
            Var::Input(i) => format!("u_{i}"),
            Var::Lambda(i) => format!("lambda_{i}"),
            Var::Chart(i) => format!("r_{i}"),
            Var::Force(i) => format!("f_{i}"),
        }
    }

    fn bind(&self, v: Var) -> String {
        match v {
            Var::Q(i) => format!("let q_{i} = q[{i}];"),
            Var::Qd(i) => format!("let qd_{i} = qd[{i}];"),
            Var::Qdd(i) => format!("let qdd_{i} = qdd[{i}];"),
            Var::T => String::new(),
            Var::Param(i) => {
                let n = &self.params[i as usize].name;
                format!("let p_{} = {}.{n};", raw_stripped(n), self.params_path)
            }
            Var::Input(i) => format!("let u_{i} = u[{i}];"),
            Var::Lambda(i) => format!("let lambda_{i} = lambda[{i}];"),
            Var::Force(i) => format!("let f_{i} = f[{i}];"),
            Var::Chart(i) => {
                let (j, r, c) = (i / 9, i % 9 / 3, i % 3);
                format!("let r_{i} = {}[{j}][{r}][{c}];", self.charts_path)
            }
        }
    }
    /// A parameter's or a chart's lanes from the models of the batch method's argument
    /// `each` (batch code is a method of a scene type: `m.params`, `m.charts`): the first
    /// model's value in every lane, or each lane's model's when they differ (`EACH`).
    fn bind_lanes(&self, v: Var) -> String {
        match v {
            Var::Param(i) => {
                let n = &self.params[i as usize].name;
                format!(
                    "let p_{} = ::mbs::lanes::gather::<EACH, _>(each, |m| m.params.{n});",
                    raw_stripped(n)
                )
            }
            Var::Chart(i) => {
                let (j, r, c) = (i / 9, i % 9 / 3, i % 3);
                format!(
                    "let r_{i} = ::mbs::lanes::gather::<EACH, _>(each, |m| m.charts[{j}][{r}][{c}]);"
                )
            }
            _ => self.bind(v),
        }
    }
    fn spline(&self, s: u16) -> String {
        format!("{}[{s}]", self.splines_path)
    }
}

/// The generic parameter of batch methods and their chunks: whether the models of their
/// lanes (`each`) differ, so that each lane reads its own model's parameters and charts, or
/// are one model, whose values the compiler then knows to be the same in every lane. One
/// function body serves both: with values that might differ in every call, the 12-joint
/// arm's batch `dynamics` took 5–20 % longer than with one model's, the two in one program
/// (gathering the four models' values into an array beforehand did not help); the
/// timings of such long functions also move by as much with where the linker places them.
pub const LANES_GENERIC: &str = "<const EACH: bool>";

/// A method to generate: `fn {name}(&self, {args})` computing `outputs`.
pub struct FnSpec {
    pub name: String,
    /// parameter list, e.g. `t: f64, q: &[f64], m: &mut [f64]`
    pub args: String,
    /// the same names as a call's arguments, e.g. `t, q, m`
    pub call: String,
    /// statements before the computation (buffer resets)
    pub prelude: Vec<String>,
    /// the outputs' buffers the prelude fills with zeros
    pub zeroed: Vec<String>,
    /// outputs added to their targets (`k[3] += …;`) rather than assigned
    pub accumulate: bool,
    pub outputs: Vec<(String, ExprId)>,
    /// `f64`, or lanes of several states (the batch functions of `option batch;`)
    pub numbers: Numbers,
    /// a second method made of this one's first chunks, when it has several
    pub prefix: Option<Prefix>,
    /// written as a table of operations that the runtime reads in a loop (`codegen::tape`),
    /// where it can be one
    pub table: bool,
}

/// A method computing the outputs before `outputs[split]` of a chunked [`FnSpec`] by calling
/// the chunks that compute them (scheduled first): `mass_matrix` as the first chunks of
/// `dynamics`, whose code then exists once.
pub struct Prefix {
    pub name: String,
    /// its parameter list
    pub args: String,
    pub split: usize,
    /// statements binding the arguments of the whole method it lacks (unused by its chunks)
    pub bind: Vec<String>,
    /// statements before the computation (buffer resets of its outputs)
    pub prelude: Vec<String>,
}

impl FnSpec {
    pub fn new(name: &str, args: &str) -> FnSpec {
        let call = super::api::call_of(args);
        FnSpec {
            name: name.into(),
            args: args.into(),
            call,
            prelude: Vec::new(),
            zeroed: Vec::new(),
            accumulate: false,
            outputs: Vec::new(),
            numbers: Numbers::Scalar,
            prefix: None,
            table: false,
        }
    }

    /// A method on lanes of four states: its arguments' `f64` become lanes, and the first,
    /// `each`, holds the four lanes' models, whose parameters and charts it reads.
    pub fn lanes(name: &str, args: &str) -> FnSpec {
        let args = format!("each: [&Self; 4], {}", args.replace("f64", LANES_TYPE));
        let mut f = FnSpec::new(name, &args);
        f.numbers = Numbers::Lanes;
        f
    }

    /// Adds a dense matrix output given by rows, stored column-major (`target[i + rows*j]`);
    /// zeros are written by one `fill`.
    pub fn matrix(&mut self, a: &Arena, target: &str, rows: &[Vec<ExprId>]) {
        if rows.iter().flatten().any(|&e| a.is_num(e, 0.0)) {
            self.prelude
                .push(format!("{target}.fill({});", self.numbers.zero()));
            self.zeroed.push(target.into());
        }
        self.nonzero_entries(a, target, rows);
    }

    /// Adds a dense matrix given by rows to `target` (column-major, as [`FnSpec::matrix`]),
    /// which holds a matrix already: its nonzero entries are added; the method adds all its
    /// outputs so.
    pub fn matrix_added(&mut self, a: &Arena, target: &str, rows: &[Vec<ExprId>]) {
        self.accumulate = true;
        self.nonzero_entries(a, target, rows);
    }

    /// The nonzero entries of a matrix given by rows as outputs `target[i + rows*j]`.
    fn nonzero_entries(&mut self, a: &Arena, target: &str, rows: &[Vec<ExprId>]) {
        let n = rows.len();
        for (i, row) in rows.iter().enumerate() {
            for (j, &e) in row.iter().enumerate() {
                if !a.is_num(e, 0.0) {
                    self.outputs.push((format!("{target}[{}]", i + n * j), e));
                }
            }
        }
    }

    /// Adds a vector to `target`, which holds one already (as [`FnSpec::matrix_added`]).
    pub fn vector_added(&mut self, a: &Arena, target: &str, v: &[ExprId]) {
        self.accumulate = true;
        for (i, &e) in v.iter().enumerate() {
            if !a.is_num(e, 0.0) {
                self.outputs.push((format!("{target}[{i}]"), e));
            }
        }
    }

    /// Adds a vector output `target[i]`.
    pub fn vector(&mut self, target: &str, v: &[ExprId]) {
        for (i, &e) in v.iter().enumerate() {
            self.outputs.push((format!("{target}[{i}]"), e));
        }
    }
}

/// What [`emit_fn`] made: the text of the method (and of its prefix method), its chunk
/// methods when it has several, the op count of the method and, when its [`Prefix`] was
/// emitted, the op count of the prefix method.
pub struct EmittedFn {
    pub text: String,
    pub chunks: Vec<Chunk>,
    pub count: OpCount,
    pub prefix: Option<OpCount>,
}

impl EmittedFn {
    /// The method and its chunk methods, for an `impl` of `self_ty`; the chunks' own modules
    /// (see [`Chunk::text`]) are added to `items`.
    pub fn full_text(&self, self_ty: &str, items: &mut String, formulas: &mut Formulas) -> String {
        let mut s = self.text.clone();
        for c in &self.chunks {
            s.push_str(&c.text(self_ty, items, formulas));
        }
        s
    }
}

/// One chunk method of a method split into chunks: `fn {name}(&self, {args}, w: &mut [..; N])`,
/// called with `{call}, w` (`w` the workspace of values that cross chunks).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Chunk {
    pub name: String,
    pub args: String,
    pub call: String,
    /// the number type's name
    pub number: &'static str,
    /// attributes of batch code (empty in `f64` code)
    pub simd: &'static str,
    /// the length of `w`, an array: the compiler then knows that every read and write of it
    /// is in bounds (the chunk functions of other modules are compiled without their caller)
    pub workspace: usize,
    pub body: String,
}

impl Chunk {
    /// The chunk for an `impl` of `self_ty`: a method that calls the chunk's code, a method of
    /// a type of a module of its own, which this adds to `items` (outside the `impl`).
    ///
    /// The compiler puts a method in the code-generation unit of its type's module, so that
    /// LLVM compiles the chunks on several cores. A program that runs the hexapod with
    /// tangents with Radau5 (`benches/compile_time.sh hexapod-radau`) built in 8.7–8.9 s
    /// where 10.9–11.4 s with the chunks in the model's one unit; the `hexapod` case, whose
    /// program calls forward dynamics alone, in 3.6–3.9 where 3.9–4.0 s. The type is a wrapper of a
    /// reference, declared in the module and given its methods here, where `self_ty` is
    /// named: a model declared in a function's body has no path from a module. Batch code stays
    /// a method: its target features would make the call from the method unsafe.
    ///
    /// The values of an `f64` chunk call the model's `formulas` (see [`Formulas`]).
    pub fn text(&self, self_ty: &str, items: &mut String, formulas: &mut Formulas) -> String {
        if !self.simd.is_empty() {
            return format!(
                "#[inline(never)]\n{}fn {}{LANES_GENERIC}(&self, {}, w: &mut [{}; {}]) {{\n{}}}\n",
                self.simd, self.name, self.args, self.number, self.workspace, self.body
            );
        }
        let module = format!("__{self_ty}{}", self.name);
        let _ = write!(
            items,
            "#[doc(hidden)]\n#[allow(non_snake_case)]\nmod {module} {{\npub struct Chunk<T>(pub T);\n}}\n\
             #[automatically_derived]\n#[allow(unused_variables, clippy::all)]\n\
             impl {module}::Chunk<&{self_ty}> {{\n#[inline(never)]\n\
             fn run(self, {}, w: &mut [{}; {}]) {{\nlet this = self.0;\n{}}}\n}}\n",
            self.args,
            self.number,
            self.workspace,
            self_to_this(&formulas.rewrite(&self.body))
        );
        format!(
            "#[inline]\nfn {}(&self, {}, w: &mut [{}; {}]) {{\n{module}::Chunk(self).run({}, w)\n}}\n",
            self.name, self.args, self.number, self.workspace, self.call
        )
    }
}

/// A method's body as a function's whose first argument is `this`: `self.` → `this.` (a
/// chunk reads parameters and charts through `self`, and nothing else of it).
fn self_to_this(body: &str) -> String {
    let mut out = String::with_capacity(body.len());
    let mut rest = body;
    while let Some(k) = rest.find("self.") {
        let before = rest[..k].chars().next_back();
        out.push_str(&rest[..k]);
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
            out.push_str("self.");
        } else {
            out.push_str("this.");
        }
        rest = &rest[k + 5..];
    }
    out.push_str(rest);
    out
}

/// Emits the method(s) of `spec`; with a [`Prefix`], the outputs are scheduled in two
/// segments (so in two chunks at least: the caller gives one only to a method that has
/// several chunks anyway) and the prefix method is emitted too.
pub fn emit_fn(
    arena: &Arena,
    spec: &FnSpec,
    names: &dyn Naming,
) -> Result<EmittedFn, Vec<MissingDerivative>> {
    if spec.table
        && let Some(e) = super::tape::emit(arena, spec, names)
    {
        return Ok(e);
    }
    let roots: Vec<ExprId> = spec.outputs.iter().map(|o| o.1).collect();
    let targets: Vec<String> = spec.outputs.iter().map(|o| o.0.clone()).collect();
    let prefix = spec.prefix.as_ref();
    let sch = match prefix {
        Some(p) => Schedule::with_segments(arena, &roots, &[p.split], MAX_LETS),
        None => Schedule::new(arena, &roots),
    };
    let em = emit(
        arena,
        &sch,
        &targets,
        &spec.zeroed,
        spec.accumulate,
        names,
        spec.numbers,
    )?;
    let number = spec.numbers.type_name();
    // batch code is compiled for 256-bit registers on x86-64 whatever the build's target CPU
    // (the trait method checks the processor before calling it)
    let simd = match spec.numbers {
        Numbers::Scalar => "",
        Numbers::Lanes => {
            "#[cfg_attr(target_arch = \"x86_64\", target_feature(enable = \"avx2\"))]\n"
        }
    };
    // batch code is generic over whether its lanes' models differ ([`LANES_GENERIC`])
    let (generic, each) = match spec.numbers {
        Numbers::Scalar => ("", ""),
        Numbers::Lanes => (LANES_GENERIC, "::<EACH>"),
    };
    let mut s = String::new();
    let mut chunks = Vec::new();
    let prelude: String = spec.prelude.iter().map(|p| format!("{p}\n")).collect();
    if em.chunks.len() == 1 {
        let _ = writeln!(
            s,
            "#[inline]\n{simd}fn {}{generic}(&self, {}) {{\n{prelude}{}}}",
            spec.name, spec.args, em.chunks[0]
        );
    } else {
        let _ = write!(
            s,
            "#[inline]\n{simd}fn {}{generic}(&self, {}) {{\n{prelude}let mut w = [{}; {}];\n",
            spec.name,
            spec.args,
            spec.numbers.zero(),
            em.workspace
        );
        for k in 0..em.chunks.len() {
            let _ = writeln!(
                s,
                "self.{}_part{k}{each}({}, &mut w);",
                spec.name, spec.call
            );
        }
        s.push_str("}\n");
        for (k, c) in em.chunks.iter().enumerate() {
            chunks.push(Chunk {
                name: format!("{}_part{k}", spec.name),
                args: spec.args.clone(),
                call: spec.call.clone(),
                number,
                simd,
                workspace: em.workspace,
                body: c.clone(),
            });
        }
    }
    let prefix_count = prefix.map(|p| {
        let chunks = sch.segments[0].clone();
        let lets = sch.chunks[chunks.end - 1].end;
        let _ = write!(
            s,
            "#[inline]\n{simd}fn {}(&self, {}) {{\n{}{}let mut w = [{}; {}];\n",
            p.name,
            p.args,
            p.bind.iter().map(|b| format!("{b}\n")).collect::<String>(),
            p.prelude
                .iter()
                .map(|b| format!("{b}\n"))
                .collect::<String>(),
            spec.numbers.zero(),
            em.workspace
        );
        for k in chunks {
            let _ = writeln!(s, "self.{}_part{k}({}, &mut w);", spec.name, spec.call);
        }
        s.push_str("}\n");
        // the work of the first segment: the nodes its outputs need
        let mut c = crate::expr::ops(arena, &roots[..p.split]);
        c.lets = lets;
        c
    });
    Ok(EmittedFn {
        text: s,
        chunks,
        count: em.count,
        prefix: prefix_count,
    })
}

/// `name` without the `r#` of a raw identifier.
fn raw_stripped(name: &str) -> &str {
    name.strip_prefix("r#").unwrap_or(name)
}
