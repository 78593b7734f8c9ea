//! What luxeval checks before openusd composes a stage (docs/INPUTS.md "Stages"): the layers are
//! read on their own (openusd's `sdf` layer API reads specs without composing), and the graph of
//! prims and composition arcs they author is walked here, iteratively, with its own cycle
//! detection and limits. openusd's composition engine recurses and counts differently: it
//! overflows the stack on some cycles (a class that inherits itself) and on deep namespaces,
//! abandons a legal chain of ≥ 99 arcs as if it were a cycle (dropping its light silently), and
//! composes whatever number of prims a few small layers multiply out to. Refusing those here,
//! naming the file and the prim, is what keeps a bad stage from aborting or exhausting memory.
//!
//! Every file read (here and by openusd, layers and packages alike) goes through
//! [`LimitedResolver`], which refuses what is not a regular file or exceeds the size limit.
//!
//! The stage is opened before the walk: opening only reads the root layer stack (the root and
//! its sublayers, through that resolver, whose brace-depth check guards the text parser) and
//! composes nothing, so the walk takes those layers from the stage instead of parsing them a
//! second time (on a 100,000-light layer, parsing and freeing it again was most of the
//! walk's time). Layers the stack does not hold (references, payloads) are read here.
//!
//! The walk is an upper bound, not a second composition engine: every variant of every variant
//! set counts, arcs to the same prim are counted once per arc, implied inherits are ignored.
use std::collections::{HashMap, HashSet};
use std::path::Path;

use openusd::ar::{self, Resolver};
use openusd::sdf;
use openusd::usd as ousd;

use super::resolver::LimitedResolver;
use crate::error::{LuxError, Result};
use crate::limits::{ENV_MAX_PRIM_DEPTH, ENV_MAX_PRIMS, Limits, MAX_ARC_DEPTH, raise_hint};

/// One composition arc as authored: its kind and the site it targets.
#[derive(Clone, Debug)]
struct Arc {
    kind: &'static str,
    /// The layer stack (by its root layer's identifier) and prim it targets.
    stack: String,
    path: sdf::Path,
}

/// What one layer authors, by prim path with variant selections stripped (a variant's children
/// and arcs belong to the prim whose variant it is).
#[derive(Default)]
struct LayerSpecs {
    /// Display name (the identifier).
    name: String,
    sublayers: Vec<String>,
    default_prim: Option<sdf::Path>,
    children: HashMap<sdf::Path, Vec<sdf::Path>>,
    arcs: HashMap<sdf::Path, Vec<Arc>>,
}

/// A prim of a layer stack: the node of the walk.
type Site = (usize, sdf::Path);

/// What the walk knows of a site once done.
#[derive(Clone, Copy, Default)]
struct Metrics {
    /// Prims it composes to, itself included (saturating).
    size: u64,
    /// Namespace levels below it.
    height: u64,
    /// The longest chain of arcs starting at it.
    chain: u64,
}

/// Reads every layer the root reaches (sublayers, references and payloads in every variant) and
/// walks the prims and arcs; refuses a cycle, a chain of arcs deeper than openusd composes, a
/// namespace deeper than [`Limits::max_prim_depth`] and more prims than [`Limits::max_prims`].
/// A layer that cannot be read is left for openusd to report when it composes.
///
/// `stage` is the stage opened from `file` and not yet composed (nothing traversed, no prim
/// asked for): the layers it already holds are read from it.
pub(super) fn preflight(
    file: &Path,
    resolver: &LimitedResolver,
    limits: &Limits,
    stage: &ousd::Stage,
) -> Result<()> {
    let Some(root) = file.to_str() else {
        return Ok(());
    };
    let mut layers: Vec<LayerSpecs> = Vec::new();
    let mut ids: HashMap<String, usize> = HashMap::new();
    let root_id = resolver.create_identifier(root, None);
    let mut queue = vec![root_id.clone()];
    while let Some(id) = queue.pop() {
        if ids.contains_key(&id) {
            continue;
        }
        let specs = match stage.layer(&id) {
            Some(layer) => read_specs(&layer, resolver),
            None => match sdf::Layer::open_with(resolver.clone(), &id) {
                Ok(layer) => read_specs(&layer, resolver),
                Err(_) => {
                    // openusd reports it (with its line) when it composes.
                    if layers.is_empty() {
                        return Ok(());
                    }
                    continue;
                }
            },
        };
        ids.insert(id.clone(), layers.len());
        for a in specs.arcs.values().flatten() {
            queue.push(a.stack.clone());
        }
        queue.extend(specs.sublayers.iter().cloned());
        layers.push(specs);
    }
    let root_layer = ids[&root_id];
    check_sublayer_cycles(file, &layers, &ids, root_layer)?;
    // A layer stack by its root layer: the layer and its sublayers, strongest first.
    let stack_layers = |stack: usize| -> Vec<usize> {
        let mut out = Vec::new();
        // A set sized by the stack, not by every layer read: a stage referencing thousands of
        // asset layers computes one stack per layer.
        let mut seen = HashSet::new();
        let mut todo = vec![stack];
        while let Some(l) = todo.pop() {
            if !seen.insert(l) {
                continue;
            }
            out.push(l);
            for s in layers[l].sublayers.iter().rev() {
                if let Some(&i) = ids.get(s) {
                    todo.push(i);
                }
            }
        }
        out
    };
    let stacks: Vec<Vec<usize>> = (0..layers.len()).map(stack_layers).collect();
    let walk = Walk {
        file,
        layers: &layers,
        ids: &ids,
        stacks: &stacks,
    };
    walk.run(root_layer, limits)
}

