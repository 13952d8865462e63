//! The layering check: every module imports only lower layers, and no hand-written source file
//! is over 800 lines.
//!
//! The layer order is declared once, in `docs/layers.txt` (lowest first; modules on one line
//! are peers). This test reads it, maps every file of `src/` (the library; the binaries in
//! `src/bin/` sit above every layer) to the listed module that owns it (the longest listed
//! prefix of its module path), resolves every `crate::…`, `super::…` and `self::…` path in it
//! (use trees included) and fails naming file, line and path when the path reaches a module
//! on the same or a higher line. It also fails when a listed module has no source file, when a
//! top-level module of `src/lib.rs` is not listed, and when a path goes through a namespace
//! module that only groups listed ones (`crate::plan::X` where `plan::types` is listed: import
//! from the listed module).
//!
//! Unit tests (`#[cfg(test)]` items and the files they declare) are not checked: a test may
//! build its fixtures from any layer (a whole configuration, a controller). Comments, doc
//! comments (intra-doc links) and string literals are not code and are skipped.
//!
//! The size rule covers `src/`, `tests/` and `benches/`: a file over [`MAX_LINES`] lines fails,
//! except the ones in [`OVERSIZE_PENDING`] (being split by another change); an entry there that
//! is no longer oversized fails too, so the list only shrinks.
//!
//! The design documents: no file cites the old specification (it is not in the repository; the
//! citations point at `docs/` now), and every pointer into `docs/*.md` names a section that
//! exists: "docs/METHODS.md, Local path" (the text after the comma starts with a heading of
//! that file), a `docs/CONVENTIONS.md#heading` anchor, and the links between the documents.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Largest hand-written source file, lines.
const MAX_LINES: usize = 800;

/// Files known to be over [`MAX_LINES`] whose split is under way elsewhere (none now).
const OVERSIZE_PENDING: &[&str] = &[];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The declared layers: one entry per line, each a list of module paths.
fn layers(text: &str) -> Vec<Vec<Vec<String>>> {
    text.lines()
        .map(|l| l.split('#').next().unwrap_or("").trim())
        .filter(|l| !l.is_empty())
        .map(|l| {
            l.split_whitespace()
                .map(|m| m.split("::").map(str::to_string).collect())
                .collect()
        })
        .collect()
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// Module path of a library file: `src/plan/coverage/mod.rs` → `plan::coverage`.
fn module_of(rel: &Path) -> Vec<String> {
    let mut parts: Vec<String> = rel
        .iter()
        .skip(1)
        .map(|s| s.to_string_lossy().to_string())
        .collect();
    if let Some(last) = parts.pop() {
        let stem = last.trim_end_matches(".rs");
        if stem != "mod" && stem != "lib" {
            parts.push(stem.to_string());
        }
    }
    parts
}

/// The source with comments, strings and char literals blanked (newlines kept, so line
/// numbers stay right).
fn strip(src: &str) -> String {
    let b: Vec<char> = src.chars().collect();
    let mut out = String::with_capacity(src.len());
    let blank = |c: char| if c == '\n' { '\n' } else { ' ' };
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let next = b.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < b.len() && b[i] != '\n' {
                out.push(' ');
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == '/' && b.get(i + 1) == Some(&'*') {
                    depth += 1;
                    out.push_str("  ");
                    i += 2;
                } else if b[i] == '*' && b.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    out.push_str("  ");
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    out.push(blank(b[i]));
                    i += 1;
                }
            }
        } else if c == 'r' && (next == Some('"') || next == Some('#')) && !ident_before(&b, i) {
            // Raw string r"…" or r#"…"#.
            let mut j = i + 1;
            let mut hashes = 0;
            while b.get(j) == Some(&'#') {
                hashes += 1;
                j += 1;
            }
            if b.get(j) != Some(&'"') {
                out.push(c);
                i += 1;
                continue;
            }
            j += 1;
            loop {
                if j >= b.len() {
                    break;
                }
                if b[j] == '"' && (0..hashes).all(|k| b.get(j + 1 + k) == Some(&'#')) {
                    j += 1 + hashes;
                    break;
                }
                j += 1;
            }
            for &ch in &b[i..j.min(b.len())] {
                out.push(blank(ch));
            }
            i = j;
        } else if c == '"' {
            out.push(' ');
            i += 1;
            while i < b.len() && b[i] != '"' {
                if b[i] == '\\' {
                    out.push(' ');
                    i += 1;
                }
                if i < b.len() {
                    out.push(blank(b[i]));
                    i += 1;
                }
            }
            out.push(' ');
            i += 1;
        } else if c == '\'' {
            // A char literal ('x', '\n', '\u{1F600}'); a lifetime ('a) is left alone.
            let close = if next == Some('\\') {
                (i + 2..b.len().min(i + 12)).find(|&j| b[j] == '\'')
            } else if b.get(i + 2) == Some(&'\'') {
                Some(i + 2)
            } else {
                None
            };
            match close {
                Some(j) => {
                    for _ in i..=j {
                        out.push(' ');
                    }
                    i = j + 1;
                }
                None => {
                    out.push(c);
                    i += 1;
                }
            }
        } else {
            out.push(c);
            i += 1;
        }
    }
    out
}

