//! `mbs`: command-line tools of the mbs toolkit.
//!
//! `mbs expand FILE.rs [--model NAME] [--scene S]` prints the code that `multibody!` generates
//! for the blocks of a file and of the files it includes (`mod name;`, `#[path = "…"] mod
//! name;`, and the modules of workspace crates it names in `use`), exactly as the macro emits
//! it, pretty-printed (below each table of operations, `option tangents = table;`, its
//! operations one a line as comments), then a table of operation counts per generated function
//! and the generation time. Errors are reported with file:line:col, after every model is tried.
//!
//! `mbs import urdf FILE.urdf [--floating-base] > model.rs` writes a robot's URDF description
//! as a `multibody!` block to edit (feature `urdf`; see `mbs::urdf`).

use clap::{Parser, Subcommand};
use mbs_symbolic::codegen::Generated;
use mbs_symbolic::expand::{Expansion, expand_models, sources};
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "mbs", version, about = "Tools of the mbs multibody toolkit")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print the code multibody! generates for a file, with op counts and generation time
    Expand {
        /// a Rust source file containing `multibody! { … }` blocks
        file: PathBuf,
        /// only this model (its name in `model NAME { … }`)
        #[arg(long)]
        model: Option<String>,
        /// only this scene's type
        #[arg(long)]
        scene: Option<String>,
        /// print only the op-count table
        #[arg(long)]
        counts_only: bool,
    },
    /// Write a robot description as a `multibody!` block (on standard output)
    #[cfg(feature = "urdf")]
    Import {
        #[command(subcommand)]
        format: ImportFormat,
    },
}

#[cfg(feature = "urdf")]
#[derive(Subcommand)]
enum ImportFormat {
    /// a URDF file: links, joints, inertias, visuals
    Urdf {
        /// the URDF file
        file: PathBuf,
        /// free the root link (a floating joint `floating_base` from the ground) instead of
        /// fixing it to the ground
        #[arg(long)]
        floating_base: bool,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Expand {
            file,
            model,
            scene,
            counts_only,
        } => {
            let errors = expand_file(&file, model.as_deref(), scene.as_deref(), counts_only);
            for e in &errors {
                eprintln!("error: {e}");
            }
            if errors.is_empty() {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            }
        }
        #[cfg(feature = "urdf")]
        Command::Import {
            format:
                ImportFormat::Urdf {
                    file,
                    floating_base,
                },
        } => match mbs::urdf::import_file(&file, mbs::urdf::ImportOptions { floating_base }) {
            Ok(imported) => {
                let source = file.file_name().unwrap_or(file.as_os_str());
                let block = imported.block(&source.to_string_lossy());
                // a reader that stops early (`| head`) is not an error; a full disk is
                match std::io::stdout().lock().write_all(block.as_bytes()) {
                    Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
                        eprintln!("error: cannot write the model: {e}");
                        ExitCode::FAILURE
                    }
                    _ => ExitCode::SUCCESS,
                }
            }
            Err(e) => {
                eprintln!("error: {}: {e}", file.display());
                ExitCode::FAILURE
            }
        },
    }
}

/// `file:line:col: message` of an error in `file` (line and column of the span's start).
fn located(file: &Path, span: Option<proc_macro2::Span>, message: &str) -> String {
    match span {
        Some(s) => {
            let p = s.start();
            format!("{}:{}:{}: {message}", file.display(), p.line, p.column + 1)
        }
        None => format!("{}: {message}", file.display()),
    }
}

/// Prints the expansion of every model of `file` and of the files it includes (or of
/// `model` only, of its scene `scene` only); returns every error, each with file:line:col,
/// after going through every model.
fn expand_file(
    file: &Path,
    model: Option<&str>,
    scene: Option<&str>,
    counts_only: bool,
) -> Vec<String> {
    let (sources, read_errors) = sources(file);
    let mut errors: Vec<String> = read_errors
        .iter()
        .map(|e| located(&e.file, e.span, &e.message))
        .collect();
    if sources.iter().all(|s| s.blocks.is_empty()) {
        if errors.is_empty() {
            let read: Vec<String> = sources
                .iter()
                .map(|s| s.path.display().to_string())
                .collect();
            errors.push(format!(
                "no multibody! block in {} (read: {})",
                file.display(),
                read.join(", ")
            ));
        }
        return errors;
    }
    // models found, and the scenes of those `--model` selects
    let (mut found, mut scenes): (bool, Vec<(String, Vec<String>)>) = (false, Vec::new());
    for source in &sources {
        for tokens in &source.blocks {
            let expansions = match expand_models(tokens.clone()) {
                Ok(e) => e,
                Err(e) => {
                    errors.extend(
                        e.into_iter()
                            .map(|e| located(&source.path, Some(e.span()), &e.to_string())),
                    );
                    continue;
                }
            };
            for e in expansions {
                match e {
                    Expansion::Err { name, error, .. } => {
                        if model.is_none_or(|m| m == name) {
                            found = true;
                            errors.extend(error.into_iter().map(|e| {
                                located(
                                    &source.path,
                                    Some(e.span()),
                                    &format!("model `{name}`: {e}"),
                                )
                            }));
                        }
                    }
                    Expansion::Ok { name, generated } => {
                        if model.is_some_and(|m| m != name) {
                            continue;
                        }
                        found = true;
                        let own = model_scenes(&name, &generated);
                        let shown = scene.is_none_or(|s| own.iter().any(|o| o == s));
                        scenes.push((name.clone(), own));
                        if !shown {
                            continue;
                        }
                        if let Err(e) = print_model(&name, &generated, scene, counts_only) {
                            errors.push(located(&source.path, None, &e));
                        }
                    }
                }
            }
        }
    }
    if !found {
        errors.push(match model {
            Some(m) => format!(
                "no model named `{m}` in {} or the files it includes",
                file.display()
            ),
            None => format!("no model generated from {}", file.display()),
        });
    } else if let Some(s) = scene {
        if !scenes.iter().any(|(_, own)| own.iter().any(|o| o == s)) {
            errors.push(unknown_scene(s, &scenes));
        }
    }
    errors
}

