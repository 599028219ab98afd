//! Latin hypercube sampling (McKay, Beckman & Conover 1979): each column
//! holds exactly one point in each of the `n` equal bins of [0, 1).

use super::UnitDesign;
use rand::seq::SliceRandom;
use rand::Rng;

/// A random Latin hypercube: bin permutations, uniform jitter inside bins.
pub fn latin_hypercube<R: Rng>(n: usize, d: usize, rng: &mut R) -> UnitDesign {
    let mut x = vec![0.0; n * d];
    let mut perm: Vec<usize> = (0..n).collect();
    for k in 0..d {
        perm.shuffle(rng);
        for (i, &bin) in perm.iter().enumerate() {
            x[i * d + k] = (bin as f64 + rng.random::<f64>()) / n as f64;
        }
    }
    UnitDesign { d, x }
}

/// True when every column has exactly one point in each of the `n` bins.
pub fn is_latin(design: &UnitDesign) -> bool {
    let n = design.n();
    (0..design.d).all(|k| {
        let mut seen = vec![false; n];
        (0..n).all(|i| {
            let bin = (design.row(i)[k] * n as f64).floor();
            if !(0.0..n as f64).contains(&bin) || seen[bin as usize] {
                return false;
            }
            seen[bin as usize] = true;
            true
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use rand::SeedableRng;

    proptest! {
        #[test]
        fn every_column_is_stratified(n in 2usize..60, d in 1usize..8, seed in any::<u64>()) {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            prop_assert!(is_latin(&latin_hypercube(n, d, &mut rng)));
        }
    }
}
