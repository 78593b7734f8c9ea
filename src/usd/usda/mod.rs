//! luxeval's reader of `.usda` text: the `sdf` text grammar with every lexical form and value
//! coercion that Pixar's usd-core accepts, handed to openusd's composition in the one form
//! openusd's own text parser reads (docs/INPUTS.md "What the USD reader accepts").
//!
//! openusd 0.8 registers its formats statically and reads layers only through the resolver, so
//! this reader sits in [`super::resolver::LimitedResolver::open_asset`]: a text layer is lexed and
//! parsed here, and what is passed on is the same layer written canonically, token for token,
//! on the same lines (openusd's errors keep naming the author's line). What usd-core accepts and
//! openusd 0.8 does not, and what this reader does with it (usd-core's behaviour, checked with
//! its `Sdf.Layer.ImportFromString` / `ExportToString`, release 0.26):
//!
//! | written | usd-core reads | passed on |
//! | --- | --- | --- |
//! | `// comment` (to the line's end), `/* … */` | comments | nothing |
//! | `0.`, `.5`, `-.5e-1`, `1.e5` | the number | `0`, `0.5`, `-0.5e-1`, `1e5` |
//! | `asset a = "t.png"`, `asset[] b = ["x"]` | asset paths | `@t.png@` |
//! | `int x = 5.0`, `int2 v = (1.5, 2.)`, `int x = -5.7` | truncated toward zero | `5`, `(1, 2)`, `-5` |
//! | `bool b = 2`, `bool b = -1`, `bool b = 0.5` | `true` (non-zero) | `true` |
//! | `active = False`, `active = 0` (any case) | the bool | `false` |
//! | `config token info:id` | uniform (`config` is the old spelling) | `uniform` |
//! | `token t = </A/B>` (a path where a token or string is declared) | a path, which no typed `Get` of the attribute reads | no value, and a warning |
//! | `"""…"""`, `'''…'''` over several lines | the string | one `"…"` with escapes |
//!
//! Everything else is passed on as written; what openusd then refuses is refused with its line.

use std::fmt;

mod lex;
mod read;

/// A text layer as openusd reads it, and what was read differently from how it was written.
#[derive(Debug)]
pub(super) struct Canonical {
    pub text: String,
    /// One line per value usd-core keeps but no typed read sees (see the module table).
    pub notes: Vec<String>,
    /// Whether some property authors a spline (`name.spline = {...}`): the only way a text
    /// layer holds one, which `values::reject_spline` refuses.
    pub has_spline: bool,
}

/// Text this reader cannot read, at a 1-based line.
#[derive(Debug, PartialEq)]
pub(super) struct SyntaxError {
    pub line: usize,
    pub reason: String,
}

impl fmt::Display for SyntaxError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}: {}", self.line, self.reason)
    }
}

type R<T> = std::result::Result<T, SyntaxError>;

/// Reads `text` (a whole `.usda` layer) and writes it back canonically. Prims, dictionaries,
/// lists and tuples nested deeper than `max_nesting` are refused (the reader recurses per level).
pub(super) fn canonical(text: &str, max_nesting: usize) -> R<Canonical> {
    read::Reader::new(text, lex::lex(text)?, max_nesting).read()
}

