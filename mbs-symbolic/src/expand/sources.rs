//! The files `mbs expand` reads: a file, the modules it includes (`mod name;` and
//! `#[path = "…"] mod name;`, found as rustc finds them), and the modules of workspace crates
//! it names in `use` (`use mbs_models::hexapod;` reads that crate's `src/hexapod.rs`).

use super::multibody_blocks;
use proc_macro2::{Span, TokenStream};
use std::path::{Path, PathBuf};

/// A file read, with its `multibody!` blocks in order.
pub struct Source {
    pub path: PathBuf,
    pub blocks: Vec<TokenStream>,
}

/// A file that could not be read or parsed: the file the error is in, and where in it when
/// known (the `mod` item that names a missing file, the tokens that do not parse).
pub struct SourceError {
    pub file: PathBuf,
    pub span: Option<Span>,
    pub message: String,
}

/// `root` and the files it includes, depth first in the order of their `mod` and `use` items.
pub fn sources(root: &Path) -> (Vec<Source>, Vec<SourceError>) {
    let mut r = Reader {
        out: Vec::new(),
        errors: Vec::new(),
        seen: Vec::new(),
        workspace: None,
    };
    r.read(root.to_path_buf(), finds_modules_beside(root), None);
    (r.out, r.errors)
}

/// Whether the `mod x;` of the file `root` are found beside it, as for a crate root
/// (`lib.rs`, `main.rs`, `src/bin/*.rs`, an example, a test, a bench) or a `mod.rs`, rather
/// than in a folder of its name, as for any other module of a crate's `src`
/// (`src/human.rs` finds `mod muscles;` in `src/human/muscles.rs`).
fn finds_modules_beside(root: &Path) -> bool {
    let name = root
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or_default();
    if matches!(name, "lib.rs" | "main.rs" | "mod.rs") {
        return true;
    }
    let dirs: Vec<&str> = root
        .parent()
        .map(|d| d.iter().filter_map(|c| c.to_str()).collect())
        .unwrap_or_default();
    match dirs.iter().rposition(|d| *d == "src") {
        Some(i) => dirs.get(i + 1) == Some(&"bin") && i + 2 == dirs.len(),
        None => true,
    }
}

struct Reader {
    out: Vec<Source>,
    errors: Vec<SourceError>,
    seen: Vec<PathBuf>,
    /// crates of the workspace around the root: (crate name, `src/lib.rs`), read once
    workspace: Option<Vec<(String, PathBuf)>>,
}

impl Reader {
    /// Reads `path`; `mod_rs`: its `mod x;` are found next to it (a crate root, `mod.rs`, a
    /// file named by `#[path]`) rather than in a folder of its name. `from` is the item that
    /// named it, for errors.
    fn read(&mut self, path: PathBuf, mod_rs: bool, from: Option<(PathBuf, Span)>) {
        let key = path.canonicalize().unwrap_or_else(|_| path.clone());
        if self.seen.contains(&key) {
            return;
        }
        self.seen.push(key);
        // a FIFO or a device would block the read or never end it: only regular files
        let text = match std::fs::metadata(&path).and_then(|m| {
            if m.is_file() {
                std::fs::read_to_string(&path)
            } else {
                Err(std::io::Error::other(
                    "it is not a regular file (a folder, a FIFO or a device): name a Rust source file",
                ))
            }
        }) {
            Ok(t) => t,
            Err(e) => {
                let (file, span) = match from {
                    Some((f, s)) => (f, Some(s)),
                    None => (path.clone(), None),
                };
                self.errors.push(SourceError {
                    file,
                    span,
                    message: format!("cannot read {}: {e}", path.display()),
                });
                return;
            }
        };
        let file = match syn::parse_file(&text) {
            Ok(f) => f,
            Err(e) => {
                for e in e {
                    self.errors.push(SourceError {
                        file: path.clone(),
                        span: Some(e.span()),
                        message: format!("this file does not parse as Rust: {e}"),
                    });
                }
                return;
            }
        };
        self.out.push(Source {
            path: path.clone(),
            blocks: multibody_blocks(&file),
        });
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let children = if mod_rs {
            dir.clone()
        } else {
            dir.join(path.file_stem().unwrap_or_default())
        };
        self.items(&file.items, &path, &children, &dir);
    }

