//! The shader defs a shader and the modules it imports test: `#ifdef`/`#ifndef`/`#if` and
//! `#{NAME}` in naga_oil WGSL, `#ifdef`/`#if defined(..)`/`#if NAME op N` in GLSL, `@if(..)` /
//! `@elif(..)` and `constants::NAME` in WESL. Imports are followed through lodkit's modules and
//! the user's `-I` folders.

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};

use lodkit::shaders;

/// What the defs of one shader are tested for.
#[derive(Clone, Debug, Default)]
pub struct Found {
    /// Defs only tested for being set (`#ifdef X`, `@if(X)`, `defined(X)`).
    pub flags: BTreeSet<String>,
    /// Defs compared with numbers (`#if X == 3`) or substituted (`#{X}`, `constants::X`), with
    /// the numbers they are compared with.
    pub valued: BTreeMap<String, BTreeSet<i64>>,
}

impl Found {
    fn flag(&mut self, name: &str) {
        if is_name(name) {
            self.flags.insert(name.to_owned());
        }
    }

    fn valued(&mut self, name: &str, value: Option<i64>) {
        if is_name(name) {
            let values = self.valued.entry(name.to_owned()).or_default();
            values.extend(value);
        }
    }
}

fn is_name(s: &str) -> bool {
    !s.is_empty()
        && !s.starts_with(|c: char| c.is_ascii_digit())
        && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !matches!(s, "defined" | "true" | "false")
}

/// The user's WGSL modules by `#define_import_path`, and the `-I` folders.
pub struct Sources {
    wgsl: HashMap<String, PathBuf>,
    dirs: Vec<PathBuf>,
}

impl Sources {
    /// Scans the `-I` folders (leaving out paths that contain an `exclude` pattern).
    pub fn scan(dirs: &[PathBuf], exclude: &[String]) -> Self {
        let mut wgsl = HashMap::new();
        let mut stack: Vec<PathBuf> = dirs.to_vec();
        while let Some(dir) = stack.pop() {
            let Ok(entries) = std::fs::read_dir(&dir) else {
                continue;
            };
            for entry in entries.flatten() {
                let path = entry.path();
                let shown = path.display().to_string();
                if exclude.iter().any(|p| shown.contains(p.as_str())) {
                    continue;
                }
                if path.is_dir() {
                    stack.push(path);
                } else if shown.ends_with(".wgsl")
                    && let Ok(text) = std::fs::read_to_string(&path)
                    && let Some(import_path) = text
                        .lines()
                        .find_map(|l| l.trim().strip_prefix("#define_import_path").map(str::trim))
                {
                    wgsl.insert(import_path.to_owned(), path);
                }
            }
        }
        Self {
            wgsl,
            dirs: dirs.to_vec(),
        }
    }

    /// The defs `source` (the text of `path`) and everything it imports test.
    pub fn defs_of(&self, path: &Path, source: &str) -> Found {
        let mut found = Found::default();
        let mut seen = BTreeSet::new();
        let mut queue = vec![(path.to_path_buf(), source.to_owned())];
        while let Some((path, text)) = queue.pop() {
            let language = Lang::of(&path);
            // A def or an import named in a comment is not one.
            let text = shaders::blank_comments(&text, language.comments());
            scan_defs(&text, language, &mut found);
            for (key, next) in self.imports(&path, &text, language) {
                if seen.insert(key) {
                    queue.push(next);
                }
            }
        }
        found
    }

