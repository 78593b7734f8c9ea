//! The outer breakpoints of the chart quadrature (f64). Twin of
//! `shaders/irradiance/critical.wgsl`.
//!
//! The integral over the chart is taken over lines Y = const (planes through x containing E1);
//! the outer integrand is smooth in Y except where the inner structure of a line changes. The
//! outer integral is split at every such Y:
//! - the region's ends (square edges; disk and cylinder ends, where the X-interval closes like a
//!   square root);
//! - the horizon (and the focus plane) crossing the region boundary, each other, and the kink
//!   cones;
//! - the kink cones (cone edge, smoothstep start) tangent to a line of the pencil (closed form: a
//!   plane through x containing E1 tangent to a circular cone), crossing the region boundary
//!   (quadratic for straight edges; for elliptic boundaries the degree-2 trigonometric equation
//!   is solved by bracketing and bisection);
//! - where the outer integrand peaks: a curve bounding the inner intervals (a region edge, a
//!   cone edge, the focus line) comes nearest to x;
//! - the line through the axis directions where the shaping is singular there.
//!
//! A split placed slightly off (bisection precision) leaves an error of second order in the
//! offset.

use glam::DVec3;
use std::f64::consts::PI;

use super::chart::{Arc, Chart, Region, arc_at, make_chart};
use crate::cpu::roots::{
    bracket_roots, cone_roots_on_line, lin_trig_roots, pencil_tangent_normals, plane_cone_dirs,
    wrap_into,
};
use crate::prepare::ies_kinks::IesKinks;
use crate::prepare::{Kink, Prepared, PreparedIes, Profile};

/// Samples per arc when bracketing the roots of a degree-2 trigonometric polynomial (the
/// kernel uses `rules::IRR_ARC_SAMPLES`, fewer, for speed).
pub const ARC_SAMPLES: usize = 64;

/// Samples per arc for the loose `--tolerance` rules: the GPU kernel's count
/// (`rules::IRR_ARC_SAMPLES`, held to 1e-4 by the conformance tests). A pair of roots closer
/// than a sample spacing can go unlisted; the adaptive rule then still sees the kink.
pub const LOOSE_ARC_SAMPLES: usize = crate::rules::IRR_ARC_SAMPLES as usize;

/// Keeps `y` when it lies in the chart's Y-range.
fn push_y(ys: &mut Vec<f64>, y: f64, chart: &Chart) {
    let (ya, yb) = chart.y_range();
    if y.is_finite() && y >= ya && y <= yb {
        ys.push(y);
    }
}

/// Keeps the chart Y of the direction `w`, when the ray reaches the chart plane.
fn push_dir(ys: &mut Vec<f64>, w: DVec3, chart: &Chart) {
    if let Some(y) = chart.chart_y(w) {
        push_y(ys, y, chart);
    }
}

/// The lines where the planes of the pencil (through the receiver, containing the chart's
/// `e1`) are tangent to the cone of `axis` and cosine `c` (`roots::pencil_tangent_normals`),
/// each meeting the chart at Y = −m·w0 / m·e2.
fn pencil_tangent_ys(ys: &mut Vec<f64>, chart: &Chart, axis: DVec3, c: f64) {
    for m in pencil_tangent_normals(chart.e1, axis, c)
        .into_iter()
        .flatten()
    {
        let me2 = m.dot(chart.e2);
        if me2 != 0.0 {
            push_y(ys, -m.dot(chart.w0) / me2, chart);
        }
    }
}

/// Crossings of the cone −ŵ·axis = cos with an elliptic arc (correct nappe).
fn arc_cone_crossings(
    ys: &mut Vec<f64>,
    chart: &Chart,
    arc: &Arc,
    axis: DVec3,
    cos: f64,
    samples: usize,
) {
    let f = |t: f64| arc_f(arc, axis, cos, t);
    for t in bracket_roots(&f, arc.t0, arc.t1, samples) {
        let w = arc_at(arc, t);
        if -w.dot(axis) * cos > 0.0 {
            push_dir(ys, w, chart);
        }
    }
}

