//! What changes a renderer's picture and luxeval does not apply, read so that it can be said
//! out loud instead of ignored without a word: a light's filters, its light-link and
//! shadow-link collections, shaping inputs authored without ShapingAPI, and the stage's light
//! lists (ListAPI / LightListAPI).
//!
//! luxeval evaluates a light on its own, on every receiver, unfiltered; a renderer applies all of
//! these. `luxeval lights` lists them per light and per stage, and every query command prints
//! one warning when the lights it evaluates have any of them (see [`super::Stage::unapplied`]).

use openusd::sdf;
use openusd::tf::Token;
use openusd::usd::{self as ousd, TimeCode};
use serde::Serialize;

use super::values::{authors, is_blocked, value_at};

/// `light:filters` (spec/001 "light:filters": "Use filters to modulate the effects of the light.
/// Light filters use shaders to create custom light effects").
const FILTERS: &str = "light:filters";

/// The two collections LightAPI defines on every light (spec/000 "Linking": "Linking controls
/// which geometry a light illuminates, and which geometry casts shadows from the light").
const LINK_COLLECTIONS: [&str; 2] = ["lightLink", "shadowLink"];

/// The namespace of ShapingAPI's inputs (spec/002).
const SHAPING_PREFIX: &str = "inputs:shaping:";

/// The API schemas that author a `lightList` (spec/003: "UsdLuxListAPI provides a 'light list'
/// relationship to enumerate locations of known lights in the scene"; LightListAPI is its
/// newer name).
const LIST_APIS: [&str; 2] = ["ListAPI", "LightListAPI"];

/// A light-link or shadow-link collection authored on a light that says something: it names
/// paths (`includes`, `excludes`), excludes the root (`includeRoot` authored false) or authors a
/// `membershipExpression`. luxeval does not apply it: its queries evaluate every light on every
/// receiver, and lights do not occlude (DESIGN.md §2). spec/000 "Linking".
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LinkCollection {
    /// `lightLink` (which geometry the light illuminates) or `shadowLink` (which geometry casts
    /// shadows from it): the properties are `collection:<name>:*`.
    pub name: String,
    /// `collection:<name>:includeRoot`; `true`, LightAPI's fallback, where it is not authored
    /// ("these collections have their includeRoot set to true, so that lights will illuminate
    /// and cast shadows from all objects by default", spec/000 "Linking").
    pub include_root: bool,
    /// The `includes` relationship's targets as composed (list edits across layers folded,
    /// paths mapped through references and into instances, as usd-core's `GetTargets`).
    pub includes: Vec<String>,
    /// The `excludes` relationship's targets as composed.
    pub excludes: Vec<String>,
    /// `collection:<name>:expansionRule` (`expandPrims`, its fallback, where not authored).
    pub expansion_rule: String,
    /// `collection:<name>:membershipExpression` where authored, as text.
    pub membership_expression: Option<String>,
}

impl LinkCollection {
    /// One line: what the collection says, e.g. `includeRoot false, includes /A, excludes /A/B,
    /// expansionRule explicitOnly`.
    pub fn describe(&self) -> String {
        let mut parts = vec![format!("includeRoot {}", self.include_root)];
        if !self.includes.is_empty() {
            parts.push(format!("includes {}", self.includes.join(", ")));
        }
        if !self.excludes.is_empty() {
            parts.push(format!("excludes {}", self.excludes.join(", ")));
        }
        if let Some(e) = &self.membership_expression {
            parts.push(format!("membershipExpression {e:?}"));
        }
        parts.push(format!("expansionRule {}", self.expansion_rule));
        parts.join(", ")
    }
}

/// A prim's `lightList` (ListAPI / LightListAPI, spec/003): a cache of the lights below it that
/// a renderer may read instead of traversing (`consumeAndHalt` stops its traversal there).
/// luxeval always traverses the whole stage and does not read the list: a light the list omits
/// is still evaluated, and a path it names that is no light is not.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LightList {
    /// The prim that authors it.
    pub path: String,
    /// `ListAPI` or `LightListAPI` where one is applied to the prim; `None` where `lightList`
    /// is authored on a prim without either.
    pub api: Option<String>,
    /// The `lightList` relationship's targets as composed.
    pub targets: Vec<String>,
    /// `lightList:cacheBehavior` at the query time (`consumeAndHalt`, `consumeAndContinue`,
    /// `ignore`); `None` where not authored (the schema has no fallback).
    pub cache_behavior: Option<String>,
}

/// What a light authors that luxeval does not apply, found once when the stage is opened
/// (relationships and uniform attributes do not change with time).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct LightExtras {
    pub filters: Vec<String>,
    pub link_collections: Vec<LinkCollection>,
    pub shaping_without_api: Vec<String>,
}

/// A prim found to author a light list, read at each query time.
pub(crate) struct ListSite {
    prim: ousd::Prim,
    api: Option<String>,
}

fn targets(rel: &ousd::Relationship) -> openusd::Result<Vec<String>> {
    Ok(rel.targets()?.iter().map(sdf::Path::to_string).collect())
}

/// A uniform attribute's authored value, `None` where it is not authored or blocked.
fn authored(attr: &ousd::Attribute) -> openusd::Result<Option<sdf::Value>> {
    if !attr.has_authored_value()? {
        return Ok(None);
    }
    Ok(attr.get::<sdf::Value>()?.filter(|v| !is_blocked(v)))
}

