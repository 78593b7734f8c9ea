//! World transforms as usd-core's XformCache computes them, where openusd 0.8 gives other
//! numbers: a time-sampled `orient` between samples ([`usd_slerp`], usd-core's `GfSlerp`) and an
//! op held before a blocked sample ([`super::values::held_before_block`]).

use std::collections::HashMap;

use openusd::usd::{self as ousd, TimeCode};
use openusd::{gf, sdf};
use openusd_schemas::SchemaError;
use openusd_schemas::geom::{XformOp, XformOpKind, XformQuery, Xformable, XformableExt};

/// Local-to-world matrices at one time, computed as openusd's `XformCache` computes them (its
/// `ctm`: climb from the prim to the first ancestor whose matrix is known, one that resets the
/// transform stack, or the pseudo-root, then fold `local * parent` back down), with the same
/// products in the same order, so the same numbers. What differs is what is kept: only the
/// matrices of the ancestors climbed through, by path. openusd's cache keeps every prim's ops
/// as well (about 1 KiB a prim), though each light's own ops are needed once.
pub(super) struct WorldCache {
    time: TimeCode,
    ancestors: HashMap<sdf::Path, gf::Matrix4d>,
}

impl WorldCache {
    pub(super) fn new(time: TimeCode) -> Self {
        WorldCache {
            time,
            ancestors: HashMap::new(),
        }
    }

    /// `prim`'s local transform and whether it resets the transform stack (an identity that
    /// does not reset for a prim that is not Xformable).
    pub(super) fn local_transformation(
        &self,
        prim: &ousd::Prim,
    ) -> std::result::Result<(gf::Matrix4d, bool), SchemaError> {
        let query = XformQuery::for_prim(prim)?;
        Ok((
            query.local_transformation(self.time)?,
            query.resets_xform_stack(),
        ))
    }

    /// `prim`'s local-to-world transform, USD row-vector convention.
    pub(super) fn local_to_world(
        &mut self,
        prim: &ousd::Prim,
    ) -> std::result::Result<gf::Matrix4d, SchemaError> {
        let mut base = gf::Matrix4d::IDENTITY;
        let mut chain = Vec::new();
        let mut current = Some(prim.clone());
        while let Some(p) = current.filter(|p| !p.path().is_abs_root()) {
            if let Some(ctm) = self.ancestors.get(p.path()) {
                base = *ctm;
                break;
            }
            let (local, resets) = self.local_transformation(&p)?;
            // A prim that resets the stack ends the climb: its matrix is its local transform
            // alone.
            current = match resets {
                true => None,
                false => p.parent(),
            };
            chain.push((local, p));
        }
        for (i, (local, p)) in chain.into_iter().enumerate().rev() {
            base = local * base;
            // `prim` itself (i = 0) is not kept: a light is asked for once.
            if i > 0 {
                self.ancestors.insert(p.path().clone(), base);
            }
        }
        Ok(base)
    }
}

use super::values::{held_before_block, is_blocked};
use crate::error::LuxError;

/// Whether `prim` has an xformOp openusd 0.8 evaluates differently from usd-core between
/// samples: a time-sampled orient (see [`usd_slerp`]), or any op with a blocked sample (see
/// [`held_before_block`]).
pub(super) fn needs_own_xform(prim: &ousd::Prim) -> std::result::Result<bool, SchemaError> {
    let Some(x) = Xformable::from_prim(prim.clone())? else {
        return Ok(false);
    };
    let (ops, _) = x.ordered_xform_ops()?;
    ops_need_own_xform(&ops)
}

/// [`needs_own_xform`] of a prim whose ordered ops the caller has already read.
pub(super) fn ops_need_own_xform(ops: &[XformOp]) -> std::result::Result<bool, SchemaError> {
    for op in ops {
        let Some(samples) = op.attribute().time_samples()? else {
            continue;
        };
        let orient = op.kind() == Some(XformOpKind::Orient) && samples.len() > 1;
        if orient || samples.iter().any(|(_, v)| is_blocked(v)) {
            return Ok(true);
        }
    }
    Ok(false)
}

pub(super) fn xform_error(path: &sdf::Path, err: impl std::fmt::Display) -> LuxError {
    LuxError::InvalidTransform {
        light: path.to_string(),
        reason: format!("cannot be read: {err}"),
    }
}

