//! Axes: a data range rounded out to "nice" tick values (1, 2, 5 x 10^k on a
//! linear scale, decades on a log scale), the map from data to pixels, and
//! tick labels.

/// Linear or base-10 logarithmic scale.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scale {
    /// Equal steps are equal distances.
    Linear,
    /// Equal ratios are equal distances.
    Log10,
}

/// A tick: its data value, its label (empty for a minor tick).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Tick {
    /// Data value.
    pub value: f64,
    /// Label; empty for a minor tick.
    pub label: String,
}

/// An axis: data range [lo, hi] on `scale`, drawn from pixel `px_lo` to `px_hi`.
#[derive(Debug, Clone)]
pub(crate) struct Axis {
    /// Low end of the data range.
    pub lo: f64,
    /// High end of the data range.
    pub hi: f64,
    /// Scale.
    pub scale: Scale,
    /// Pixel of `lo`.
    pub px_lo: f64,
    /// Pixel of `hi`.
    pub px_hi: f64,
    /// Ticks inside [lo, hi].
    pub ticks: Vec<Tick>,
}

/// Smallest and largest finite value of `values` (positive only on a log
/// scale), or `None` when there is none.
pub(crate) fn data_range(values: impl Iterator<Item = f64>, scale: Scale) -> Option<(f64, f64)> {
    let ok = |v: &f64| v.is_finite() && (scale == Scale::Linear || *v > 0.0);
    values.filter(ok).fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

impl Axis {
    /// An axis over the data range `lo..=hi` (finite, lo <= hi, positive on a
    /// log scale), rounded out to nice ticks, about `target_ticks` of them.
    pub fn new(lo: f64, hi: f64, scale: Scale, target_ticks: usize) -> Self {
        let (lo, hi, ticks) = match scale {
            Scale::Linear => linear_ticks(lo, hi, target_ticks.max(2)),
            Scale::Log10 => log_ticks(lo, hi),
        };
        Axis { lo, hi, scale, px_lo: 0.0, px_hi: 1.0, ticks }
    }

    /// An axis over exactly `lo..=hi` (lo < hi) with nice ticks inside it;
    /// for images, whose extent must not be rounded out.
    pub fn exact(lo: f64, hi: f64, target_ticks: usize) -> Self {
        let (_, _, ticks) = linear_ticks(lo, hi, target_ticks.max(2));
        let eps = (hi - lo).abs() * 1e-9;
        let ticks =
            ticks.into_iter().filter(|t| t.value >= lo - eps && t.value <= hi + eps).collect();
        Axis { lo, hi, scale: Scale::Linear, px_lo: 0.0, px_hi: 1.0, ticks }
    }

    /// The same axis drawn between pixels `px_lo` and `px_hi`.
    pub fn placed(mut self, px_lo: f64, px_hi: f64) -> Self {
        self.px_lo = px_lo;
        self.px_hi = px_hi;
        self
    }

    /// Pixel of data value `v`, or `None` if `v` cannot be drawn (not finite,
    /// or not positive on a log scale).
    pub fn map(&self, v: f64) -> Option<f64> {
        let t = match self.scale {
            Scale::Linear => (v - self.lo) / (self.hi - self.lo),
            Scale::Log10 if v > 0.0 => {
                (v.log10() - self.lo.log10()) / (self.hi.log10() - self.lo.log10())
            }
            Scale::Log10 => return None,
        };
        let p = self.px_lo + t * (self.px_hi - self.px_lo);
        p.is_finite().then_some(p)
    }
}

/// Step of 1, 2 or 5 x 10^k nearest above `raw`.
fn nice_step(raw: f64) -> f64 {
    let e = raw.log10().floor();
    let base = 10f64.powf(e);
    let f = raw / base;
    let m = if f <= 1.0 {
        1.0
    } else if f <= 2.0 {
        2.0
    } else if f <= 5.0 {
        5.0
    } else {
        10.0
    };
    m * base
}

/// Range widened around a single value `v` (a constant series).
fn widen(v: f64) -> (f64, f64) {
    let pad = if v == 0.0 { 1.0 } else { v.abs() * 0.1 };
    (v - pad, v + pad)
}

fn linear_ticks(lo: f64, hi: f64, target: usize) -> (f64, f64, Vec<Tick>) {
    let (lo, hi) = if hi - lo <= (lo.abs().max(hi.abs())) * 1e-12 { widen(lo) } else { (lo, hi) };
    let step = nice_step(hi / target as f64 - lo / target as f64);
    let (k_lo, k_hi) = ((lo / step).floor(), (hi / step).ceil());
    let n = ((k_hi - k_lo) as usize).min(100);
    let ticks = (0..=n)
        .map(|i| {
            let value = (k_lo + i as f64) * step;
            Tick { value, label: linear_label(value, step, k_lo.abs().max(k_hi.abs()) * step) }
        })
        .collect();
    (k_lo * step, k_hi * step, ticks)
}

/// A log axis over the data range padded by 2 % of its decades (half a
/// decade each side for a single value); ticks at decades, with minor ticks
/// 2..9 when at most six decades show, and 2 and 5 labelled when fewer
/// than two decades fall inside.
fn log_ticks(lo: f64, hi: f64) -> (f64, f64, Vec<Tick>) {
    let (l_lo, l_hi) = (lo.log10().max(-307.0), hi.log10().min(307.0));
    let pad = if l_hi - l_lo < 1e-9 { 0.5 } else { 0.02 * (l_hi - l_lo) };
    let (l_lo, l_hi) = (l_lo - pad, l_hi + pad);
    let inside = |v: f64| v.log10() >= l_lo - 1e-12 && v.log10() <= l_hi + 1e-12;
    let (e_lo, e_hi) = (l_lo.floor(), l_hi.ceil());
    let decades = (e_hi - e_lo) as usize;
    let every = decades.div_ceil(8).max(1);
    let decade_ticks = (0..=decades).filter(|i| inside(10f64.powf(e_lo + *i as f64))).count();
    let mut ticks = Vec::new();
    for i in 0..=decades {
        let e = e_lo + i as f64;
        let label = if i % every == 0 { log_label(e) } else { String::new() };
        ticks.push(Tick { value: 10f64.powf(e), label });
        if decades <= 6 && i < decades {
            for m in 2..=9 {
                let labelled = decade_ticks < 2 && (m == 2 || m == 5 || decade_ticks == 0);
                let value = m as f64 * 10f64.powf(e);
                let label =
                    if labelled { plain(value, (-e).max(0.0) as usize) } else { String::new() };
                ticks.push(Tick { value, label });
            }
        }
    }
    ticks.retain(|t| inside(t.value));
    (10f64.powf(l_lo), 10f64.powf(l_hi), ticks)
}

/// A decade's label: plain for 10^-3..10^5, else `1e-6`.
fn log_label(e: f64) -> String {
    if (-3.0..=5.0).contains(&e) {
        plain(10f64.powf(e), (-e).max(0.0) as usize)
    } else {
        minus(&format!("1e{}", e as i64))
    }
}

/// A linear tick label with as many decimals as the step needs; exponent
/// form when the axis reaches 1e5 or the step is below 1e-3.
fn linear_label(v: f64, step: f64, abs_max: f64) -> String {
    if v.abs() < step * 1e-9 {
        return "0".to_string();
    }
    if abs_max >= 1e5 || step < 1e-3 {
        let digits = (abs_max.log10().floor() - step.log10().floor()).clamp(0.0, 6.0) as usize;
        let s = format!("{:.*e}", digits, v);
        return minus(&trim_mantissa(&s));
    }
    let decimals = (-step.log10().floor()).clamp(0.0, 12.0) as usize;
    plain(v, decimals)
}

/// Trailing zeros of an exponent-form mantissa removed ("1.50e3" -> "1.5e3").
fn trim_mantissa(s: &str) -> String {
    match s.split_once('e') {
        Some((m, e)) if m.contains('.') => {
            format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
        }
        _ => s.to_string(),
    }
}

fn plain(v: f64, decimals: usize) -> String {
    minus(&format!("{:.*}", decimals, v))
}

/// Typographic minus sign.
fn minus(s: &str) -> String {
    s.replace('-', "\u{2212}")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(a: &Axis) -> Vec<&str> {
        a.ticks.iter().filter(|t| !t.label.is_empty()).map(|t| t.label.as_str()).collect()
    }

    #[test]
    fn linear_rounds_out_to_nice_steps() {
        let a = Axis::new(0.13, 9.7, Scale::Linear, 5);
        assert_eq!((a.lo, a.hi), (0.0, 10.0));
        assert_eq!(labels(&a), ["0", "2", "4", "6", "8", "10"]);
    }

    #[test]
    fn linear_small_and_negative_values() {
        let a = Axis::new(-0.031, 0.029, Scale::Linear, 3);
        assert_eq!(labels(&a), ["\u{2212}0.04", "\u{2212}0.02", "0", "0.02", "0.04"]);
    }

    #[test]
    fn large_values_use_exponent_form() {
        let a = Axis::new(0.0, 3.0e6, Scale::Linear, 3);
        assert_eq!(labels(&a), ["0", "1e6", "2e6", "3e6"]);
    }

    #[test]
    fn exact_axis_keeps_its_ends() {
        let a = Axis::new(0.0, 1.0, Scale::Linear, 5);
        let e = Axis::exact(-0.05, 9.95, 5);
        assert_eq!((e.lo, e.hi), (-0.05, 9.95));
        assert_eq!(labels(&e), ["0", "2", "4", "6", "8"]);
        assert_eq!(labels(&a).len(), 6);
    }

    #[test]
    fn constant_range_is_widened() {
        let a = Axis::new(5.0, 5.0, Scale::Linear, 5);
        assert!(a.lo < 5.0 && a.hi > 5.0);
        let z = Axis::new(0.0, 0.0, Scale::Linear, 5);
        assert!(z.lo <= -1.0 && z.hi >= 1.0);
    }

    #[test]
    fn log_axis_pads_the_data_range() {
        let a = Axis::new(0.1, 100.0, Scale::Log10, 5);
        assert!((a.lo.log10() + 1.06).abs() < 1e-12 && (a.hi.log10() - 2.06).abs() < 1e-12);
        assert_eq!(labels(&a), ["0.1", "1", "10", "100"]);
        let p = a.placed(0.0, 312.0).map(10.0).unwrap();
        assert!((p - 206.0).abs() < 1e-9, "{p}");
    }

    #[test]
    fn short_log_axis_labels_two_and_five() {
        let a = Axis::new(1.5, 8.0, Scale::Log10, 5);
        assert_eq!(labels(&a), ["2", "3", "4", "5", "6", "7", "8"]);
        let b = Axis::new(3.0, 30.0, Scale::Log10, 5);
        assert_eq!(labels(&b), ["5", "10", "20"]);
    }

    #[test]
    fn log_axis_maps_nonpositive_to_none() {
        let a = Axis::new(1.0, 10.0, Scale::Log10, 5).placed(0.0, 100.0);
        assert_eq!(a.map(0.0), None);
        assert_eq!(a.map(-1.0), None);
    }

    #[test]
    fn data_range_skips_gaps_and_nonpositive_on_log() {
        let v = [f64::NAN, -2.0, 0.0, 3.0, f64::INFINITY];
        assert_eq!(data_range(v.into_iter(), Scale::Linear), Some((-2.0, 3.0)));
        assert_eq!(data_range(v.into_iter(), Scale::Log10), Some((3.0, 3.0)));
        assert_eq!(data_range([f64::NAN].into_iter(), Scale::Linear), None);
    }
}
