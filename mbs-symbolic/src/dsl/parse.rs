//! Tokens → [`ModelDef`]s. Only the statement structure is parsed here; expressions are
//! `syn::Expr` and get their meaning in `check`.

use super::ast::{BodyRef, ConstraintBody, DofName, EffectStmt, Item, ModelDef};
use super::repeat;
use proc_macro2::TokenTree;
use syn::ext::IdentExt;
use syn::parse::{Parse, ParseStream};
use syn::punctuated::Punctuated;
use syn::{Expr, Ident, Token, braced, bracketed, parenthesized};

/// All models of one `multibody!` invocation.
pub struct Models(pub Vec<ModelDef>);

impl Parse for Models {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let mut v = Vec::new();
        while !input.is_empty() {
            v.push(input.parse()?);
        }
        if v.is_empty() {
            return Err(input.error(
                "expected `model Name { … }`: a multibody! block declares at least one model",
            ));
        }
        Ok(Models(v))
    }
}

fn keyword(input: ParseStream, kw: &str) -> bool {
    input.fork().parse::<Ident>().is_ok_and(|i| i == kw)
}

impl Parse for ModelDef {
    fn parse(input: ParseStream) -> syn::Result<Self> {
        let attrs = input.call(syn::Attribute::parse_outer)?;
        let mut docs = Vec::new();
        for a in &attrs {
            match &a.meta {
                syn::Meta::NameValue(nv) if a.path().is_ident("doc") => {
                    if let Expr::Lit(syn::ExprLit {
                        lit: syn::Lit::Str(s),
                        ..
                    }) = &nv.value
                    {
                        docs.push(s.value());
                    }
                }
                _ => {
                    return Err(syn::Error::new_spanned(
                        a,
                        "only `///` doc comments may precede a model",
                    ));
                }
            }
        }
        let vis: syn::Visibility = input.parse()?;
        let kw: Ident = input
            .parse()
            .map_err(|e| syn::Error::new(e.span(), "expected `model Name { … }`"))?;
        if kw != "model" {
            return Err(syn::Error::new(
                kw.span(),
                format!("expected `model`, found `{kw}`: write `model Name {{ … }}`"),
            ));
        }
        let name: Ident = input.parse().map_err(|e| {
            syn::Error::new(
                e.span(),
                "expected the model's name after `model`: write `model Name { … }`",
            )
        })?;
        if !input.peek(syn::token::Brace) {
            return Err(input.error(format!(
                "expected the statements of `model {name}` in braces: write `model {name} {{ … }}`"
            )));
        }
        let content;
        let brace = braced!(content in input);
        let tokens: proc_macro2::TokenStream = content.parse()?;
        let mut errors = Vec::new();
        let stmts = repeat::expand(tokens, brace.span.close(), &mut errors);
        let mut items = Vec::new();
        let mut origins = Vec::new();
        for s in stmts {
            let word = first_word(&s.tokens);
            let parsed = match s.inner {
                None => parse_in(s.tokens, s.end, parse_item),
                Some(inner) => parse_in(s.tokens, s.end, |input| {
                    input.parse::<Ident>()?;
                    input.parse::<Ident>()
                })
                .map(|name| {
                    let mut stmts = Vec::new();
                    let mut origins = Vec::new();
                    for e in inner {
                        let word = first_word(&e.tokens);
                        match parse_in(e.tokens, e.end, parse_effect) {
                            Ok(stmt) => {
                                stmts.push(stmt);
                                origins.push(e.origin);
                            }
                            Err(err) => errors.push(relabel(explained(err, &word), &e.origin)),
                        }
                    }
                    Item::EffectBlock {
                        name,
                        stmts,
                        origins,
                    }
                }),
            };
            match parsed {
                Ok(Item::Scene { name, .. }) if name.to_string().contains(repeat::SEP) => {
                    errors.push(relabel(
                        syn::Error::new(
                            name.span(),
                            format!("a scene's name names a type, so `{name}` cannot be indexed: give it a plain name"),
                        ),
                        &s.origin,
                    ));
                }
                Ok(item) => {
                    items.push(item);
                    origins.push(s.origin);
                }
                Err(e) => errors.push(relabel(explained(e, &word), &s.origin)),
            }
        }
        Ok(ModelDef {
            docs,
            vis,
            name,
            items,
            origins,
            errors: repeat::dedupe(errors),
        })
    }
}

