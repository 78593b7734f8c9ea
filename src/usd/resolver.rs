//! The resolver every stage file is read through: openusd's filesystem resolver, refusing what
//! is not a regular file, exceeds the size limit, or (usda text) nests braces too deep, and
//! handing openusd every text layer as luxeval's own reader reads it ([`super::usda`]).

use std::cell::RefCell;
use std::io::{self, Read};
use std::path::{Path, PathBuf};
use std::rc::Rc;

use openusd::ar;

use super::usda;
use crate::limits::{ENV_MAX_FILE_BYTES, ENV_MAX_PRIM_DEPTH, Limits, raise_hint};

/// openusd's filesystem resolver, refusing to open what is not a regular file (an endless device
/// would be read without end) or is larger than [`Limits::max_file_bytes`].
/// Text layers are also refused when their braces nest deeper than a namespace within the
/// depth limit needs: openusd's text parser recurses per level and takes time quadratic in the
/// depth (100 s for 10 000 levels in a debug build), before the walk could count prims.
#[derive(Clone)]
pub(super) struct LimitedResolver {
    inner: Rc<ar::DefaultResolver>,
    max_bytes: u64,
    max_braces: u64,
    /// Every file opened through this resolver (and its clones), each once: the files a
    /// command reads through the stage, which no output may overwrite.
    opened: Rc<RefCell<Vec<PathBuf>>>,
    /// What the text reader read differently from how it was written, each once, naming the
    /// layer and line.
    notes: Rc<RefCell<Vec<String>>>,
    noted: Rc<RefCell<std::collections::HashSet<String>>>,
    /// Whether a layer read so far may hold a spline: a text layer where a property authors
    /// one, and every asset that is not text (a crate file, a package), whose fields luxeval
    /// does not read itself.
    may_hold_splines: Rc<std::cell::Cell<bool>>,
}

/// Text luxeval's reader cannot read: rendered as openusd renders its parse errors
/// (`error: why` and ` --> file:line:col`), so every path that reports a layer's failure finds
/// the line the same way.
#[derive(Debug)]
pub(super) struct LayerSyntaxError {
    pub file: String,
    pub error: usda::SyntaxError,
}

impl std::fmt::Display for LayerSyntaxError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "error: {}\n --> {}:{}:1",
            self.error.reason, self.file, self.error.line
        )
    }
}

impl std::error::Error for LayerSyntaxError {}

impl LimitedResolver {
    pub(super) fn new(limits: &Limits) -> Self {
        LimitedResolver {
            inner: Rc::new(ar::DefaultResolver::new()),
            max_bytes: limits.max_file_bytes,
            // A prim is one level of braces; a variant set adds two and metadata dictionaries
            // a few more: twice the depth limit and some room is more than a legal stage uses.
            max_braces: limits.max_prim_depth.saturating_mul(2).saturating_add(64),
            opened: Rc::default(),
            notes: Rc::default(),
            noted: Rc::default(),
            may_hold_splines: Rc::default(),
        }
    }

    /// Whether a layer opened so far may hold a spline (see `values::reject_spline`): false
    /// only when every one was text without a `.spline` property, so that no attribute of the
    /// stage has a spline field to ask about.
    pub(super) fn may_hold_splines(&self) -> bool {
        self.may_hold_splines.get()
    }

    /// What the text reader read differently from how it was written, in the order found.
    pub(super) fn notes(&self) -> Vec<String> {
        self.notes.borrow().clone()
    }

    /// The files opened so far, in the order first opened.
    pub(super) fn opened(&self) -> Vec<PathBuf> {
        self.opened.borrow().clone()
    }

    /// The file (a package for a package-relative path) behind `resolved`, checked.
    fn check(&self, resolved: &ar::ResolvedPath) -> io::Result<()> {
        let text = resolved.to_str().unwrap_or_default();
        let file = match ar::split_package_relative_path_outer(text) {
            Some((package, _)) if ar::is_package_relative_path(text) => package,
            _ => text.to_string(),
        };
        check_file(Path::new(&file), self.max_bytes)?;
        let mut opened = self.opened.borrow_mut();
        if !opened.iter().any(|f| f.as_os_str() == file.as_str()) {
            opened.push(PathBuf::from(file));
        }
        Ok(())
    }
}

/// A layer file must be a regular file no larger than `max_bytes`.
pub(super) fn check_file(path: &Path, max_bytes: u64) -> io::Result<()> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} is not a regular file", path.display()),
        ));
    }
    if meta.len() > max_bytes {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "{}: {} bytes exceed the limit of {max_bytes} bytes ({})",
                path.display(),
                meta.len(),
                raise_hint(ENV_MAX_FILE_BYTES)
            ),
        ));
    }
    Ok(())
}