fn text(v: sdf::Value) -> Option<String> {
    match v {
        sdf::Value::Token(t) => Some(t.as_str().to_string()),
        sdf::Value::String(s) => Some(s),
        sdf::Value::PathExpression(e) => Some(e.to_string()),
        _ => None,
    }
}

impl LightExtras {
    /// `stray` (a light's inputs of schemas it does not have) without the shaping inputs said
    /// here, so that each is said once.
    pub(crate) fn not_shaping(&self, stray: Vec<String>) -> Vec<String> {
        stray
            .into_iter()
            .filter(|n| !self.shaping_without_api.contains(n))
            .collect()
    }
}

/// `light:filters`, the link collections that restrict the light and the shaping inputs
/// authored without ShapingAPI, of the light `prim` with these `applied` schemas;
/// `authored_names` is the prim's `authored_property_names()`.
///
/// A property no layer authors has no spec, so it has neither targets nor a value (openusd
/// composes both from specs): only properties among `authored_names` are asked about. A light
/// that authors none of them (most lights) costs no query here; on a stage of 30,000 plain
/// lights the five relationship and four attribute queries a light made, and a second listing
/// of its authored names, took 9 % of `luxeval lights` (BENCHMARKS.md "Big stages").
pub(crate) fn light_extras(
    prim: &ousd::Prim,
    applied: &[String],
    authored_names: &[Token],
) -> openusd::Result<LightExtras> {
    let filters = match authors(authored_names, FILTERS) {
        true => targets(&prim.relationship(FILTERS))?,
        false => Vec::new(),
    };
    let mut link_collections = Vec::new();
    for name in LINK_COLLECTIONS {
        let prop = |p: &str| format!("collection:{name}:{p}");
        let namespace = format!("collection:{name}:");
        // Nothing of the collection authored: includeRoot true, no paths, no expression,
        // which links the light to everything (the `continue` below).
        if !authored_names
            .iter()
            .any(|n| n.as_str().starts_with(&namespace))
        {
            continue;
        }
        let include_root = match authored(&prim.attribute(prop("includeRoot")))? {
            Some(sdf::Value::Bool(b)) => b,
            _ => true,
        };
        let includes = targets(&prim.relationship(prop("includes")))?;
        let excludes = targets(&prim.relationship(prop("excludes")))?;
        let membership_expression =
            authored(&prim.attribute(prop("membershipExpression")))?.and_then(text);
        // An empty list (`rel includes = []`, often written to block a weaker layer's
        // opinion) with includeRoot true links the light to everything: nothing to say.
        if include_root
            && includes.is_empty()
            && excludes.is_empty()
            && membership_expression.is_none()
        {
            continue;
        }
        let expansion_rule = authored(&prim.attribute(prop("expansionRule")))?
            .and_then(text)
            .unwrap_or_else(|| "expandPrims".to_string());
        link_collections.push(LinkCollection {
            name: name.to_string(),
            include_root,
            includes,
            excludes,
            expansion_rule,
            membership_expression,
        });
    }
    // Without ShapingAPI its inputs are not part of the light (an API schema's properties
    // belong to the prims it is applied to; DESIGN.md §2 "ShapingAPI not applied: no shaping"),
    // so a renderer that follows the schema, and luxeval, evaluate the light unshaped. A DCC's
    // spot light written this way is a common mistake.
    let shaping_without_api = if applied.iter().any(|s| s == "ShapingAPI") {
        Vec::new()
    } else {
        authored_names
            .iter()
            .map(|t| t.as_str())
            .filter(|n| n.starts_with(SHAPING_PREFIX))
            .map(str::to_string)
            .collect()
    };
    Ok(LightExtras {
        filters,
        link_collections,
        shaping_without_api,
    })
}

/// The light list `prim` authors: where ListAPI or LightListAPI is applied, or `lightList` or
/// `lightList:cacheBehavior` is authored without either. `authored_names`, the prim's
/// `authored_property_names()` where the caller has them (a light's), spares the queries of
/// properties no layer authors (see [`light_extras`]).
pub(crate) fn list_site(
    prim: &ousd::Prim,
    applied: &[String],
    authored_names: Option<&[Token]>,
) -> openusd::Result<Option<ListSite>> {
    let api = applied
        .iter()
        .find(|s| LIST_APIS.contains(&s.as_str()))
        .cloned();
    let may = |name: &str| authored_names.is_none_or(|ns| authors(ns, name));
    let authored = api.is_some()
        || (may("lightList") && prim.relationship("lightList").has_authored_targets()?)
        || (may("lightList:cacheBehavior")
            && prim
                .attribute("lightList:cacheBehavior")
                .has_authored_value()?);
    Ok(authored.then(|| ListSite {
        prim: prim.clone(),
        api,
    }))
}

/// The light list of `site` at `tc`.
pub(crate) fn light_list(site: &ListSite, tc: TimeCode) -> openusd::Result<LightList> {
    let cache_behavior = value_at(&site.prim.attribute("lightList:cacheBehavior"), tc)?
        .filter(|v| !is_blocked(v))
        .and_then(text);
    Ok(LightList {
        path: site.prim.path().to_string(),
        api: site.api.clone(),
        targets: targets(&site.prim.relationship("lightList"))?,
        cache_behavior,
    })
}
