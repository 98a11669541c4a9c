//! The expansion pass between the tokens and `parse`: `for` loops and `part`s are unrolled
//! by token substitution, and indexed names (`bar[3]`) become single identifiers.
//!
//! - `for i in A..B { statements }` (or `A..=B`; nestable; at model level and inside `effect`
//!   blocks) repeats its statements with `i` replaced by each integer in turn;
//! - `part Name(a, b, …) { statements }` declares a template, and `Name(x, y, …);` (at model
//!   level, in a loop or in another part) pastes its statements with every argument replaced
//!   by the tokens given for it (an integer when they evaluate to one);
//! - `name[k]` with `name` not one of `q`, `qd`, `qdd`, `u`, `TOG` and `k` a constant integer
//!   expression becomes the identifier `name·k` (`·`, U+00B7, never typed by users), shown as
//!   `name[k]` ([`display`]) and written `name_k` where it must be a Rust identifier
//!   ([`rust_ident`]).
//!
//! Substituted tokens keep the template's spans, so errors point at the template; each
//! statement carries its [`Origin`] (which loop iteration, which part instance), appended to
//! every error found in it.

use proc_macro2::{Delimiter, Group, Literal, Punct, Spacing, Span, TokenStream, TokenTree};
use std::rc::Rc;

/// Which instance of a repetition a statement comes from: "in `for i in 0..40`, i = 7", "in
/// part Leg, instance 3 (k = 2, …)", nested ones joined by "; "; `None` outside any.
pub type Origin = Option<Rc<str>>;

/// The separator of an indexed name's parts in its identifier.
pub const SEP: char = '·';

/// Names that are indexed by the language itself (coordinates, velocities, accelerations,
/// inputs, poses): their brackets are left alone.
const INDEXED_BY_LANGUAGE: [&str; 5] = ["q", "qd", "qdd", "u", "TOG"];

/// More instances than this in one loop is a mistake (a runaway range), not a model.
const MAX_ITERATIONS: i64 = 100_000;

/// `bar·3·1` → `bar[3][1]`; text without indexed names is returned unchanged. Works on whole
/// messages.
pub fn display(text: &str) -> String {
    if !text.contains(SEP) {
        return text.to_string();
    }
    let mut out = String::with_capacity(text.len() + 8);
    let mut open = false;
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        // a separator before an index; elsewhere (`N·m` in a message) the dot stays
        if c == SEP && chars.peek().is_some_and(|n| n.is_ascii_digit()) {
            if open {
                out.push(']');
            }
            out.push('[');
            open = true;
        } else {
            if open && !c.is_ascii_digit() {
                out.push(']');
                open = false;
            }
            out.push(c);
        }
    }
    if open {
        out.push(']');
    }
    out
}

/// `bar·3` → `bar_3`: an indexed name where it must be a Rust identifier (parameter fields).
pub fn rust_ident(name: &str) -> String {
    name.replace(SEP, "_")
}

/// "; `bar[…]` has the indices 0 to 39" when `name` is indexed and `candidates` hold other
/// indices of the same name; for unknown-name messages.
pub fn index_hint(name: &str, candidates: &[&str]) -> Option<String> {
    let (base, last) = name.rsplit_once(SEP)?;
    last.parse::<u64>().ok()?;
    let mut found: Vec<u64> = candidates
        .iter()
        .filter_map(|c| {
            let (b, l) = c.rsplit_once(SEP)?;
            (b == base).then(|| l.parse::<u64>().ok()).flatten()
        })
        .collect();
    if found.is_empty() {
        return None;
    }
    found.sort_unstable();
    found.dedup();
    let (lo, hi) = (found[0], found[found.len() - 1]);
    let shown = display(base);
    let which = if hi.checked_sub(lo).and_then(|d| d.checked_add(1)) == Some(found.len() as u64) {
        if lo == hi {
            format!("only the index {lo}")
        } else {
            format!("the indices {lo} to {hi}")
        }
    } else {
        let list: Vec<String> = found.iter().take(8).map(u64::to_string).collect();
        let more = if found.len() > 8 { ", …" } else { "" };
        format!("the indices {}{more}", list.join(", "))
    };
    Some(format!("; `{shown}[…]` is declared with {which}"))
}

