//! The Taguchi L27(3^13) orthogonal array (seed 000 Table 1 uses 7 of its columns) and the
//! smaller-the-better signal-to-noise ratio.

/// The 27 runs × 13 columns of L27, levels 0, 1, 2.
pub type L27 = [[u8; 13]; 27];

/// L27 built over GF(3): run r = (a, b, c) in base 3, column k = ⟨(a, b, c), v_k⟩ mod 3 for the 13
/// points v_k of the projective plane PG(2, 3) in the standard column order. Any two columns hold
/// every pair of levels exactly three times (strength 2).
pub fn l27() -> L27 {
    const V: [[u8; 3]; 13] = [
        [1, 0, 0],
        [0, 1, 0],
        [1, 1, 0],
        [1, 2, 0],
        [0, 0, 1],
        [1, 0, 1],
        [1, 0, 2],
        [0, 1, 1],
        [1, 1, 1],
        [1, 2, 2],
        [0, 1, 2],
        [1, 2, 1],
        [1, 1, 2],
    ];
    let mut t = [[0u8; 13]; 27];
    for (r, row) in t.iter_mut().enumerate() {
        let x = [(r / 9) as u8, ((r / 3) % 3) as u8, (r % 3) as u8];
        for (k, v) in V.iter().enumerate() {
            row[k] = (x[0] * v[0] + x[1] * v[1] + x[2] * v[2]) % 3;
        }
    }
    t
}

/// Smaller-the-better S/N ratio in dB: −10 log10(mean(y²)).
pub fn sn_smaller_the_better(ys: &[f64]) -> f64 {
    let m = ys.iter().map(|y| y * y).sum::<f64>() / ys.len().max(1) as f64;
    -10.0 * m.log10()
}

/// Mean S/N of each level (0, 1, 2) of each factor, for runs whose factor levels are `levels[run][factor]`.
pub fn main_effects(levels: &[Vec<u8>], sn: &[f64]) -> Vec<[f64; 3]> {
    let nf = levels.first().map_or(0, |l| l.len());
    (0..nf)
        .map(|f| {
            let mut sum = [0.0; 3];
            let mut cnt = [0usize; 3];
            for (l, s) in levels.iter().zip(sn) {
                sum[l[f] as usize] += s;
                cnt[l[f] as usize] += 1;
            }
            [0, 1, 2].map(|k| {
                if cnt[k] > 0 {
                    sum[k] / cnt[k] as f64
                } else {
                    f64::NAN
                }
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn l27_is_orthogonal() {
        let t = l27();
        for a in 0..13 {
            for b in 0..13 {
                if a == b {
                    continue;
                }
                let mut count = [[0; 3]; 3];
                for row in &t {
                    count[row[a] as usize][row[b] as usize] += 1;
                }
                assert!(
                    count.iter().flatten().all(|&c| c == 3),
                    "columns {a}, {b}: {count:?}"
                );
            }
        }
    }

    #[test]
    fn sn_and_main_effects() {
        assert!((sn_smaller_the_better(&[0.1, 0.1]) - 20.0).abs() < 1e-12);
        let levels = vec![vec![0u8], vec![1], vec![2], vec![0]];
        let me = main_effects(&levels, &[1.0, 2.0, 3.0, 3.0]);
        assert_eq!(me[0], [2.0, 2.0, 3.0]);
    }
}
