//! Multi-linear skeleton (backbone) curves for the Takeda and Pivot laws:
//! on each side a polyline from the origin through up to [`MAX_POINTS`]
//! points, the first being the yield point, continued past the last point
//! with the last segment's slope (flat if there is one point).
//! Units: deformation mm, force N.

use super::MaterialError;

/// Most points per side.
pub const MAX_POINTS: usize = 8;

/// One side of a skeleton, in magnitudes (deformations and forces > 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Side {
    d: [f64; MAX_POINTS],
    f: [f64; MAX_POINTS],
    n: usize,
    k_end: f64,
}

impl Side {
    /// Checks and stores one side; `sign` is +1 or -1 for the JSON values.
    fn new(
        material: &'static str,
        d: &[f64],
        f: &[f64],
        sign: f64,
        keys: (&'static str, &'static str),
    ) -> Result<Self, MaterialError> {
        let bad =
            |key, value, expected| MaterialError::Parameter { material, key, value, expected };
        if d.is_empty() || d.len() > MAX_POINTS || d.len() != f.len() {
            return Err(bad(keys.0, d.len() as f64, "1 to 8 points, as many as forces"));
        }
        let mut side = Side { d: [0.0; MAX_POINTS], f: [0.0; MAX_POINTS], n: d.len(), k_end: 0.0 };
        let mut last = 0.0;
        for (i, (&di, &fi)) in d.iter().zip(f).enumerate() {
            let (di, fi) = (sign * di, sign * fi);
            if !(di.is_finite() && di > last) {
                return Err(bad(
                    keys.0,
                    sign * di,
                    "deformations of the side's sign, growing in size",
                ));
            }
            if !(fi.is_finite() && fi > 0.0) {
                return Err(bad(keys.1, sign * fi, "finite forces of the side's sign"));
            }
            side.d[i] = di;
            side.f[i] = fi;
            last = di;
        }
        if side.n > 1 {
            let j = side.n - 1;
            side.k_end = (side.f[j] - side.f[j - 1]) / (side.d[j] - side.d[j - 1]);
        }
        Ok(side)
    }

    /// Force magnitude and slope at deformation magnitude `x` >= 0.
    fn eval(&self, x: f64) -> (f64, f64) {
        let (mut d0, mut f0) = (0.0, 0.0);
        for i in 0..self.n {
            if x <= self.d[i] {
                let k = (self.f[i] - f0) / (self.d[i] - d0);
                return (f0 + k * (x - d0), k);
            }
            d0 = self.d[i];
            f0 = self.f[i];
        }
        (f0 + self.k_end * (x - d0), self.k_end)
    }
}

/// A skeleton with a positive and a negative side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Skeleton {
    pos: Side,
    neg: Side,
}

impl Skeleton {
    /// From the JSON arrays (negative side as negative numbers).
    pub(crate) fn new(
        material: &'static str,
        e_pd: &[f64],
        e_pf: &[f64],
        e_nd: &[f64],
        e_nf: &[f64],
    ) -> Result<Self, MaterialError> {
        Ok(Skeleton {
            pos: Side::new(material, e_pd, e_pf, 1.0, ("ePd", "ePf"))?,
            neg: Side::new(material, e_nd, e_nf, -1.0, ("eNd", "eNf"))?,
        })
    }

    /// Force and slope at `d`.
    pub(crate) fn eval(&self, d: f64) -> (f64, f64) {
        if d >= 0.0 {
            self.pos.eval(d)
        } else {
            let (f, k) = self.neg.eval(-d);
            (-f, k)
        }
    }

    /// Signed yield deformation of the side `s` (+1 or -1).
    pub(crate) fn dy(&self, s: f64) -> f64 {
        if s > 0.0 {
            self.pos.d[0]
        } else {
            -self.neg.d[0]
        }
    }

    /// Signed yield force of the side `s`.
    pub(crate) fn fy(&self, s: f64) -> f64 {
        if s > 0.0 {
            self.pos.f[0]
        } else {
            -self.neg.f[0]
        }
    }

    /// Elastic stiffness of the side `s` (N/mm).
    pub(crate) fn k0(&self, s: f64) -> f64 {
        self.fy(s) / self.dy(s)
    }
}

/// The state a step of a peak-oriented law (Takeda, Pivot) changes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PeakHistory {
    /// Deformation (mm).
    pub d: f64,
    /// Force (N).
    pub f: f64,
    /// Tangent (N/mm).
    pub k_t: f64,
    /// Largest positive deformation so far (mm, >= the positive yield deformation).
    pub d_max: f64,
    /// Largest negative deformation so far (mm, <= the negative yield deformation).
    pub d_min: f64,
    /// Zero-force crossing of the positive reloading path (mm).
    pub d0_pos: f64,
    /// Zero-force crossing of the negative reloading path (mm).
    pub d0_neg: f64,
}

impl PeakHistory {
    /// Zero deformation and force, excursions at the yield points.
    pub fn virgin(skeleton: &Skeleton) -> Self {
        Self {
            d: 0.0,
            f: 0.0,
            k_t: skeleton.k0(1.0),
            d_max: skeleton.dy(1.0),
            d_min: skeleton.dy(-1.0),
            d0_pos: 0.0,
            d0_neg: 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_and_continues_the_last_slope() {
        let s = Skeleton::new("t", &[1.0, 3.0], &[100.0, 110.0], &[-2.0], &[-50.0]).unwrap();
        assert_eq!(s.eval(0.5), (50.0, 100.0));
        assert_eq!(s.eval(2.0), (105.0, 5.0));
        assert_eq!(s.eval(5.0), (120.0, 5.0));
        assert_eq!(s.eval(-1.0), (-25.0, 25.0));
        assert_eq!(s.eval(-4.0), (-50.0, 0.0));
        assert_eq!((s.dy(-1.0), s.fy(-1.0), s.k0(-1.0)), (-2.0, -50.0, 25.0));
    }

    #[test]
    fn rejects_unsorted_or_wrong_signs() {
        assert!(Skeleton::new("t", &[1.0, 0.5], &[1.0, 2.0], &[-1.0], &[-1.0]).is_err());
        assert!(Skeleton::new("t", &[1.0], &[1.0], &[1.0], &[-1.0]).is_err());
        assert!(Skeleton::new("t", &[], &[], &[-1.0], &[-1.0]).is_err());
    }
}