/// Errors that several instances of one template repeat word for word (but for the
/// instance), reported once: at the first instance, which the message names.
pub fn dedupe(errors: Vec<syn::Error>) -> Vec<syn::Error> {
    let mut seen: Vec<(String, String)> = Vec::new();
    let mut out = Vec::with_capacity(errors.len());
    for e in errors.into_iter().flatten() {
        let msg = e.to_string();
        let at = ["; in `for ", "; in part ", " (in `for ", " (in part "]
            .iter()
            .filter_map(|m| msg.find(m))
            .min();
        let Some(at) = at else {
            out.push(e);
            continue;
        };
        let (base, origin) = msg.split_at(at);
        // the template: each frame without its values
        let template: Vec<&str> = origin
            .split("; in ")
            .map(|f| match (f.find("`, "), f.find(", instance")) {
                (Some(k), _) if f.contains("for ") => &f[..k],
                (_, Some(k)) => &f[..k],
                _ => f,
            })
            .collect();
        let key = (base.to_string(), template.join("; "));
        if !seen.contains(&key) {
            seen.push(key);
            out.push(e);
        }
    }
    out
}

/// One statement after expansion.
pub struct Stmt {
    pub tokens: TokenStream,
    /// where an error at the end of the statement points (the next token)
    pub end: Span,
    pub origin: Origin,
    /// for `effect NAME { … }`: its statements, expanded (then `tokens` is `effect NAME`)
    pub inner: Option<Vec<Stmt>>,
}

#[derive(Clone)]
enum Binding {
    Int(i64),
    Tokens(TokenStream),
}

#[derive(Clone)]
struct Part {
    name: proc_macro2::Ident,
    args: Vec<proc_macro2::Ident>,
    body: TokenStream,
    /// instances so far, for messages
    instances: Rc<std::cell::Cell<usize>>,
}

struct Expander {
    parts: Vec<Part>,
    /// parts whose declaration has an error (reported): their instances are skipped
    broken: Vec<String>,
    errors: Vec<syn::Error>,
    /// the parts being instantiated, outermost first: a part met again among them
    /// instantiates itself
    instantiating: Vec<String>,
}

/// Expands a model's statements (the tokens inside `model Name { … }`); `end` is the span of
/// its closing brace. Errors (with their origin) go to `errors`.
pub fn expand(content: TokenStream, end: Span, errors: &mut Vec<syn::Error>) -> Vec<Stmt> {
    let mut ex = Expander {
        parts: Vec::new(),
        broken: Vec::new(),
        errors: Vec::new(),
        instantiating: Vec::new(),
    };
    separator_written(content.clone(), errors);
    let stmts = split(content, end);
    // parts first: a part may be instantiated above its declaration
    let mut rest = Vec::new();
    for (s, end) in stmts {
        if starts_with(&s, "part") {
            ex.declare_part(s);
        } else {
            rest.push((s, end));
        }
    }
    let mut out = Vec::new();
    ex.statements(rest, &[], &None, &mut out, false);
    errors.append(&mut ex.errors);
    out
}

/// An error for each name written with [`SEP`], which only the expansion writes (`b[0]`
/// becomes `b·0`): written by hand it would name an instance, or collide with one.
fn separator_written(tokens: TokenStream, errors: &mut Vec<syn::Error>) {
    for t in tokens {
        match t {
            TokenTree::Ident(i) if i.to_string().contains(SEP) => errors.push(syn::Error::new(
                i.span(),
                format!("`{SEP}` is reserved for the instances of indexed names: write `b[0]`, not `{i}`"),
            )),
            TokenTree::Group(g) => separator_written(g.stream(), errors),
            _ => {}
        }
    }
}

fn starts_with(s: &[TokenTree], kw: &str) -> bool {
    matches!(s.first(), Some(TokenTree::Ident(i)) if i == kw)
}

/// Splits statement tokens: up to and including a `;`, or up to and including a `{ … }`
/// block. Each statement comes with the span of the token after it (or `end`).
fn split(content: TokenStream, end: Span) -> Vec<(Vec<TokenTree>, Span)> {
    let mut out: Vec<(Vec<TokenTree>, Span)> = Vec::new();
    let mut cur = Vec::new();
    for t in content {
        if cur.is_empty() {
            if let Some(last) = out.last_mut() {
                last.1 = t.span();
            }
        }
        let done = match &t {
            TokenTree::Punct(p) => p.as_char() == ';',
            TokenTree::Group(g) => g.delimiter() == Delimiter::Brace,
            _ => false,
        };
        cur.push(t);
        if done {
            out.push((std::mem::take(&mut cur), end));
        }
    }
    if !cur.is_empty() {
        out.push((cur, end));
    }
    out
}

