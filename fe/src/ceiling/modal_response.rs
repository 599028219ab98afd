//! The linear response of a run by modal superposition: the run is prepared
//! as [`super::simulate`] prepares it (same model, Rayleigh pair on the same
//! first x and y modes, same sensors and base motion), its lowest `n_modes`
//! modes are computed once, and the equations of motion projected on them,
//!
//! q̈ + C_q q̇ + Ω² q = −Σ_d Γ_d a_d(t),   C_q = α I + β Φᵀ K_R Φ,
//!
//! are integrated by the same Newmark average-acceleration steps from rest
//! (q̈₀ = 0, as the FE transient starts). Φ is mass-normalised, K_R the
//! stiffness the Rayleigh term is proportional to (beams and flagged
//! springs), so a model whose damping is classical decouples exactly, and
//! one whose damping is not keeps its modal coupling. With every mode that
//! carries mass the result is the FE transient's on a linear model to
//! round-off; with the lowest modes only it omits the quasi-static response
//! of the modes left out, which the tests measure.
//!
//! A linear run costs one eigen-solution and O(n_modes²) per step instead
//! of a sparse factorization and its solves: the linear stage of a diagnosis
//! evaluates thousands of parameter points this way.
//!
//! Units: the model's N, mm, s, t; base motion mm/s²; sensors m/s² or m.

use super::input::BaseInput;
use super::prepare::{damped_model_on, instrument, PreparedRun};
use super::sensor::{Sensor, SensorKind};
use super::simulate::{CeilingError, SensorHistory, SimOptions, Simulation};
use crate::assembly::Structure;
use crate::eigen::{horizontal_share, ModalResult};
use crate::generator::{CeilingSpec, Parameters};
use nalgebra::{DMatrix, DVector};

/// A linear simulation and the modes it superposed.
#[derive(Debug, Clone)]
pub struct LinearSimulation {
    /// The sensors' histories, frequencies and Rayleigh pair, as
    /// [`super::simulate`] reports them (no spring peaks).
    pub simulation: Simulation,
    /// Frequencies (Hz) of every mode superposed, ascending.
    pub modes_hz: Vec<f64>,
    /// Each mode's damping ratio C_q[k][k] / (2 ω_k).
    pub modal_damping: Vec<f64>,
    /// Each mode's share of its kinetic energy in x and y
    /// ([`crate::eigen::horizontal_share`]).
    pub horizontal_share: Vec<f64>,
    /// Each mode's shape at each sensor (sensor order, then mode order):
    /// the sensor's reading per unit modal coordinate.
    pub sensor_shapes: Vec<Vec<f64>>,
}

/// Simulates one run of a linear model by superposing its lowest
/// `n_modes` modes (all that carry mass when fewer); the Rayleigh pair is
/// fitted on the first `opts.n_modes` of them, as the FE transient's is.
pub fn simulate_linear(
    spec: &CeilingSpec,
    params: &Parameters,
    input: &BaseInput,
    sensors: &[Sensor],
    opts: &SimOptions,
    n_modes: usize,
) -> Result<LinearSimulation, CeilingError> {
    let mut out = simulate_linear_runs(spec, params, &[(input, sensors)], opts, n_modes)?;
    Ok(out.remove(0))
}

/// [`simulate_linear`] for several runs of one model (input and sensors
/// each), its modes computed once.
pub fn simulate_linear_runs(
    spec: &CeilingSpec,
    params: &Parameters,
    runs: &[(&BaseInput, &[Sensor])],
    opts: &SimOptions,
    n_modes: usize,
) -> Result<Vec<LinearSimulation>, CeilingError> {
    simulate_linear_runs_on(spec, params, runs, opts, n_modes, None)
}

/// [`simulate_linear_runs`] with the modes found by Rayleigh–Ritz on
/// `basis` ([`damped_model_on`]; Lanczos without one, or when it does not
/// fit the mesh): a model near the one whose modes the basis holds, as the
/// forward differences of a search are.
pub fn simulate_linear_runs_on(
    spec: &CeilingSpec,
    params: &Parameters,
    runs: &[(&BaseInput, &[Sensor])],
    opts: &SimOptions,
    n_modes: usize,
    basis: Option<&[Vec<f64>]>,
) -> Result<Vec<LinearSimulation>, CeilingError> {
    let dm = damped_model_on(spec, params, opts, n_modes, basis)?;
    runs.iter()
        .map(|(input, sensors)| {
            let run = instrument(&dm, spec, input, sensors, opts)?;
            Ok(superpose(&run, &dm.structure, &dm.modal))
        })
        .collect()
}