    /// The `mod` and `use` items of a file or inline module: `children` is where `mod x;`
    /// looks, `paths` what `#[path]` is relative to.
    fn items(&mut self, items: &[syn::Item], file: &Path, children: &Path, paths: &Path) {
        for item in items {
            match item {
                syn::Item::Mod(m) => {
                    let name = m.ident.to_string();
                    let path_attr = m.attrs.iter().find_map(|a| match &a.meta {
                        syn::Meta::NameValue(nv) if nv.path.is_ident("path") => match &nv.value {
                            syn::Expr::Lit(syn::ExprLit {
                                lit: syn::Lit::Str(s),
                                ..
                            }) => Some(s.value()),
                            _ => None,
                        },
                        _ => None,
                    });
                    if let Some((_, inner)) = &m.content {
                        let sub = match &path_attr {
                            Some(p) => paths.join(p),
                            None => children.join(&name),
                        };
                        self.items(inner, file, &sub, &sub);
                        continue;
                    }
                    let from = Some((file.to_path_buf(), m.ident.span()));
                    match path_attr {
                        Some(p) => self.read(paths.join(p), true, from),
                        None => {
                            let flat = children.join(format!("{name}.rs"));
                            let nested = children.join(&name).join("mod.rs");
                            if flat.is_file() {
                                self.read(flat, false, from);
                            } else if nested.is_file() {
                                self.read(nested, true, from);
                            } else {
                                self.errors.push(SourceError {
                                    file: file.to_path_buf(),
                                    span: Some(m.ident.span()),
                                    message: format!(
                                        "file not found for module `{name}`: neither {} nor {}",
                                        flat.display(),
                                        nested.display()
                                    ),
                                });
                            }
                        }
                    }
                }
                syn::Item::Use(u) => {
                    let mut paths_used = Vec::new();
                    use_paths(&u.tree, &mut Vec::new(), &mut paths_used);
                    for p in paths_used {
                        self.workspace_module(file, &p);
                    }
                }
                _ => {}
            }
        }
    }

    /// The file of module `krate::a::b…` when `krate` is a crate of the workspace (the
    /// longest prefix of the path that names a file module).
    fn workspace_module(&mut self, file: &Path, path: &[String]) {
        let Some((krate, rest)) = path.split_first() else {
            return;
        };
        if rest.is_empty() || matches!(krate.as_str(), "crate" | "self" | "super" | "std") {
            return;
        }
        if self.workspace.is_none() {
            self.workspace = Some(workspace_crates(file));
        }
        let Some(lib) = self
            .workspace
            .as_ref()
            .and_then(|w| w.iter().find(|(n, _)| n == krate))
            .map(|(_, lib)| lib.clone())
        else {
            return;
        };
        let mut dir = lib.parent().map(Path::to_path_buf).unwrap_or_default();
        let mut found = None;
        for seg in rest {
            let flat = dir.join(format!("{seg}.rs"));
            let nested = dir.join(seg).join("mod.rs");
            if flat.is_file() {
                found = Some((flat, false));
            } else if nested.is_file() {
                found = Some((nested, true));
            } else {
                break;
            }
            dir = dir.join(seg);
        }
        if let Some((f, mod_rs)) = found {
            self.read(f, mod_rs, None);
        }
    }
}

/// Every path a `use` tree names, as segments (`use a::{b, c::d as e}` → a::b, a::c::d).
fn use_paths(tree: &syn::UseTree, prefix: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    match tree {
        syn::UseTree::Path(p) => {
            prefix.push(p.ident.to_string());
            use_paths(&p.tree, prefix, out);
            prefix.pop();
        }
        syn::UseTree::Name(n) => {
            let mut v = prefix.clone();
            v.push(n.ident.to_string());
            out.push(v);
        }
        syn::UseTree::Rename(r) => {
            let mut v = prefix.clone();
            v.push(r.ident.to_string());
            out.push(v);
        }
        syn::UseTree::Glob(_) => out.push(prefix.clone()),
        syn::UseTree::Group(g) => {
            for t in &g.items {
                use_paths(t, prefix, out);
            }
        }
    }
}

/// The library crates of the Cargo workspace around `file`: (crate name with `_`,
/// `src/lib.rs`). Empty when there is none.
fn workspace_crates(file: &Path) -> Vec<(String, PathBuf)> {
    let start = file
        .canonicalize()
        .ok()
        .and_then(|f| f.parent().map(Path::to_path_buf));
    let mut dir = start;
    while let Some(d) = dir {
        let manifest = d.join("Cargo.toml");
        if let Ok(text) = std::fs::read_to_string(&manifest) {
            if text.lines().any(|l| l.trim() == "[workspace]") {
                let mut out = Vec::new();
                let mut dirs = vec![d.clone()];
                dirs.extend(members(&text).into_iter().map(|m| d.join(m)));
                for m in dirs {
                    let lib = m.join("src").join("lib.rs");
                    let name = std::fs::read_to_string(m.join("Cargo.toml"))
                        .ok()
                        .and_then(|t| package_name(&t));
                    if let (Some(n), true) = (name, lib.is_file()) {
                        out.push((n.replace('-', "_"), lib));
                    }
                }
                return out;
            }
        }
        dir = d.parent().map(Path::to_path_buf);
    }
    Vec::new()
}

/// The strings of `members = [ … ]` of a workspace manifest.
fn members(manifest: &str) -> Vec<String> {
    let Some(start) = manifest.find("members") else {
        return Vec::new();
    };
    let rest = &manifest[start..];
    let (Some(open), Some(close)) = (rest.find('['), rest.find(']')) else {
        return Vec::new();
    };
    rest[open + 1..close]
        .split(',')
        .map(|s| s.trim().trim_matches('"').to_string())
        .filter(|s| !s.is_empty())
        .collect()
}

/// `name = "…"` of the `[package]` section.
fn package_name(manifest: &str) -> Option<String> {
    let mut in_package = false;
    for line in manifest.lines() {
        let l = line.trim();
        if l.starts_with('[') {
            in_package = l == "[package]";
        } else if in_package && l.starts_with("name") {
            let v = l.split_once('=')?.1.trim();
            return Some(v.trim_matches('"').to_string());
        }
    }
    None
}
