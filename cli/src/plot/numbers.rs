//! Numbers as the pictures and reports print them, in one place: 1-2-5 steps and tick values for
//! axes, rings and colour bars, and decimals without trailing zeros.

/// How values map to positions on an axis or colour bar.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Scale {
    /// log10: falloff maps span decades (default).
    #[default]
    Log,
    Linear,
}

/// A "nice" step (1, 2 or 5 times a power of ten) for about `n` divisions of a span of `span`;
/// 1 for a span that is not a positive finite number.
pub fn nice_step(span: f64, n: f64) -> f64 {
    // NaN fails is_finite.
    if !span.is_finite() || span <= 0.0 {
        return 1.0;
    }
    let raw = span / n;
    let p = 10f64.powf(raw.log10().floor());
    let f = raw / p;
    let m = if f <= 1.0 {
        1.0
    } else if f <= 2.0 {
        2.0
    } else if f <= 5.0 {
        5.0
    } else {
        10.0
    };
    m * p
}

/// The most ticks [`ticks`] returns (a linear range holds about five; a log range one per decade
/// of at most 308 + 324).
const MAX_TICKS: usize = 700;

/// Tick values inside `range`: decades (plus 2 and 5 when few) on a log scale, 1-2-5 steps (about
/// five) on a linear one. A range too narrow for its 1-2-5 step to be a normal float (`0,1e-323`)
/// is ticked at its two ends; never more than [`MAX_TICKS`] values.
pub fn ticks(range: (f64, f64), scale: Scale) -> Vec<f64> {
    let (lo, hi) = range;
    if !lo.is_finite() || !hi.is_finite() || hi <= lo {
        return vec![];
    }
    match scale {
        Scale::Log => {
            let lo = lo.max(f64::MIN_POSITIVE);
            let (k0, k1) = (lo.log10().ceil() as i32, hi.log10().floor() as i32);
            let decades: Vec<f64> = (k0..=k1).map(|k| 10f64.powi(k)).collect();
            if decades.len() >= 3 {
                return decades;
            }
            let mut t: Vec<f64> = (k0 - 1..=k1)
                .flat_map(|k| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(k)))
                .filter(|v| *v >= lo * (1.0 - 1e-12) && *v <= hi * (1.0 + 1e-12))
                .collect();
            t.dedup();
            t
        }
        Scale::Linear => {
            let step = nice_step(hi - lo, 5.0);
            let (first, last) = ((lo / step).ceil(), (hi / step).floor());
            // The step of a subnormal span rounds to 0 or loses its digits: the ends instead.
            // A NaN end (an infinite quotient's) makes the span NaN.
            let span = last - first;
            if !step.is_normal() || span.is_nan() || span >= MAX_TICKS as f64 || first > last {
                return vec![lo, hi];
            }
            (first as i64..=last as i64)
                .map(|k| k as f64 * step)
                .collect()
        }
    }
}

/// `v` with `places` decimals, trailing zeros (and a trailing point) removed; never "-0".
pub fn decimal(v: f64, places: usize) -> String {
    let s = format!("{v:.places$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        &s
    };
    if s == "-0" { "0".into() } else { s.to_string() }
}

/// A compact label: plain decimals from 0.001 to 99999 (at most four significant decimals),
/// otherwise `1e6`-style.
pub fn label(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if (1e-3..1e5).contains(&a) {
        // Four decimals may still be too many significant digits for values ≥ 1000.
        let digits = (a.log10().floor() as i32 + 1).max(1) as usize;
        if digits >= 4 {
            format!("{v:.0}")
        } else {
            decimal(v, 4)
        }
    } else {
        let e = a.log10().floor() as i32;
        let m = v / 10f64.powi(e);
        if (m.abs() - 1.0).abs() < 1e-9 {
            format!("{}1e{e}", if v < 0.0 { "-" } else { "" })
        } else {
            format!("{m:.1}e{e}")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_steps() {
        assert_eq!(nice_step(100.0, 5.0), 20.0);
        assert_eq!(nice_step(7.0, 4.0), 2.0);
        assert_eq!(nice_step(0.03, 3.0), 0.01);
        assert_eq!(nice_step(0.0, 3.0), 1.0);
        assert_eq!(nice_step(10.0, 5.0), 2.0);
        assert_eq!(nice_step(1000.0, 4.0), 500.0);
        assert_eq!(nice_step(0.3, 3.0), 0.1);
        assert_eq!(nice_step(0.0, 4.0), 1.0);
    }

    #[test]
    fn more_ticks_and_labels() {
        assert_eq!(
            ticks((0.0, 10.0), Scale::Linear),
            [0.0, 2.0, 4.0, 6.0, 8.0, 10.0]
        );
        assert_eq!(ticks((0.5, 500.0), Scale::Log), [1.0, 10.0, 100.0]);
        assert_eq!(ticks((3.0, 30.0), Scale::Log), [5.0, 10.0, 20.0]);
        assert_eq!(label(1234.6), "1235");
        assert_eq!(label(0.25), "0.25");
        assert_eq!(label(2e6), "2.0e6");
        assert_eq!(label(1e-5), "1e-5");
    }

    #[test]
    fn ticks_and_labels() {
        assert_eq!(
            ticks((0.5, 2000.0), Scale::Log),
            vec![1.0, 10.0, 100.0, 1000.0]
        );
        assert_eq!(ticks((0.3, 4.0), Scale::Log), vec![0.5, 1.0, 2.0]);
        assert_eq!(
            ticks((0.0, 1.0), Scale::Linear),
            vec![0.0, 0.2, 0.4, 0.6000000000000001, 0.8, 1.0]
        );
        assert_eq!(label(0.25), "0.25");
        assert_eq!(label(1000.0), "1000");
        assert_eq!(label(1e6), "1e6");
        assert_eq!(label(2.5e-5), "2.5e-5");
        assert_eq!(label(12.5), "12.5");
    }

    /// A valid but subnormal range is ticked at its ends (it once made ~9e18 ticks).
    #[test]
    fn ranges_too_narrow_for_a_step_are_ticked_at_their_ends() {
        assert_eq!(ticks((0.0, 1e-323), Scale::Linear), [0.0, 1e-323]);
        let narrow = ticks((1.0, 1.0 + 1e-15), Scale::Linear);
        assert!(
            narrow.iter().all(|t| (1.0..=1.0 + 1e-15).contains(t)),
            "{narrow:?}"
        );
        assert!(ticks((f64::MIN_POSITIVE, f64::MAX), Scale::Log).len() <= MAX_TICKS);
        assert!(ticks((-1.0, 10.0), Scale::Linear).contains(&0.0));
    }

    #[test]
    fn decimals_lose_their_trailing_zeros() {
        assert_eq!(decimal(2.5, 3), "2.5");
        assert_eq!(decimal(3.0, 4), "3");
        assert_eq!(decimal(-0.0001, 3), "0");
        assert_eq!(decimal(120.0, 0), "120");
    }
}
