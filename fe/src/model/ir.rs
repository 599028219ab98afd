//! Types of the `ceiling-fe-model` v1 format (`shared/verification/MODEL_FORMAT.md`).
//!
//! Units: N, mm, s, t (tonne = N s²/mm); stiffness N/mm, moduli MPa. The
//! field names carry their units; serde names follow the JSON file.

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use crate::materials::MaterialSpec;

/// The value of the `format` key.
pub const FORMAT_NAME: &str = "ceiling-fe-model";
/// The supported `format_version`.
pub const FORMAT_VERSION: u32 = 1;

/// A whole model file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Model {
    /// Must be [`FORMAT_NAME`].
    pub format: String,
    /// Must be [`FORMAT_VERSION`].
    pub format_version: u32,
    /// Short name.
    #[serde(default)]
    pub name: String,
    /// Free text.
    #[serde(default)]
    pub description: String,
    /// Unit block; must be N, mm, s, t.
    pub units: Units,
    /// Number of dimensions (3).
    pub ndm: u32,
    /// DOFs per node (6).
    pub ndf: u32,
    /// Nodes with coordinates.
    pub nodes: Vec<Node>,
    /// Fixed DOFs.
    #[serde(default)]
    pub fixities: Vec<Fixity>,
    /// Uniaxial materials.
    #[serde(default)]
    pub materials: Vec<MaterialDef>,
    /// Elastic beam-columns.
    #[serde(default)]
    pub beams: Vec<Beam>,
    /// Zero-length one-DOF springs.
    #[serde(default)]
    pub springs: Vec<Spring>,
    /// Lumped masses.
    #[serde(default)]
    pub masses: Vec<Mass>,
    /// Rayleigh damping (transient only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damping: Option<Damping>,
    /// The analysis the file asks for.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub analysis: Option<Analysis>,
    /// Descriptive information, never needed to rebuild.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub meta: Option<Value>,
}

impl Model {
    /// A 3-D model named `name` in the standard units with nothing in it.
    pub fn empty(name: &str) -> Self {
        Model {
            format: FORMAT_NAME.into(),
            format_version: FORMAT_VERSION,
            name: name.into(),
            description: String::new(),
            units: Units::standard(),
            ndm: 3,
            ndf: 6,
            nodes: vec![],
            fixities: vec![],
            materials: vec![],
            beams: vec![],
            springs: vec![],
            masses: vec![],
            damping: None,
            analysis: None,
            meta: None,
        }
    }

    /// DOFs that carry mass (each positive entry of each lumped mass): the
    /// most modes an eigen solution can have.
    pub fn mass_dofs(&self) -> usize {
        self.masses.iter().map(|m| m.m_t.iter().filter(|v| **v > 0.0).count()).sum()
    }
}

/// The `units` block.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Units {
    /// Force unit ("N").
    pub force: String,
    /// Length unit ("mm").
    pub length: String,
    /// Time unit ("s").
    pub time: String,
    /// Mass unit ("t").
    pub mass: String,
    /// Descriptive keys (`note`).
    #[serde(flatten)]
    pub extra: Map<String, Value>,
}

impl Units {
    /// The only unit block v1 allows.
    pub fn standard() -> Self {
        Units {
            force: "N".into(),
            length: "mm".into(),
            time: "s".into(),
            mass: "t".into(),
            extra: Map::new(),
        }
    }
}

/// A node `[id, x, y, z]` (mm).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(from = "(u64, f64, f64, f64)", into = "(u64, f64, f64, f64)")]
pub struct Node {
    /// Node id (> 0).
    pub id: u64,
    /// Coordinates (mm).
    pub xyz_mm: [f64; 3],
}

impl From<(u64, f64, f64, f64)> for Node {
    fn from(t: (u64, f64, f64, f64)) -> Self {
        Node { id: t.0, xyz_mm: [t.1, t.2, t.3] }
    }
}

impl From<Node> for (u64, f64, f64, f64) {
    fn from(n: Node) -> Self {
        (n.id, n.xyz_mm[0], n.xyz_mm[1], n.xyz_mm[2])
    }
}

/// A fixity `[node, f1, ..., f6]`; `true` = that DOF is held at zero.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(from = "(u64, u8, u8, u8, u8, u8, u8)", into = "(u64, u8, u8, u8, u8, u8, u8)")]
pub struct Fixity {
    /// Node id.
    pub node: u64,
    /// Fixed flags for ux, uy, uz, rx, ry, rz.
    pub fixed: [bool; 6],
}

impl From<(u64, u8, u8, u8, u8, u8, u8)> for Fixity {
    fn from(t: (u64, u8, u8, u8, u8, u8, u8)) -> Self {
        let f = [t.1, t.2, t.3, t.4, t.5, t.6].map(|v| v != 0);
        Fixity { node: t.0, fixed: f }
    }
}

impl From<Fixity> for (u64, u8, u8, u8, u8, u8, u8) {
    fn from(f: Fixity) -> Self {
        let v = f.fixed.map(u8::from);
        (f.node, v[0], v[1], v[2], v[3], v[4], v[5])
    }
}

/// A material with its id; the JSON object is `{"id", "type", ...}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "Value", into = "Value")]
pub struct MaterialDef {
    /// Material id.
    pub id: u64,
    /// The law and its parameters.
    pub spec: MaterialSpec,
}

