//! Lexing: the token forms of usd-core's text file format lexer (`textFileFormat.ll`), and
//! each written back in the form openusd 0.8's lexer reads.

use super::{R, err};

#[derive(Clone, Debug, PartialEq)]
pub(super) enum Tok<'a> {
    /// The `#usda 1.0` cookie (its whole first line, comments after the version dropped).
    Magic(&'a str),
    /// A name: `def`, `float3`, `inputs:intensity`, `Foo::Bar`, `inf`, `True`.
    Ident(&'a str),
    /// A number as written (`-1`, `0.`, `.5`, `1.e5`).
    Number(&'a str),
    /// A quoted string, its escapes evaluated.
    Str(String),
    /// An asset path between `@…@` or `@@@…@@@`.
    Asset(String),
    /// A path between `<…>`.
    Path(&'a str),
    Punct(char),
}

#[derive(Clone, Debug)]
pub(super) struct Lexed<'a> {
    pub tok: Tok<'a>,
    /// 1-based line the token starts on.
    pub line: usize,
    /// Its bytes in the source.
    pub span: (usize, usize),
}

fn is_name_start(c: char) -> bool {
    c == '_' || c.is_alphabetic()
}

fn is_name_char(c: char) -> bool {
    c == '_' || c.is_alphanumeric()
}

pub(super) fn lex(text: &str) -> R<Vec<Lexed<'_>>> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0usize;
    let mut line = 1usize;
    // The cookie is the first line's `#usda <version>`, whatever follows it on that line.
    let start = text.len() - text.trim_start().len();
    line += text[..start].matches('\n').count();
    i = i.max(start);
    if !text[i..].starts_with("#usda") {
        return err(line, "a text layer begins with `#usda 1.0`");
    }
    let eol = text[i..].find('\n').map_or(text.len(), |k| i + k);
    let cookie = text[i..eol].trim_end();
    let version_end = cookie[5..]
        .trim_start()
        .find(char::is_whitespace)
        .map_or(cookie.len(), |k| {
            cookie.len() - cookie[5..].trim_start().len() + k
        });
    out.push(Lexed {
        tok: Tok::Magic(cookie[..version_end].trim_end()),
        line,
        span: (i, eol),
    });
    i = eol;
    while i < bytes.len() {
        let c = text[i..].chars().next().unwrap_or('\0');
        let first_line = line;
        match c {
            '\n' => {
                line += 1;
                i += 1;
            }
            c if c.is_whitespace() => i += c.len_utf8(),
            '#' => i = text[i..].find('\n').map_or(text.len(), |k| i + k),
            '/' if text[i..].starts_with("//") => {
                i = text[i..].find('\n').map_or(text.len(), |k| i + k)
            }
            '/' if text[i..].starts_with("/*") => {
                let Some(k) = text[i + 2..].find("*/") else {
                    return err(line, "a `/*` comment is not closed");
                };
                line += text[i..i + 2 + k].matches('\n').count();
                i += k + 4;
            }
            '"' | '\'' => {
                let (value, len) = string(&text[i..], line)?;
                line += text[i..i + len].matches('\n').count();
                out.push(Lexed {
                    tok: Tok::Str(value),
                    line: first_line,
                    span: (i, i + len),
                });
                i += len;
            }
            '@' => {
                let (value, len) = if text[i..].starts_with("@@@") {
                    asset_triple(&text[i..], line)?
                } else {
                    let Some(k) = text[i + 1..].find(['@', '\n']) else {
                        return err(line, "an asset path `@…@` is not closed");
                    };
                    if bytes[i + 1 + k] == b'\n' {
                        return err(line, "an asset path `@…@` is not closed on its line");
                    }
                    (text[i + 1..i + 1 + k].to_string(), k + 2)
                };
                out.push(Lexed {
                    tok: Tok::Asset(value),
                    line,
                    span: (i, i + len),
                });
                i += len;
            }
            '<' => {
                let Some(k) = text[i + 1..].find(['>', '\n']) else {
                    return err(line, "a path `<…>` is not closed");
                };
                if bytes[i + 1 + k] == b'\n' {
                    return err(line, "a path `<…>` is not closed on its line");
                }
                out.push(Lexed {
                    tok: Tok::Path(&text[i + 1..i + 1 + k]),
                    line,
                    span: (i, i + k + 2),
                });
                i += k + 2;
            }
            c if c.is_ascii_digit()
                || ((c == '-' || c == '.') && number_len(&text[i..]).is_some_and(|n| n > 1)) =>
            {
                let n = number_len(&text[i..]).unwrap_or(1);
                out.push(Lexed {
                    tok: Tok::Number(&text[i..i + n]),
                    line,
                    span: (i, i + n),
                });
                i += n;
            }
            c if is_name_start(c) => {
                let n = name_len(&text[i..]);
                out.push(Lexed {
                    tok: Tok::Ident(&text[i..i + n]),
                    line,
                    span: (i, i + n),
                });
                i += n;
            }
            '=' | ',' | ';' | ':' | '.' | '(' | ')' | '{' | '}' | '[' | ']' | '&' | '-' | '+' => {
                out.push(Lexed {
                    tok: Tok::Punct(c),
                    line,
                    span: (i, i + 1),
                });
                i += 1;
            }
            other => return err(line, format!("unexpected character {other:?}")),
        }
    }
    Ok(out)
}

/// The length of the number at the start of `s`: `-?(digits(.digits?)?|.digits)(e[+-]?digits)?`
/// (usd-core's lexer takes `0.` and `.5` alike), or `None` when `s` does not start with one.
fn number_len(s: &str) -> Option<usize> {
    let b = s.as_bytes();
    let mut i = usize::from(b.first() == Some(&b'-'));
    let digits = |from: usize| b[from..].iter().take_while(|c| c.is_ascii_digit()).count();
    let whole = digits(i);
    i += whole;
    let mut frac = 0;
    if b.get(i) == Some(&b'.') {
        frac = digits(i + 1);
        // `1.` is a number; `.` alone, or `.x`, is not.
        if whole == 0 && frac == 0 {
            return None;
        }
        i += 1 + frac;
    }
    if whole == 0 && frac == 0 {
        return None;
    }
    if matches!(b.get(i), Some(b'e' | b'E')) {
        let sign = usize::from(matches!(b.get(i + 1), Some(b'+' | b'-')));
        let exp = digits(i + 1 + sign);
        if exp > 0 {
            i += 1 + sign + exp;
        }
    }
    Some(i)
}

/// The length of the name at the start of `s`: identifier characters, joined by `:` or `::`
/// (`inputs:shaping:cone:angle`, `Foo::Bar`).
fn name_len(s: &str) -> usize {
    let mut n = s
        .char_indices()
        .find(|&(_, c)| !is_name_char(c))
        .map_or(s.len(), |(k, _)| k);
    loop {
        let rest = &s[n..];
        let colons = rest.len() - rest.trim_start_matches(':').len();
        if colons == 0 || colons > 2 {
            return n;
        }
        let after = &rest[colons..];
        match after.chars().next() {
            Some(c) if is_name_char(c) => {
                n += colons
                    + after
                        .char_indices()
                        .find(|&(_, c)| !is_name_char(c))
                        .map_or(after.len(), |(k, _)| k);
            }
            _ => return n,
        }
    }
}

/// A quoted string at the start of `s` (`"…"`, `'…'`, `"""…"""`, `'''…'''`): its value with
/// escapes evaluated as usd-core's `Sdf_EvalQuotedString` does, and its length in bytes.
fn string(s: &str, line: usize) -> R<(String, usize)> {
    let q = s.as_bytes()[0] as char;
    let triple: String = [q, q, q].iter().collect();
    let (open, multi) = if s.starts_with(&triple) {
        (3, true)
    } else {
        (1, false)
    };
    let mut value = String::new();
    let mut chars = s[open..].char_indices().peekable();
    while let Some((k, c)) = chars.next() {
        match c {
            '\\' => {
                let Some((_, e)) = chars.next() else { break };
                match e {
                    'n' => value.push('\n'),
                    't' => value.push('\t'),
                    'r' => value.push('\r'),
                    'a' => value.push('\u{7}'),
                    'b' => value.push('\u{8}'),
                    'f' => value.push('\u{c}'),
                    'v' => value.push('\u{b}'),
                    'x' => {
                        let mut v = 0u32;
                        for _ in 0..2 {
                            match chars.peek().and_then(|(_, d)| d.to_digit(16)) {
                                Some(d) => {
                                    v = v * 16 + d;
                                    chars.next();
                                }
                                None => break,
                            }
                        }
                        value.push(char::from_u32(v).unwrap_or('\u{fffd}'));
                    }
                    '0'..='7' => {
                        let mut v = e.to_digit(8).unwrap_or(0);
                        for _ in 0..2 {
                            match chars.peek().and_then(|(_, d)| d.to_digit(8)) {
                                Some(d) => {
                                    v = v * 8 + d;
                                    chars.next();
                                }
                                None => break,
                            }
                        }
                        value.push(char::from_u32(v).unwrap_or('\u{fffd}'));
                    }
                    other => value.push(other),
                }
            }
            '\n' if !multi => return err(line, "a quoted string is not closed on its line"),
            c if c == q && (!multi || s[open + k..].starts_with(&triple)) => {
                return Ok((value, open + k + open));
            }
            c => value.push(c),
        }
    }
    err(line, "a quoted string is not closed")
}

/// An `@@@…@@@` asset path (which may hold `@`; `\@@@` is a literal `@@@`), and its length.
fn asset_triple(s: &str, line: usize) -> R<(String, usize)> {
    let mut value = String::new();
    let mut k = 3;
    while k < s.len() {
        let rest = &s[k..];
        if rest.starts_with("\\@@@") {
            value.push_str("@@@");
            k += 4;
        } else if rest.starts_with("@@@") {
            // The path ends at the last `@` of a run (`@@@a@@@@` is `a@`).
            let run = rest.len() - rest.trim_start_matches('@').len();
            value.extend(std::iter::repeat_n('@', run - 3));
            return Ok((value, k + run));
        } else if rest.starts_with('\n') {
            break;
        } else {
            let c = rest.chars().next().unwrap_or('\0');
            value.push(c);
            k += c.len_utf8();
        }
    }
    err(line, "an asset path `@@@…@@@` is not closed on its line")
}

/// A number as openusd's lexer reads it: a digit on both sides of the point (`0.` → `0`,
/// `.5` → `0.5`, `1.e5` → `1e5`); the digits themselves are kept as written.
pub(super) fn canonical_number(n: &str) -> String {
    let (sign, rest) = match n.strip_prefix('-') {
        Some(r) => ("-", r),
        None => ("", n),
    };
    let (mantissa, exp) = match rest.find(['e', 'E']) {
        Some(k) => (&rest[..k], &rest[k..]),
        None => (rest, ""),
    };
    let mantissa = match mantissa.split_once('.') {
        Some((w, "")) => w.to_string(),
        Some(("", f)) => format!("0.{f}"),
        _ => mantissa.to_string(),
    };
    format!("{sign}{mantissa}{exp}")
}

/// A string as one double-quoted token openusd's lexer reads back to the same value.
pub(super) fn quote(s: &str) -> String {
    let mut q = String::with_capacity(s.len() + 2);
    q.push('"');
    for c in s.chars() {
        match c {
            '"' => q.push_str("\\\""),
            '\\' => q.push_str("\\\\"),
            '\n' => q.push_str("\\n"),
            '\r' => q.push_str("\\r"),
            '\t' => q.push_str("\\t"),
            c if (c as u32) < 0x20 => q.push_str(&format!("\\x{:02x}", c as u32)),
            c => q.push(c),
        }
    }
    q.push('"');
    q
}

/// An asset path as openusd's lexer reads it: `@…@`, or `@@@…@@@` when it holds an `@`.
pub(super) fn asset(a: &str) -> String {
    if a.contains('@') {
        format!("@@@{a}@@@")
    } else {
        format!("@{a}@")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_of_every_form_read_as_usd_core_reads_them() {
        for (n, want) in [
            ("0.", "0"),
            (".5", "0.5"),
            ("-.5e-1", "-0.5e-1"),
            ("1.e5", "1e5"),
            ("1E+3", "1E+3"),
            ("-12.25", "-12.25"),
        ] {
            assert_eq!(number_len(n), Some(n.len()), "{n}");
            assert_eq!(canonical_number(n), want, "{n}");
        }
        assert_eq!(number_len("."), None);
        assert_eq!(number_len("-"), None);
        assert_eq!(number_len("1.x"), Some(2));
    }
}
