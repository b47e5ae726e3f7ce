//! Files import in layers: within each crate of the workspace (and the command), no two files
//! import each other, directly or round a longer circle. A reader can then start from the
//! files that import nothing of their crate and read upwards, and a change to a file touches
//! only the files above it.
//!
//! Read from the source, not the compiler: every `crate::…` and `super::…` path outside the
//! files' test modules, every `use` of a child module, and names used through the crate
//! root's re-exports (`use crate::{Mesh, …}`) resolved to the file that defines them.
//!
//! Files and the vocabulary stay small: no Rust file of the workspace is over
//! [`MAX_FILE_LINES`] lines (a longer one holds more than one idea, to be split by idea), and
//! `radiosity_core`, which every crate builds on, is at most [`MAX_CORE_LINES`] in all.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Circles that are known and left as they are, each with why. None now: a circle that has
/// to stay for a while is listed here, with the reason and the way to end it.
const KNOWN_CIRCLES: &[(&str, &[&str])] = &[];

/// Most lines in one Rust file (source, tests, benches, examples) of the workspace.
const MAX_FILE_LINES: usize = 800;

/// Most lines in `radiosity_core`'s source, tests included: the vocabulary every crate
/// builds on stays small, so that it changes seldom.
const MAX_CORE_LINES: usize = 2_500;

/// A crate's modules: module path ("" for the root, "a::b") → its file.
fn modules(src: &Path) -> BTreeMap<String, PathBuf> {
    let mut out = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).expect("readable source folder") {
            let path = entry.expect("a folder entry").path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let rel = path.strip_prefix(src).expect("under src").with_extension("");
            let mut parts: Vec<String> = rel.iter().map(|p| p.to_string_lossy().into_owned()).collect();
            if matches!(parts.last().map(String::as_str), Some("mod" | "lib" | "main")) {
                parts.pop();
            }
            // A file that is only a test module of another (`#[path]`-less `tests.rs` beside
            // `lib.rs`) is still a module of its own: its imports count like any other's.
            out.insert(parts.join("::"), path);
        }
    }
    out
}

/// The source of a file without its comments and without its `#[cfg(test)]` items (test
/// modules may use anything of their parent).
fn code_of(text: &str) -> String {
    let mut out = String::new();
    let mut lines = text.lines().peekable();
    while let Some(line) = lines.next() {
        let trimmed = line.trim_start();
        if trimmed.starts_with("//") {
            continue;
        }
        if trimmed.starts_with("#[cfg(test)]") {
            // Skip the next item: to the end of its braces, or its `;`.
            let mut depth = 0i32;
            let mut opened = false;
            for l in lines.by_ref() {
                let code = l.split("//").next().unwrap_or("");
                depth += code.matches('{').count() as i32 - code.matches('}').count() as i32;
                opened |= code.contains('{');
                if (opened && depth <= 0) || (!opened && code.trim_end().ends_with(';')) {
                    break;
                }
            }
            continue;
        }
        out.push_str(line.split("//").next().unwrap_or(""));
        out.push('\n');
    }
    out
}

/// The names a module re-exports (`pub use a::{X, Y}`, `pub(crate) use crate::a::X`) → the
/// module they come from, so that an import of them counts as an import of that file.
fn re_exports(module: &str, code: &str, modules: &BTreeMap<String, PathBuf>) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    for stmt in code.split(';') {
        let s: String = stmt.split_whitespace().collect::<Vec<_>>().join(" ");
        let Some(rest) = ["pub use ", "pub(crate) use ", "pub(super) use "]
            .iter()
            .find_map(|p| s.find(p).map(|i| &s[i + p.len()..]))
        else {
            continue;
        };
        let (rest, base) = match rest.strip_prefix("crate::") {
            Some(r) => (r, String::new()),
            None => (rest, module.to_owned()),
        };
        let Some((head, names)) = rest.rsplit_once("::") else { continue };
        let from = if base.is_empty() { head.to_owned() } else { format!("{base}::{head}") };
        if !modules.contains_key(&from) {
            continue;
        }
        for name in names.trim_start_matches('{').trim_end_matches('}').split(',') {
            let name = name.split(" as ").last().unwrap_or(name).trim();
            if !name.is_empty() && name != "self" {
                out.insert(name.to_owned(), from.clone());
            }
        }
    }
    out
}

/// The module that `path` (segments from the crate root) names or lies in: the longest known
/// module, or, for a name it re-exports, the module the name comes from.
fn resolve(
    path: &[&str],
    modules: &BTreeMap<String, PathBuf>,
    exports: &BTreeMap<String, BTreeMap<String, String>>,
) -> Option<String> {
    for n in (0..=path.len()).rev() {
        let m = path[..n].join("::");
        if modules.contains_key(&m) {
            let via = path.get(n).and_then(|name| exports.get(&m)?.get(*name));
            return Some(via.cloned().unwrap_or(m));
        }
    }
    None
}

