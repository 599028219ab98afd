//! Pinching4 (Lowes & Altoontash 2003; Lowes, Mitra & Altoontash 2004,
//! PEER 2003/10) as OpenSees `Pinching4Material` implements it: a
//! four-point backbone on each side, unload-reload paths with pinching
//! (rDisp, rForce, uForce), unloading-stiffness, reloading-stiffness and
//! strength degradation driven by `cycle` or `energy` damage.
//!
//! States: 0 virgin elastic, 1 positive backbone, 2 negative backbone,
//! 3 reloading towards the negative side, 4 reloading towards the positive
//! side. Every quantity OpenSees changes during a trial is held in the
//! [`History`] struct, so revert restores the committed state exactly
//! (OpenSees keeps a few of them outside its trial/commit pairs; with one
//! trial per commit the two agree). A step of |Δd| <= 1e-12 leaves a zero
//! deformation rate behind, as OpenSees does without revert.
//! Units: deformation mm, force N, stiffness N/mm, energy N mm.

mod branch;
mod damage;

pub use damage::{DamageRule, DamageType};

use super::{check_finite, MaterialError, Pinching4Spec, UniaxialMaterial};

/// Pinching parameters of one side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PinchingSide {
    /// Reloading deformation ratio.
    pub r_disp: f64,
    /// Reloading force ratio.
    pub r_force: f64,
    /// Unloading force ratio.
    pub u_force: f64,
}

/// Backbone of one side as OpenSees stores it: the four user points between
/// a tiny elastic point and a far extrapolation point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Backbone {
    /// Deformations (mm), points 0..5.
    pub disp: [f64; 6],
    /// Forces (N), points 0..5.
    pub force: [f64; 6],
}

impl Backbone {
    /// Secant slope to the first user point (N/mm): the elastic stiffness
    /// that stiffness damage reduces.
    fn elastic_slope(&self) -> f64 {
        self.force[1] / self.disp[1]
    }
}

/// Everything a step changes.
#[derive(Debug, Clone, Copy, PartialEq)]
struct History {
    state: u8,
    d: f64,
    f: f64,
    k_t: f64,
    /// Last non-negligible deformation increment (mm).
    rate: f64,
    /// Increment of the trial from the committed deformation (mm).
    dd: f64,
    low_d: f64,
    low_f: f64,
    high_d: f64,
    high_f: f64,
    min_demand: f64,
    max_demand: f64,
    energy: f64,
    gamma_k: f64,
    gamma_d: f64,
    gamma_f: f64,
    n_cycle: f64,
    gamma_k_used: f64,
    gamma_f_used: f64,
    k_pos_dmg: f64,
    k_neg_dmg: f64,
    u_max_dmg: f64,
    u_min_dmg: f64,
    pos_f_dmg: [f64; 6],
    neg_f_dmg: [f64; 6],
}

/// The Pinching4 material.
#[derive(Debug, Clone, PartialEq)]
pub struct Pinching4 {
    pos: Backbone,
    neg: Backbone,
    pinch_pos: PinchingSide,
    pinch_neg: PinchingSide,
    k_rule: DamageRule,
    d_rule: DamageRule,
    f_rule: DamageRule,
    damage: DamageType,
    k_elastic_pos: f64,
    k_elastic_neg: f64,
    energy_capacity: f64,
    virgin: History,
    committed: History,
    trial: History,
}

fn bad(key: &'static str, value: f64, expected: &'static str) -> MaterialError {
    MaterialError::Parameter { material: "Pinching4", key, value, expected }
}

/// Checks one side's user backbone: finite, signed and strictly monotone.
fn check_backbone(
    d: &[f64; 4],
    f: &[f64; 4],
    sign: f64,
    keys: (&'static str, &'static str),
) -> Result<(), MaterialError> {
    let mut last = 0.0;
    for (&di, &fi) in d.iter().zip(f) {
        if !(di.is_finite() && sign * di > sign * last) {
            return Err(bad(
                keys.0,
                di,
                "deformations of the side's sign, strictly growing in size",
            ));
        }
        if !fi.is_finite() || sign * fi <= 0.0 {
            return Err(bad(keys.1, fi, "finite forces of the side's sign"));
        }
        last = di;
    }
    Ok(())
}

