//! The tile tables of a textured dome (each piece's moment, grouped in tiles under bounding
//! caps, the tiles in blocks under bounding caps, built once) and the walk over them that gives
//! a receiver's `E(n)`, or its part inside a convex intersection of half-spaces (a masked dome's
//! portal piece, DESIGN.md §8 P2).

use glam::DVec3;
use rayon::prelude::*;

use super::clip::{Clip, exact};
use super::horizon::HorizonCurve;
use super::pieces::Domain;
use super::{DomeIrradiance, REL_TOL, add};
use crate::prepare::texture::DomeFormat;

/// Pieces per table entry at most (the tile size grows beyond it).
const MAX_TILES: usize = 1 << 20;

struct Tile {
    grid: usize,
    ix: (usize, usize),
    iy: (usize, usize),
    v: [f64; 9],
    /// Cap centre and angular radius; radius = ∞ forces a descent.
    centre: DVec3,
    radius: f64,
    /// `sin(radius)`, kept: a receiver's walk tests every tile (for a masked dome, once per
    /// portal piece), and the sine was most of that walk's cost.
    sin_radius: f64,
}

/// A block of up to [`BLOCK`] × [`BLOCK`] neighbouring tiles of one grid (a contiguous range
/// of `Tables::tiles`): their summed moment under a cap bounding all of theirs. The walk tests
/// blocks first and only a crossed block's tiles, so a receiver costs the blocks plus the tiles
/// along its clip lines rather than every tile: a masked dome's portal piece clips a small
/// part of the sphere, and its walk tested all 524,288 tiles of a 1024 × 512 map each time.
struct Block {
    tiles: std::ops::Range<usize>,
    v: [f64; 9],
    centre: DVec3,
    radius: f64,
    sin_radius: f64,
}

/// Tiles per block side.
const BLOCK: usize = 16;

pub(super) struct Tables {
    tiles: Vec<Tile>,
    blocks: Vec<Block>,
    single: bool,
}

/// Where a cap lies with respect to the lit region, the intersection of the half-spaces
/// `m̂ᵢ·d > 0`.
#[derive(PartialEq)]
enum Side {
    /// Inside every half-space.
    Lit,
    /// Outside one of them.
    Dark,
    Crossed,
}

/// Where a cap lies with respect to one half-space `m̂·d > 0` (Dark: outside it; a cap of
/// radius ≥ 90° is taken as crossed).
fn side_of(mhat: DVec3, centre: DVec3, radius: f64, sin_radius: f64) -> Side {
    if radius >= 0.5 * std::f64::consts::PI {
        return Side::Crossed;
    }
    let r = sin_radius + 1e-12;
    let s = mhat.dot(centre);
    if s < -r {
        Side::Dark
    } else if s > r {
        Side::Lit
    } else {
        Side::Crossed
    }
}

/// Where a cap lies with respect to the lit region, the intersection of the half-spaces.
fn side(mhats: &[DVec3], centre: DVec3, radius: f64, sin_radius: f64) -> Side {
    let mut lit = true;
    for mhat in mhats {
        match side_of(*mhat, centre, radius, sin_radius) {
            Side::Dark => return Side::Dark,
            Side::Crossed => lit = false,
            Side::Lit => {}
        }
    }
    if lit { Side::Lit } else { Side::Crossed }
}

/// The clips whose circle may meet a crossed cap (those [`side_of`] does not find wholly lit):
/// a clip positive over the whole cap has no root in the piece, no crossing on its edges and
/// no vertex inside it, so [`exact`] gives the same value without it, and the five clips of a
/// portal piece (four edges and the horizon) cost a crossed piece along one edge one clip's
/// roots per line rather than five.
fn meeting<'a>(
    clips: &[Clip<'a>],
    hats: &[DVec3],
    centre: DVec3,
    radius: f64,
    sin_radius: f64,
) -> Vec<Clip<'a>> {
    clips
        .iter()
        .zip(hats)
        .filter(|(_, h)| side_of(**h, centre, radius, sin_radius) != Side::Lit)
        .map(|(c, _)| *c)
        .collect()
}

/// `tex ⊗ v`, channel-major: a moment's RGB × xyz entries.
fn outer(tex: DVec3, v: DVec3) -> [f64; 9] {
    [
        tex.x * v.x,
        tex.x * v.y,
        tex.x * v.z,
        tex.y * v.x,
        tex.y * v.y,
        tex.y * v.z,
        tex.z * v.x,
        tex.z * v.y,
        tex.z * v.z,
    ]
}