fn ident_before(b: &[char], i: usize) -> bool {
    i > 0 && (b[i - 1].is_alphanumeric() || b[i - 1] == '_')
}

/// The code with `#[cfg(test)]` items blanked; also the names of test modules declared as
/// files (`#[cfg(test)] mod tests;`).
fn drop_test_items(code: &str) -> (String, Vec<String>) {
    let mut out: Vec<char> = code.chars().collect();
    let mut files = Vec::new();
    let pat: Vec<char> = "#[cfg(test)]".chars().collect();
    let mut i = 0;
    while i + pat.len() <= out.len() {
        if out[i..i + pat.len()] != pat[..] {
            i += 1;
            continue;
        }
        // The item runs to its first `;` at depth 0, or to the end of its first block.
        let start = i;
        let mut j = i + pat.len();
        let mut depth = 0i32;
        let mut header = String::new();
        while j < out.len() {
            let c = out[j];
            if depth == 0 && c == ';' {
                j += 1;
                break;
            }
            if c == '{' {
                depth += 1;
            } else if c == '}' {
                depth -= 1;
                if depth == 0 {
                    j += 1;
                    break;
                }
            } else if depth == 0 {
                header.push(c);
            }
            j += 1;
        }
        let words: Vec<&str> = header.split_whitespace().collect();
        if let Some(k) = words.iter().position(|w| *w == "mod") {
            if out[..j].last() == Some(&';') {
                if let Some(name) = words.get(k + 1) {
                    files.push(name.trim_end_matches(';').to_string());
                }
            }
        }
        let end = j.min(out.len());
        for c in &mut out[start..end] {
            if *c != '\n' {
                *c = ' ';
            }
        }
        i = j;
    }
    (out.into_iter().collect(), files)
}

/// A path found in the code: its line and its segments from the crate root.
struct Found {
    line: usize,
    text: String,
    path: Vec<String>,
}

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// Parse a use tree at `s[i..]` (after a prefix already resolved to `base`), pushing every
/// leaf path. Returns the index after the tree.
fn tree(s: &[char], mut i: usize, base: &[String], out: &mut Vec<Vec<String>>) -> usize {
    let skip_ws = |s: &[char], mut i: usize| {
        while i < s.len() && s[i].is_whitespace() {
            i += 1;
        }
        i
    };
    let mut path = base.to_vec();
    loop {
        i = skip_ws(s, i);
        if i < s.len() && s[i] == '{' {
            i += 1;
            loop {
                i = skip_ws(s, i);
                if i >= s.len() {
                    return i;
                }
                if s[i] == '}' {
                    return i + 1;
                }
                if s[i] == ',' {
                    i += 1;
                    continue;
                }
                i = tree(s, i, &path, out);
            }
        }
        if i < s.len() && s[i] == '*' {
            out.push(path);
            return i + 1;
        }
        let start = i;
        while i < s.len() && is_ident(s[i]) {
            i += 1;
        }
        let word: String = s[start..i].iter().collect();
        if word.is_empty() {
            out.push(path);
            return i;
        }
        match word.as_str() {
            "self" => {}
            "super" => {
                path.pop();
            }
            _ => path.push(word),
        }
        let j = skip_ws(s, i);
        if s.get(j) == Some(&':') && s.get(j + 1) == Some(&':') {
            i = j + 2;
        } else {
            out.push(path);
            return i;
        }
    }
}

