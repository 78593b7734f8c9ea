//! Reading a referenced file by its resolved path, also from inside a `.usdz` package:
//! openusd resolves a package-relative asset to `/abs/pkg.usdz[inner/path]` (nested packages:
//! `/abs/a.usdz[b.usdz[c.ies]]`). A usdz is a zip archive whose entries are stored
//! uncompressed (the USDZ specification), so its members are read here directly from the
//! archive's central directory.

use std::io::{Error, ErrorKind, Read};
use std::path::Path;

/// The largest file luxeval reads as an asset (IES profiles are kilobytes; an 8k × 4k float
/// EXR is ~400 MiB).
pub const MAX_ASSET_BYTES: u64 = 1 << 30;

/// The bytes of the asset at `resolved` (a file, or a package member).
pub fn read(resolved: &str) -> std::io::Result<Vec<u8>> {
    match split_package(resolved) {
        Some((package, inner)) => {
            let archive = read(package)?;
            member(&archive, inner, package)
        }
        None => read_file(Path::new(resolved)),
    }
}

/// `name` resolved beside `resolved`: in the same directory, or the same package folder.
pub fn sibling(resolved: &str, name: &str) -> String {
    if Path::new(name).is_absolute() {
        return name.to_string();
    }
    match split_package(resolved) {
        Some((package, inner)) => format!("{package}[{}]", sibling(inner, name)),
        None => match Path::new(resolved).parent() {
            Some(dir) if !dir.as_os_str().is_empty() => dir.join(name).display().to_string(),
            _ => name.to_string(),
        },
    }
}

/// The file on disk that holds the asset at `resolved`: the path itself, or the outermost
/// package of a package member (`/abs/a.usdz[b.usdz[c.ies]]` → `/abs/a.usdz`).
pub fn file_of(resolved: &str) -> &Path {
    match split_package(resolved) {
        Some((package, _)) => Path::new(package),
        None => Path::new(resolved),
    }
}

/// `pkg.usdz[inner]` → (`pkg.usdz`, `inner`), the inner part possibly a nested package path.
fn split_package(path: &str) -> Option<(&str, &str)> {
    let inner = path.strip_suffix(']')?;
    let open = inner.find('[')?;
    Some((&inner[..open], &inner[open + 1..]))
}

/// A file's bytes: the one way luxeval opens an asset file (IES profiles, their TILT files,
/// textures, `.usdz` packages holding them). The path (after symbolic links) must be a regular
/// file of at most [`MAX_ASSET_BYTES`], both checked from its metadata before it is opened, so
/// that a FIFO without a writer cannot block the open and a device (`/dev/zero`) is refused
/// before a byte is read; the read itself stops past the limit too (a file that grows while it
/// is read).
pub fn read_file(path: &Path) -> std::io::Result<Vec<u8>> {
    let meta = std::fs::metadata(path)?;
    if meta.is_dir() {
        return Err(Error::new(ErrorKind::IsADirectory, "is a directory"));
    }
    if !meta.is_file() {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            "is not a regular file (a FIFO, socket or device), so it is not read",
        ));
    }
    let too_large = || {
        Error::new(
            ErrorKind::InvalidData,
            format!("larger than the {MAX_ASSET_BYTES}-byte limit on assets"),
        )
    };
    if meta.len() > MAX_ASSET_BYTES {
        return Err(too_large());
    }
    let file = std::fs::File::open(path)?;
    let mut bytes = Vec::new();
    file.take(MAX_ASSET_BYTES + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_ASSET_BYTES {
        return Err(too_large());
    }
    Ok(bytes)
}

fn u16_at(b: &[u8], i: usize) -> Option<usize> {
    Some(u16::from_le_bytes(b.get(i..i + 2)?.try_into().ok()?) as usize)
}

fn u32_at(b: &[u8], i: usize) -> Option<usize> {
    Some(u32::from_le_bytes(b.get(i..i + 4)?.try_into().ok()?) as usize)
}

