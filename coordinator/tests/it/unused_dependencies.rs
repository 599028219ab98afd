//! Every dependency a workspace member declares is used by its code, the
//! check `cargo machete` makes, here without a tool to install: for each
//! member's `[dependencies]`, `[dev-dependencies]` and
//! `[build-dependencies]` (also under `[target.*]`), the name code knows
//! the crate by (the key, hyphens as underscores; an unrenamed path
//! dependency's `[lib] name`) must appear as a path (`name::`), in a `use
//! name` or in an `extern crate name` somewhere in the member's src/,
//! tests/, benches/, examples/ or build.rs. And every
//! `[workspace.dependencies]` entry is inherited by some member. A mention
//! in a comment counts as a use: the check errs towards keeping.

use std::path::{Path, PathBuf};

/// The repository root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `path` relative to the repository root when it lies inside it.
fn shown(path: &Path) -> String {
    path.strip_prefix(root()).unwrap_or(path).display().to_string()
}

/// A parsed Cargo.toml, naming the file in a failure.
fn manifest(path: &Path) -> toml::Table {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.parse().unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The dependency tables of a manifest: (section name, table), target-specific ones included.
fn dependency_tables(m: &toml::Table) -> Vec<(String, &toml::Table)> {
    let kinds = ["dependencies", "dev-dependencies", "build-dependencies"];
    let mut out: Vec<(String, &toml::Table)> =
        kinds.iter().filter_map(|k| Some((k.to_string(), m.get(*k)?.as_table()?))).collect();
    for (cfg, t) in m.get("target").and_then(|t| t.as_table()).into_iter().flatten() {
        for k in kinds {
            if let Some(deps) = t.get(k).and_then(|d| d.as_table()) {
                out.push((format!("target.{cfg}.{k}"), deps));
            }
        }
    }
    out
}

/// The name code uses for dependency `key` declared as `spec` by the member
/// in `dir`; `workspace` holds `[workspace.dependencies]` for inherited entries.
fn crate_name(key: &str, spec: &toml::Value, dir: &Path, workspace: &toml::Table) -> String {
    let inherited = spec.get("workspace").and_then(|w| w.as_bool()) == Some(true);
    let entry = if inherited { workspace.get(key).unwrap_or(spec) } else { spec };
    let renamed = spec.get("package").is_some() || entry.get("package").is_some();
    let path = entry.get("path").and_then(|p| p.as_str());
    let base = if inherited { root() } else { dir.to_path_buf() };
    let lib_name = path.filter(|_| !renamed).and_then(|p| {
        let target = manifest(&base.join(p).join("Cargo.toml"));
        Some(target.get("lib")?.get("name")?.as_str()?.to_string())
    });
    lib_name.unwrap_or_else(|| key.replace('-', "_"))
}

/// Whether `text` uses crate `name`: `name::`, `use name` or `extern crate
/// name`, with no identifier character before `name` or right after it.
fn uses(text: &str, name: &str) -> bool {
    let ident = |c: char| c.is_alphanumeric() || c == '_';
    text.match_indices(name).any(|(i, _)| {
        let before = text[..i].chars().next_back();
        let rest = &text[i + name.len()..];
        if before.is_some_and(ident) || rest.starts_with(ident) {
            return false;
        }
        let mut head = text[..i].split_whitespace().rev();
        let (last, before_last) = (head.next(), head.next());
        rest.starts_with("::")
            || last == Some("use")
            || (last == Some("crate") && before_last == Some("extern"))
    })
}

/// The text of every .rs file under `dir`'s src/, tests/, benches/ and
/// examples/, and of its build.rs.
fn member_sources(dir: &Path) -> String {
    let mut files = vec![dir.join("build.rs")];
    let mut stack: Vec<PathBuf> =
        ["src", "tests", "benches", "examples"].iter().map(|d| dir.join(d)).collect();
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten() {
            let p = e.unwrap_or_else(|e| panic!("{}: {e}", d.display())).path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                files.push(p);
            }
        }
    }
    files.iter().filter_map(|f| std::fs::read_to_string(f).ok()).collect::<Vec<_>>().join("\n")
}

/// One line per declared dependency of the member in `dir` that its code
/// does not use, naming its Cargo.toml, section and crate.
fn unused_in(dir: &Path, workspace: &toml::Table) -> Vec<String> {
    let path = dir.join("Cargo.toml");
    let m = manifest(&path);
    let code = member_sources(dir);
    let mut out = Vec::new();
    for (section, deps) in dependency_tables(&m) {
        for (key, spec) in deps {
            let name = crate_name(key, spec, dir, workspace);
            if !uses(&code, &name) {
                out.push(format!(
                    "{}: [{section}] {key}: no `{name}::`, `use {name}` or `extern crate {name}` \
                     in src/, tests/, benches/, examples/ or build.rs; use it or remove it",
                    shown(&path)
                ));
            }
        }
    }
    out
}

