//! The calibration parameters of seed Table 6.1 (section and stiffness
//! values, units as in the model: mm², MPa, mm⁴, N/mm) with their uniform
//! prior bounds, the extension parameters of the model variants (perimeter
//! friction, pounding, connection hysteresis), and the values a generated
//! model uses.
//!
//! The extension priors are centred on the seed's values (friction 2 N and
//! b 0.05, seed 5.1.1; the nominal gap and 0.4 EA/L, seed 5.1.2; the CJS-A
//! Pinching4 set, seed Table 5.4), so that the prior mid-points rebuild the
//! seed's model and `variant = "nonlinear"` equals `perimeter =
//! "friction-pounding"` at the mid-points.

use std::collections::BTreeMap;

use super::along::along_factor_info;
use super::connections::CJS_A_COMPRESSION_RATIO;
use super::spec::{CeilingSpec, Connections};

/// The values a parameter may take.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Domain {
    /// A finite number > 0.
    Positive,
    /// A ratio in [0, 1) (Steel01 hardening).
    Fraction,
    /// A signed ratio in (−1, 1) (a shift of Pinching4's uForce, a spread of gaps).
    SignedRatio,
    /// A finite number ≥ 0 (a mass that may be absent).
    NonNegative,
}

/// One named parameter: unit and prior bounds (seed Table 6.1, or the
/// extension table [`EXTENSIONS`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamInfo {
    /// Name as in the table.
    pub name: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// Lower prior bound.
    pub low: f64,
    /// Upper prior bound.
    pub high: f64,
    /// Whether the default model (linear perimeter, rigid connections) uses
    /// it; [`parameters_for`] marks every parameter it returns as used.
    pub modelled: bool,
    /// The values it may take.
    pub domain: Domain,
    /// The value a model uses when none is given (None: the prior mid-point).
    pub default: Option<f64>,
}

impl ParamInfo {
    /// The prior mid-point, the value a model uses when none is given.
    pub fn midpoint(&self) -> f64 {
        0.5 * (self.low + self.high)
    }
    /// The value a model uses when none is given: [`ParamInfo::default`],
    /// else the prior mid-point.
    pub fn default_value(&self) -> f64 {
        self.default.unwrap_or_else(|| self.midpoint())
    }
    /// Whether `value` is in the parameter's domain.
    pub fn accepts(&self, value: f64) -> bool {
        match self.domain {
            Domain::Positive => value > 0.0 && value.is_finite(),
            Domain::Fraction => (0.0..1.0).contains(&value),
            Domain::SignedRatio => value > -1.0 && value < 1.0,
            Domain::NonNegative => value >= 0.0 && value.is_finite(),
        }
    }
}

const fn p(
    name: &'static str,
    unit: &'static str,
    low: f64,
    high: f64,
    modelled: bool,
) -> ParamInfo {
    ParamInfo { name, unit, low, high, modelled, domain: Domain::Positive, default: None }
}

/// The 15 parameters of seed Table 6.1. K_cc1-3 act on the tee joints in
/// the joining member's axes (axial, in-plane transverse, vertical) and K_mc
/// on the main-tee splices' axis when connections are not rigid; K_rod has no
/// documented meaning and is never modelled.
pub const PARAMETERS: [ParamInfo; 15] = [
    p("A_cross", "mm2", 30.0, 36.0, true),
    p("E", "MPa", 1.9e5, 2.3e5, true),
    p("G", "MPa", 7.4e4, 8.2e4, true),
    p("J_cross", "mm4", 4800.0, 5100.0, true),
    p("Iy_cross", "mm4", 4000.0, 4700.0, true),
    p("Iz_cross", "mm4", 650.0, 750.0, true),
    p("K_rod", "-", 0.5, 3.0, false),
    p("K_friction", "N/mm", 15.0, 25.0, true),
    p("K_cc1", "N/mm", 750.0, 850.0, false),
    p("K_cc2", "N/mm", 75.0, 125.0, false),
    p("K_cc3", "N/mm", 10.0, 35.0, false),
    p("A_main", "mm2", 35.0, 42.0, true),
    p("J_main", "mm4", 7900.0, 8500.0, true),
    p("Iy_main", "mm4", 7250.0, 7800.0, true),
    p("K_mc", "N/mm", 1400.0, 1600.0, false),
];

