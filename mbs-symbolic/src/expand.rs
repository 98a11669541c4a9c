//! `multibody!` tokens → generated items, or compile errors on the offending tokens plus stub
//! types so that the user's code does not cascade into more errors. The macro and
//! `mbs expand` share this function, so they produce the same code.

use crate::codegen::{Generated, generate};
use crate::dsl::ast::{Item, ModelDef};
use crate::dsl::check::check;
use crate::dsl::parse::Models;
use proc_macro2::TokenStream;
use quote::ToTokens;

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
    Ok(models.0.iter().map(expand_one).collect())
}

fn vis_text(def: &ModelDef) -> String {
    def.vis.to_token_stream().to_string()
}

fn expand_one(def: &ModelDef) -> Expansion {
    let name = def.name.to_string();
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
            let mut errs = missing.iter().map(|m| {
                let span = spans.iter().find(|(n, _)| *n == m.function).map_or(def.name.span(), |s| s.1);
                let which = ["the function", "the first derivative", "the second derivative", "the third derivative"]
                    .get(m.order as usize)
                    .map_or_else(|| format!("derivative {}", m.order), |s| s.to_string());
                syn::Error::new(
                    span,
                    format!(
                        "the generated equations need {which} of `{f}`, which `extern fn {f}` does not give: append its path to the list `extern fn {f} = [f, f', f'', …];`",
                        f = m.function
                    ),
                )
            });
            let mut error = errs.next().expect("at least one missing derivative");
            for e in errs {
                error.combine(e);
            }
            Expansion::Err {
                name,
                error,
                stub: stub(def),
            }
        }
    }
}

/// Placeholder types for a model with errors.
fn stub(def: &ModelDef) -> String {
    let vis = vis_text(def);
    let name = def.name.to_string();
    let mut types = vec![format!("{name}Params")];
    let scenes: Vec<String> = def
        .items
        .iter()
        .filter_map(|i| match i {
            Item::Scene { name: s, .. } => Some(format!("{name}{s}")),
            _ => None,
        })
        .collect();
    if scenes.is_empty() {
        types.push(name);
    } else {
        types.extend(scenes);
    }
    types
        .iter()
        .map(|t| format!("#[derive(Clone, Debug, Default)] {vis} struct {t};\n"))
        .collect()
}

/// What the macro emits.
pub fn expand(input: TokenStream) -> TokenStream {
    let expansions = match expand_models(input) {
        Ok(e) => e,
        Err(e) => return e.to_compile_error(),
    };
    let mut out = TokenStream::new();
    for e in expansions {
        match e {
            Expansion::Ok { generated, .. } => match generated.code.parse::<TokenStream>() {
                Ok(ts) => out.extend(ts),
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