/// "in `for i in 0..40`, i = 7" appended to the origin around it.
fn nest(outer: &Origin, inner: String) -> Origin {
    Some(match outer {
        None => inner.into(),
        Some(o) => format!("{o}; {inner}").into(),
    })
}

/// `msg` with the origin appended: "…; in `for i in 0..40`, i = 7".
pub fn with_origin(msg: &str, origin: &Origin) -> String {
    let msg = display(msg);
    match origin {
        None => msg,
        Some(o) if msg.ends_with('?') => format!("{msg} ({o})"),
        Some(o) => format!("{msg}; {o}"),
    }
}

impl Expander {
    fn error(&mut self, span: Span, msg: impl std::fmt::Display, origin: &Origin) {
        self.errors
            .push(syn::Error::new(span, with_origin(&msg.to_string(), origin)));
    }

    fn declare_part(&mut self, s: Vec<TokenTree>) {
        let usage = "write `part Name(a, b, …) { statements }`";
        let kw = s[0].span();
        let (
            Some(TokenTree::Ident(name)),
            Some(TokenTree::Group(args)),
            Some(TokenTree::Group(body)),
            4,
        ) = (s.get(1), s.get(2), s.get(3), s.len())
        else {
            self.error(kw, format!("a part is declared with a name, its arguments in parentheses and its statements in braces: {usage}"), &None);
            return;
        };
        self.broken.push(name.to_string());
        if args.delimiter() != Delimiter::Parenthesis || body.delimiter() != Delimiter::Brace {
            self.error(kw, format!("expected the part's arguments in parentheses, then its statements in braces: {usage}"), &None);
            return;
        }
        if !name
            .to_string()
            .starts_with(|c: char| c.is_ascii_uppercase())
        {
            self.error(
                name.span(),
                format!("a part's name starts with an uppercase letter, which tells its instances from effects: `part {}…`", capitalised(&name.to_string())),
                &None,
            );
            return;
        }
        if self.parts.iter().any(|p| p.name == *name) {
            self.error(
                name.span(),
                format!("duplicate part `{name}`: rename one of the two"),
                &None,
            );
            return;
        }
        let mut list = Vec::new();
        let before = self.errors.len();
        let pieces = if args.stream().is_empty() {
            Vec::new()
        } else {
            comma_split(args.stream())
        };
        for (k, piece) in pieces.into_iter().enumerate() {
            match piece.as_slice() {
                [TokenTree::Ident(a)] => {
                    if list.iter().any(|b: &proc_macro2::Ident| b == a) {
                        self.error(
                            a.span(),
                            format!(
                                "part `{name}` has two arguments named `{a}`: rename one of them"
                            ),
                            &None,
                        );
                    } else if INDEXED_BY_LANGUAGE.contains(&a.to_string().as_str()) {
                        self.error(
                            a.span(),
                            format!(
                                "`{a}` is reserved: give argument {} of part `{name}` another name",
                                k + 1
                            ),
                            &None,
                        );
                    } else {
                        list.push(a.clone());
                    }
                }
                other => {
                    let span = other.first().map_or(args.span(), TokenTree::span);
                    self.error(
                        span,
                        format!("the arguments of a part are names: {usage}"),
                        &None,
                    );
                }
            }
        }
        if self.errors.len() > before {
            return;
        }
        self.broken.pop();
        self.parts.push(Part {
            name: name.clone(),
            args: list,
            body: body.stream(),
            instances: Rc::default(),
        });
    }

