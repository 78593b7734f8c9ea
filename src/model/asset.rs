//! Files a light references (an IES profile; textures later): where the stage resolved them to,
//! or their contents given in memory. `prepare` reads and parses them; the model only names them.

use std::sync::Arc;

/// A referenced file.
#[derive(Clone, Debug, PartialEq)]
pub struct Asset {
    /// The path as authored (for messages).
    pub authored: String,
    /// The resolved path: a file, or `/abs/pkg.usdz[inner/path]` inside a package; `None` when
    /// the path resolves to no existing file.
    pub resolved: Option<String>,
    /// The contents, when given in memory instead of a path (lights built in code, tests).
    pub bytes: Option<Arc<[u8]>>,
}

impl Asset {
    /// A file on disk (or inside a package: `/abs/pkg.usdz[inner/path]`).
    pub fn file(path: impl Into<String>) -> Self {
        let path = path.into();
        Asset {
            authored: path.clone(),
            resolved: Some(path),
            bytes: None,
        }
    }

    /// Contents given in memory; `name` is what messages call it.
    pub fn from_bytes(name: impl Into<String>, bytes: impl Into<Arc<[u8]>>) -> Self {
        Asset {
            authored: name.into(),
            resolved: None,
            bytes: Some(bytes.into()),
        }
    }

    /// What messages call the asset: the resolved path when there is one, else as authored.
    pub fn display(&self) -> &str {
        self.resolved.as_deref().unwrap_or(&self.authored)
    }
}

#[cfg(test)]
impl Asset {
    /// A `w × h` RGB PNG in memory with texels `f(x, y)`, for the unit tests' textures.
    pub(crate) fn png(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 3]) -> Asset {
        let img = image::RgbImage::from_fn(w, h, |x, y| image::Rgb(f(x, y)));
        let mut bytes = std::io::Cursor::new(Vec::new());
        img.write_to(&mut bytes, image::ImageFormat::Png)
            .expect("a PNG encodes");
        Asset::from_bytes(format!("gen-{w}x{h}.png"), bytes.into_inner())
    }
}
