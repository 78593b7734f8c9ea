//! Fast irradiance of a textured rect at a loose tolerance (issue 24 item 4), f64, CPU only.
//!
//! The reference (`rect_texture`, DESIGN.md §6 "RectLight texture" and "Dome and texture
//! irradiance: what 'exact' means") splits the chart quadrature at every texel line: ~2M smooth
//! pieces for a 2048 × 1024 texture, ~50 s per receiver. This path computes the same integral,
//! `E = L ∫∫ t(X, Y) · K(X, Y) dX dY` with `K = S(−ŵ)·max(0, n·w)·J/|w|⁴` (everything but the
//! texture t, see `cpu::irradiance`), to a relative tolerance `rel` ≥ [`MIN_TOLERANCE`]:
//!
//! - Linearity in the texture: on a chart rectangle R with the 3 × 3 Gauss–Legendre points
//!   `x_ab` of R and the tensor Lagrange basis `ℓ_ab` on them, `∫_R t·K ≈ ∫_R t·I(K) =
//!   Σ_ab K(x_ab)·W_ab` with the texture's *Lagrange moments* `W_ab = ∫_R t·ℓ_ab`. They are exact
//!   integrals of the interpolant actually used (DESIGN.md "what 'exact' means"): t is bilinear
//!   (or constant) on each texel piece (`prepare::texture::axis_pieces`) and ℓ_ab biquadratic,
//!   so the 3-point Gauss–Legendre rule of each piece (exact to degree 5 per axis) integrates
//!   `t·ℓ_ab` exactly. A parent's moments follow exactly from its children's, because the
//!   parent's ℓ restricted to a child is the child's biquadratic interpolant of it:
//!   `W^P_ab = Σ_children Σ_cd W^C_cd ℓ^P_ab(x^C_cd)`. The moments of a quadtree over the texel
//!   pieces (blocks of ≤ [`tree::LEAF_PIECES`] pieces at its leaves) are built once per texture
//!   ([`tree`], lazily, in the texture's `irradiance` slot); below a leaf they are computed on
//!   the fly from the pieces, and below one piece from the piece's Gauss points (a sub-rect of
//!   a piece: `W_ab = Σ gauss weight · t · ℓ_ab`).
//! - Per receiver, globally adaptive subdivision of that tree (QUADPACK `qag` in 2-D, Piessens
//!   et al. 1983, with the moment rule of a cell as the basic rule): every active cell carries
//!   the sum of its children's rules as its value and `|Σ children − own rule|` as its error
//!   estimate; the cell with the largest error is replaced by its children until the summed
//!   error is below `rel/16` of the summed value in every channel. Cells continue below texel
//!   pieces (quadrants of a piece), so the near-field peak is resolved by subdivision.
//! - Where K is not smooth the moment rule is not used: a cell the receiver's horizon crosses
//!   (K's kink `max(0, n·w)`, a line of the chart) or that a shaping kink may cross (cone edge,
//!   smoothstep start, focus plane: `Prepared::profile`) is integrated by
//!   [`Kernel::clipped`], a 5 × 5 Gauss rule on the part in front of the horizon whose lines
//!   are split at the shaping's kinks (the roots `line::line_integral` splits at), with t
//!   sampled; no rule point then lies where K = 0, so no lit sliver goes unseen along a line.
//!   Across lines the rule is split where a kink's inner roots change (a kink cone crossing
//!   the cell's sides or the horizon line, or tangent to the pencil of lines; the focus plane
//!   crossing them), as `critical::critical_ys` splits the reference's outer integral, so
//!   that the outer integrand is smooth on each part and no lit cap of the cone lies between
//!   two lines unseen. Subdivision goes on below pieces until the estimates meet the tolerance.
//! - The clipped rule samples t, so over several texel pieces it samples across t's kinks
//!   (bilinear) or jumps (nearest): neither it nor its children's rules converge there, and
//!   the estimate can read 0 while both miss a texel (a cell whose lit part lies in one child
//!   gets that child's very rule points). This was the bias that kept shaped rects on the
//!   exact path: at 256 × 128, nearest, sheared, grazing receiver (the lit part a few texels
//!   between the horizon and the cone), 1.0e-4 and 3.0e-4 error at 1e-4 and at 1e-3, 1.1e-4
//!   and 4.6e-4 at 1e-2 (not the tolerance's); with the texture lit in one texel of it only, 33 % of that texel's light found,
//!   the same at rel 1e-4, 1e-6, 1e-8. A clipped cell over more than one piece that a
//!   shaping kink may cross is therefore split untrusted down to single pieces (where t is a polynomial and
//!   the rule converges): that case then < 5e-8, every shaped 256 × 128 one ≤ 5e-7 at 1e-4. The outer splits above were
//!   needed too: without them (in a variant that split only the kink-crossed cells) 4
//!   one-texel textures of 16 × 8 of shaped rects were missed entirely (a lit cap between
//!   two lines).
//! - A cell over several pieces that the horizon cuts, or that only a soft cone's kink cones
//!   (softness > 0) may cross, is not sampled at all ([`Kernel::bracket`]): the horizon's
//!   factor `max(0, n·w)` is bracketed on it by two parallel planes of the chart, and the cone
//!   factor by its range over the cell's directions (of the square of the cell's angular size
//!   astride a kink: the smoothstep's slope is 0 at both ends), so its rule is the moment rule
//!   of a smooth kernel (every texel counted through the exact moments) and its error has an
//!   a-priori bound (for the horizon alone `(D/2)·max|S·J/|w|⁴|·∫|t|`, D the band's height),
//!   which shrinks like the cell's size cubed (to the fourth for a kink cone); the adaptive
//!   split refines such cells only as far as the tolerance needs, and their bounds are held
//!   to half the tolerance ([`BOUND_SHARE`]; the estimates to rel/16). Hard cones' edges, the
//!   focus plane and a singular axis still split a crossed cell down to single pieces. History: while such cells of unshaped rects took the sampled clipped rule
//!   trusted on its estimate, one-texel 16 × 8 textures (both filters, both transforms, the 9
//!   receivers of the tests) were off by 1.2e-4 to 100 % at 1e-4 (random textures did not
//!   show it); the bound of the whole contribution instead ([`Kernel::cut_bound`], still the
//!   fallback where smaller) made visibleRect's 128² map take 28 s; the bracket takes it to
//!   0.63 s and shaped rects' focus-only receivers from 20–39 ms to 1–4 ms; bracketing soft
//!   cones' kinks took their receivers from up to 364 ms to up to ~60 ms (BENCHMARKS.md).
//! - Guard against a peak no rule point sees: a cell is split without being trusted while its
//!   world half-diagonal R exceeds half the lower bound `|w_c| − R` of its distance from x
//!   (FMM's well-separated criterion), unless the receiver's horizon hides all of it.
//!
//! Threshold ([`MIN_TOLERANCE`], `Rule::texture_tolerance`): `Adaptive::for_tolerance(rel)`
//! with rel ≥ 1e-4 (the CLI's and Python's default) takes this path; tighter tolerances and the
//! reference (`Adaptive::REFERENCE`, 1e-9) keep the exact split path unchanged. At 1e-5 the
//! estimates were measured to miss by 2–4× (1.9e-5 unshaped nearest, 3.6e-5 shaped, the latter
//! before the shaped fix above; not measured since).
//!
//! What this does not prove: the error estimates of smooth cells are a-posteriori (as the
//! reference's Gauss–Kronrod estimates are), not a-priori bounds, and the bracket bound
//! trusts the moment rule of its smooth kernel; the tests measure the result against
//! the 1e-9 reference on random textures, unshaped and shaped (cones with softness 0 to 0.4,
//! focus with tint, focus alone; sizes to 64 × 32 in the default run, 256 × 128 with
//! `--ignored`), and on one-texel textures of unshaped and shaped rects (8 × 4; 16 × 8 with `--ignored`),
//! near, grazing and far receivers.
//! IES profiles are left to the exact path ([`applies`]: never tried here).