/// The local minima of |w(t)|² on the arc: its points nearest to x.
fn arc_nearest(ys: &mut Vec<f64>, chart: &Chart, arc: &Arc, samples: usize) {
    let d = |t: f64| arc_d(arc, t);
    for t in bracket_roots(&d, arc.t0, arc.t1, samples) {
        if d(t).1 > 0.0 {
            push_dir(ys, arc_at(arc, t), chart);
        }
    }
}

/// ½ d|w|²/dt on the arc, and its derivative.
fn arc_d(arc: &Arc, t: f64) -> (f64, f64) {
    let w = arc_at(arc, t);
    let dw = arc.v * t.cos() - arc.u * t.sin();
    let ddw = -arc.u * t.cos() - arc.v * t.sin();
    (w.dot(dw), dw.length_squared() + w.dot(ddw))
}

/// F(t) = (w·a)² − cos²|w|² on the arc (degree 2 in (cos t, sin t)), and F'(t).
fn arc_f(arc: &Arc, axis: DVec3, cos: f64, t: f64) -> (f64, f64) {
    let w = arc_at(arc, t);
    let dw = arc.v * t.cos() - arc.u * t.sin();
    let wa = w.dot(axis);
    (
        wa * wa - cos * cos * w.length_squared(),
        2.0 * wa * dw.dot(axis) - 2.0 * cos * cos * w.dot(dw),
    )
}

/// The chart region's straight edges X = const (the square's sides) and its elliptic arcs (a
/// disk's rim, a cylinder's).
fn region_edges(chart: &Chart) -> (Vec<f64>, Vec<Arc>) {
    match &chart.region {
        Region::Square => (vec![-1.0, 1.0], vec![]),
        Region::Disk => (
            vec![],
            vec![Arc {
                c: chart.w0,
                u: chart.e1,
                v: chart.e2,
                t0: 0.0,
                t1: 2.0 * PI,
            }],
        ),
        Region::Cylinder(c) => (vec![], c.arcs.to_vec()),
    }
}

/// The Ys where a plane m·w = 0 through x meets the chart's inner structure: the line of the
/// pencil lying in it, its crossings with the straight edges X = xs (`segs`) and with the arcs
/// ([`critical_ys_with`]'s planes and [`ies_ys`]'s profile planes).
fn plane_ys(ys: &mut Vec<f64>, chart: &Chart, segs: &[f64], arcs: &[Arc], m: DVec3) {
    let (me1, me2, mw0) = (m.dot(chart.e1), m.dot(chart.e2), m.dot(chart.w0));
    if me1.abs() <= 1e-12 * m.length() * chart.e1.length() && me2 != 0.0 {
        // A plane of the pencil: one line Y = const lies in it.
        push_y(ys, -mw0 / me2, chart);
    }
    if me2 != 0.0 {
        for &xs in segs {
            push_y(ys, -(mw0 + xs * me1) / me2, chart);
        }
    }
    for arc in arcs {
        for t in lin_trig_roots(m.dot(arc.u), m.dot(arc.v), -m.dot(arc.c)) {
            let t = wrap_into(t, arc.t0);
            if t <= arc.t1 {
                push_dir(ys, arc_at(arc, t), chart);
            }
        }
    }
}

/// The Ys where the cone of `axis` and cosine `c` meets the chart's inner structure: tangent
/// to a line of the pencil, crossing the straight edges X = xs (a quadratic in Y) and the arcs
/// ([`critical_ys_with`]'s kink cones and [`ies_ys`]'s profile cones).
fn cone_ys(
    ys: &mut Vec<f64>,
    chart: &Chart,
    segs: &[f64],
    arcs: &[Arc],
    axis: DVec3,
    c: f64,
    arc_samples: usize,
) {
    let (w0, e1, e2) = (chart.w0, chart.e1, chart.e2);
    pencil_tangent_ys(ys, chart, axis, c);
    for &xs in segs {
        for y in cone_roots_on_line(axis, c, w0 + e1 * xs, e2) {
            push_y(ys, y, chart);
        }
    }
    for arc in arcs {
        arc_cone_crossings(ys, chart, arc, axis, c, arc_samples);
    }
}

