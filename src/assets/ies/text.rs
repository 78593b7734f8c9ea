//! Lines and numeric tokens shared by the LM-63 and EULUMDAT readers.
//!
//! Both formats are line-based ASCII in practice, but labels may hold any bytes (Latin-1 names,
//! stray control characters), so everything here works on bytes and only numeric tokens are
//! decoded. Allocations are bounded by the input: one entry per line, one per token.

use super::error::{IesError, IesErrorKind as K};

/// The file split into lines, each `(1-based number, content)`. A line ends at CRLF, LF or a
/// lone CR (old Mac files), so every common convention counts lines the way an editor does.
pub fn split_lines(text: &[u8]) -> Vec<(usize, &[u8])> {
    let mut lines = Vec::new();
    let mut start = 0;
    let mut i = 0;
    while i < text.len() {
        match text[i] {
            b'\n' => {
                lines.push((lines.len() + 1, &text[start..i]));
                i += 1;
                start = i;
            }
            b'\r' => {
                lines.push((lines.len() + 1, &text[start..i]));
                i += if text.get(i + 1) == Some(&b'\n') {
                    2
                } else {
                    1
                };
                start = i;
            }
            _ => i += 1,
        }
    }
    if start < text.len() {
        lines.push((lines.len() + 1, &text[start..]));
    }
    lines
}

/// `bytes` without leading and trailing ASCII blanks (space, tab, VT, FF).
pub fn trim(bytes: &[u8]) -> &[u8] {
    let blank = |b: &u8| matches!(b, b' ' | b'\t' | 0x0b | 0x0c);
    let start = bytes.iter().position(|b| !blank(b)).unwrap_or(bytes.len());
    let end = bytes
        .iter()
        .rposition(|b| !blank(b))
        .map_or(start, |e| e + 1);
    &bytes[start..end.max(start)]
}

/// A token as text for error messages: lossy UTF-8, at most 40 characters.
pub fn show(token: &[u8]) -> String {
    let s = String::from_utf8_lossy(token);
    if s.chars().count() > 40 {
        let head: String = s.chars().take(40).collect();
        format!("{head}…")
    } else {
        s.into_owned()
    }
}

/// A number in an EULUMDAT field: as `parse_number`, but a lone decimal comma (`12,5`, common in
/// files written with a German locale) reads as a decimal point.
pub fn parse_number_decimal_comma(token: &[u8], what: &'static str) -> Result<f64, K> {
    let commas = token.iter().filter(|&&b| b == b',').count();
    if commas == 1 && !token.contains(&b'.') {
        let fixed: Vec<u8> = token
            .iter()
            .map(|&b| if b == b',' { b'.' } else { b })
            .collect();
        return parse_number(&fixed, what).map_err(|_| K::NotANumber {
            what,
            token: show(token),
        });
    }
    parse_number(token, what)
}

/// A finite decimal number (`1`, `-2.5`, `.5`, `1e3`); `inf`/`nan` and anything else is refused.
pub fn parse_number(token: &[u8], what: &'static str) -> Result<f64, K> {
    let bad = || K::NotANumber {
        what,
        token: show(token),
    };
    let s = std::str::from_utf8(token).map_err(|_| bad())?;
    // Rust's parser also takes "inf", "NaN" and "infinity": those are not LM-63 numbers.
    if !s
        .bytes()
        .all(|b| b.is_ascii_digit() || b".+-eE".contains(&b))
    {
        return Err(bad());
    }
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(bad()),
    }
}

/// The numeric part of a file as a token stream; each token remembers its line.
pub struct Tokens<'a> {
    toks: Vec<(&'a [u8], usize)>,
    pos: usize,
    /// The line reported when a value is missing: the last line of the file.
    end_line: usize,
    /// EULUMDAT: commas are decimal commas, not separators.
    decimal_comma: bool,
}

