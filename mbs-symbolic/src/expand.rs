//! `multibody!` tokens → generated items, or compile errors on the offending tokens plus stub
//! types so that the user's code does not cascade into more errors. The macro and
//! `mbs expand` share this function, so they produce the same code.

use crate::codegen::api::{Sizes, model_impl};
use crate::codegen::{Generated, generate};
use crate::dsl::ast::{Item, ModelDef};
use crate::dsl::check::check;
use crate::dsl::parse::Models;
use proc_macro2::{Group, TokenStream, TokenTree};
use quote::ToTokens;

mod sources;
pub use sources::{Source, SourceError, sources};

/// The tokens of every `multibody! { … }` invocation in a Rust file (for `mbs expand` and
/// tools that expand a file the way the macro does).
pub fn multibody_blocks(file: &syn::File) -> Vec<TokenStream> {
    struct Finder(Vec<TokenStream>);
    impl<'a> syn::visit::Visit<'a> for Finder {
        fn visit_macro(&mut self, m: &'a syn::Macro) {
            if m.path
                .segments
                .last()
                .is_some_and(|s| s.ident == "multibody")
            {
                self.0.push(m.tokens.clone());
            }
            syn::visit::visit_macro(self, m);
        }
    }
    let mut f = Finder(Vec::new());
    syn::visit::Visit::visit_file(&mut f, file);
    f.0
}

/// One model's outcome.
pub enum Expansion {
    Ok {
        name: String,
        generated: Generated,
    },
    Err {
        name: String,
        error: syn::Error,
        stub: String,
    },
}

/// Expands every model of a block.
pub fn expand_models(input: TokenStream) -> Result<Vec<Expansion>, syn::Error> {
    let models: Models = syn::parse2(input)?;
    Ok(expand_defs(&models))
}

/// One expansion per model, in order.
fn expand_defs(models: &Models) -> Vec<Expansion> {
    let mut out = Vec::new();
    for (i, def) in models.0.iter().enumerate() {
        if models.0[..i].iter().any(|d| d.name == def.name) {
            // the first model of that name defines the types; this one only reports
            let error = syn::Error::new(
                def.name.span(),
                format!(
                    "duplicate model `{}`: each model of a multibody! block needs its own name (it names the generated types); rename one of them",
                    def.name
                ),
            );
            out.push(Expansion::Err {
                name: def.name.to_string(),
                error,
                stub: String::new(),
            });
            continue;
        }
        out.push(expand_one(def));
    }
    out
}

fn vis_text(def: &ModelDef) -> String {
    def.vis.to_token_stream().to_string()
}

fn expand_one(def: &ModelDef) -> Expansion {
    let name = def.name.to_string();
    if let Some((first, rest)) = def.errors.split_first() {
        // statements that did not parse: report them only, checking the rest would cascade
        let mut error = first.clone();
        for e in rest {
            error.combine(e.clone());
        }
        return Expansion::Err {
            name,
            error,
            stub: stub(def),
        };
    }
    let checked = match check(def) {
        Ok(c) => c,
        Err(error) => {
            return Expansion::Err {
                name,
                error,
                stub: stub(def),
            };
        }
    };
    let spans = checked.extern_spans;
    match generate(checked.system, &vis_text(def)) {
        Ok(generated) => Expansion::Ok { name, generated },
        Err(missing) => {
            let error = missing_derivatives(def, &spans, &missing);
            Expansion::Err {
                name,
                error,
                stub: stub(def),
            }
        }
    }
}

/// One error per `extern fn` whose list stops short of the derivatives the equations need.
fn missing_derivatives(
    def: &ModelDef,
    spans: &[(String, proc_macro2::Span)],
    missing: &[crate::expr::emit::MissingDerivative],
) -> syn::Error {
    const ORDINAL: [&str; 5] = ["", "first", "second", "third", "fourth"];
    let mut functions: Vec<&str> = Vec::new();
    for m in missing {
        if !functions.contains(&m.function.as_str()) {
            functions.push(&m.function);
        }
    }
    let mut errors = functions.iter().map(|&f| {
        let needed = missing
            .iter()
            .filter(|m| m.function == f)
            .map(|m| m.order as usize)
            .max()
            .unwrap_or(1);
        let given: Vec<String> = def
            .items
            .iter()
            .find_map(|i| match i {
                Item::ExternFn { name, paths } if name == f => Some(
                    paths
                        .iter()
                        .map(|p| p.to_token_stream().to_string().replace(' ', ""))
                        .collect(),
                ),
                _ => None,
            })
            .unwrap_or_default();
        let ordinal = |k: usize| {
            ORDINAL
                .get(k)
                .map_or_else(|| format!("order-{k}"), |s| s.to_string())
        };
        let has = match given.len() {
            0 | 1 => format!("gives only `{f}` itself"),
            n => format!("gives `{f}` and its derivatives up to the {}", ordinal(n - 1)),
        };
        let mut list = given.clone();
        for k in given.len()..=needed {
            list.push(format!("path::to::{f}_{}", "d".repeat(k)));
        }
        let primes = "'".repeat(needed);
        let span = spans
            .iter()
            .find(|(n, _)| n == f)
            .map_or(def.name.span(), |s| s.1);
        syn::Error::new(
            span,
            format!(
                "`extern fn {f}` {has}, but the equations of motion need its {} derivative ({f}{primes}): list the derivatives after the function, `extern fn {f} = [{}];`",
                ordinal(needed),
                list.join(", ")
            ),
        )
    });
    let mut error = errors.next().expect("at least one missing derivative");
    for e in errors {
        error.combine(e);
    }
    error
}

