//! The repository's models changed by one to three tokens (a token deleted, repeated, swapped
//! with its neighbour, a number, a name or an operator replaced), as a user's typing slips
//! would: every mutant that lexes goes through the generator as `multibody!` gives it.
//! Asserted: the generator never panics and always returns; an expansion that succeeds emits
//! code that parses and names no `inf` or `NaN` (Display's text of a number that is not
//! finite, which parses as a name: a mass of 1e308 gave a default shape of radius `inf`); one
//! that fails carries messages that name the construct, not only the
//! token the parser expected (syn's bare "expected an expression" is completed by how its
//! statement is written), and a stub that parses (so that the user's code does not cascade
//! into more errors). The tokens of `///` comments are left alone: no slip reaches them.
//!
//! `cargo test --release -p mbs-symbolic --test mutations -- --nocapture` prints the count of
//! each outcome per model; `MUTATION_SCALE=10` sweeps ten times as many mutants of each
//! model (at most 250 a block at the default scale), `MUTANTS_CRATE=dir` writes those that generate into a crate
//! to compile.

mod common;
use common::Rng;
use mbs_symbolic::expand::{Expansion, expand_models, multibody_blocks};
use proc_macro2::{Delimiter, Group, Ident, Punct, Spacing, Span, TokenStream, TokenTree};
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// Numbers a slip or a bad value puts in place of a literal.
const NUMBERS: [&str; 10] = [
    "0", "0.0", "-1.0", "1e308", "1e-308", "65", "1000000", "3", "2.5", "-0",
];
/// Operators a slip puts in place of another.
const PUNCTS: [char; 10] = ['+', '-', '*', '/', ',', ';', '=', '.', ':', '^'];
/// Names of the language a slip puts in place of another name.
const NAMES: [&str; 12] = [
    "Trotz", "Trotx", "Tdisp", "Tfree", "q", "t", "TOG", "body", "dof", "param", "sin", "powi",
];

/// One change of one leaf token (an identifier, a literal or a punctuation mark).
#[derive(Clone, Debug)]
enum Change {
    Delete,
    Repeat,
    /// the leaf and the next leaf of the same group exchanged
    SwapNext,
    Replace(String),
}

/// Whether `trees[i]` starts an attribute, `#[…]`: the lowered form of a `///` comment, whose
/// tokens no typing slip reaches (they are left out of the leaves).
fn attribute_at(trees: &[TokenTree], i: usize) -> bool {
    matches!(&trees[i], TokenTree::Punct(p) if p.as_char() == '#')
        && matches!(trees.get(i + 1), Some(TokenTree::Group(g)) if g.delimiter() == Delimiter::Bracket)
}

/// The leaves of `ts` in order, depth first, but those of attributes.
fn leaves(ts: &TokenStream, out: &mut Vec<TokenTree>) {
    let trees: Vec<TokenTree> = ts.clone().into_iter().collect();
    let mut i = 0;
    while i < trees.len() {
        if attribute_at(&trees, i) {
            i += 2;
            continue;
        }
        match &trees[i] {
            TokenTree::Group(g) => leaves(&g.stream(), out),
            leaf => out.push(leaf.clone()),
        }
        i += 1;
    }
}

/// The tokens of `text`: a name, a number (a negative one is two tokens) or an operator.
fn tokens_of(text: &str) -> Vec<TokenTree> {
    if let Some(c) = text.chars().next().filter(|_| text.len() == 1)
        && !c.is_alphanumeric()
    {
        return vec![TokenTree::Punct(Punct::new(c, Spacing::Alone))];
    }
    if text.starts_with(|c: char| c.is_ascii_digit() || c == '-') {
        return text
            .parse::<TokenStream>()
            .expect("a number")
            .into_iter()
            .collect();
    }
    vec![TokenTree::Ident(Ident::new(text, Span::call_site()))]
}

