//! Pinching4 damage indices (OpenSees `updateDmg`): unloading-stiffness,
//! reloading-stiffness and strength degradation,
//! gamma = g1 (u_max / u_ult)^g3 + g2 x^g4 with x the cycle count or the
//! normalised dissipated energy, capped by the limits and, for stiffness, by
//! the secant stiffness at the largest excursions. Dimensionless.

use super::super::pinching4_path::{neg_backbone, pos_backbone};
use super::{History, Pinching4};

/// How damage accumulates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DamageType {
    /// Damage grows with the number of cycles.
    Cycle,
    /// Damage grows with the dissipated energy.
    Energy,
}

/// One damage rule: gamma = g1 (umax/uult)^g3 + g2 (E or n)^g4, capped.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DamageRule {
    /// Coefficients g1..g4.
    pub g: [f64; 4],
    /// Upper limit of the damage index.
    pub limit: f64,
}

impl Pinching4 {
    /// Damage indices of the trial (OpenSees `updateDmg`).
    pub(super) fn update_damage(&self, t: &mut History, u: f64, du: f64, elastic_energy: f64) {
        let u_max_abs = if t.max_demand > -t.min_demand { t.max_demand } else { -t.min_demand };
        let u_ult_abs =
            if self.pos.disp[4] > -self.neg.disp[4] { self.pos.disp[4] } else { -self.neg.disp[4] };
        t.n_cycle = self.committed.n_cycle + du.abs() / (4.0 * u_max_abs);
        if !(u < u_ult_abs && u > -u_ult_abs) {
            return;
        }
        let k_min_p = pos_backbone(&self.pos.disp, &t.pos_f_dmg, t.max_demand).0 / t.max_demand;
        let k_min_n = neg_backbone(&self.neg.disp, &t.neg_f_dmg, t.min_demand).0 / t.min_demand;
        let (rp, rn) = (k_min_p / self.k_elastic_pos, k_min_n / self.k_elastic_neg);
        let k_min = if rp >= rn { rp } else { rn };
        let gamma_k_env = if 0.0 > 1.0 - k_min { 0.0 } else { 1.0 - k_min };
        if t.energy < self.energy_capacity {
            let ratio = u_max_abs / u_ult_abs;
            let growth = match self.damage {
                DamageType::Energy if t.energy > elastic_energy => {
                    Some((t.energy - elastic_energy) / self.energy_capacity)
                }
                DamageType::Energy => None,
                DamageType::Cycle => Some(t.n_cycle),
            };
            let index = |r: &DamageRule| {
                let base = r.g[0] * ratio.powf(r.g[2]);
                match growth {
                    Some(x) => base + r.g[1] * x.powf(r.g[3]),
                    None => base,
                }
            };
            let (gk, gd, gf) = (index(&self.k_rule), index(&self.d_rule), index(&self.f_rule));
            let gk = if gk < self.k_rule.limit { gk } else { self.k_rule.limit };
            t.gamma_k = if gk < gamma_k_env { gk } else { gamma_k_env };
            t.gamma_d = if gd < self.d_rule.limit { gd } else { self.d_rule.limit };
            t.gamma_f = if gf < self.f_rule.limit { gf } else { self.f_rule.limit };
        } else {
            let lim = self.k_rule.limit;
            t.gamma_k = if lim < gamma_k_env { lim } else { gamma_k_env };
            t.gamma_d = self.d_rule.limit;
            t.gamma_f = self.f_rule.limit;
        }
    }
}
