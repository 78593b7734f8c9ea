//! The WGSL irradiance kernel's quadrature rule replayed in f64 (`shaders/irradiance/line.wgsl`
//! and `outer.wgsl`, constants in [`crate::rules`]): the same pieces, maps and breakpoints as
//! the reference, integrated as the kernel integrates them. Tests hold it within 1e-5 of the
//! reference, which separates the kernel's quadrature error from its f32 rounding. It lives
//! here, not in the reference: the reference stops on its own estimates only.

use glam::DVec3;

use crate::cpu::irradiance::chart::Chart;
use crate::cpu::irradiance::{Rule, critical, irradiance_with, outer};
use crate::prepare::Prepared;
use crate::query::Reference;
use crate::rules::{
    IRR_GL_INNER, IRR_INNER_DEPTH, IRR_INNER_TOL, IRR_OUTER_DEPTH, IRR_OUTER_TOL, MAX_U_SPAN,
    gauss_legendre, gk15,
};

/// The kernel's rule: per outer span the Gauss–Kronrod 7/15 pair, halved while the pair
/// disagrees by more than `IRR_OUTER_TOL` (relative), at most `IRR_OUTER_DEPTH` times; per
/// inner span `IRR_GL_INNER`-point Gauss–Legendre, halved while halves and parent differ by more
/// than `IRR_INNER_TOL`, at most `IRR_INNER_DEPTH` times; both depth first, in the order of the
/// WGSL.
pub(crate) struct KernelRule {
    inner_x: Vec<f64>,
    inner_w: Vec<f64>,
}

impl KernelRule {
    pub fn new() -> Self {
        let (inner_x, inner_w) = gauss_legendre(IRR_GL_INNER);
        KernelRule { inner_x, inner_w }
    }
}

impl Rule for KernelRule {
    fn outer(&self, f: &mut impl FnMut(f64) -> DVec3) -> DVec3 {
        let mut sum = DVec3::ZERO;
        let mut stack = vec![(0.0, 1.0, 0)];
        while let Some((s0, s1, depth)) = stack.pop() {
            let (k, err) = gk15(f, s0, s1);
            if depth + 1 >= IRR_OUTER_DEPTH || err <= IRR_OUTER_TOL * k.abs().max_element() {
                sum += k;
            } else {
                let mid = 0.5 * (s0 + s1);
                stack.push((mid, s1, depth + 1));
                stack.push((s0, mid, depth + 1));
            }
        }
        sum
    }

    fn inner(&self, f: &mut impl FnMut(f64) -> DVec3) -> DVec3 {
        let mut rule = |s0: f64, s1: f64| -> DVec3 {
            let h = s1 - s0;
            self.inner_x
                .iter()
                .zip(&self.inner_w)
                .map(|(x, w)| f(s0 + h * x) * (w * h))
                .sum()
        };
        let mut sum = DVec3::ZERO;
        let mut stack = vec![(0.0, 1.0, rule(0.0, 1.0), 0)];
        while let Some((s0, s1, q, depth)) = stack.pop() {
            let mid = 0.5 * (s0 + s1);
            let (ql, qr) = (rule(s0, mid), rule(mid, s1));
            let fine = ql + qr;
            if depth + 1 >= IRR_INNER_DEPTH
                || (fine - q).abs().max_element() <= IRR_INNER_TOL * fine.abs().max_element()
            {
                sum += fine;
            } else {
                stack.push((mid, s1, qr, depth + 1));
                stack.push((s0, mid, ql, depth + 1));
            }
        }
        sum
    }

    fn max_u_span(&self) -> Option<f64> {
        Some(MAX_U_SPAN)
    }

    fn unshaped_closed_form(&self, tan_mapped: bool) -> bool {
        tan_mapped
    }

    /// The kernel's outer breakpoints: the shaping's (`critical_ys`) and an IES profile's
    /// grid surfaces that meet the chart (`critical::ies_ys`; critical.wgsl `ies_ys`).
    fn chart(&self, p: &Prepared, chart: &Chart, n: DVec3) -> DVec3 {
        if p.profile.dark || !(chart.jac > 0.0) || !chart.jac.is_finite() {
            return DVec3::ZERO;
        }
        let mut ys = critical::critical_ys(p, chart, n);
        if let Some(ies) = &p.ies {
            critical::add_ies_ys(p, ies, chart, n, &mut ys);
        }
        outer::chart_integral(p, chart, n, &ys, self)
    }
}

/// irradiance at `x` on a receiver with normal `n` (any length; 0 for a zero normal) by the
/// kernel's rule in f64 (closed forms as the reference).
pub fn kernel_rule_irradiance(r: &Reference, x: DVec3, n: DVec3) -> DVec3 {
    let len = n.length();
    if !(len > 0.0 && len.is_finite()) {
        return DVec3::ZERO;
    }
    irradiance_with(&r.p, x, n / len, &KernelRule::new())
}