/// Backbone areas up to point 4 (N mm), OpenSees' energy capacity basis.
fn backbone_energy(b: &Backbone) -> f64 {
    let mut e = 0.5 * b.disp[0] * b.force[0];
    for j in 0..4 {
        e += 0.5 * (b.force[j] + b.force[j + 1]) * (b.disp[j + 1] - b.disp[j]);
    }
    e
}

/// Refuses backbones out of order and any non-finite scalar or coefficient.
fn check_spec(s: &Pinching4Spec) -> Result<(), MaterialError> {
    check_backbone(&s.ePd, &s.ePf, 1.0, ("ePd", "ePf"))?;
    check_backbone(&s.eNd, &s.eNf, -1.0, ("eNd", "eNf"))?;
    let scalars = [
        ("rDispP", s.rDispP),
        ("rForceP", s.rForceP),
        ("uForceP", s.uForceP),
        ("rDispN", s.rDispN),
        ("rForceN", s.rForceN),
        ("uForceN", s.uForceN),
        ("gKLim", s.gKLim),
        ("gDLim", s.gDLim),
        ("gFLim", s.gFLim),
        ("gE", s.gE),
    ];
    for (key, v) in scalars {
        if !v.is_finite() {
            return Err(bad(key, v, "a finite number"));
        }
    }
    for (key, g) in [("gK", s.gK), ("gD", s.gD), ("gF", s.gF)] {
        if let Some(v) = g.iter().find(|v| !v.is_finite()) {
            return Err(bad(key, *v, "finite coefficients"));
        }
    }
    Ok(())
}

/// The damage type named by `dmgType` (OpenSees' spellings accepted).
fn damage_type(name: &str) -> Result<DamageType, MaterialError> {
    match name {
        "cycle" | "Cycle" | "DamageCycle" | "damageCycle" => Ok(DamageType::Cycle),
        "energy" | "Energy" | "DamageEnergy" | "damageEnergy" => Ok(DamageType::Energy),
        _ => Err(bad("dmgType", f64::NAN, "\"cycle\" or \"energy\"")),
    }
}

impl History {
    /// The state before any deformation: elastic on the first backbone
    /// points, no damage, demands at the second points.
    fn virgin(pos: &Backbone, neg: &Backbone) -> Self {
        History {
            state: 0,
            d: 0.0,
            f: 0.0,
            k_t: pos.force[0] / pos.disp[0],
            rate: 0.0,
            dd: 0.0,
            low_d: neg.disp[0],
            low_f: neg.force[0],
            high_d: pos.disp[0],
            high_f: pos.force[0],
            min_demand: neg.disp[1],
            max_demand: pos.disp[1],
            energy: 0.0,
            gamma_k: 0.0,
            gamma_d: 0.0,
            gamma_f: 0.0,
            n_cycle: 0.0,
            gamma_k_used: 0.0,
            gamma_f_used: 0.0,
            k_pos_dmg: pos.elastic_slope(),
            k_neg_dmg: neg.elastic_slope(),
            u_max_dmg: pos.disp[1],
            u_min_dmg: neg.disp[1],
            pos_f_dmg: pos.force,
            neg_f_dmg: neg.force,
        }
    }
}

impl Pinching4 {
    /// Builds the material from its JSON parameters.
    pub fn new(s: &Pinching4Spec) -> Result<Self, MaterialError> {
        check_spec(s)?;
        let damage = damage_type(&s.dmgType)?;
        let (pos, neg) = Self::backbones(s);
        let k_elastic_pos = pos.elastic_slope();
        let k_elastic_neg = neg.elastic_slope();
        let energy_capacity = s.gE * backbone_energy(&pos).max(backbone_energy(&neg));
        let virgin = History::virgin(&pos, &neg);
        let rule = |g: [f64; 4], limit| DamageRule { g, limit };
        Ok(Pinching4 {
            pos,
            neg,
            pinch_pos: PinchingSide { r_disp: s.rDispP, r_force: s.rForceP, u_force: s.uForceP },
            pinch_neg: PinchingSide { r_disp: s.rDispN, r_force: s.rForceN, u_force: s.uForceN },
            k_rule: rule(s.gK, s.gKLim),
            d_rule: rule(s.gD, s.gDLim),
            f_rule: rule(s.gF, s.gFLim),
            damage,
            k_elastic_pos,
            k_elastic_neg,
            energy_capacity,
            virgin,
            committed: virgin,
            trial: virgin,
        })
    }