/// `ts` with the change applied to its leaf number `target` (depth first).
fn mutate(ts: TokenStream, counter: &mut usize, target: usize, change: &Change) -> TokenStream {
    let trees: Vec<TokenTree> = ts.into_iter().collect();
    let mut out: Vec<TokenTree> = Vec::with_capacity(trees.len() + 1);
    let mut i = 0;
    while i < trees.len() {
        if attribute_at(&trees, i) {
            out.extend(trees[i..i + 2].iter().cloned());
            i += 2;
            continue;
        }
        match &trees[i] {
            TokenTree::Group(g) => {
                let inner = mutate(g.stream(), counter, target, change);
                let mut ng = Group::new(g.delimiter(), inner);
                ng.set_span(g.span());
                out.push(TokenTree::Group(ng));
            }
            leaf => {
                if *counter == target {
                    match change {
                        Change::Delete => {}
                        Change::Repeat => {
                            out.push(leaf.clone());
                            out.push(leaf.clone());
                        }
                        Change::SwapNext => match trees.get(i + 1) {
                            // the counter has passed the target: it is not met again
                            Some(next) => {
                                out.push(next.clone());
                                out.push(leaf.clone());
                                *counter += 1;
                                i += 2;
                                continue;
                            }
                            None => out.push(leaf.clone()),
                        },
                        Change::Replace(text) => out.extend(tokens_of(text)),
                    }
                } else {
                    out.push(leaf.clone());
                }
                *counter += 1;
            }
        }
        i += 1;
    }
    out.into_iter().collect()
}

/// A replacement for `leaf`: a number for a number, else a name of the model or of the
/// language for a name, an operator for an operator.
fn replacement(leaf: &TokenTree, names: &[String], rng: &mut Rng) -> String {
    match leaf {
        TokenTree::Literal(_) => NUMBERS[rng.below(NUMBERS.len())].to_string(),
        // an operator mostly for an operator, so that more mutants reach the generator
        TokenTree::Punct(p) if "+-*/".contains(p.as_char()) && rng.below(2) == 0 => {
            PUNCTS[rng.below(4)].to_string()
        }
        TokenTree::Punct(_) => PUNCTS[rng.below(PUNCTS.len())].to_string(),
        _ => {
            if rng.below(3) == 0 {
                NAMES[rng.below(NAMES.len())].to_string()
            } else {
                names[rng.below(names.len())].clone()
            }
        }
    }
}

/// What the generator made of one mutant.
#[derive(Debug, PartialEq, Eq, Hash, Clone, Copy, PartialOrd, Ord)]
enum Outcome {
    /// the tokens are not a `multibody!` block (syn's parse)
    Syntax,
    /// a model's error with its message
    Refused,
    /// generated code
    Generated,
}

/// A broken promise for one mutant, as text.
type Broken = String;

/// Whether a message says only which token the parser expected ("expected an expression"),
/// not what is written there.
fn bare(message: &str) -> bool {
    (message.starts_with("expected ") || message.starts_with("unexpected "))
        && !message.contains(": ")
        && !message.contains("write")
        && !message.contains('…')
        && !message.contains("found `")
}

/// The messages of `e` that say nothing beyond [`bare`].
fn bare_messages(e: syn::Error) -> Option<String> {
    let bare: Vec<String> = e
        .into_iter()
        .map(|m| m.to_string())
        .filter(|m| bare(m))
        .collect();
    (!bare.is_empty()).then(|| bare.join(" | "))
}

