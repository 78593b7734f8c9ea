//! Attribute values as usd-core resolves them: openusd's, except where openusd 0.8 gives other
//! numbers (a sample held before a block), and refusing what it cannot evaluate (splines).

use std::collections::HashMap;

use openusd::sdf;
use openusd::tf::Token;
use openusd::usd::{self as ousd, TimeCode};
use openusd_schemas::geom::Imageable;

use crate::error::{LuxError, Result};
use crate::model::Value;
use crate::model::schema::{self, Fallback};

/// openusd 0.8 parses a spline-valued attribute (`float x.spline = {...}`, USD 25.05+) but
/// resolves it as unauthored, so its value would silently be the fallback; usd-core evaluates
/// the spline. Refuse it, naming the light and attribute. (In a usdc file openusd cannot even
/// decode the spline field, which is reported the same way.)
pub(super) fn reject_spline(light: &sdf::Path, attr: &ousd::Attribute) -> Result<()> {
    let spline = match attr.has_authored_metadata("spline") {
        Ok(spline) => spline,
        Err(err) => {
            // Only a spline field fails to decode this way; anything else is a real error.
            let text = err.to_string();
            if !format!("{err:?}").contains("\"spline\"") {
                return Err(LuxError::InvalidAttribute {
                    light: light.to_string(),
                    attr: attr.name().to_string(),
                    value: "?".into(),
                    reason: format!("cannot be read: {text}"),
                });
            }
            true
        }
    };
    if spline {
        return Err(LuxError::attr(
            &light.to_string(),
            attr.name(),
            "(spline)",
            "spline-valued attributes are not supported (openusd 0.8 does not evaluate them); \
             bake the spline to timeSamples",
        ));
    }
    Ok(())
}

/// `attr`'s value at `tc` as usd-core resolves it: openusd's, except where openusd has none
/// and usd-core holds the sample before a block (see [`held_before_block`]). `None` where
/// usd-core has no value either (a blocked value).
pub(super) fn value_at(
    attr: &ousd::Attribute,
    tc: TimeCode,
) -> openusd::Result<Option<sdf::Value>> {
    if let Some(v) = attr.get_at::<sdf::Value>(tc)? {
        return Ok(Some(v));
    }
    let Some(samples) = attr.time_samples()? else {
        return Ok(None);
    };
    Ok(held_before_block(&samples, tc).map(|i| samples[i].1.clone()))
}

/// Whether `name` is among a prim's authored property names (`authored_property_names()`). A
/// property none of them names has no spec in any layer, so it has neither a value, targets,
/// nor a spline: the reader asks openusd about a light's properties only where this holds.
pub(super) fn authors(authored_names: &[Token], name: &str) -> bool {
    authored_names.iter().any(|n| n.as_str() == name)
}

pub(super) fn is_blocked(v: &sdf::Value) -> bool {
    matches!(v, sdf::Value::ValueBlock | sdf::Value::None)
}

/// The index of the sample usd-core holds at `tc` where openusd 0.8 has no value: `tc` lies
/// strictly between two samples, the upper a block and the lower not. usd-core holds the lower
/// sample up to the block; openusd treats any blocked bracket as no value.
pub(super) fn held_before_block(samples: &sdf::TimeSampleMap, tc: TimeCode) -> Option<usize> {
    if tc.is_earliest_time() {
        return None;
    }
    let t = tc.value();
    let hi = samples.iter().position(|(st, _)| *st > t)?;
    let lo = hi.checked_sub(1)?;
    (samples[lo].0 < t && !is_blocked(&samples[lo].1) && is_blocked(&samples[hi].1)).then_some(lo)
}

