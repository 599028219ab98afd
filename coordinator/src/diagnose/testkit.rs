//! Known answers for the symptom kernels: a single-degree-of-freedom
//! oscillator on a shaking platform, linear or with a stop (a gap).

use super::fit::Simulated;
use rand::{Rng, SeedableRng};

/// A square one-layer semi-free specimen of side `side_m` on the 0.6 m
/// module, with the nominal gap `nominal_gap_mm`.
pub fn square_structure(side_m: f64, nominal_gap_mm: f64) -> crate::bundle::Structure {
    crate::bundle::Structure {
        length_x_m: side_m,
        length_y_m: side_m,
        module_m: 0.6,
        main_tee_spacing_m: 1.2,
        hanger_spacing_m: 1.2,
        hanger_length_m: 1.0,
        panel_mass_kg: 1.2,
        layers: 1,
        boundary: crate::bundle::Boundary::SemiFree,
        nominal_gap_mm: Some(nominal_gap_mm),
        wall_members: false,
        hanger_offset_m: 0.0,
    }
}

/// Seeded white noise, uniform in [-amp, amp].
pub fn white_noise(n: usize, amp: f64, seed: u64) -> Vec<f64> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| rng.random_range(-amp..amp)).collect()
}

/// Response of an oscillator (`f_hz`, `zeta`) to base acceleration `ag`:
/// (absolute acceleration, displacement relative to the base). With
/// `gap = Some((g, k_ratio))` a stop of stiffness `k_ratio` times the
/// oscillator's acts beyond |u| = g. Newmark average acceleration with
/// 20 substeps and a fixed point on the stop force.
pub fn sdof(
    ag: &[f64],
    dt: f64,
    f_hz: f64,
    zeta: f64,
    gap: Option<(f64, f64)>,
) -> (Vec<f64>, Vec<f64>) {
    let w = 2.0 * std::f64::consts::PI * f_hz;
    let (k, c) = (w * w, 2.0 * zeta * w);
    let stop = |u: f64| match gap {
        Some((g, r)) if u.abs() > g => r * k * (u - g * u.signum()),
        _ => 0.0,
    };
    let sub = 20;
    let h = dt / sub as f64;
    let (mut u, mut v) = (0.0f64, 0.0f64);
    let mut a = -ag[0];
    let (mut acc, mut disp) = (vec![0.0; ag.len()], vec![0.0; ag.len()]);
    for i in 1..ag.len() {
        for s in 1..=sub {
            let g = ag[i - 1] + (ag[i] - ag[i - 1]) * s as f64 / sub as f64;
            // Solve for u1 with the stop force lagged one fixed-point pass at a time.
            let mut u1 = u + h * v;
            for _ in 0..8 {
                let rhs =
                    -g - stop(u1) + u * 4.0 / (h * h) + v * 4.0 / h + a + c * (2.0 * u / h + v);
                u1 = rhs / (k + 2.0 * c / h + 4.0 / (h * h));
            }
            let v1 = 2.0 * (u1 - u) / h - v;
            let a1 = 4.0 * (u1 - u) / (h * h) - 4.0 * v / h - a;
            (u, v, a) = (u1, v1, a1);
        }
        acc[i] = a + ag[i];
        disp[i] = u;
    }
    (acc, disp)
}