fn err<T>(line: usize, reason: impl Into<String>) -> R<T> {
    Err(SyntaxError {
        line,
        reason: reason.into(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn canon(text: &str) -> String {
        canonical(text, 64).unwrap().text
    }

    #[test]
    fn lines_are_kept_and_comments_dropped() {
        let text = "#usda 1.0\n// a comment\n/* a\nblock */ def Xform \"A\" // tail\n{\n    double d = .5\n}\n";
        let out = canon(text);
        assert_eq!(out.lines().nth(3).unwrap().trim(), "def Xform \"A\"");
        assert_eq!(out.lines().nth(5).unwrap().trim(), "double d = 0.5");
        assert!(!out.contains("comment") && !out.contains("tail"));
    }

    #[test]
    fn declared_types_coerce_values_as_usd_core_does() {
        let text = "#usda 1.0\ndef Xform \"A\" (\n    active = False\n    customData = {\n        int n = 5.0\n        asset a = \"x.png\"\n    }\n)\n{\n    config token info:id = \"x\"\n    asset a = \"t.png\"\n    asset[] b = [\"x.png\", @y.png@]\n    int i = -5.7\n    int2 v = (1.5, 2.)\n    bool b1 = 2\n    bool b2 = True\n    float f.timeSamples = { 1.: .5, 2: 1. }\n    int n.timeSamples = { 1: 2.5 }\n}\n";
        let out = canon(text);
        for want in [
            "active = false",
            "int n = 5",
            "asset a = @x.png@",
            "uniform token info:id = \"x\"",
            "asset a = @t.png@",
            "asset[] b = [@x.png@, @y.png@]",
            "int i = -5",
            "int2 v = (1, 2)",
            "bool b1 = true",
            "bool b2 = true",
            "float f.timeSamples = { 1: 0.5, 2: 1 }",
            "int n.timeSamples = { 1: 2 }",
        ] {
            assert!(out.contains(want), "{want:?} not in\n{out}");
        }
    }

    /// `has_spline` is what lets the stage skip asking every attribute about splines: true
    /// for a `.spline` property anywhere (a prim's, a nested prim's), false for a layer whose
    /// other suffixes (`.timeSamples`, `.connect`) or names merely mention splines.
    #[test]
    fn a_spline_property_is_noticed() {
        let spline = "#usda 1.0\ndef Xform \"A\"\n{\n    def Xform \"B\"\n    {\n        \
                      float f.spline = {\n            bezier,\n            1: 0,\n        }\n    }\n}\n";
        assert!(canonical(spline, 64).unwrap().has_spline);
        let none = "#usda 1.0\ndef Xform \"A\" (\n    doc = \"f.spline = {}\"\n)\n{\n    \
                    float spline.timeSamples = { 1: 0.5 }\n    float g.connect = </A.spline>\n}\n";
        let c = canonical(none, 64).unwrap();
        assert!(!c.has_spline, "{}", c.text);
    }

    #[test]
    fn a_path_declared_as_a_token_is_no_value_with_a_note() {
        let c = canonical(
            "#usda 1.0\ndef Xform \"A\"\n{\n    token outputs:x = </A/B>\n}\n",
            64,
        )
        .unwrap();
        assert!(c.text.contains("token outputs:x = None"), "{}", c.text);
        assert_eq!(c.notes.len(), 1);
        assert!(c.notes[0].starts_with("line 4:"), "{}", c.notes[0]);
    }

    #[test]
    fn strings_and_assets_of_every_form() {
        let c = canon(
            "#usda 1.0\n(\n    doc = \"\"\"a \"q\" \"\"b\"\"\nline\"\"\"\n)\ndef Xform \"A\"\n{\n    asset a = @@@a@b.png@@@\n    string s = 'it\\'s'\n    string t = \"tab\\there\"\n}\n",
        );
        assert!(c.contains(r#"doc = "a \"q\" \"\"b\"\"\nline""#), "{c}");
        assert!(c.contains(r#"string s = "it's""#), "{c}");
        // The string over two lines is written on one: what follows keeps its line.
        assert_eq!(c.lines().nth(4).unwrap().trim(), ")");
        assert!(c.contains("asset a = @@@a@b.png@@@"), "{c}");
        assert!(c.contains(r#""tab\there""#), "{c}");
    }

    #[test]
    fn errors_name_the_line() {
        let e = canonical("#usda 1.0\ndef Xform \"A\"\n{\n    float f = \"x\n}\n", 64).unwrap_err();
        assert_eq!(e.line, 4);
        let e = canonical("#usda 1.0\ndef Xform \"A\"\n{\n    float f = 1\n", 64).unwrap_err();
        assert!(e.reason.contains("not closed"), "{e}");
        assert!(canonical("def Xform \"A\" {}", 64).is_err());
        let e = canonical("#usda 1.0\ndef Xform \"A\"\n{\n    float f = $\n}\n", 64).unwrap_err();
        assert_eq!(e.line, 4);
    }

    #[test]
    fn nesting_deeper_than_allowed_is_refused_not_recursed() {
        let deep = format!(
            "#usda 1.0\ndef Xform \"A\"\n{{\n    float[] f = {}1{}\n}}\n",
            "[".repeat(100_000),
            "]".repeat(100_000)
        );
        let e = canonical(&deep, 64).unwrap_err();
        assert!(e.reason.contains("nest more than 64"), "{e}");
        assert_eq!(e.line, 4);
        let prims = format!(
            "#usda 1.0\n{}{}",
            "def \"A\" {\n".repeat(70),
            "}\n".repeat(70)
        );
        assert!(canonical(&prims, 64).is_err());
        assert!(canonical(&prims, 80).is_ok());
    }

    /// Every text layer of the repository's test data that openusd 0.8 reads on its own gives
    /// the same specs, field for field, when read through this reader: the canonical text
    /// changes nothing openusd already read (the same check over OpenUSD's 2,431 `testenv`
    /// text layers of releases 24.08 and 24.11 is in docs/INPUTS.md).
    #[test]
    fn layers_openusd_reads_are_read_the_same_through_this_reader() {
        use openusd::usda::parser::Parser;
        let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
        let mut stack = vec![data];
        let (mut compared, mut files) = (0, Vec::new());
        while let Some(dir) = stack.pop() {
            for e in std::fs::read_dir(&dir).unwrap() {
                let p = e.unwrap().path();
                if p.is_dir() {
                    stack.push(p);
                } else if p.extension().is_some_and(|x| x == "usda" || x == "usd") {
                    files.push(p);
                }
            }
        }
        files.sort();
        for p in files {
            let Ok(text) = std::fs::read_to_string(&p) else {
                continue;
            };
            // Deeper than a test thread's stack lets openusd's parser go: refused before it.
            let Ok(c) = canonical(&text, 200) else {
                continue;
            };
            let Ok(before) = Parser::new(&text).parse() else {
                continue;
            };
            let after = Parser::new(&c.text)
                .parse()
                .unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            assert_eq!(before.len(), after.len(), "{}", p.display());
            for (path, spec) in &before {
                let other = &after[path];
                assert_eq!(spec.ty, other.ty, "{} {path}", p.display());
                // NaN is not equal to itself; its text is.
                let same = spec.fields == other.fields
                    || format!("{:?}", spec.fields) == format!("{:?}", other.fields);
                assert!(
                    same,
                    "{} {path}: {:?} vs {:?}",
                    p.display(),
                    spec.fields,
                    other.fields
                );
            }
            compared += 1;
        }
        assert!(compared > 50, "only {compared} layers compared");
    }
}
