//! Pinching4 branches (OpenSees `getstate` and the force evaluation of
//! `setTrialStrain`): which of the five states the trial is in, the bounds
//! of that branch, and the force and tangent on it. Units: mm, N, N/mm.

use super::super::pinching4_path::{
    neg_backbone, pos_backbone, state3_path, state4_path, PathInputs,
};
use super::{History, Pinching4};

impl Pinching4 {
    /// Switches the trial state when `u` leaves the current branch or the
    /// loading direction reverses (OpenSees `getstate`).
    pub(super) fn update_branch(&self, t: &mut History, u: f64, du: f64) {
        let reversal_check = du * self.committed.rate <= 0.0;
        if !(u < t.low_d || u > t.high_d || reversal_check) {
            return;
        }
        match t.state {
            0 => {
                if u > t.high_d {
                    self.enter_positive_backbone(t, false);
                } else if u < t.low_d {
                    self.enter_negative_backbone(t, false);
                }
            }
            1 if du < 0.0 => self.unload_positive_backbone(t, u, du),
            2 if du > 0.0 => self.unload_negative_backbone(t, u),
            3 => self.leave_state3(t, u, du),
            4 => self.leave_state4(t, u, du),
            _ => {}
        }
    }

    /// Unloading from the positive backbone: records the peak demand and
    /// heads for the negative side (state 3, or state 2 beyond its demand).
    fn unload_positive_backbone(&self, t: &mut History, u: f64, du: f64) {
        if self.committed.d > t.max_demand {
            t.max_demand = u - du;
        }
        if t.max_demand < t.u_max_dmg {
            t.max_demand = t.u_max_dmg;
        }
        self.damage_negative_strength(t);
        if u < t.u_min_dmg {
            self.enter_negative_backbone(t, false);
        } else {
            self.enter_state3(t);
        }
        self.damage_positive_stiffness(t);
    }

    /// Unloading from the negative backbone: records the peak demand and
    /// heads for the positive side (state 4, or state 1 beyond its demand).
    fn unload_negative_backbone(&self, t: &mut History, u: f64) {
        if self.committed.d < t.min_demand {
            t.min_demand = self.committed.d;
        }
        if t.min_demand > t.u_min_dmg {
            t.min_demand = t.u_min_dmg;
        }
        self.damage_positive_strength(t);
        if u > t.u_max_dmg {
            self.enter_positive_backbone(t, false);
        } else {
            self.enter_state4(t);
        }
        self.damage_negative_stiffness(t);
    }

    /// Leaving state 3 (reloading towards the negative side).
    fn leave_state3(&self, t: &mut History, u: f64, du: f64) {
        if u < t.low_d {
            self.enter_negative_backbone(t, true);
        } else if u > t.u_max_dmg && du > 0.0 {
            self.enter_positive_backbone(t, false);
        } else if du > 0.0 {
            self.damage_positive_strength(t);
            self.enter_state4(t);
            self.damage_negative_stiffness(t);
        }
    }

    /// Leaving state 4 (reloading towards the positive side).
    fn leave_state4(&self, t: &mut History, u: f64, du: f64) {
        if u > t.high_d {
            self.enter_positive_backbone(t, true);
        } else if u < t.u_min_dmg && du < 0.0 {
            self.enter_negative_backbone(t, true);
        } else if du < 0.0 {
            self.damage_negative_strength(t);
            self.enter_state3(t);
            self.damage_positive_stiffness(t);
        }
    }

    /// Applies the committed stiffness damage to the positive unloading slope.
    fn damage_positive_stiffness(&self, t: &mut History) {
        t.gamma_k_used = self.committed.gamma_k;
        t.k_pos_dmg = self.k_elastic_pos * (1.0 - t.gamma_k_used);
    }

    /// Applies the committed stiffness damage to the negative unloading slope.
    fn damage_negative_stiffness(&self, t: &mut History) {
        t.gamma_k_used = self.committed.gamma_k;
        t.k_neg_dmg = self.k_elastic_neg * (1.0 - t.gamma_k_used);
    }

