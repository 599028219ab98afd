//! The selection's Nelder–Mead (`stats::selection::nelder_mead`) against
//! argmin's `NelderMead` (0.11) from the same start and the same initial
//! simplex (x0 plus `step` along each axis), with argmin's
//! `sd_tolerance` set to our `f_tol`: evaluations, final f, distance
//! between the minima. On Rosenbrock in 2 and 5 dimensions, then on the
//! real objectives of `ceilfarm select configs/calibration/oscillator-select.toml`
//! (the oscillator has no Jacobian, so `fit_ml` runs Nelder–Mead twice
//! from each of 16 starts), and whether AIC, BIC and MDL and their winners
//! would change.
//!
//! Run from the repository root: `scripts/bench/nelder-mead/run`.

use argmin::core::{CostFunction, Error, Executor, State};
use argmin::solver::neldermead::NelderMead;
use stats::calibration::simulator::{FnSimulator, SubsetSimulator};
use stats::calibration::Posterior;
use stats::calibration::{GaussianLikelihood, Hyper, Likelihood, UniformBox};
use stats::mcmc::AdaptiveMetropolis;
use stats::selection::criteria::{aic, bic, dic, mdl};
use stats::selection::fisher::log_fisher_integral;
use stats::selection::ml::fit_ml;
use stats::selection::nelder_mead::nelder_mead;
use stats::selection::{select, Candidate, SelectionProblem, SelectionSettings};
use std::cell::Cell;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// A minimum and what it cost.
struct Run {
    x: Vec<f64>,
    f: f64,
    evals: usize,
}

/// `f` counting its evaluations, as argmin's cost function.
struct Counted<'a> {
    f: &'a dyn Fn(&[f64]) -> f64,
    evals: &'a Cell<usize>,
}

impl CostFunction for Counted<'_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, x: &Vec<f64>) -> Result<f64, Error> {
        self.evals.set(self.evals.get() + 1);
        Ok((self.f)(x))
    }
}

/// Ours from `x0`, simplex edge `step`.
fn ours(f: &dyn Fn(&[f64]) -> f64, x0: &[f64], step: f64, f_tol: f64, max: usize) -> Run {
    let evals = Cell::new(0);
    let g = |x: &[f64]| {
        evals.set(evals.get() + 1);
        f(x)
    };
    let m = nelder_mead(&g, x0, step, f_tol, max);
    Run { x: m.x, f: m.f, evals: evals.get() }
}

/// argmin's from the same simplex, its default coefficients, `sd_tolerance = f_tol`.
fn argmin_nm(f: &dyn Fn(&[f64]) -> f64, x0: &[f64], step: f64, f_tol: f64, max: usize) -> Run {
    let simplex: Vec<Vec<f64>> = (0..=x0.len())
        .map(|i| {
            let mut x = x0.to_vec();
            if i > 0 {
                x[i - 1] += step;
            }
            x
        })
        .collect();
    let evals = Cell::new(0);
    let solver = NelderMead::new(simplex).with_sd_tolerance(f_tol).expect("tolerance");
    let res = Executor::new(Counted { f, evals: &evals }, solver)
        .configure(|s| s.max_iters(max as u64))
        .run()
        .expect("argmin runs");
    let st = res.state();
    Run {
        x: st.get_best_param().expect("a best point").clone(),
        f: st.get_best_cost(),
        evals: evals.get(),
    }
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(p, q)| (p - q).powi(2)).sum::<f64>().sqrt()
}

fn rosenbrock(x: &[f64]) -> f64 {
    x.windows(2).map(|w| 100.0 * (w[1] - w[0] * w[0]).powi(2) + (1.0 - w[0]).powi(2)).sum()
}

/// Whether argmin takes the adaptive coefficients (Gao & Han 2012) ours uses in dimension `n`.
fn adaptive_accepted(n: usize) -> String {
    let nf = n as f64;
    let (gamma, rho, sigma) = (1.0 + 2.0 / nf, 0.75 - 0.5 / nf, 1.0 - 1.0 / nf);
    let nm = NelderMead::<Vec<f64>, f64>::new(vec![vec![0.0; n]; n + 1]);
    match nm.with_gamma(gamma).and_then(|s| s.with_rho(rho)).and_then(|s| s.with_sigma(sigma)) {
        Ok(_) => format!("n = {n}: accepted (gamma {gamma:.3}, rho {rho:.3}, sigma {sigma:.3})"),
        Err(e) => format!("n = {n}: refused: {e}"),
    }
}

