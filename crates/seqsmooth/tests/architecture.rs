//! The import rule of ARCHITECTURE.md, checked on the source: every module of a crate sits on a
//! level of the layer table in ARCHITECTURE.md, and no file imports from a module on a higher
//! level than its own. The tables are read from ARCHITECTURE.md itself (between the markers
//! `<!-- layers: CRATE -->` and `<!-- /layers -->`), so the document and the check cannot drift
//! apart: a module missing from its table fails the test too.
//!
//! A module's place is the longest table entry that prefixes its path (`polynomial::fading::gains`
//! before `polynomial::fading`). Imports are every `crate::…` and `super::…` path in the code
//! (use declarations, braced groups included, and paths inside expressions); comments and doc
//! comments are skipped.

use std::collections::BTreeMap;
use std::fs;
use std::path::{Path, PathBuf};

/// The workspace root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The layer table of `krate` in ARCHITECTURE.md: module path (without `crate::`) → level.
fn layers(krate: &str) -> BTreeMap<String, usize> {
    let doc = fs::read_to_string(root().join("ARCHITECTURE.md")).expect("ARCHITECTURE.md exists");
    let start = format!("<!-- layers: {krate} -->");
    let begin = doc
        .find(&start)
        .unwrap_or_else(|| panic!("ARCHITECTURE.md has no `{start}` table"));
    let rest = &doc[begin + start.len()..];
    let end = rest
        .find("<!-- /layers -->")
        .expect("the layer table is closed");
    let mut table = BTreeMap::new();
    for line in rest[..end].lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        // | level | modules | what they own |
        if cells.len() < 4 {
            continue;
        }
        let Ok(level) = cells[1].parse::<usize>() else {
            continue;
        };
        for module in cells[2].split(',') {
            // `` is the crate root (lib.rs or main.rs)
            let module = module.trim();
            if module.starts_with('`') {
                table.insert(module.trim_matches('`').to_string(), level);
            }
        }
    }
    assert!(!table.is_empty(), "the `{krate}` layer table is empty");
    table
}

/// The module path of a source file: `polynomial/fading/gains.rs` → `polynomial::fading::gains`,
/// `polynomial/mod.rs` → `polynomial`, `lib.rs`/`main.rs` → `` (the crate root).
fn module_of(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).unwrap();
    let mut parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_string())
        .collect();
    if matches!(
        parts.last().map(String::as_str),
        Some("mod" | "lib" | "main")
    ) {
        parts.pop();
    }
    parts
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The code of a file without comments (line comments, doc comments, block comments) and
/// without string literals' contents, so that neither a doc link nor a message counts as an
/// import.
fn code_only(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let b = text.as_bytes();
    let mut i = 0;
    let mut depth = 0usize;
    while i < b.len() {
        if depth > 0 {
            if b[i..].starts_with(b"*/") {
                depth -= 1;
                i += 2;
            } else if b[i..].starts_with(b"/*") {
                depth += 1;
                i += 2;
            } else {
                i += 1;
            }
        } else if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else if b[i..].starts_with(b"/*") {
            depth = 1;
            i += 2;
        } else if b[i] == b'"' {
            out.push('"');
            i += 1;
            while i < b.len() && b[i] != b'"' {
                i += if b[i] == b'\\' { 2 } else { 1 };
            }
            out.push('"');
            i += 1;
        } else if b[i] == b'\'' && i + 2 < b.len() && (b[i + 2] == b'\'' || b[i + 1] == b'\\') {
            // a char literal ('"', '\n', …), not a lifetime
            let close = text[i + 1..].find('\'').map_or(b.len(), |k| i + 1 + k + 1);
            i = close;
        } else {
            let c = text[i..].chars().next().unwrap();
            out.push(c);
            i += c.len_utf8();
        }
    }
    out
}