fn read_specs(layer: &sdf::Layer, resolver: &LimitedResolver) -> LayerSpecs {
    let data = layer.data();
    let anchor = layer.resolved_path().map(ar::ResolvedPath::new);
    let identify = |asset: &str| resolver.create_identifier(asset, anchor.as_ref());
    let mut specs = LayerSpecs {
        name: layer.identifier().to_string(),
        ..LayerSpecs::default()
    };
    if let Some(pr) = layer.pseudo_root() {
        specs.sublayers = pr
            .sublayers()
            .unwrap_or_default()
            .iter()
            .map(|s| identify(s))
            .collect();
        specs.default_prim = pr
            .default_prim()
            .and_then(|t| sdf::default_prim_path(t.as_str()));
    }
    let me = layer.identifier().to_string();
    // Prims already listed as a child: the variant specs of one prim (`/A{v=x}B`, `/A{v=y}B`)
    // strip to the same path. A set, not a scan of the parent's list, so that a parent with k
    // children costs k, not k² (100,000 lights under one prim took minutes).
    let mut listed: HashSet<sdf::Path> = HashSet::new();
    for p in data.spec_paths() {
        let kind = data.spec_type(&p);
        if !matches!(kind, Some(sdf::SpecType::Prim | sdf::SpecType::Variant)) {
            continue;
        }
        let prim = p.strip_all_variant_selections();
        if kind == Some(sdf::SpecType::Prim)
            && let Some(parent) = prim.parent()
            && !listed.contains(&prim)
        {
            listed.insert(prim.clone());
            specs.children.entry(parent).or_default().push(prim.clone());
        }
        let mut arcs = Vec::new();
        let field = |name: &str| data.try_field(&p, name).ok().flatten();
        let mut external = |kind: &'static str, asset: &str, target: &sdf::Path| {
            let stack = if asset.is_empty() {
                me.clone()
            } else {
                identify(asset)
            };
            let path = if target.is_empty() {
                // The target layer's defaultPrim, resolved once the layer is read.
                sdf::Path::abs_root()
            } else {
                prim.make_absolute(target)
            };
            arcs.push(Arc { kind, stack, path });
        };
        if let Some(v) = field("references")
            && let sdf::Value::ReferenceListOp(op) = &*v
        {
            for r in op.iter() {
                external("references", &r.asset_path, &r.prim_path);
            }
        }
        if let Some(v) = field("payload") {
            match &*v {
                sdf::Value::PayloadListOp(op) => {
                    for r in op.iter() {
                        external("payload", &r.asset_path, &r.prim_path);
                    }
                }
                sdf::Value::Payload(r) => external("payload", &r.asset_path, &r.prim_path),
                _ => {}
            }
        }
        for (kind, key) in [("inherits", "inheritPaths"), ("specializes", "specializes")] {
            if let Some(v) = field(key)
                && let sdf::Value::PathListOp(op) = &*v
            {
                for t in op.iter() {
                    arcs.push(Arc {
                        kind,
                        stack: me.clone(),
                        path: prim.make_absolute(t),
                    });
                }
            }
        }
        if !arcs.is_empty() {
            specs.arcs.entry(prim).or_default().extend(arcs);
        }
    }
    specs
}

