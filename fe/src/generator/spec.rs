//! The specimen as built: the `[structure]` table of the measured-data bundle
//! (`shared/spec/measured-bundle.md`; metres, kg, mm as named) plus an
//! optional `[model]` table choosing the model variant: the perimeter law
//! (`perimeter`) and the grid-connection law (`connections`), or the older
//! shorthand `variant`.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

/// Perimeter condition of the grid (seed Table 4.5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Boundary {
    /// Grid ends resting on the wall angle, unattached: friction both ways
    /// in the plane, contact across the gap along their axis (seed 4.2.2).
    Free,
    /// Grid ends riveted or clipped fast to the wall angle on every side.
    Fixed,
    /// Fixed on the two walls through the origin (x = 0, y = 0), semi-free
    /// on the two opposite walls (seed 4.2.2, the American style).
    FixedSemiFree,
    /// Grid ends clipped to the wall angle, sliding along their own axis.
    SemiFree,
}

/// How the grid ends on one wall are held.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EndCondition {
    /// Sliding clip: friction along the axis, held across it.
    SemiFree,
    /// Unattached: friction along and across the axis.
    Free,
    /// Held in every direction.
    Fixed,
}

impl Boundary {
    /// The spelling in `[structure] boundary`.
    pub fn as_str(self) -> &'static str {
        match self {
            Boundary::SemiFree => "semi-free",
            Boundary::Free => "free",
            Boundary::Fixed => "fixed",
            Boundary::FixedSemiFree => "fixed-semi-free",
        }
    }

    /// The condition of the grid ends on wall `side` (`x0`, `x1`, `y0`, `y1`).
    pub fn on_side(self, side: &str) -> EndCondition {
        match self {
            Boundary::SemiFree => EndCondition::SemiFree,
            Boundary::Free => EndCondition::Free,
            Boundary::Fixed => EndCondition::Fixed,
            Boundary::FixedSemiFree if side.ends_with('0') => EndCondition::Fixed,
            Boundary::FixedSemiFree => EndCondition::SemiFree,
        }
    }

    /// Whether some grid ends can slide and strike the wall (the
    /// perimeter-friction and perimeter-pounding physics has a place).
    pub fn has_sliding_ends(self) -> bool {
        self != Boundary::Fixed
    }
}

/// Which perimeter springs to write (shorthand kept from the first format).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Variant {
    /// Elastic along-axis friction spring (K_friction): `perimeter = "linear"`.
    #[default]
    Linear,
    /// Steel01 friction plus the eq. 5.4 gap: `perimeter = "friction-pounding"`.
    Nonlinear,
}

/// The along-axis law of each perimeter grid end (seed 5.1.1, 5.1.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Perimeter {
    /// Elastic friction spring K_friction, no contact.
    #[default]
    Linear,
    /// Steel01 friction: Fy `friction_fy_N`, E0 K_friction, b `friction_b`.
    Friction,
    /// Elastic friction spring plus the eq. 5.4 gap (`gap_ratio`, `impact_factor`).
    Pounding,
    /// Steel01 friction plus the eq. 5.4 gap.
    FrictionPounding,
}

impl Perimeter {
    /// Whether the friction spring is Steel01.
    pub fn has_friction(self) -> bool {
        matches!(self, Perimeter::Friction | Perimeter::FrictionPounding)
    }
    /// Whether gap contact springs are written.
    pub fn has_pounding(self) -> bool {
        matches!(self, Perimeter::Pounding | Perimeter::FrictionPounding)
    }
    /// The name as the `[model]` table writes it.
    pub fn name(self) -> &'static str {
        match self {
            Perimeter::Linear => "linear",
            Perimeter::Friction => "friction",
            Perimeter::Pounding => "pounding",
            Perimeter::FrictionPounding => "friction-pounding",
        }
    }
}

/// The law of the grid connections (main-cross and cross-sub cross tee
/// joints, main-tee splices).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Connections {
    /// Continuous members through the joints (no connection springs).
    #[default]
    Rigid,
    /// Zero-length elastic springs K_cc1-3 (tee joints) and K_mc (splices).
    Elastic,
    /// As `elastic`, with the tee joints' axial spring a scaled CJS-A Pinching4.
    Pinching4,
}

