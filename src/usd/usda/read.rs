//! Parsing and writing back: the layer's grammar (`textFileFormat.yy`) as far as values need
//! their declared type; what needs none is passed on token by token.

use super::lex::{Lexed, Tok, asset, canonical_number, quote};
use super::{R, err};

/// Metadata fields usd-core types as bool that openusd 0.8 reads only as `true` or `false`
/// (`active`); it reads `instanceable` as usd-core does, and keeps `hidden` as a token nothing
/// here interprets, so their values are passed on as written.
const BOOL_FIELDS: &[&str] = &["active"];

/// What a declared value type asks of its written values.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Coerce {
    Asset,
    Int,
    Bool,
    /// token and string: a path written there is not a token.
    Text,
    None,
}

fn coerce_for(type_name: &str) -> Coerce {
    let base = type_name.trim_end_matches(|c: char| c.is_ascii_digit());
    match type_name {
        "asset" => Coerce::Asset,
        "bool" => Coerce::Bool,
        "token" | "string" => Coerce::Text,
        "uchar" | "uint" | "uint64" | "int64" => Coerce::Int,
        _ if base == "int" => Coerce::Int,
        _ => Coerce::None,
    }
}

pub(super) struct Reader<'a> {
    src: &'a str,
    tokens: Vec<Lexed<'a>>,
    pos: usize,
    out: String,
    /// The line the output is on: tokens are written on their own source line.
    out_line: usize,
    notes: Vec<String>,
    /// Whether a property authors a spline (`.spline =`).
    has_spline: bool,
    /// How deep the construct being read nests, and the most allowed.
    depth: usize,
    max_nesting: usize,
}

impl<'a> Reader<'a> {
    pub(super) fn new(src: &'a str, tokens: Vec<Lexed<'a>>, max_nesting: usize) -> Self {
        Reader {
            src,
            tokens,
            pos: 0,
            out: String::with_capacity(src.len() + 64),
            out_line: 1,
            notes: Vec::new(),
            has_spline: false,
            depth: 0,
            max_nesting,
        }
    }

    /// The whole layer written canonically, the notes of what was read differently, and
    /// whether a property authors a spline.
    pub(super) fn read(mut self) -> R<super::Canonical> {
        self.layer()?;
        self.out.push('\n');
        Ok(super::Canonical {
            text: self.out,
            notes: self.notes,
            has_spline: self.has_spline,
        })
    }

