//! Reading `#import` statements: every path a statement names (naga_oil only reports the ones
//! that are used), where it is written, and which module an item path belongs to.

use super::registry;

/// The module part of an import (`lodkit::a::item` -> `lodkit::a` when `lodkit::a::item` is no
/// module itself).
pub(crate) fn module_prefix(import: &str) -> &str {
    if registry::find_module(import).is_some() {
        return import;
    }
    match import.rsplit_once("::") {
        Some((head, _)) if head.contains("::") => head,
        _ => import,
    }
}

/// The longest prefix of `import` (itself, then without its last `::` segment, and so on) for
/// which `find` gives something, with what it gave.
pub(crate) fn longest_prefix<T>(
    import: &str,
    mut find: impl FnMut(&str) -> Option<T>,
) -> Option<(&str, T)> {
    let mut candidate = import;
    loop {
        if let Some(found) = find(candidate) {
            return Some((candidate, found));
        }
        candidate = candidate.rsplit_once("::")?.0;
    }
}

/// Every path an `#import` statement names, fully expanded (`#import a::{b, c::d}` names `a::b`
/// and `a::c::d`), with the byte offset of its `#import`. Unlike naga_oil's own scan, imports that
/// are never used count too.
pub(crate) fn declared_imports(source: &str) -> Vec<(String, usize)> {
    fn expand(list: &str, prefix: &str, out: &mut Vec<String>) {
        let mut depth = 0;
        let mut start = 0;
        let mut items = Vec::new();
        for (i, c) in list.char_indices() {
            match c {
                '{' => depth += 1,
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    items.push(&list[start..i]);
                    start = i + 1;
                }
                _ => {}
            }
        }
        items.push(&list[start..]);
        for item in items {
            let item = item.trim();
            let item = match item.rsplit_once(" as ") {
                Some((head, alias)) if !alias.contains('}') => head.trim(),
                _ => item,
            };
            if item.is_empty() {
                continue;
            }
            match (item.find('{'), item.rfind('}')) {
                (Some(open), Some(close)) if open < close => {
                    let head = item[..open].trim().trim_end_matches("::");
                    let joined = if head.is_empty() {
                        prefix.to_owned()
                    } else {
                        format!("{prefix}{head}::")
                    };
                    expand(&item[open + 1..close], &joined, out);
                }
                _ => out.push(format!("{prefix}{item}")),
            }
        }
    }
    let mut out = Vec::new();
    let mut offset = 0;
    let mut pending: Option<(String, usize)> = None;
    for line in source.split_inclusive('\n') {
        let code = line.split("//").next().unwrap_or_default();
        let at = offset;
        offset += line.len();
        let (text, start) = match pending.take() {
            Some((mut text, start)) => {
                text.push_str(code);
                (text, start)
            }
            None => match code.trim_start().strip_prefix("#import") {
                Some(rest) => (rest.to_owned(), at + (code.len() - code.trim_start().len())),
                None => continue,
            },
        };
        if text.matches('{').count() > text.matches('}').count() {
            pending = Some((text, start));
            continue;
        }
        let mut paths = Vec::new();
        expand(text.trim().trim_end_matches(';'), "", &mut paths);
        out.extend(paths.into_iter().map(|p| (p, start)));
    }
    out
}

/// Where `#import <module>` is written in `source` (the module name's bytes), if it is.
pub(crate) fn import_site(source: &str, module: &str) -> std::ops::Range<usize> {
    let mut offset = 0;
    for line in source.split_inclusive('\n') {
        if let Some(rest) = line.trim_start().strip_prefix("#import")
            && let Some(i) = rest.find(module)
        {
            let at = offset + (line.len() - rest.len()) + i;
            return at..at + module.len();
        }
        offset += line.len();
    }
    0..0
}

#[cfg(test)]
mod tests {
    use super::declared_imports;

    #[test]
    fn declared_imports_expand_nested_lists_and_aliases() {
        let src = "// header\n#import a::b::item\n#import c::{d, e::{f, g} , h as k}\n  #import m as n // trailing\nfn x() {}\n";
        let paths: Vec<String> = declared_imports(src).into_iter().map(|(p, _)| p).collect();
        assert_eq!(
            paths,
            ["a::b::item", "c::d", "c::e::f", "c::e::g", "c::h", "m"]
        );
    }

    #[test]
    fn multi_line_import_is_one_statement() {
        let src = "#import lodkit::{\n  fullscreen,\n  normal_distance,\n}\n";
        let got = declared_imports(src);
        assert_eq!(got.len(), 2);
        assert!(got.iter().all(|(_, at)| *at == 0));
    }
}