    /// The modules `text` imports, each with a key that names it once, its path and its text.
    fn imports(&self, path: &Path, text: &str, language: Lang) -> Vec<(String, (PathBuf, String))> {
        let mut out = Vec::new();
        let lodkit = |m: &shaders::ModuleInfo| {
            (
                format!("lodkit:{}", m.path),
                (PathBuf::from(m.path), m.source.to_owned()),
            )
        };
        let file = |p: PathBuf| {
            let text = std::fs::read_to_string(&p).ok()?;
            Some((p.display().to_string(), (p, text)))
        };
        for line in text.lines() {
            let line = line.trim();
            match language {
                Lang::Wgsl => {
                    let Some(rest) = line.strip_prefix("#import") else {
                        continue;
                    };
                    let rest = rest.trim();
                    let head = rest.split(['{', ' ', '"']).next().unwrap_or_default();
                    let head = head.trim_end_matches("::");
                    let mut candidate = head;
                    loop {
                        if let Some(m) = shaders::find_module(candidate) {
                            out.push(lodkit(m));
                            break;
                        }
                        if let Some(p) = self.wgsl.get(candidate) {
                            out.extend(file(p.clone()));
                            break;
                        }
                        match candidate.rsplit_once("::") {
                            Some((h, _)) => candidate = h,
                            None => break,
                        }
                    }
                }
                Lang::Wesl => {
                    let Some(rest) = line.strip_prefix("import ") else {
                        continue;
                    };
                    let head = rest.split(['{', ';', ' ']).next().unwrap_or_default();
                    let segments: Vec<&str> = head.split("::").filter(|s| !s.is_empty()).collect();
                    if segments.first() == Some(&"lodkit") {
                        for n in (2..=segments.len()).rev() {
                            if let Some(m) = shaders::find_wesl_module(&segments[..n].join("::")) {
                                out.push(lodkit(m));
                                break;
                            }
                        }
                    } else if segments.first() == Some(&"package") {
                        'found: for n in (2..=segments.len()).rev() {
                            let rel = format!("{}.wesl", segments[1..n].join("/"));
                            for dir in &self.dirs {
                                if let Some(f) = file(dir.join(&rel)) {
                                    out.push(f);
                                    break 'found;
                                }
                            }
                        }
                    }
                }
                Lang::Glsl => {
                    let Some(rest) = line.strip_prefix("#include") else {
                        continue;
                    };
                    let name = rest.trim().trim_matches(['"', '<', '>']);
                    if let Some(m) = shaders::find_glsl_include(name) {
                        out.push(lodkit(m));
                        continue;
                    }
                    let here = path.parent().map(Path::to_path_buf).unwrap_or_default();
                    for dir in std::iter::once(&here).chain(&self.dirs) {
                        if let Some(f) = file(dir.join(name)) {
                            out.push(f);
                            break;
                        }
                    }
                }
            }
        }
        out
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Lang {
    Wgsl,
    Wesl,
    Glsl,
}

impl Lang {
    fn comments(self) -> shaders::CommentSyntax {
        match self {
            Self::Wgsl | Self::Wesl => shaders::CommentSyntax::Wgsl,
            Self::Glsl => shaders::CommentSyntax::Glsl,
        }
    }

    fn of(path: &Path) -> Self {
        match path.extension().and_then(|e| e.to_str()) {
            Some("wgsl") => Self::Wgsl,
            Some("wesl") => Self::Wesl,
            _ => Self::Glsl,
        }
    }
}

/// The identifiers of `expr`, each with the number it is compared with, if any
/// (`A == 3 && defined(B)` gives `A` 3 and `B`).
fn names_in(expr: &str) -> Vec<(String, Option<i64>, bool)> {
    let mut out = Vec::new();
    let tokens: Vec<&str> = expr
        .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '-'))
        .filter(|t| !t.is_empty())
        .collect();
    let mut i = 0;
    let mut after_defined = false;
    while i < tokens.len() {
        let t = tokens[i];
        if t == "defined" {
            after_defined = true;
        } else if is_name(t) {
            let number = tokens
                .get(i + 1)
                .and_then(|n| n.trim_end_matches(['u', 'i']).parse::<i64>().ok());
            out.push((t.to_owned(), number, after_defined));
            after_defined = false;
            if number.is_some() {
                i += 1;
            }
        }
        i += 1;
    }
    out
}