    /// Expands statements in `env`, appending them to `out`. `in_effect`: inside an `effect`
    /// block (only effect statements and loops).
    fn statements(
        &mut self,
        stmts: Vec<(Vec<TokenTree>, Span)>,
        env: &[(String, Binding)],
        origin: &Origin,
        out: &mut Vec<Stmt>,
        in_effect: bool,
    ) {
        for (s, end) in stmts {
            if starts_with(&s, "for") {
                self.for_loop(s, env, origin, out, in_effect);
                continue;
            }
            if starts_with(&s, "part") {
                self.error(
                    s[0].span(),
                    "a part is declared at model level, outside loops, effects and other parts",
                    origin,
                );
                continue;
            }
            // `Name(…);`: a part instance
            if let (Some(TokenTree::Ident(id)), Some(TokenTree::Group(g))) = (s.first(), s.get(1)) {
                let ends = match s.get(2) {
                    None => true,
                    Some(TokenTree::Punct(p)) => p.as_char() == ';' && s.len() == 3,
                    Some(_) => false,
                };
                if g.delimiter() == Delimiter::Parenthesis
                    && ends
                    && id != "TOG"
                    && id.to_string().starts_with(|c: char| c.is_ascii_uppercase())
                {
                    self.instance(&s, env, origin, out, in_effect);
                    continue;
                }
            }
            if !in_effect
                && starts_with(&s, "effect")
                && matches!(s.last(), Some(TokenTree::Group(g)) if g.delimiter() == Delimiter::Brace)
            {
                let Some(TokenTree::Group(block)) = s.last() else {
                    unreachable!()
                };
                let head: Vec<TokenTree> = s[..s.len() - 1].to_vec();
                let head = self.substitute(head.into_iter().collect(), env, origin);
                let mut inner = Vec::new();
                let stmts = split(block.stream(), block.span_close());
                self.statements(stmts, env, origin, &mut inner, true);
                out.push(Stmt {
                    tokens: head,
                    end: block.span_open(),
                    origin: origin.clone(),
                    inner: Some(inner),
                });
                continue;
            }
            let tokens = self.substitute(s.into_iter().collect(), env, origin);
            out.push(Stmt {
                tokens,
                end,
                origin: origin.clone(),
                inner: None,
            });
        }
    }

    fn for_loop(
        &mut self,
        s: Vec<TokenTree>,
        env: &[(String, Binding)],
        origin: &Origin,
        out: &mut Vec<Stmt>,
        in_effect: bool,
    ) {
        let usage = "write `for i in 0..n { statements }`";
        let kw = s[0].span();
        let var = match s.get(1) {
            Some(TokenTree::Ident(v)) => v.clone(),
            _ => {
                self.error(
                    kw,
                    format!("expected the loop variable after `for`: {usage}"),
                    origin,
                );
                return;
            }
        };
        if !matches!(s.get(2), Some(TokenTree::Ident(i)) if i == "in") {
            self.error(
                s.get(2).map_or(kw, TokenTree::span),
                format!("expected `in` after `for {var}`: {usage}"),
                origin,
            );
            return;
        }
        let Some(TokenTree::Group(body)) = s
            .last()
            .filter(|t| matches!(t, TokenTree::Group(g) if g.delimiter() == Delimiter::Brace))
        else {
            self.error(
                kw,
                format!("expected the loop's statements in braces: {usage}"),
                origin,
            );
            return;
        };
        if s.len() < 5 {
            self.error(
                var.span(),
                format!("expected a range after `for {var} in`: {usage}"),
                origin,
            );
            return;
        }
        if INDEXED_BY_LANGUAGE.contains(&var.to_string().as_str()) || var == "t" {
            self.error(
                var.span(),
                format!("`{var}` is reserved: give the loop variable another name"),
                origin,
            );
            return;
        }
        let range_tokens: TokenStream = s[3..s.len() - 1].iter().cloned().collect();
        let range_span = s[3].span();
        let range_tokens = self.substitute_vars(range_tokens, env);
        let range: syn::Expr = match syn::parse2(range_tokens) {
            Ok(e) => e,
            Err(e) => {
                self.error(
                    e.span(),
                    format!("expected a range `a..b` or `a..=b` of constant integers: {usage}"),
                    origin,
                );
                return;
            }
        };
        let syn::Expr::Range(r) = &range else {
            self.error(
                range_span,
                format!("expected a range `a..b` or `a..=b` of constant integers: {usage}"),
                origin,
            );
            return;
        };
        let (Some(a), Some(b)) = (&r.start, &r.end) else {
            self.error(
                range_span,
                format!("a loop range needs both ends: {usage}"),
                origin,
            );
            return;
        };
        let what = "a loop range";
        let (Some(a), Some(b)) = (self.int(a, what, origin), self.int(b, what, origin)) else {
            return;
        };
        let b = if matches!(r.limits, syn::RangeLimits::Closed(_)) {
            b.saturating_add(1)
        } else {
            b
        };
        if b.saturating_sub(a) > MAX_ITERATIONS {
            self.error(range_span, format!("`for {var} in {a}..{b}` repeats {} times: at most {MAX_ITERATIONS} instances per loop", i128::from(b) - i128::from(a)), origin);
            return;
        }
        let stmts = split(body.stream(), body.span_close());
        for v in a..b {
            let mut env = env.to_vec();
            env.push((var.to_string(), Binding::Int(v)));
            let o = nest(origin, format!("in `for {var} in {a}..{b}`, {var} = {v}"));
            self.statements(stmts.clone(), &env, &o, out, in_effect);
        }
    }

