//! Checks run when a model is loaded: format and units, unique ids, node and
//! material references, coincident spring nodes, beam geometry and section
//! properties. Each error names the item and what was expected.

use std::collections::{HashMap, HashSet};

use super::ir::{Beam, Damping, Model, Spring, FORMAT_NAME, FORMAT_VERSION};
use crate::materials::{build, MaterialError};

/// Distance (mm) under which two spring nodes count as coincident.
pub const COINCIDENT_TOL_MM: f64 = 1e-6;

/// A broken rule of the model format.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// `format` or `format_version` is not the supported one.
    #[error("format `{found}` version {version}: expected `ceiling-fe-model` version 1")]
    Format {
        /// The format name found.
        found: String,
        /// The version found.
        version: u32,
    },
    /// A unit differs from N, mm, s, t.
    #[error("units.{key} = `{found}`: expected `{expected}`")]
    Units {
        /// The unit key.
        key: &'static str,
        /// The unit found.
        found: String,
        /// The unit required.
        expected: &'static str,
    },
    /// `ndm`/`ndf` not 3/6.
    #[error("ndm = {ndm}, ndf = {ndf}: expected ndm = 3, ndf = 6")]
    Dimensions {
        /// Found ndm.
        ndm: u32,
        /// Found ndf.
        ndf: u32,
    },
    /// An id is zero or used twice.
    #[error("{kind} id {id}: {expected}")]
    Id {
        /// "node", "element" or "material".
        kind: &'static str,
        /// The id.
        id: u64,
        /// What was expected.
        expected: &'static str,
    },
    /// A coordinate or value is NaN or infinite.
    #[error("{item}: {key} = {value}: expected a finite number")]
    NonFinite {
        /// The item, e.g. "node 12".
        item: String,
        /// The key.
        key: &'static str,
        /// The value.
        value: f64,
    },
    /// An item names a node that does not exist.
    #[error("{item}: node {node} does not exist")]
    DanglingNode {
        /// The item, e.g. "beam 3".
        item: String,
        /// The missing node id.
        node: u64,
    },
    /// A spring names a material that does not exist.
    #[error("spring {spring}: material {mat} does not exist")]
    DanglingMaterial {
        /// Spring id.
        spring: u64,
        /// Missing material id.
        mat: u64,
    },
    /// A spring's nodes are not coincident.
    #[error(
        "spring {spring}: nodes {i} and {j} are {distance_mm} mm apart: expected coincident nodes"
    )]
    NotCoincident {
        /// Spring id.
        spring: u64,
        /// Node i.
        i: u64,
        /// Node j.
        j: u64,
        /// Their distance (mm).
        distance_mm: f64,
    },
    /// A spring's DOF is out of 1..6.
    #[error("spring {spring}: dof = {dof}: expected 1..6")]
    Dof {
        /// Spring id.
        spring: u64,
        /// The DOF found.
        dof: u8,
    },
    /// A beam joins a node to itself or to a coincident node.
    #[error("beam {beam}: nodes {i} and {j} coincide: expected a positive length")]
    ZeroLength {
        /// Beam id.
        beam: u64,
        /// Node i.
        i: u64,
        /// Node j.
        j: u64,
    },
    /// vecxz is parallel to the beam axis (or zero).
    #[error("beam {beam}: vecxz {vecxz:?} is parallel to the beam axis: expected a vector not parallel to x")]
    ParallelVecxz {
        /// Beam id.
        beam: u64,
        /// The vector.
        vecxz: [f64; 3],
    },
    /// A section property is not positive.
    #[error("beam {beam}: {key} = {value}: expected > 0")]
    Section {
        /// Beam id.
        beam: u64,
        /// Property name as in the file (A, E, G, J, Iy, Iz).
        key: &'static str,
        /// Its value.
        value: f64,
    },
    /// A material's parameters are invalid.
    #[error("material {id}: {source}")]
    Material {
        /// Material id.
        id: u64,
        /// The material's complaint.
        source: MaterialError,
    },
    /// The damping block breaks a rule.
    #[error("damping.{key} = {found}: expected {expected}")]
    Damping {
        /// The key as in the file.
        key: &'static str,
        /// The value found.
        found: String,
        /// What was expected.
        expected: &'static str,
    },
    /// A mass is negative.
    #[error("mass on node {node}: m[{index}] = {value}: expected >= 0")]
    NegativeMass {
        /// Node id.
        node: u64,
        /// Index 0..5.
        index: usize,
        /// The value.
        value: f64,
    },
}

/// Checks a model against every rule; returns the first broken one.
#[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN must fail the check
pub fn validate(model: &Model) -> Result<(), ModelError> {
    check_header(model)?;
    let coords = check_nodes(model)?;
    let has = |item: String, node: u64| {
        if coords.contains_key(&node) {
            Ok(())
        } else {
            Err(ModelError::DanglingNode { item, node })
        }
    };
    for f in &model.fixities {
        has(format!("fixity of node {}", f.node), f.node)?;
    }
    for m in &model.masses {
        has(format!("mass on node {}", m.node), m.node)?;
        if let Some((index, &value)) = m.m_t.iter().enumerate().find(|(_, v)| !(**v >= 0.0)) {
            return Err(ModelError::NegativeMass { node: m.node, index, value });
        }
    }
    let mats = check_materials(model)?;
    let mut elements = HashSet::new();
    for b in &model.beams {
        unique_element(&mut elements, b.id)?;
        has(format!("beam {}", b.id), b.i)?;
        has(format!("beam {}", b.id), b.j)?;
        check_beam(b, coords[&b.i], coords[&b.j])?;
    }
    for s in &model.springs {
        unique_element(&mut elements, s.id)?;
        has(format!("spring {}", s.id), s.i)?;
        has(format!("spring {}", s.id), s.j)?;
        check_spring(s, coords[&s.i], coords[&s.j], &mats)?;
    }
    model.damping.as_ref().map_or(Ok(()), check_damping)
}