fn scan_defs(text: &str, language: Lang, found: &mut Found) {
    for line in text.lines() {
        let line = line.trim();
        // `#{NAME}` substitutions (naga_oil), `constants::NAME` (WESL).
        let mut rest = line;
        while let Some(at) = rest.find("#{") {
            rest = &rest[at + 2..];
            if let Some(end) = rest.find('}') {
                found.valued(&rest[..end], None);
            }
        }
        if language == Lang::Wesl {
            let mut rest = line;
            while let Some(at) = rest.find("constants::") {
                rest = &rest[at + "constants::".len()..];
                let end = rest
                    .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                    .unwrap_or(rest.len());
                found.valued(&rest[..end], None);
            }
            for attr in ["@if(", "@elif("] {
                let mut rest = line;
                while let Some(at) = rest.find(attr) {
                    rest = &rest[at + attr.len()..];
                    let end = rest.find(')').unwrap_or(rest.len());
                    for (name, _, _) in names_in(&rest[..end]) {
                        found.flag(&name);
                    }
                }
            }
            continue;
        }
        let Some(directive) = line.strip_prefix('#') else {
            continue;
        };
        let directive = directive.trim_start();
        let directive = directive
            .strip_prefix("else")
            .map_or(directive, str::trim_start);
        if let Some(name) = directive
            .strip_prefix("ifdef")
            .or_else(|| directive.strip_prefix("ifndef"))
        {
            found.flag(name.trim());
        } else if let Some(expr) = directive
            .strip_prefix("if")
            .or_else(|| directive.strip_prefix("elif"))
            .filter(|e| e.starts_with([' ', '(', '!']))
        {
            for (name, number, defined) in names_in(expr) {
                match number {
                    Some(n) => found.valued(&name, Some(n)),
                    // GLSL `#if X` reads X's value: on is 1, off 0 (or unset).
                    None if defined || language == Lang::Glsl => found.flag(&name),
                    None => found.flag(&name),
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_defs_of_each_dialect() {
        let mut f = Found::default();
        scan_defs(
            "#ifdef A\n#else ifndef B\n#if MAX == 3\n#else if MAX > 5\nx = #{N};\n#endif",
            Lang::Wgsl,
            &mut f,
        );
        assert_eq!(f.flags, ["A", "B"].map(String::from).into());
        assert_eq!(f.valued["MAX"], [3, 5].into());
        assert!(f.valued["N"].is_empty());
        let mut g = Found::default();
        scan_defs(
            "#if defined(C) && !defined(D)\n#elif E == 2\n#ifdef F",
            Lang::Glsl,
            &mut g,
        );
        assert_eq!(g.flags, ["C", "D", "F"].map(String::from).into());
        assert_eq!(g.valued["E"], [2].into());
        let mut w = Found::default();
        scan_defs(
            "@if(G && !H) fn f() {}\n@elif(true) let x = constants::K;",
            Lang::Wesl,
            &mut w,
        );
        assert_eq!(w.flags, ["G", "H"].map(String::from).into());
        assert!(w.valued.contains_key("K"));
    }

    /// The flags and valued defs `source` (the file `name`) tests, imports not followed.
    fn defs(name: &str, source: &str) -> (Vec<String>, Vec<String>) {
        let found = Sources::scan(&[], &[]).defs_of(Path::new(name), source);
        (
            found.flags.into_iter().collect(),
            found.valued.into_keys().collect(),
        )
    }

    #[test]
    fn a_def_named_only_in_a_wgsl_comment_is_not_one() {
        let src = "// #ifdef LINE_COMMENT\n\
                   /* #ifdef BLOCK\n\
                   #if VALUE == 3 /* nested */ #{SUBST}\n\
                   */\n\
                   #ifdef REAL /* #ifdef AFTER */\n\
                   #endif\n\
                   fn f() -> f32 { return #{N}.0; } // #{NOT_N}\n";
        assert_eq!(defs("a.wgsl", src), (vec!["REAL".into()], vec!["N".into()]));
    }

    #[test]
    fn a_condition_named_only_in_a_wesl_comment_is_not_one() {
        let src = "// @if(LINE_COMMENT) fn g() {}\n\
                   /* @if(BLOCK) /* @elif(NESTED) */ constants::HIDDEN */\n\
                   @if(REAL) fn f() -> f32 { return constants::K; } // constants::NOT_K\n";
        assert_eq!(defs("a.wesl", src), (vec!["REAL".into()], vec!["K".into()]));
    }

    #[test]
    fn a_def_named_only_in_a_glsl_comment_is_not_one() {
        let src = "#version 450\n\
                   // #ifdef LINE_COMMENT\n\
                   /* #if defined(BLOCK)\n\
                   #elif VALUE == 2 */\n\
                   #if defined(REAL) && LEVEL > 1 // #ifdef TRAILING\n\
                   #endif\n\
                   void main() {}\n";
        assert_eq!(
            defs("a.frag", src),
            (vec!["REAL".into()], vec!["LEVEL".into()])
        );
    }

    #[test]
    fn an_import_named_only_in_a_comment_is_not_followed() {
        // lodkit::screen_door tests LODKIT_SCREEN_DOOR_BLUE_NOISE: only an import brings it in.
        let wgsl = "/*\n#import lodkit::screen_door::screen_door_keep\n*/\nfn f() {}\n";
        assert_eq!(defs("a.wgsl", wgsl), (vec![], vec![]));
        let wesl = "/*\nimport lodkit::screen_door::screen_door_keep;\n*/\nfn f() {}\n";
        assert_eq!(defs("a.wesl", wesl), (vec![], vec![]));
        let imported = "#import lodkit::screen_door::screen_door_keep\nfn f() {}\n";
        assert_eq!(
            defs("a.wgsl", imported).0,
            vec!["LODKIT_SCREEN_DOOR_BLUE_NOISE".to_owned()]
        );
    }
}