impl ar::Resolver for LimitedResolver {
    fn create_identifier(&self, asset_path: &str, anchor: Option<&ar::ResolvedPath>) -> String {
        self.inner.create_identifier(asset_path, anchor)
    }
    fn resolve(&self, asset_path: &str) -> Option<ar::ResolvedPath> {
        self.inner.resolve(asset_path)
    }
    fn resolve_for_new_asset(&self, asset_path: &str) -> Option<ar::ResolvedPath> {
        self.inner.resolve_for_new_asset(asset_path)
    }
    fn open_asset(&self, resolved_path: &ar::ResolvedPath) -> io::Result<Box<dyn ar::Asset>> {
        self.check(resolved_path)?;
        let mut asset = self.inner.open_asset(resolved_path)?;
        let mut bytes = Vec::new();
        asset.read_to_end(&mut bytes)?;
        // Text is recognised by its cookie, as openusd does (a `.usd` may hold either).
        if bytes.trim_ascii_start().starts_with(b"#usda") {
            let depth = brace_depth(&bytes);
            if depth > self.max_braces {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidData,
                    format!(
                        "{resolved_path}: braces nest {depth} deep, more than a namespace within \
                         the limit on prim depth needs ({})",
                        raise_hint(ENV_MAX_PRIM_DEPTH)
                    ),
                ));
            }
            let text = std::str::from_utf8(&bytes).map_err(|e| {
                io::Error::new(
                    io::ErrorKind::InvalidData,
                    format!("{resolved_path}: a text layer must be UTF-8: {e}"),
                )
            })?;
            let read = usda::canonical(text, self.max_braces as usize).map_err(|error| {
                io::Error::new(
                    io::ErrorKind::InvalidData,
                    LayerSyntaxError {
                        file: resolved_path.to_string(),
                        error,
                    },
                )
            })?;
            // A layer read twice (the safety checks, then composition) notes the same once;
            // a set keeps that linear in the notes.
            let (mut notes, mut seen) = (self.notes.borrow_mut(), self.noted.borrow_mut());
            for n in read.notes {
                let n = format!("{resolved_path}, {n}");
                if seen.insert(n.clone()) {
                    notes.push(n);
                }
            }
            if read.has_spline {
                self.may_hold_splines.set(true);
            }
            bytes = read.text.into_bytes();
        } else {
            self.may_hold_splines.set(true);
        }
        Ok(Box::new(io::Cursor::new(ar::AssetBuffer::Owned(bytes))))
    }
    fn get_extension<'a>(&self, asset_path: &'a str) -> &'a str {
        self.inner.get_extension(asset_path)
    }
    fn is_context_dependent_path(&self, asset_path: &str) -> bool {
        self.inner.is_context_dependent_path(asset_path)
    }
    fn in_memory_identifier<'a>(&self, asset_path: &'a str) -> std::borrow::Cow<'a, str> {
        self.inner.in_memory_identifier(asset_path)
    }
    fn get_asset_info(&self, asset_path: &str, resolved_path: &ar::ResolvedPath) -> ar::AssetInfo {
        self.inner.get_asset_info(asset_path, resolved_path)
    }
    fn get_modification_timestamp(
        &self,
        asset_path: &str,
        resolved_path: &ar::ResolvedPath,
    ) -> Option<std::time::SystemTime> {
        self.inner
            .get_modification_timestamp(asset_path, resolved_path)
    }
    fn identity(&self) -> String {
        self.inner.identity()
    }
    fn cache_id(&self) -> Option<u64> {
        self.inner.cache_id()
    }
}

/// The deepest nesting of `{` in usda text, outside strings, asset paths and comments.
fn brace_depth(text: &[u8]) -> u64 {
    let (mut depth, mut max, mut i) = (0u64, 0u64, 0usize);
    // Skips to just past the next `close` at or after `from` (or to the end).
    let skip = |from: usize, close: &[u8]| {
        text[from..]
            .windows(close.len())
            .position(|w| w == close)
            .map_or(text.len(), |k| from + k + close.len())
    };
    while i < text.len() {
        i = match text[i] {
            b'{' => {
                depth += 1;
                max = max.max(depth);
                i + 1
            }
            b'}' => {
                depth = depth.saturating_sub(1);
                i + 1
            }
            b'#' => skip(i, b"\n"),
            b'@' if text[i..].starts_with(b"@@@") => skip(i + 3, b"@@@"),
            b'@' => skip(i + 1, b"@"),
            q @ (b'"' | b'\'') => {
                if text[i..].starts_with(&[q, q, q]) {
                    skip(i + 3, &[q, q, q])
                } else {
                    // A short string ends at the next unescaped quote or at the line's end.
                    let mut j = i + 1;
                    while j < text.len() && text[j] != q && text[j] != b'\n' {
                        j += if text[j] == b'\\' { 2 } else { 1 };
                    }
                    j + 1
                }
            }
            _ => i + 1,
        };
    }
    max
}

#[cfg(test)]
mod tests {
    use super::brace_depth;

    #[test]
    fn brace_depth_skips_strings_assets_and_comments() {
        assert_eq!(
            brace_depth(b"#usda 1.0\ndef \"a\" {\n def \"b\" {\n }\n}\n"),
            2
        );
        // Braces inside strings, asset paths and comments do not nest prims.
        let text = b"#usda 1.0 {{{\ndef \"a\" (doc = \"{{{{\" ) {\n string s = '''{{{\n{{'''\n \
                     asset a = @x{y}.usda@\n asset b = @@@{{{@@@\n # {{{{\n}\n";
        assert_eq!(brace_depth(text), 1);
        // An unterminated string stops at its line's end.
        assert_eq!(brace_depth(b"#usda 1.0\nstring s = \"{{\n{ {\n"), 2);
    }
}