/// Rayleigh damping with finite coefficients >= 0 on a stiffness the
/// format knows.
#[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN must fail the check
fn check_damping(d: &Damping) -> Result<(), ModelError> {
    let bad = |key, found: String, expected| ModelError::Damping { key, found, expected };
    if d.kind != "rayleigh" {
        return Err(bad("type", format!("`{}`", d.kind), "`rayleigh`"));
    }
    for (key, v) in [("alphaM", d.alpha_m_per_s), ("betaK", d.beta_k_s)] {
        if !(v >= 0.0 && v.is_finite()) {
            return Err(bad(key, v.to_string(), "a finite number >= 0"));
        }
    }
    d.stiffness().map_err(|found| bad("stiffness", found, "\"initial\" or \"committed\""))?;
    d.committed_share().map_err(|found| {
        bad("committed_share", found, "a number 0..=1, with stiffness = \"committed\"")
    })?;
    Ok(())
}

fn check_header(model: &Model) -> Result<(), ModelError> {
    if model.format != FORMAT_NAME || model.format_version != FORMAT_VERSION {
        return Err(ModelError::Format {
            found: model.format.clone(),
            version: model.format_version,
        });
    }
    let u = &model.units;
    for (key, found, expected) in [
        ("force", &u.force, "N"),
        ("length", &u.length, "mm"),
        ("time", &u.time, "s"),
        ("mass", &u.mass, "t"),
    ] {
        if found != expected {
            return Err(ModelError::Units { key, found: found.clone(), expected });
        }
    }
    if model.ndm != 3 || model.ndf != 6 {
        return Err(ModelError::Dimensions { ndm: model.ndm, ndf: model.ndf });
    }
    Ok(())
}

fn check_nodes(model: &Model) -> Result<HashMap<u64, [f64; 3]>, ModelError> {
    let mut coords = HashMap::with_capacity(model.nodes.len());
    for n in &model.nodes {
        if n.id == 0 {
            return Err(ModelError::Id { kind: "node", id: 0, expected: "expected a positive id" });
        }
        for (k, key) in ["x", "y", "z"].into_iter().enumerate() {
            if !n.xyz_mm[k].is_finite() {
                let item = format!("node {}", n.id);
                return Err(ModelError::NonFinite { item, key, value: n.xyz_mm[k] });
            }
        }
        if coords.insert(n.id, n.xyz_mm).is_some() {
            return Err(ModelError::Id { kind: "node", id: n.id, expected: "duplicate node id" });
        }
    }
    Ok(coords)
}

fn check_materials(model: &Model) -> Result<HashSet<u64>, ModelError> {
    let mut ids = HashSet::new();
    for m in &model.materials {
        if !ids.insert(m.id) {
            return Err(ModelError::Id {
                kind: "material",
                id: m.id,
                expected: "duplicate material id",
            });
        }
        build(&m.spec).map_err(|source| ModelError::Material { id: m.id, source })?;
    }
    Ok(ids)
}

fn unique_element(seen: &mut HashSet<u64>, id: u64) -> Result<(), ModelError> {
    if id == 0 || !seen.insert(id) {
        let expected = if id == 0 {
            "expected a positive id"
        } else {
            "duplicate element id (beams and springs share one id space)"
        };
        return Err(ModelError::Id { kind: "element", id, expected });
    }
    Ok(())
}

#[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN must fail the check
fn check_beam(b: &Beam, xi: [f64; 3], xj: [f64; 3]) -> Result<(), ModelError> {
    for (key, value) in [
        ("A", b.area_mm2),
        ("E", b.e_mpa),
        ("G", b.g_mpa),
        ("J", b.j_mm4),
        ("Iy", b.iy_mm4),
        ("Iz", b.iz_mm4),
    ] {
        if !(value > 0.0) || !value.is_finite() {
            return Err(ModelError::Section { beam: b.id, key, value });
        }
    }
    let axis = [xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]];
    let len = norm(axis);
    if len <= COINCIDENT_TOL_MM {
        return Err(ModelError::ZeroLength { beam: b.id, i: b.i, j: b.j });
    }
    let v = b.vecxz;
    let c = cross(v, axis);
    if !(norm(c) > 1e-9 * norm(v) * len) {
        return Err(ModelError::ParallelVecxz { beam: b.id, vecxz: v });
    }
    Ok(())
}

fn check_spring(
    s: &Spring,
    xi: [f64; 3],
    xj: [f64; 3],
    mats: &HashSet<u64>,
) -> Result<(), ModelError> {
    if !(1..=6).contains(&s.dof) {
        return Err(ModelError::Dof { spring: s.id, dof: s.dof });
    }
    if !mats.contains(&s.mat) {
        return Err(ModelError::DanglingMaterial { spring: s.id, mat: s.mat });
    }
    let distance_mm = norm([xj[0] - xi[0], xj[1] - xi[1], xj[2] - xi[2]]);
    if distance_mm > COINCIDENT_TOL_MM {
        return Err(ModelError::NotCoincident { spring: s.id, i: s.i, j: s.j, distance_mm });
    }
    Ok(())
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