/// A sublayer cycle (a layer that is its own sublayer, at any depth) is refused: usd-core and
/// openusd drop the closing sublayer with an error, which would lose the lights it holds.
fn check_sublayer_cycles(
    file: &Path,
    layers: &[LayerSpecs],
    ids: &HashMap<String, usize>,
    root: usize,
) -> Result<()> {
    // Iterative depth-first search over sublayer edges; `path` is the current chain.
    let mut on_path = vec![false; layers.len()];
    let mut done = vec![false; layers.len()];
    let mut stack: Vec<(usize, usize)> = vec![(root, 0)];
    on_path[root] = true;
    while let Some((l, next)) = stack.last_mut() {
        let (l, k) = (*l, *next);
        *next += 1;
        match layers[l].sublayers.get(k) {
            Some(s) => {
                let Some(&c) = ids.get(s) else { continue };
                if on_path[c] {
                    let chain: Vec<&str> = stack
                        .iter()
                        .map(|(i, _)| layers[*i].name.as_str())
                        .skip_while(|n| *n != layers[c].name)
                        .collect();
                    return Err(LuxError::Format {
                        path: file.to_path_buf(),
                        line: None,
                        reason: format!(
                            "sublayer cycle: {} → {}",
                            chain.join(" → "),
                            layers[c].name
                        ),
                    });
                }
                if !done[c] {
                    on_path[c] = true;
                    stack.push((c, 0));
                }
            }
            None => {
                on_path[l] = false;
                done[l] = true;
                stack.pop();
            }
        }
    }
    Ok(())
}

struct Walk<'a> {
    file: &'a Path,
    layers: &'a [LayerSpecs],
    ids: &'a HashMap<String, usize>,
    stacks: &'a [Vec<usize>],
}

/// A frame of the depth-first path: a site, its edges, the next edge, its metrics so far, and
/// the edge that led to it.
struct Frame {
    site: Site,
    edges: Vec<Edge>,
    next: usize,
    m: Metrics,
    via: &'static str,
}

/// An edge of the walk: to a namespace child, or along an arc.
enum Edge {
    Child(Site),
    Arc(&'static str, Site),
}

impl Walk<'_> {
    fn edges(&self, (stack, path): &Site) -> Vec<Edge> {
        let mut out: Vec<Edge> = Vec::new();
        let layers = &self.stacks[*stack];
        // A child authored in several layers of the stack is one edge. Within one layer the
        // children are already distinct, so a single-layer stack (the common case) needs no
        // set; a set rather than a scan of `out` keeps a prim with k children at k, not k².
        let mut seen: HashSet<&sdf::Path> = HashSet::new();
        for &l in layers {
            let specs = &self.layers[l];
            for c in specs.children.get(path).into_iter().flatten() {
                if layers.len() == 1 || seen.insert(c) {
                    out.push(Edge::Child((*stack, c.clone())));
                }
            }
            for a in specs.arcs.get(path).into_iter().flatten() {
                let Some(&t) = self.ids.get(&a.stack) else {
                    continue; // unreadable: openusd reports it
                };
                let target = if a.path.is_abs_root() {
                    match &self.layers[t].default_prim {
                        Some(p) => p.clone(),
                        None => continue, // openusd reports the missing defaultPrim
                    }
                } else {
                    a.path.clone()
                };
                out.push(Edge::Arc(a.kind, (t, target)));
            }
        }
        out
    }

    fn name(&self, (stack, path): &Site) -> String {
        format!("<{path}> of {}", self.layers[*stack].name)
    }

