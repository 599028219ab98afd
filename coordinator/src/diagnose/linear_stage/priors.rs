//! The linear stage's parameters: everything that moves a ceiling's linear
//! response that the baseline otherwise holds at the generator's form, with
//! uniform priors (log-uniform for stiffnesses and factors spanning decades).
//! Each range is set by what a built specimen can be, not by any campaign:
//!
//! - `K_friction` 3–150 N/mm: the grid end's support along its axis; Table
//!   6.1's 15–25 N/mm, five times wider each way (a clip with play, an end
//!   resting on the angle, a screwed clip);
//! - `K_across` 10–10 000 N/mm: across the axis, from an end held only by
//!   friction on the angle to the generator's rigid restraint;
//! - `panel_mass_factor` 0.8–1.2: the panels' weight scatters ±20 % about
//!   the bundle's nominal (moisture, fixtures, another tile);
//! - `member_mass_factor` 0–1.5: from massless members (the seed's models)
//!   to sections half again as heavy as seed-facts' tees and rods;
//! - `rod_bending_factor` 0.1–2: a rod pinned at the tee (0.25 of the fixed
//!   rod's sway stiffness), one bent or longer, to a stiffer hanger;
//! - `K_cc1` 100–100 000 N/mm, `K_cc2` 10–100 000 N/mm: the tee joints'
//!   axial and in-plane transverse springs (Table 6.1: 750–850 and 75–125
//!   N/mm for the seed's CJS-A joints), from a joint that gives ten times
//!   more to one that is as stiff as the tees themselves (a 0.6 m tee's
//!   EA/L is about 11 000 N/mm: tabs riveted or locked tight);
//! - `grid_bending_factor` 0.3–3: the members' bending inertias over
//!   Table 4.4's sections (another profile, a tee that is not straight);
//! - `K_joint_rot` 1e3–1e10 N·mm/rad: the tee joints' turn in the plane,
//!   from a tab that pivots in its slot to a thousand times the main tee's
//!   own 4EI/L over a module (1.05e7; the frequencies then differ from a
//!   continuous grid's by about 1e-3);
//! - `K_rod_rot` 1e2–1e8 N·mm/rad: the rods' turn at the tee, from pinned
//!   (a thousandth of the M8 rod's own 4EI/L over 1 m, 1.0e5) to a
//!   thousand times it (the seed's rigid tie; a hinged rod's first mode
//!   then differs from the tied rod's by about 1e-3);
//! - `damping_ratio` 0.5–15 %: bare steel grids to panels rubbing;
//! - `damping_mass_share` 0–1: the Rayleigh pair's split
//!   ([`super::super::damping_share`]);
//! - each grid line's along factor (`along_factor_row_yY`,
//!   `along_factor_line_xX`: `K_friction` times it at both ends of the line,
//!   [`fe::generator::along`]) for every line that ends on a wall it may
//!   slide along: a random effect, log-normal about 1 with log-sd
//!   [`LINE_LOG_SD`] (the likelihood's prior term, [`line_prior_rows`]),
//!   kept within [`LINE_BOUNDS`]. A lab seats each end on its angle by hand
//!   and its clips scatter; a line's two ends together decide how it slides,
//!   and a line held half or twice as firmly as the wall's mean is rare
//!   but seen (2.8 sd).

use crate::bundle::Bundle;
use crate::diagnose::cause::{Cause, Prior};

const fn prior(name: &'static str, unit: &'static str, low: f64, high: f64, log: bool) -> Prior {
    Prior { name, unit, low, high, log, reference: None }
}

/// The linear stage's parameters and priors (see the module documentation).
pub const LINEAR_PRIORS: [Prior; 12] = [
    prior("K_friction", "N/mm", 3.0, 150.0, true),
    prior("K_across", "N/mm", 10.0, 1.0e4, true),
    prior("panel_mass_factor", "-", 0.8, 1.2, false),
    prior("member_mass_factor", "-", 0.0, 1.5, false),
    prior("rod_bending_factor", "-", 0.1, 2.0, true),
    prior("K_cc1", "N/mm", 100.0, 1.0e5, true),
    prior("K_cc2", "N/mm", 10.0, 1.0e5, true),
    prior("grid_bending_factor", "-", 0.3, 3.0, true),
    prior("K_joint_rot", "N*mm/rad", 1.0e3, 1.0e10, true),
    prior("K_rod_rot", "N*mm/rad", 1.0e2, 1.0e8, true),
    prior("damping_ratio", "-", 0.005, 0.15, true),
    prior("damping_mass_share", "-", 0.0, 1.0, false),
];

/// The nominal specimen in [`LINEAR_PRIORS`]' order: the seed's values
/// (Table 6.1's mid-points, the rigid restraint across, seed-facts'
/// member masses, the M8 rod fixed at both ends and tied to the tee,
/// continuous joints, 5 % damping split evenly), the first start of the
/// linear stage's search.
pub const NOMINAL: [f64; 12] =
    [20.0, 1.0e4, 1.0, 1.0, 1.0, 800.0, 100.0, 1.0, 1.0e10, 1.0e8, 0.05, 0.5];

/// Log-sd of a grid line's along factor about 1 (see the module
/// documentation): ±25 % at one sd.
pub const LINE_LOG_SD: f64 = 0.25;

/// Bounds of a grid line's along factor: e^{±3.7 sd}, where the
/// log-normal prior has left less than 1e-4 of its mass.
pub const LINE_BOUNDS: (f64, f64) = (0.4, 2.5);

/// The linear stage's parameters for `b`: [`LINEAR_PRIORS`], then one along
/// factor per grid line that ends on a wall it may slide along.
pub fn linear_priors(b: &Bundle) -> Vec<Prior> {
    let spec = crate::specimen::fe_spec(&b.manifest.structure, Cause::NONE.model_options());
    let lines = spec.map(|s| fe::generator::along_factor_names(&s)).unwrap_or_default();
    let (low, high) = LINE_BOUNDS;
    let line = |name| Prior { name, unit: "-", low, high, log: true, reference: None };
    LINEAR_PRIORS.iter().copied().chain(lines.into_iter().map(line)).collect()
}

/// The nominal specimen for `priors`: [`NOMINAL`], every line's factor 1.
pub fn nominal(priors: &[Prior]) -> Vec<f64> {
    (0..priors.len()).map(|i| NOMINAL.get(i).copied().unwrap_or(1.0)).collect()
}

/// The prior's whitened residuals ln(f)/[`LINE_LOG_SD`] of the line factors
/// among `priors` at the physical values `theta`: ½ |rows|² is the
/// log-normal prior's −log density (constants dropped).
pub fn line_prior_rows(priors: &[Prior], theta: &[f64]) -> Vec<f64> {
    priors
        .iter()
        .zip(theta)
        .filter(|(p, _)| fe::generator::along::is_along_factor(p.name))
        .map(|(_, v)| v.ln() / LINE_LOG_SD)
        .collect()
}