    /// OpenSees' six-point backbones: a tiny elastic point at 1e-4 of the
    /// larger first deformation with the stiffer first slope, the four user
    /// points, and an extrapolation to 1e6 times point 4 (continuing the
    /// last slope if it rises, else 1.1 times the last force).
    fn backbones(s: &Pinching4Spec) -> (Backbone, Backbone) {
        let k_pos = s.ePf[0] / s.ePd[0];
        let k_neg = s.eNf[0] / s.eNd[0];
        let k = if k_pos > k_neg { k_pos } else { k_neg };
        let u = if s.ePd[0] > -s.eNd[0] { 1e-4 * s.ePd[0] } else { -1e-4 * s.eNd[0] };
        let side = |d: &[f64; 4], f: &[f64; 4], sign: f64| {
            let k_last = (f[3] - f[2]) / (d[3] - d[2]);
            let d_far = 1e6 * d[3];
            let f_far = if k_last > 0.0 { f[3] + k_last * (d_far - d[3]) } else { f[3] * 1.1 };
            Backbone {
                disp: [sign * u, d[0], d[1], d[2], d[3], d_far],
                force: [sign * u * k, f[0], f[1], f[2], f[3], f_far],
            }
        };
        (side(&s.ePd, &s.ePf, 1.0), side(&s.eNd, &s.eNf, -1.0))
    }
}