impl DomeIrradiance {
    /// `V = ∫_piece L d w dd` (RGB × xyz, channel-major).
    fn moment(&self, grid: usize, ix: usize, iy: usize) -> [f64; 9] {
        let p = self.piece(grid, ix, iy);
        let dom = self.geom.domain(&p);
        if dom == Domain::Outside {
            return [0.0; 9];
        }
        let mut f = |d: DVec3, tex: DVec3, j: f64| outer(tex, d * (self.weight(d) * j));
        // A latlong piece always has a cap (`Geometry::cap`); its moment comes from the axis
        // factors (latlong.rs), and its cap (two sin_cos per piece, once a quarter of a dome
        // map's time) is not needed for that.
        match self.conformal {
            Some(w) if self.sweeps() => {
                let axes = self.axes();
                let (cx, ry) = (&axes.cols[ix], &axes.rows[iy]);
                let k = w
                    * (2.0 * std::f64::consts::PI / self.geom.w)
                    * (std::f64::consts::PI / self.geom.h);
                let corners = [
                    (p.ax.i0, p.ay.i0, 0, 0),
                    (p.ax.i1, p.ay.i0, 1, 0),
                    (p.ax.i0, p.ay.i1, 0, 1),
                    (p.ax.i1, p.ay.i1, 1, 1),
                ];
                let mut v = [0.0; 9];
                for (i, j, a, b) in corners {
                    let m = DVec3::new(
                        cx[a][0] * ry[b][0],
                        cx[a][1] * ry[b][1],
                        cx[a][2] * ry[b][0],
                    ) * k;
                    let tex = crate::cpu::texture::tex_fetch(&self.img, i, j);
                    add(&mut v, &outer(tex, m));
                }
                v
            }
            _ => self.whole_piece(&p, dom, 0, &mut f),
        }
    }
    pub(super) fn tables(&self) -> &Tables {
        self.tables.get_or_init(|| self.build())
    }

    fn build(&self) -> Tables {
        let count: usize = self.grids.iter().map(|g| g.xs.len() * g.ys.len()).sum();
        let tsize = ((count as f64 / MAX_TILES as f64).sqrt().ceil() as usize).max(1);
        // Tiles in block order (blocks of BLOCK × BLOCK tiles, row by row), each block's
        // tiles contiguous.
        let mut specs = vec![];
        let mut block = 0;
        for (gi, g) in self.grids.iter().enumerate() {
            let (nx, ny) = (g.xs.len().div_ceil(tsize), g.ys.len().div_ceil(tsize));
            for by in (0..ny).step_by(BLOCK) {
                for bx in (0..nx).step_by(BLOCK) {
                    for ty in by..(by + BLOCK).min(ny) {
                        for tx in bx..(bx + BLOCK).min(nx) {
                            let (x, y) = (tx * tsize, ty * tsize);
                            specs.push((
                                block,
                                gi,
                                (x, (x + tsize).min(g.xs.len())),
                                (y, (y + tsize).min(g.ys.len())),
                            ));
                        }
                    }
                    block += 1;
                }
            }
        }
        let tiles: Vec<(usize, Tile)> = specs
            .into_par_iter()
            .filter_map(|(b, grid, ix, iy)| self.tile(grid, ix, iy).map(|t| (b, t)))
            .collect();
        let mut ranges = vec![];
        let mut start = 0;
        for i in 1..=tiles.len() {
            if i == tiles.len() || tiles[i].0 != tiles[start].0 {
                ranges.push(start..i);
                start = i;
            }
        }
        let tiles: Vec<Tile> = tiles.into_iter().map(|(_, t)| t).collect();
        let blocks = ranges
            .into_par_iter()
            .map(|r| Self::block(&tiles, r))
            .collect();
        Tables {
            tiles,
            blocks,
            single: tsize == 1,
        }
    }

    /// The block over `tiles[range]`: their moments summed, and a cap about the middle tile's
    /// centre that holds every tile's cap (unbounded where one is).
    fn block(tiles: &[Tile], range: std::ops::Range<usize>) -> Block {
        let part = &tiles[range.clone()];
        let mut v = [0.0; 9];
        for t in part {
            add(&mut v, &t.v);
        }
        let centre = part[part.len() / 2].centre;
        let radius = part
            .iter()
            .map(|t| centre.cross(t.centre).length().atan2(centre.dot(t.centre)) + t.radius)
            .fold(0.0, f64::max);
        Block {
            tiles: range,
            v,
            centre,
            radius,
            sin_radius: radius.sin(),
        }
    }