/// Refusals whose message the parser's bare one was completed into.
static COMPLETED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// Expands `tokens` and checks what comes out.
fn judge(tokens: TokenStream) -> Result<Vec<Outcome>, Broken> {
    let expansions = match expand_models(tokens) {
        Ok(e) => e,
        Err(e) => {
            let m = e.to_string();
            return if m.trim().is_empty() {
                Err("a syntax error without a message".into())
            } else if let Some(b) = bare_messages(e) {
                Err(format!("a syntax error that names no construct: {b}"))
            } else {
                Ok(vec![Outcome::Syntax])
            };
        }
    };
    let mut outcomes = Vec::new();
    for e in expansions {
        match e {
            Expansion::Ok { name, generated } => {
                if let Err(err) = syn::parse_file(&generated.code) {
                    return Err(format!(
                        "model `{name}`: generated code does not parse: {err}"
                    ));
                }
                // a number Display wrote (`inf`, `NaN`) parses as a name and does not compile
                if let Some(word) = generated
                    .code
                    .split(|c: char| !c.is_alphanumeric() && c != '_')
                    .find(|w| matches!(*w, "inf" | "NaN"))
                {
                    return Err(format!("model `{name}`: generated code names `{word}`"));
                }
                outcomes.push(Outcome::Generated);
            }
            Expansion::Err { name, error, stub } => {
                if error.to_string().trim().is_empty() {
                    return Err(format!("model `{name}`: an error without a message"));
                }
                let text = error.to_string();
                if text.contains("this statement is written")
                    || text.contains("a statement starts with")
                {
                    COMPLETED.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                }
                if let Some(b) = bare_messages(error) {
                    return Err(format!(
                        "model `{name}`: an error that names no construct: {b}"
                    ));
                }
                if let Err(err) = syn::parse_file(&stub) {
                    return Err(format!(
                        "model `{name}`: its error stub does not parse: {err}"
                    ));
                }
                outcomes.push(Outcome::Refused);
            }
        }
    }
    Ok(outcomes)
}

/// The source files of the repository's models.
fn model_files() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/src");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("models/src")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "rs"))
        .collect();
    files.sort();
    files
}

/// A crate of the mutants that generate, each block in a module of its own, to compile them
/// (`MUTANTS_CRATE=dir cargo test --release -p mbs-symbolic --test mutations`, then `cargo
/// build --release --manifest-path dir/Cargo.toml`): what parses may still not compile.
fn write_crate(dir: &Path, generated: &[(String, String)]) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let root = root.canonicalize().expect("the repository");
    std::fs::create_dir_all(dir.join("src")).expect("the crate's folder");
    let manifest = format!(
        "[package]\nname = \"mbs-mutants\"\nversion = \"0.0.0\"\nedition = \"2024\"\npublish = false\n\n\
         [dependencies]\nmbs = {{ path = {:?} }}\n\n[workspace]\n",
        root.display().to_string()
    );
    std::fs::write(dir.join("Cargo.toml"), manifest).expect("Cargo.toml");
    let mut lib = String::from("#![allow(dead_code, unused)]\n");
    for (i, (what, tokens)) in generated.iter().enumerate() {
        lib += &format!(
            "// {}\npub mod m{i} {{ mbs::multibody! {{ {tokens} }} }}\n",
            what.replace('\n', " ")
        );
    }
    std::fs::write(dir.join("src/lib.rs"), lib).expect("lib.rs");
}

/// Longest a mutant may take before the sweep calls it a hang.
const HANG: Duration = Duration::from_secs(120);

