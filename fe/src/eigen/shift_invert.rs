//! The shift-invert operator of K φ = ω² M φ (M diagonal, possibly
//! singular) in mass-scaled coordinates on the DOFs that carry mass:
//! Op = M½ (K − σM)⁻¹ M½, symmetric in the plain inner product, with the
//! same eigenvalues θ = 1/(ω² − σ) as (K − σM)⁻¹ M. A vector x on the massed
//! DOFs stands for the displacement M^-½ x; its image also comes back on all
//! DOFs, (K − σM)⁻¹ M½ x, statically condensed onto the massless ones.
//! Units: masses in t (or t·mm²), σ in rad²/s².

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::LltRef;
use faer::{Conj, MatMut, MatRef, Par};

use crate::transient::factor_cache::TangentFactor;

/// (K − σM)⁻¹ acting on mass-scaled vectors.
pub struct ScaledShiftInvert<'a> {
    factor: &'a TangentFactor,
    /// Scratch of the supernodal solves, and the column count it is for.
    scratch: (MemBuffer, usize),
    /// Equations with positive mass, ascending.
    massed: Vec<usize>,
    /// √m of each massed equation.
    sqrt_mass: Vec<f64>,
    /// Number of equations.
    n: usize,
}

impl<'a> ScaledShiftInvert<'a> {
    /// The operator of a factorized K − σM and the mass diagonal.
    pub fn new(factor: &'a TangentFactor, mass: &[f64]) -> Self {
        let massed: Vec<usize> = (0..mass.len()).filter(|&i| mass[i] > 0.0).collect();
        let sqrt_mass = massed.iter().map(|&i| mass[i].sqrt()).collect();
        let scratch = (MemBuffer::new(faer::dyn_stack::StackReq::EMPTY), 0);
        ScaledShiftInvert { factor, scratch, massed, sqrt_mass, n: mass.len() }
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
        full.fill(0.0);
        for j in 0..x.ncols() {
            let mut col = full.as_mut().col_mut(j);
            for (k, (&e, s)) in self.massed.iter().zip(&self.sqrt_mass).enumerate() {
                col[e] = s * x[(k, j)];
            }
        }
        self.solve(full.as_mut());
        for j in 0..x.ncols() {
            let col = full.as_ref().col(j);
            let mut out = scaled.as_mut().col_mut(j);
            for (k, (&e, s)) in self.massed.iter().zip(&self.sqrt_mass).enumerate() {
                out[k] = s * col[e];
            }
        }
    }

    /// Overwrites each column of `x` with (K − σM)⁻¹ x.
    fn solve(&mut self, mut x: MatMut<'_, f64>) {
        match self.factor {
            TangentFactor::Cholesky { symbolic, values } => {
                if self.scratch.1 != x.ncols() {
                    let req = symbolic.solve_in_place_scratch::<f64>(x.ncols(), Par::Seq);
                    self.scratch = (MemBuffer::new(req), x.ncols());
                }
                LltRef::new(symbolic, values).solve_in_place_with_conj(
                    Conj::No,
                    x.as_mut(),
                    Par::Seq,
                    MemStack::new(&mut self.scratch.0),
                );
            }
            TangentFactor::General(f) => f.solve_mat_in_place(x),
        }
    }
}