fn rosenbrock_table() {
    println!("Rosenbrock, from (-1.2, 1, ...), step 0.5, f_tol = sd_tolerance = 1e-14");
    println!(
        "{:<6}{:>10}{:>12}{:>12}{:>12}{:>12}{:>14}",
        "n", "", "evals", "f", "x[0]", "x[n-1]", "|x - x*|"
    );
    for n in [2, 5] {
        let x0: Vec<f64> = (0..n).map(|i| if i % 2 == 0 { -1.2 } else { 1.0 }).collect();
        for (name, r) in [
            ("ours", ours(&rosenbrock, &x0, 0.5, 1e-14, 50_000)),
            ("argmin", argmin_nm(&rosenbrock, &x0, 0.5, 1e-14, 50_000)),
        ] {
            let err = distance(&r.x, &vec![1.0; n]);
            println!(
                "{n:<6}{name:>10}{:>12}{:>12.3e}{:>12.6}{:>12.6}{:>14.3e}",
                r.evals,
                r.f,
                r.x[0],
                r.x[n - 1],
                err
            );
        }
    }
}

/// The oscillator benchmark's data: x, y (shared benchmarks §3).
fn read_data() -> (Vec<f64>, Vec<f64>) {
    let dir = std::env::var_os("CEILFARM_BENCHMARKS").map(PathBuf::from).unwrap_or_else(|| {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../../shared/benchmarks")
    });
    let path = dir.join("calib_nodisc.csv");
    let mut r = csv::Reader::from_path(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let (mut x, mut y) = (vec![], vec![]);
    for row in r.records() {
        let row = row.unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        x.push(row[0].parse().expect("x"));
        y.push(row[1].parse().expect("y"));
    }
    (x, y)
}

/// eta(x; k, c, m), worker/src/models/oscillator.rs.
fn oscillator_eta(x: f64, k: f64, c: f64, m: f64) -> f64 {
    let w = 0.5 + 1.5 * x;
    1.0 / ((k - m * w * w).powi(2) + (c * w).powi(2)).sqrt()
}

/// `fit_ml`'s start points (stats/src/selection/ml.rs): the centre, then Sobol' points.
fn start_points(d: usize, starts: usize, seed: u32) -> Vec<Vec<f64>> {
    let mut pts = vec![vec![0.0; d]];
    for i in 1..starts {
        let u: Vec<f64> =
            (0..d).map(|j| sobol_burley::sample(i as u32, j as u32, seed) as f64).collect();
        pts.push(u.iter().map(|u| ((0.02 + 0.96 * u) / (1.0 - 0.02 - 0.96 * u)).ln()).collect());
    }
    pts
}

/// `fit_ml`'s two Nelder–Mead passes from `z0` with `nm`.
fn two_passes(
    nm: fn(&dyn Fn(&[f64]) -> f64, &[f64], f64, f64, usize) -> Run,
    nll: &dyn Fn(&[f64]) -> f64,
    z0: &[f64],
) -> Run {
    let a = nm(nll, z0, 0.5, 1e-10, 4000);
    let b = nm(nll, &a.x, 0.05, 1e-12, 4000);
    Run { evals: a.evals + b.evals, ..b }
}

/// The selection's DIC (stats/src/selection/select.rs `dic_of`): an
/// adaptive-Metropolis posterior started at theta-hat, the command's
/// settings (seed 1).
fn dic_at<L: Likelihood>(box_: &UniformBox, lik: &L, theta_hat: &[f64]) -> f64 {
    let mut mcmc = SelectionSettings::default().mcmc;
    (mcmc.seed, mcmc.init_sd) = (1, 0.01);
    let post = Posterior::new(box_.clone(), lik).expect("posterior");
    let init = box_.to_unconstrained(theta_hat).unwrap_or_else(|| vec![0.0; box_.dim()]);
    let run = AdaptiveMetropolis::new(mcmc).run(&post, &init).expect("sampler");
    let draws: Vec<Vec<f64>> = run.draws().iter().map(|z| box_.to_physical(z)).collect();
    let dev = |t: &[f64]| -2.0 * lik.log_likelihood(t).unwrap_or(f64::NEG_INFINITY);
    let devs: Vec<f64> = draws.iter().map(|t| dev(t)).collect();
    let mean: Vec<f64> = (0..box_.dim())
        .map(|j| draws.iter().map(|t| t[j]).sum::<f64>() / draws.len() as f64)
        .collect();
    dic(&devs, dev(&mean)).0
}

/// Whether stats' own `select` with the command's settings gives the
/// -log L, theta-hat, MDL and DIC computed here with ours.
fn same_as_select<S: stats::calibration::Simulator>(
    sim: &S,
    candidates: &[&[usize]],
    y: &[f64],
    crit: &[Scores],
    thetas: &[(Vec<f64>, f64)],
) -> bool {
    let names = ["k", "c", "m"];
    let nominal = [1.5, 0.4, 1.0];
    let prior = UniformBox::new(
        names.iter().map(|s| s.to_string()).collect(),
        vec![0.5, 0.1, 0.5],
        vec![2.5, 0.7, 1.5],
    )
    .expect("box");
    let cands: Vec<Candidate> = candidates
        .iter()
        .zip(crit)
        .map(|(free, c)| Candidate {
            name: c.0.clone(),
            free: free.iter().map(|&i| names[i].to_string()).collect(),
            fixed: (0..3)
                .filter(|i| !free.contains(i))
                .map(|i| (names[i].to_string(), nominal[i]))
                .collect::<BTreeMap<_, _>>(),
        })
        .collect();
    let mut settings = SelectionSettings {
        seed: 1,
        starts: 16,
        qmc_points: 4096,
        qmc_replicates: 8,
        ..SelectionSettings::default()
    };
    settings.mcmc.seed = 1;
    let p = SelectionProblem { sim, prior, y: y.to_vec(), noise_sd: 0.1, truth: None };
    let table = select(&p, &cands, &settings).expect("select");
    table.candidates.iter().zip(crit).zip(thetas).all(|((s, c), t)| {
        s.neg_log_likelihood == t.1 && s.theta_hat == t.0 && s.mdl == c.1[2] && s.dic == c.1[3]
    })
}

/// A candidate's AIC, BIC, MDL and DIC with ours' fit, then with argmin's.
type Scores = (String, [f64; 4], [f64; 4]);

fn selection_table() {
    let (xs, y) = read_data();
    let n = y.len();
    let names = ["k", "c", "m"];
    let (lower, upper, nominal) = ([0.5, 0.1, 0.5], [2.5, 0.7, 1.5], [1.5, 0.4, 1.0]);
    let sim = FnSimulator::new(3, n, move |t: &[f64]| {
        Ok(xs.iter().map(|&x| oscillator_eta(x, t[0], t[1], t[2])).collect())
    });
    let candidates: [&[usize]; 7] = [&[0, 1, 2], &[0, 1], &[0, 2], &[1, 2], &[0], &[1], &[2]];
    println!();
    println!("configs/calibration/oscillator-select.toml: per candidate, 16 starts (seed 1), two passes each");
    println!(
        "{:<8}{:>9}{:>9}{:>9}{:>16}{:>16}{:>11}{:>11}{:>10}{:>10}",
        "cand.",
        "evals",
        "argmin",
        "fit_ml=",
        "-logL ours",
        "-logL argmin",
        "d(-logL)",
        "|d theta|",
        "worse",
        "better"
    );
    let mut crit: Vec<Scores> = vec![];
    let mut thetas: Vec<(Vec<f64>, f64)> = vec![];
    for free in candidates {
        let label: Vec<&str> = free.iter().map(|&i| names[i]).collect();
        let label = label.join("-");
        let sub = SubsetSimulator::new(&sim, free.to_vec(), nominal.to_vec()).expect("subset");
        let pick = |v: &[f64]| free.iter().map(|&i| v[i]).collect::<Vec<f64>>();
        let box_ = UniformBox::new(
            free.iter().map(|&i| names[i].to_string()).collect(),
            pick(&lower),
            pick(&upper),
        )
        .expect("box");
        let lik = GaussianLikelihood::new(&sub, y.clone(), Hyper::Fixed(0.1)).expect("likelihood");
        let nll = |z: &[f64]| match lik.log_likelihood(&box_.to_physical(z)) {
            Ok(v) if v.is_finite() => -v,
            _ => f64::INFINITY,
        };
        let (mut best_o, mut best_a): (Option<Run>, Option<Run>) = (None, None);
        let (mut evals_o, mut evals_a, mut worse, mut better) = (0, 0, 0, 0);
        for z0 in start_points(free.len(), 16, 1) {
            let (o, a) = (two_passes(ours, &nll, &z0), two_passes(argmin_nm, &nll, &z0));
            (evals_o, evals_a) = (evals_o + o.evals, evals_a + a.evals);
            worse += usize::from(a.f > o.f + 1e-9);
            better += usize::from(a.f < o.f - 1e-9);
            if best_o.as_ref().is_none_or(|b| o.f < b.f) {
                best_o = Some(o);
            }
            if best_a.as_ref().is_none_or(|b| a.f < b.f) {
                best_a = Some(a);
            }
        }
        let (o, a) = (best_o.expect("16 starts"), best_a.expect("16 starts"));
        let fit = fit_ml(&lik, &box_, 16, 1);
        let same = fit.neg_log_likelihood == o.f && fit.theta == box_.to_physical(&o.x);
        let dtheta = distance(&box_.to_physical(&o.x), &box_.to_physical(&a.x));
        println!(
            "{label:<8}{evals_o:>9}{evals_a:>9}{:>9}{:>16.9}{:>16.9}{:>11.2e}{:>11.2e}{:>10}{:>10}",
            if same { "yes" } else { "NO" },
            o.f,
            a.f,
            a.f - o.f,
            dtheta,
            format!("{worse}/16"),
            format!("{better}/16")
        );
        let k = free.len();
        let lfi =
            log_fisher_integral(&sub, &box_, 0.1, 4096, 8, 1).expect("Fisher integral").log_value;
        let scores = |r: &Run| {
            let theta = box_.to_physical(&r.x);
            [aic(r.f, k), bic(r.f, k, n), mdl(r.f, k, n, lfi), dic_at(&box_, &lik, &theta)]
        };
        crit.push((label, scores(&o), scores(&a)));
        thetas.push((box_.to_physical(&o.x), o.f));
    }
    let agree = same_as_select(&sim, &candidates, &y, &crit, &thetas);
    println!("stats' select() (the command's settings) gives ours' -logL, theta-hat, MDL and DIC bit for bit: {}", if agree { "yes" } else { "NO" });
    println!("(evals: both passes over the 16 starts; fit_ml=: ours here equals stats' fit_ml bit for bit;");
    println!(" worse/better: starts where argmin ended above/below ours by more than 1e-9)");
    for (j, name) in ["AIC", "BIC", "MDL", "DIC"].iter().enumerate() {
        let winner = |pick: fn(&Scores) -> [f64; 4]| {
            let best = crit.iter().min_by(|p, q| pick(p)[j].total_cmp(&pick(q)[j])).expect("7");
            best.0.clone()
        };
        let largest = crit.iter().map(|c| (c.2[j] - c.1[j]).abs()).fold(0.0, f64::max);
        let same_csv = crit.iter().all(|c| format!("{:.6}", c.1[j]) == format!("{:.6}", c.2[j]));
        println!(
            "{name}: winner ours {}, argmin {}; largest |change| of a candidate's {name} {largest:.2e}; \
             criteria.csv's {name} column (6 decimals) {}",
            winner(|c| c.1),
            winner(|c| c.2),
            if same_csv { "unchanged" } else { "CHANGED" }
        );
    }
}

fn main() {
    rosenbrock_table();
    println!("argmin's NelderMead and the adaptive coefficients ours uses:");
    for n in [1, 2, 3, 5] {
        println!("  {}", adaptive_accepted(n));
    }
    selection_table();
}
