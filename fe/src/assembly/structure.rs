//! The assembled structure: DOF map, sparse pattern, the beams' constant
//! stiffness, the springs' scatter positions and materials, and the lumped
//! mass diagonal, all on the free DOFs.

use std::collections::HashMap;

use super::{DofMap, SparsePattern};
use crate::elements::{beam_global_stiffness, spring_dofs};
use crate::materials::MaterialSpec;
use crate::model::Model;

/// Why a model cannot be assembled.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AssemblyError {
    /// A beam's geometry is degenerate (coincident nodes or parallel vecxz).
    #[error("beam {beam}: degenerate geometry (coincident nodes or vecxz parallel to the axis)")]
    BeamGeometry {
        /// Beam id.
        beam: u64,
    },
    /// A referenced node or material is missing (the model was not validated).
    #[error("{item}: reference to missing {what} {id}")]
    Missing {
        /// The referring item.
        item: String,
        /// "node" or "material".
        what: &'static str,
        /// The missing id.
        id: u64,
    },
}

/// One spring ready for the element loop.
#[derive(Debug, Clone)]
pub struct SpringSlot {
    /// Spring id.
    pub id: u64,
    /// Equation numbers of u_i[dof] and u_j[dof].
    pub eqs: [Option<usize>; 2],
    /// Storage positions of the 2×2 tangent (row-major).
    pub positions: [Option<usize>; 4],
    /// Its material.
    pub material: MaterialSpec,
    /// Whether its initial stiffness enters the Rayleigh term.
    pub rayleigh: bool,
}

/// A model assembled on its free DOFs.
#[derive(Debug, Clone)]
pub struct Structure {
    /// Equation numbering.
    pub dofs: DofMap,
    /// Sparsity pattern of K (and of K − σM, C, the Newmark matrix).
    pub pattern: SparsePattern,
    /// Values of the beams' (constant, linear) stiffness on `pattern`.
    pub beam_values: Vec<f64>,
    /// The springs, in file order.
    pub springs: Vec<SpringSlot>,
    /// Lumped mass per equation (t or t·mm²).
    pub mass: Vec<f64>,
}

impl Structure {
    /// Assembles a validated model.
    pub fn new(model: &Model) -> Result<Self, AssemblyError> {
        let dofs = DofMap::new(model);
        let beam_eqs: Vec<[Option<usize>; 12]> =
            model.beams.iter().map(|b| dofs.element_eqs(b.i, b.j)).collect();
        let spring_eqs: Vec<[Option<usize>; 2]> = model
            .springs
            .iter()
            .map(|s| {
                let e = dofs.element_eqs(s.i, s.j);
                spring_dofs(s.dof).map(|d| e[d])
            })
            .collect();
        let pattern = SparsePattern::from_elements(
            dofs.n_free,
            beam_eqs.iter().map(|e| &e[..]).chain(spring_eqs.iter().map(|e| &e[..])),
        );
        let beam_values = beam_values(model, &dofs, &pattern, &beam_eqs)?;
        let springs = spring_slots(model, &pattern, &spring_eqs)?;
        let mass = lumped_mass(model, &dofs);
        Ok(Structure { dofs, pattern, beam_values, springs, mass })
    }

    /// Adds each spring's tangent (N/mm, one per spring in order) into `values`.
    pub fn add_spring_tangents(&self, values: &mut [f64], tangents: &[f64]) {
        for (s, k) in self.springs.iter().zip(tangents) {
            for (p, sign) in s.positions.iter().zip([1.0, -1.0, -1.0, 1.0]) {
                if let Some(p) = p {
                    values[*p] += sign * k;
                }
            }
        }
    }

    /// Initial tangents of all springs (gaps open: 0).
    pub fn initial_spring_tangents(&self) -> Vec<f64> {
        self.springs.iter().map(|s| s.material.initial_tangent()).collect()
    }

    /// Values of the initial stiffness K on `pattern`.
    pub fn initial_stiffness(&self) -> Vec<f64> {
        let mut v = self.beam_values.clone();
        self.add_spring_tangents(&mut v, &self.initial_spring_tangents());
        v
    }

    /// Storage positions of the diagonal entries.
    pub fn diagonal_positions(&self) -> Vec<usize> {
        (0..self.pattern.n).map(|c| self.pattern.position(c, c).unwrap_or(usize::MAX)).collect()
    }
}

fn beam_values(
    model: &Model,
    dofs: &DofMap,
    pattern: &SparsePattern,
    beam_eqs: &[[Option<usize>; 12]],
) -> Result<Vec<f64>, AssemblyError> {
    let mut values = vec![0.0; pattern.nnz()];
    for (b, eqs) in model.beams.iter().zip(beam_eqs) {
        let missing =
            |id| AssemblyError::Missing { item: format!("beam {}", b.id), what: "node", id };
        let xi = dofs.coords(b.i).ok_or_else(|| missing(b.i))?;
        let xj = dofs.coords(b.j).ok_or_else(|| missing(b.j))?;
        let k =
            beam_global_stiffness(b, xi, xj).ok_or(AssemblyError::BeamGeometry { beam: b.id })?;
        for (rc, p) in pattern.positions(eqs).into_iter().enumerate() {
            if let Some(p) = p {
                values[p] += k[(rc / 12, rc % 12)];
            }
        }
    }
    Ok(values)
}

fn spring_slots(
    model: &Model,
    pattern: &SparsePattern,
    spring_eqs: &[[Option<usize>; 2]],
) -> Result<Vec<SpringSlot>, AssemblyError> {
    let mats: HashMap<u64, &MaterialSpec> =
        model.materials.iter().map(|m| (m.id, &m.spec)).collect();
    model
        .springs
        .iter()
        .zip(spring_eqs)
        .map(|(s, eqs)| {
            let material = (*mats.get(&s.mat).ok_or(AssemblyError::Missing {
                item: format!("spring {}", s.id),
                what: "material",
                id: s.mat,
            })?)
            .clone();
            let pos = pattern.positions(eqs);
            Ok(SpringSlot {
                id: s.id,
                eqs: *eqs,
                positions: [pos[0], pos[1], pos[2], pos[3]],
                material,
                rayleigh: s.rayleigh,
            })
        })
        .collect()
}

/// Lumped mass per equation; entries on one node add up.
fn lumped_mass(model: &Model, dofs: &DofMap) -> Vec<f64> {
    let mut m = vec![0.0; dofs.n_free];
    for entry in &model.masses {
        for (d, eq) in dofs.node_eqs(entry.node).iter().enumerate() {
            if let Some(eq) = eq {
                m[*eq] += entry.m_t[d];
            }
        }
    }
    m
}