/// Parameters of the model variants, with priors centred on the seed's values:
/// - `friction_fy_N` U(0.5, 3.5) N: perimeter slip force, seed 2 N (5.1.1);
/// - `friction_b` U(0, 0.1): Steel01 hardening after slip, seed 0.05;
/// - `gap_ratio` U(0.5, 1.5): gap / nominal gap; the seed measured 17.33 mm
///   mean (0.91 of 19 mm) and used 13.3 mm (0.70) in its simplified model;
/// - `impact_factor` U(0.25, 1.75): contact stiffness / 0.4 EA/L; the seed
///   notes real contact is softer than EA/L and its simplified model used
///   300 N/mm (0.51 of the main tee's 588 N/mm, 1.38 of the cross tee's 217);
/// - `gap_spread` U(−0.5, 0.5): the gaps along each wall differ, spread
///   evenly over (1 ± gap_spread) × the gap (the sign reverses which ends
///   are the tight ones); the seed measured a standard deviation of 1.86 mm
///   on 17.33 mm (a spread of ±0.19) at a fixed-semi-free perimeter and
///   2.08 mm on 3.05 mm at a free one, and modelled one gap per side;
/// - `conn_force_scale`, `conn_disp_scale` U(0.5, 1.5): factors on the
///   forces and deformations of the CJS-A Pinching4 backbone (Table 5.4 is
///   the median of fitted specimens);
/// - `conn_reload_force` U(0.1, 0.3): the CJS-A pinching, Pinching4 rForce on
///   both sides (reloading force over the force at the largest past
///   deformation; larger: fuller loops), Table 5.4's 0.2;
/// - `conn_unload_shift` U(−0.3, 0.3): added to Table 5.4's Pinching4
///   uForce (−0.01) on both sides (the force left on unloading over the
///   monotonic strength; larger: fuller loops); Table 5.5's connection
///   kinds range from −0.3 (JAC) to −0.01;
/// - `conn_compression_ratio` U(0.5, 2), [`CJS_A_COMPRESSION_RATIO`] unless
///   given: the backbone's first slope in compression over its first slope
///   in tension (Table 5.4: 200 N at 0.5 mm against 150 N at 0.5 mm, 4/3),
///   set by moving the first compression deformation alone; 1 makes the
///   joint below its first backbone point the elastic K_cc1 spring in both
///   directions;
/// - `conn_transverse_force_scale` (0 unless given: the spring stays the
///   elastic K_cc2), `conn_transverse_disp_scale` (1 unless given): the tee
///   joints' in-plane transverse spring as the CJS-A Pinching4 too, its
///   forces and deformations times these, its pinching, unloading and
///   compression ratio those of the axial joint: a cross tee loaded across
///   its axis (a ceiling shaken along the main tees) bends and works its
///   tab in the slot, and yields and pinches as it does when pulled; the
///   seed modelled the axial direction alone (5.1.1);
/// - `channel_mass_kg_per_m` U(0, 4.5) kg/m, 0 unless given: the carrying
///   channels of a double-layer ceiling, which run along x through every
///   row of rods above the grid, as mass shared among the row's rod nodes
///   (their stiffness is not modelled); the seed's U50x15x1 weighs 2.24 kg/m;
/// - `channel_beam_factor` U(0, 1), 0 unless given: the carrying channels'
///   beams between neighbouring rod nodes of a row, as a fraction of the
///   seed's U50x15x1 section (A 70 mm², Iy 2.9e4 mm⁴, Iz 1.6e3 mm⁴, J 27 mm⁴,
///   web vertical) on the tees' E and G: 1 joins them rigidly to the main
///   tees, less stands for the clips' give.
pub const EXTENSIONS: [ParamInfo; 14] = [
    p("friction_fy_N", "N", 0.5, 3.5, true),
    ParamInfo { domain: Domain::Fraction, ..p("friction_b", "-", 0.0, 0.1, true) },
    p("gap_ratio", "-", 0.5, 1.5, true),
    p("impact_factor", "-", 0.25, 1.75, true),
    ParamInfo { domain: Domain::SignedRatio, ..p("gap_spread", "-", -0.5, 0.5, true) },
    p("conn_force_scale", "-", 0.5, 1.5, true),
    p("conn_disp_scale", "-", 0.5, 1.5, true),
    ParamInfo { domain: Domain::Fraction, ..p("conn_reload_force", "-", 0.1, 0.3, true) },
    ParamInfo { domain: Domain::SignedRatio, ..p("conn_unload_shift", "-", -0.3, 0.3, true) },
    ParamInfo {
        default: Some(CJS_A_COMPRESSION_RATIO),
        ..p("conn_compression_ratio", "-", 0.5, 2.0, true)
    },
    ParamInfo {
        domain: Domain::NonNegative,
        default: Some(0.0),
        ..p("conn_transverse_force_scale", "-", 0.0, 1.5, true)
    },
    ParamInfo { default: Some(1.0), ..p("conn_transverse_disp_scale", "-", 0.5, 1.5, true) },
    ParamInfo {
        domain: Domain::NonNegative,
        default: Some(0.0),
        ..p("channel_mass_kg_per_m", "kg/m", 0.0, 4.5, true)
    },
    ParamInfo {
        domain: Domain::NonNegative,
        default: Some(0.0),
        ..p("channel_beam_factor", "-", 0.0, 1.0, true)
    },
];