/// The Y values where the inner structure of the chart integral changes (see the module docs),
/// sorted, within and including the region's Y-range.
pub fn critical_ys(p: &Prepared, chart: &Chart, n: DVec3) -> Vec<f64> {
    critical_ys_with(p, &p.profile, chart, n, ARC_SAMPLES)
}

/// [`critical_ys`] for the shaping kinks of `prof` (an empty profile: a shaping factor that is
/// uniform over the chart), bracketing arc roots with `arc_samples` samples per arc (the loose
/// `--tolerance` rules take [`LOOSE_ARC_SAMPLES`]).
pub fn critical_ys_with(
    p: &Prepared,
    prof: &Profile,
    chart: &Chart,
    n: DVec3,
    arc_samples: usize,
) -> Vec<f64> {
    let axis = p.axis;
    let (ya, yb) = chart.y_range();
    // Room for a typical chart's breakpoints at once: growing the list a push at a time cost
    // several reallocations per receiver, which contend for malloc's locks on many cores
    // (BENCHMARKS.md, "The CPU path's system time").
    let mut ys = Vec::with_capacity(64);
    ys.extend([ya, yb]);
    let mut planes: Vec<DVec3> = vec![n];
    let mut cones: Vec<f64> = Vec::new();
    for k in &prof.kinks {
        match *k {
            Kink::Cone { cos } => cones.push(cos),
            Kink::Plane { m, .. } => planes.push(m),
        }
    }
    let (w0, e1, e2) = (chart.w0, chart.e1, chart.e2);
    let (mut segs, arcs) = region_edges(chart);
    // A textured rect: the texture's vertical break lines are straight edges too, and its
    // horizontal ones are breaks (DESIGN.md §6 "what 'exact' means", rect_texture.rs).
    segs.extend(super::rect_texture::texel_xs(p, chart));
    for y in super::rect_texture::texel_ys(p, chart) {
        push_y(&mut ys, y, chart);
    }
    for &m in &planes {
        plane_ys(&mut ys, chart, &segs, &arcs, m);
        // Plane ∩ plane: the line through x along m × m'.
        for &m2 in &planes {
            let d = m.cross(m2);
            if d.length_squared() > 0.0 {
                push_dir(&mut ys, d, chart);
                push_dir(&mut ys, -d, chart);
            }
        }
        // Plane ∩ kink cones.
        for &c in &cones {
            for w in plane_cone_dirs(m, axis, c) {
                push_dir(&mut ys, w, chart);
            }
        }
    }
    for &c in &cones {
        cone_ys(&mut ys, chart, &segs, &arcs, axis, c, arc_samples);
    }
    // The outer integrand peaks where a curve bounding the inner intervals (a region edge, a
    // cone edge, the focus line) comes nearest to x: split there too.
    for &xs in &segs {
        push_y(
            &mut ys,
            -(w0 + e1 * xs).dot(e2) / e2.length_squared(),
            chart,
        );
    }
    for arc in &arcs {
        arc_nearest(&mut ys, chart, arc, arc_samples);
    }
    let nrm = e1.cross(e2).normalize() * w0.dot(e1.cross(e2)).signum();
    for &c in &cones {
        // The cone's generator nearest to the chart plane's normal: the nearest point of the
        // cone-edge curve.
        let q = -axis;
        let perp = nrm - q * nrm.dot(q);
        if perp.length_squared() > 0.0 {
            push_dir(
                &mut ys,
                q * c + perp.normalize() * (1.0 - c * c).max(0.0).sqrt(),
                chart,
            );
        }
    }
    for &m in planes.iter().skip(1) {
        // The nearest point of the plane's line in the chart plane.
        let mu = m.normalize();
        let perp = nrm - mu * nrm.dot(mu);
        if perp.length_squared() > 0.0 {
            push_dir(&mut ys, perp, chart);
        }
    }
    if prof.axis_singular {
        // The line of the pencil through the axis directions.
        let m = e1.cross(axis);
        if m.dot(e2) != 0.0 {
            push_y(&mut ys, -m.dot(w0) / m.dot(e2), chart);
        }
    }
    ys.sort_by(f64::total_cmp);
    let span = yb - ya;
    ys.dedup_by(|b, a| (*b - *a).abs() <= 1e-13 * span);
    ys
}

