//! 3D elastic Euler-Bernoulli beam-column, as OpenSees `elasticBeamColumn`
//! with `geomTransf Linear` (no offsets, no P-Delta, no shear deformation).
//!
//! Local axes: x from node i to node j; y = (vecxz × x)/|…|; z = x × y.
//! DOF order per node: ux, uy, uz, rx, ry, rz. Units: N, mm, MPa, mm⁴.

use nalgebra::{Matrix3, SMatrix, Vector3};

use crate::model::Beam;

/// A 12×12 element matrix (node i DOFs 0..6, node j DOFs 6..12).
pub type Mat12 = SMatrix<f64, 12, 12>;

/// Rows are the unit local axes x, y, z in global components, plus the
/// length (mm); `None` if the nodes coincide or vecxz is parallel to x.
#[allow(clippy::neg_cmp_op_on_partial_ord)] // NaN must fail the check
pub fn local_axes(xi: [f64; 3], xj: [f64; 3], vecxz: [f64; 3]) -> Option<(Matrix3<f64>, f64)> {
    let d = Vector3::from(xj) - Vector3::from(xi);
    let len = d.norm();
    if !(len > 0.0) {
        return None;
    }
    let ex = d / len;
    let y = Vector3::from(vecxz).cross(&ex);
    let ny = y.norm();
    if !(ny > 1e-12 * Vector3::from(vecxz).norm()) {
        return None;
    }
    let ey = y / ny;
    let ez = ex.cross(&ey);
    Some((Matrix3::from_rows(&[ex.transpose(), ey.transpose(), ez.transpose()]), len))
}

/// Local 12×12 stiffness of a beam of length `len_mm` (standard Euler-Bernoulli
/// matrix: EA/L, GJ/L, 12EI/L³, 6EI/L², 4EI/L, 2EI/L).
pub fn beam_local_stiffness(b: &Beam, len_mm: f64) -> Mat12 {
    let l = len_mm;
    let mut k = Mat12::zeros();
    let ea = b.e_mpa * b.area_mm2 / l;
    let gj = b.g_mpa * b.j_mm4 / l;
    set_pair(&mut k, 0, 6, ea);
    set_pair(&mut k, 3, 9, gj);
    // Bending in local x-y (about z): v (1, 7), θz (5, 11).
    bending(&mut k, b.e_mpa * b.iz_mm4, l, [1, 5, 7, 11], 1.0);
    // Bending in local x-z (about y): w (2, 8), θy (4, 10); θy = -dw/dx.
    bending(&mut k, b.e_mpa * b.iy_mm4, l, [2, 4, 8, 10], -1.0);
    k
}

/// Axial-type 2×2 block [[s, -s], [-s, s]] on DOFs a, b.
fn set_pair(k: &mut Mat12, a: usize, b: usize, s: f64) {
    k[(a, a)] = s;
    k[(b, b)] = s;
    k[(a, b)] = -s;
    k[(b, a)] = -s;
}

/// Bending block on [w1, θ1, w2, θ2]; `sign` flips the w-θ coupling.
fn bending(k: &mut Mat12, ei: f64, l: f64, d: [usize; 4], sign: f64) {
    let (k1, k2, k3, k4) =
        (12.0 * ei / l.powi(3), 6.0 * ei / l.powi(2), 4.0 * ei / l, 2.0 * ei / l);
    let c = sign * k2;
    let block = [[k1, c, -k1, c], [c, k3, -c, k4], [-k1, -c, k1, -c], [c, k4, -c, k3]];
    for (r, row) in block.iter().enumerate() {
        for (s, v) in row.iter().enumerate() {
            k[(d[r], d[s])] = *v;
        }
    }
}

/// Global 12×12 stiffness T' k T, T = diag(R, R, R, R); `None` on bad geometry.
pub fn beam_global_stiffness(b: &Beam, xi: [f64; 3], xj: [f64; 3]) -> Option<Mat12> {
    let (r, len) = local_axes(xi, xj, b.vecxz)?;
    let kl = beam_local_stiffness(b, len);
    let mut t = Mat12::zeros();
    for blk in 0..4 {
        t.fixed_view_mut::<3, 3>(3 * blk, 3 * blk).copy_from(&r);
    }
    Some(t.transpose() * kl * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn beam() -> Beam {
        Beam {
            id: 1,
            i: 1,
            j: 2,
            area_mm2: 38.0,
            e_mpa: 210000.0,
            g_mpa: 78000.0,
            j_mm4: 8200.0,
            iy_mm4: 7525.0,
            iz_mm4: 1000.0,
            vecxz: [0.0, 0.0, 1.0],
            group: None,
        }
    }

    #[test]
    fn axes_of_a_horizontal_member_put_local_z_up() {
        let (r, len) = local_axes([0.0; 3], [0.0, 600.0, 0.0], [0.0, 0.0, 1.0]).unwrap();
        assert_eq!(len, 600.0);
        assert!((r.row(1) - Vector3::new(-1.0, 0.0, 0.0).transpose()).norm() < 1e-15);
        assert!((r.row(2) - Vector3::new(0.0, 0.0, 1.0).transpose()).norm() < 1e-15);
    }

    #[test]
    fn vertical_tip_load_gives_cantilever_deflection_with_iy() {
        // Beam along global x, vecxz = z: vertical bending uses Iy.
        // Tip deflection P L³ / (3 E Iy) (Gere & Timoshenko).
        let b = beam();
        let k = beam_global_stiffness(&b, [0.0; 3], [600.0, 0.0, 0.0]).unwrap();
        let kff = k.fixed_view::<6, 6>(6, 6).into_owned();
        let u = kff.try_inverse().unwrap() * nalgebra::Vector6::new(0.0, 0.0, 1.0, 0.0, 0.0, 0.0);
        let expected = 600f64.powi(3) / (3.0 * 210000.0 * 7525.0);
        assert!((u[2] - expected).abs() < 1e-12 * expected.max(1.0), "{} vs {expected}", u[2]);
    }
}
