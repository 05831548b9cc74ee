//! The house rules a reader of the code relies on, checked on the sources: no import circle
//! between the files of `src/`, `cli/src`, `lodkit_bevy/src` and `scenes/src` (a `use` or an inline
//! `crate::`/`super::`/`self::` path from one file to an item of another is an edge; an item a
//! module re-exports with `pub use` counts as the file that defines it), and no file over 600
//! lines outside tests and generated files; and the demo (`cli/src/demo`) imports only from a
//! file's own layer or those below (error, fixtures, measures, report).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use crate::support::workspace_root;

/// One crate's module tree: module path (segments) -> file.
struct Crate {
    modules: BTreeMap<Vec<String>, PathBuf>,
}

/// `mod name;` declarations of a source (not `mod name { .. }`), with their `#[path]`.
fn declared_modules(source: &str) -> Vec<(String, Option<String>)> {
    let mut out = Vec::new();
    let mut path_attr = None;
    for line in source.lines() {
        let t = line.trim();
        if let Some(rest) = t.strip_prefix("#[path = \"") {
            path_attr = rest.split('"').next().map(str::to_owned);
            continue;
        }
        let t = t
            .strip_prefix("pub(crate) ")
            .or_else(|| t.strip_prefix("pub(super) "))
            .or_else(|| t.strip_prefix("pub "))
            .unwrap_or(t);
        if let Some(rest) = t.strip_prefix("mod ")
            && let Some(name) = rest.strip_suffix(';')
        {
            out.push((name.trim().to_owned(), path_attr.take()));
        } else if !t.starts_with("#[") {
            path_attr = None;
        }
    }
    out
}

impl Crate {
    /// The modules reachable from `root` (lib.rs or main.rs) by `mod` declarations.
    fn load(root: &Path) -> Crate {
        let mut modules = BTreeMap::new();
        let mut stack = vec![(Vec::new(), root.to_path_buf())];
        while let Some((segments, file)) = stack.pop() {
            let source = std::fs::read_to_string(&file).unwrap_or_default();
            let dir = match file.file_name().and_then(|n| n.to_str()) {
                Some("lib.rs" | "main.rs" | "mod.rs") => file.parent().unwrap().to_path_buf(),
                _ => file.with_extension(""),
            };
            for (name, path) in declared_modules(&source) {
                let child = match path {
                    Some(p) => file.parent().unwrap().join(p),
                    None if dir.join(format!("{name}.rs")).exists() => {
                        dir.join(format!("{name}.rs"))
                    }
                    None => dir.join(&name).join("mod.rs"),
                };
                if child.exists() {
                    let mut s = segments.clone();
                    s.push(name);
                    stack.push((s, child));
                }
            }
            modules.insert(segments, file);
        }
        Crate { modules }
    }
}

/// Code without comments and string literals (so paths in docs and messages do not count).
fn code_only(source: &str) -> String {
    let mut out = String::with_capacity(source.len());
    let mut chars = source.chars().peekable();
    let (mut in_str, mut in_char) = (false, false);
    while let Some(c) = chars.next() {
        if in_str {
            if c == '\\' {
                chars.next();
            } else if c == '"' {
                in_str = false;
            }
            continue;
        }
        if in_char {
            if c == '\\' {
                chars.next();
            } else if c == '\'' {
                in_char = false;
            }
            continue;
        }
        match c {
            '/' if chars.peek() == Some(&'/') => {
                for c in chars.by_ref() {
                    if c == '\n' {
                        out.push('\n');
                        break;
                    }
                }
            }
            '"' => in_str = true,
            // A char literal, not a lifetime: 'x' or '\n'.
            '\'' => {
                let mut ahead = chars.clone();
                let first = ahead.next();
                let second = ahead.next();
                if first == Some('\\') || second == Some('\'') {
                    in_char = true;
                } else {
                    out.push(c);
                }
            }
            _ => out.push(c),
        }
    }
    out
}