/// The workspace's `[workspace.dependencies]` and its members' directories.
fn workspace() -> (toml::Table, Vec<PathBuf>) {
    let m = manifest(&root().join("Cargo.toml"));
    let ws = m.get("workspace").and_then(|w| w.as_table()).expect("Cargo.toml: [workspace]");
    let deps = ws.get("dependencies").and_then(|d| d.as_table()).cloned().unwrap_or_default();
    let members = ws.get("members").and_then(|m| m.as_array()).expect("[workspace] members");
    let dirs = members.iter().map(|m| root().join(m.as_str().expect("a member path"))).collect();
    (deps, dirs)
}

#[test]
fn every_declared_dependency_is_used() {
    let (deps, members) = workspace();
    assert!(members.len() >= 5, "{members:?}");
    let unused: Vec<String> = members.iter().flat_map(|d| unused_in(d, &deps)).collect();
    assert!(unused.is_empty(), "unused dependencies:\n{}", unused.join("\n"));
}

/// The `[workspace.dependencies]` keys of `deps` that no manifest of
/// `members` inherits (`key.workspace = true`).
fn orphans(deps: &toml::Table, members: &[toml::Table]) -> Vec<String> {
    let inherited = |key: &str| {
        members.iter().any(|m| {
            dependency_tables(m).iter().any(|(_, t)| {
                t.get(key).and_then(|s| s.get("workspace")).and_then(|w| w.as_bool()) == Some(true)
            })
        })
    };
    deps.keys().filter(|k| !inherited(k)).cloned().collect()
}

#[test]
fn every_workspace_dependency_is_inherited() {
    let (deps, members) = workspace();
    let manifests: Vec<toml::Table> =
        members.iter().map(|d| manifest(&d.join("Cargo.toml"))).collect();
    let orphans = orphans(&deps, &manifests);
    assert!(
        orphans.is_empty(),
        "Cargo.toml: [workspace.dependencies] {orphans:?}: no member inherits them; remove them"
    );
}

/// A workspace entry no member inherits is caught; a member's own
/// `version = ...` entry of the same name does not count as inheriting.
#[test]
fn an_orphan_workspace_dependency_is_caught() {
    let deps: toml::Table = "serde = \"1\"\nplotters = \"0.3\"\nrand = \"0.9\"".parse().unwrap();
    let member: toml::Table =
        "[dependencies]\nserde.workspace = true\n[dev-dependencies]\nrand = \"0.9\"\n"
            .parse()
            .unwrap();
    assert_eq!(orphans(&deps, &[member]), ["plotters", "rand"]);
}

#[test]
fn uses_sees_paths_and_imports_not_lookalikes() {
    assert!(uses("let v: serde_json::Value;", "serde_json"));
    assert!(uses("use rand_chacha;", "rand_chacha"));
    assert!(uses("use rand_chacha as chacha;", "rand_chacha"));
    assert!(uses("extern crate pulp;", "pulp"));
    assert!(uses("#[derive(serde::Serialize)]", "serde"));
    assert!(!uses("let v: serde_json::Value;", "serde"), "serde_json is not serde");
    assert!(!uses("my_serde::x()", "serde"), "my_serde is not serde");
    assert!(!uses("// serde is great", "serde"), "a bare word is no use");
    assert!(!uses("fn rand() {}", "rand"));
    assert!(!uses("because serde", "serde"), "a word ending in `use` is not `use`");
}

/// A member that declares `rand` and a renamed `chacha`, and uses neither,
/// is caught with its Cargo.toml, section and crate; once its code uses
/// them, nothing is reported.
#[test]
fn an_unused_dependency_is_caught() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("src")).unwrap();
    std::fs::create_dir_all(dir.path().join("tests/it")).unwrap();
    std::fs::write(
        dir.path().join("Cargo.toml"),
        "[package]\nname = \"fixture\"\n\n[dependencies]\nserde.workspace = true\nrand = \"0.9\"\n\
         [dev-dependencies]\nchacha = { package = \"rand_chacha\", version = \"0.9\" }\n",
    )
    .unwrap();
    std::fs::write(dir.path().join("src/lib.rs"), "use serde::Serialize;\n// rand_chacha::\n")
        .unwrap();
    let workspace: toml::Table = "serde = \"1\"".parse().unwrap();
    let found = unused_in(dir.path(), &workspace);
    assert_eq!(found.len(), 2, "{found:?}");
    let toml = shown(&dir.path().join("Cargo.toml"));
    assert!(
        found[0].starts_with(&format!("{toml}: [dependencies] rand: no `rand::`")),
        "{found:?}"
    );
    assert!(
        found[1].starts_with(&format!("{toml}: [dev-dependencies] chacha: no `chacha::`")),
        "{found:?}"
    );
    std::fs::write(
        dir.path().join("tests/it/main.rs"),
        "fn f() { rand::random::<u8>(); use chacha; }\n",
    )
    .unwrap();
    assert_eq!(unused_in(dir.path(), &workspace), Vec::<String>::new());
}
