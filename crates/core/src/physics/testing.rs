//! Sheets the terms' unit tests share.

/// A grid of `n` × `n` vertices, spacing h, split along one diagonal or alternating ones.
pub fn grid(n: usize, h: f64, alternate: bool) -> (Vec<[f64; 2]>, Vec<[usize; 3]>) {
    let rest = (0..n * n)
        .map(|k| [(k % n) as f64 * h, (k / n) as f64 * h])
        .collect();
    let mut tris = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let (a, b, c, d) = (
                j * n + i,
                j * n + i + 1,
                (j + 1) * n + i + 1,
                (j + 1) * n + i,
            );
            if alternate && (i + j) % 2 == 1 {
                tris.extend([[a, b, d], [b, c, d]]);
            } else {
                tris.extend([[a, b, c], [a, c, d]]);
            }
        }
    }
    (rest, tris)
}