    fn peek(&self) -> Option<&Tok<'a>> {
        self.tokens.get(self.pos).map(|t| &t.tok)
    }

    fn peek_at(&self, ahead: usize) -> Option<&Tok<'a>> {
        self.tokens.get(self.pos + ahead).map(|t| &t.tok)
    }

    fn line(&self) -> usize {
        self.tokens
            .get(self.pos)
            .or(self.tokens.last())
            .map_or(1, |t| t.line)
    }

    fn at_punct(&self, c: char) -> bool {
        self.peek() == Some(&Tok::Punct(c))
    }

    fn at_ident(&self, word: &str) -> bool {
        self.peek() == Some(&Tok::Ident(word))
    }

    /// Starts writing the token at `pos`: after the blanks that precede it in the source when
    /// they are only blanks and the output is on their line (openusd keeps the text of values
    /// it does not know, blanks included), else on its own line, a space apart.
    fn place(&mut self, pos: usize) {
        let Some(t) = self.tokens.get(pos) else {
            return;
        };
        let line = t.line;
        if let Some(prev) = pos.checked_sub(1).and_then(|p| self.tokens.get(p)) {
            let gap = &self.src[prev.span.1..t.span.0];
            if gap.chars().all(char::is_whitespace)
                && self.out_line + gap.matches('\n').count() == line
            {
                self.out.push_str(gap);
                self.out_line = line;
                return;
            }
        }
        if self.out_line < line {
            while self.out_line < line {
                self.out.push('\n');
                self.out_line += 1;
            }
        } else if !self.out.is_empty() {
            self.out.push(' ');
        }
    }

    /// Writes `text` for the current token and moves past it.
    fn put(&mut self, text: &str) {
        // A string over several lines is written on one; the next token keeps its own line.
        self.place(self.pos);
        self.out.push_str(text);
        self.pos += 1;
    }

    /// Passes the current token on canonically.
    fn pass(&mut self) -> R<()> {
        let Some(t) = self.tokens.get(self.pos) else {
            return err(self.line(), "the layer ends early");
        };
        let text = match &t.tok {
            Tok::Magic(m) => m.to_string(),
            Tok::Ident(s) => s.to_string(),
            Tok::Number(n) => canonical_number(n),
            Tok::Str(s) => quote(s),
            Tok::Asset(a) => asset(a),
            Tok::Path(p) => format!("<{p}>"),
            Tok::Punct(c) => c.to_string(),
        };
        self.put(&text);
        Ok(())
    }

    /// Runs `read` one level deeper, refusing what nests deeper than allowed.
    fn nested(&mut self, read: impl FnOnce(&mut Self) -> R<()>) -> R<()> {
        if self.depth >= self.max_nesting {
            return err(
                self.line(),
                format!(
                    "prims, dictionaries, lists or tuples nest more than {} deep",
                    self.max_nesting
                ),
            );
        }
        self.depth += 1;
        let r = read(self);
        self.depth -= 1;
        r
    }

    fn expect_punct(&mut self, c: char) -> R<()> {
        if !self.at_punct(c) {
            return err(
                self.line(),
                format!("expected `{c}`, found {}", self.describe()),
            );
        }
        self.pass()
    }

    fn describe(&self) -> String {
        match self.peek() {
            None => "the end of the layer".into(),
            Some(Tok::Magic(_)) => "a second `#usda` cookie".into(),
            Some(Tok::Ident(s)) => format!("`{s}`"),
            Some(Tok::Number(n)) => format!("the number {n}"),
            Some(Tok::Str(s)) => format!("the string {s:?}"),
            Some(Tok::Asset(a)) => format!("the asset path @{a}@"),
            Some(Tok::Path(p)) => format!("the path <{p}>"),
            Some(Tok::Punct(c)) => format!("`{c}`"),
        }
    }

    fn layer(&mut self) -> R<()> {
        self.pass()?; // the cookie
        if self.at_punct('(') {
            self.metadata()?;
        }
        while self.peek().is_some() {
            self.statement()?;
        }
        Ok(())
    }

    /// A `( … )` block of metadata: a doc string, or `[listop] field = value`, separated by
    /// line breaks, `;` or `,`.
    fn metadata(&mut self) -> R<()> {
        self.expect_punct('(')?;
        loop {
            match self.peek() {
                Some(Tok::Punct(')')) => return self.pass(),
                Some(Tok::Punct(';' | ',')) | Some(Tok::Str(_)) => self.pass()?,
                Some(Tok::Ident(_)) => {
                    if let Some(Tok::Ident("add" | "append" | "prepend" | "delete" | "reorder")) =
                        self.peek()
                        && matches!(self.peek_at(1), Some(Tok::Ident(_)))
                    {
                        self.pass()?;
                    }
                    let Some(Tok::Ident(field)) = self.peek().cloned() else {
                        return err(self.line(), "expected a metadata field name");
                    };
                    self.pass()?;
                    if self.at_punct('=') {
                        self.pass()?;
                        self.field_value(field)?;
                    }
                }
                None => return err(self.line(), "a metadata block `( … )` is not closed"),
                Some(_) => {
                    return err(
                        self.line(),
                        format!("expected a metadata field, found {}", self.describe()),
                    );
                }
            }
        }
    }

    /// The value of metadata field `field`, whose type the layer does not write (a dictionary's
    /// entries, `customData = { … }`, declare theirs: see [`Self::value`]).
    fn field_value(&mut self, field: &str) -> R<()> {
        if BOOL_FIELDS.contains(&field) {
            return self.scalar(Coerce::Bool, "");
        }
        self.value(Coerce::None, "")?;
        // A reference or payload's layer offset: `@a.usda@</P> (offset = 10; scale = 2)`.
        if self.at_punct('(')
            && matches!(
                self.tokens.get(self.pos.wrapping_sub(1)).map(|t| &t.tok),
                Some(Tok::Asset(_) | Tok::Path(_))
            )
        {
            self.value(Coerce::None, "")?;
        }
        Ok(())
    }

    /// A dictionary `{ type name = value … }`, `dictionary name = { … }` nesting (a `{ … }` of
    /// another form, `relocates = { <a>: <b> }`, is passed on as written by [`Self::value`]).
    fn dictionary(&mut self) -> R<()> {
        self.expect_punct('{')?;
        loop {
            match self.peek() {
                Some(Tok::Punct('}')) => return self.pass(),
                Some(Tok::Punct(';' | ',')) => self.pass()?,
                Some(Tok::Ident("dictionary")) => {
                    self.pass()?;
                    self.name()?;
                    self.expect_punct('=')?;
                    self.nested(Self::dictionary)?;
                }
                Some(Tok::Ident(ty)) => {
                    let ty = *ty;
                    self.pass()?;
                    if self.at_punct('[') {
                        self.pass()?;
                        self.expect_punct(']')?;
                    }
                    self.name()?;
                    self.expect_punct('=')?;
                    self.value(coerce_for(ty), ty)?;
                }
                None => return err(self.line(), "a dictionary `{ … }` is not closed"),
                Some(_) => {
                    return err(
                        self.line(),
                        format!("expected a dictionary entry, found {}", self.describe()),
                    );
                }
            }
        }
    }

    /// A name: an identifier (keywords included) or a quoted string.
    fn name(&mut self) -> R<()> {
        match self.peek() {
            Some(Tok::Ident(_) | Tok::Str(_)) => self.pass(),
            _ => err(
                self.line(),
                format!("expected a name, found {}", self.describe()),
            ),
        }
    }

    /// One statement of a layer or prim body.
    fn statement(&mut self) -> R<()> {
        match self.peek() {
            Some(Tok::Ident("def" | "over" | "class")) => self.prim(),
            Some(Tok::Ident("variantSet")) if matches!(self.peek_at(1), Some(Tok::Str(_))) => {
                self.variant_set()
            }
            Some(Tok::Ident("reorder"))
                if matches!(
                    self.peek_at(1),
                    Some(Tok::Ident("nameChildren" | "properties" | "rootPrims"))
                ) =>
            {
                self.pass()?;
                self.pass()?;
                self.expect_punct('=')?;
                self.value(Coerce::None, "")
            }
            Some(Tok::Punct(';')) => self.pass(),
            Some(Tok::Ident(_)) => self.property(),
            _ => err(
                self.line(),
                format!("expected a prim or a property, found {}", self.describe()),
            ),
        }
    }

    fn prim(&mut self) -> R<()> {
        self.pass()?; // def, over or class
        if let Some(Tok::Ident(_)) = self.peek() {
            self.pass()?; // the type name
            // A type name may be a dotted or `::` qualified identifier.
            while self.at_punct('.') {
                self.pass()?;
                self.name()?;
            }
        }
        match self.peek() {
            Some(Tok::Str(_)) => self.pass()?,
            _ => {
                return err(
                    self.line(),
                    format!("expected the prim's quoted name, found {}", self.describe()),
                );
            }
        }
        if self.at_punct('(') {
            self.metadata()?;
        }
        self.body()
    }

    /// `{ statements }`.
    fn body(&mut self) -> R<()> {
        self.expect_punct('{')?;
        loop {
            match self.peek() {
                Some(Tok::Punct('}')) => return self.pass(),
                None => return err(self.line(), "a prim's `{ … }` is not closed"),
                _ => self.nested(Self::statement)?,
            }
        }
    }

    /// `variantSet "name" = { "variant" [( metadata )] { body } … }`.
    fn variant_set(&mut self) -> R<()> {
        self.pass()?;
        self.pass()?;
        self.expect_punct('=')?;
        self.expect_punct('{')?;
        loop {
            match self.peek() {
                Some(Tok::Punct('}')) => return self.pass(),
                Some(Tok::Str(_)) => {
                    self.pass()?;
                    if self.at_punct('(') {
                        self.metadata()?;
                    }
                    self.body()?;
                }
                _ => {
                    return err(
                        self.line(),
                        format!("expected a quoted variant name, found {}", self.describe()),
                    );
                }
            }
        }
    }

    /// An attribute or relationship:
    /// `[listop] [custom] [uniform|config|varying] type[[]] name[.connect|.timeSamples|…]
    /// [= value] [( metadata )]`, or `… rel name [= targets] [( metadata )]`.
    fn property(&mut self) -> R<()> {
        if let Some(Tok::Ident("add" | "append" | "prepend" | "delete" | "reorder")) = self.peek() {
            self.pass()?;
        }
        if self.at_ident("custom") {
            self.pass()?;
        }
        match self.peek() {
            Some(Tok::Ident("uniform" | "varying")) => self.pass()?,
            // `config` is usd-core's old spelling of `uniform`.
            Some(Tok::Ident("config")) => self.put("uniform"),
            _ => {}
        }
        let Some(Tok::Ident(ty)) = self.peek().cloned() else {
            return err(
                self.line(),
                format!("expected a property's type, found {}", self.describe()),
            );
        };
        self.pass()?;
        let is_rel = ty == "rel";
        if !is_rel && self.at_punct('[') {
            self.pass()?;
            self.expect_punct(']')?;
        }
        let name_line = self.line();
        let name = match self.peek() {
            Some(Tok::Ident(n)) => n.to_string(),
            _ => {
                return err(
                    self.line(),
                    format!("expected a property name, found {}", self.describe()),
                );
            }
        };
        self.pass()?;
        let mut suffix = "";
        if self.at_punct('.')
            && let Some(Tok::Ident(s)) = self.peek_at(1)
        {
            suffix = s;
            self.pass()?;
            self.pass()?;
        }
        self.has_spline |= suffix == "spline";
        if self.at_punct('=') {
            self.pass()?;
            match (is_rel, suffix) {
                (_, "connect") | (true, _) => self.value(Coerce::None, "")?,
                (false, "timeSamples") => self.time_samples(coerce_for(ty), ty)?,
                (false, "spline") => self.value(Coerce::None, "")?,
                (false, _) => {
                    let coerce = coerce_for(ty);
                    if coerce == Coerce::Text && matches!(self.peek(), Some(Tok::Path(_))) {
                        let Some(Tok::Path(p)) = self.peek().cloned() else {
                            unreachable!()
                        };
                        self.notes.push(format!(
                            "line {name_line}: `{ty} {name} = <{p}>` declares a {ty} but holds \
                             a path; usd-core keeps the path, which no {ty} read sees, so it \
                             is read as no value"
                        ));
                        self.put("None");
                    } else {
                        self.value(coerce, ty)?;
                    }
                }
            }
        }
        if self.at_punct('(') {
            self.metadata()?;
        }
        Ok(())
    }

    /// `{ time: value, … }` for attribute `ty`.
    fn time_samples(&mut self, coerce: Coerce, ty: &str) -> R<()> {
        self.expect_punct('{')?;
        loop {
            match self.peek() {
                Some(Tok::Punct('}')) => return self.pass(),
                Some(Tok::Punct(',')) => self.pass()?,
                Some(Tok::Number(_)) => {
                    self.pass()?;
                    self.expect_punct(':')?;
                    self.value(coerce, ty)?;
                }
                _ => {
                    return err(
                        self.line(),
                        format!(
                            "expected a time sample `time: value`, found {}",
                            self.describe()
                        ),
                    );
                }
            }
        }
    }

    /// A value: `None`, a scalar, a tuple `( … )`, a list `[ … ]`, a dictionary `{ … }`, or a
    /// reference/payload with its layer offset; each scalar coerced as `coerce` says.
    fn value(&mut self, coerce: Coerce, ty: &str) -> R<()> {
        match self.peek() {
            Some(Tok::Punct('[')) => {
                self.pass()?;
                loop {
                    match self.peek() {
                        Some(Tok::Punct(']')) => break self.pass()?,
                        Some(Tok::Punct(',')) => self.pass()?,
                        None => return err(self.line(), "a list `[ … ]` is not closed"),
                        _ => self.nested(|r| r.value(coerce, ty))?,
                    }
                }
            }
            Some(Tok::Punct('(')) => {
                self.pass()?;
                loop {
                    match self.peek() {
                        Some(Tok::Punct(')')) => break self.pass()?,
                        Some(Tok::Punct(',' | ';' | '=')) => self.pass()?,
                        None => return err(self.line(), "a tuple `( … )` is not closed"),
                        _ => self.nested(|r| r.value(coerce, ty))?,
                    }
                }
            }
            Some(Tok::Punct('{')) => {
                // A value in braces: a dictionary where entries declare types, else passed on.
                if matches!(self.peek_at(1), Some(Tok::Ident(_)))
                    && matches!(
                        self.peek_at(2),
                        Some(Tok::Ident(_) | Tok::Str(_) | Tok::Punct('['))
                    )
                {
                    self.nested(Self::dictionary)?;
                } else {
                    self.pass()?;
                    let mut depth = 1usize;
                    while depth > 0 {
                        match self.peek() {
                            Some(Tok::Punct('{')) => depth += 1,
                            Some(Tok::Punct('}')) => depth -= 1,
                            None => return err(self.line(), "a `{ … }` value is not closed"),
                            _ => {}
                        }
                        self.pass()?;
                    }
                }
            }
            Some(_) => {
                self.scalar(coerce, ty)?;
                // A reference or payload: `@layer@</Prim>` (the path follows the asset).
                while matches!(self.peek(), Some(Tok::Path(_)))
                    && self.pos > 0
                    && matches!(self.tokens[self.pos - 1].tok, Tok::Asset(_))
                {
                    self.pass()?;
                }
            }
            None => return err(self.line(), "expected a value, found the end of the layer"),
        }
        Ok(())
    }

    /// One scalar of a value, coerced as its declared type asks.
    fn scalar(&mut self, coerce: Coerce, ty: &str) -> R<()> {
        let Some(tok) = self.peek().cloned() else {
            return err(self.line(), "expected a value, found the end of the layer");
        };
        match (coerce, tok) {
            (Coerce::Asset, Tok::Str(s)) => self.put(&asset(&s)),
            (Coerce::Int, Tok::Number(n)) if n.contains(['.', 'e', 'E']) => {
                let Some(v) = n.parse::<f64>().ok().filter(|v| v.is_finite()) else {
                    return err(self.line(), format!("{n} is not a number"));
                };
                let t = v.trunc();
                if t.abs() >= 2f64.powi(63) {
                    return err(
                        self.line(),
                        format!("{n} does not fit the integer type {ty}"),
                    );
                }
                self.put(&format!("{}", t as i64));
            }
            (Coerce::Bool, Tok::Number(n)) => {
                let Some(v) = n.parse::<f64>().ok() else {
                    return err(self.line(), format!("{n} is not a number"));
                };
                self.put(if v != 0.0 { "true" } else { "false" });
            }
            (Coerce::Bool, Tok::Ident(w))
                if w.eq_ignore_ascii_case("true") || w.eq_ignore_ascii_case("false") =>
            {
                let v = w.eq_ignore_ascii_case("true");
                self.put(if v { "true" } else { "false" });
            }
            (_, Tok::Punct('-')) if matches!(self.peek_at(1), Some(Tok::Ident("inf"))) => {
                self.pos += 1;
                self.put("-inf");
            }
            _ => self.pass()?,
        }
        Ok(())
    }
}
