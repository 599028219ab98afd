//! The shift-invert operator of K φ = ω² M φ (M diagonal, possibly
//! singular) in mass-scaled coordinates on the DOFs that carry mass:
//! Op = M½ (K − σM)⁻¹ M½, symmetric in the plain inner product, with the
//! same eigenvalues θ = 1/(ω² − σ) as (K − σM)⁻¹ M. A vector x on the massed
//! DOFs stands for the displacement M^-½ x; its image also comes back on all
//! DOFs, (K − σM)⁻¹ M½ x, statically condensed onto the massless ones.
//! Units: masses in t (or t·mm²), σ in rad²/s².

use faer::{MatMut, MatRef};

use super::factor::SparseFactor;
use super::supernodal::SupernodalCholesky;

/// A factorized K − σM.
pub enum ShiftedFactor {
    /// Supernodal LLᵀ (σ below the lowest eigenvalue); boxed, being far
    /// larger than the other variant.
    Cholesky(Box<SupernodalCholesky>),
    /// LU of an indefinite K − σM.
    General(SparseFactor),
}

/// (K − σM)⁻¹ acting on mass-scaled vectors.
pub struct ScaledShiftInvert<'a> {
    factor: &'a ShiftedFactor,
    /// Equations with positive mass, ascending.
    massed: Vec<usize>,
    /// √m of each massed equation.
    sqrt_mass: Vec<f64>,
    /// Interleaved right-hand sides of the Cholesky substitutions.
    work: Vec<f64>,
    /// Number of equations.
    n: usize,
}

impl<'a> ScaledShiftInvert<'a> {
    /// The operator of a factorized K − σM and the mass diagonal.
    pub fn new(factor: &'a ShiftedFactor, mass: &[f64]) -> Self {
        let massed: Vec<usize> = (0..mass.len()).filter(|&i| mass[i] > 0.0).collect();
        let sqrt_mass = massed.iter().map(|&i| mass[i].sqrt()).collect();
        ScaledShiftInvert { factor, massed, sqrt_mass, work: Vec::new(), n: mass.len() }
    }

    /// Number of massed DOFs (the dimension of the scaled space).
    pub fn dim(&self) -> usize {
        self.massed.len()
    }

    /// Number of equations (the length of a full image).
    pub fn n_equations(&self) -> usize {
        self.n
    }

    /// For each column x of `x` (dim × k): the full image
    /// (K − σM)⁻¹ M½ x into `full` (n × k) and its scaled restriction
    /// Op x into `scaled` (dim × k).
    pub fn apply(
        &mut self,
        x: MatRef<'_, f64>,
        mut full: MatMut<'_, f64>,
        mut scaled: MatMut<'_, f64>,
    ) {
        match self.factor {
            ShiftedFactor::Cholesky(f) => {
                // Up to four right-hand sides per substitution.
                let mut j0 = 0;
                while j0 < x.ncols() {
                    let k = (x.ncols() - j0).min(4);
                    let (xs, fs) = (x.subcols(j0, k), full.as_mut().subcols_mut(j0, k));
                    match k {
                        1 => self.cholesky_apply::<1>(f, xs, fs),
                        2 => self.cholesky_apply::<2>(f, xs, fs),
                        3 => self.cholesky_apply::<3>(f, xs, fs),
                        _ => self.cholesky_apply::<4>(f, xs, fs),
                    }
                    j0 += k;
                }
            }
            ShiftedFactor::General(f) => {
                full.fill(0.0);
                for j in 0..x.ncols() {
                    let mut col = full.as_mut().col_mut(j);
                    for (k, (&e, s)) in self.massed.iter().zip(&self.sqrt_mass).enumerate() {
                        col[e] = s * x[(k, j)];
                    }
                }
                f.solve_mat_in_place(full.as_mut());
            }
        }
        for j in 0..x.ncols() {
            let col = full.as_ref().col(j);
            let mut out = scaled.as_mut().col_mut(j);
            for (k, (&e, s)) in self.massed.iter().zip(&self.sqrt_mass).enumerate() {
                out[k] = s * col[e];
            }
        }
    }

    /// `full` = (K − σM)⁻¹ M½ x for K columns, by one interleaved substitution.
    fn cholesky_apply<const K: usize>(
        &mut self,
        f: &SupernodalCholesky,
        x: MatRef<'_, f64>,
        mut full: MatMut<'_, f64>,
    ) {
        self.work.clear();
        self.work.resize(K * self.n, 0.0);
        let y = &mut self.work;
        for (k, (&e, s)) in self.massed.iter().zip(&self.sqrt_mass).enumerate() {
            let at = K * f.position(e);
            for j in 0..K {
                y[at + j] = s * x[(k, j)];
            }
        }
        f.solve_interleaved::<K>(y);
        for j in 0..K {
            let mut col = full.as_mut().col_mut(j);
            for e in 0..self.n {
                col[e] = y[K * f.position(e) + j];
            }
        }
    }
}
