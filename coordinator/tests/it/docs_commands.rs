//! The docs a user reads stay true to the binary: every `ceilfarm
//! <subcommand>` shown in README.md and docs/*.md (in shell code blocks and
//! inline code, also as `cargo run --release -- <subcommand>`) parses, that
//! is `ceilfarm <subcommand> --help` succeeds, nested subcommands checked
//! against their parent's list; and every relative link in them resolves
//! to a file of the repository.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// README.md and every docs/*.md, with their text.
fn pages() -> Vec<(PathBuf, String)> {
    let mut paths = vec![root().join("README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    docs.sort();
    paths.extend(docs);
    paths.into_iter().map(|p| (p.clone(), std::fs::read_to_string(&p).unwrap())).collect()
}

/// Texts that may hold a command: lines of shell code blocks and inline code spans.
fn code_texts(page: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut fence: Option<String> = None;
    for line in page.lines() {
        if let Some(info) = line.trim_start().strip_prefix("```") {
            fence = if fence.is_some() { None } else { Some(info.trim().to_string()) };
            continue;
        }
        match &fence {
            Some(info) if ["", "sh", "bash", "shell", "console"].contains(&info.as_str()) => {
                out.push(line.to_string())
            }
            Some(_) => {}
            None => out.extend(line.split('`').skip(1).step_by(2).map(str::to_string)),
        }
    }
    out
}

/// Whether `w` is a subcommand-shaped word (lowercase, digits, dashes).
fn is_word(w: &str) -> bool {
    w.starts_with(|c: char| c.is_ascii_lowercase())
        && w.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
}

/// The words after `ceilfarm` (or `cargo run ... --`) in `text`, if any.
fn command_words(text: &str) -> Option<Vec<String>> {
    let tokens: Vec<&str> = text.split_whitespace().collect();
    let cargo_run = tokens.windows(2).any(|w| w == ["cargo", "run"]);
    let start = tokens
        .iter()
        .position(|t| *t == "ceilfarm" || t.ends_with("/ceilfarm") || (cargo_run && *t == "--"))?;
    let words: Vec<String> =
        tokens[start + 1..].iter().take_while(|t| is_word(t)).map(|t| t.to_string()).collect();
    (!words.is_empty()).then_some(words)
}

/// Runs `ceilfarm ARGS --help`: its standard output, or why it failed.
fn help(args: &[String]) -> Result<String, String> {
    let out = Command::new(env!("CARGO_BIN_EXE_ceilfarm"))
        .args(args)
        .arg("--help")
        .output()
        .map_err(|e| e.to_string())?;
    if out.status.success() {
        Ok(String::from_utf8_lossy(&out.stdout).into_owned())
    } else {
        Err(String::from_utf8_lossy(&out.stderr).trim().to_string())
    }
}

/// The subcommands a clap help text lists under `Commands:`.
fn subcommands(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|l| l.trim() != "Commands:")
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .collect()
}

/// Checks one shown command: each level's `--help` succeeds, and a word
/// after a command with subcommands is one of them.
fn check_command(words: &[String]) -> Result<(), String> {
    let mut text = help(&words[..1])?;
    for j in 1..words.len() {
        let subs = subcommands(&text);
        if subs.is_empty() {
            return Ok(());
        }
        if !subs.contains(&words[j]) {
            return Err(format!("no subcommand {:?} (has: {})", words[j], subs.join(", ")));
        }
        text = help(&words[..=j])?;
    }
    Ok(())
}

#[test]
fn every_shown_subcommand_parses() {
    let mut shown = BTreeSet::new();
    for (path, page) in pages() {
        for text in code_texts(&page) {
            if let Some(words) = command_words(&text) {
                shown.insert((words, path.file_name().unwrap().to_string_lossy().into_owned()));
            }
        }
    }
    assert!(shown.len() >= 10, "too few commands found: {shown:?}");
    let failures: Vec<String> = shown
        .iter()
        .filter_map(|(words, page)| {
            check_command(words).err().map(|e| format!("{page}: ceilfarm {}: {e}", words.join(" ")))
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Targets of the Markdown links `[text](target)` in `page`.
fn link_targets(page: &str) -> Vec<String> {
    page.match_indices("](")
        .filter_map(|(i, _)| {
            let rest = &page[i + 2..];
            let end = rest.find([')', ' ', '\n'])?;
            (rest.as_bytes().get(end) == Some(&b')')).then(|| rest[..end].to_string())
        })
        .collect()
}

/// Whether `target` leaves the repository's files (a URL or a page anchor).
fn is_external(target: &str) -> bool {
    target.starts_with('#') || target.contains("://") || target.starts_with("mailto:")
}

#[test]
fn every_relative_link_resolves() {
    let mut broken = Vec::new();
    let mut checked = 0;
    for (path, page) in pages() {
        for target in link_targets(&page).into_iter().filter(|t| !is_external(t)) {
            let file = target.split('#').next().unwrap_or("");
            checked += 1;
            if !path.parent().unwrap().join(file).exists() {
                broken.push(format!("{}: {target}", path.display()));
            }
        }
    }
    assert!(checked >= 5, "too few links found");
    assert!(broken.is_empty(), "links that resolve to no file:\n{}", broken.join("\n"));
}

#[test]
fn the_extractors_find_what_a_page_shows() {
    let page = "Run `ceilfarm gp fit x.toml`.\n```sh\ncargo run --release -- diagnose demo/bundle\n```\n```toml\n# ceilfarm chooses\n```\nSee [a](docs/a.md#s), [b](https://x.org).";
    let words: Vec<Vec<String>> =
        code_texts(page).iter().filter_map(|t| command_words(t)).collect();
    assert_eq!(words, vec![vec!["gp", "fit"], vec!["diagnose"]], "demo/bundle is an argument");
    assert_eq!(link_targets(page), vec!["docs/a.md#s", "https://x.org"]);
}