/// Parses one statement's tokens with `f`, as if they stood alone in braces whose end is
/// `end` (the next statement), so that "expected `;`, found …" points where it did before.
fn parse_in<T>(
    tokens: proc_macro2::TokenStream,
    end: proc_macro2::Span,
    f: impl FnOnce(ParseStream) -> syn::Result<T>,
) -> syn::Result<T> {
    let mut g = proc_macro2::Group::new(proc_macro2::Delimiter::Brace, tokens);
    g.set_span(end);
    let wrapped: proc_macro2::TokenStream = TokenTree::Group(g).into();
    syn::parse::Parser::parse2(
        |input: ParseStream| {
            let content;
            braced!(content in input);
            let v = f(&content)?;
            if !content.is_empty() {
                return Err(content
                    .error("unexpected tokens after the statement: end each statement with `;`"));
            }
            Ok(v)
        },
        wrapped,
    )
}

/// The first word of a statement's tokens (its keyword, or an effect's name), if it has one.
fn first_word(tokens: &proc_macro2::TokenStream) -> Option<String> {
    match tokens.clone().into_iter().next() {
        Some(TokenTree::Ident(i)) => Some(i.to_string()),
        _ => None,
    }
}

/// How the statement that starts with `word` is written, for messages that say only what
/// token the parser expected.
fn statement_form(word: &str) -> String {
    match word {
        "let" => "`let name = expression;`".into(),
        "fn" => "`fn name(x, y) = expression;`".into(),
        "extern" => "`extern fn name = [path::to::function];`".into(),
        "param" => "`param name = 1.0;`".into(),
        "dof" => "`dof name = q0;` or `dof name = q0, qd = qd0;`".into(),
        "input" => "`input name;`".into(),
        "body" => "`body name { mass = m; inertia = (Ixx, Iyy, Izz); }`".into(),
        "frame" => "`frame name;`".into(),
        "point" => "`point name on body at (x, y, z);`".into(),
        "mass" => "`mass name on body at (x, y, z) = m;`".into(),
        "TOG" => "`TOG[body] = Trotz(q[0]) * Tdisp(x, y, z);`".into(),
        "effect" => "`effect name { gravity(0, -9.81, 0); … }`".into(),
        "scene" => "`scene name = [effect, …];`".into(),
        "constraint" => {
            "`constraint name = expression;` or `constraint name: coincide(a, b);`".into()
        }
        "shape" => "`shape body: box(lx, ly, lz);`".into(),
        "option" => "`option name = value;`".into(),
        "part" => "`part Name(a, b) { statements }`".into(),
        "for" => "`for i in 0..n { statements }`".into(),
        effect => format!("`{effect}(a, b, …);`, its arguments separated by commas"),
    }
}

/// `e` with each message that names only the token the parser expected (syn's own, such as
/// "expected an expression") completed by how its statement is written; a number that does
/// not parse said so, where Rust's parser of integers said "invalid digit found in string".
fn explained(e: syn::Error, word: &Option<String>) -> syn::Error {
    each_message(e, |m| {
        let m = match m.as_str() {
            "invalid digit found in string"
            | "cannot parse integer from empty string"
            | "number too large to fit in target type"
            | "number too small to fit in target type"
            | "invalid float literal" => "expected a number".to_string(),
            _ => m,
        };
        let bare = (m.starts_with("expected ") || m.starts_with("unexpected "))
            && !m.contains(": ")
            && !m.contains("write")
            && !m.contains('…')
            && !m.contains("found `");
        match word {
            Some(w) if bare => format!("{m}: this statement is written {}", statement_form(w)),
            None if bare => format!(
                "{m}: a statement starts with its keyword (param, let, dof, body, TOG, …) or with an effect's name, such as `gravity(…)`"
            ),
            _ => m,
        }
    })
}