use std::collections::BinaryHeap;

use glam::DVec3;

use super::chart::Chart;
use crate::prepare::Prepared;
use kernel::{Class, Kernel};
use tree::Cell;

/// The tightest tolerance the fast path takes: below it (`Adaptive::for_tolerance` of less
/// than 1e-4, and the reference) the exact split path runs. At 1e-5 the error estimates were
/// measured to miss by 2–4× (module docs), at 1e-4 to 1e-2 the tests hold every receiver.
pub const MIN_TOLERANCE: f64 = 1e-4;

/// The share of the tolerance the summed error estimates are held to. The estimates are not
/// bounds, so the sum stops well inside rel (the shaped bias once measured did not change from
/// rel/8 to rel/16: it was not the stop's, see the module docs).
const ESTIMATE_SHARE: f64 = 1.0 / 16.0;

/// The share of the tolerance the summed a-priori bounds (horizon-cut cells of unshaped lights,
/// [`Kernel::bracket`]) are held to: they hold whatever the texture, so half of it.
const BOUND_SHARE: f64 = 0.5;

/// At most this many cells are split per receiver (then the current sum is returned).
const MAX_SPLITS: usize = 2_000_000;

/// Whether the fast path takes `p`: a textured rect, unshaped or shaped by ShapingAPI's cone,
/// softness, focus and focusTint (their kinks handled as the module docs say; the shaped bias
/// once measured here was the clipped rule sampling the texture across texel pieces). With an
/// IES profile the exact split path runs: its kinks (`prepare::ies_kinks`) are not listed by
/// `Prepared::profile`, which [`Kernel::kinks`] and the clipped rule read, and it was never
/// measured here.
pub fn applies(p: &Prepared) -> bool {
    p.rect_texture().is_some() && p.ies.is_none()
}

