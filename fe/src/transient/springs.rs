//! The springs' material states during a transient run: trial deformations
//! from the nodal displacements, their forces and tangents, and the
//! commit / revert life cycle delegated to each [`UniaxialMaterial`].
//!
//! Units: deformation mm, force N, tangent N/mm.

use crate::assembly::Structure;
use crate::materials::{build, MaterialError, UniaxialMaterial};

/// One material instance per spring plus the trial and committed values.
pub struct SpringStates {
    materials: Vec<Box<dyn UniaxialMaterial>>,
    /// Trial deformation per spring (mm).
    pub deformation_mm: Vec<f64>,
    /// Trial force per spring (N).
    pub force_n: Vec<f64>,
    /// Trial tangent per spring (N/mm).
    pub tangent_n_mm: Vec<f64>,
    committed: (Vec<f64>, Vec<f64>, Vec<f64>),
}

/// A spring whose material refused a trial deformation.
#[derive(Debug, Clone, PartialEq)]
pub struct SpringFailure {
    /// Spring id.
    pub spring: u64,
    /// The material's complaint.
    pub error: MaterialError,
}

impl SpringStates {
    /// Virgin materials for every spring of the structure.
    pub fn new(s: &Structure) -> Result<Self, SpringFailure> {
        let materials = s
            .springs
            .iter()
            .map(|sp| build(&sp.material).map_err(|error| SpringFailure { spring: sp.id, error }))
            .collect::<Result<Vec<_>, _>>()?;
        let n = materials.len();
        let tangent: Vec<f64> = materials.iter().map(|m| m.tangent()).collect();
        Ok(SpringStates {
            materials,
            deformation_mm: vec![0.0; n],
            force_n: vec![0.0; n],
            tangent_n_mm: tangent.clone(),
            committed: (vec![0.0; n], vec![0.0; n], tangent),
        })
    }

    /// Sets every spring's trial deformation from the free-DOF displacements.
    pub fn set_trial(&mut self, s: &Structure, u: &[f64]) -> Result<(), SpringFailure> {
        for (k, (sp, m)) in s.springs.iter().zip(self.materials.iter_mut()).enumerate() {
            let ui = sp.eqs[0].map_or(0.0, |e| u[e]);
            let uj = sp.eqs[1].map_or(0.0, |e| u[e]);
            let d = uj - ui;
            let (f, kt) = m.trial(d).map_err(|error| SpringFailure { spring: sp.id, error })?;
            self.deformation_mm[k] = d;
            self.force_n[k] = f;
            self.tangent_n_mm[k] = kt;
        }
        Ok(())
    }

    /// Sets spring `k`'s trial deformation `d_mm`; returns its force and tangent.
    pub fn set_trial_one(
        &mut self,
        s: &Structure,
        k: usize,
        d_mm: f64,
    ) -> Result<(f64, f64), SpringFailure> {
        let (f, kt) = self.materials[k]
            .trial(d_mm)
            .map_err(|error| SpringFailure { spring: s.springs[k].id, error })?;
        self.deformation_mm[k] = d_mm;
        self.force_n[k] = f;
        self.tangent_n_mm[k] = kt;
        Ok((f, kt))
    }

    /// Adds the resisting forces (−f on i, +f on j) into `out`.
    pub fn add_forces(&self, s: &Structure, out: &mut [f64]) {
        for (sp, f) in s.springs.iter().zip(&self.force_n) {
            if let Some(e) = sp.eqs[0] {
                out[e] -= f;
            }
            if let Some(e) = sp.eqs[1] {
                out[e] += f;
            }
        }
    }

    /// Commits every material at its trial state.
    pub fn commit(&mut self) {
        self.materials.iter_mut().for_each(|m| m.commit());
        self.committed.0.clone_from(&self.deformation_mm);
        self.committed.1.clone_from(&self.force_n);
        self.committed.2.clone_from(&self.tangent_n_mm);
    }

    /// Returns every material to its last committed state.
    pub fn revert(&mut self) {
        self.materials.iter_mut().for_each(|m| m.revert());
        self.deformation_mm.clone_from(&self.committed.0);
        self.force_n.clone_from(&self.committed.1);
        self.tangent_n_mm.clone_from(&self.committed.2);
    }
}
