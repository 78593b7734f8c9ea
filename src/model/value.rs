//! Resolved attribute values: what a stage authors (or the schema table supplies) for one input
//! of one light, typed as the schema table types the attribute's fallback.

use serde::Serialize;

use super::schema::Fallback;

/// A resolved input value, typed as the schema table types its fallback.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Value {
    Float(f64),
    Bool(bool),
    Color([f64; 3]),
    Token(String),
    /// An `asset` input: the path as authored (empty when unauthored) and the path it resolves
    /// to, anchored to the layer that authored it (`/abs/pkg.usdz[inner/path]` inside a usdz);
    /// `None` where it resolves to no existing file.
    Asset {
        authored: String,
        resolved: Option<String>,
    },
}

/// One input of a light: its resolved value and whether any layer authors it (a default or time
/// samples); an unauthored input holds the schema fallback of [`super::schema`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Input {
    pub name: String,
    pub value: Value,
    pub authored: bool,
}

/// Prints a value that came from a USD `float` as that float's shortest form (0.95, not
/// 0.949999988079071); genuine doubles print in full.
struct Short(f64);

impl std::fmt::Display for Short {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let single = self.0 as f32;
        if single as f64 == self.0 {
            write!(f, "{single}")
        } else {
            write!(f, "{}", self.0)
        }
    }
}

impl std::fmt::Display for Value {
    /// The value as `luxeval lights` prints it.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Float(v) => write!(f, "{}", Short(*v)),
            Value::Bool(v) => write!(f, "{v}"),
            Value::Color([r, g, b]) => write!(f, "({}, {}, {})", Short(*r), Short(*g), Short(*b)),
            Value::Token(t) => write!(f, "{t:?}"),
            Value::Asset { authored, .. } if authored.is_empty() => write!(f, "@@"),
            Value::Asset {
                authored,
                resolved: Some(r),
            } => write!(f, "@{authored}@ -> {r}"),
            Value::Asset {
                authored,
                resolved: None,
            } => write!(f, "@{authored}@ (unresolved)"),
        }
    }
}

impl Value {
    /// The value of a schema fallback (an unauthored attribute).
    pub fn fallback(f: Fallback) -> Value {
        match f {
            Fallback::Float(v) => Value::Float(v),
            Fallback::Bool(v) => Value::Bool(v),
            Fallback::Color(v) => Value::Color(v),
            Fallback::Token(v) => Value::Token(v.to_string()),
            Fallback::Asset => Value::Asset {
                authored: String::new(),
                resolved: None,
            },
        }
    }
}