/// The code without its inline test modules (`#[cfg(test)] mod name { … }`): their `super` is
/// the file's module, not its parent, and test helpers may reach anywhere.
fn without_test_modules(code: &str) -> String {
    let mut out = String::with_capacity(code.len());
    let mut rest = code;
    while let Some(k) = rest.find("#[cfg(test)]") {
        let after = rest[k + "#[cfg(test)]".len()..].trim_start();
        if !after.starts_with("mod ")
            || !after[..after.find('\n').unwrap_or(after.len())].contains('{')
        {
            out.push_str(&rest[..k + 1]);
            rest = &rest[k + 1..];
            continue;
        }
        out.push_str(&rest[..k]);
        let open = rest[k..].find('{').map(|j| k + j).unwrap();
        let mut depth = 0usize;
        let mut end = rest.len();
        for (j, c) in rest[open..].char_indices() {
            match c {
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth == 0 {
                        end = open + j + 1;
                        break;
                    }
                }
                _ => {}
            }
        }
        rest = &rest[end..];
    }
    out.push_str(rest);
    out
}

/// Every path the code names from `crate::` or `super::`, with braced `use` groups expanded,
/// resolved to an absolute module path (a list of segments).
fn imports(code: &str, module: &[String]) -> Vec<Vec<String>> {
    let mut found = Vec::new();
    let bytes = code.as_bytes();
    let is_ident = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    let mut i = 0;
    while i < bytes.len() {
        let at_start = i == 0 || !(is_ident(bytes[i - 1]) || bytes[i - 1] == b':');
        let starts = |word: &[u8]| bytes[i..].starts_with(word);
        if at_start && (starts(b"crate::") || starts(b"super::")) {
            let rest = &code[i..];
            let (len, paths) = parse_path(rest);
            for p in paths {
                if let Some(abs) = resolve(&p, module) {
                    found.push(abs);
                }
            }
            i += len.max(1);
            continue;
        }
        i += 1;
    }
    found
}

/// Parses `a::b::{c, d::{e, f}}` (or a plain path) at the start of `s`: its length and the
/// paths it names.
fn parse_path(s: &str) -> (usize, Vec<Vec<String>>) {
    let b = s.as_bytes();
    let mut prefix: Vec<String> = Vec::new();
    let mut i = 0;
    loop {
        let start = i;
        while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
            i += 1;
        }
        if i > start {
            prefix.push(s[start..i].to_string());
        }
        if s[i..].starts_with("::") {
            i += 2;
            if s[i..].starts_with('{') {
                // a group: split at top-level commas
                let mut depth = 0;
                let mut j = i;
                let mut items = Vec::new();
                let mut item_start = i + 1;
                while j < b.len() {
                    match b[j] {
                        b'{' => depth += 1,
                        b'}' => {
                            depth -= 1;
                            if depth == 0 {
                                items.push(&s[item_start..j]);
                                break;
                            }
                        }
                        b',' if depth == 1 => {
                            items.push(&s[item_start..j]);
                            item_start = j + 1;
                        }
                        _ => {}
                    }
                    j += 1;
                }
                let mut out = Vec::new();
                for item in items {
                    let item = item.trim();
                    if item.is_empty() {
                        continue;
                    }
                    let (_, subs) = parse_path(item);
                    for sub in subs {
                        let mut p = prefix.clone();
                        p.extend(sub);
                        out.push(p);
                    }
                }
                return (j + 1, out);
            }
            continue;
        }
        return (i, vec![prefix]);
    }
}

/// `crate::a::b` → `[a, b]`; `super::x` relative to `module`; `self` segments dropped.
fn resolve(path: &[String], module: &[String]) -> Option<Vec<String>> {
    let mut abs: Vec<String> = Vec::new();
    let mut it = path.iter().peekable();
    match it.peek().map(|s| s.as_str()) {
        Some("crate") => {
            it.next();
        }
        Some("super") => {
            abs = module.to_vec();
            while it.peek().map(|s| s.as_str()) == Some("super") {
                it.next();
                abs.pop()?;
            }
        }
        _ => return None,
    }
    abs.extend(it.filter(|s| s.as_str() != "self").cloned());
    Some(abs)
}

/// The level of a module path: the longest table entry that prefixes it (the crate root, ``,
/// only for the root itself, so that a module missing from the table is found).
fn level_of(table: &BTreeMap<String, usize>, path: &[String]) -> Option<(String, usize)> {
    let shortest = usize::from(!path.is_empty());
    (shortest..=path.len()).rev().find_map(|n| {
        let key = path[..n].join("::");
        table.get(&key).map(|&l| (key, l))
    })
}

