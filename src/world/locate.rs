//! Finding a field path such as `obstacles[2].radius` in RON text, so that semantic errors
//! (found after deserialisation, which forgets positions) can still say `file:line:col`.
//!
//! A small tokenizer skips whitespace, line and nested block comments, strings and chars;
//! a recursive walk then follows the path through struct fields (`name: value`) and list
//! or tuple elements (`[a, b]`, `(a, b)`), skipping over optional struct and variant names.
//! Linear in the length of the text. Best effort: if the path is not in the text (a field
//! left at its default), the deepest prefix that is present is reported instead.

/// One step of a field path.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Step {
    Field(String),
    Index(usize),
}

/// Splits `obstacles[2].points[0]` into steps; `None` if the path is malformed.
fn steps(path: &str) -> Option<Vec<Step>> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (name, mut rest) = match part.find('[') {
            Some(i) => (&part[..i], &part[i..]),
            None => (part, ""),
        };
        if !name.is_empty() {
            out.push(Step::Field(name.to_string()));
        }
        while let Some(r) = rest.strip_prefix('[') {
            let end = r.find(']')?;
            out.push(Step::Index(r[..end].parse().ok()?));
            rest = &r[end + 1..];
        }
    }
    Some(out)
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Open(char),
    Close,
    Comma,
    Colon,
    Ident,
    Other,
}

#[derive(Debug, Clone)]
struct Token<'a> {
    kind: Kind,
    text: &'a str,
    line: usize,
    col: usize,
}

/// If `rest` opens a raw string (`r"`, `r#"`, `r##"` …), the number of its `#`.
fn raw_string_hashes(rest: &[(usize, char)]) -> Option<usize> {
    if rest.first()?.1 != 'r' {
        return None;
    }
    let hashes = rest[1..].iter().take_while(|x| x.1 == '#').count();
    (rest.get(1 + hashes)?.1 == '"').then_some(hashes)
}

