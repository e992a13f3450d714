//! The engine's folders follow the pipeline, and none imports one that imports it back: each
//! folder of `engine/src` may name only the folders below it in [`LAYERS`]. Read from the
//! sources (every `crate::` path outside test modules, names re-exported at the crate root
//! resolved through `lib.rs`), so a new import across the layers fails here with its file.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Each folder and the folders it may import, lowest layer first.
const LAYERS: &[(&str, &[&str])] = &[
    ("laws", &[]),
    ("spec", &["laws"]),
    ("lang", &["laws", "spec"]),
    ("sim", &["laws", "spec"]),
    ("compile", &["laws", "spec", "sim"]),
    ("analysis", &["laws", "spec", "sim"]),
    (
        "instrument",
        &["laws", "spec", "lang", "compile", "sim", "analysis"],
    ),
];

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The folder a file of `engine/src` belongs to: its first path component (`compile.rs`
/// belongs to `compile`).
fn folder_of(path: &Path) -> String {
    let rel = path.strip_prefix(src()).unwrap();
    let first = rel
        .components()
        .next()
        .unwrap()
        .as_os_str()
        .to_str()
        .unwrap();
    first.trim_end_matches(".rs").to_string()
}

/// The code of a file without comments and without its test module (`#[cfg(test)] mod …
/// {`, at the end of a file by the crate's convention).
fn code(text: &str) -> String {
    let text = match text.find("#[cfg(test)]\nmod ") {
        Some(i) if text[i..].lines().nth(1).is_some_and(|l| l.ends_with('{')) => &text[..i],
        _ => text,
    };
    text.lines()
        .map(|l| match l.find("//") {
            Some(i) => &l[..i],
            None => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn ident(s: &str) -> &str {
    let end = s
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .unwrap_or(s.len());
    &s[..end]
}

/// The first segment of every path after `crate::`, with the members of `crate::{…}` groups.
fn crate_paths(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (i, _) in code.match_indices("crate::") {
        let rest = &code[i + "crate::".len()..];
        if let Some(group) = rest.strip_prefix('{') {
            let mut depth = 0;
            let mut start = true;
            for (j, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => start = true,
                    c if start && !c.is_whitespace() => {
                        out.push(ident(&group[j..]).to_string());
                        start = false;
                    }
                    _ => {}
                }
            }
        } else {
            out.push(ident(rest).to_string());
        }
    }
    out
}

/// Names at the crate root and the folder each comes from: the folders themselves, and what
/// `lib.rs` re-exports (`pub use folder::…`).
fn root_names(folders: &BTreeSet<String>) -> BTreeMap<String, String> {
    let lib = code(&std::fs::read_to_string(src().join("lib.rs")).unwrap());
    let mut names: BTreeMap<String, String> =
        folders.iter().map(|f| (f.clone(), f.clone())).collect();
    for stmt in lib.split(';') {
        let Some(path) = stmt.trim().strip_prefix("pub use ") else {
            continue;
        };
        let folder = ident(path).to_string();
        assert!(
            folders.contains(&folder),
            "lib.rs re-exports from `{folder}`"
        );
        let tail = path.rsplit("::").next().unwrap();
        let members = tail.trim_start_matches('{').trim_end_matches('}');
        for m in members.split(',') {
            let name = ident(m.trim());
            if !name.is_empty() {
                names.insert(name.to_string(), folder.clone());
            }
        }
    }
    names
}

#[test]
fn no_folder_imports_one_that_imports_it_back() {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    files.sort();
    let folders: BTreeSet<String> = files
        .iter()
        .map(|f| folder_of(f))
        .filter(|f| f != "lib")
        .collect();
    let layers: BTreeMap<&str, &[&str]> = LAYERS.iter().copied().collect();
    for f in &folders {
        assert!(
            layers.contains_key(f.as_str()),
            "engine/src/{f} is in no layer of this test: place it in LAYERS"
        );
    }
    let names = root_names(&folders);
    let mut wrong = Vec::new();
    let mut seen = 0;
    for file in &files {
        let from = folder_of(file);
        if from == "lib" {
            continue;
        }
        let text = std::fs::read_to_string(file).unwrap();
        for name in crate_paths(&code(&text)) {
            let Some(to) = names.get(&name) else {
                wrong.push(format!("{}: crate::{name} is not a folder", file.display()));
                continue;
            };
            seen += 1;
            if *to != from && !layers[from.as_str()].contains(&to.as_str()) {
                wrong.push(format!(
                    "{}: `{from}` imports `{to}` (crate::{name})",
                    file.strip_prefix(src()).unwrap().display()
                ));
            }
        }
    }
    assert!(
        seen > 100,
        "read only {seen} crate paths: the parsing is broken"
    );
    assert!(
        wrong.is_empty(),
        "imports across the layers:\n{}",
        wrong.join("\n")
    );
}

#[test]
fn each_folder_says_what_it_owns() {
    for (folder, _) in LAYERS {
        let dir = src().join(folder);
        let file = [dir.join("mod.rs"), src().join(format!("{folder}.rs"))]
            .into_iter()
            .find(|p| p.exists())
            .unwrap_or_else(|| panic!("no module file for {folder}"));
        let text = std::fs::read_to_string(&file).unwrap();
        let doc: Vec<&str> = text.lines().take_while(|l| l.starts_with("//!")).collect();
        assert!(
            doc.len() >= 3,
            "{} has no module doc saying what the folder owns",
            file.display()
        );
    }
}

/// The parser of this test reads grouped and nested paths.
#[test]
fn crate_paths_reads_groups() {
    let code = "use crate::{a::B, c, d::{e, f}};\nlet x = crate::g::h(crate::i);";
    assert_eq!(crate_paths(code), ["a", "c", "d", "g", "i"]);
}