    fn tile(&self, grid: usize, ix: (usize, usize), iy: (usize, usize)) -> Option<Tile> {
        let mut v = [0.0; 9];
        let mut caps = vec![];
        let mut bounded = true;
        for j in iy.0..iy.1 {
            for i in ix.0..ix.1 {
                let p = self.piece(grid, i, j);
                if self.geom.domain(&p) == Domain::Outside {
                    continue;
                }
                add(&mut v, &self.moment(grid, i, j));
                match self.geom.cap(&p) {
                    Some(c) => caps.push(c),
                    None => bounded = false,
                }
            }
        }
        if caps.is_empty() && bounded {
            return None;
        }
        let centre = caps.get(caps.len() / 2).map_or(DVec3::Z, |c| c.0);
        let radius = if bounded {
            caps.iter()
                .map(|(c, r)| centre.cross(*c).length().atan2(centre.dot(*c)) + r)
                .fold(0.0, f64::max)
        } else {
            f64::INFINITY
        };
        Some(Tile {
            grid,
            ix,
            iy,
            v,
            centre,
            radius,
            sin_radius: radius.sin(),
        })
    }

    /// `E(n)` (RGB) for a unit world normal `n`: the exact integral of the filtered texture
    /// (module docs). Multiply by the dome's `intensity · 2^exposure · color ⊙ temperature` and
    /// `diffuse` outside.
    /// A latlong map under a conformal frame takes the sweep (latlong.rs: the same sum, without
    /// building the tables).
    pub fn irradiance(&self, n: DVec3) -> DVec3 {
        self.sweep(n)
            .unwrap_or_else(|| self.irradiance_within(n, &[]))
    }

    /// `∫ L(ω) max(0, n·ω) dω` over the directions ω with `k·ω ≥ 0` for every `k` in `planes`
    /// (world vectors), exactly as [`DomeIrradiance::irradiance`] (which is the case of no
    /// plane): a convex spherical polygon clipped at the horizon, e.g. a portal piece seen from
    /// a receiver (DESIGN.md §8 P2 mask mode, `cpu/portal.rs`). Each world half-space is the
    /// dome-space half-space `(A_effᵀ k)·d ≥ 0` (`k·ω ∝ k·A_eff d`, §6 D1), the horizon
    /// included. A tile or piece is added wholesale (`m · V`) when its cap is inside all of
    /// them, skipped when it is outside any one, and integrated exactly ([`exact`]) otherwise.
    pub fn irradiance_within(&self, n: DVec3, planes: &[DVec3]) -> DVec3 {
        let t = self.tables();
        let m = self.frame.horizon(n);
        let ms: Vec<DVec3> = std::iter::once(m)
            .chain(planes.iter().map(|k| self.frame.horizon(*k)))
            .collect();
        let hats: Vec<DVec3> = ms.iter().map(|v| v.normalize()).collect();
        let disk = matches!(self.format, DomeFormat::MirroredBall | DomeFormat::Angular);
        // On a disk image a great circle through the rim's direction −Z (to within 1e-7 rad) is
        // drawn as a diameter: then the clip is that straight line through the image's centre
        // ([`Clip::line`]), and what this leaves out is within a cap of radius 1e-7 about −Z
        // (< 4e-14 sr).
        // A portal edge parallel to the dome's Z axis gives such a circle; its [`HorizonCurve`]
        // would jump across the image there. Not applied to the unmasked dome (no plane), which
        // stays as it was.
        let lines: Vec<bool> = hats
            .iter()
            .map(|h| disk && !planes.is_empty() && !(h.z.abs() > 1e-7))
            .collect();
        let curves: Vec<Option<HorizonCurve>> = ms
            .iter()
            .zip(&lines)
            .map(|(v, line)| (disk && !line).then(|| HorizonCurve::new(self.format, *v)))
            .collect();
        let clips: Vec<Clip> = ms
            .iter()
            .zip(curves.iter().zip(&lines))
            .map(|(m, (c, line))| Clip {
                m: *m,
                curve: c.as_ref(),
                line: *line,
            })
            .collect();
        let dot = |v: &[f64; 9]| {
            DVec3::new(
                m.dot(DVec3::new(v[0], v[1], v[2])),
                m.dot(DVec3::new(v[3], v[4], v[5])),
                m.dot(DVec3::new(v[6], v[7], v[8])),
            )
        };
        // Blocks first; a crossed block's tiles; a crossed tile's pieces.
        let mut e = DVec3::ZERO;
        let mut crossed_tiles = vec![];
        for b in &t.blocks {
            match side(&hats, b.centre, b.radius, b.sin_radius) {
                Side::Lit => e += dot(&b.v),
                Side::Dark => {}
                Side::Crossed => crossed_tiles.extend(&t.tiles[b.tiles.clone()]),
            }
        }
        for tile in crossed_tiles {
            match side(&hats, tile.centre, tile.radius, tile.sin_radius) {
                Side::Lit => e += dot(&tile.v),
                Side::Dark => {}
                Side::Crossed if t.single && tile.radius.is_finite() => {
                    let meet = meeting(&clips, &hats, tile.centre, tile.radius, tile.sin_radius);
                    e += self.crossed(tile.grid, tile.ix.0, tile.iy.0, m, &meet);
                }
                Side::Crossed => {
                    for j in tile.iy.0..tile.iy.1 {
                        for i in tile.ix.0..tile.ix.1 {
                            let p = self.piece(tile.grid, i, j);
                            if self.geom.domain(&p) == Domain::Outside {
                                continue;
                            }
                            let cap = self.geom.cap(&p).map(|(c, r)| (c, r, r.sin()));
                            match cap.map(|(c, r, sr)| side(&hats, c, r, sr)) {
                                Some(Side::Lit) => e += dot(&self.moment(tile.grid, i, j)),
                                Some(Side::Dark) => {}
                                _ => {
                                    let meet = match cap {
                                        Some((c, r, sr)) => meeting(&clips, &hats, c, r, sr),
                                        None => clips.clone(),
                                    };
                                    e += self.crossed(tile.grid, i, j, m, &meet);
                                }
                            }
                        }
                    }
                }
            }
        }
        e
    }

