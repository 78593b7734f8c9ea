//! Exact irradiance of a textured rect (DESIGN.md §6 "RectLight texture" and "Dome and texture
//! irradiance: what 'exact' means"), f64, CPU only: the GPU path takes it from here
//! (`query::irradiance_on_host`), so this module has no WGSL twin.
//!
//! The rect's plane chart (`chart::plane_chart`) is `X = x/hx`, `Y = y/hy` ∈ [−1, 1] in the
//! light's local coordinates, so by §6's `s = 0.5 − x/w`, `t = 0.5 − y/h` the texture at chart
//! point (X, Y) is `tex((1 − X)/2, (1 − Y)/2)`. The irradiance is the chart integral of
//! `cpu::irradiance` with the texture as one more factor of the integrand,
//! `E = L ∫∫ S(−ŵ) · tex(X, Y) · max(0, n·w) · J/|w|⁴ dX dY`, i.e. the integral of the filtered
//! texture over the surface (with L's shaping, cosines and the receiver's horizon), not a sum of
//! texel solid angles. The reconstruction is a polynomial on each cell between texel-centre
//! lines (bilinear: its kinks, with the clamped half-texel borders constant) or texel edges
//! (nearest: its jumps), so the quadrature splits there:
//! - along each line Y = const at the X of every such vertical line ([`ChartTexture::xs`],
//!   breakpoints of `line::line_integral`);
//! - across lines at every such horizontal line ([`texel_ys`]), and where the vertical lines
//!   meet the receiver's horizon, the focus plane and the kink cones, and come nearest to x (the
//!   vertical lines join the square's sides as straight edges in `critical::critical_ys`).
//!
//! Each smooth piece is integrated by the reference's adaptive Gauss–Kronrod rule to its
//! tolerance (`Adaptive::REFERENCE`, ~1e-9 relative), as for an untextured shaped rect.

use glam::{DVec2, DVec3};

use super::chart::{Chart, Region};
use crate::cpu::dome::sample_rect;
use crate::prepare::Prepared;
use crate::prepare::dome::{Filter, Image, axis_pieces};

/// A textured rect's texture as the chart quadrature reads it.
pub struct ChartTexture<'a> {
    img: &'a Image,
    filter: Filter,
    /// Chart X of the vertical lines where the reconstruction is not smooth, inside (−1, 1).
    pub xs: Vec<f64>,
}

impl ChartTexture<'_> {
    /// The filtered texture at chart point (X, Y).
    pub fn value(&self, x: f64, y: f64) -> DVec3 {
        sample_rect(
            self.img,
            DVec2::new(0.5 * (1.0 - x), 0.5 * (1.0 - y)),
            self.filter,
        )
    }
}

/// The texture of `p` when it is a textured rect integrated over its square chart.
pub fn chart_texture<'a>(p: &'a Prepared, chart: &Chart) -> Option<ChartTexture<'a>> {
    let t = p.rect_texture.as_ref()?;
    if !matches!(chart.region, Region::Square) {
        return None;
    }
    let xs = breaks(t.image.width, t.filter())
        .into_iter()
        .map(|s| 1.0 - 2.0 * s)
        .collect();
    Some(ChartTexture {
        img: &t.image,
        filter: t.filter(),
        xs,
    })
}

/// Where the reconstruction of an axis of `n` texels is not smooth, as fractions of the axis
/// in (0, 1): the ends of `prepare::dome::axis_pieces` (clamped, so no wrap), interior only.
fn breaks(n: usize, filter: Filter) -> Vec<f64> {
    let nf = n as f64;
    let mut v: Vec<f64> = axis_pieces(n as u32, false, filter)
        .iter()
        .map(|piece| piece.x0 / nf)
        .filter(|&s| s > 0.0 && s < 1.0)
        .collect();
    v.dedup();
    v
}

/// The chart X of the texture's vertical break lines (textured rect on its square chart;
/// empty otherwise): `critical::critical_ys` treats them as straight edges X = const.
pub fn texel_xs(p: &Prepared, chart: &Chart) -> Vec<f64> {
    chart_texture(p, chart).map(|t| t.xs).unwrap_or_default()
}

/// The chart Y of the texture's horizontal break lines (textured rect on its square chart;
/// empty otherwise).
pub fn texel_ys(p: &Prepared, chart: &Chart) -> Vec<f64> {
    match (&p.rect_texture, &chart.region) {
        (Some(t), Region::Square) => breaks(t.image.height, t.filter())
            .into_iter()
            .map(|t| 1.0 - 2.0 * t)
            .collect(),
        _ => Vec::new(),
    }
}