/// Placeholder types for a model with errors: the parameter struct with its fields and the
/// model types with `new` and the `Model` trait, so that code using them type-checks and the
/// only errors are the model's own. Their methods are never run: the crate does not compile.
fn stub(def: &ModelDef) -> String {
    let vis = vis_text(def);
    let name = def.name.to_string();
    let pty = format!("{name}Params");
    let mut params: Vec<String> = Vec::new();
    let (mut nq, mut nu, mut nframes, mut npoints) = (0, 0, 0, 0);
    let mut scenes: Vec<String> = Vec::new();
    for item in &def.items {
        match item {
            Item::Param { name: p, .. } => {
                let p = crate::dsl::repeat::rust_ident(&p.to_string());
                if !params.contains(&p) && !matches!(p.as_str(), "t" | "q" | "qd" | "qdd" | "u") {
                    params.push(p);
                }
            }
            Item::Dof { .. } => nq += 1,
            Item::Input { .. } => nu += 1,
            Item::Body { .. } | Item::Frame { .. } | Item::Mass { .. } => nframes += 1,
            Item::Point { .. } => npoints += 1,
            Item::Scene { name: s, .. } => {
                let ty = format!("{name}{s}");
                if !scenes.contains(&ty) && ty != pty {
                    scenes.push(ty);
                }
            }
            _ => {}
        }
    }
    if scenes.is_empty() {
        scenes.push(name.clone());
    }
    let fields: String = params.iter().map(|p| format!("pub {p}: f64,")).collect();
    let zeros: String = params.iter().map(|p| format!("{p}: 0.0,")).collect();
    let names: String = params.iter().map(|p| format!("{p:?},")).collect();
    let never = format!("::core::unreachable!(\"model `{name}` has errors\")");
    let mut code = format!(
        "#[derive(Clone, Debug, PartialEq, ::mbs::__private::serde::Serialize, ::mbs::__private::serde::Deserialize)]
#[serde(crate = \"::mbs::__private::serde\")]
{vis} struct {pty} {{ {fields} }}
impl ::core::default::Default for {pty} {{ fn default() -> Self {{ Self {{ {zeros} }} }} }}
impl ::mbs::Parameters for {pty} {{
const NAMES: &'static [&'static str] = &[{names}];
fn values(&self) -> ::std::vec::Vec<f64> {{ {never} }}
fn set(&mut self, _: &str, _: f64) -> ::core::result::Result<(), ::mbs::ParamError> {{ {never} }}
fn validate(&self) -> ::core::result::Result<(), ::mbs::ParamError> {{ {never} }}
}}
"
    );
    let sizes = Sizes {
        nq,
        nu,
        nframes,
        npoints,
        nc: 0,
        charts: 0,
        batch: false,
        motion: false,
        sensitive: Vec::new(),
        rest_derivatives: false,
        constraint_sensitivity: false,
        constraint_rest_derivatives: false,
    };
    for ty in scenes {
        code.push_str(&format!(
            "#[derive(Clone, Debug, Default, PartialEq)]
{vis} struct {ty} {{ params: {pty} }}
impl {ty} {{
pub const GENERATED_HASH: u64 = 0;
pub fn new(_: {pty}) -> ::core::result::Result<Self, ::mbs::ParamError> {{ {never} }}
}}
#[allow(unused_variables)]
"
        ));
        code.push_str(&model_impl(&ty, &pty, &sizes, |m| match m.name {
            "params" => "&self.params".into(),
            _ => never.clone(),
        }));
    }
    code
}