    /// `∫ L(ω) max(0, n·ω) dω` over the directions of the convex planar polygon `q` (vectors
    /// from the receiver to its vertices, in order): [`DomeIrradiance::irradiance_within`] of
    /// its [`edge_planes`]; 0 for a polygon of no solid angle.
    pub fn irradiance_over_polygon(&self, n: DVec3, q: &[DVec3]) -> DVec3 {
        match edge_planes(q) {
            Some(planes) => self.irradiance_within(n, &planes),
            None => DVec3::ZERO,
        }
    }

    /// One piece's share of `E`, clipped exactly at the horizon and the other clips (the first
    /// clip is the horizon `m`).
    pub(super) fn crossed(
        &self,
        grid: usize,
        i: usize,
        j: usize,
        m: DVec3,
        clips: &[Clip],
    ) -> DVec3 {
        let p = self.piece(grid, i, j);
        let delta = self.geom.cap(&p).map_or(0.5, |c| c.1.min(0.5));
        let v = exact(
            &self.geom,
            &self.img,
            &p,
            clips,
            self.order(delta) + 2,
            REL_TOL * self.scale(&p) * m.length(),
            &mut |d, tex, jac| {
                let k = m.dot(d) * self.weight(d) * jac;
                [tex.x * k, tex.y * k, tex.z * k]
            },
        );
        DVec3::from_array(v)
    }
}

/// The half-spaces `k·ω ≥ 0` (unit world `k`) whose intersection is the convex planar polygon
/// `q` (vectors from x to its vertices, in order) seen from x: one per edge, the plane through x
/// and the edge, `σ (q_i × q_{i+1})` with σ the sign of `(Σ q_i × q_{i+1})·q_0` (twice the
/// polygon's vector area dotted with a vertex: positive when the vertices run
/// counter-clockwise about the normal pointing away from x, when every `q_i × q_{i+1}` points
/// inward). `None` for a polygon of no solid angle (a sliver seen edge-on, which the visibility
/// split can leave): its edge planes would not bound it. An edge whose endpoints coincide is
/// left out (its neighbours meet there).
pub fn edge_planes(q: &[DVec3]) -> Option<Vec<DVec3>> {
    let k = q.len();
    if k < 3 {
        return None;
    }
    let area2: DVec3 = (0..k).map(|i| q[i].cross(q[(i + 1) % k])).sum();
    let scale = q.iter().map(|v| v.length()).fold(0.0, f64::max);
    let volume = area2.dot(q[0]);
    if !(volume.abs() > 1e-12 * scale * scale * scale) {
        return None;
    }
    let sigma = volume.signum();
    let mut out = Vec::with_capacity(k);
    for i in 0..k {
        let (a, b) = (q[i], q[(i + 1) % k]);
        let c = a.cross(b);
        let l = c.length();
        if l > 1e-12 * a.length() * b.length() {
            out.push(c * (sigma / l));
        }
    }
    Some(out)
}
