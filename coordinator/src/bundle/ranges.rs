//! The physically plausible range of every number a bundle states, in one
//! place: a value outside it (a ceiling 6e11 m long, a time of 1.7e308 s, a
//! step of 1e-300 s) is a corrupt or mistyped file, refused with its key and
//! this range before it reaches the model generator or a solver.

/// An accepted closed range `lo..=hi` of one quantity.
#[derive(Debug, Clone, Copy)]
pub(super) struct Range {
    /// Smallest accepted value.
    pub lo: f64,
    /// Largest accepted value.
    pub hi: f64,
    /// Unit, as written in messages.
    pub unit: &'static str,
}

/// Specimen plan dimensions (`length_x_m`, `length_y_m`), m.
pub(super) const LENGTH_M: Range = Range { lo: 0.0, hi: 100.0, unit: "m" };
/// Grid spacings (`module_m`, `main_tee_spacing_m`, `hanger_spacing_m`), m.
pub(super) const SPACING_M: Range = Range { lo: 0.0, hi: 10.0, unit: "m" };
/// Hanger rod length, m.
pub(super) const HANGER_M: Range = Range { lo: 0.0, hi: 20.0, unit: "m" };
/// One panel's mass, kg.
pub(super) const PANEL_KG: Range = Range { lo: 0.0, hi: 500.0, unit: "kg" };
/// Nominal perimeter gap, mm.
pub(super) const GAP_MM: Range = Range { lo: 0.0, hi: 1000.0, unit: "mm" };
/// A run file's time stamps, s (about eleven days either side of zero).
pub(super) const TIME_S: Range = Range { lo: -1e6, hi: 1e6, unit: "s" };
/// A run file's sampling step, s (1 MHz to 0.1 Hz).
pub(super) const DT_S: Range = Range { lo: 1e-6, hi: 10.0, unit: "s" };
/// An identified natural frequency, Hz.
pub(super) const FREQ_HZ: Range = Range { lo: 0.0, hi: 1e4, unit: "Hz" };
/// A frequency's one-sigma uncertainty, Hz.
pub(super) const STD_HZ: Range = Range { lo: 0.0, hi: 1e4, unit: "Hz" };

/// Refuses `v` outside `r`, saying the value and the accepted range.
pub(super) fn check_range(r: &Range, v: f64) -> Result<(), String> {
    if (r.lo..=r.hi).contains(&v) {
        Ok(())
    } else {
        let (v, lo, hi) = (show(v), show(r.lo), show(r.hi));
        Err(format!("{v}: outside the accepted range {lo} to {hi} {}", r.unit))
    }
}

/// A number as written in messages: plain, or in exponent form when huge or tiny.
fn show(v: f64) -> String {
    if v != 0.0 && !(1e-4..1e9).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}