    fn instance(
        &mut self,
        s: &[TokenTree],
        env: &[(String, Binding)],
        origin: &Origin,
        out: &mut Vec<Stmt>,
        in_effect: bool,
    ) {
        let (TokenTree::Ident(id), TokenTree::Group(g)) = (&s[0], &s[1]) else {
            unreachable!("checked by the caller")
        };
        let Some(part) = self.parts.iter().find(|p| p.name == *id).cloned() else {
            if self.broken.iter().any(|b| id == b) {
                return; // its declaration's error is reported
            }
            let names: Vec<String> = self.parts.iter().map(|p| p.name.to_string()).collect();
            let hint = super::names::did_you_mean(
                &id.to_string(),
                names.iter().map(String::as_str),
                &format!(
                    "declare it with `part {id}(…) {{ … }}` (effects, such as `gravity(…)`, are written in lowercase)"
                ),
            );
            self.error(id.span(), format!("unknown part `{id}`{hint}"), origin);
            return;
        };
        if !matches!(s.get(2), Some(TokenTree::Punct(p)) if p.as_char() == ';') || s.len() != 3 {
            let span = s.get(2).map_or(g.span_close(), TokenTree::span);
            self.error(
                span,
                format!("expected `;` after the instance `{id}(…)`"),
                origin,
            );
            return;
        }
        let args = if g.stream().is_empty() {
            Vec::new()
        } else {
            comma_split(g.stream())
        };
        if args.len() != part.args.len() {
            let list: Vec<String> = part.args.iter().map(ToString::to_string).collect();
            self.error(
                g.span(),
                format!(
                    "part `{id}` takes {} ({}), found {}: write `{id}({});`",
                    count(part.args.len(), "argument"),
                    list.join(", "),
                    args.len(),
                    list.join(", ")
                ),
                origin,
            );
            return;
        }
        let name = id.to_string();
        if let Some(k) = self.instantiating.iter().position(|p| *p == name) {
            let how = super::names::through(&self.instantiating[k + 1..]);
            self.error(id.span(), format!("part `{id}` instantiates itself{how}: a part cannot be recursive; repeat its statements with `for` instead"), &None);
            return;
        }
        let n = part.instances.get() + 1;
        part.instances.set(n);
        let mut inner_env: Vec<(String, Binding)> = Vec::new();
        let mut shown = Vec::new();
        for (name, arg) in part.args.iter().zip(args) {
            let tokens = self.substitute(arg.into_iter().collect(), env, origin);
            let b = match syn::parse2::<syn::Expr>(tokens.clone())
                .ok()
                .and_then(|e| exact(&e))
            {
                Some(v) => Binding::Int(v),
                None => Binding::Tokens(tokens.clone()),
            };
            shown.push(match &b {
                Binding::Int(v) => format!("{name} = {v}"),
                Binding::Tokens(t) => format!("{name} = {}", display(&super::check::text(t))),
            });
            inner_env.push((name.to_string(), b));
        }
        let o = nest(
            origin,
            format!("in part {id}, instance {n} ({})", shown.join(", ")),
        );
        let stmts = split(part.body.clone(), id.span());
        self.instantiating.push(name);
        self.statements(stmts, &inner_env, &o, out, in_effect);
        self.instantiating.pop();
    }

    /// Replaces bound names only (no index folding): for loop ranges.
    fn substitute_vars(&self, ts: TokenStream, env: &[(String, Binding)]) -> TokenStream {
        let tokens: Vec<TokenTree> = ts.into_iter().collect();
        let mut out = Vec::with_capacity(tokens.len());
        for (k, t) in tokens.iter().enumerate() {
            match t {
                // a group left as it is keeps the spans of its delimiters
                TokenTree::Group(g) if !touches(&g.stream(), env) => out.push(t.clone()),
                TokenTree::Group(g) => {
                    let mut ng = Group::new(g.delimiter(), self.substitute_vars(g.stream(), env));
                    ng.set_span(g.span());
                    out.push(TokenTree::Group(ng));
                }
                TokenTree::Ident(id) if !is_key(&tokens, k) => {
                    match env.iter().rev().find(|(n, _)| id == n) {
                        Some((_, b)) => out.extend(bound_tokens(b, id.span())),
                        None => out.push(t.clone()),
                    }
                }
                _ => out.push(t.clone()),
            }
        }
        out.into_iter().collect()
    }

