//! Space-filling designs on the unit cube, mapped to physical units.
//!
//! Every design is reproducible across platforms: the only randomness is a
//! `ChaCha8Rng` seeded with the study's seed (rand_chacha documents its
//! output as portable), and Owen-scrambled Sobol' points come from
//! `sobol_burley`, a pure function of (index, dimension, seed).

pub mod lhs;
pub mod maximin;
pub mod sobol;

use crate::study::{DesignMethod, Parameter};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// A design: `n` points in `d` dimensions, row-major, each in [0, 1).
#[derive(Debug, Clone, PartialEq)]
pub struct UnitDesign {
    /// Dimension (number of parameters).
    pub d: usize,
    /// Coordinates, `n x d`, row-major.
    pub x: Vec<f64>,
}

impl UnitDesign {
    /// Number of points.
    pub fn n(&self) -> usize {
        self.x.len().checked_div(self.d).unwrap_or(0)
    }

    /// Point `i` as a slice of `d` coordinates.
    pub fn row(&self, i: usize) -> &[f64] {
        &self.x[i * self.d..(i + 1) * self.d]
    }

    /// The points in physical units, one vector per point.
    pub fn to_physical(&self, params: &[Parameter]) -> Vec<Vec<f64>> {
        (0..self.n())
            .map(|i| self.row(i).iter().zip(params).map(|(u, p)| p.from_unit(*u)).collect())
            .collect()
    }
}

/// Draws the design a study asks for.
pub fn draw(method: DesignMethod, n: usize, d: usize, seed: u64) -> UnitDesign {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    match method {
        DesignMethod::Lhs => lhs::latin_hypercube(n, d, &mut rng),
        DesignMethod::MaximinLhs => {
            maximin::maximin_lhs(n, d, &maximin::MaximinSettings::for_size(n, d), &mut rng)
        }
        DesignMethod::Sobol => sobol::scrambled_sobol(n, d, seed as u32 ^ (seed >> 32) as u32),
    }
}

/// Smallest Euclidean distance between any two points.
pub fn min_distance(design: &UnitDesign) -> f64 {
    let n = design.n();
    let mut best = f64::INFINITY;
    for i in 0..n {
        for j in i + 1..n {
            best = best.min(sq_dist(design.row(i), design.row(j)));
        }
    }
    best.sqrt()
}

/// Squared Euclidean distance of two points.
pub fn sq_dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}
