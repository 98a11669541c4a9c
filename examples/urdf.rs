//! A robot from its URDF description: imports it (`mbs::urdf`), prints the operation counts of
//! the functions `multibody!` generates for it and the generation time, then writes a small
//! package (`Cargo.toml` depending on this `mbs` by path, `src/main.rs` with the imported
//! block and the command line of the per-system programs, `mbs::cli::RunArgs`) and runs it
//! with `cargo run --release`, passing on the arguments after `--`: the simulation, its
//! summary and, with `--out DIR`, the CSV, plots, HTML animation and glTF file.
//!
//! A model is compiled, so running an imported one means compiling it: the package is that
//! compilation, as a user would write it (edit `src/main.rs` there to add effects, scenes,
//! shapes). The first build compiles `mbs` and its dependencies into the package's `target/`
//! (or `CARGO_TARGET_DIR`); later ones only the model. The build time is printed.
//!
//! ```text
//! cargo run --release --example urdf -- tests/urdf/arm2.urdf -- --t-end 2 --out out/arm2
//! cargo run --release --example urdf -- ur5_robot.urdf --dir target/ur5 -- --scheme radau5
//! ```

use clap::Parser;
use mbs_symbolic::expand::{Expansion, expand_models, multibody_blocks};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};
use std::time::Instant;

#[derive(Parser)]
#[command(about = "Import a URDF robot, print its op counts, build and simulate it")]
struct Args {
    /// the URDF file
    urdf: PathBuf,
    /// where to write the robot's package (default: target/urdf/NAME)
    #[arg(long)]
    dir: Option<PathBuf>,
    /// free the root link (a floating joint from the ground) instead of fixing it
    #[arg(long)]
    floating_base: bool,
    /// only import, count and write the package; do not build or run it
    #[arg(long)]
    no_run: bool,
    /// arguments of the robot's program (`--t-end`, `--scheme`, `--out`, …; `-- --help`)
    #[arg(last = true)]
    run: Vec<String>,
}

fn main() -> ExitCode {
    match run(Args::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: Args) -> Result<(), String> {
    let options = mbs::urdf::ImportOptions {
        floating_base: args.floating_base,
    };
    let imported = mbs::urdf::import_file(&args.urdf, options).map_err(|e| e.to_string())?;
    let file = args.urdf.file_name().unwrap_or(args.urdf.as_os_str());
    let block = imported.block(&file.to_string_lossy());
    print_counts(&block, &imported.name)?;

    let snake = snake(&imported.name);
    let dir = args.dir.unwrap_or_else(|| {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("target/urdf")
            .join(&snake)
    });
    write_package(&dir, &snake, &imported.name, &block)?;
    println!("package: {}", dir.display());
    if args.no_run {
        return Ok(());
    }

    let start = Instant::now();
    let status = Command::new(env!("CARGO"))
        .args(["build", "--release", "--quiet"])
        .current_dir(&dir)
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if !status.success() {
        return Err(format!("building {} failed", dir.display()));
    }
    println!("build: {:.1} s", start.elapsed().as_secs_f64());
    let status = Command::new(env!("CARGO"))
        .args(["run", "--release", "--quiet", "--"])
        .args(&args.run)
        .current_dir(&dir)
        .status()
        .map_err(|e| format!("cannot run cargo: {e}"))?;
    if status.success() {
        Ok(())
    } else {
        Err(format!("the program of {} failed", imported.name))
    }
}

/// The op counts of the generated functions, as `mbs expand --counts-only` prints them.
fn print_counts(block: &str, name: &str) -> Result<(), String> {
    let file = syn::parse_file(block).map_err(|e| format!("internal error: {e}"))?;
    for tokens in multibody_blocks(&file) {
        for e in expand_models(tokens).map_err(|e| e.to_string())? {
            match e {
                Expansion::Err { error, .. } => {
                    return Err(format!("the imported model `{name}` has errors: {error}"));
                }
                Expansion::Ok { name, generated } => {
                    println!(
                        "{name}: generated in {:.1} ms",
                        (generated.build_time + generated.emit_time).as_secs_f64() * 1e3
                    );
                    println!(
                        "{:<22} {:>8} {:>8} {:>8} {:>6} {:>6}",
                        "function", "flops", "adds", "muls", "divs", "funcs"
                    );
                    for r in &generated.reports {
                        let [flops, adds, muls, divs, funcs, _] = r.ops.columns();
                        println!(
                            "{:<22} {flops:>8} {adds:>8} {muls:>8} {divs:>6} {funcs:>6}",
                            r.function
                        );
                    }
                }
            }
        }
    }
    Ok(())
}

/// The robot's package: a manifest, this workspace's lock file (the same dependency versions)
/// and the program.
fn write_package(dir: &Path, snake: &str, name: &str, block: &str) -> Result<(), String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::fs::create_dir_all(dir.join("src"))
        .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let manifest = format!(
        "[package]\nname = \"{}-model\"\nversion = \"0.1.0\"\nedition = \"2024\"\npublish = false\n\n\
         [dependencies]\nmbs = {{ path = {:?} }}\n\n# a package of its own, not a member of an \
         enclosing workspace\n[workspace]\n",
        snake.replace('_', "-"),
        root.display().to_string()
    );
    let main = format!(
        "{block}\n/// Simulates the robot: `cargo run --release -- --help` for the options.\n\
         fn main() {{\n    use mbs::Model;\n    \
         let args = mbs::cli::RunArgs::parse_with_defaults(&[(\"t_end\", \"2\")]);\n    \
         let model = {name}::default();\n    \
         args.sweep_if_asked(&model, 2.0);\n    \
         if !args.quiet {{\n        let info = model.info();\n        \
         println!(\"{{}}: {{}} dof, {{}} bodies\", info.name, {name}::NQ, info.body_count());\n    }}\n    \
         if let Err(e) = args.run(model, 2.0) {{\n        eprintln!(\"error: {{e}}\");\n        \
         std::process::exit(1);\n    }}\n}}\n"
    );
    let write = |path: PathBuf, text: &str| {
        // unchanged files keep their time stamps, so cargo does not rebuild
        if std::fs::read_to_string(&path).ok().as_deref() == Some(text) {
            return Ok(());
        }
        std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
    };
    write(dir.join("Cargo.toml"), &manifest)?;
    write(dir.join("src/main.rs"), &main)?;
    if !dir.join("Cargo.lock").exists()
        && let Ok(lock) = std::fs::read_to_string(root.join("Cargo.lock"))
    {
        write(dir.join("Cargo.lock"), &lock)?;
    }
    Ok(())
}

/// `Ur5` → `ur5`, `BranchedArm` → `branched_arm`.
fn snake(name: &str) -> String {
    let mut s = String::new();
    for (i, c) in name.chars().enumerate() {
        if c.is_ascii_uppercase() && i > 0 {
            s.push('_');
        }
        s.push(c.to_ascii_lowercase());
    }
    s
}