#[test]
fn typing_slips_never_panic_or_hang_the_generator_and_are_named() {
    // the generator's panics are what this test looks for: silence the default hook's text
    std::panic::set_hook(Box::new(|_| {}));
    // `MUTATION_SCALE=10` sweeps ten times as many mutants of each model
    let scale: f64 = std::env::var("MUTATION_SCALE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1.0);
    let mut broken: Vec<String> = Vec::new();
    let mut total = 0usize;
    let mut outcomes = Vec::new();
    // the mutants that generate, (what changed, tokens), for `MUTANTS_CRATE`
    let mut generated: Vec<(String, String)> = Vec::new();
    for file in model_files() {
        let text = std::fs::read_to_string(&file).expect("a model file");
        let Ok(parsed) = syn::parse_file(&text) else {
            continue;
        };
        let blocks = multibody_blocks(&parsed);
        if blocks.is_empty() {
            continue;
        }
        let name = file.file_stem().unwrap().to_string_lossy().to_string();
        for (b, block) in blocks.into_iter().enumerate() {
            // the unchanged block is timed: the mutants of a slow model are fewer
            let start = Instant::now();
            let base = judge(block.clone());
            let took = start.elapsed();
            assert!(
                matches!(&base, Ok(o) if o.iter().all(|&x| x == Outcome::Generated)),
                "{name} block {b} does not expand: {base:?}"
            );
            let mut all = Vec::new();
            leaves(&block, &mut all);
            // fewer mutants of a larger model, whose expansion takes longer: the same mutants
            // on every machine (a count from the time measured would not be)
            let count = (scale * 4e7 / (all.len() as f64).powi(2))
                .clamp(4.0, 250.0 * scale.max(1.0)) as usize;
            let names: Vec<String> = all
                .iter()
                .filter_map(|t| match t {
                    TokenTree::Ident(i) => Some(i.to_string()),
                    _ => None,
                })
                .collect();
            // seeded by the mutants before: the same mutants on every run
            let mut rng = Rng::new(0x5eed ^ total as u64);
            let mut tally = std::collections::BTreeMap::<Outcome, usize>::new();
            let mut lexed = 0usize;
            for _ in 0..count {
                // one to three changes, each at a leaf of the mutant so far
                let mut mutant = block.clone();
                let mut what = format!("{name} block {b}:");
                for _ in 0..1 + rng.below(3) {
                    let mut now = Vec::new();
                    leaves(&mutant, &mut now);
                    if now.is_empty() {
                        break;
                    }
                    let target = rng.below(now.len());
                    let change = match rng.below(5) {
                        0 => Change::Delete,
                        1 => Change::Repeat,
                        2 => Change::SwapNext,
                        _ => Change::Replace(replacement(&now[target], &names, &mut rng)),
                    };
                    what += &format!(" leaf {target} `{}` {change:?};", now[target]);
                    mutant = mutate(mutant, &mut 0, target, &change);
                }
                // as rustc would hand it over: the text lexed again (a mutant that does not
                // lex never reaches the macro)
                let Ok(tokens) = mutant.to_string().parse::<TokenStream>() else {
                    continue;
                };
                lexed += 1;
                let (tx, rx) = mpsc::channel();
                let text = tokens.to_string();
                std::thread::spawn(move || {
                    let tokens: TokenStream = text.parse().expect("lexed once");
                    let r = std::panic::catch_unwind(|| judge(tokens));
                    let _ = tx.send(r);
                });
                match rx.recv_timeout(HANG) {
                    Ok(Ok(Ok(outcomes))) => {
                        if outcomes.iter().all(|&o| o == Outcome::Generated) {
                            generated.push((what.clone(), tokens.to_string()));
                        }
                        for o in outcomes {
                            *tally.entry(o).or_default() += 1;
                        }
                    }
                    Ok(Ok(Err(b))) => broken.push(format!("{what}: {b}")),
                    Ok(Err(p)) => {
                        let msg = p
                            .downcast_ref::<String>()
                            .cloned()
                            .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                            .unwrap_or_default();
                        broken.push(format!("{what}: the generator panicked: {msg}"));
                    }
                    Err(_) => {
                        broken.push(format!("{what}: no answer within {HANG:?}"));
                        // the thread still runs; the rest of the sweep would wait on it
                        break;
                    }
                }
            }
            total += lexed;
            outcomes.extend(tally.clone());
            println!(
                "{name:<18} block {b}: {lexed:>3} mutants of {} leaves ({:.2} s unchanged): {tally:?}",
                all.len(),
                took.as_secs_f64()
            );
        }
    }
    let _ = std::panic::take_hook();
    if let Ok(dir) = std::env::var("MUTANTS_CRATE") {
        write_crate(Path::new(&dir), &generated);
        println!("{} mutants that generate written to {dir}", generated.len());
    }
    let mut sum = std::collections::BTreeMap::<Outcome, usize>::new();
    for (o, n) in &outcomes {
        *sum.entry(*o).or_default() += n;
    }
    println!(
        "{total} mutants: {sum:?}, {} refused by a parser message completed with its statement's form; {} broken",
        COMPLETED.load(std::sync::atomic::Ordering::Relaxed),
        broken.len()
    );
    for b in &broken {
        println!("  {b}");
    }
    assert!(total > 500, "only {total} mutants");
    assert!(
        broken.is_empty(),
        "{} broken:\n{}",
        broken.len(),
        broken.join("\n")
    );
}
