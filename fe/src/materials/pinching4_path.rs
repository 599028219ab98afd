//! Pinching4 piecewise-linear pieces: the backbone on either side and the
//! three-segment unload-reload paths of states 3 and 4, with the corrections
//! OpenSees `Pinching4Material` (getState3 / getState4) applies to them.
//! Units: deformation mm, force N.

/// Force and slope on a backbone of six points (0 is the tiny elastic point,
/// 5 the far extrapolation), positive side. Segments of zero slope are
/// skipped as OpenSees does.
pub(crate) fn pos_backbone(d: &[f64; 6], f: &[f64; 6], u: f64) -> (f64, f64) {
    let mut k = 0.0;
    let mut force = 0.0;
    let mut i = 0;
    while k == 0.0 && i <= 4 {
        if u <= d[i + 1] {
            k = (f[i + 1] - f[i]) / (d[i + 1] - d[i]);
            force = f[i] + (u - d[i]) * k;
        }
        i += 1;
    }
    if k == 0.0 {
        k = (f[5] - f[4]) / (d[5] - d[4]);
        force = f[5] + k * (u - d[5]);
    }
    (force, k)
}

/// Force and slope on the negative backbone (deformations decreasing).
pub(crate) fn neg_backbone(d: &[f64; 6], f: &[f64; 6], u: f64) -> (f64, f64) {
    let mut k = 0.0;
    let mut force = 0.0;
    let mut i = 0;
    while k == 0.0 && i <= 4 {
        if u >= d[i + 1] {
            k = (f[i] - f[i + 1]) / (d[i] - d[i + 1]);
            force = f[i + 1] + (u - d[i + 1]) * k;
        }
        i += 1;
    }
    if k == 0.0 {
        k = (f[4] - f[5]) / (d[4] - d[5]);
        force = f[5] + k * (u - d[5]);
    }
    (force, k)
}

/// A four-point unload-reload path (deformations `d`, forces `f`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Path {
    pub d: [f64; 4],
    pub f: [f64; 4],
}

impl Path {
    /// Force and slope at `u`: the last segment starting at or before `u`;
    /// before the first point, the first segment extended.
    pub(crate) fn eval(&self, u: f64) -> (f64, f64) {
        let (d, f) = (&self.d, &self.f);
        let mut k = 0.0;
        let mut force = 0.0;
        for i in 0..3 {
            if u >= d[i] {
                k = (f[i + 1] - f[i]) / (d[i + 1] - d[i]);
                force = f[i] + (u - d[i]) * k;
            }
        }
        if k == 0.0 {
            let i = if u < d[0] { 0 } else { 2 };
            k = (f[i + 1] - f[i]) / (d[i + 1] - d[i]);
            force = f[i] + (u - d[i]) * k;
        }
        (force, k)
    }

    /// Points 1 and 2 at 33 % and 67 % of the straight line from 0 to 3.
    fn make_linear(&mut self) {
        let du = self.d[3] - self.d[0];
        let df = self.f[3] - self.f[0];
        self.d[1] = self.d[0] + 0.33 * du;
        self.d[2] = self.d[0] + 0.67 * du;
        self.f[1] = self.f[0] + 0.33 * df;
        self.f[2] = self.f[0] + 0.67 * df;
    }

    /// Point 1 halfway between points 0 and 2.
    fn mid_1(&mut self) {
        self.d[1] = self.d[0] + 0.5 * (self.d[2] - self.d[0]);
        self.f[1] = self.f[0] + 0.5 * (self.f[2] - self.f[0]);
    }

    /// Point 2 halfway between points 1 and 3.
    fn mid_2(&mut self) {
        self.d[2] = self.d[1] + 0.5 * (self.d[3] - self.d[1]);
        self.f[2] = self.f[1] + 0.5 * (self.f[3] - self.f[1]);
    }

    /// Pulls points 1 and 2 to 1 % either side of their mean force, keeping
    /// the slopes of the first and last segments.
    fn split_mean_force(&mut self) {
        let avg = 0.5 * (self.f[2] + self.f[1]);
        let dfr = avg.abs() / 100.0;
        let slope01 = (self.f[1] - self.f[0]) / (self.d[1] - self.d[0]);
        let slope23 = (self.f[3] - self.f[2]) / (self.d[3] - self.d[2]);
        self.f[1] = avg - dfr;
        self.f[2] = avg + dfr;
        self.d[1] = self.d[0] + (self.f[1] - self.f[0]) / slope01;
        self.d[2] = self.d[3] - (self.f[3] - self.f[2]) / slope23;
    }

    /// OpenSees' last check: a path that goes backwards becomes straight,
    /// and a straight path flatter than the secant to point 0 is replaced
    /// by one through the origin.
    fn final_check(&mut self) {
        let check_slope = self.f[0] / self.d[0];
        let mut slope = 0.0;
        let mut i = 0;
        while i < 3 {
            let du = self.d[i + 1] - self.d[i];
            let df = self.f[i + 1] - self.f[i];
            if du < 0.0 || df < 0.0 {
                self.make_linear();
                slope = (self.f[3] - self.f[0]) / (self.d[3] - self.d[0]);
                i = 3;
            }
            if slope > 1e-8 && slope < check_slope {
                self.d[1] = 0.0;
                self.f[1] = 0.0;
                self.d[2] = self.d[3] / 2.0;
                self.f[2] = self.f[3] / 2.0;
            }
            i += 1;
        }
    }
}