/// `e` with each of its messages rewritten by `f`, at its own span.
fn each_message(e: syn::Error, f: impl Fn(String) -> String) -> syn::Error {
    let mut out: Option<syn::Error> = None;
    for one in e {
        let new = syn::Error::new(one.span(), f(one.to_string()));
        match &mut out {
            None => out = Some(new),
            Some(o) => o.combine(new),
        }
    }
    out.expect("an error has at least one message")
}

/// An error with its statement's origin appended and indexed names shown as written.
fn relabel(e: syn::Error, origin: &repeat::Origin) -> syn::Error {
    if origin.is_none() && !e.to_string().contains(repeat::SEP) {
        return e;
    }
    each_message(e, |m| repeat::with_origin(&m, origin))
}

fn body_ref(input: ParseStream) -> syn::Result<BodyRef> {
    if input.peek(syn::LitInt) {
        let l: syn::LitInt = input.parse()?;
        return Ok(BodyRef::Index(l.base10_parse()?, l.span()));
    }
    let i: Ident = input
        .parse()
        .map_err(|e| syn::Error::new(e.span(), "expected a body name or number"))?;
    Ok(BodyRef::Name(i))
}

fn semi(input: ParseStream, what: &str) -> syn::Result<()> {
    if input.peek(Token![;]) {
        input.parse::<Token![;]>()?;
        Ok(())
    } else {
        let found = match input.fork().parse::<TokenTree>() {
            Ok(TokenTree::Group(g)) => match g.delimiter() {
                proc_macro2::Delimiter::Brace => "`{`".to_string(),
                proc_macro2::Delimiter::Bracket => "`[`".to_string(),
                proc_macro2::Delimiter::Parenthesis => "`(`".to_string(),
                proc_macro2::Delimiter::None => "an expression".to_string(),
            },
            Ok(t) => format!("`{t}`"),
            Err(_) => "the end of the model".to_string(),
        };
        Err(input.error(format!(
            "expected `;` after {what}, found {found}: end each statement with `;`"
        )))
    }
}