fn tokenize(text: &str) -> Vec<Token<'_>> {
    let chars: Vec<(usize, char)> = text.char_indices().collect();
    let mut out = Vec::new();
    let (mut i, mut line, mut col) = (0, 1, 1);
    // Advances over chars[i], keeping line and column (both 1-based, columns in chars).
    let step = |i: &mut usize, line: &mut usize, col: &mut usize| {
        if chars[*i].1 == '\n' {
            *line += 1;
            *col = 1;
        } else {
            *col += 1;
        }
        *i += 1;
    };
    while i < chars.len() {
        let c = chars[i].1;
        let next = chars.get(i + 1).map(|x| x.1);
        let (start, sl, sc) = (chars[i].0, line, col);
        if c.is_whitespace() {
            step(&mut i, &mut line, &mut col);
        } else if c == '/' && next == Some('/') {
            while i < chars.len() && chars[i].1 != '\n' {
                step(&mut i, &mut line, &mut col);
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0usize;
            while i < chars.len() {
                let (a, b) = (chars[i].1, chars.get(i + 1).map(|x| x.1));
                if a == '/' && b == Some('*') {
                    depth += 1;
                    step(&mut i, &mut line, &mut col);
                } else if a == '*' && b == Some('/') {
                    depth -= 1;
                    step(&mut i, &mut line, &mut col);
                    if depth == 0 {
                        step(&mut i, &mut line, &mut col);
                        break;
                    }
                }
                step(&mut i, &mut line, &mut col);
            }
        } else if c == '"' || c == '\'' || raw_string_hashes(&chars[i..]).is_some() {
            if let Some(hashes) = raw_string_hashes(&chars[i..]) {
                // A raw string, r"…" or r#"…"#: no escapes, and it ends only at a quote
                // followed by as many `#` as opened it.
                for _ in 0..hashes + 2 {
                    step(&mut i, &mut line, &mut col);
                }
                while i < chars.len() {
                    let closes = chars[i].1 == '"'
                        && (1..=hashes).all(|k| chars.get(i + k).is_some_and(|x| x.1 == '#'));
                    if closes {
                        for _ in 0..hashes + 1 {
                            step(&mut i, &mut line, &mut col);
                        }
                        break;
                    }
                    step(&mut i, &mut line, &mut col);
                }
            } else {
                step(&mut i, &mut line, &mut col);
                while i < chars.len() && chars[i].1 != c {
                    if chars[i].1 == '\\' {
                        step(&mut i, &mut line, &mut col);
                    }
                    if i < chars.len() {
                        step(&mut i, &mut line, &mut col);
                    }
                }
                if i < chars.len() {
                    step(&mut i, &mut line, &mut col);
                }
            }
            let end = chars.get(i).map_or(text.len(), |x| x.0);
            out.push(Token {
                kind: Kind::Other,
                text: &text[start..end],
                line: sl,
                col: sc,
            });
        } else if "([{)]},:".contains(c) {
            let kind = match c {
                '(' | '[' | '{' => Kind::Open(c),
                ')' | ']' | '}' => Kind::Close,
                ',' => Kind::Comma,
                _ => Kind::Colon,
            };
            step(&mut i, &mut line, &mut col);
            out.push(Token {
                kind,
                text: &text[start..start + c.len_utf8()],
                line: sl,
                col: sc,
            });
        } else {
            let word = |c: char| c.is_alphanumeric() || "_+-.#!".contains(c);
            while i < chars.len() && word(chars[i].1) {
                step(&mut i, &mut line, &mut col);
            }
            if i < chars.len() && chars[i].0 == start {
                // A character we do not know: take it alone so we always progress.
                step(&mut i, &mut line, &mut col);
            }
            let end = chars.get(i).map_or(text.len(), |x| x.0);
            let s = &text[start..end];
            let ident = s
                .chars()
                .next()
                .is_some_and(|c| c.is_alphabetic() || c == '_')
                && s.chars().all(|c| c.is_alphanumeric() || c == '_');
            out.push(Token {
                kind: if ident { Kind::Ident } else { Kind::Other },
                text: s,
                line: sl,
                col: sc,
            });
        }
    }
    out
}