impl Connections {
    /// The name as the `[model]` table writes it.
    pub fn name(self) -> &'static str {
        match self {
            Connections::Rigid => "rigid",
            Connections::Elastic => "elastic",
            Connections::Pinching4 => "pinching4",
        }
    }
}

/// The `[structure]` table (nominal values).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Structure {
    /// Plan size along x (m), a multiple of `module_m`.
    pub length_x_m: f64,
    /// Plan size along y (m), a multiple of `module_m`.
    pub length_y_m: f64,
    /// Panel size / cross-tee spacing (m).
    pub module_m: f64,
    /// Main-tee spacing (m), a multiple of `module_m`.
    pub main_tee_spacing_m: f64,
    /// Hanger rod spacing on the main tees (m).
    pub hanger_spacing_m: f64,
    /// Hanger rod length (m).
    pub hanger_length_m: f64,
    /// Mass of one lay-in panel (kg).
    pub panel_mass_kg: f64,
    /// 1 or 2 (2: carrying channels above the grid).
    #[serde(default = "two")]
    pub layers: u8,
    /// Perimeter condition.
    pub boundary: Boundary,
    /// Grid end to wall angle (mm).
    pub nominal_gap_mm: f64,
    /// Main tees on the lines x = 0, s, 2s, … and hanger rods on the rows
    /// y = 0, h, 2h, … counted from the origin corner (the frame of the
    /// measured-bundle format; the lines on a wall are the wall's);
    /// false (the default): the verification models' layout, the first
    /// main tee and the first row of rods one module from the walls.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub lines_from_origin: bool,
    /// Members lie on the wall lines: a main tee on a wall x = 0 or x = Lx
    /// that falls on the main-tee lines, hung on rods like the others, and
    /// cross tees along y = 0 and y = Ly (so the corners are grid nodes),
    /// every node on a wall still held by that wall's perimeter springs;
    /// false (the default): the lines on a wall are the wall's.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub wall_members: bool,
    /// Distance from the wall y = 0 to the first row of hanger rods (m), a
    /// multiple of `module_m` below `hanger_spacing_m`: the rows lie at
    /// y = offset, offset + h, … (in the frame the main tees are counted
    /// in); 0 (the default): on the lines y = 0, h, 2h, …, a row on a wall
    /// left out.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub hanger_offset_m: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn two() -> u8 {
    2
}

/// The `[model]` table as written: `variant` is the older shorthand for
/// `perimeter` and may not be given with it.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct ModelTable {
    #[serde(default)]
    variant: Option<Variant>,
    #[serde(default)]
    perimeter: Option<Perimeter>,
    #[serde(default)]
    connections: Connections,
}

/// The `[model]` table: which model variant to build (defaults: linear
/// perimeter, rigid connections).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize, Default)]
#[serde(try_from = "ModelTable")]
pub struct ModelOptions {
    /// Along-axis law at the perimeter.
    pub perimeter: Perimeter,
    /// Law of the grid connections.
    pub connections: Connections,
}

impl TryFrom<ModelTable> for ModelOptions {
    type Error = String;
    fn try_from(t: ModelTable) -> Result<Self, String> {
        let perimeter = match (t.variant, t.perimeter) {
            (Some(_), Some(_)) => {
                return Err("model: `variant` and `perimeter` given together; \
                            expected one (variant = \"nonlinear\" is perimeter = \"friction-pounding\")"
                    .into())
            }
            (Some(v), None) => Perimeter::from(v),
            (None, Some(p)) => p,
            (None, None) => Perimeter::default(),
        };
        Ok(ModelOptions { perimeter, connections: t.connections })
    }
}

impl From<Variant> for Perimeter {
    fn from(v: Variant) -> Self {
        match v {
            Variant::Linear => Perimeter::Linear,
            Variant::Nonlinear => Perimeter::FrictionPounding,
        }
    }
}

impl ModelOptions {
    /// A variant from its two choices.
    pub fn new(perimeter: Perimeter, connections: Connections) -> Self {
        ModelOptions { perimeter, connections }
    }
    /// The older shorthand: `nonlinear` is friction-pounding, rigid connections.
    pub fn from_variant(variant: Variant) -> Self {
        ModelOptions { perimeter: variant.into(), connections: Connections::Rigid }
    }
}

