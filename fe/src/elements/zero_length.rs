//! Zero-length spring in one global DOF (OpenSees `zeroLength -dir dof`).
//!
//! Deformation d = u_j[dof] − u_i[dof]; resisting force −f on i, +f on j;
//! tangent k [[1, −1], [−1, 1]]. Units: mm, N, N/mm.

/// Spring deformation (mm) from the two nodal displacements in its DOF.
pub fn spring_deformation(u_i: f64, u_j: f64) -> f64 {
    u_j - u_i
}

/// Resisting force vector on (node i, node j) for material force `f_n`.
pub fn spring_force_vector(f_n: f64) -> [f64; 2] {
    [-f_n, f_n]
}

/// 2×2 tangent on (node i, node j) for material tangent `k_n_per_mm`.
pub fn spring_stiffness(k_n_per_mm: f64) -> [[f64; 2]; 2] {
    [[k_n_per_mm, -k_n_per_mm], [-k_n_per_mm, k_n_per_mm]]
}

/// Local DOF indices (0..12, node i first) that a spring in `dof` (1..6) couples.
pub fn spring_dofs(dof: u8) -> [usize; 2] {
    let d = usize::from(dof.clamp(1, 6)) - 1;
    [d, 6 + d]
}