    /// Replaces bound names, then folds `name[k]` into `name·k`, in every group.
    fn substitute(
        &mut self,
        ts: TokenStream,
        env: &[(String, Binding)],
        origin: &Origin,
    ) -> TokenStream {
        let ts = self.substitute_vars(ts, env);
        self.fold_indices(ts, origin)
    }

    fn fold_indices(&mut self, ts: TokenStream, origin: &Origin) -> TokenStream {
        let mut out: Vec<TokenTree> = Vec::new();
        for t in ts {
            // `q[2 * 0 + 1]` after substitution: the language's vectors take the value
            let value = match &t {
                TokenTree::Group(g) if vector_of_language(out.last()) => constant(g),
                _ => None,
            };
            if let Some(v) = value {
                let mut lit = Literal::u64_unsuffixed(v);
                lit.set_span(t.span());
                let mut ng = Group::new(Delimiter::Bracket, TokenTree::Literal(lit).into());
                ng.set_span(t.span());
                out.push(TokenTree::Group(ng));
                continue;
            }
            match t {
                TokenTree::Group(g)
                    if !(touches(&g.stream(), &[])
                        || g.delimiter() == Delimiter::Bracket && indexable(out.last())) =>
                {
                    out.push(TokenTree::Group(g));
                }
                TokenTree::Group(g) => {
                    let inner = self.fold_indices(g.stream(), origin);
                    if g.delimiter() == Delimiter::Bracket && indexable(out.last()) {
                        let Some(TokenTree::Ident(id)) = out.pop() else {
                            unreachable!()
                        };
                        let shown = display(&id.to_string());
                        let value = match syn::parse2::<syn::Expr>(inner.clone()) {
                            Ok(e) => match eval(&e) {
                                Ok(v) => Some(v),
                                Err((span, why)) => {
                                    self.error(span, format!("the index of `{shown}[…]` must be a constant integer: {why}"), origin);
                                    None
                                }
                            },
                            Err(_) => {
                                self.error(g.span(), format!("the index of `{shown}[…]` must be a constant integer expression, such as `i`, `i - 1` or `2 * i + 1`"), origin);
                                None
                            }
                        };
                        match value {
                            Some(v) if v >= 0 => {
                                let base = id.to_string();
                                let base = base.trim_start_matches("r#");
                                out.push(TokenTree::Ident(proc_macro2::Ident::new(
                                    &format!("{base}{SEP}{v}"),
                                    id.span(),
                                )));
                            }
                            Some(v) => {
                                self.error(g.span(), format!("`{shown}[{v}]`: indices start at 0, so there is no `{shown}[{v}]`; start the loop one later (`for i in 1..n`) and write the first instance apart"), origin);
                                out.push(TokenTree::Ident(id));
                            }
                            None => out.push(TokenTree::Ident(id)),
                        }
                        continue;
                    }
                    let mut ng = Group::new(g.delimiter(), inner);
                    ng.set_span(g.span());
                    out.push(TokenTree::Group(ng));
                }
                other => out.push(other),
            }
        }
        out.into_iter().collect()
    }
}

/// Whether `[…]` after this token indexes a vector of the language (`q`, `qd`, `qdd`, `u`):
/// a constant integer expression there is replaced by its value.
fn vector_of_language(before: Option<&TokenTree>) -> bool {
    matches!(before, Some(TokenTree::Ident(id)) if matches!(id.to_string().as_str(), "q" | "qd" | "qdd" | "u"))
}

/// The value of `[…]` when it is a constant integer expression of more than one token (a
/// lone number or name stays as written).
fn constant(g: &Group) -> Option<u64> {
    if g.delimiter() != Delimiter::Bracket || g.stream().into_iter().count() < 2 {
        return None;
    }
    let e = syn::parse2::<syn::Expr>(g.stream()).ok()?;
    eval(&e).ok().and_then(|v| u64::try_from(v).ok())
}

/// Whether `[…]` after this token is an index to fold into a name.
fn indexable(before: Option<&TokenTree>) -> bool {
    match before {
        Some(TokenTree::Ident(id)) => {
            let s = id.to_string();
            !INDEXED_BY_LANGUAGE.contains(&s.as_str()) && !is_keyword(&s)
        }
        _ => false,
    }
}