/// Seeded white noise low-passed at 10 Hz (two passes of a Butterworth
/// section), scaled to RMS `rms`.
pub fn band_noise(n: usize, dt: f64, rms: f64, seed: u64) -> Vec<f64> {
    let lp = super::filter::Biquad::low_pass(10.0, dt).expect("10 Hz below Nyquist");
    let x = lp.filtfilt(&white_noise(n, 1.0, seed));
    let r = (x.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
    x.iter().map(|v| v * rms / r).collect()
}

/// A campaign on a 3 Hz oscillator (ζ = 0.03) standing for a ceiling, and
/// a diagnosis of it: three 20 s runs in x at 100 Hz, 1 s at rest then
/// white noise below 10 Hz of RMS 0.1, 0.3 and 0.6 m/s² (weak and mid
/// calibrate, strong validates); with `pounding` the measured oscillator
/// strikes a stop at half the strong run's free peak (stiffness 200 k),
/// else it is linear; measurements carry noise, offsets and two missing
/// readings. The baseline simulates the linear oscillator, the chosen
/// extension (perimeter-pounding, or the baseline without `pounding`) the
/// true one without noise. With `with_disp` the bundle has a displacement
/// sensor D1 beside accelerometer A1.
pub fn pounding_diagnosis(
    pounding: bool,
    with_disp: bool,
) -> (crate::bundle::Bundle, super::pipeline::Diagnosis) {
    use crate::bundle::*;
    let dt = 0.01;
    let n = 2000;
    let runs = [("weak", 0.1), ("mid", 0.3), ("strong", 0.6)];
    // 1 s at rest first: the pre-event offset of the records is read there.
    let quiet = 100;
    let inputs: Vec<Vec<f64>> = runs
        .iter()
        .enumerate()
        .map(|(k, (_, a))| [vec![0.0; quiet], band_noise(n - quiet, dt, *a, 7 + k as u64)].concat())
        .collect();
    let (_, free) = sdof(&inputs[2], dt, 3.0, 0.03, None);
    let gap_m = 0.5 * free.iter().fold(0.0f64, |m, d| m.max(d.abs()));
    let stop = pounding.then_some((gap_m, 200.0));
    let channels = |acc: &[f64], disp: &[f64]| -> Simulated {
        let mut out = vec![("A2".to_string(), acc.to_vec()), ("A1".to_string(), acc.to_vec())];
        if with_disp {
            out.push(("D1".to_string(), disp.iter().map(|u| u * 1000.0).collect()));
        }
        out
    };
    let (mut measured, mut base, mut ext) = (vec![], vec![], vec![]);
    for (k, ag) in inputs.iter().enumerate() {
        let (a, u) = sdof(ag, dt, 3.0, 0.03, stop);
        let mut m = channels(&a, &u);
        for (c, (_, v)) in m.iter_mut().enumerate() {
            let (rms, off) = if c == 2 { (0.05, 0.02) } else { (0.02, 0.005) };
            let noise = white_noise(n, rms * 3f64.sqrt(), 100 * k as u64 + c as u64);
            v.iter_mut().zip(noise).for_each(|(x, e)| *x += e + off);
            v[n / 3 + c] = f64::NAN;
        }
        measured.push(m);
        let (a, u) = sdof(ag, dt, 3.0, 0.03, None);
        base.push(channels(&a, &u));
        let (a, u) = sdof(ag, dt, 3.0, 0.03, stop);
        ext.push(channels(&a, &u));
    }
    let ids: Vec<&str> = runs.iter().map(|(id, _)| *id).collect();
    let manifest = sdof_manifest(&ids, sdof_sensors(with_disp), gap_m);
    let data = ids
        .iter()
        .zip(&inputs)
        .zip(measured)
        .map(|((id, ag), sensors)| RunData {
            id: (*id).into(),
            t0_s: 0.0,
            dt_s: dt,
            input_x_m_s2: Some(ag.clone()),
            input_y_m_s2: None,
            sensors,
        })
        .collect();
    let bundle = Bundle {
        dir: "sdof-campaign".into(),
        manifest,
        runs: data,
        modal: None,
        linear_form: Vec::new(),
    };
    (bundle, sdof_diagnosis(pounding, &base, &ext))
}

/// The oscillator campaign's sensors: accelerometers A2 and A1 in x, and
/// displacement sensor D1 beside A1 `with_disp`.
fn sdof_sensors(with_disp: bool) -> Vec<crate::bundle::Sensor> {
    use crate::bundle::*;
    let sensor = |id: &str, kind, x_m| Sensor {
        id: id.into(),
        kind,
        x_m,
        y_m: x_m,
        direction: Direction::X,
        units: if kind == SensorKind::Displacement { SensorUnits::Mm } else { SensorUnits::MPerS2 },
    };
    let mut sensors = vec![
        sensor("A2", SensorKind::Acceleration, 0.6),
        sensor("A1", SensorKind::Acceleration, 1.8),
    ];
    if with_disp {
        sensors.push(sensor("D1", SensorKind::Displacement, 1.8));
    }
    sensors
}

/// The oscillator campaign's manifest: runs `ids` in x (the last
/// validates), on a 3.6 m square specimen with the gap `gap_m`.
fn sdof_manifest(
    ids: &[&str],
    sensors: Vec<crate::bundle::Sensor>,
    gap_m: f64,
) -> crate::bundle::Manifest {
    use crate::bundle::*;
    let last = ids.len() - 1;
    Manifest {
        format: FORMAT.into(),
        name: "sdof-campaign".into(),
        description: None,
        structure: square_structure(3.6, gap_m * 1000.0),
        sensors,
        runs: ids
            .iter()
            .enumerate()
            .map(|(k, id)| RunMeta {
                id: (*id).into(),
                file: format!("{id}.csv"),
                description: None,
                input_x: Some("ax".into()),
                input_y: None,
                input_units: InputUnits::MPerS2,
                role: Some(if k == last { RunRole::Validation } else { RunRole::Calibration }),
            })
            .collect(),
    }
}

/// A diagnosis choosing pounding (or none) from the baseline's and the
/// extension's simulations of the three runs, the last validating.
fn sdof_diagnosis(
    pounding: bool,
    base: &[Simulated],
    ext: &[Simulated],
) -> super::pipeline::Diagnosis {
    use super::cause::Cause;
    use super::pipeline::{CandidateResult, Diagnosis};
    let candidate = |cause, sims: &[Simulated], selected| CandidateResult {
        validation_sims: vec![sims[2].clone()],
        calibration_sims: sims[..2].to_vec(),
        selected,
        ..CandidateResult::unassessed(cause, None)
    };
    Diagnosis {
        cause: if pounding { Cause::PERIMETER_POUNDING } else { Cause::NONE },
        candidates: vec![
            candidate(Cause::NONE, base, !pounding),
            candidate(Cause::PERIMETER_POUNDING, ext, pounding),
        ],
        calibration_runs: vec![0, 1],
        validation_runs: vec![2],
        ..diagnosis(&[])
    }
}

/// A diagnosis of "sdof-campaign" with an unassessed candidate of each of
/// `causes` (none selected), naming `none` by the MDL rules.
pub fn diagnosis(causes: &[super::cause::Cause]) -> super::pipeline::Diagnosis {
    use super::pipeline::{CandidateResult, Diagnosis};
    Diagnosis {
        bundle: "sdof-campaign".into(),
        cause: super::cause::Cause::NONE,
        candidates: causes.iter().map(|c| CandidateResult::unassessed(*c, None)).collect(),
        calibration_runs: vec![],
        validation_runs: vec![],
        baseline_validation_error: f64::NAN,
        extended_validation_error: f64::NAN,
        gain: 0.0,
        fe_points: 0,
        channels: None,
        linear: None,
        unexplained: None,
        stage_loads: Vec::new(),
        rule: super::pipeline::VerdictRule::Mdl,
    }
}

/// An MDL of `total` nats, all of it fit, for `k` parameters.
pub fn mdl_of(total: f64, k: usize) -> super::mdl::Mdl {
    super::mdl::Mdl {
        fit: total,
        parametric: 0.0,
        geometric: 0.0,
        geometric_se: 0.0,
        total,
        k,
        n_eff: 1e4,
    }
}

/// The odds of a class whose evidence is `ln_z` (± 0.1 nat, k̂ 0.3, its
/// Laplace value the same), `converged` or not, no rounds run, under
/// equal prior odds; probability not yet set (NaN).
pub fn class_odds(ln_z: f64, converged: bool) -> super::class_odds::ClassOdds {
    let evidence = super::class_evidence::ClassEvidence {
        ln_evidence: ln_z,
        ln_evidence_sd: 0.1,
        k_hat: 0.3,
        converged,
        laplace_ln_evidence: ln_z,
        curvature_scale: 1.0,
        rounds: vec![],
        fe_points: 0,
        likelihood: super::likelihood::LikelihoodKind::Band,
        restarts: 0,
        higher_ground: None,
        annealed: None,
    };
    super::class_odds::ClassOdds { evidence, probability: f64::NAN, effect_prior: 0.5 }
}

/// The odds of a class whose evidence did not settle, an annealing of
/// `fe_points` FE runs having bounded it to `lower` ..= `upper` (each ± 0,
/// so counted at `lower`; `upper` None: bounded below only).
pub fn bounded(lower: f64, upper: Option<f64>, fe_points: usize) -> super::class_odds::ClassOdds {
    let mut o = class_odds(lower, false);
    o.evidence.annealed = Some(super::class_evidence::Annealed {
        estimate: None,
        stages: 8,
        fe_points,
        beta: 0.1,
        lower: Some((lower, 0.0)),
        upper: upper.map(|u| (u, 0.0)),
    });
    o
}
