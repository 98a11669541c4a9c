//! The `multibody!` expansion of a source text, for the tests of the language.
#![allow(dead_code)]

use mbs_symbolic::expand::{Expansion, expand_models};

/// The generated code of the single model in `src`, or its errors' messages.
pub fn code(src: &str) -> Result<String, Vec<String>> {
    let tokens: proc_macro2::TokenStream = src.parse().expect("tokens");
    let mut out = expand_models(tokens).map_err(|e| vec![e.to_string()])?;
    assert_eq!(out.len(), 1);
    match out.remove(0) {
        Expansion::Ok { generated, .. } => Ok(generated.code),
        Expansion::Err { error, .. } => Err(error.into_iter().map(|e| e.to_string()).collect()),
    }
}

/// [`code`] without the line of its hash, for comparisons.
pub fn generate(src: &str) -> Result<String, Vec<String>> {
    code(src).map(|c| {
        c.lines()
            .filter(|l| !l.contains("GENERATED_HASH"))
            .collect::<Vec<_>>()
            .join("\n")
    })
}

/// The errors' messages of the single model in `src`, which must have some.
pub fn errors(src: &str) -> Vec<String> {
    match generate(src) {
        Ok(_) => panic!("expected errors"),
        Err(e) => e,
    }
}
