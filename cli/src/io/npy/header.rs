//! NumPy's `.npy` header: the dict literal with `descr`, `fortran_order` and `shape`, parsed
//! strictly into the dtype, order and row count of an (N, 3) float array.

/// The longest header accepted (NumPy itself refuses more than 10 000 bytes unless told to).
pub(super) const MAX_HEADER_BYTES: usize = 65_536;

/// What the header says.
pub(super) struct Header {
    pub(super) little_endian: bool,
    /// 4 or 8.
    pub(super) item: usize,
    pub(super) fortran: bool,
    pub(super) rows: u64,
}

/// Parses NumPy's header, a Python dict literal with exactly the keys `descr`, `fortran_order`
/// and `shape`, e.g. `{'descr': '<f4', 'fortran_order': False, 'shape': (4, 3), }`.
pub(super) fn parse_header(text: &str) -> std::result::Result<Header, String> {
    let (little_endian, item, fortran, shape) = parse_dict(text)?;
    match shape.as_slice() {
        [rows, 3] => Ok(Header {
            little_endian,
            item,
            fortran,
            rows: *rows,
        }),
        _ => Err(format!(
            "shape {shape:?}: expected an array of shape (N, 3)"
        )),
    }
}

/// The dict's dtype (little-endian, item size), order and shape, of any float32/float64 array.
pub(super) fn parse_dict(text: &str) -> std::result::Result<(bool, usize, bool, Vec<u64>), String> {
    let body = text
        .trim_end_matches(['\n', ' ', '\0'])
        .trim_start()
        .strip_prefix('{')
        .and_then(|t| t.strip_suffix('}'))
        .ok_or_else(|| format!("{:?} is not a dict", clip(text)))?;
    let mut descr = None;
    let mut fortran = None;
    let mut shape: Option<Vec<u64>> = None;
    let mut rest = body.trim();
    while !rest.is_empty() {
        let (key, after) =
            string_literal(rest).ok_or_else(|| format!("bad key in {:?}", clip(text)))?;
        let after = after
            .trim_start()
            .strip_prefix(':')
            .ok_or_else(|| format!("no ':' after {key:?}"))?
            .trim_start();
        let after = match key.as_str() {
            "descr" => {
                let (v, a) = string_literal(after).ok_or("descr is not a string")?;
                descr = Some(v);
                a
            }
            "fortran_order" => {
                if let Some(a) = after.strip_prefix("True") {
                    fortran = Some(true);
                    a
                } else if let Some(a) = after.strip_prefix("False") {
                    fortran = Some(false);
                    a
                } else {
                    return Err("fortran_order is not True or False".into());
                }
            }
            "shape" => {
                let inner = after.strip_prefix('(').ok_or("shape is not a tuple")?;
                let close = inner.find(')').ok_or("shape is not a tuple")?;
                let dims = inner[..close]
                    .split(',')
                    .map(str::trim)
                    .filter(|d| !d.is_empty())
                    .map(|d| {
                        d.parse::<u64>()
                            .map_err(|_| format!("shape entry {d:?} is not a size"))
                    })
                    .collect::<std::result::Result<Vec<_>, _>>()?;
                shape = Some(dims);
                &inner[close + 1..]
            }
            other => return Err(format!("has an unexpected key {other:?}")),
        };
        let after = after.trim_start();
        rest = match after.strip_prefix(',') {
            Some(a) => a.trim_start(),
            None if after.is_empty() => after,
            None => return Err(format!("expected ',' in {:?}", clip(text))),
        };
    }
    let (Some(descr), Some(fortran), Some(shape)) = (descr, fortran, shape) else {
        return Err("lacks one of descr, fortran_order, shape".into());
    };
    let (little_endian, item) = match descr.as_str() {
        "<f4" => (true, 4),
        ">f4" => (false, 4),
        "<f8" => (true, 8),
        ">f8" => (false, 8),
        "=f4" => (cfg!(target_endian = "little"), 4),
        "=f8" => (cfg!(target_endian = "little"), 8),
        other => {
            return Err(format!(
                "dtype {other:?}: expected a float32 or float64 array"
            ));
        }
    };
    Ok((little_endian, item, fortran, shape))
}

/// A Python string literal in single or double quotes (no escapes: NumPy writes none in these
/// keys and values) and what follows it.
fn string_literal(s: &str) -> Option<(String, &str)> {
    let q = s.chars().next().filter(|c| *c == '\'' || *c == '"')?;
    let end = s[1..].find(q)? + 1;
    Some((s[1..end].to_string(), &s[end + 1..]))
}

fn clip(s: &str) -> String {
    s.chars().take(80).collect()
}