/// Every `crate::`, `super::` and `self::` path of `code`, resolved from module `module`.
fn paths(code: &str, module: &[String]) -> Vec<Found> {
    let s: Vec<char> = code.chars().collect();
    let mut line_of = Vec::with_capacity(s.len());
    let mut line = 1;
    for &c in &s {
        line_of.push(line);
        if c == '\n' {
            line += 1;
        }
    }
    let mut found = Vec::new();
    let mut i = 0;
    while i < s.len() {
        if !is_ident(s[i]) || (i > 0 && (is_ident(s[i - 1]) || s[i - 1] == '$')) {
            i += 1;
            continue;
        }
        let start = i;
        while i < s.len() && is_ident(s[i]) {
            i += 1;
        }
        let word: String = s[start..i].iter().collect();
        let base: Vec<String> = match word.as_str() {
            "crate" => Vec::new(),
            "super" => module[..module.len().saturating_sub(1)].to_vec(),
            "self" => module.to_vec(),
            _ => continue,
        };
        // Only a path: `crate::`, `super::`, `self::` (not `self.x` or `&self`).
        let mut j = i;
        while j < s.len() && s[j].is_whitespace() {
            j += 1;
        }
        if !(s.get(j) == Some(&':') && s.get(j + 1) == Some(&':')) {
            continue;
        }
        // A preceding `::` means this is not the path's start (`super::super::x`).
        let mut k = start;
        while k > 0 && s[k - 1].is_whitespace() {
            k -= 1;
        }
        if k >= 2 && s[k - 1] == ':' && s[k - 2] == ':' {
            continue;
        }
        let mut leaves = Vec::new();
        let end = tree(&s, j + 2, &base, &mut leaves);
        let text: String = s[start..end.min(s.len())]
            .iter()
            .collect::<String>()
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        for path in leaves {
            found.push(Found {
                line: line_of[start],
                text: text.clone(),
                path,
            });
        }
        i = end.max(i);
    }
    found
}

/// The listed module owning `path` (its longest listed prefix) and its layer.
fn owner<'a>(
    listed: &'a [(Vec<String>, usize)],
    path: &[String],
) -> Option<&'a (Vec<String>, usize)> {
    listed
        .iter()
        .filter(|(m, _)| path.starts_with(m))
        .max_by_key(|(m, _)| m.len())
}

fn show(m: &[String]) -> String {
    m.join("::")
}

#[test]
fn modules_import_only_lower_layers() {
    let root = root();
    let text = std::fs::read_to_string(root.join("docs/layers.txt")).expect("docs/layers.txt");
    let listed: Vec<(Vec<String>, usize)> = layers(&text)
        .into_iter()
        .enumerate()
        .flat_map(|(rank, mods)| mods.into_iter().map(move |m| (m, rank)))
        .collect();
    let mut problems = Vec::new();

    // Every listed module exists; every top-level module is listed.
    for (m, _) in &listed {
        let dir = root.join("src").join(m.join("/"));
        if !dir.with_extension("rs").is_file() && !dir.join("mod.rs").is_file() {
            problems.push(format!(
                "docs/layers.txt lists `{}`, which has no source file",
                show(m)
            ));
        }
    }
    let lib = strip(&std::fs::read_to_string(root.join("src/lib.rs")).expect("src/lib.rs"));
    let top: BTreeSet<String> = lib
        .lines()
        .filter_map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            let k = w.iter().position(|x| *x == "mod")?;
            w.get(k + 1).map(|n| n.trim_end_matches(';').to_string())
        })
        .collect();
    for name in &top {
        if !listed.iter().any(|(m, _)| m[0] == *name) {
            problems.push(format!(
                "src/lib.rs declares `mod {name}`, which docs/layers.txt does not list"
            ));
        }
    }

    let mut files = Vec::new();
    rust_files(&root.join("src"), &mut files);
    let mut test_files: BTreeSet<Vec<String>> = BTreeSet::new();
    let mut checked = 0;
    // Parents first, so that test files declared by a parent are known before they are read.
    files.sort_by_key(|p| p.components().count());
    for file in &files {
        let rel = file.strip_prefix(&root).unwrap_or(file).to_path_buf();
        if rel.starts_with("src/bin") || rel == Path::new("src/lib.rs") {
            continue;
        }
        let module = module_of(&rel);
        if test_files.iter().any(|t| module.starts_with(t)) {
            continue;
        }
        let src = std::fs::read_to_string(file).expect("readable source");
        let (code, tests) = drop_test_items(&strip(&src));
        for t in tests {
            let mut m = module.clone();
            m.push(t);
            test_files.insert(m);
        }
        let own = match owner(&listed, &module) {
            Some(o) => Some(o),
            None if listed.iter().any(|(m, _)| m.starts_with(&module)) => None,
            None => {
                problems.push(format!(
                    "{}: module `{}` is in no layer of docs/layers.txt",
                    rel.display(),
                    show(&module)
                ));
                continue;
            }
        };
        checked += 1;
        for f in paths(&code, &module) {
            let target = owner(&listed, &f.path);
            let bad = match (own, target) {
                // Inside its own module.
                (Some((m, _)), Some((t, _))) if m == t => None,
                (Some((_, rank)), Some((t, trank))) if trank >= rank => Some(format!(
                    "imports `{}` (layer {}) from layer {}",
                    show(t),
                    trank,
                    rank
                )),
                (_, Some(_)) => None,
                // A namespace module (e.g. `plan`) may name its own children only.
                (None, None) if f.path.starts_with(&module) => None,
                (_, None) => Some(format!(
                    "`{}` is in no layer of docs/layers.txt (list its module, or import a namespace's item from its listed submodule)",
                    show(&f.path)
                )),
            };
            if let Some(why) = bad {
                problems.push(format!("{}:{}: `{}` {why}", rel.display(), f.line, f.text));
            }
        }
    }
    assert!(checked > 50, "only {checked} files checked");
    problems.dedup();
    assert!(
        problems.is_empty(),
        "layering (docs/layers.txt) broken in {} place(s):\n{}",
        problems.len(),
        problems.join("\n")
    );
}

