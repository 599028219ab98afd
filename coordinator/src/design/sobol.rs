//! Owen-scrambled Sobol' points (Joe–Kuo direction numbers, hash-based
//! Owen scrambling as in Burley 2020), via `sobol_burley`; up to 256
//! dimensions, 2^32 points, 24-bit resolution per coordinate.

use super::UnitDesign;

/// Largest dimension the sequence supports.
pub const MAX_DIMENSION: usize = sobol_burley::NUM_DIMENSIONS as usize;

/// The first `n` scrambled Sobol' points in `d` dimensions.
pub fn scrambled_sobol(n: usize, d: usize, seed: u32) -> UnitDesign {
    let mut x = Vec::with_capacity(n * d);
    for i in 0..n {
        for k in 0..d {
            x.push(sobol_burley::sample(i as u32, k as u32, seed) as f64);
        }
    }
    UnitDesign { d, x }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_power_of_two_is_stratified_per_column() {
        // A (0, m, s)-net property in each column: 2^m points fill 2^m bins once.
        let design = scrambled_sobol(64, 5, 7);
        assert!(crate::design::lhs::is_latin(&design));
    }

    #[test]
    fn seed_changes_points() {
        assert_ne!(scrambled_sobol(8, 2, 1), scrambled_sobol(8, 2, 2));
    }
}