/// `ys` (sorted, from [`critical_ys`]) with [`ies_ys`] of the profile's surfaces that can meet
/// the chart (`outer::chart_ies_kinks`) merged in, sorted and de-duplicated as `critical_ys`
/// does (the loose rules' and the GPU kernel's outer breakpoints).
pub fn add_ies_ys(p: &Prepared, ies: &PreparedIes, chart: &Chart, n: DVec3, ys: &mut Vec<f64>) {
    let local = super::outer::chart_ies_kinks(p, chart);
    let extra = ies_ys(p, chart, n, local.as_ref().unwrap_or(&ies.kinks));
    if !extra.is_empty() {
        ys.extend(extra);
        ys.sort_by(f64::total_cmp);
        let span = ys[ys.len() - 1] - ys[0];
        ys.dedup_by(|b, a| (*b - *a).abs() <= 1e-13 * span);
    }
}

/// The Ys where an IES profile's grid lines change the inner structure (used by the loose
/// `--tolerance` rules, whose 7-point pair across lines needs the outer integrand smooth on each
/// piece; the reference leaves these kinks to its 15-point adaptive rule, bit for bit as
/// before). `kinks` are the profile's kink surfaces in the light's frame
/// (`outer::chart_ies_kinks`). The chart is mapped to the light's frame by M⁻¹: a linear map
/// keeps the chart's parameters (X, Y), so Ys found there are Ys of the chart. There the
/// profile's surfaces are circular cones and planes through x, and the same constructions as
/// [`critical_ys`] apply: each surface tangent to a line of the pencil, crossing the region's
/// edges and arcs, and crossing the horizon, the focus plane and the profile's other surfaces.
/// (Not listed: a profile cone crossing the shaping's cone, a circular cone of the world frame
/// only; the adaptive rule still sees it.)
pub fn ies_ys(p: &Prepared, chart: &Chart, n: DVec3, kinks: &IesKinks) -> Vec<f64> {
    let l = p.to_local;
    let region = match &chart.region {
        Region::Cylinder(c) => {
            let mut c = (**c).clone();
            for a in c.arcs.iter_mut() {
                (a.c, a.u, a.v) = (l * a.c, l * a.u, l * a.v);
            }
            Region::Cylinder(Box::new(c))
        }
        r => r.clone(),
    };
    let lc = make_chart(l * chart.w0, l * chart.e1, l * chart.e2, region);
    // Planes through x in the light's frame: a world normal m becomes Mᵀm.
    let mt = p.linear.transpose();
    let mut fixed: Vec<DVec3> = vec![mt * n];
    for k in &p.profile.kinks {
        if let Kink::Plane { m, .. } = *k {
            fixed.push(mt * m);
        }
    }
    let (segs, arcs) = region_edges(&lc);
    let mut ys = Vec::with_capacity(64);
    for &m in &kinks.planes {
        plane_ys(&mut ys, &lc, &segs, &arcs, m);
        for &m2 in fixed.iter().chain(&kinks.planes) {
            let d = m.cross(m2);
            if d.length_squared() > 0.0 {
                push_dir(&mut ys, d, &lc);
                push_dir(&mut ys, -d, &lc);
            }
        }
        for &(axis, c) in &kinks.cones {
            for w in plane_cone_dirs(m, axis, c) {
                push_dir(&mut ys, w, &lc);
            }
        }
    }
    for &(axis, c) in &kinks.cones {
        cone_ys(&mut ys, &lc, &segs, &arcs, axis, c, LOOSE_ARC_SAMPLES);
        for &m in &fixed {
            for w in plane_cone_dirs(m, axis, c) {
                push_dir(&mut ys, w, &lc);
            }
        }
    }
    ys
}