/// The linear response of a prepared run on the modes `modal` of its
/// structure `s`.
pub fn superpose(run: &PreparedRun, s: &Structure, modal: &ModalResult) -> LinearSimulation {
    let (alpha, beta) = (run.rayleigh.alpha_m_per_s, run.rayleigh.beta_k_s);
    let damping = modal_damping_matrix(s, modal, alpha, beta);
    let shapes = sensor_rows(run, s, modal);
    let forcing: Vec<(u8, Vec<f64>)> = run
        .base
        .components
        .iter()
        .map(|g| (g.dof, modal.participation.iter().map(|p| -p[g.dof as usize - 1]).collect()))
        .collect();
    let q = integrate(run, &modal.omega2, &damping, &forcing);
    let sensors = read_sensors(run, &shapes, &q);
    let n = modal.freq_hz.len();
    let modal_damping =
        (0..n).map(|k| damping[(k, k)] / (2.0 * modal.omega2[k].max(1e-300).sqrt())).collect();
    let first = run.freq_hz.len();
    LinearSimulation {
        simulation: Simulation {
            freq_hz: modal.freq_hz[..first.min(n)].to_vec(),
            mode_dir: run.mode_dir.clone(),
            rayleigh: run.rayleigh,
            dt_s: run.input_dt_s,
            sensors,
            spring_peaks: vec![],
        },
        modes_hz: modal.freq_hz.clone(),
        modal_damping,
        horizontal_share: horizontal_share(s, modal),
        sensor_shapes: shapes,
    }
}

/// C_q = α I + β Φᵀ K_R Φ on mass-normalised shapes, K_R the beams' and
/// the Rayleigh-flagged springs' initial stiffness.
fn modal_damping_matrix(s: &Structure, modal: &ModalResult, alpha: f64, beta: f64) -> DMatrix<f64> {
    let n = modal.shapes.len();
    let mut kr = s.beam_values.clone();
    let k0: Vec<f64> = s
        .springs
        .iter()
        .map(|sp| if sp.rayleigh { sp.material.initial_tangent() } else { 0.0 })
        .collect();
    s.add_spring_tangents(&mut kr, &k0);
    let mut k_phi = vec![0.0; s.dofs.n_free];
    let mut c = DMatrix::zeros(n, n);
    for j in 0..n {
        s.pattern.mul_vec(&kr, &modal.shapes[j], &mut k_phi);
        for i in 0..n {
            let v: f64 = modal.shapes[i].iter().zip(&k_phi).map(|(a, b)| a * b).sum();
            c[(i, j)] = beta * v;
        }
        c[(j, j)] += alpha;
    }
    c
}

/// Each sensor's reading per unit modal coordinate, for every mode.
fn sensor_rows(run: &PreparedRun, s: &Structure, modal: &ModalResult) -> Vec<Vec<f64>> {
    run.sensors
        .iter()
        .zip(&run.placements)
        .map(|(sensor, place)| {
            let dof = sensor.direction.dof() as usize - 1;
            (0..modal.shapes.len())
                .map(|k| {
                    place
                        .nodes
                        .iter()
                        .map(|(node, w)| {
                            s.dofs.node_eqs(*node)[dof].map_or(0.0, |e| w * modal.shapes[k][e])
                        })
                        .sum()
                })
                .collect()
        })
        .collect()
}

/// Modal coordinates and their accelerations at every output row.
struct ModalHistory {
    /// q per row (mm·t^½).
    q: Vec<DVector<f64>>,
    /// q̈ per row.
    qdd: Vec<DVector<f64>>,
    /// The base acceleration per row, one value per component (mm/s²).
    base: Vec<Vec<f64>>,
}