/// Whether substitution or folding would change `ts`: a bound name or an index to fold.
fn touches(ts: &TokenStream, env: &[(String, Binding)]) -> bool {
    let mut before: Option<TokenTree> = None;
    for t in ts.clone() {
        match &t {
            TokenTree::Ident(id) if env.iter().any(|(n, _)| id == n) => return true,
            TokenTree::Group(g) => {
                if g.delimiter() == Delimiter::Bracket && indexable(before.as_ref())
                    || vector_of_language(before.as_ref()) && constant(g).is_some()
                {
                    return true;
                }
                if touches(&g.stream(), env) {
                    return true;
                }
            }
            _ => {}
        }
        before = Some(t);
    }
    false
}

/// Words after which `[…]` is not an index: `= [a, b]` lists follow keywords' `=` and never
/// a name, but `in [..]` or `at [..]` must not fold.
fn is_keyword(s: &str) -> bool {
    matches!(s, "in" | "at" | "on" | "fn" | "extern")
}

/// An identifier that names an argument or a property (`k = …` right after `(`, `{`, `,` or
/// `;`): never substituted.
fn is_key(tokens: &[TokenTree], k: usize) -> bool {
    let eq_next = matches!(tokens.get(k + 1), Some(TokenTree::Punct(p)) if p.as_char() == '=' && p.spacing() == Spacing::Alone);
    let after_sep = k == 0
        || matches!(&tokens[k - 1], TokenTree::Punct(p) if p.as_char() == ',' || p.as_char() == ';');
    eq_next && after_sep
}

fn bound_tokens(b: &Binding, span: Span) -> Vec<TokenTree> {
    match b {
        Binding::Int(v) => {
            let mut lit = Literal::u64_unsuffixed(v.unsigned_abs());
            lit.set_span(span);
            if *v >= 0 {
                vec![TokenTree::Literal(lit)]
            } else {
                let mut minus = Punct::new('-', Spacing::Alone);
                minus.set_span(span);
                let mut g = Group::new(
                    Delimiter::Parenthesis,
                    [TokenTree::Punct(minus), TokenTree::Literal(lit)]
                        .into_iter()
                        .collect(),
                );
                g.set_span(span);
                vec![TokenTree::Group(g)]
            }
        }
        Binding::Tokens(t) => {
            let v: Vec<TokenTree> = t.clone().into_iter().collect();
            if v.len() == 1 {
                v
            } else {
                // keeps the argument one operand: `2 * hx` with hx = `-0.4 + d`
                let mut g = Group::new(Delimiter::Parenthesis, t.clone());
                g.set_span(span);
                vec![TokenTree::Group(g)]
            }
        }
    }
}

/// Splits on top-level commas.
fn comma_split(ts: TokenStream) -> Vec<Vec<TokenTree>> {
    let mut out = vec![Vec::new()];
    for t in ts {
        if matches!(&t, TokenTree::Punct(p) if p.as_char() == ',') {
            out.push(Vec::new());
        } else {
            out.last_mut().expect("never empty").push(t);
        }
    }
    if out.last().is_some_and(Vec::is_empty) && out.len() > 1 {
        out.pop();
    }
    out
}

fn count(n: usize, what: &str) -> String {
    if n == 1 {
        format!("1 {what}")
    } else {
        format!("{n} {what}s")
    }
}

fn capitalised(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        Some(f) => f.to_uppercase().chain(c).collect(),
        None => String::new(),
    }
}

/// Integer arithmetic on literals: `+ - * / %` (`/` and `%` as Rust's on integers), unary
/// minus, parentheses. The error names the offending tokens.
fn eval(e: &syn::Expr) -> Result<i64, (Span, String)> {
    use syn::spanned::Spanned;
    use syn::{BinOp, Expr, Lit};
    let overflow = |e: &Expr| (e.span(), "the arithmetic overflows".to_string());
    match e {
        Expr::Lit(l) => match &l.lit {
            Lit::Int(i) => i
                .base10_parse::<i64>()
                .map_err(|x| (i.span(), x.to_string())),
            other => Err((
                other.span(),
                format!("`{}` is not an integer", super::check::text(other)),
            )),
        },
        Expr::Paren(p) => eval(&p.expr),
        Expr::Group(g) => eval(&g.expr),
        Expr::Unary(u) if matches!(u.op, syn::UnOp::Neg(_)) => {
            eval(&u.expr)?.checked_neg().ok_or_else(|| overflow(e))
        }
        Expr::Binary(b) => {
            let (x, y) = (eval(&b.left)?, eval(&b.right)?);
            let r = match b.op {
                BinOp::Add(_) => x.checked_add(y),
                BinOp::Sub(_) => x.checked_sub(y),
                BinOp::Mul(_) => x.checked_mul(y),
                BinOp::Div(_) | BinOp::Rem(_) if y == 0 => {
                    return Err((b.right.span(), "division by zero".to_string()));
                }
                BinOp::Div(_) => x.checked_div(y),
                BinOp::Rem(_) => x.checked_rem(y),
                _ => {
                    return Err((
                        b.op.span(),
                        format!(
                            "`{}` is not integer arithmetic (+ - * / %)",
                            super::check::text(&b.op)
                        ),
                    ));
                }
            };
            r.ok_or_else(|| overflow(e))
        }
        Expr::Path(p) => Err((
            p.span(),
            format!(
                "`{}` is not a loop variable or an integer argument of a part (parameters and other names can change at run time)",
                display(&super::check::text(p))
            ),
        )),
        other => Err((
            other.span(),
            format!(
                "`{}` is not integer arithmetic (+ - * / %)",
                display(&super::check::text(other))
            ),
        )),
    }
}