    fn run(&self, root: usize, limits: &Limits) -> Result<()> {
        #[derive(Clone, Copy)]
        enum State {
            OnPath,
            Done(Metrics),
        }
        let mut state: HashMap<Site, State> = HashMap::new();
        let roots: Vec<Site> = self
            .edges(&(root, sdf::Path::abs_root()))
            .into_iter()
            .filter_map(|e| match e {
                Edge::Child(s) => Some(s),
                Edge::Arc(..) => None,
            })
            .collect();
        let mut total = 0u64;
        for r in roots {
            let mut path: Vec<Frame> = Vec::new();
            if !state.contains_key(&r) {
                state.insert(r.clone(), State::OnPath);
                path.push(Frame {
                    edges: self.edges(&r),
                    site: r.clone(),
                    next: 0,
                    m: Metrics {
                        size: 1,
                        ..Metrics::default()
                    },
                    via: "",
                });
            }
            while let Some(top) = path.last_mut() {
                if top.next < top.edges.len() {
                    top.next += 1;
                    let (site, via) = match &top.edges[top.next - 1] {
                        Edge::Child(s) => (s.clone(), "has the child"),
                        Edge::Arc(k, s) => (s.clone(), *k),
                    };
                    let top_site = &path.last().expect("top").site;
                    // An arc to the prim's own descendant is a cycle too: the descendant
                    // composes its ancestor's arcs, which lead to itself again (usd-core and
                    // openusd report it as one).
                    let to_descendant = via != "has the child"
                        && site.0 == top_site.0
                        && site.1 != top_site.1
                        && site.1.has_prefix(&top_site.1);
                    if to_descendant {
                        let closing = top_site.clone();
                        return Err(self.cycle(
                            &path,
                            &closing,
                            &format!("{via} its descendant <{}>, which composes", site.1),
                        ));
                    }
                    match state.get(&site) {
                        Some(State::OnPath) => {
                            return Err(self.cycle(&path, &site, via));
                        }
                        Some(State::Done(m)) => {
                            let m = *m;
                            let top = path.last_mut().expect("top");
                            let edge = &top.edges[top.next - 1];
                            let mut acc = top.m;
                            fold(&mut acc, edge, m);
                            top.m = acc;
                        }
                        None => {
                            state.insert(site.clone(), State::OnPath);
                            let edges = self.edges(&site);
                            path.push(Frame {
                                site,
                                edges,
                                next: 0,
                                m: Metrics {
                                    size: 1,
                                    ..Metrics::default()
                                },
                                via,
                            });
                        }
                    }
                    continue;
                }
                let done = path.pop().expect("top");
                self.check_site(&done.site, &done.m)?;
                state.insert(done.site.clone(), State::Done(done.m));
                if let Some(parent) = path.last_mut() {
                    let mut acc = parent.m;
                    fold(&mut acc, &parent.edges[parent.next - 1], done.m);
                    parent.m = acc;
                }
            }
            let Some(State::Done(m)) = state.get(&r) else {
                continue;
            };
            total = total.saturating_add(m.size);
            // A root prim is one level deep.
            if m.height + 1 > limits.max_prim_depth {
                return Err(LuxError::Format {
                    path: self.file.to_path_buf(),
                    line: None,
                    reason: format!(
                        "prim {} composes to a namespace {} levels deep, over the limit of {} ({})",
                        self.name(&r),
                        m.height + 1,
                        limits.max_prim_depth,
                        raise_hint(ENV_MAX_PRIM_DEPTH)
                    ),
                });
            }
            if total > limits.max_prims {
                return Err(LuxError::Format {
                    path: self.file.to_path_buf(),
                    line: None,
                    reason: format!(
                        "the stage composes to up to {total} prims (counting every variant; \
                         {} under {}), over the limit of {} ({})",
                        m.size,
                        self.name(&r),
                        limits.max_prims,
                        raise_hint(ENV_MAX_PRIMS)
                    ),
                });
            }
        }
        Ok(())
    }

    /// The chain of arcs at one site must stay within what openusd composes.
    fn check_site(&self, site: &Site, m: &Metrics) -> Result<()> {
        if m.chain > MAX_ARC_DEPTH {
            return Err(LuxError::Format {
                path: self.file.to_path_buf(),
                line: None,
                reason: format!(
                    "prim {} starts a chain of {} nested composition arcs; luxeval's USD reader \
                     (openusd 0.8) composes at most {MAX_ARC_DEPTH} and would drop the prim \
                     (usd-core composes it): flatten part of the chain",
                    self.name(site),
                    m.chain
                ),
            });
        }
        Ok(())
    }

    fn cycle(&self, path: &[Frame], closing: &Site, via: &str) -> LuxError {
        let start = path.iter().position(|f| &f.site == closing).unwrap_or(0);
        let mut text = self.name(closing);
        for f in &path[start + 1..] {
            text.push_str(&format!(" {} {}", f.via, self.name(&f.site)));
        }
        text.push_str(&format!(" {via} {}", self.name(closing)));
        let layer = &self.layers[closing.0].name;
        LuxError::Format {
            path: if Path::new(layer).exists() {
                Path::new(layer).to_path_buf()
            } else {
                self.file.to_path_buf()
            },
            line: None,
            reason: format!("composition cycle at prim <{}>: {text}", closing.1),
        }
    }
}

/// Adds a finished site's metrics to the site that reached it.
fn fold(m: &mut Metrics, edge: &Edge, t: Metrics) {
    match edge {
        Edge::Child(_) => {
            m.size = m.size.saturating_add(t.size);
            m.height = m.height.max(t.height + 1);
        }
        Edge::Arc(..) => {
            // The target's root merges into this prim; its descendants become this prim's.
            m.size = m.size.saturating_add(t.size - 1);
            m.height = m.height.max(t.height);
            m.chain = m.chain.max(t.chain + 1);
        }
    }
}