fn check_crate(krate: &str, src: &Path) {
    let table = layers(krate);
    let mut files = Vec::new();
    rust_files(src, &mut files);
    files.sort();
    let mut violations = Vec::new();
    for file in &files {
        let module = module_of(src, file);
        let Some((home, level)) = level_of(&table, &module) else {
            violations.push(format!(
                "{}: module `{}` is in no layer of ARCHITECTURE.md",
                file.display(),
                module.join("::")
            ));
            continue;
        };
        let code = without_test_modules(&code_only(&fs::read_to_string(file).unwrap()));
        for target in imports(&code, &module) {
            // Imports from the module's own home (and its children) are inside one layer.
            if target.starts_with(&module) {
                continue;
            }
            if let Some((to, to_level)) = level_of(&table, &target) {
                if to_level > level {
                    violations.push(format!(
                        "{}: `{home}` (level {level}) imports `{}` from `{to}` (level {to_level})",
                        file.strip_prefix(root()).unwrap_or(file).display(),
                        target.join("::"),
                    ));
                }
            }
        }
    }
    assert!(
        violations.is_empty(),
        "the import rule of ARCHITECTURE.md is broken:\n{}",
        violations.join("\n")
    );
}

#[test]
fn library_modules_import_only_from_their_level_or_below() {
    check_crate("seqsmooth", &root().join("crates/seqsmooth/src"));
}

#[test]
fn command_modules_import_only_from_their_level_or_below() {
    check_crate("seqsmooth-cli", &root().join("crates/seqsmooth-cli/src"));
}

#[test]
fn binding_modules_import_only_from_their_level_or_below() {
    check_crate("seqsmooth-py", &root().join("crates/seqsmooth-py/src"));
}

#[test]
fn the_checker_sees_braced_relative_and_inline_paths() {
    let module: Vec<String> = ["polynomial", "fading", "filter"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let code = code_only(
        "use super::switch::{SwitchRule, memory::{a, b}};\n\
         // use crate::hidden::Thing;\n\
         let x = crate::calculus::factorial::<f64>(3); let s = \"crate::in_a_string\";\n\
         use super::super::options::Engine;",
    );
    let got: Vec<String> = imports(&code, &module)
        .iter()
        .map(|p| p.join("::"))
        .collect();
    assert_eq!(
        got,
        [
            "polynomial::fading::switch::SwitchRule",
            "polynomial::fading::switch::memory::a",
            "polynomial::fading::switch::memory::b",
            "calculus::factorial",
            "polynomial::options::Engine",
        ]
    );
    // and a violation is found: a low layer naming a higher one
    let table: BTreeMap<String, usize> =
        [("calculus".to_string(), 1), ("polynomial".to_string(), 5)]
            .into_iter()
            .collect();
    let from = level_of(&table, &["calculus".to_string()]).unwrap().1;
    let to = level_of(&table, &["polynomial".to_string(), "x".to_string()])
        .unwrap()
        .1;
    assert!(to > from);
}

/// In the command, no subcommand (`commands::<name>`) imports another: what two of them use is
/// in `commands::shared`. (Subcommands share a level, so the level check alone lets them.)
#[test]
fn no_subcommand_imports_another() {
    let src = root().join("crates/seqsmooth-cli/src");
    let mut files = Vec::new();
    rust_files(&src.join("commands"), &mut files);
    files.sort();
    assert!(
        files.len() > 10,
        "the subcommands are in crates/seqsmooth-cli/src/commands/"
    );
    let mut violations = Vec::new();
    for file in &files {
        let module = module_of(&src, file);
        // `commands` itself (commands/mod.rs) declares the modules; `shared` is below them.
        let Some(own) = module.get(1).filter(|own| *own != "shared") else {
            continue;
        };
        let code = without_test_modules(&code_only(&fs::read_to_string(file).unwrap()));
        for target in imports(&code, &module) {
            if let [first, other, ..] = target.as_slice() {
                if first == "commands" && other != own && other != "shared" {
                    violations.push(format!(
                        "{}: `commands::{own}` imports `{}`",
                        file.strip_prefix(root()).unwrap_or(file).display(),
                        target.join("::")
                    ));
                }
            }
        }
    }
    assert!(
        violations.is_empty(),
        "a subcommand imports another (move what they share into commands::shared):\n{}",
        violations.join("\n")
    );
}

/// The files of `src` that import each other in a circle: the strongly connected components of
/// the graph "file `a` names a path in file `b`" (a path goes to the file whose module is its
/// longest prefix) with more than one file, each as its files' module paths.
fn import_circles(src: &Path) -> Vec<Vec<String>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    files.sort();
    let modules: Vec<Vec<String>> = files.iter().map(|f| module_of(src, f)).collect();
    let index: BTreeMap<String, usize> = modules
        .iter()
        .enumerate()
        .map(|(i, m)| (m.join("::"), i))
        .collect();
    let edges: Vec<Vec<usize>> = files
        .iter()
        .zip(&modules)
        .enumerate()
        .map(|(i, (file, module))| {
            let code = without_test_modules(&code_only(&fs::read_to_string(file).unwrap()));
            let mut to: Vec<usize> = imports(&code, module)
                .iter()
                .filter_map(|t| {
                    (0..=t.len())
                        .rev()
                        .find_map(|n| index.get(&t[..n].join("::")))
                })
                .copied()
                .filter(|&j| j != i)
                .collect();
            to.sort_unstable();
            to.dedup();
            to
        })
        .collect();
    // reach[i]: the files reachable from file i
    let reach: Vec<Vec<bool>> = (0..files.len())
        .map(|start| {
            let mut seen = vec![false; files.len()];
            let mut stack = vec![start];
            while let Some(i) = stack.pop() {
                for &j in &edges[i] {
                    if !seen[j] {
                        seen[j] = true;
                        stack.push(j);
                    }
                }
            }
            seen
        })
        .collect();
    let mut done = vec![false; files.len()];
    let mut circles = Vec::new();
    for i in 0..files.len() {
        if done[i] || !reach[i][i] {
            continue;
        }
        let members: Vec<usize> = (0..files.len())
            .filter(|&j| reach[i][j] && reach[j][i])
            .collect();
        for &j in &members {
            done[j] = true;
        }
        circles.push(members.iter().map(|&j| modules[j].join("::")).collect());
    }
    circles
}