/// Every path a source names that starts at `crate`, `super` or `self`, with `use` groups
/// expanded: each as segments.
fn referenced_paths(source: &str) -> Vec<Vec<String>> {
    let code = code_only(source);
    let mut paths = Vec::new();
    // `use` declarations, braces expanded.
    let mut rest = code.as_str();
    while let Some(i) = rest.find("use ") {
        let before_ok = i == 0
            || !rest.as_bytes()[i - 1].is_ascii_alphanumeric() && rest.as_bytes()[i - 1] != b'_';
        let after = &rest[i + 4..];
        let end = after.find(';').unwrap_or(after.len());
        if before_ok {
            expand_use(after[..end].trim(), &mut Vec::new(), &mut paths);
        }
        rest = &after[end.min(after.len())..];
    }
    // Inline paths.
    for start in ["crate::", "super::", "self::"] {
        let mut rest = code.as_str();
        while let Some(i) = rest.find(start) {
            let ok = i == 0 || {
                let b = rest.as_bytes()[i - 1];
                !(b.is_ascii_alphanumeric() || b == b'_' || b == b':')
            };
            let tail = &rest[i..];
            let len = tail
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(tail.len());
            if ok {
                let segs: Vec<String> = tail[..len]
                    .split("::")
                    .filter(|s| !s.is_empty())
                    .map(str::to_owned)
                    .collect();
                paths.push(segs);
            }
            rest = &rest[i + len.max(1)..];
        }
    }
    paths
        .into_iter()
        .filter(|p| {
            matches!(
                p.first().map(String::as_str),
                Some("crate" | "super" | "self")
            )
        })
        .collect()
}

/// Expands a `use` tree (`a::b::{c, d::{e, f}}`) into paths.
fn expand_use(tree: &str, prefix: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    let tree = tree.trim();
    if let Some(open) = tree.find('{') {
        let head: Vec<String> = tree[..open]
            .split("::")
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .map(str::to_owned)
            .collect();
        let inner = &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())];
        let n = prefix.len();
        prefix.extend(head);
        let mut depth = 0;
        let mut start = 0;
        for (i, c) in inner.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    expand_use(&inner[start..i], prefix, out);
                    start = i + 1;
                }
                _ => {}
            }
        }
        expand_use(&inner[start..], prefix, out);
        prefix.truncate(n);
    } else if !tree.is_empty() {
        let tree = tree.split(" as ").next().unwrap_or(tree);
        let mut p = prefix.clone();
        p.extend(
            tree.split("::")
                .map(str::trim)
                .filter(|s| !s.is_empty())
                .map(str::to_owned),
        );
        out.push(p);
    }
}

/// The `pub use` re-exports of a module: item name -> the path it names.
fn reexports(source: &str) -> BTreeMap<String, Vec<String>> {
    let code = code_only(source);
    let mut out = BTreeMap::new();
    for decl in code.split(';') {
        let t = decl.trim();
        let Some(tree) = t
            .strip_prefix("pub use ")
            .or_else(|| t.strip_prefix("pub(crate) use "))
            .or_else(|| t.strip_prefix("pub(super) use "))
        else {
            continue;
        };
        let mut paths = Vec::new();
        expand_use(tree, &mut Vec::new(), &mut paths);
        for p in paths {
            if let Some(last) = p.last() {
                out.insert(last.clone(), p);
            }
        }
    }
    out
}