/// "no scene `S` …" with the scenes there are.
fn unknown_scene(s: &str, scenes: &[(String, Vec<String>)]) -> String {
    let list = |v: &[String]| {
        let v: Vec<String> = v.iter().map(|x| format!("`{x}`")).collect();
        match v.split_last() {
            None => "none".to_string(),
            Some((last, [])) => last.clone(),
            Some((last, init)) => format!("{} and {last}", init.join(", ")),
        }
    };
    match scenes {
        [(m, own)] if own.is_empty() => {
            format!(
                "no scene `{s}`: model `{m}` has no scenes (its one type is `{m}`); leave out --scene"
            )
        }
        [(m, own)] => format!(
            "no scene `{s}` in model `{m}`: its scenes are {}",
            list(own)
        ),
        _ => {
            let all: Vec<String> = scenes
                .iter()
                .map(|(m, own)| format!("model `{m}`: {}", list(own)))
                .collect();
            format!(
                "no scene `{s}` in any model; the scenes are, {}",
                all.join("; ")
            )
        }
    }
}

/// The scenes of a model: the suffixes of its types (none when its one type is the model).
fn model_scenes(name: &str, generated: &Generated) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for r in &generated.reports {
        if let Some(s) = r.model.strip_prefix(name).filter(|s| !s.is_empty()) {
            if !out.iter().any(|o| o == s) {
                out.push(s.to_string());
            }
        }
    }
    out
}

/// Prints a model's code (its scene's, with `scene`) and its op-count table.
fn print_model(
    name: &str,
    generated: &Generated,
    scene: Option<&str>,
    counts_only: bool,
) -> Result<(), String> {
    let file: syn::File = syn::parse_str(&generated.code)
        .map_err(|e| format!("internal error: generated code does not parse: {e}"))?;
    let items: Vec<syn::Item> = file
        .items
        .into_iter()
        .filter(|it| scene.is_none_or(|s| item_belongs(it, name, s)))
        .collect();
    let mut out = String::new();
    if !counts_only {
        let listings = table_listings(&items);
        let shown = syn::File {
            shebang: None,
            attrs: Vec::new(),
            items,
        };
        let _ = writeln!(
            out,
            "{}",
            with_listings(&prettyplease::unparse(&shown), &listings)
        );
    }
    let _ = writeln!(
        out,
        "// model {name}: generation {:.1} ms (symbolic {:.1} ms, emission {:.1} ms)",
        (generated.build_time + generated.emit_time).as_secs_f64() * 1e3,
        generated.build_time.as_secs_f64() * 1e3,
        generated.emit_time.as_secs_f64() * 1e3
    );
    let _ = writeln!(
        out,
        "// {:<28} {:<22} {:>8} {:>8} {:>8} {:>6} {:>6} {:>6}",
        "type", "function", "flops", "adds", "muls", "divs", "funcs", "lets"
    );
    for r in &generated.reports {
        if scene.is_some_and(|s| r.model != format!("{name}{s}") && r.model != name) {
            continue;
        }
        let (model, function) = (&r.model, &r.function);
        let [flops, adds, muls, divs, funcs, lets] = r.ops.columns();
        let _ = writeln!(
            out,
            "// {model:<28} {function:<22} {flops:>8} {adds:>8} {muls:>8} {divs:>6} {funcs:>6} {lets:>6}"
        );
    }
    // a reader that stops early (`mbs expand … | head`) is not an error
    match std::io::stdout().lock().write_all(out.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(format!("cannot write the code: {e}"))
        }
        _ => Ok(()),
    }
}

/// The operations of every table (`option tangents = table;`) in `items`, in the order they are
/// printed, one line each (`mbs_runtime::tape::listing`): constants by their value, leaves by
/// their names, the values computed as `s` and their slot.
fn table_listings(items: &[syn::Item]) -> Vec<Vec<String>> {
    struct Tables(Vec<Vec<String>>);
    impl<'a> syn::visit::Visit<'a> for Tables {
        fn visit_block(&mut self, block: &'a syn::Block) {
            if let Some(l) = block_listing(block) {
                self.0.push(l);
            }
            syn::visit::visit_block(self, block);
        }
    }
    let mut tables = Tables(Vec::new());
    for item in items {
        syn::visit::Visit::visit_item(&mut tables, item);
    }
    tables.0
}