    /// Applies the committed strength damage to the positive backbone.
    fn damage_positive_strength(&self, t: &mut History) {
        t.gamma_f_used = self.committed.gamma_f;
        t.pos_f_dmg = self.pos.force.map(|f| f * (1.0 - t.gamma_f_used));
    }

    /// Applies the committed strength damage to the negative backbone.
    fn damage_negative_strength(&self, t: &mut History) {
        t.gamma_f_used = self.committed.gamma_f;
        t.neg_f_dmg = self.neg.force.map(|f| f * (1.0 - t.gamma_f_used));
    }

    /// State 1; its bounds carry damaged forces when entered from state 4.
    fn enter_positive_backbone(&self, t: &mut History, damaged_bounds: bool) {
        let f = if damaged_bounds { t.pos_f_dmg } else { self.pos.force };
        t.state = 1;
        t.low_d = self.pos.disp[0];
        t.low_f = f[0];
        t.high_d = self.pos.disp[5];
        t.high_f = f[5];
    }

    /// State 2; its bounds carry damaged forces when entered from state 3 or 4.
    fn enter_negative_backbone(&self, t: &mut History, damaged: bool) {
        let f = if damaged { t.neg_f_dmg } else { self.neg.force };
        t.state = 2;
        t.low_d = self.neg.disp[5];
        t.low_f = f[5];
        t.high_d = self.neg.disp[0];
        t.high_f = f[0];
    }

    /// State 3: from the committed point down to the damaged negative target.
    fn enter_state3(&self, t: &mut History) {
        let c = &self.committed;
        t.state = 3;
        t.low_d = t.u_min_dmg;
        t.low_f = neg_backbone(&self.neg.disp, &t.neg_f_dmg, t.u_min_dmg).0;
        t.high_d = c.d;
        t.high_f = c.f;
    }

    /// State 4: from the committed point up to the damaged positive target.
    fn enter_state4(&self, t: &mut History) {
        let c = &self.committed;
        t.state = 4;
        t.low_d = c.d;
        t.low_f = c.f;
        t.high_d = t.u_max_dmg;
        t.high_f = pos_backbone(&self.pos.disp, &t.pos_f_dmg, t.u_max_dmg).0;
    }

    /// Force and tangent on the trial branch at `u`.
    pub(super) fn branch_force(&self, t: &History, u: f64) -> (f64, f64) {
        match t.state {
            1 => pos_backbone(&self.pos.disp, &t.pos_f_dmg, u),
            2 => neg_backbone(&self.neg.disp, &t.neg_f_dmg, u),
            3 => {
                let k_unload = if t.high_d < 0.0 { t.k_neg_dmg } else { t.k_pos_dmg };
                let inputs = PathInputs {
                    k_unload,
                    k_elastic_dmg: t.k_neg_dmg,
                    r_disp: self.pinch_neg.r_disp,
                    r_force: self.pinch_neg.r_force,
                    u_force: self.pinch_neg.u_force,
                    beyond_point3: t.min_demand < self.neg.disp[3],
                    env_f3: t.neg_f_dmg[3],
                    env_f4: t.neg_f_dmg[4],
                };
                state3_path(t.low_d, t.low_f, t.high_d, t.high_f, &inputs).eval(u)
            }
            4 => {
                let k_unload = if t.low_d < 0.0 { t.k_neg_dmg } else { t.k_pos_dmg };
                let inputs = PathInputs {
                    k_unload,
                    k_elastic_dmg: t.k_pos_dmg,
                    r_disp: self.pinch_pos.r_disp,
                    r_force: self.pinch_pos.r_force,
                    u_force: self.pinch_pos.u_force,
                    beyond_point3: t.max_demand > self.pos.disp[3],
                    env_f3: t.pos_f_dmg[3],
                    env_f4: t.pos_f_dmg[4],
                };
                state4_path(t.low_d, t.low_f, t.high_d, t.high_f, &inputs).eval(u)
            }
            _ => {
                let k = self.pos.force[0] / self.pos.disp[0];
                (k * u, k)
            }
        }
    }
}