/// The stored member `inner` of the zip archive `archive` (nested packages recurse).
fn member(archive: &[u8], inner: &str, package: &str) -> std::io::Result<Vec<u8>> {
    let bad = |why: &str| Error::new(ErrorKind::InvalidData, format!("{package}: {why}"));
    let (name, rest) = match split_package(inner) {
        Some((nested, rest)) => (nested, Some(rest)),
        None => (inner, None),
    };
    // End of central directory: the last "PK\5\6" record (it may be followed by a comment).
    let eocd = (0..archive.len().saturating_sub(21))
        .rev()
        .take(65_557)
        .find(|&i| archive[i..].starts_with(b"PK\x05\x06"))
        .ok_or_else(|| bad("not a zip archive (no end of central directory)"))?;
    let entries = u16_at(archive, eocd + 10).ok_or_else(|| bad("truncated"))?;
    let mut at = u32_at(archive, eocd + 16).ok_or_else(|| bad("truncated"))?;
    for _ in 0..entries {
        let field = |off: usize, size: usize| -> std::io::Result<usize> {
            match size {
                2 => u16_at(archive, at + off),
                _ => u32_at(archive, at + off),
            }
            .ok_or_else(|| bad("truncated central directory"))
        };
        if !archive
            .get(at..)
            .is_some_and(|b| b.starts_with(b"PK\x01\x02"))
        {
            return Err(bad("corrupt central directory"));
        }
        let (method, size, name_len) = (field(10, 2)?, field(20, 4)?, field(28, 2)?);
        let (extra_len, comment_len, local) = (field(30, 2)?, field(32, 2)?, field(42, 4)?);
        let entry_name = archive
            .get(at + 46..at + 46 + name_len)
            .ok_or_else(|| bad("truncated central directory"))?;
        if entry_name == name.as_bytes() {
            if method != 0 {
                return Err(bad(&format!(
                    "{name} is compressed (method {method}); usdz members are stored uncompressed"
                )));
            }
            let lname = u16_at(archive, local + 26).ok_or_else(|| bad("truncated"))?;
            let lextra = u16_at(archive, local + 28).ok_or_else(|| bad("truncated"))?;
            let start = local + 30 + lname + lextra;
            let data = archive
                .get(start..start.saturating_add(size))
                .ok_or_else(|| bad(&format!("{name} runs past the end of the archive")))?;
            return match rest {
                Some(rest) => member(data, rest, &format!("{package}[{name}]")),
                None => Ok(data.to_vec()),
            };
        }
        at += 46 + name_len + extra_len + comment_len;
    }
    Err(Error::new(
        ErrorKind::NotFound,
        format!("{package} has no member {name}"),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stored zip archive written by hand, one member.
    fn zip_with(name: &str, data: &[u8]) -> Vec<u8> {
        let mut z = Vec::new();
        let local = 0u32;
        z.extend(b"PK\x03\x04");
        z.extend([20, 0, 0, 0, 0, 0, 0, 0, 0, 0]); // version, flags, method 0, time, date
        z.extend([0u8; 4]); // crc (not checked)
        z.extend((data.len() as u32).to_le_bytes());
        z.extend((data.len() as u32).to_le_bytes());
        z.extend((name.len() as u16).to_le_bytes());
        z.extend(0u16.to_le_bytes());
        z.extend(name.as_bytes());
        z.extend(data);
        let cd = z.len() as u32;
        z.extend(b"PK\x01\x02");
        z.extend([20, 0, 20, 0, 0, 0, 0, 0, 0, 0, 0, 0]); // versions, flags, method 0, time, date
        z.extend([0u8; 4]);
        z.extend((data.len() as u32).to_le_bytes());
        z.extend((data.len() as u32).to_le_bytes());
        z.extend((name.len() as u16).to_le_bytes());
        z.extend([0u8; 12]); // extra, comment, disk, attributes
        z.extend(local.to_le_bytes());
        z.extend(name.as_bytes());
        let cd_size = z.len() as u32 - cd;
        z.extend(b"PK\x05\x06");
        z.extend([0u8; 4]);
        z.extend(1u16.to_le_bytes());
        z.extend(1u16.to_le_bytes());
        z.extend(cd_size.to_le_bytes());
        z.extend(cd.to_le_bytes());
        z.extend(0u16.to_le_bytes());
        z
    }

    #[test]
    fn members_of_packages_and_nested_packages() {
        let dir = tempfile::tempdir().unwrap();
        let inner = zip_with("tex/a.ies", b"TILT=NONE\n");
        let outer = zip_with("inner.usdz", &inner);
        let path = dir.path().join("outer.usdz");
        std::fs::write(&path, &outer).unwrap();
        let p = path.display().to_string();
        assert_eq!(
            read(&format!("{p}[inner.usdz[tex/a.ies]]")).unwrap(),
            b"TILT=NONE\n"
        );
        let e = read(&format!("{p}[inner.usdz[tex/b.ies]]")).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::NotFound);
        assert!(e.to_string().contains("tex/b.ies"), "{e}");
        let e = read(&format!("{p}[junk]")).unwrap_err();
        assert!(e.to_string().contains("no member junk"), "{e}");
        std::fs::write(&path, b"not a zip").unwrap();
        assert!(read(&format!("{p}[x]")).is_err());
    }

    #[test]
    fn siblings_stay_in_their_package() {
        assert_eq!(sibling("/a/b/c.ies", "t.tlt"), "/a/b/t.tlt");
        assert_eq!(sibling("/a/p.usdz[d/c.ies]", "t.tlt"), "/a/p.usdz[d/t.tlt]");
        assert_eq!(sibling("c.ies", "t.tlt"), "t.tlt");
    }
}