impl UniaxialMaterial for Pinching4 {
    fn set_trial(&mut self, d: f64) -> Result<(), MaterialError> {
        check_finite(d)?;
        let c = self.committed;
        let mut t = c;
        t.d = d;
        let mut du = d - c.d;
        if du.abs() < 1e-12 {
            du = 0.0;
        }
        t.dd = du;
        self.update_branch(&mut t, d, du);
        let (f, k_t) = self.branch_force(&t, d);
        t.f = f;
        t.k_t = k_t;
        t.energy = c.energy + 0.5 * (t.f + c.f) * du;
        let k_side = if d > 0.0 { t.k_pos_dmg } else { t.k_neg_dmg };
        let elastic_energy = 0.5 * t.f / k_side * t.f;
        self.update_damage(&mut t, d, du, elastic_energy);
        self.trial = t;
        Ok(())
    }
    fn force(&self) -> f64 {
        self.trial.f
    }
    fn tangent(&self) -> f64 {
        self.trial.k_t
    }
    /// The stiffer of the two first backbone slopes, as OpenSees reports it.
    fn initial_tangent(&self) -> f64 {
        self.pos.force[0] / self.pos.disp[0]
    }
    fn commit(&mut self) {
        let t = &mut self.trial;
        t.rate = if t.dd.abs() > 1e-12 { t.dd } else { 0.0 };
        t.k_pos_dmg = self.k_elastic_pos * (1.0 - t.gamma_k_used);
        t.k_neg_dmg = self.k_elastic_neg * (1.0 - t.gamma_k_used);
        t.u_max_dmg = t.max_demand * (1.0 + t.gamma_d);
        t.u_min_dmg = t.min_demand * (1.0 + t.gamma_d);
        let keep = 1.0 - t.gamma_f_used;
        t.pos_f_dmg = self.pos.force.map(|f| f * keep);
        t.neg_f_dmg = self.neg.force.map(|f| f * keep);
        self.committed = self.trial;
    }
    fn revert(&mut self) {
        self.trial = self.committed;
    }
    fn boxed_clone(&self) -> Box<dyn UniaxialMaterial> {
        Box::new(Pinching4 { committed: self.virgin, trial: self.virgin, ..self.clone() })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cjsa(gk: f64, dmg: &str) -> Pinching4 {
        Pinching4::new(&Pinching4Spec {
            ePf: [150.0, 651.0, 1001.0, 458.0],
            ePd: [0.5, 5.5, 10.5, 13.8],
            eNf: [-200.0, -620.0, -1248.0, -556.0],
            eNd: [-0.5, -5.0, -12.7, -16.0],
            rDispP: 0.6,
            rForceP: 0.2,
            uForceP: -0.01,
            rDispN: 0.6,
            rForceN: 0.2,
            uForceN: -0.01,
            gK: [gk, gk, 1.0, 1.0],
            gKLim: 0.9,
            gD: [0.0; 4],
            gDLim: 0.0,
            gF: [0.0; 4],
            gFLim: 0.0,
            gE: 10.0,
            dmgType: dmg.to_string(),
        })
        .unwrap()
    }

    fn step(m: &mut Pinching4, d: f64) -> f64 {
        m.set_trial(d).unwrap();
        m.commit();
        m.force()
    }

    #[test]
    fn virgin_material_uses_the_stiffer_first_slope_then_the_backbone() {
        let mut m = cjsa(0.0, "cycle");
        assert_eq!(m.initial_tangent(), 400.0);
        // OpenSees' tiny elastic point at 5e-5 mm on the 400 N/mm line, then
        // the secant to (0.5, 150)
        let k = (150.0 - 0.02) / (0.5 - 5e-5);
        assert!((step(&mut m, 0.01) - (0.02 + (0.01 - 5e-5) * k)).abs() < 1e-12);
        assert!((step(&mut m, 3.0) - (150.0 + 2.5 * 501.0 / 5.0)).abs() < 1e-9);
    }

    #[test]
    fn reloading_after_a_cycle_passes_through_the_pinched_point() {
        let mut m = cjsa(0.0, "cycle");
        let mut d = 0.0_f64;
        for target in [6.0_f64, -6.0] {
            while (d - target).abs() > 1e-9 {
                d += (target - d).clamp(-0.01, 0.01);
                step(&mut m, d);
            }
        }
        // reloading towards (6, f(6)); its reloading point sits at
        // rDisp * 6 = 3.6 mm with force rForce * f(6)
        let f6 = 651.0 + 0.5 * (1001.0 - 651.0) / 5.0;
        while d < 3.6 - 1e-9 {
            d += 0.01;
            step(&mut m, d);
        }
        assert!((m.force() - 0.2 * f6).abs() < 1e-6 * f6, "{}", m.force());
    }

    #[test]
    fn unloading_stiffness_degrades_with_cycles() {
        let mut fresh = cjsa(0.0, "cycle");
        let mut damaged = cjsa(0.5, "cycle");
        // 0 -> 6 -> -6 -> 6 mm: both sides loaded past their first point
        let up: Vec<f64> = (-600..=600).map(|i| 0.01 * i as f64).collect();
        let mut k = [0.0; 2];
        for (j, m) in [&mut fresh, &mut damaged].into_iter().enumerate() {
            let first = up.iter().skip(600);
            for &d in first.chain(up.iter().rev().skip(1)).chain(up.iter().skip(1)) {
                step(m, d);
            }
            step(m, 5.99);
            k[j] = m.tangent();
        }
        assert!(k[1] < k[0], "damaged {} vs fresh {}", k[1], k[0]);
    }

    #[test]
    fn rejects_unknown_damage_type() {
        let mut s = Pinching4Spec {
            ePf: [1.0, 2.0, 3.0, 4.0],
            ePd: [1.0, 2.0, 3.0, 4.0],
            eNf: [-1.0, -2.0, -3.0, -4.0],
            eNd: [-1.0, -2.0, -3.0, -4.0],
            rDispP: 0.5,
            rForceP: 0.5,
            uForceP: 0.0,
            rDispN: 0.5,
            rForceN: 0.5,
            uForceN: 0.0,
            gK: [0.0; 4],
            gKLim: 0.0,
            gD: [0.0; 4],
            gDLim: 0.0,
            gF: [0.0; 4],
            gFLim: 0.0,
            gE: 1.0,
            dmgType: "fatigue".into(),
        };
        assert!(Pinching4::new(&s).is_err());
        s.dmgType = "energy".into();
        s.ePd[2] = 1.5;
        assert!(Pinching4::new(&s).is_err());
    }
}