/// The generated code calls `extern fn` paths; gives those calls the spans of the paths as
/// written, so that an unresolved or ill-typed path is reported on the user's tokens (rustc
/// reports identical errors once) rather than on the whole macro call.
fn respan_extern_paths(ts: TokenStream, paths: &[Vec<TokenTree>]) -> TokenStream {
    fn same(a: &TokenTree, b: &TokenTree) -> bool {
        match (a, b) {
            (TokenTree::Ident(x), TokenTree::Ident(y)) => x == y,
            (TokenTree::Punct(x), TokenTree::Punct(y)) => x.as_char() == y.as_char(),
            _ => false,
        }
    }
    let tts: Vec<TokenTree> = ts.into_iter().collect();
    let mut out = Vec::with_capacity(tts.len());
    let mut i = 0;
    while i < tts.len() {
        let method = i > 0 && matches!(&tts[i - 1], TokenTree::Punct(p) if p.as_char() == '.');
        let called = |n: usize| matches!(tts.get(i + n), Some(TokenTree::Group(g)) if g.delimiter() == proc_macro2::Delimiter::Parenthesis);
        let hit = paths.iter().find(|p| {
            !method
                && tts.len() >= i + p.len()
                && p.iter().zip(&tts[i..]).all(|(a, b)| same(a, b))
                && called(p.len())
        });
        if let Some(p) = hit {
            for (k, user) in p.iter().enumerate() {
                let mut t = tts[i + k].clone();
                t.set_span(user.span());
                out.push(t);
            }
            i += p.len();
            continue;
        }
        match &tts[i] {
            TokenTree::Group(g) => {
                let mut ng = Group::new(g.delimiter(), respan_extern_paths(g.stream(), paths));
                ng.set_span(g.span());
                out.push(TokenTree::Group(ng));
            }
            t => out.push(t.clone()),
        }
        i += 1;
    }
    out.into_iter().collect()
}

/// What the macro emits.
pub fn expand(input: TokenStream) -> TokenStream {
    expand_with(input, |code| {
        code.parse()
            .map_err(|e: proc_macro2::LexError| e.to_string())
    })
}

/// [`expand`], the generated code turned into tokens by `parse`. The macro passes the
/// compiler's own lexer (`proc_macro::TokenStream::from_str`): inside a proc-macro,
/// proc-macro2's `FromStr` first lexes the text with its own lexer to validate it (built, as
/// build dependencies are, at opt-level 0), which the generator's output does not need: the
/// hexapod's 2 MB of code took 0.30 s that way and 0.04 s by the compiler's lexer alone.
pub fn expand_with(
    input: TokenStream,
    parse: impl Fn(&str) -> Result<TokenStream, String>,
) -> TokenStream {
    let models: Models = match syn::parse2(input) {
        Ok(m) => m,
        Err(e) => return e.to_compile_error(),
    };
    let expansions = expand_defs(&models);
    let mut out = TokenStream::new();
    for (def, e) in models.0.iter().zip(expansions) {
        let paths: Vec<Vec<TokenTree>> = def
            .items
            .iter()
            .filter_map(|i| match i {
                Item::ExternFn { paths, .. } => Some(paths),
                _ => None,
            })
            .flatten()
            .map(|p| p.to_token_stream().into_iter().collect())
            .collect();
        match e {
            Expansion::Ok { generated, .. } => match parse(&generated.code) {
                Ok(ts) if paths.is_empty() => out.extend(ts),
                Ok(ts) => out.extend(respan_extern_paths(ts, &paths)),
                Err(err) => {
                    let msg = format!(
                        "internal error: generated code does not parse ({err}); please report it"
                    );
                    out.extend(
                        syn::Error::new(proc_macro2::Span::call_site(), msg).to_compile_error(),
                    );
                }
            },
            Expansion::Err { error, stub, .. } => {
                out.extend(error.to_compile_error());
                out.extend(stub.parse::<TokenStream>().unwrap_or_default());
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Frames are declared in any order; poses start from poses defined above them.
    #[test]
    fn a_body_may_be_declared_before_the_frame_its_pose_starts_from() {
        let src: TokenStream = "model M {
            dof q[0] = 0.1;
            body b { mass = 1.0; inertia = (0.1, 0.1, 0.1); }
            frame f;
            TOG[f] = Trotz(q[0]);
            TOG[b] = TOG[f] * Tdisp(1, 0, 0);
            gravity(0, -9.81, 0);
        }"
        .parse()
        .unwrap();
        let out = expand_models(src).unwrap();
        match &out[0] {
            Expansion::Ok { generated, .. } => assert!(generated.code.contains("struct M ")),
            Expansion::Err { error, .. } => panic!("{error}"),
        }
    }
}