impl<'a> Tokens<'a> {
    /// Tokens of `lines`, separated by any mix of blanks, tabs and commas (LM-63-2002 §3: "values
    /// separated by blanks or commas"; line breaks are already gone). `end_line` is the file's
    /// last line.
    pub fn new(lines: &[(usize, &'a [u8])], end_line: usize) -> Self {
        Self::split(lines, end_line, false)
    }

    /// EULUMDAT's numeric tail: blank-separated, a comma is a decimal comma.
    pub fn new_decimal_comma(lines: &[(usize, &'a [u8])], end_line: usize) -> Self {
        Self::split(lines, end_line, true)
    }

    fn split(lines: &[(usize, &'a [u8])], end_line: usize, decimal_comma: bool) -> Self {
        let sep = move |b: &u8| {
            matches!(b, b' ' | b'\t' | 0x0b | 0x0c | b'\r' | b'\n')
                || (*b == b',' && !decimal_comma)
        };
        let toks = lines
            .iter()
            .flat_map(|&(n, l)| l.split(sep).filter(|t| !t.is_empty()).map(move |t| (t, n)))
            .collect();
        Tokens {
            toks,
            pos: 0,
            end_line,
            decimal_comma,
        }
    }

    pub fn remaining(&self) -> usize {
        self.toks.len() - self.pos
    }

    /// The next token, if any, without consuming it.
    pub fn peek(&self) -> Option<(&'a [u8], usize)> {
        self.toks.get(self.pos).copied()
    }

    /// The next number and its line.
    pub fn number(&mut self, what: &'static str) -> Result<(f64, usize), IesError> {
        let Some(&(tok, line)) = self.toks.get(self.pos) else {
            return Err(IesError::at(self.end_line, K::MissingValue { what }));
        };
        self.pos += 1;
        let parsed = if self.decimal_comma {
            parse_number_decimal_comma(tok, what)
        } else {
            parse_number(tok, what)
        };
        parsed.map(|v| (v, line)).map_err(|k| IesError::at(line, k))
    }

    /// The next number, which must be an integer in `min..=max`.
    pub fn integer(
        &mut self,
        what: &'static str,
        min: f64,
        max: f64,
        expected: &'static str,
    ) -> Result<(f64, usize), IesError> {
        let (v, line) = self.number(what)?;
        if v.fract() != 0.0 {
            return Err(IesError::at(line, K::NotAnInteger { what, value: v }));
        }
        if v < min || v > max {
            return Err(IesError::at(
                line,
                K::OutOfRange {
                    what,
                    value: v,
                    expected,
                },
            ));
        }
        Ok((v, line))
    }

    /// A count of items, each `per_item` numbers long, that the rest of the file can hold: a
    /// header announcing more values than remain is refused before anything is allocated.
    pub fn count(
        &mut self,
        what: &'static str,
        min: usize,
        per_item: usize,
    ) -> Result<(usize, usize), IesError> {
        let (v, line) = self.integer(what, min as f64, f64::MAX, "below the minimum")?;
        let fits = (v as usize)
            .checked_mul(per_item)
            .is_some_and(|n| v < usize::MAX as f64 && n <= self.remaining());
        if !fits {
            return Err(IesError::at(
                line,
                K::CountTooLarge {
                    what,
                    count: v,
                    remaining: self.remaining(),
                },
            ));
        }
        Ok((v as usize, line))
    }

    /// `n` strictly increasing numbers (`what` = "vertical angles", ...), each in `lo..=hi`.
    pub fn increasing(
        &mut self,
        n: usize,
        what: &'static str,
        lo: f64,
        hi: f64,
        expected: &'static str,
    ) -> Result<(Vec<f64>, usize), IesError> {
        let mut out = Vec::with_capacity(n.min(self.remaining()));
        let mut last_line = self.end_line;
        for _ in 0..n {
            let (v, line) = self.number(what)?;
            if v < lo || v > hi {
                return Err(IesError::at(
                    line,
                    K::OutOfRange {
                        what,
                        value: v,
                        expected,
                    },
                ));
            }
            if let Some(&prev) = out.last()
                && v <= prev
            {
                return Err(IesError::at(
                    line,
                    K::NotIncreasing {
                        what,
                        prev,
                        value: v,
                    },
                ));
            }
            out.push(v);
            last_line = line;
        }
        Ok((out, last_line))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_ends_crlf_lf_and_lone_cr_count_alike() {
        let l = split_lines(b"a\r\nb\nc\rd");
        assert_eq!(
            l,
            vec![
                (1, &b"a"[..]),
                (2, &b"b"[..]),
                (3, &b"c"[..]),
                (4, &b"d"[..])
            ]
        );
        assert_eq!(split_lines(b"a\n\n").len(), 2);
    }

    #[test]
    fn numbers_refuse_words_that_rust_would_accept() {
        assert_eq!(parse_number(b"-1.5e2", "x"), Ok(-150.0));
        assert_eq!(parse_number(b".5", "x"), Ok(0.5));
        for bad in [
            &b"inf"[..],
            b"NaN",
            b"infinity",
            b"1e999",
            b"1.0.0",
            b"\xff",
            b"0x10",
        ] {
            assert!(parse_number(bad, "x").is_err(), "{bad:?}");
        }
    }

    #[test]
    fn tokens_split_on_blanks_tabs_and_commas_and_keep_lines() {
        let lines = split_lines(b"1, 2\t3\n,,4 \n");
        let mut t = Tokens::new(&lines, 2);
        let got: Vec<(f64, usize)> = (0..4).map(|_| t.number("v").unwrap()).collect();
        assert_eq!(got, vec![(1.0, 1), (2.0, 1), (3.0, 1), (4.0, 2)]);
        assert_eq!(t.number("v").unwrap_err().line, Some(2));
    }
}