#[test]
fn no_library_file_is_in_an_import_circle_with_more_than_one_other() {
    let wide: Vec<Vec<String>> = import_circles(&root().join("crates/seqsmooth/src"))
        .into_iter()
        .filter(|c| c.len() > 2)
        .collect();
    assert!(
        wide.is_empty(),
        "files importing each other in a circle of more than two:\n{wide:#?}"
    );
}

#[test]
fn the_circle_finder_finds_a_circle_of_three_and_not_a_chain() {
    let dir = std::env::temp_dir().join(format!("seqsmooth-circles-{}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(dir.join("m")).unwrap();
    let write = |p: &str, s: &str| fs::write(dir.join(p), s).unwrap();
    write("lib.rs", "pub mod m;\n");
    write("m/mod.rs", "mod a; mod b; mod c; mod d;\n");
    write("m/a.rs", "use super::b::B;\n");
    write("m/b.rs", "use crate::m::c::C;\n");
    write("m/c.rs", "use super::a::A; use super::d::D;\n");
    write("m/d.rs", "pub struct D;\n");
    let circles = import_circles(&dir);
    fs::remove_dir_all(&dir).unwrap();
    assert_eq!(circles, vec![vec!["m::a", "m::b", "m::c"]]);
}

/// Every library source file small enough to hold in mind: at most 800 lines.
#[test]
fn no_library_file_is_over_800_lines() {
    let mut files = Vec::new();
    rust_files(&root().join("crates/seqsmooth/src"), &mut files);
    assert!(files.len() > 100, "found only {} files", files.len());
    let long: Vec<(usize, PathBuf)> = files
        .into_iter()
        .map(|f| (fs::read_to_string(&f).unwrap().lines().count(), f))
        .filter(|(n, _)| *n > 800)
        .collect();
    assert!(long.is_empty(), "library files over 800 lines: {long:?}");
}