/// An active cell: its value (the sum of its children's rules), their rules and error
/// bounds, its error (an estimate, or an a-priori bound when `bounded`).
struct Active {
    key: f64,
    value: DVec3,
    err: DVec3,
    bounded: bool,
    /// The children, their classes and their rules (value, bound).
    kids: Vec<(Cell, Class, (DVec3, DVec3))>,
}

impl PartialEq for Active {
    fn eq(&self, o: &Self) -> bool {
        self.key.total_cmp(&o.key).is_eq()
    }
}
impl Eq for Active {}
impl PartialOrd for Active {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Active {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.key.total_cmp(&o.key)
    }
}

/// The chart integral `∫∫ t·K dX dY` of the textured rect `p` (base radiance not applied) to
/// relative tolerance `rel` (module docs). None when `p` has no texture.
pub fn chart_integral(p: &Prepared, chart: &Chart, n: DVec3, rel: f64) -> Option<DVec3> {
    let tree = tree(p.rect_texture()?)?;
    let k = Kernel::new(p, chart, n);
    // A cell's rule serves only its parent's estimate and, until the cell is refined, the
    // running sum; a forced cell is always refined before the sum is taken (the loop below
    // does not stop while one is active) and a forced parent's estimate is not used. So a
    // forced child of a forced parent takes no rule (it would be discarded: half the clipped
    // rules of a hard cone's receivers were), unless it cannot be split.
    let activate = |cell: Cell, class: Class, (own, own_bound): (DVec3, DVec3)| -> Active {
        let kids: Vec<(Cell, Class, (DVec3, DVec3))> = tree
            .children(&cell)
            .into_iter()
            .map(|c| {
                let cc = k.class(&tree, &c);
                let v = if class.forced && cc.forced && tree.splits(&c) {
                    (DVec3::ZERO, DVec3::ZERO)
                } else {
                    k.cell_rule(&tree, &c, cc)
                };
                (c, cc, v)
            })
            .collect();
        if kids.is_empty() {
            return Active {
                key: 0.0,
                value: own,
                err: DVec3::ZERO,
                bounded: false,
                kids,
            };
        }
        let value: DVec3 = kids.iter().map(|c| c.2.0).sum();
        let err = (value - own).abs();
        let r = tree.rect(&cell);
        // A clipped rule samples t at its Gauss points; over more than one texel piece it
        // samples across t's kinks (bilinear) or jumps (nearest), where neither it nor its
        // children's rules converge, and both can miss the same texel: a cell whose lit part
        // lies in one child gets that child's very rule points (estimate exactly 0), and a
        // lit texel between the points of both goes unseen. Measured (module docs): a shaped
        // 256 × 128 rect off by 3.0e-4 at every tolerance, a one-texel texture found to 33 %.
        // So such a cell is not trusted on its estimate. Where a shaping kink may cross it, it
        // is split untrusted down to single pieces, where t is a polynomial and the clipped
        // rule converges (`Class::forced`). Where only the horizon cuts it, its own rule is the
        // bracket rule (`Kernel::bracket`: no sampling) whose error is at most `own_bound`, so
        // the children's sum is off by at most `own_bound + |Σ children − own|` (or the whole
        // contribution's `Kernel::cut_bound`, where smaller): a bound, not an estimate, held to
        // its own share of the tolerance (`BOUND_SHARE`). One-texel textures were missed by up
        // to 100 % while such cells were trusted on their estimates (module docs).
        let (key, err, bounded) = if class.forced {
            (f64::INFINITY, DVec3::ZERO, false)
        } else if class.bracketed {
            let b = (own_bound + err).min(k.cut_bound(tree.t_max(&cell), r));
            (b.max_element() * (ESTIMATE_SHARE / BOUND_SHARE), b, true)
        } else {
            (err.max_element(), err, false)
        };
        Active {
            key,
            value,
            err,
            bounded,
            kids,
        }
    };
    let root = Cell::Node(0);
    let class = k.class(&tree, &root);
    let first = activate(root, class, k.cell_rule(&tree, &root, class));
    // Estimated errors and a-priori bounds are summed apart, each held to its share of rel.
    let mut total = first.value;
    let mut err = [DVec3::ZERO; 2];
    err[usize::from(first.bounded)] += first.err;
    let mut forced = usize::from(first.key == f64::INFINITY);
    let mut heap = BinaryHeap::new();
    heap.push(first);
    let shares = [ESTIMATE_SHARE * rel, BOUND_SHARE * rel];
    for _ in 0..MAX_SPLITS {
        let tiny = 1e-14 * total.abs().max_element();
        let done = forced == 0
            && err.iter().zip(shares).all(|(e, q)| {
                (e.x <= q * total.x.abs() + tiny)
                    && (e.y <= q * total.y.abs() + tiny)
                    && (e.z <= q * total.z.abs() + tiny)
            });
        if done {
            break;
        }
        let Some(top) = heap.pop() else { break };
        if top.key == 0.0 && forced == 0 {
            heap.push(top);
            break;
        }
        if top.key == f64::INFINITY {
            forced -= 1;
        }
        total -= top.value;
        err[usize::from(top.bounded)] -= top.err;
        for (c, class, own) in top.kids {
            let a = activate(c, class, own);
            total += a.value;
            err[usize::from(a.bounded)] += a.err;
            forced += usize::from(a.key == f64::INFINITY);
            heap.push(a);
        }
    }
    // The running sums lose digits as large terms leave: the final value is summed afresh.
    Some(heap.iter().map(|a| a.value).sum())
}

mod kernel;
pub mod tree;

pub use tree::tree;

#[cfg(test)]
mod tests;