/// `visibility` as usd-core's `UsdGeomImageable::ComputeVisibility` resolves it: invisible when
/// the prim or any imageable ancestor reads `invisible` at `tc` (values read with
/// [`value_at`], so a sample held before a block counts as usd-core counts it).
///
/// `known` holds the answers found so far at `tc`, by prim path: the walk up from `prim` stops at
/// the first prim already answered, so lights sharing ancestors read each ancestor's
/// visibility once (a stage of n lights costs n walks of one or two steps, not n walks to the
/// root). Every prim walked is answered: a prim is visible when it is and the prim the walk
/// stopped at is. The prims are asked in the same order, bottom-up, as without `known`, and
/// a prim answered visible was asked without error, so errors and answers are the same.
///
/// `prim_authors_it` is false where the caller knows that no layer authors `visibility` on
/// `prim` itself (its authored property names lack it: no spec, so no value), which spares the
/// query; its ancestors are asked as before.
pub(super) fn visible_at(
    prim: &ousd::Prim,
    prim_authors_it: bool,
    tc: TimeCode,
    known: &mut HashMap<sdf::Path, bool>,
) -> openusd::Result<bool> {
    let mut walked: Vec<sdf::Path> = Vec::new();
    let mut visible = true;
    let mut cur = Some(prim.clone());
    while let Some(p) = cur.filter(|p| !p.path().is_abs_root()) {
        if let Some(&v) = known.get(p.path()) {
            visible = v;
            break;
        }
        // The walk's first prim is `prim` itself.
        let may_author = !walked.is_empty() || prim_authors_it;
        walked.push(p.path().clone());
        // An opinion on a prim that is not imageable (an untyped prim) is ignored, as in C++.
        if may_author
            && Imageable::from_prim(p.clone())?.is_some()
            && let Some(v) = value_at(&p.attribute("visibility"), tc)?
            && v.as_str() == Some("invisible")
        {
            visible = false;
            break;
        }
        cur = p.parent();
    }
    for path in walked {
        known.insert(path, visible);
    }
    Ok(visible)
}

/// Converts an authored value to the kind the schema table gives the attribute. USD files do
/// author other precisions than the schema's (a `double` intensity, a `color3d`), which
/// usd-core reads as they are; numbers are widened to f64 exactly.
pub(super) fn convert(light: &str, a: &schema::SchemaAttr, v: sdf::Value) -> Result<Value> {
    let shown = format!("{v:?}");
    let bad = |want: &str| {
        LuxError::attr(
            light,
            a.name,
            &shown,
            format!(
                "expected a {want} value, as the {} schema declares",
                a.schema
            ),
        )
    };
    Ok(match a.fallback {
        // Any floating-point precision is read as usd-core reads it; an integer type is not a
        // precision of the schema's type (usd-core's typed Get fails on it), so it is refused
        // rather than converted silently.
        Fallback::Float(_) => Value::Float(match v {
            sdf::Value::Bool(_)
            | sdf::Value::Uchar(_)
            | sdf::Value::Int(_)
            | sdf::Value::Uint(_)
            | sdf::Value::Int64(_)
            | sdf::Value::Uint64(_) => return Err(bad("floating-point")),
            other => other.cast::<f64>().map_err(|_| bad("floating-point"))?,
        }),
        Fallback::Bool(_) => Value::Bool(match v {
            sdf::Value::Bool(b) => b,
            // usda allows 0/1 for bools; openusd coerces them already, this is a safety net.
            other => match other.cast::<i64>() {
                Ok(0) => false,
                Ok(1) => true,
                _ => return Err(bad("bool")),
            },
        }),
        Fallback::Color(_) => Value::Color(match v {
            sdf::Value::Vec3i(_) => return Err(bad("color3f (floating-point)")),
            other => other.cast::<[f64; 3]>().map_err(|_| bad("color3f"))?,
        }),
        Fallback::Token(_) => Value::Token(match v {
            sdf::Value::Token(t) => t.as_str().to_string(),
            sdf::Value::String(s) => s,
            _ => return Err(bad("token")),
        }),
        Fallback::Asset => match v {
            sdf::Value::AssetPath(p) => Value::Asset {
                authored: p.as_str().to_string(),
                resolved: p.resolved_path().map(str::to_string),
            },
            _ => return Err(bad("asset")),
        },
    })
}