/// Newmark average acceleration (displacement form, as the FE transient)
/// on the modal equations, from rest with zero acceleration.
fn integrate(
    run: &PreparedRun,
    omega2: &[f64],
    c: &DMatrix<f64>,
    forcing: &[(u8, Vec<f64>)],
) -> ModalHistory {
    if decoupled(c) {
        integrate_decoupled(run, omega2, c, forcing)
    } else {
        integrate_coupled(run, omega2, c, forcing)
    }
}

/// Off-diagonal terms of the modal damping matrix below which it is taken
/// as diagonal, relative to its largest diagonal term: a model whose every
/// damped element carries the Rayleigh term has C_q = αI + βΩ² to the
/// eigenvectors' accuracy.
const DECOUPLED: f64 = 1e-9;

/// Whether `c` is diagonal to [`DECOUPLED`].
fn decoupled(c: &DMatrix<f64>) -> bool {
    let n = c.nrows();
    let scale = (0..n).map(|i| c[(i, i)].abs()).fold(0.0, f64::max);
    (0..n).all(|i| (0..n).all(|j| i == j || c[(i, j)].abs() <= DECOUPLED * scale))
}

/// The modes one by one (classical damping): the same Newmark steps, a
/// scalar recursion per mode.
fn integrate_decoupled(
    run: &PreparedRun,
    omega2: &[f64],
    c: &DMatrix<f64>,
    forcing: &[(u8, Vec<f64>)],
) -> ModalHistory {
    let n = omega2.len();
    let h = run.dt_s;
    let (c_mass, c_damp) = (4.0 / (h * h), 2.0 / h);
    let cd: Vec<f64> = (0..n).map(|k| c[(k, k)]).collect();
    let eff: Vec<f64> = (0..n).map(|k| c_mass + c_damp * cd[k] + omega2[k]).collect();
    let (mut q, mut v, mut a) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let every = run.output_every_n_steps.max(1);
    let mut base = Vec::new();
    run.base.accel_at(0.0, &mut base);
    let zeros = DVector::zeros(n);
    let mut out =
        ModalHistory { q: vec![zeros.clone()], qdd: vec![zeros], base: vec![base.clone()] };
    for step in 1..=run.n_steps {
        run.base.accel_at(step as f64 * h, &mut base);
        for k in 0..n {
            let p: f64 = forcing.iter().zip(&base).map(|((_, gamma), ag)| gamma[k] * ag).sum();
            let rhs = p + c_mass * q[k] + 4.0 / h * v[k] + a[k] + cd[k] * (c_damp * q[k] + v[k]);
            let q1 = rhs / eff[k];
            let a1 = (q1 - q[k]) * c_mass - v[k] * (4.0 / h) - a[k];
            v[k] += (a[k] + a1) * (0.5 * h);
            (q[k], a[k]) = (q1, a1);
        }
        if step % every == 0 {
            out.q.push(DVector::from_column_slice(&q));
            out.qdd.push(DVector::from_column_slice(&a));
            out.base.push(base.clone());
        }
    }
    out
}

/// The modes coupled by a damping matrix that is not diagonal.
fn integrate_coupled(
    run: &PreparedRun,
    omega2: &[f64],
    c: &DMatrix<f64>,
    forcing: &[(u8, Vec<f64>)],
) -> ModalHistory {
    let n = omega2.len();
    let h = run.dt_s;
    let (c_mass, c_damp) = (4.0 / (h * h), 2.0 / h);
    let k = DMatrix::from_diagonal(&DVector::from_column_slice(omega2));
    let eff = DMatrix::identity(n, n) * c_mass + c * c_damp + &k;
    let lu = eff.lu();
    let (mut q, mut v, mut a) = (DVector::zeros(n), DVector::zeros(n), DVector::zeros(n));
    let every = run.output_every_n_steps.max(1);
    let mut base = Vec::new();
    run.base.accel_at(0.0, &mut base);
    let mut out =
        ModalHistory { q: vec![q.clone()], qdd: vec![a.clone()], base: vec![base.clone()] };
    for step in 1..=run.n_steps {
        let t = step as f64 * h;
        run.base.accel_at(t, &mut base);
        let mut p = DVector::zeros(n);
        for ((_, gamma), ag) in forcing.iter().zip(&base) {
            p.iter_mut().zip(gamma).for_each(|(pi, g)| *pi += g * ag);
        }
        // M (c_mass q + 4/h v + a) + C (c_damp q + v) terms of the known state.
        let inertia = &q * c_mass + &v * (4.0 / h) + &a;
        let viscous = &q * c_damp + &v;
        let rhs = p + inertia + c * viscous;
        let q1 = lu.solve(&rhs).unwrap_or_else(|| DVector::zeros(n));
        let a1 = (&q1 - &q) * c_mass - &v * (4.0 / h) - &a;
        let v1 = &v + (&a + &a1) * (0.5 * h);
        (q, v, a) = (q1, v1, a1);
        if step % every == 0 {
            out.q.push(q.clone());
            out.qdd.push(a.clone());
            out.base.push(base.clone());
        }
    }
    out
}