impl Crate {
    /// The file a path from the module `from` names: the deepest module it reaches, followed
    /// through that module's re-exports to the file defining the item.
    fn resolve(&self, from: &[String], path: &[String], depth: usize) -> Option<PathBuf> {
        let mut abs: Vec<String> = Vec::new();
        let mut segs = path.iter().peekable();
        match segs.peek().map(|s| s.as_str()) {
            Some("crate") => {
                segs.next();
            }
            Some("super") | Some("self") => {
                abs = from.to_vec();
                while let Some(s) = segs.peek() {
                    match s.as_str() {
                        "super" => {
                            abs.pop();
                        }
                        "self" => {}
                        _ => break,
                    }
                    segs.next();
                }
            }
            _ => return None,
        }
        let rest: Vec<&String> = segs.collect();
        let mut module = abs.clone();
        let mut used = 0;
        for s in &rest {
            let mut next = module.clone();
            next.push((*s).clone());
            if self.modules.contains_key(&next) {
                module = next;
                used += 1;
            } else {
                break;
            }
        }
        let file = self.modules.get(&module)?.clone();
        // An item re-exported by that module: the file it comes from.
        if depth < 8
            && let Some(item) = rest.get(used)
        {
            let source = std::fs::read_to_string(&file).unwrap_or_default();
            if let Some(target) = reexports(&source).get(item.as_str()) {
                let target = if matches!(target[0].as_str(), "crate" | "super" | "self") {
                    target.clone()
                } else {
                    // `pub use child::Item`: relative to the module.
                    std::iter::once("self".to_owned())
                        .chain(target.iter().cloned())
                        .collect()
                };
                if let Some(f) = self.resolve(&module, &target, depth + 1) {
                    return Some(f);
                }
            }
        }
        Some(file)
    }

    /// File -> files it imports from (edges to itself left out).
    fn edges(&self) -> BTreeMap<PathBuf, BTreeSet<PathBuf>> {
        let mut edges = BTreeMap::new();
        for (module, file) in &self.modules {
            let source = std::fs::read_to_string(file).unwrap_or_default();
            let targets: BTreeSet<PathBuf> = referenced_paths(&source)
                .iter()
                .filter_map(|p| self.resolve(module, p, 0))
                .filter(|t| t != file)
                .collect();
            edges.insert(file.clone(), targets);
        }
        edges
    }
}

