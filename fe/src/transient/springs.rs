//! The springs' material states during a transient run: trial deformations
//! from the nodal displacements, their forces and tangents, and the
//! commit / revert life cycle delegated to each [`UniaxialMaterial`]. With
//! damping on the committed tangent ([`super::tangent_damping`]) a damped
//! spring's force and tangent include its damping; its material force is
//! kept apart for the recorders.
//!
//! Units: deformation mm, force N, tangent N/mm.

use super::low_rank::w_dot;
use super::newmark::NewmarkConstants;
use super::newton::Kinematics;
use super::tangent_damping::CommittedTangentDamping;
use crate::assembly::Structure;
use crate::materials::{build, MaterialError, UniaxialMaterial};

/// One material instance per spring plus the trial and committed values.
pub struct SpringStates {
    materials: Vec<Box<dyn UniaxialMaterial>>,
    /// Trial deformation per spring (mm).
    pub deformation_mm: Vec<f64>,
    /// Trial force per spring (N), its damping on the committed tangent
    /// included.
    pub force_n: Vec<f64>,
    /// Trial tangent per spring (N/mm), its damping's included.
    pub tangent_n_mm: Vec<f64>,
    /// Trial material force per spring (N).
    pub material_force_n: Vec<f64>,
    /// Committed deformation, force, tangent and material force.
    committed: [Vec<f64>; 4],
    damping: Option<CommittedTangentDamping>,
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
            material_force_n: vec![0.0; n],
            committed: [vec![0.0; n], vec![0.0; n], tangent, vec![0.0; n]],
            damping: None,
        })
    }

    /// Damps the flagged nonlinear springs on their committed tangent with
    /// coefficient s β (s) ([`super::tangent_damping`]).
    pub fn with_committed_tangent_damping(mut self, s: &Structure, beta_k_s: f64) -> Self {
        self.damping = CommittedTangentDamping::of(s, beta_k_s);
        self
    }

    /// Starts a step of `nm` from the committed state: fixes each damped
    /// spring's damping for the step and sets its force and tangent at the
    /// committed deformation. Does nothing without such damping.
    pub fn begin_step(&mut self, s: &Structure, nm: &NewmarkConstants, committed: &Kinematics) {
        let Some(dmp) = self.damping.as_mut() else { return };
        dmp.begin_step(s, nm, committed, &self.deformation_mm);
        for i in 0..dmp.len() {
            let k = dmp.spring(i);
            let kt = dmp.committed_tangent_n_mm(i);
            let (fc, kc) = dmp.trial(k, self.deformation_mm[k], kt);
            self.force_n[k] = self.material_force_n[k] + fc;
            self.tangent_n_mm[k] = kt + kc;
        }
    }

    /// Sets every spring's trial deformation from the free-DOF displacements.
    pub fn set_trial(&mut self, s: &Structure, u: &[f64]) -> Result<(), SpringFailure> {
        for (k, sp) in s.springs.iter().enumerate() {
            self.set_trial_one(s, k, w_dot(&sp.eqs, u))?;
        }
        Ok(())
    }

    /// Sets spring `k`'s trial deformation `d_mm`; returns its force and
    /// tangent (damping included).
    pub fn set_trial_one(
        &mut self,
        s: &Structure,
        k: usize,
        d_mm: f64,
    ) -> Result<(f64, f64), SpringFailure> {
        let (f, kt) = self.materials[k]
            .trial(d_mm)
            .map_err(|error| SpringFailure { spring: s.springs[k].id, error })?;
        let (fc, kc) = self.damping.as_mut().map_or((0.0, 0.0), |dm| dm.trial(k, d_mm, kt));
        self.deformation_mm[k] = d_mm;
        self.material_force_n[k] = f;
        self.force_n[k] = f + fc;
        self.tangent_n_mm[k] = kt + kc;
        Ok((f + fc, kt + kc))
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
        if let Some(dm) = self.damping.as_mut() {
            dm.commit();
        }
        let [d, f, kt, fm] = &mut self.committed;
        d.clone_from(&self.deformation_mm);
        f.clone_from(&self.force_n);
        kt.clone_from(&self.tangent_n_mm);
        fm.clone_from(&self.material_force_n);
    }

    /// Returns every material to its last committed state.
    pub fn revert(&mut self) {
        self.materials.iter_mut().for_each(|m| m.revert());
        if let Some(dm) = self.damping.as_mut() {
            dm.revert();
        }
        let [d, f, kt, fm] = &self.committed;
        self.deformation_mm.clone_from(d);
        self.force_n.clone_from(f);
        self.tangent_n_mm.clone_from(kt);
        self.material_force_n.clone_from(fm);
    }
}