/// The sensors' readings (m/s² absolute, or m relative) at every row.
fn read_sensors(run: &PreparedRun, shapes: &[Vec<f64>], h: &ModalHistory) -> Vec<SensorHistory> {
    run.sensors
        .iter()
        .zip(shapes)
        .map(|(sensor, row)| {
            let row = DVector::from_column_slice(row);
            let comp = run.base.component_of(sensor.direction.dof());
            let values = match sensor.kind {
                SensorKind::Displacement => h.q.iter().map(|q| row.dot(q) * 1e-3).collect(),
                SensorKind::Acceleration => h
                    .qdd
                    .iter()
                    .zip(&h.base)
                    .map(|(qdd, b)| (row.dot(qdd) + comp.map_or(0.0, |c| b[c])) * 1e-3)
                    .collect(),
            };
            SensorHistory { id: sensor.id.clone(), values }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ceiling::{damped_model, instrument, sine_sweep, Direction, SineSweep};
    use crate::generator::{Boundary, ModelOptions, Structure};

    /// The coupled integration, given a diagonal damping matrix, is the
    /// decoupled one to round-off.
    #[test]
    fn coupled_and_decoupled_steps_agree_on_classical_damping() {
        let spec = CeilingSpec {
            structure: Structure {
                length_x_m: 2.4,
                length_y_m: 2.4,
                module_m: 0.6,
                main_tee_spacing_m: 1.2,
                hanger_spacing_m: 1.2,
                hanger_length_m: 1.0,
                panel_mass_kg: 1.2,
                layers: 1,
                boundary: Boundary::SemiFree,
                nominal_gap_mm: 19.0,
                lines_from_origin: true,
                wall_members: false,
                hanger_offset_m: 0.0,
            },
            model: ModelOptions::default(),
        };
        let params = Parameters::prior_midpoints_for(&spec);
        let opts = SimOptions::default();
        let dm = damped_model(&spec, &params, &opts, 20).unwrap();
        let sweep = SineSweep {
            f_start_hz: 15.0,
            f_end_hz: 1.0,
            duration_s: 3.0,
            amplitude_m_s2: 1.0,
            ramp_s: 0.5,
        };
        let input =
            BaseInput { dt_s: 0.005, x_m_s2: Some(sine_sweep(&sweep, 0.005)), y_m_s2: None };
        let sensor = Sensor {
            id: "a".into(),
            kind: SensorKind::Acceleration,
            x_m: 1.2,
            y_m: 1.2,
            direction: Direction::X,
        };
        let run = instrument(&dm, &spec, &input, &[sensor], &opts).unwrap();
        let (a, b) = (run.rayleigh.alpha_m_per_s, run.rayleigh.beta_k_s);
        let c = modal_damping_matrix(&dm.structure, &dm.modal, a, b);
        assert!(decoupled(&c));
        let forcing: Vec<(u8, Vec<f64>)> =
            vec![(1, dm.modal.participation.iter().map(|p| -p[0]).collect())];
        let one = integrate_decoupled(&run, &dm.modal.omega2, &c, &forcing);
        let all = integrate_coupled(&run, &dm.modal.omega2, &c, &forcing);
        let scale = all.q.iter().map(|q| q.amax()).fold(0.0, f64::max);
        let diff = one.q.iter().zip(&all.q).map(|(x, y)| (x - y).amax()).fold(0.0, f64::max);
        assert!(diff <= 1e-9 * scale, "{diff} against {scale}");
    }
}