/// The listing of the table a method's body holds: its `const CONSTANTS`, `const CODE` and the
/// leaves and outputs of its call of `tape::run`.
fn block_listing(block: &syn::Block) -> Option<Vec<String>> {
    let (mut code, mut constants, mut call) = (None, None, None);
    for stmt in &block.stmts {
        match stmt {
            syn::Stmt::Item(syn::Item::Const(c)) if c.ident == "CODE" => {
                if let syn::Expr::Lit(syn::ExprLit {
                    lit: syn::Lit::ByteStr(b),
                    ..
                }) = &*c.expr
                {
                    code = Some(b.value());
                }
            }
            syn::Stmt::Item(syn::Item::Const(c)) if c.ident == "CONSTANTS" => {
                if let syn::Expr::Array(a) = &*c.expr {
                    constants = Some(a.elems.iter().map(expr_text).collect::<Vec<_>>());
                }
            }
            syn::Stmt::Expr(syn::Expr::Call(c), _) => {
                let is_run = matches!(&*c.func, syn::Expr::Path(p)
                    if p.path.segments.iter().rev().take(2).map(|s| s.ident.to_string()).eq(["run", "tape"]));
                if is_run && c.args.len() == 6 {
                    call = Some(c);
                }
            }
            _ => {}
        }
    }
    let (code, constants, call) = (code?, constants?, call?);
    let elements = |e: &syn::Expr| -> Vec<String> {
        match e {
            syn::Expr::Reference(r) => match &*r.expr {
                syn::Expr::Array(a) => a.elems.iter().map(expr_text).collect(),
                _ => Vec::new(),
            },
            _ => Vec::new(),
        }
    };
    let leaves = elements(&call.args[3]);
    let outputs = elements(&call.args[5]);
    let slot = |i: u16| {
        let i = i as usize;
        match constants.get(i) {
            Some(c) => c.clone(),
            None => leaves
                .get(i - constants.len())
                .cloned()
                .unwrap_or_else(|| format!("s{i}")),
        }
    };
    let output = |o: u16| {
        outputs
            .get(o as usize)
            .cloned()
            .unwrap_or_else(|| format!("output{o}"))
    };
    Some(mbs_runtime::tape::listing(&code, &slot, &output))
}

/// A constant, leaf or output of a table's call as the listing names it: `-2.0`, `q_1`, `k`.
fn expr_text(e: &syn::Expr) -> String {
    match e {
        syn::Expr::Lit(syn::ExprLit {
            lit: syn::Lit::Float(f),
            ..
        }) => f.to_string(),
        syn::Expr::Lit(syn::ExprLit {
            lit: syn::Lit::Int(i),
            ..
        }) => i.to_string(),
        syn::Expr::Unary(u) => {
            let inner = expr_text(&u.expr);
            match u.op {
                syn::UnOp::Neg(_) => format!("-{inner}"),
                _ => inner,
            }
        }
        syn::Expr::Reference(r) => expr_text(&r.expr),
        syn::Expr::Path(p) => p
            .path
            .segments
            .iter()
            .map(|s| s.ident.to_string())
            .collect::<Vec<_>>()
            .join("::"),
        _ => "?".into(),
    }
}

/// `code` with each table's listing written below its `const CODE` line, as comments at its
/// indentation, in the order of `listings`.
fn with_listings(code: &str, listings: &[Vec<String>]) -> String {
    if listings.is_empty() {
        return code.to_string();
    }
    let mut out = String::with_capacity(code.len());
    let mut next = listings.iter();
    for line in code.lines() {
        out.push_str(line);
        out.push('\n');
        let trimmed = line.trim_start();
        if trimmed.starts_with("const CODE: &[u8] = b\"") {
            if let Some(listing) = next.next() {
                let indent = &line[..line.len() - trimmed.len()];
                let _ = writeln!(
                    out,
                    "{indent}// CODE, one operation a line: constants by their value, leaves by name, s<n> the value in slot n"
                );
                for l in listing {
                    let _ = writeln!(out, "{indent}// {l}");
                }
            }
        }
    }
    out
}

/// Whether a generated item is part of scene `scene` of model `name` (the parameter struct is
/// shared by all scenes).
fn item_belongs(item: &syn::Item, name: &str, scene: &str) -> bool {
    let ty = format!("{name}{scene}");
    let ident = match item {
        syn::Item::Struct(s) => s.ident.to_string(),
        syn::Item::Impl(i) => match &*i.self_ty {
            syn::Type::Path(p) => p
                .path
                .segments
                .last()
                .map(|s| s.ident.to_string())
                .unwrap_or_default(),
            _ => String::new(),
        },
        _ => String::new(),
    };
    ident == ty || ident == format!("{name}Params")
}