/// The strongly connected components of more than one file (Tarjan).
fn circles(edges: &BTreeMap<PathBuf, BTreeSet<PathBuf>>) -> Vec<Vec<PathBuf>> {
    struct State<'a> {
        edges: &'a BTreeMap<PathBuf, BTreeSet<PathBuf>>,
        index: BTreeMap<&'a PathBuf, usize>,
        low: BTreeMap<&'a PathBuf, usize>,
        stack: Vec<&'a PathBuf>,
        on: BTreeSet<&'a PathBuf>,
        out: Vec<Vec<PathBuf>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a PathBuf) {
        let i = s.index.len();
        s.index.insert(v, i);
        s.low.insert(v, i);
        s.stack.push(v);
        s.on.insert(v);
        let edges = s.edges;
        for w in edges.get(v).into_iter().flatten() {
            if !edges.contains_key(w) {
                continue;
            }
            if !s.index.contains_key(w) {
                visit(s, w);
                let lw = s.low[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(lw);
            } else if s.on.contains(w) {
                let iw = s.index[w];
                let lv = s.low.get_mut(v).unwrap();
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut component = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on.remove(w);
                component.push(w.clone());
                if w == v {
                    break;
                }
            }
            if component.len() > 1 {
                component.sort();
                s.out.push(component);
            }
        }
    }
    let mut s = State {
        edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in edges.keys() {
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    s.out
}

fn crate_roots() -> Vec<PathBuf> {
    let root = workspace_root();
    [
        "src/lib.rs",
        "cli/src/lib.rs",
        "cli/src/main.rs",
        "lodkit_bevy/src/lib.rs",
        "scenes/src/lib.rs",
    ]
    .iter()
    .map(|p| root.join(p))
    .collect()
}

#[test]
fn no_import_circle_between_the_files_of_any_crate() {
    let root = workspace_root();
    let mut found = Vec::new();
    let mut files = 0;
    for crate_root in crate_roots() {
        let krate = Crate::load(&crate_root);
        files += krate.modules.len();
        for circle in circles(&krate.edges()) {
            let names: Vec<String> = circle
                .iter()
                .map(|p| p.strip_prefix(&root).unwrap_or(p).display().to_string())
                .collect();
            found.push(names.join(" <-> "));
        }
    }
    assert!(files > 100, "the module trees were read ({files} files)");
    assert!(found.is_empty(), "import circles:\n{}", found.join("\n"));
}

/// The demo's layer of a file under `demo` (`cli/src/demo`), bottom up: the error type, the
/// fixtures, the measures, the report, and `mod.rs`, which runs them in order. `None` outside
/// the demo.
fn demo_layer(file: &Path, demo: &Path) -> Option<(usize, &'static str)> {
    let first = file.strip_prefix(demo).ok()?.components().next()?;
    Some(match first.as_os_str().to_str()? {
        "error.rs" => (0, "error"),
        "fixtures" => (1, "fixtures"),
        "measures" => (2, "measures"),
        "report" => (3, "report"),
        _ => (4, "demo/mod.rs"),
    })
}

/// The demo is three layers (fixtures, measures, report) over its error type: a file imports
/// only from its own layer or those below, so a measure never reaches into the report.
#[test]
fn the_demo_imports_only_from_its_own_layer_or_below() {
    let root = workspace_root();
    let demo = root.join("cli/src/demo");
    let krate = Crate::load(&root.join("cli/src/lib.rs"));
    let (mut edges, mut up) = (0, Vec::new());
    for (from, tos) in krate.edges() {
        let Some((a, layer_a)) = demo_layer(&from, &demo) else {
            continue;
        };
        for to in tos {
            let Some((b, layer_b)) = demo_layer(&to, &demo) else {
                continue;
            };
            edges += 1;
            if b > a {
                let name = |p: &Path| p.strip_prefix(&root).unwrap_or(p).display().to_string();
                up.push(format!(
                    "{} ({layer_a}) -> {} ({layer_b})",
                    name(&from),
                    name(&to)
                ));
            }
        }
    }
    assert!(edges > 50, "the demo's imports were read ({edges} edges)");
    assert!(
        up.is_empty(),
        "imports from a lower layer up:\n{}",
        up.join("\n")
    );
}

/// The checker sees a circle: hand-made modules that import each other.
#[test]
fn the_circle_finder_finds_a_hand_made_circle() {
    let dir = tempfile::tempdir().unwrap();
    let w = |name: &str, text: &str| std::fs::write(dir.path().join(name), text).unwrap();
    w("lib.rs", "mod a;\nmod b;\nmod c;\npub use a::A;\n");
    w("a.rs", "use crate::b::B;\npub struct A;\n");
    w("b.rs", "pub struct B;\nfn f() { let _ = super::c::C; }\n");
    w(
        "c.rs",
        "// crate::a::A in a comment is no edge\npub struct C(crate::A);\n",
    );
    let krate = Crate::load(&dir.path().join("lib.rs"));
    assert_eq!(krate.modules.len(), 4);
    let found = circles(&krate.edges());
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(
        found[0].len(),
        3,
        "a -> b -> c -> (the re-export of) a: {found:?}"
    );
    // Without the last edge there is none.
    w("c.rs", "pub struct C;\n");
    assert!(circles(&Crate::load(&dir.path().join("lib.rs")).edges()).is_empty());
}

/// Files over 600 lines, outside tests and generated files.
#[test]
fn no_source_file_over_600_lines() {
    let root = workspace_root();
    let mut long = Vec::new();
    for dir in [
        "src",
        "cli/src",
        "lodkit_bevy/src",
        "lodkit_bevy/examples",
        "examples",
        "scenes/src",
    ] {
        let mut stack = vec![root.join(dir)];
        while let Some(d) = stack.pop() {
            for entry in std::fs::read_dir(&d).into_iter().flatten().flatten() {
                let p = entry.path();
                if p.is_dir() {
                    stack.push(p);
                } else if p
                    .extension()
                    .is_some_and(|e| e == "rs" || e == "wesl" || e == "wgsl")
                    && !p.to_string_lossy().contains("tests")
                {
                    let lines = std::fs::read_to_string(&p)
                        .unwrap_or_default()
                        .lines()
                        .count();
                    if lines > 600 {
                        long.push(format!(
                            "{} ({lines})",
                            p.strip_prefix(&root).unwrap().display()
                        ));
                    }
                }
            }
        }
    }
    assert!(long.is_empty(), "files over 600 lines: {long:?}");
}