#[test]
fn source_files_stay_under_800_lines() {
    let root = root();
    let mut files = Vec::new();
    for dir in ["src", "tests", "benches"] {
        rust_files(&root.join(dir), &mut files);
    }
    let mut problems = Vec::new();
    for file in &files {
        let rel = file.strip_prefix(&root).unwrap_or(file);
        let name = rel.to_string_lossy().replace('\\', "/");
        let lines = std::fs::read_to_string(file)
            .map(|t| t.lines().count())
            .unwrap_or(0);
        let pending = OVERSIZE_PENDING.contains(&name.as_str());
        if lines > MAX_LINES && !pending {
            problems.push(format!(
                "{name}: {lines} lines (at most {MAX_LINES}: split it)"
            ));
        }
        if pending && lines <= MAX_LINES {
            problems.push(format!(
                "{name}: {lines} lines now; remove it from OVERSIZE_PENDING in tests/binaries/layering.rs"
            ));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn the_path_parser_resolves_use_trees() {
    let m: Vec<String> = vec!["plan".into(), "abline".into()];
    let code = strip(
        "use super::{coverage::{PlanSegment, turns::TurnCache}, turns};\n\
         // use crate::demo::x;\n\
         let s = \"crate::config\"; let c = '{';\n\
         fn f(&self) { crate::geo::v2(self.x, super::super::y::Z) }\n",
    );
    let found: Vec<String> = paths(&code, &m).iter().map(|f| show(&f.path)).collect();
    assert_eq!(
        found,
        [
            "plan::coverage::PlanSegment",
            "plan::coverage::turns::TurnCache",
            "plan::turns",
            "geo::v2",
            "y::Z"
        ]
    );
    let (code, files) = drop_test_items(
        "fn a() {}\n#[cfg(test)]\nmod tests {\n use crate::demo;\n}\n#[cfg(test)]\nmod more;\n",
    );
    assert!(!code.contains("demo"));
    assert_eq!(files, ["more"]);
}

// ---- The design documents: no citations of the old specification, and every pointer into
// docs/*.md names a section that exists. ----

/// Every file under `dir` (recursively), or `dir` itself when it is a file.
fn all_files(dir: &Path, out: &mut Vec<PathBuf>) {
    if dir.is_file() {
        out.push(dir.to_path_buf());
        return;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            all_files(&p, out);
        } else {
            out.push(p);
        }
    }
}

/// The places that may point into docs/: the code, the tools, the configuration, the READMEs
/// and the documents themselves.
fn doc_citing_files() -> Vec<PathBuf> {
    let root = root();
    let mut files = Vec::new();
    for p in [
        "src",
        "tests",
        "benches",
        "build.rs",
        "tools",
        "config",
        "docs",
        "README.md",
    ] {
        all_files(&root.join(p), &mut files);
    }
    // tools/vcan-vm's cache (git-ignored) holds a copy of config/ as the VM saw it.
    let cache = root.join("tools/vm/cache");
    files.retain(|f| !f.starts_with(&cache));
    files.sort();
    files
}

/// GitHub's anchor of a Markdown heading: lower case, spaces to hyphens, other punctuation
/// dropped.
fn slug(heading: &str) -> String {
    heading
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// The headings of a Markdown file (outside code fences), without their `#`s.
fn headings(text: &str) -> Vec<String> {
    let mut fenced = false;
    let mut out = Vec::new();
    for line in text.lines() {
        if line.starts_with("```") {
            fenced = !fenced;
        } else if !fenced && line.starts_with('#') {
            out.push(line.trim_start_matches('#').trim().to_string());
        }
    }
    out
}

/// A file's text with each line's indentation and comment marker dropped and the lines joined
/// by spaces, so that a pointer wrapped over two comment lines reads as one.
fn joined_text(text: &str) -> String {
    let mut out = String::new();
    for line in text.lines() {
        let t = line.trim_start();
        let t = ["//!", "///", "//", "#"]
            .iter()
            .find_map(|m| t.strip_prefix(m))
            .unwrap_or(t);
        out.push_str(t.trim());
        out.push(' ');
    }
    out
}

#[test]
fn no_comment_cites_the_old_spec() {
    // The needle is built so that this file does not contain it.
    let needle = format!("SPEC {}", '§');
    let root = root();
    let mut found = Vec::new();
    for file in doc_citing_files() {
        let Ok(text) = std::fs::read(&file) else {
            continue;
        };
        let text = String::from_utf8_lossy(&text);
        for (i, line) in text.lines().enumerate() {
            if line.contains(&needle) {
                let rel = file.strip_prefix(&root).unwrap_or(&file);
                found.push(format!("{}:{}: {}", rel.display(), i + 1, line.trim()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "point at a section of docs/ARCHITECTURE.md or docs/CONVENTIONS.md or docs/METHODS.md (\"see \
         docs/METHODS.md, Local path\") instead of the specification, which is not in the \
         repository:\n{}",
        found.join("\n")
    );
}

#[test]
fn pointers_into_docs_name_existing_sections() {
    let root = root();
    let mut problems = Vec::new();
    let mut checked = 0;
    for file in doc_citing_files() {
        let Ok(bytes) = std::fs::read(&file) else {
            continue;
        };
        let Ok(text) = String::from_utf8(bytes) else {
            continue;
        };
        let rel = file.strip_prefix(&root).unwrap_or(&file).to_path_buf();
        let in_docs = rel.starts_with("docs");
        let text = joined_text(&text);
        // `docs/<name>.md` anywhere; `](<name>.md` and `](#` links inside docs/ too.
        let mut refs: Vec<(String, &str)> = Vec::new();
        for (i, _) in text.match_indices("docs/") {
            let rest = &text[i + 5..];
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_' || *c == '-')
                .collect();
            if let Some(after) = rest[name.len()..].strip_prefix(".md") {
                refs.push((name, after));
            }
        }
        if in_docs {
            let own = rel
                .file_stem()
                .map(|s| s.to_string_lossy().to_string())
                .unwrap_or_default();
            for (i, _) in text.match_indices("](") {
                let rest = &text[i + 2..];
                if rest.starts_with('#') {
                    refs.push((own.clone(), rest));
                    continue;
                }
                let name: String = rest
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_' || *c == '-')
                    .collect();
                if let Some(after) = rest[name.len()..].strip_prefix(".md") {
                    refs.push((name, after));
                }
            }
        }
        for (name, after) in refs {
            let target = root.join("docs").join(format!("{name}.md"));
            let Ok(doc) = std::fs::read_to_string(&target) else {
                problems.push(format!("{}: docs/{name}.md does not exist", rel.display()));
                continue;
            };
            let heads = headings(&doc);
            if let Some(anchor) = after.strip_prefix('#') {
                let anchor: String = anchor
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '-' || *c == '_')
                    .collect();
                checked += 1;
                if !heads.iter().any(|h| slug(h) == anchor) {
                    problems.push(format!(
                        "{}: docs/{name}.md has no section #{anchor}",
                        rel.display()
                    ));
                }
            } else if let Some(section) = after.strip_prefix(", ") {
                checked += 1;
                let names = |h: &&String| {
                    section.starts_with(h.as_str())
                        && !section[h.len()..].starts_with(|c: char| c.is_alphanumeric())
                };
                if !heads.iter().any(|h| names(&h)) {
                    let shown: String = section.chars().take(40).collect();
                    problems.push(format!(
                        "{}: \"docs/{name}.md, {shown}…\" names no section of docs/{name}.md \
                         (its sections: {})",
                        rel.display(),
                        heads.join(" | ")
                    ));
                }
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    // The pointers that replaced the old citations are all checked here.
    assert!(checked >= 30, "only {checked} pointers into docs/ found");
}