/// The linear form of the specimen beyond Table 6.1, each at a default
/// that rebuilds the model without it (so a model that does not name them
/// is unchanged), for a specimen built otherwise than the generator assumes:
/// - `K_across` (N/mm, default 10 000, the rigid restraint): the perimeter's
///   stiffness across a grid end's axis on a semi-free wall (a wall angle
///   that bends, a clip with play, an end resting on the angle by friction);
/// - `panel_mass_factor` (default 1): the panels' mass over the bundle's
///   nominal `panel_mass_kg` (tiles absorb water, carry fixtures, scatter);
/// - `member_mass_factor` (default 0: members massless, as the seed's
///   models): the grid members' and rods' own mass over the seed-facts
///   values ([`MEMBER_KG_PER_M`]), lumped half to each end's grid node
///   (a rod's upper half to its fixed top);
/// - `rod_bending_factor` (default 1): the rods' bending inertia over the
///   M8 rod's (0.25 gives a rod pinned at the tee the fixed rod's sway
///   stiffness 3EI/L³);
/// - `grid_axial_factor`, `grid_bending_factor` (default 1): the grid
///   members' area, and their three inertias, over Table 6.1's sections:
///   joints that give (a connection's springs in series with the member,
///   a splice's play) smeared over the members between them;
/// - `K_joint_rot` (N·mm/rad, default 1e13, continuity): the tee joints'
///   rotational stiffness in the plane when connections are not rigid (a
///   tab locked in a slot turns before it pulls out);
/// - `K_rod_rot` (N·mm/rad, default 1e13, the seed's rigid tie): the rods'
///   rotational stiffness at the tee about both horizontal axes (a rod in
///   a clip, a wire's loop; [`super::rods`]), pinned towards 0.
pub const LINEAR_FORM: [ParamInfo; 8] = [
    ParamInfo { default: Some(1.0e4), ..p("K_across", "N/mm", 10.0, 1.0e4, true) },
    ParamInfo { default: Some(1.0), ..p("panel_mass_factor", "-", 0.8, 1.2, true) },
    ParamInfo {
        domain: Domain::NonNegative,
        default: Some(0.0),
        ..p("member_mass_factor", "-", 0.0, 1.5, true)
    },
    ParamInfo { default: Some(1.0), ..p("rod_bending_factor", "-", 0.1, 2.0, true) },
    ParamInfo { default: Some(1.0), ..p("grid_axial_factor", "-", 0.02, 1.5, true) },
    ParamInfo { default: Some(1.0), ..p("grid_bending_factor", "-", 0.3, 3.0, true) },
    ParamInfo { default: Some(1.0e13), ..p("K_joint_rot", "N*mm/rad", 1.0e3, 1.0e13, true) },
    ParamInfo { default: Some(1.0e13), ..p("K_rod_rot", "N*mm/rad", 1.0e1, 1.0e13, true) },
];