/// Index just past the value starting at `i`.
fn skip_value(t: &[Token<'_>], mut i: usize) -> usize {
    if i < t.len()
        && t[i].kind == Kind::Ident
        && matches!(t.get(i + 1), Some(x) if matches!(x.kind, Kind::Open(_)))
    {
        i += 1;
    }
    match t.get(i).map(|x| x.kind) {
        Some(Kind::Open(_)) => {
            let mut depth = 0usize;
            while i < t.len() {
                match t[i].kind {
                    Kind::Open(_) => depth += 1,
                    Kind::Close => {
                        depth -= 1;
                        if depth == 0 {
                            return i + 1;
                        }
                    }
                    _ => {}
                }
                i += 1;
            }
            i
        }
        Some(_) => i + 1,
        None => i,
    }
}

/// Follows `path` from the value starting at `i`; returns the position of the deepest
/// step found (`best` is the position of the value itself).
fn walk(t: &[Token<'_>], mut i: usize, path: &[Step], best: (usize, usize)) -> (usize, usize) {
    let Some(head) = path.first() else {
        return best;
    };
    if i < t.len()
        && t[i].kind == Kind::Ident
        && matches!(t.get(i + 1), Some(x) if matches!(x.kind, Kind::Open(_)))
    {
        i += 1;
    }
    if !matches!(t.get(i).map(|x| x.kind), Some(Kind::Open(_))) {
        return best;
    }
    i += 1; // past the opening bracket
    let mut index = 0usize;
    while i < t.len() && t[i].kind != Kind::Close {
        let is_field =
            t[i].kind == Kind::Ident && t.get(i + 1).map(|x| x.kind) == Some(Kind::Colon);
        let value_start = if is_field { i + 2 } else { i };
        let hit = match head {
            Step::Field(name) => is_field && t[i].text == name,
            Step::Index(k) => !is_field && index == *k,
        };
        if hit {
            let here = (t[i].line, t[i].col);
            return walk(t, value_start, &path[1..], here);
        }
        i = skip_value(t, value_start);
        index += 1;
        if t.get(i).map(|x| x.kind) == Some(Kind::Comma) {
            i += 1;
        }
    }
    best
}

/// `(line, col)` of the field at `path` (e.g. `obstacles[2].radius`) in RON `text`, or
/// of the deepest part of the path present in the text; `None` if not even the first
/// step is there.
pub fn locate(text: &str, path: &str) -> Option<(usize, usize)> {
    let steps = steps(path)?;
    let tokens = tokenize(text);
    // Skip inner attributes such as `#![enable(implicit_some)]`.
    let mut i = 0;
    while i < tokens.len() && tokens[i].text.starts_with('#') {
        i += 1;
        if tokens.get(i).map(|x| x.kind) == Some(Kind::Open('[')) {
            i = skip_value(&tokens, i);
        }
    }
    let found = walk(&tokens, i, &steps, (0, 0));
    (found != (0, 0)).then_some(found)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = r#"// comment with (brackets] and "quotes
#![enable(implicit_some)]
(
    name: "a (tricky) name, with: punctuation",
    /* nested /* block */ comment */
    obstacles: [
        Rect(min: (1.0, 2.0), max: (3.0, 4.0)),
        Circle(center: (5.0, 3.0), radius: -1.0),
        Polygon(points: [(0.0, 0.0), (1.0, 0.0), (0.5, 1.0)]),
    ],
    swarm: (agents: 0),
)
"#;

    #[test]
    fn finds_fields_and_elements() {
        assert_eq!(locate(TEXT, "name"), Some((4, 5)));
        assert_eq!(locate(TEXT, "obstacles"), Some((6, 5)));
        assert_eq!(locate(TEXT, "obstacles[0]"), Some((7, 9)));
        assert_eq!(locate(TEXT, "obstacles[1].radius"), Some((8, 36)));
        assert_eq!(locate(TEXT, "obstacles[2].points[2]"), Some((9, 50)));
        assert_eq!(locate(TEXT, "swarm.agents"), Some((11, 13)));
    }

    #[test]
    fn falls_back_to_the_deepest_prefix() {
        assert_eq!(locate(TEXT, "swarm.speed"), Some((11, 5)));
        assert_eq!(locate(TEXT, "obstacles[7].radius"), Some((6, 5)));
        assert_eq!(locate(TEXT, "leader.window"), None);
        assert_eq!(locate("", "name"), None);
        assert_eq!(locate("(((", "a.b"), None);
    }

    #[test]
    fn raw_strings_hide_what_they_hold() {
        let t = "(\n  name: r#\"x \" arena: (width: -1.0) \"#,\n  arena: (width: -2.0),\n)\n";
        assert_eq!(locate(t, "arena.width"), Some((3, 11)));
        let t = "(name: r\"a: (b: 1)\", a: (b: 2))";
        assert_eq!(locate(t, "a.b"), Some((1, 26)));
        // Unterminated: the rest of the text is the string; nothing after it is found.
        assert_eq!(locate("(name: r##\"x\"# a: 1)", "a"), None);
        // Identifiers that begin with r are words, not raw strings.
        assert_eq!(locate("(radius: 1, r: 2)", "r"), Some((1, 13)));
    }

    #[test]
    fn parses_paths() {
        assert_eq!(
            steps("a[1][2].b"),
            Some(vec![
                Step::Field("a".into()),
                Step::Index(1),
                Step::Index(2),
                Step::Field("b".into())
            ])
        );
        assert_eq!(steps("a[x]"), None);
    }
}