/// Path segments that follow `prefix` at `at` in `code`: `a::b::{c, d}` gives [a, b, c] and
/// [a, b, d] (one level of braces).
fn paths_after(code: &str, at: usize) -> Vec<Vec<String>> {
    let rest = &code[at..];
    let mut head = Vec::new();
    let mut chars = rest.char_indices().peekable();
    let mut word = String::new();
    while let Some((i, c)) = chars.next() {
        if c.is_alphanumeric() || c == '_' {
            word.push(c);
        } else if c == ':' && rest[i..].starts_with("::") {
            chars.next();
            if !word.is_empty() {
                head.push(std::mem::take(&mut word));
            }
        } else if c == '{' && word.is_empty() {
            let end = rest[i..].find('}').map_or(rest.len(), |e| i + e);
            return rest[i + 1..end]
                .split(',')
                .map(|item| {
                    let first = item.trim().split("::").next().unwrap_or("").trim();
                    let first = first.split_whitespace().next().unwrap_or("");
                    let mut p = head.clone();
                    if !first.is_empty() && first != "self" {
                        p.push(first.to_owned());
                    }
                    p
                })
                .collect();
        } else {
            break;
        }
    }
    if !word.is_empty() {
        head.push(word);
    }
    vec![head]
}

/// Whether the path at `at` is in a `pub use` (a re-export: the name passes through).
fn is_re_export(code: &str, at: usize) -> bool {
    let start = code[..at].rfind([';', '}', '{']).map_or(0, |i| i + 1);
    let stmt = code[start..at].trim_start();
    stmt.starts_with("pub use ") || stmt.starts_with("pub(crate) use ") || stmt.starts_with("pub(super) use ")
}

/// Each module's imports of other modules of its crate.
fn imports(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let modules = modules(src);
    let code: BTreeMap<&String, String> = modules
        .iter()
        .map(|(m, file)| (m, code_of(&std::fs::read_to_string(file).expect("readable source file"))))
        .collect();
    let exports: BTreeMap<String, BTreeMap<String, String>> =
        code.iter().map(|(m, c)| ((*m).clone(), re_exports(m, c, &modules))).collect();
    let mut out = BTreeMap::new();
    for module in modules.keys() {
        let code = &code[module];
        let here: Vec<&str> = if module.is_empty() { vec![] } else { module.split("::").collect() };
        let mut found = BTreeSet::new();
        let mut add = |path: Vec<String>| {
            let segs: Vec<&str> = path.iter().map(String::as_str).collect();
            if let Some(m) = resolve(&segs, &modules, &exports)
                && m != *module
                && !m.is_empty()
            {
                found.insert(m);
            }
        };
        for (at, _) in code.match_indices("crate::") {
            if code[..at].ends_with(|c: char| c.is_alphanumeric() || c == '_' || c == '$') {
                continue; // `$crate::`, `radiosity_crate::`
            }
            if is_re_export(code, at) {
                continue;
            }
            for p in paths_after(code, at + "crate::".len()) {
                add(p);
            }
        }
        for (at, _) in code.match_indices("super::") {
            if code[..at].ends_with(|c: char| c.is_alphanumeric() || c == '_' || c == ':') {
                continue;
            }
            let parent = &here[..here.len().saturating_sub(1)];
            for p in paths_after(code, at + "super::".len()) {
                let mut full: Vec<String> = parent.iter().map(|s| (*s).to_owned()).collect();
                full.extend(p);
                if full.is_empty() {
                    continue;
                }
                add(full);
            }
        }
        // `use child::…` from a module to its own children (re-exports are not uses).
        for stmt in code.split(';') {
            let s = stmt.trim_start();
            let Some(rest) = s.strip_prefix("use ") else {
                continue;
            };
            let first = rest.split("::").next().unwrap_or("").trim();
            let mut child: Vec<String> = here.iter().map(|s| (*s).to_owned()).collect();
            child.push(first.to_owned());
            if !module.is_empty() && modules.contains_key(&child.join("::")) {
                found.insert(child.join("::"));
            }
        }
        out.insert(module.clone(), found);
    }
    out
}

/// The groups of modules that import each other round a circle (Tarjan's strongly connected
/// components of more than one module), each sorted.
fn circles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct State<'a> {
        graph: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on_stack: BTreeSet<&'a str>,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a str) {
        let i = s.index.len();
        s.index.insert(v, i);
        s.low.insert(v, i);
        s.stack.push(v);
        s.on_stack.insert(v);
        for w in s.graph.get(v).into_iter().flatten() {
            let w = w.as_str();
            if !s.graph.contains_key(w) {
                continue;
            }
            if !s.index.contains_key(w) {
                visit(s, w);
                let lw = s.low[w];
                let lv = s.low.get_mut(v).expect("visited");
                *lv = (*lv).min(lw);
            } else if s.on_stack.contains(w) {
                let iw = s.index[w];
                let lv = s.low.get_mut(v).expect("visited");
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut group = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack.remove(w);
                group.push(w.to_owned());
                if w == v {
                    break;
                }
            }
            if group.len() > 1 {
                group.sort();
                s.out.push(group);
            }
        }
    }
    let mut s = State {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in graph.keys() {
        if !s.index.contains_key(v.as_str()) {
            visit(&mut s, v);
        }
    }
    s.out
}