/// The members' own mass (kg/m: main tee, cross tee, sub cross tee, hanger
/// rod), seed-facts' values, scaled by `member_mass_factor`.
pub const MEMBER_KG_PER_M: [f64; 4] = [1.07, 0.31, 0.13, 0.37];

/// Every parameter a generator knows: Table 6.1, the extensions, the linear form.
fn all_params() -> impl Iterator<Item = &'static ParamInfo> {
    PARAMETERS.iter().chain(&EXTENSIONS).chain(&LINEAR_FORM)
}

/// The parameters of the Pinching4 connections (`connections = "pinching4"`).
const PINCHING4_PARAMS: [&str; 7] = [
    "conn_force_scale",
    "conn_disp_scale",
    "conn_reload_force",
    "conn_unload_shift",
    "conn_compression_ratio",
    "conn_transverse_force_scale",
    "conn_transverse_disp_scale",
];

/// Which model choice a parameter needs (for the refusal message).
fn needs(name: &str) -> &'static str {
    match name {
        "K_rod" => "no variant models it: Table 6.1 does not say what it acts on",
        "K_cc1" => "it needs connections = \"elastic\"",
        "K_cc2" | "K_cc3" | "K_mc" => "it needs connections = \"elastic\" or \"pinching4\"",
        "friction_fy_N" | "friction_b" => {
            "it needs perimeter = \"friction\" or \"friction-pounding\""
        }
        "gap_ratio" | "impact_factor" | "gap_spread" => {
            "it needs perimeter = \"pounding\" or \"friction-pounding\""
        }
        n if PINCHING4_PARAMS.contains(&n) => "it needs connections = \"pinching4\"",
        "channel_mass_kg_per_m" | "channel_beam_factor" => {
            "it needs layers = 2 (carrying channels above the grid)"
        }
        "K_joint_rot" => "it needs connections = \"elastic\" or \"pinching4\"",
        _ => "it is a parameter of the default model",
    }
}

/// Every parameter a specimen's model variant uses, with its prior, in
/// Table 6.1 order, then [`EXTENSIONS`] order, then [`LINEAR_FORM`] order.
pub fn parameters_for(spec: &CeilingSpec) -> Vec<ParamInfo> {
    let m = spec.model;
    let conn = m.connections;
    let used = |name: &str| match name {
        "K_rod" => false,
        "K_cc1" => conn == Connections::Elastic,
        "K_cc2" | "K_cc3" | "K_mc" => conn != Connections::Rigid,
        "friction_fy_N" | "friction_b" => m.perimeter.has_friction(),
        "gap_ratio" | "impact_factor" | "gap_spread" => m.perimeter.has_pounding(),
        n if PINCHING4_PARAMS.contains(&n) => conn == Connections::Pinching4,
        "channel_mass_kg_per_m" | "channel_beam_factor" => spec.structure.layers == 2,
        "K_joint_rot" => conn != Connections::Rigid,
        _ => true,
    };
    all_params().filter(|p| used(p.name)).map(|p| ParamInfo { modelled: true, ..*p }).collect()
}

/// The description of a parameter by name, from any table, or a grid
/// line's along factor ([`super::along`]).
pub fn param_info(name: &str) -> Option<ParamInfo> {
    all_params().find(|p| p.name == name).copied().or_else(|| along_factor_info(name))
}

/// Why a parameter value is refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ParamError {
    /// Not one of the 15 names.
    #[error("parameter `{name}`: unknown (known: {known})")]
    Unknown {
        /// The name given.
        name: String,
        /// The known names.
        known: String,
    },
    /// A known parameter that this model variant does not use.
    #[error("parameter `{name}`: not used by this model variant; {needs}")]
    NotModelled {
        /// The name given.
        name: String,
        /// The model choice that uses it.
        needs: &'static str,
    },
    /// Outside the parameter's domain.
    #[error("parameter `{name}` = {value}: expected {expected}")]
    Value {
        /// The name.
        name: String,
        /// The value.
        value: f64,
        /// The domain.
        expected: &'static str,
    },
    /// `NAME=VALUE` syntax error.
    #[error("`{text}`: expected NAME=VALUE")]
    Syntax {
        /// The text given.
        text: String,
    },
}

