//! Saltelli's cross-sampling scheme (Saltelli 2002; Saltelli et al. 2010,
//! *Comput. Phys. Commun.* 181:259): two independent base matrices A and B
//! from one 2d-dimensional Owen-scrambled Sobol' sequence, and for each
//! input i the matrix A_B^(i) (A with column i taken from B). Row order of
//! the returned points: for each base row j, A_j, A_B^(1)_j .. A_B^(d)_j,
//! B_j — so a model sees N (d + 2) points (SALib's layout without second
//! order).

use super::problem::Problem;

/// Points of the Saltelli design, (N (d + 2), d) row-major, physical units.
pub fn saltelli_sample(problem: &Problem, n: usize, seed: u32) -> Vec<f64> {
    let d = problem.dim();
    let mut out = Vec::with_capacity(n * (d + 2) * d);
    let mut a = vec![0.0; d];
    let mut b = vec![0.0; d];
    for j in 0..n {
        for k in 0..d {
            a[k] = problem.to_physical(k, unit(j, k, seed));
            b[k] = problem.to_physical(k, unit(j, d + k, seed));
        }
        out.extend_from_slice(&a);
        for i in 0..d {
            out.extend((0..d).map(|k| if k == i { b[k] } else { a[k] }));
        }
        out.extend_from_slice(&b);
    }
    out
}

/// Coordinate `dim` of scrambled Sobol' point `index`, in (0, 1).
fn unit(index: usize, dim: usize, seed: u32) -> f64 {
    // Centre the f32 cell so no coordinate is exactly 0.
    let u = sobol_burley::sample(index as u32, dim as u32, seed) as f64;
    (u + 0.5 / 16_777_216.0).min(1.0 - 1e-9)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_shares_columns_between_a_b_and_cross_matrices() {
        let p = Problem {
            names: vec!["a".into(), "b".into(), "c".into()],
            bounds: vec![(0.0, 1.0); 3],
        };
        let s = saltelli_sample(&p, 4, 1);
        let d = 3;
        assert_eq!(s.len(), 4 * 5 * d);
        for j in 0..4 {
            let row = |r: usize| &s[(j * 5 + r) * d..(j * 5 + r + 1) * d];
            let (a, b) = (row(0), row(4));
            for i in 0..d {
                let ab = row(1 + i);
                for k in 0..d {
                    assert_eq!(ab[k], if k == i { b[k] } else { a[k] });
                }
            }
        }
    }
}