/// The local-to-world matrix of `prim` as usd-core's XformCache computes it, for a prim whose
/// chain holds an op of [`needs_own_xform`]: the local transforms of the chain composed as
/// openusd's XformCache does (row-vector, `local * parent`, stopping at `!resetXformStack!`),
/// with the prims that own such an op evaluated by [`local_as_usd_core`].
pub(super) fn world_as_usd_core(
    cache: &WorldCache,
    prim: &ousd::Prim,
    tc: TimeCode,
) -> std::result::Result<gf::Matrix4d, SchemaError> {
    let mut world = gf::Matrix4d::IDENTITY;
    let mut cur = Some(prim.clone());
    while let Some(p) = cur.filter(|p| !p.path().is_abs_root()) {
        let (local, resets) = match needs_own_xform(&p)? {
            true => local_as_usd_core(&p, tc)?,
            false => cache.local_transformation(&p)?,
        };
        world = world * local;
        if resets {
            break;
        }
        cur = p.parent();
    }
    Ok(world)
}

/// `prim`'s local transform at `tc`, op by op as openusd's XformQuery composes it (an op beside
/// its own inverse is skipped with it), except that an orient op between two time samples is
/// interpolated with [`usd_slerp`], and an op held before a blocked sample is evaluated at the
/// held sample.
fn local_as_usd_core(
    prim: &ousd::Prim,
    tc: TimeCode,
) -> std::result::Result<(gf::Matrix4d, bool), SchemaError> {
    let Some(x) = Xformable::from_prim(prim.clone())? else {
        return Ok((gf::Matrix4d::IDENTITY, false));
    };
    let (ops, resets) = x.ordered_xform_ops()?;
    let mut m = gf::Matrix4d::IDENTITY;
    let mut rev = ops.iter().rev().peekable();
    while let Some(op) = rev.next() {
        if rev.peek().is_some_and(|next| {
            next.is_inverse_op() != op.is_inverse_op() && next.attribute() == op.attribute()
        }) {
            rev.next();
            continue;
        }
        let op_matrix = match interpolated_orient(op, tc)? {
            Some(q) => {
                let rotation = gf::Rotation::from_quat(gf::Quatd {
                    w: q[0],
                    x: q[1],
                    y: q[2],
                    z: q[3],
                });
                let rotation = match op.is_inverse_op() {
                    true => rotation.inverse(),
                    false => rotation,
                };
                gf::Matrix4d::from_quat(rotation.quat())
            }
            None => match op.attribute().time_samples()? {
                Some(samples) => match held_before_block(&samples, tc) {
                    Some(i) => op.op_transform(TimeCode::new(samples[i].0))?,
                    None => op.op_transform(tc)?,
                },
                None => op.op_transform(tc)?,
            },
        };
        m = m * op_matrix;
    }
    Ok((m, resets))
}

/// The value usd-core gives an orient op at `tc` when `tc` lies strictly between two of its
/// time samples, as `[w, x, y, z]`; `None` wherever no interpolation happens (on a sample,
/// outside the samples, EarliestTime, value clips, a blocked sample) and openusd's value is
/// usd-core's.
fn interpolated_orient(
    op: &XformOp,
    tc: TimeCode,
) -> std::result::Result<Option<[f64; 4]>, SchemaError> {
    if op.kind() != Some(XformOpKind::Orient) || tc.is_earliest_time() {
        return Ok(None);
    }
    let t = tc.value();
    let Some(samples) = op.attribute().time_samples()? else {
        return Ok(None);
    };
    let Some(hi) = samples.iter().position(|(st, _)| *st > t) else {
        return Ok(None);
    };
    if hi == 0 || samples[hi - 1].0 == t {
        return Ok(None);
    }
    let (t0, v0) = &samples[hi - 1];
    let (t1, v1) = &samples[hi];
    // USD's Usd_LinearInterpolator: the parametric time in double.
    let alpha = (t - t0) / (t1 - t0);
    Ok(match (v0, v1) {
        (sdf::Value::Quatd(a), sdf::Value::Quatd(b)) => Some(usd_slerp(
            alpha,
            [a.w, a.x, a.y, a.z],
            [b.w, b.x, b.y, b.z],
            Precision::DOUBLE,
        )),
        (sdf::Value::Quatf(a), sdf::Value::Quatf(b)) => Some(usd_slerp(
            alpha,
            [a.w, a.x, a.y, a.z].map(f64::from),
            [b.w, b.x, b.y, b.z].map(f64::from),
            Precision::FLOAT,
        )),
        (sdf::Value::Quath(a), sdf::Value::Quath(b)) => Some(usd_slerp(
            alpha,
            [a.w, a.x, a.y, a.z].map(|h| h.to_f64()),
            [b.w, b.x, b.y, b.z].map(|h| h.to_f64()),
            Precision::HALF,
        )),
        _ => None,
    })
}

/// How a quaternion's scalar type rounds: `store` is the scalar type itself, `compute` the type
/// C++ does its arithmetic in (GfHalf arithmetic happens in float).
#[derive(Clone, Copy)]
struct Precision {
    store: fn(f64) -> f64,
    compute: fn(f64) -> f64,
}