fn parse_item(input: ParseStream) -> syn::Result<Item> {
    if input.peek(Token![let]) {
        input.parse::<Token![let]>()?;
        let name: Ident = input.parse()?;
        input.parse::<Token![=]>()?;
        let value: Expr = input.parse()?;
        semi(input, "`let`")?;
        return Ok(Item::Let { name, value });
    }
    if input.peek(Token![fn]) {
        input.parse::<Token![fn]>()?;
        let name: Ident = input.parse()?;
        let args;
        parenthesized!(args in input);
        let args: Punctuated<Ident, Token![,]> = args.parse_terminated(Ident::parse, Token![,])?;
        input.parse::<Token![=]>()?;
        let body: Expr = input.parse()?;
        semi(input, "`fn`")?;
        return Ok(Item::Fn {
            name,
            args: args.into_iter().collect(),
            body,
        });
    }
    if input.peek(Token![extern]) {
        input.parse::<Token![extern]>()?;
        input.parse::<Token![fn]>()?;
        let name: Ident = input.parse()?;
        input.parse::<Token![=]>()?;
        let list;
        bracketed!(list in input);
        let paths: Punctuated<syn::Path, Token![,]> =
            list.parse_terminated(syn::Path::parse, Token![,])?;
        semi(input, "`extern fn`")?;
        return Ok(Item::ExternFn {
            name,
            paths: paths.into_iter().collect(),
        });
    }
    let kw: Ident = input.fork().parse().map_err(|e| {
        syn::Error::new(e.span(), "expected a statement: param, let, dof, input, body, frame, point, mass, TOG[…], fn, extern fn, effect, scene, option or an effect such as gravity(…)")
    })?;
    let k = kw.to_string();
    match k.as_str() {
        "param" => {
            input.parse::<Ident>()?;
            let name: Ident = input.parse()?;
            input.parse::<Token![=]>().map_err(|e| {
                syn::Error::new(
                    e.span(),
                    format!("a parameter needs a default value: `param {name} = 1.0;`"),
                )
            })?;
            let value: Expr = input.parse()?;
            let mut sensitive = false;
            if input.peek(Ident) {
                let word: Ident = input.parse()?;
                if word != "sensitive" {
                    return Err(syn::Error::new(
                        word.span(),
                        format!(
                            "after a parameter's value only `sensitive` may follow (`param {name} = … sensitive;` generates ∂τ/∂{name}), not `{word}`"
                        ),
                    ));
                }
                sensitive = true;
            }
            semi(input, "`param`")?;
            Ok(Item::Param {
                name,
                value,
                sensitive,
            })
        }
        "dof" => {
            input.parse::<Ident>()?;
            let span = input.span();
            let id: Ident = input.parse()?;
            let name = if id == "q" && input.peek(syn::token::Bracket) {
                let idx;
                bracketed!(idx in input);
                let whole = |span| {
                    syn::Error::new(
                        span,
                        "the index of a coordinate `q[i]` is a whole number from 0, such as `dof q[0]`",
                    )
                };
                let l: syn::LitInt = idx.parse().map_err(|e| whole(e.span()))?;
                DofName::Indexed(l.base10_parse().map_err(|_| whole(l.span()))?, l.span())
            } else {
                DofName::Named(id)
            };
            let mut q0 = None;
            let mut qd0 = None;
            let mut independent = false;
            if input.peek(Token![=]) {
                input.parse::<Token![=]>()?;
                q0 = Some(input.parse()?);
            }
            // `, qd = …` and `, independent`, in any order
            while input.peek(Token![,]) {
                input.parse::<Token![,]>()?;
                let k: Ident = input.parse()?;
                if k == "qd" && qd0.is_none() {
                    input.parse::<Token![=]>()?;
                    qd0 = Some(input.parse()?);
                } else if k == "independent" && !independent {
                    independent = true;
                } else {
                    return Err(syn::Error::new(
                        k.span(),
                        "expected `qd = …` (the initial velocity) or `independent` (kept when a closed loop is assembled)",
                    ));
                }
            }
            semi(input, "`dof`")?;
            Ok(Item::Dof {
                name,
                q0,
                qd0,
                independent,
                span,
            })
        }
        "input" => {
            input.parse::<Ident>()?;
            let name: Ident = input.parse()?;
            semi(input, "`input`")?;
            Ok(Item::Input { name })
        }
        "body" => {
            input.parse::<Ident>()?;
            let name: Ident = input.parse()?;
            let mut props = Vec::new();
            if input.peek(syn::token::Brace) {
                let content;
                braced!(content in input);
                while !content.is_empty() {
                    let key: Ident = content.parse().map_err(|e| {
                        syn::Error::new(
                            e.span(),
                            format!("expected a property of body `{name}`: `mass = …;` or `inertia = (Ixx, Iyy, Izz);`"),
                        )
                    })?;
                    content.parse::<Token![=]>().map_err(|e| {
                        syn::Error::new(
                            e.span(),
                            format!("expected `=` after `{key}`: body properties are written `{key} = …;`"),
                        )
                    })?;
                    let value: Expr = content.parse()?;
                    semi(&content, &format!("`{key} = …`"))?;
                    props.push((key, value));
                }
            } else {
                semi(
                    input,
                    "`body` (or give its properties in `{ mass = …; inertia = …; }`)",
                )?;
            }
            Ok(Item::Body { name, props })
        }
        "frame" => {
            input.parse::<Ident>()?;
            let name: Ident = input.parse()?;
            semi(input, "`frame`")?;
            Ok(Item::Frame { name })
        }
        "point" => {
            input.parse::<Ident>()?;
            let name: Ident = input.parse()?;
            let on: Ident = input.parse()?;
            if on != "on" {
                return Err(syn::Error::new(
                    on.span(),
                    "expected `on`: write `point name on body at (x, y, z);`",
                ));
            }
            let body = body_ref(input)?;
            let at: Ident = input.parse()?;
            if at != "at" {
                return Err(syn::Error::new(
                    at.span(),
                    "expected `at`: write `point name on body at (x, y, z);`",
                ));
            }
            let pos: Expr = input.parse()?;
            semi(input, "`point`")?;
            Ok(Item::Point {
                name,
                body,
                at: pos,
            })
        }
        "mass" => {
            input.parse::<Ident>()?;
            let usage = "write `mass name on body at (x, y, z) = m;`";
            let name: Ident = input.parse()?;
            // the keyword `w` next, or an error naming it
            let word = |w: &str| -> syn::Result<()> {
                match input.fork().parse::<Ident>() {
                    Ok(i) if i == w => input.parse::<Ident>().map(|_| ()),
                    _ => Err(syn::Error::new(
                        input.span(),
                        format!("expected `{w}`: {usage}"),
                    )),
                }
            };
            word("on")?;
            let body = body_ref(input)?;
            word("at")?;
            if !input.peek(syn::token::Paren) {
                return Err(syn::Error::new(
                    input.span(),
                    format!("expected the position `(x, y, z)` in the body's axes: {usage}"),
                ));
            }
            let content;
            let paren_token = parenthesized!(content in input);
            let pos = Expr::Tuple(syn::ExprTuple {
                attrs: Vec::new(),
                paren_token,
                elems: content.parse_terminated(Expr::parse, Token![,])?,
            });
            input
                .parse::<Token![=]>()
                .map_err(|e| syn::Error::new(e.span(), format!("expected `= m`: {usage}")))?;
            let value: Expr = input.parse()?;
            semi(input, "`mass`")?;
            Ok(Item::Mass {
                name,
                body,
                at: pos,
                value,
            })
        }
        "TOG" => {
            let span = input.parse::<Ident>()?.span();
            if !input.peek(syn::token::Bracket) {
                return Err(input.error(
                    "expected `[`: a pose is written `TOG[body] = …;`, with the body in square brackets",
                ));
            }
            let idx;
            bracketed!(idx in input);
            let target = body_ref(&idx)?;
            input.parse::<Token![=]>().map_err(|e| {
                syn::Error::new(
                    e.span(),
                    "expected `=`: write `TOG[body] = Trotz(q[0]) * Tdisp(x, y, z);`",
                )
            })?;
            let chain: Expr = input.parse()?;
            semi(input, "`TOG[…] = …`")?;
            Ok(Item::Tog {
                target,
                chain,
                span,
            })
        }
        "effect" => {
            input.parse::<Ident>()?;
            let name: Ident = input.parse()?;
            let content;
            braced!(content in input);
            let mut stmts = Vec::new();
            while !content.is_empty() {
                stmts.push(parse_effect(&content)?);
            }
            let origins = vec![None; stmts.len()];
            Ok(Item::EffectBlock {
                name,
                stmts,
                origins,
            })
        }
        "scene" => {
            input.parse::<Ident>()?;
            let name: Ident = input.parse()?;
            let usage = |e: syn::Error| {
                syn::Error::new(
                    e.span(),
                    format!(
                        "expected `scene {name} = [effect, …];`, with the effects in square brackets"
                    ),
                )
            };
            input.parse::<Token![=]>().map_err(usage)?;
            if !input.peek(syn::token::Bracket) {
                return Err(usage(input.error("")));
            }
            let list;
            bracketed!(list in input);
            let effects: Punctuated<Ident, Token![,]> =
                list.parse_terminated(Ident::parse, Token![,])?;
            semi(input, "`scene`")?;
            Ok(Item::Scene {
                name,
                effects: effects.into_iter().collect(),
            })
        }
        "constraint" => {
            input.parse::<Ident>()?;
            let name: Ident = input.parse()?;
            let body = if input.peek(Token![=]) {
                input.parse::<Token![=]>()?;
                let e: Expr = input.parse()?;
                semi(input, "`constraint NAME = expression`")?;
                ConstraintBody::Scalar(e)
            } else if input.peek(Token![:]) {
                input.parse::<Token![:]>()?;
                ConstraintBody::Closure(parse_effect(input)?)
            } else {
                return Err(input.error(format!(
                    "expected `=` or `:` after `constraint {name}`: write `constraint {name} = expression;` (Φ = 0) or `constraint {name}: coincide(a, b);`"
                )));
            };
            Ok(Item::Constraint { name, body })
        }
        "shape" => {
            input.parse::<Ident>()?;
            let usage = "write `shape BODY: box(lx, ly, lz);`, `cylinder(radius, length, axis = z)`, `sphere(radius)` or `line(from = (x, y, z), to = (x, y, z))`";
            let body: Ident = input.parse().map_err(|e| {
                syn::Error::new(
                    e.span(),
                    format!(
                        "expected the name of a body, a frame or `ground` after `shape`: {usage}"
                    ),
                )
            })?;
            if !input.peek(Token![:]) {
                return Err(input.error(format!("expected `:` after `shape {body}`: {usage}")));
            }
            input.parse::<Token![:]>()?;
            if !(input.peek(Ident::peek_any) && input.peek2(syn::token::Paren)) {
                return Err(input.error(format!("expected a shape after `shape {body}:`: {usage}")));
            }
            // `box` is a Rust keyword: take any identifier
            let kind = input.call(Ident::parse_any)?;
            let shape = parse_call(input, kind)?;
            Ok(Item::Shape { body, shape })
        }
        "option" => {
            input.parse::<Ident>()?;
            let key: Ident = input.parse()?;
            let value = if input.peek(Token![=]) {
                input.parse::<Token![=]>()?;
                Some(input.parse()?)
            } else {
                None
            };
            semi(input, "`option`")?;
            Ok(Item::Option { key, value })
        }
        _ if keyword(input, &k) && input.peek2(syn::token::Paren) => {
            Ok(Item::Effect(parse_effect(input)?))
        }
        _ => Err(syn::Error::new(
            kw.span(),
            format!(
                "unknown statement `{kw}`: expected param, let, dof, input, body, frame, point, TOG[…], fn, extern fn, effect, scene, option or an effect such as gravity(…)"
            ),
        )),
    }
}

fn parse_effect(input: ParseStream) -> syn::Result<EffectStmt> {
    let kind: Ident = input.parse()?;
    parse_call(input, kind)
}

/// The arguments of a call `kind(…);` and its `;`.
fn parse_call(input: ParseStream, kind: Ident) -> syn::Result<EffectStmt> {
    let args;
    parenthesized!(args in input);
    let list: Punctuated<Expr, Token![,]> = args.parse_terminated(Expr::parse, Token![,])?;
    semi(input, &format!("`{kind}(…)`"))?;
    let mut positional = Vec::new();
    let mut named = Vec::new();
    for a in list {
        match a {
            Expr::Assign(asg) => match &*asg.left {
                Expr::Path(p) if p.path.get_ident().is_some() => {
                    named.push((p.path.get_ident().unwrap().clone(), *asg.right));
                }
                other => {
                    return Err(syn::Error::new_spanned(
                        other,
                        "expected an argument name before `=`",
                    ));
                }
            },
            e => {
                if !named.is_empty() {
                    // positional after named is allowed (`torque(b, axis = z, expr)`)
                }
                positional.push(e);
            }
        }
    }
    Ok(EffectStmt {
        kind,
        positional,
        named,
    })
}