impl TryFrom<Value> for MaterialDef {
    type Error = String;
    fn try_from(v: Value) -> Result<Self, String> {
        let id = v.get("id").and_then(Value::as_u64).ok_or("material without integer `id`")?;
        let spec = serde_json::from_value(v).map_err(|e| format!("material {id}: {e}"))?;
        Ok(MaterialDef { id, spec })
    }
}

impl From<MaterialDef> for Value {
    fn from(m: MaterialDef) -> Value {
        let mut v = serde_json::to_value(&m.spec).unwrap_or(Value::Null);
        if let Value::Object(map) = &mut v {
            map.insert("id".into(), Value::from(m.id));
        }
        v
    }
}

/// A 3D elastic Euler-Bernoulli beam-column (OpenSees `elasticBeamColumn`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Beam {
    /// Element id (shared with springs).
    pub id: u64,
    /// Start node.
    pub i: u64,
    /// End node.
    pub j: u64,
    /// Area (mm²).
    #[serde(rename = "A")]
    pub area_mm2: f64,
    /// Young's modulus (MPa).
    #[serde(rename = "E")]
    pub e_mpa: f64,
    /// Shear modulus (MPa).
    #[serde(rename = "G")]
    pub g_mpa: f64,
    /// Torsion constant (mm⁴).
    #[serde(rename = "J")]
    pub j_mm4: f64,
    /// Second moment about local y (mm⁴).
    #[serde(rename = "Iy")]
    pub iy_mm4: f64,
    /// Second moment about local z (mm⁴).
    #[serde(rename = "Iz")]
    pub iz_mm4: f64,
    /// A vector in the local x-z plane (global components).
    pub vecxz: [f64; 3],
    /// Descriptive member group.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub group: Option<String>,
}

/// A zero-length spring in one global DOF between coincident nodes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Spring {
    /// Element id (shared with beams).
    pub id: u64,
    /// Node i (deformation d = u_j - u_i).
    pub i: u64,
    /// Node j.
    pub j: u64,
    /// Global DOF 1..6.
    pub dof: u8,
    /// Material id.
    pub mat: u64,
    /// Whether the initial stiffness enters the Rayleigh term.
    #[serde(default)]
    pub rayleigh: bool,
    /// Descriptive group.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub group: Option<String>,
    /// Descriptive wall side.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub side: Option<String>,
    /// Descriptive member name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub member: Option<String>,
}

/// A lumped mass on a node, in t and t·mm².
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Mass {
    /// Node id.
    pub node: u64,
    /// Masses for the six DOFs (t, t, t, t·mm², t·mm², t·mm²).
    #[serde(rename = "m")]
    pub m_t: [f64; 6],
}

/// Rayleigh damping C = alphaM M + betaK K_R.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Damping {
    /// "rayleigh".
    #[serde(rename = "type")]
    pub kind: String,
    /// Mass coefficient (1/s).
    #[serde(rename = "alphaM")]
    pub alpha_m_per_s: f64,
    /// Stiffness coefficient (s); the stiffness is the one `stiffness` names.
    #[serde(rename = "betaK")]
    pub beta_k_s: f64,
    /// `stiffness` ([`Damping::stiffness`]) and descriptive keys (`target`,
    /// `applies_to`).
    #[serde(flatten)]
    pub extra: Map<String, Value>,
}

/// The stiffness the Rayleigh term β K_R is proportional to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DampingStiffness {
    /// The initial stiffness (OpenSees `betaKinit`); the format's default.
    #[default]
    Initial,
    /// Each flagged spring's last committed tangent (OpenSees `betaKcomm`);
    /// the beams are elastic, so theirs stays the initial one.
    Committed,
}

impl Damping {
    /// The `stiffness` key: `initial` when absent, else `initial` or
    /// `committed`; any other value is returned as found.
    pub fn stiffness(&self) -> Result<DampingStiffness, String> {
        match self.extra.get("stiffness") {
            None => Ok(DampingStiffness::Initial),
            Some(Value::String(s)) if s == "initial" => Ok(DampingStiffness::Initial),
            Some(Value::String(s)) if s == "committed" => Ok(DampingStiffness::Committed),
            Some(v) => Err(v.to_string()),
        }
    }

    /// The share s of the committed-tangent form, for K_R = (1 − s) K₀ +
    /// s K_committed on the flagged springs: 0 on the initial stiffness;
    /// `committed_share` (default 1) on the committed tangent. A share
    /// outside 0..=1, or given with the initial stiffness, is returned as
    /// found.
    pub fn committed_share(&self) -> Result<f64, String> {
        let share = self.extra.get("committed_share");
        match (self.stiffness(), share) {
            (Ok(DampingStiffness::Initial), None) => Ok(0.0),
            (Ok(DampingStiffness::Committed), None) => Ok(1.0),
            (Ok(DampingStiffness::Committed), Some(v)) => match v.as_f64() {
                Some(x) if (0.0..=1.0).contains(&x) => Ok(x),
                _ => Err(v.to_string()),
            },
            (_, Some(v)) => Err(v.to_string()),
            (Err(found), None) => Err(found),
        }
    }
}

/// The analysis block.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum Analysis {
    /// Lowest `n_modes` modes of K phi = w² M phi.
    Eigen {
        /// Number of modes.
        n_modes: usize,
        /// Descriptive keys.
        #[serde(flatten)]
        extra: Map<String, Value>,
    },
    /// Time history; its keys are kept as written.
    Transient(Map<String, Value>),
}