impl Precision {
    const DOUBLE: Precision = Precision {
        store: |x| x,
        compute: |x| x,
    };
    const FLOAT: Precision = Precision {
        store: |x| x as f32 as f64,
        compute: |x| x as f32 as f64,
    };
    // C++ converts double to half through float.
    const HALF: Precision = Precision {
        store: |x| gf::f16::from_f32(x as f32).to_f64(),
        compute: |x| x as f32 as f64,
    };
}

/// usd-core's `GfSlerp(alpha, q0, q1)` for `GfQuatd`/`GfQuatf`/`GfQuath`, operation by operation
/// (pxr/base/gf/quat.template.cpp): the cosine in double from the scalar-typed dot product, the
/// angle and its sine rounded to the scalar type, the weights in double but applied as scalars.
/// openusd 0.8 slerps in double throughout (and switches to a normalised lerp at cos > 0.9995),
/// so a `quatf` orient between samples came out a few float ulps away from usd-core.
fn usd_slerp(alpha: f64, q0: [f64; 4], q1: [f64; 4], p: Precision) -> [f64; 4] {
    let (s, c) = (p.store, p.compute);
    // GfDot of the imaginary parts returns the scalar type; + real * real in the compute type.
    let dot_i = s(c(c(c(q0[1] * q1[1]) + c(q0[2] * q1[2])) + c(q0[3] * q1[3])));
    let mut cos_theta = c(dot_i + c(q0[0] * q1[0]));
    let mut flip = false;
    if cos_theta < 0.0 {
        cos_theta = -cos_theta;
        flip = true;
    }
    let (scale0, mut scale1) = if 1.0 - cos_theta > 0.00001 {
        let theta = s(cos_theta.acos());
        let sin_theta = s(theta.sin());
        (
            ((1.0 - alpha) * theta).sin() / sin_theta,
            (alpha * theta).sin() / sin_theta,
        )
    } else {
        (1.0 - alpha, alpha)
    };
    if flip {
        scale1 = -scale1;
    }
    // `scale * q` converts the double scale to the scalar type first.
    let (w0, w1) = (s(scale0), s(scale1));
    std::array::from_fn(|i| s(c(s(c(q0[i] * w0)) + s(c(q1[i] * w1)))))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `GfSlerp` results printed by usd-core 26.11 (`Gf.Slerp(alpha, Gf.Quat?(..), ..)`), bit for
    /// bit: the float and half results depend on where C++ rounds to the scalar type.
    #[test]
    fn usd_slerp_matches_gf_slerp() {
        // (precision, alpha, q0, q1, usd-core result), quaternions as [w, x, y, z].
        type Case = (Precision, f64, [f64; 4], [f64; 4], [f64; 4]);
        let cases: &[Case] = &[
            (
                Precision::FLOAT,
                0.125,
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
                [0.9807853102684021, 0.0, 0.19509032368659973, 0.0],
            ),
            (
                Precision::FLOAT,
                0.3,
                [0.9238795042037964, 0.0, 0.3826833963394165, 0.0],
                [0.5; 4],
                [
                    0.8585266470909119,
                    0.16828618943691254,
                    0.454193115234375,
                    0.16828618943691254,
                ],
            ),
            // Opposite hemispheres: the second quaternion is flipped.
            (
                Precision::FLOAT,
                0.6,
                [0.5; 4],
                [-0.5, -0.5, -0.5, -0.4999000132083893],
                [
                    0.5000060200691223,
                    0.5000060200691223,
                    0.5000060200691223,
                    0.4999459981918335,
                ],
            ),
            (
                Precision::HALF,
                0.125,
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
                [0.98046875, 0.0, 0.195068359375, 0.0],
            ),
            (
                Precision::HALF,
                0.3,
                [0.923828125, 0.0, 0.382568359375, 0.0],
                [0.5; 4],
                [0.8583984375, 0.168212890625, 0.4541015625, 0.168212890625],
            ),
            (
                Precision::DOUBLE,
                0.125,
                [1.0, 0.0, 0.0, 0.0],
                [0.0, 0.0, 1.0, 0.0],
                [0.9807852804032304, 0.0, 0.19509032201612825, 0.0],
            ),
            (
                Precision::DOUBLE,
                0.3,
                [0.9238795, 0.0, 0.3826834, 0.0],
                [0.5; 4],
                [
                    0.8585266761934467,
                    0.1682861908577956,
                    0.45419314706355307,
                    0.1682861908577956,
                ],
            ),
        ];
        for (i, (p, alpha, q0, q1, want)) in cases.iter().enumerate() {
            let got = usd_slerp(*alpha, *q0, *q1, *p);
            for k in 0..4 {
                assert!(
                    (got[k] - want[k]).abs() <= 1e-15,
                    "case {i}: {got:?} vs usd-core {want:?}"
                );
            }
        }
    }
}