/// A specimen file: `[structure]` plus optional `[model]`; other tables of a
/// bundle (`sensors`, `runs`, ...) are ignored.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
pub struct CeilingSpec {
    /// The structure as built.
    pub structure: Structure,
    /// Model choices.
    #[serde(default)]
    pub model: ModelOptions,
}

/// Why a specimen file cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum SpecError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// TOML syntax or a key of the wrong type.
    #[error("{path}: {message}")]
    Toml {
        /// The file.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// A value out of range.
    #[error("structure.{key} = {value}: {expected}")]
    Value {
        /// The key.
        key: &'static str,
        /// Its value.
        value: f64,
        /// What was expected.
        expected: &'static str,
    },
}

impl CeilingSpec {
    /// A specimen from its structure and model choices, checked.
    pub fn new(structure: Structure, model: ModelOptions) -> Result<Self, SpecError> {
        let spec = CeilingSpec { structure, model };
        spec.check()?;
        Ok(spec)
    }

    /// The same structure with other model choices.
    pub fn with_model(&self, model: ModelOptions) -> Self {
        CeilingSpec { structure: self.structure.clone(), model }
    }

    /// Reads and checks a specimen TOML file.
    pub fn from_toml_file(path: &Path) -> Result<Self, SpecError> {
        let text = std::fs::read_to_string(path)
            .map_err(|source| SpecError::Io { path: path.to_path_buf(), source })?;
        Self::from_toml_str(&text, path)
    }

    /// Parses and checks specimen TOML text; `origin` names it in errors.
    pub fn from_toml_str(text: &str, origin: &Path) -> Result<Self, SpecError> {
        let spec: CeilingSpec = toml::from_str(text)
            .map_err(|e| SpecError::Toml { path: origin.to_path_buf(), message: e.to_string() })?;
        spec.check()?;
        Ok(spec)
    }

    /// Checks sizes are positive and on the module.
    #[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN must fail the check
    pub fn check(&self) -> Result<(), SpecError> {
        let s = &self.structure;
        let positive = [
            ("length_x_m", s.length_x_m),
            ("length_y_m", s.length_y_m),
            ("module_m", s.module_m),
            ("main_tee_spacing_m", s.main_tee_spacing_m),
            ("hanger_spacing_m", s.hanger_spacing_m),
            ("hanger_length_m", s.hanger_length_m),
            ("panel_mass_kg", s.panel_mass_kg),
        ];
        for (key, value) in positive {
            if !(value > 0.0 && value.is_finite()) {
                return Err(SpecError::Value { key, value, expected: "expected > 0" });
            }
        }
        let on_module = [
            ("length_x_m", s.length_x_m),
            ("length_y_m", s.length_y_m),
            ("main_tee_spacing_m", s.main_tee_spacing_m),
            ("hanger_spacing_m", s.hanger_spacing_m),
        ];
        for (key, value) in on_module {
            let r = value / s.module_m;
            if (r - r.round()).abs() > 1e-9 || r.round() < 1.0 {
                return Err(SpecError::Value {
                    key,
                    value,
                    expected: "expected a multiple of module_m",
                });
            }
        }
        let rows = s.hanger_offset_m / s.module_m;
        let on_module = (rows - rows.round()).abs() <= 1e-9;
        if !(s.hanger_offset_m >= 0.0 && s.hanger_offset_m < s.hanger_spacing_m && on_module) {
            return Err(SpecError::Value {
                key: "hanger_offset_m",
                value: s.hanger_offset_m,
                expected: "expected a multiple of module_m, >= 0 and below hanger_spacing_m",
            });
        }
        if !(1..=2).contains(&s.layers) {
            let value = f64::from(s.layers);
            return Err(SpecError::Value { key: "layers", value, expected: "expected 1 or 2" });
        }
        if !(s.nominal_gap_mm >= 0.0) {
            let value = s.nominal_gap_mm;
            return Err(SpecError::Value {
                key: "nominal_gap_mm",
                value,
                expected: "expected >= 0",
            });
        }
        Ok(())
    }
}
