//! Latin hypercube designs on the unit cube, deterministic for a seed.

use rand::seq::SliceRandom;
use rand::{Rng, SeedableRng};

/// `samples` points of a Latin hypercube in `dims` dimensions of the unit cube: along each axis every
/// one of the `samples` equal strata holds exactly one point, at a uniform position inside it. The
/// axes are drawn one after another (a shuffle of the strata, then the positions), seeded by `seed`.
/// Returned per axis: `axes[d][i]` is coordinate d of point i.
pub fn latin_hypercube(samples: usize, dims: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    (0..dims)
        .map(|_| {
            let mut strata: Vec<usize> = (0..samples).collect();
            strata.shuffle(&mut rng);
            strata
                .iter()
                .map(|&s| (s as f64 + rng.random::<f64>()) / samples as f64)
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_stratum_of_every_axis_holds_one_point() {
        let axes = super::latin_hypercube(17, 3, 5);
        for axis in &axes {
            let mut hit = vec![0; 17];
            for &u in axis {
                assert!((0.0..1.0).contains(&u));
                hit[(u * 17.0) as usize] += 1;
            }
            assert!(hit.iter().all(|&h| h == 1), "{hit:?}");
        }
        assert_eq!(axes, super::latin_hypercube(17, 3, 5));
    }
}