/// Values of the parameters a model variant uses, by name; only those
/// names are accepted by [`Parameters::set`].
#[derive(Debug, Clone, PartialEq)]
pub struct Parameters {
    values: BTreeMap<&'static str, f64>,
    accepted: Vec<ParamInfo>,
}

impl Parameters {
    /// Every parameter of the default model (linear perimeter, rigid
    /// connections: the 10 modelled ones of Table 6.1 and the linear form
    /// but the joints' rotation) at its prior mid-point or default.
    pub fn prior_midpoints() -> Self {
        let linear = LINEAR_FORM.iter().filter(|p| p.name != "K_joint_rot");
        Self::at_midpoints(
            PARAMETERS.iter().filter(|p| p.modelled).chain(linear).copied().collect(),
        )
    }

    /// Every parameter the specimen's model variant uses at its prior
    /// mid-point (at its default where it has one: [`ParamInfo::default`]).
    pub fn prior_midpoints_for(spec: &CeilingSpec) -> Self {
        Self::at_midpoints(parameters_for(spec))
    }

    fn at_midpoints(accepted: Vec<ParamInfo>) -> Self {
        let values = accepted.iter().map(|p| (p.name, p.default_value())).collect();
        Parameters { values, accepted }
    }

    /// The parameters this set accepts, with their priors.
    pub fn accepted(&self) -> &[ParamInfo] {
        &self.accepted
    }

    /// Sets one parameter by name (a grid line's along factor, which every
    /// variant accepts, included: [`super::along`]).
    pub fn set(&mut self, name: &str, value: f64) -> Result<(), ParamError> {
        let line = along_factor_info(name);
        let Some(info) = self.accepted.iter().find(|p| p.name == name).or(line.as_ref()) else {
            return Err(match param_info(name) {
                Some(p) => ParamError::NotModelled { name: name.into(), needs: needs(p.name) },
                None => {
                    let known = all_params().map(|p| p.name);
                    ParamError::Unknown {
                        name: name.into(),
                        known: known.collect::<Vec<_>>().join(", "),
                    }
                }
            });
        };
        if !info.accepts(value) {
            let expected = match info.domain {
                Domain::Positive => "a finite number > 0",
                Domain::Fraction => "a ratio in [0, 1)",
                Domain::SignedRatio => "a ratio in (-1, 1)",
                Domain::NonNegative => "a finite number >= 0",
            };
            return Err(ParamError::Value { name: name.into(), value, expected });
        }
        self.values.insert(info.name, value);
        Ok(())
    }

    /// Parses and sets `NAME=VALUE`.
    pub fn set_text(&mut self, text: &str) -> Result<(), ParamError> {
        let syntax = || ParamError::Syntax { text: text.into() };
        let (name, value) = text.split_once('=').ok_or_else(syntax)?;
        let value: f64 = value.trim().parse().map_err(|_| syntax())?;
        self.set(name.trim(), value)
    }

    /// The value of a parameter of this set (NaN if it has none).
    pub fn get(&self, name: &str) -> f64 {
        self.values.get(name).copied().unwrap_or(f64::NAN)
    }

    /// The value of a parameter, or when this set has none its prior
    /// mid-point or default ([`ParamInfo::default_value`]; NaN for an
    /// unknown name).
    pub fn value_or_midpoint(&self, name: &str) -> f64 {
        match self.values.get(name) {
            Some(v) => *v,
            None => param_info(name).map_or(f64::NAN, |p| p.default_value()),
        }
    }

    /// All values, by name.
    pub fn iter(&self) -> impl Iterator<Item = (&'static str, f64)> + '_ {
        self.values.iter().map(|(k, v)| (*k, *v))
    }
}
