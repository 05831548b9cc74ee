//! Bounds on what GLSL macros expand to, computed from the `#define`s alone, before anything is
//! expanded: how many tokens the file becomes, how deep its brackets nest and how deep macro calls
//! nest inside each other's arguments. Eight lines of nested macros can stand for 10^5 nested
//! parentheses; expanding them and parsing the result would take minutes or overflow a stack, so
//! such a file is refused up front with a `limit` error.
//!
//! Every figure is an upper bound: a macro's expansion is described by how it grows with each of
//! its arguments (tokens `c + sum(k_i * a_i)` for arguments of `a_i` tokens, bracket depth
//! `max(d, p_i + a_i)` for arguments nested `a_i` deep), and a call combines the callee's
//! description with its arguments'.
//! Conditional compilation is not followed (every `#define` counts; a later one replaces an
//! earlier one of the same name), which can only make the bounds larger.

use std::collections::HashMap;
use std::ops::Range;

use super::limits::{MAX_EXPANDED_TOKENS, MAX_MACRO_CALL_NESTING, MAX_NESTING, TooDeep};

/// A token as far as the bounds care.
#[derive(Clone, Debug, PartialEq)]
enum Kind<'a> {
    Ident(&'a str),
    Open,
    Close,
    Comma,
    Other,
}

#[derive(Clone, Debug)]
struct Token<'a> {
    kind: Kind<'a>,
    at: Range<usize>,
}

struct Macro<'a> {
    params: Option<Vec<&'a str>>,
    body: Vec<Token<'a>>,
}

/// How a token run grows with the arguments of the macro it belongs to (see the module docs),
/// one entry per parameter. Saturating arithmetic: a bound past every limit stays past it.
#[derive(Clone, Debug, Default)]
struct Growth {
    /// Tokens without the arguments.
    tokens: u64,
    /// Tokens per token of each argument (how often it is pasted).
    per_arg: Vec<u64>,
    /// Deepest bracket nesting outside the arguments.
    depth: i64,
    /// Nesting at which each argument is pasted (the deepest such place), if anywhere.
    arg_depth: Vec<Option<i64>>,
    /// Brackets left open at the end (negative: closed that were open before).
    net: i64,
    /// Macro calls nested in arguments of macro calls.
    calls: u64,
}

impl Growth {
    fn new(params: usize) -> Self {
        Self {
            per_arg: vec![0; params],
            arg_depth: vec![None; params],
            ..Self::default()
        }
    }

    /// Adds `inner` (a run of the same macro's body) placed at nesting `depth`.
    fn add(&mut self, inner: &Growth, depth: i64) {
        self.tokens = self.tokens.saturating_add(inner.tokens);
        for (k, i) in self.per_arg.iter_mut().zip(&inner.per_arg) {
            *k = k.saturating_add(*i);
        }
        self.depth = self.depth.max(depth.saturating_add(inner.depth));
        for (p, i) in self.arg_depth.iter_mut().zip(&inner.arg_depth) {
            if let Some(i) = i {
                let i = depth.saturating_add(*i);
                *p = Some(p.map_or(i, |p| p.max(i)));
            }
        }
        self.calls = self.calls.max(inner.calls);
    }
}

/// Where a bound first goes past its limit.
pub(crate) fn too_large(text: &str, defines: &[(String, String)]) -> Option<TooDeep> {
    let mut table: HashMap<&str, Macro> = HashMap::new();
    for (name, value) in defines {
        let body = tokenize(value, 0);
        table.insert(name.as_str(), Macro { params: None, body });
    }
    let mut top = Vec::new();
    let mut offset = 0;
    for line in logical_lines(text) {
        let trimmed = line.trim_start();
        if let Some(directive) = trimmed.strip_prefix('#') {
            let directive = directive.trim_start();
            if let Some(rest) = directive.strip_prefix("define") {
                let at = offset + (line.len() - rest.len());
                if let Some((name, m)) = parse_define(rest, at) {
                    table.insert(name, m);
                }
            }
        } else {
            top.extend(tokenize(line, offset));
        }
        offset += line.len();
    }
    let mut eval = Evaluator {
        table: &table,
        memo: HashMap::new(),
        in_progress: Vec::new(),
    };
    eval.check_top(&top)
}

struct Evaluator<'t, 'a> {
    table: &'t HashMap<&'a str, Macro<'a>>,
    memo: HashMap<&'a str, Growth>,
    in_progress: Vec<&'a str>,
}

