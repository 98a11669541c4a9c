//! The `multibody!` macro. All the work happens in `mbs-symbolic`, which `mbs expand` shares.

/// Generates a specialised multibody model from CAGeM-style transforms.
/// See the `mbs` crate for the language.
#[proc_macro]
pub fn multibody(input: proc_macro::TokenStream) -> proc_macro::TokenStream {
    mbs_symbolic::expand::expand_with(input.into(), |code| {
        code.parse::<proc_macro::TokenStream>()
            .map(Into::into)
            .map_err(|e| e.to_string())
    })
    .into()
}
