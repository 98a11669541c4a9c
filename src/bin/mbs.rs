//! `mbs`: command-line tools of the mbs toolkit.
//!
//! `mbs expand FILE.rs [--model NAME] [--scene S]` prints the code that `multibody!` generates
//! for the blocks of a file, exactly as the macro emits it, pretty-printed, then a table of
//! operation counts per generated function and the generation time.
//!
//! `mbs import urdf FILE.urdf [--floating-base] > model.rs` writes a robot's URDF description
//! as a `multibody!` block to edit (feature `urdf`; see `mbs::urdf`).

use clap::{Parser, Subcommand};
use mbs_symbolic::expand::{Expansion, expand_models, multibody_blocks};
use std::path::PathBuf;
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
        } => match expand_file(&file, model.as_deref(), scene.as_deref(), counts_only) {
            Ok(()) => ExitCode::SUCCESS,
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::FAILURE
            }
        },
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
                print!("{}", imported.block(&source.to_string_lossy()));
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("error: {}: {e}", file.display());
                ExitCode::FAILURE
            }
        },
    }
}

fn expand_file(
    file: &PathBuf,
    model: Option<&str>,
    scene: Option<&str>,
    counts_only: bool,
) -> Result<(), String> {
    let src = std::fs::read_to_string(file)
        .map_err(|e| format!("cannot read {}: {e}", file.display()))?;
    let ast = syn::parse_file(&src)
        .map_err(|e| format!("{} does not parse as Rust: {e}", file.display()))?;
    let blocks = multibody_blocks(&ast);
    if blocks.is_empty() {
        return Err(format!("no multibody! block in {}", file.display()));
    }
    let mut found = false;
    for tokens in blocks {
        let expansions = expand_models(tokens).map_err(|e| e.to_string())?;
        for e in expansions {
            match e {
                Expansion::Err { name, error, .. } => {
                    if model.is_none_or(|m| m == name) {
                        return Err(format!("model `{name}` has errors: {error}"));
                    }
                }
                Expansion::Ok { name, generated } => {
                    if model.is_some_and(|m| m != name) {
                        continue;
                    }
                    found = true;
                    let file: syn::File = syn::parse_str(&generated.code).map_err(|e| {
                        format!("internal error: generated code does not parse: {e}")
                    })?;
                    let items: Vec<syn::Item> = file
                        .items
                        .into_iter()
                        .filter(|it| scene.is_none_or(|s| item_belongs(it, &name, s)))
                        .collect();
                    if !counts_only {
                        let shown = syn::File {
                            shebang: None,
                            attrs: Vec::new(),
                            items,
                        };
                        println!("{}", prettyplease::unparse(&shown));
                    }
                    println!(
                        "// model {name}: generation {:.1} ms (symbolic {:.1} ms, emission {:.1} ms)",
                        (generated.build_time + generated.emit_time).as_secs_f64() * 1e3,
                        generated.build_time.as_secs_f64() * 1e3,
                        generated.emit_time.as_secs_f64() * 1e3
                    );
                    println!(
                        "// {:<28} {:<22} {:>8} {:>8} {:>8} {:>6} {:>6} {:>6}",
                        "type", "function", "flops", "adds", "muls", "divs", "funcs", "lets"
                    );
                    for r in &generated.reports {
                        if scene.is_some_and(|s| r.model != format!("{name}{s}") && r.model != name)
                        {
                            continue;
                        }
                        let (model, function) = (&r.model, &r.function);
                        let [flops, adds, muls, divs, funcs, lets] = r.ops.columns();
                        println!(
                            "// {model:<28} {function:<22} {flops:>8} {adds:>8} {muls:>8} {divs:>6} {funcs:>6} {lets:>6}"
                        );
                    }
                }
            }
        }
    }
    if !found {
        return Err(match model {
            Some(m) => format!("no model named `{m}` in {}", file.display()),
            None => format!("no model generated from {}", file.display()),
        });
    }
    Ok(())
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