/// Every crate of the workspace and the command: (name, its `src` folder).
fn crates() -> Vec<(String, PathBuf)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out = vec![("radiosity".to_owned(), root.join("src"))];
    for entry in std::fs::read_dir(root.join("crates")).expect("a crates folder") {
        let dir = entry.expect("a folder entry").path();
        if dir.join("src").is_dir() {
            out.push((dir.file_name().expect("named").to_string_lossy().into_owned(), dir.join("src")));
        }
    }
    out.sort();
    out
}

#[test]
fn no_file_imports_round_a_circle() {
    let mut found = Vec::new();
    for (name, src) in crates() {
        for group in circles(&imports(&src)) {
            let known = KNOWN_CIRCLES
                .iter()
                .any(|(c, members)| *c == name && group.iter().all(|m| members.contains(&m.as_str())));
            if !known {
                found.push(format!("{name}: {}", group.join(" ↔ ")));
            }
        }
    }
    assert!(found.is_empty(), "files that import each other round a circle:\n{}", found.join("\n"));
}

/// The check can fail: two files importing each other are a circle, and so are three in a
/// ring; a file importing its parent's re-export counts.
#[test]
fn the_check_finds_circles() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let src = dir.path();
    std::fs::create_dir(src.join("inner")).expect("a folder");
    let files = [
        ("lib.rs", "mod a;\nmod b;\nmod c;\nmod inner;\npub use c::Thing;\n"),
        ("a.rs", "use crate::b::f;\n"),
        ("b.rs", "pub fn f() { crate::a::g(); }\n"),
        ("c.rs", "pub struct Thing;\nuse crate::inner::x;\n"),
        ("inner/mod.rs", "mod x;\nuse x::Y;\n"),
        (
            "inner/x.rs",
            "use super::Z;\nuse crate::Thing;\n#[cfg(test)]\nmod tests {\n    use crate::a::*;\n}\n",
        ),
    ];
    for (path, text) in files {
        std::fs::write(src.join(path), text).expect("written");
    }
    let mut found = circles(&imports(src));
    found.sort();
    let expected = [vec!["a", "b"], vec!["c", "inner", "inner::x"]];
    assert_eq!(found, expected.map(|g| g.into_iter().map(str::to_owned).collect::<Vec<_>>()));
}

/// Prints each crate's imports, bottom-up where there is no circle (a reader's map):
/// `cargo test --test suite modules::print_layers -- --ignored --nocapture`.
#[test]
#[ignore = "prints a map; nothing to check"]
fn print_layers() {
    for (name, src) in crates() {
        println!("{name}");
        for (m, deps) in imports(&src) {
            println!("  {m:<24} → {}", deps.into_iter().collect::<Vec<_>>().join(", "));
        }
    }
}

/// Every `.rs` file under `dir`, build outputs left out.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).expect("readable folder") {
            let path = entry.expect("a folder entry").path();
            if path.is_dir() {
                if path.file_name().is_none_or(|n| n != "target") {
                    stack.push(path);
                }
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

/// Lines in `file`, as `wc -l` counts them.
fn lines_of(file: &Path) -> usize {
    std::fs::read_to_string(file).expect("readable source file").lines().count()
}

#[test]
fn no_file_is_over_800_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let files: Vec<PathBuf> =
        ["src", "tests", "crates"].iter().flat_map(|d| rust_files(&root.join(d))).collect();
    assert!(files.len() > 100, "too few files found: {}", files.len());
    let long: Vec<String> = files
        .iter()
        .map(|f| (f, lines_of(f)))
        .filter(|&(_, n)| n > MAX_FILE_LINES)
        .map(|(f, n)| format!("{}: {n} lines", f.strip_prefix(root).unwrap_or(f).display()))
        .collect();
    assert!(long.is_empty(), "files over {MAX_FILE_LINES} lines (split them by idea):\n{}", long.join("\n"));
}

#[test]
fn the_vocabulary_stays_small() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("crates/radiosity_core/src");
    let total: usize = rust_files(&src).iter().map(|f| lines_of(f)).sum();
    assert!(total > 500, "radiosity_core not found: {total} lines");
    assert!(
        total <= MAX_CORE_LINES,
        "radiosity_core is {total} lines, over {MAX_CORE_LINES}: what is not the scene model, colour, \
         random streams, planar geometry or camera rays belongs in a crate above it"
    );
}
