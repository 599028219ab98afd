//! Dense reference solver for tests: static condensation of the massless
//! DOFs, then the symmetric standard problem M^-1/2 K_c M^-1/2 (nalgebra).
//! O(n³); meant for small models only.

use nalgebra::{DMatrix, SymmetricEigen};

use super::lanczos::normalize_sign;
use super::Eigenpairs;
use crate::assembly::SparsePattern;

/// All eigenpairs (ascending) of K (values on `pattern`) and diagonal M;
/// `None` if the massless block of K is singular.
pub fn dense_eigen(pattern: &SparsePattern, k_values: &[f64], mass: &[f64]) -> Option<Eigenpairs> {
    let n = pattern.n;
    let mut k = DMatrix::zeros(n, n);
    for c in 0..n {
        for p in pattern.col_ptr[c]..pattern.col_ptr[c + 1] {
            k[(pattern.row_idx[p], c)] = k_values[p];
        }
    }
    let massed: Vec<usize> = (0..n).filter(|&i| mass[i] > 0.0).collect();
    let free: Vec<usize> = (0..n).filter(|&i| mass[i] <= 0.0).collect();
    let sub = |r: &[usize], c: &[usize]| DMatrix::from_fn(r.len(), c.len(), |a, b| k[(r[a], c[b])]);
    let (kmm, kmo, koo) = (sub(&massed, &massed), sub(&massed, &free), sub(&free, &free));
    // Koo⁻¹ Kom: the massless DOFs' response to unit massed displacements.
    let g = if free.is_empty() {
        DMatrix::zeros(0, massed.len())
    } else {
        koo.clone().lu().solve(&kmo.transpose())?
    };
    let kc = &kmm - &kmo * &g;
    let d: Vec<f64> = massed.iter().map(|&i| 1.0 / mass[i].sqrt()).collect();
    let s = DMatrix::from_fn(massed.len(), massed.len(), |a, b| d[a] * kc[(a, b)] * d[b]);
    let eig = SymmetricEigen::new((&s + s.transpose()) * 0.5);
    let mut order: Vec<usize> = (0..massed.len()).collect();
    order.sort_by(|a, b| eig.eigenvalues[*a].total_cmp(&eig.eigenvalues[*b]));
    let mut out = Eigenpairs { omega2: vec![], vectors: vec![] };
    for k in order {
        let phi_m: Vec<f64> = (0..massed.len()).map(|a| d[a] * eig.eigenvectors[(a, k)]).collect();
        let phi_o = -(&g * nalgebra::DVector::from_vec(phi_m.clone()));
        let mut x = vec![0.0; n];
        massed.iter().zip(&phi_m).for_each(|(&i, v)| x[i] = *v);
        free.iter().zip(phi_o.iter()).for_each(|(&i, v)| x[i] = *v);
        normalize_sign(&mut x);
        out.omega2.push(eig.eigenvalues[k]);
        out.vectors.push(x);
    }
    Some(out)
}