/// Inputs of a reloading path construction, for one direction.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PathInputs {
    /// Unloading stiffness of this path (N/mm).
    pub k_unload: f64,
    /// Damaged elastic stiffness of the side the path reloads towards (N/mm).
    pub k_elastic_dmg: f64,
    /// Reloading deformation ratio of that side.
    pub r_disp: f64,
    /// Reloading force ratio of that side.
    pub r_force: f64,
    /// Unloading force ratio of that side.
    pub u_force: f64,
    /// Largest excursion on that side passed backbone point 3.
    pub beyond_point3: bool,
    /// Damaged backbone forces at points 3 and 4 of that side (N).
    pub env_f3: f64,
    /// See `env_f3`.
    pub env_f4: f64,
}

/// State 3 path: from (d0, f0) = the negative target down-left to
/// (d3, f3) = the point where unloading from the positive side started.
pub(crate) fn state3_path(d0: f64, f0: f64, d3: f64, f3: f64, p: &PathInputs) -> Path {
    let mut path = Path { d: [d0, 0.0, 0.0, d3], f: [f0, 0.0, 0.0, f3] };
    let k_max = if p.k_unload > p.k_elastic_dmg { p.k_unload } else { p.k_elastic_dmg };
    if d0 * d3 >= 0.0 {
        path.make_linear();
        path.final_check();
        return path;
    }
    path.d[1] = d0 * p.r_disp;
    if p.r_force - p.u_force > 1e-8 {
        path.f[1] = f0 * p.r_force;
    } else {
        let st1 = (if p.beyond_point3 { f0 } else { p.env_f3 }) * p.u_force * (1.0 + 1e-6);
        let st2 = p.env_f4 * (1.0 + 1e-6);
        path.f[1] = if st1 < st2 { st1 } else { st2 };
    }
    if (path.f[1] - f0) / (path.d[1] - d0) > p.k_elastic_dmg {
        path.d[1] = d0 + (path.f[1] - f0) / p.k_elastic_dmg;
    }
    if path.d[1] > d3 {
        path.make_linear();
    } else {
        path.f[2] = p.u_force * (if p.beyond_point3 { p.env_f4 } else { p.env_f3 });
        path.d[2] = d3 - (f3 - path.f[2]) / p.k_unload;
        let slope12 = (path.f[2] - path.f[1]) / (path.d[2] - path.d[1]);
        if path.d[2] > d3 {
            path.mid_2();
        } else if slope12 > k_max {
            path.make_linear();
        } else if path.d[2] < path.d[1] || slope12 < 0.0 {
            if path.d[2] < 0.0 {
                path.mid_2();
            } else if path.d[1] > 0.0 {
                path.mid_1();
            } else {
                path.split_mean_force();
            }
        }
    }
    path.final_check();
    path
}

/// State 4 path: from (d0, f0) = the point where unloading from the
/// negative side started up-right to (d3, f3) = the positive target.
pub(crate) fn state4_path(d0: f64, f0: f64, d3: f64, f3: f64, p: &PathInputs) -> Path {
    let mut path = Path { d: [d0, 0.0, 0.0, d3], f: [f0, 0.0, 0.0, f3] };
    let k_max = if p.k_unload > p.k_elastic_dmg { p.k_unload } else { p.k_elastic_dmg };
    if d0 * d3 >= 0.0 {
        path.make_linear();
        path.final_check();
        return path;
    }
    path.d[2] = d3 * p.r_disp;
    if p.u_force == 0.0 || p.r_force - p.u_force > 1e-8 {
        path.f[2] = f3 * p.r_force;
    } else {
        let st1 = (if p.beyond_point3 { f3 } else { p.env_f3 }) * p.u_force * (1.0 + 1e-6);
        let st2 = p.env_f4 * (1.0 + 1e-6);
        path.f[2] = if st1 > st2 { st1 } else { st2 };
    }
    if (f3 - path.f[2]) / (d3 - path.d[2]) > p.k_elastic_dmg {
        path.d[2] = d3 - (f3 - path.f[2]) / p.k_elastic_dmg;
    }
    if path.d[2] < d0 {
        path.make_linear();
    } else {
        path.f[1] = p.u_force * (if p.beyond_point3 { p.env_f4 } else { p.env_f3 });
        path.d[1] = d0 + (path.f[1] - f0) / p.k_unload;
        let slope12 = (path.f[2] - path.f[1]) / (path.d[2] - path.d[1]);
        if path.d[1] < d0 {
            path.mid_1();
        } else if slope12 > k_max {
            path.make_linear();
        } else if path.d[2] < path.d[1] || slope12 < 0.0 {
            if path.d[1] > 0.0 {
                path.mid_1();
            } else if path.d[2] < 0.0 {
                path.mid_2();
            } else {
                path.split_mean_force();
            }
        }
    }
    path.final_check();
    path
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn backbone_interpolates_and_extrapolates() {
        let d = [0.001, 1.0, 2.0, 3.0, 4.0, 4e6];
        let f = [0.1, 100.0, 150.0, 160.0, 100.0, 110.0];
        let (force, k) = pos_backbone(&d, &f, 1.5);
        assert!((force - 125.0).abs() < 1e-12 && (k - 50.0).abs() < 1e-12);
        let nd = d.map(|x| -x);
        let nf = f.map(|x| -x);
        let (force, k) = neg_backbone(&nd, &nf, -1.5);
        assert!((force + 125.0).abs() < 1e-12 && (k - 50.0).abs() < 1e-12);
    }

    #[test]
    fn path_eval_is_continuous_at_its_points() {
        let p = Path { d: [-2.0, -1.0, 1.0, 3.0], f: [-10.0, -2.0, 1.0, 20.0] };
        for i in 1..3 {
            let (a, _) = p.eval(p.d[i] - 1e-9);
            let (b, _) = p.eval(p.d[i] + 1e-9);
            assert!((a - b).abs() < 1e-6);
            assert!((b - p.f[i]).abs() < 1e-6);
        }
    }
}