impl<'a> Evaluator<'_, 'a> {
    /// The growth of macro `name`'s expansion; a macro already being expanded is not expanded
    /// again (as the preprocessor does), so it counts as a plain token.
    /// The growth is remembered per name: inside a cycle of macros naming each other, it is the
    /// growth seen from the first of them expanded, which may count one level of the cycle
    /// less than another entry point would.
    fn macro_growth(&mut self, name: &'a str) -> Growth {
        if let Some(g) = self.memo.get(name) {
            return g.clone();
        }
        let table = self.table;
        let m = &table[name];
        self.in_progress.push(name);
        let params = m.params.as_deref().unwrap_or(&[]);
        let g = self.growth(&m.body, params);
        self.in_progress.pop();
        self.memo.insert(name, g.clone());
        g
    }

    /// Whether `tokens[i]` starts a macro expansion, and the growth and end of that expansion.
    fn expansion(
        &mut self,
        tokens: &[Token<'a>],
        i: usize,
        params: &[&str],
    ) -> Option<(Growth, usize)> {
        let Kind::Ident(name) = tokens[i].kind else {
            return None;
        };
        if params.contains(&name) || self.in_progress.contains(&name) {
            return None;
        }
        let table = self.table;
        let m = table.get(name)?;
        if m.params.is_none() {
            return Some((self.macro_growth(name), i + 1));
        }
        // A function-like macro expands only when `(` follows, up to its matching `)`.
        if tokens.get(i + 1).map(|t| &t.kind) != Some(&Kind::Open) {
            return None;
        }
        let close = matching_close(tokens, i + 1)?;
        let args: Vec<Growth> = split_arguments(&tokens[i + 2..close])
            .into_iter()
            .map(|arg| self.growth(arg, params))
            .collect();
        let callee = self.macro_growth(name);
        // The callee's growth with each of its parameters replaced by the argument's growth (in
        // the enclosing macro's parameters); a missing argument is empty.
        let mut g = Growth::new(params.len());
        g.tokens = callee.tokens;
        g.depth = callee.depth;
        g.net = callee.net;
        g.calls = callee.calls;
        for (j, arg) in args.iter().enumerate() {
            let k = callee.per_arg.get(j).copied().unwrap_or(0);
            g.tokens = g.tokens.saturating_add(k.saturating_mul(arg.tokens));
            for (p, a) in g.per_arg.iter_mut().zip(&arg.per_arg) {
                *p = p.saturating_add(k.saturating_mul(*a));
            }
            if let Some(Some(at)) = callee.arg_depth.get(j) {
                g.depth = g.depth.max(at.saturating_add(arg.depth));
                for (p, a) in g.arg_depth.iter_mut().zip(&arg.arg_depth) {
                    if let Some(a) = a {
                        let a = at.saturating_add(*a);
                        *p = Some(p.map_or(a, |p| p.max(a)));
                    }
                }
            }
            g.calls = g.calls.max(arg.calls.saturating_add(1));
        }
        Some((g, close + 1))
    }

    /// The growth of a token run in which `params` are the enclosing macro's parameters.
    fn growth(&mut self, tokens: &[Token<'a>], params: &[&str]) -> Growth {
        let mut g = Growth::new(params.len());
        let mut depth = 0i64;
        let mut i = 0;
        while i < tokens.len() {
            if let Some((inner, next)) = self.expansion(tokens, i, params) {
                g.add(&inner, depth);
                depth = depth.saturating_add(inner.net);
                i = next;
                continue;
            }
            match tokens[i].kind {
                Kind::Ident(name) if params.contains(&name) => {
                    let p = params.iter().position(|q| *q == name).expect("a parameter");
                    g.per_arg[p] = g.per_arg[p].saturating_add(1);
                    g.arg_depth[p] = Some(g.arg_depth[p].map_or(depth, |q| q.max(depth)));
                }
                Kind::Open => {
                    depth += 1;
                    g.depth = g.depth.max(depth);
                    g.tokens = g.tokens.saturating_add(1);
                }
                Kind::Close => {
                    depth -= 1;
                    g.tokens = g.tokens.saturating_add(1);
                }
                _ => g.tokens = g.tokens.saturating_add(1),
            }
            i += 1;
        }
        g.net = depth;
        g
    }

    /// Walks the file's own tokens and names the first one whose expansion goes past a limit.
    fn check_top(&mut self, tokens: &[Token<'a>]) -> Option<TooDeep> {
        let mut depth = 0i64;
        let mut total = 0u64;
        let mut i = 0;
        while i < tokens.len() {
            let at = tokens[i].at.clone();
            let (g, next) = match self.expansion(tokens, i, &[]) {
                Some(found) => found,
                None => {
                    let g = self.growth(&tokens[i..i + 1], &[]);
                    (g, i + 1)
                }
            };
            total = total.saturating_add(g.tokens);
            let deepest = depth.saturating_add(g.depth);
            if deepest > MAX_NESTING as i64 {
                let what = format!(
                    "brackets nested more than {MAX_NESTING} levels deep after macro expansion \
                     (up to {deepest})"
                );
                return Some(TooDeep { at, what });
            }
            if g.calls > MAX_MACRO_CALL_NESTING {
                let what = format!(
                    "macro calls nested more than {MAX_MACRO_CALL_NESTING} deep in each other's \
                     arguments"
                );
                return Some(TooDeep { at, what });
            }
            if total > MAX_EXPANDED_TOKENS {
                let what = format!("macros expand the file past {MAX_EXPANDED_TOKENS} tokens");
                return Some(TooDeep { at, what });
            }
            depth = depth.saturating_add(g.net).max(0);
            i = next;
        }
        None
    }
}

/// The index of the `)` that closes the `(` at `open`.
fn matching_close(tokens: &[Token], open: usize) -> Option<usize> {
    let mut depth = 0usize;
    for (i, t) in tokens.iter().enumerate().skip(open) {
        match t.kind {
            Kind::Open => depth += 1,
            Kind::Close => {
                depth -= 1;
                if depth == 0 {
                    return Some(i);
                }
            }
            _ => {}
        }
    }
    None
}

/// A call's arguments: the runs between commas outside nested brackets.
fn split_arguments<'t, 'a>(tokens: &'t [Token<'a>]) -> Vec<&'t [Token<'a>]> {
    let mut args = Vec::new();
    let (mut depth, mut start) = (0usize, 0);
    for (i, t) in tokens.iter().enumerate() {
        match t.kind {
            Kind::Open => depth += 1,
            Kind::Close => depth = depth.saturating_sub(1),
            Kind::Comma if depth == 0 => {
                args.push(&tokens[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    args.push(&tokens[start..]);
    args
}

/// `NAME body` or `NAME(a, b) body` after `#define`; `at` is where `rest` starts in the file.
fn parse_define(rest: &str, at: usize) -> Option<(&str, Macro<'_>)> {
    let lead = rest.len() - rest.trim_start().len();
    if lead == 0 {
        return None; // `#defined`, `#define_x`: not a define
    }
    let text = &rest[lead..];
    let name_len = text
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(text.len());
    if name_len == 0 {
        return None;
    }
    let name = &text[..name_len];
    let after = &text[name_len..];
    let body_at = at + lead + name_len;
    // Function-like only when `(` follows the name without a space.
    if let Some(list) = after.strip_prefix('(') {
        let close = list.find(')')?;
        let params = list[..close]
            .split(',')
            .map(str::trim)
            .filter(|p| !p.is_empty())
            .collect();
        let body_start = body_at + 1 + close + 1;
        let body = tokenize(&list[close + 1..], body_start);
        return Some((
            name,
            Macro {
                params: Some(params),
                body,
            },
        ));
    }
    Some((
        name,
        Macro {
            params: None,
            body: tokenize(after, body_at),
        },
    ))
}

/// Lines joined across backslash-newlines, each with its line break, covering the whole text.
fn logical_lines(text: &str) -> impl Iterator<Item = &str> {
    let mut rest = text;
    std::iter::from_fn(move || {
        if rest.is_empty() {
            return None;
        }
        let mut end = 0;
        loop {
            match rest[end..].find('\n') {
                Some(n) => {
                    end += n + 1;
                    let line = rest[..end].trim_end_matches(['\n', '\r']);
                    if !line.ends_with('\\') {
                        break;
                    }
                }
                None => {
                    end = rest.len();
                    break;
                }
            }
        }
        let (line, tail) = rest.split_at(end);
        rest = tail;
        Some(line)
    })
}

/// The tokens of `text` (which starts at byte `offset` of the file), comments skipped. A block
/// comment is taken to end on its line: the file-level bracket check has already read the file
/// with comments across lines, and a token more or less only loosens a bound.
fn tokenize(text: &str, offset: usize) -> Vec<Token<'_>> {
    let mut out = Vec::new();
    let mut chars = text.char_indices().peekable();
    while let Some((i, c)) = chars.next() {
        let kind = match c {
            '/' if text[i + 1..].starts_with('/') => break,
            '/' if text[i + 1..].starts_with('*') => {
                let end = text[i + 2..]
                    .find("*/")
                    .map_or(text.len(), |n| i + 2 + n + 2);
                while chars.peek().is_some_and(|&(j, _)| j < end) {
                    chars.next();
                }
                continue;
            }
            '(' | '[' | '{' => Kind::Open,
            ')' | ']' | '}' => Kind::Close,
            ',' => Kind::Comma,
            c if c.is_whitespace() || c == '\\' => continue,
            c if c.is_alphanumeric() || c == '_' => {
                let mut end = i + c.len_utf8();
                while let Some(&(j, d)) = chars.peek() {
                    // A number runs on over `.` (`1.0`); a name stops at it (`P.x` may expand P).
                    if !(d.is_alphanumeric() || d == '_' || (d == '.' && c.is_ascii_digit())) {
                        break;
                    }
                    end = j + d.len_utf8();
                    chars.next();
                }
                let word = &text[i..end];
                if c.is_ascii_digit() {
                    Kind::Other
                } else {
                    Kind::Ident(word)
                }
            }
            _ => Kind::Other,
        };
        let end = i + c.len_utf8();
        let at = match &kind {
            Kind::Ident(w) => offset + i..offset + i + w.len(),
            _ => offset + i..offset + end,
        };
        out.push(Token { kind, at });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const NESTED: &str = "#define A(x) ((((((((((x))))))))))
#define B(x) A(A(A(A(A(A(A(A(A(A(x))))))))))
#define C(x) B(B(B(B(B(B(B(B(B(B(x))))))))))
";

    #[test]
    fn nested_macros_are_bounded_by_what_they_expand_to() {
        // 10 levels per A, 100 per B: B(1.0) stays within 256, C(1.0) (1000 levels) does not.
        let ok = format!("{NESTED}float f() {{ return B(1.0); }}\n");
        assert!(too_large(&ok, &[]).is_none());
        let deep = format!("{NESTED}float f() {{ return C(1.0); }}\n");
        let e = too_large(&deep, &[]).expect("1000 levels");
        assert!(e.what.contains("up to 1001"), "{}", e.what);
        assert_eq!(&deep[e.at.clone()], "C");
    }

    #[test]
    fn macros_that_double_their_argument_are_bounded_by_size() {
        let mut src = String::from("#define M0(x) x x\n");
        for i in 1..40 {
            src += &format!("#define M{i}(x) M{}(M{}(x))\n", i - 1, i - 1);
        }
        src += "float f() { return M39(1.0); }\n";
        let e = too_large(&src, &[]).expect("2^(2^39) tokens");
        assert!(e.what.contains("tokens"), "{}", e.what);
    }

    #[test]
    fn unbalanced_object_macros_count_where_they_are_used() {
        let src = format!(
            "#define O (\n#define C )\nfloat f() {{ return {}1.0{}; }}\n",
            "O ".repeat(300),
            " C".repeat(300)
        );
        let e = too_large(&src, &[]).expect("300 levels");
        assert!(e.what.contains("brackets"), "{}", e.what);
        let fine = src.replace(&"O ".repeat(300), &"O ".repeat(200));
        let fine = fine.replace(&" C".repeat(300), &" C".repeat(200));
        assert!(too_large(&fine, &[]).is_none());
    }

    #[test]
    fn a_macro_naming_itself_is_not_expanded_again() {
        let src = "#define X X + X\n#define F(a) F(a) + a\nfloat f() { return X + F(1.0); }\n";
        assert!(too_large(src, &[]).is_none());
    }

    #[test]
    fn command_line_defines_count() {
        let src = "float f() { return D; }\n";
        let deep = "(".repeat(300) + "1" + &")".repeat(300);
        assert!(too_large(src, &[("D".into(), deep)]).is_some());
    }

    #[test]
    fn lodkit_glsl_twins_are_within_every_bound() {
        // The combine twin is a macro over macros, called here with a large matrix argument.
        let matrix = format!(
            "mat4({})",
            ["vec4(f(0u), f(1u), f(2u), f(3u))"; 4].join(", ")
        );
        for m in crate::shaders::modules() {
            if m.language != crate::shaders::Language::Glsl {
                continue;
            }
            assert_eq!(too_large(m.source, &[]), None, "{:?}", m.include_path);
        }
        let combine = crate::shaders::find_glsl_include("lodkit/combine.glsl")
            .expect("the combine twin")
            .source;
        let call = format!(
            "{combine}\nvoid main() {{ vec4 c = lodkit_combine_at(a, b, c, d, e, f, px, {matrix}); }}\n"
        );
        assert_eq!(too_large(&call, &[]), None);
    }
}