/// The integer value of `e` when integer arithmetic and real arithmetic agree on it (a part's
/// argument bound as a number); `None` when a division has a remainder (`3 / 2`): the
/// argument is then pasted as its tokens, so that in a scalar position it is 1.5, as the
/// statement written out would be, where an integer binding made it 1.
fn exact(e: &syn::Expr) -> Option<i64> {
    use syn::{BinOp, Expr, Lit};
    fn real(e: &Expr) -> Option<f64> {
        match e {
            Expr::Lit(l) => match &l.lit {
                Lit::Int(i) => i.base10_parse::<f64>().ok(),
                _ => None,
            },
            Expr::Paren(p) => real(&p.expr),
            Expr::Group(g) => real(&g.expr),
            Expr::Unary(u) if matches!(u.op, syn::UnOp::Neg(_)) => real(&u.expr).map(|x| -x),
            Expr::Binary(b) => {
                let (x, y) = (real(&b.left)?, real(&b.right)?);
                match b.op {
                    BinOp::Add(_) => Some(x + y),
                    BinOp::Sub(_) => Some(x - y),
                    BinOp::Mul(_) => Some(x * y),
                    BinOp::Div(_) => Some(x / y),
                    BinOp::Rem(_) => Some(x % y),
                    _ => None,
                }
            }
            _ => None,
        }
    }
    let v = eval(e).ok()?;
    (real(e)? == v as f64).then_some(v)
}

impl Expander {
    fn int(&mut self, e: &syn::Expr, what: &str, origin: &Origin) -> Option<i64> {
        match eval(e) {
            Ok(v) => Some(v),
            Err((span, why)) => {
                self.error(
                    span,
                    format!("{what} must be constant integers: {why}"),
                    origin,
                );
                None
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_show_and_map() {
        assert_eq!(display("unknown body `bar·40`"), "unknown body `bar[40]`");
        assert_eq!(display("a·1·2 and b·3"), "a[1][2] and b[3]");
        // a middle dot that is not before an index is text: units in messages
        assert_eq!(display("k of bar·2 in N·m/rad"), "k of bar[2] in N·m/rad");
        assert_eq!(rust_ident("k·3"), "k_3");
        assert_eq!(
            index_hint("bar·40", &["bar·0", "bar·1", "bar·2", "base"]).as_deref(),
            Some("; `bar[…]` is declared with the indices 0 to 2")
        );
        assert_eq!(index_hint("bar", &["bar·0"]), None);
    }

    #[test]
    fn an_error_of_every_instance_is_reported_once() {
        let e = |m: &str| syn::Error::new(Span::call_site(), m);
        let kept = dedupe(vec![
            e("unknown name `y`; in `for i in 0..3`, i = 0"),
            e("unknown name `y`; in `for i in 0..3`, i = 1"),
            e("unknown name `z`; in `for i in 0..3`, i = 1"),
            e("unknown name `y`; in part Leg, instance 1 (k = 0)"),
            e("unknown name `y`; did you mean `t`? (in part Leg, instance 2 (k = 1))"),
            e("unknown name `y`"),
            e("unknown name `y`"),
        ]);
        let kept: Vec<String> = kept.iter().map(ToString::to_string).collect();
        assert_eq!(
            kept,
            [
                "unknown name `y`; in `for i in 0..3`, i = 0",
                "unknown name `z`; in `for i in 0..3`, i = 1",
                "unknown name `y`; in part Leg, instance 1 (k = 0)",
                "unknown name `y`; did you mean `t`? (in part Leg, instance 2 (k = 1))",
                "unknown name `y`",
                "unknown name `y`"
            ]
        );
    }
}
