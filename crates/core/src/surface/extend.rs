//! Seed 003 §10.8's first step for a drape that is not a rectangle (a disc, a skirt): extend its mesh
//! smoothly to the whole rectangle of the grid, so that a tensor-product surface can interpolate it.
//! The missing nodes minimise the sum of squared second differences along the grid lines (a discrete
//! thin plate): the extension is as straight as the present nodes allow and reproduces any affine
//! sheet exactly.

use nalgebra::{DMatrix, DVector, Vector3};

/// The second-difference triples (three consecutive nodes of a grid line) of an `nx` × `ny` grid.
fn triples(nx: usize, ny: usize) -> impl Iterator<Item = [usize; 3]> {
    let along_i = (0..ny).flat_map(move |j| {
        (1..nx.saturating_sub(1)).map(move |i| [j * nx + i - 1, j * nx + i, j * nx + i + 1])
    });
    let along_j = (1..ny.saturating_sub(1))
        .flat_map(move |j| (0..nx).map(move |i| [(j - 1) * nx + i, j * nx + i, (j + 1) * nx + i]));
    along_i.chain(along_j)
}

/// The grid positions `x` (index j·nx + i) with every node that is not `present` replaced by the
/// extension that minimises Σ |x_{k−1} − 2x_k + x_{k+1}|² over all grid lines (a least-squares
/// solve, one Cholesky factorization for the three coordinates). Unchanged when every node is present
/// or none is.
pub fn extend_to_rectangle(
    x: &[Vector3<f64>],
    present: &[bool],
    nx: usize,
    ny: usize,
) -> Vec<Vector3<f64>> {
    let mut out = x[..nx * ny].to_vec();
    let missing: Vec<usize> = (0..nx * ny).filter(|&p| !present[p]).collect();
    if missing.is_empty() || missing.len() == nx * ny {
        return out;
    }
    let mut slot = vec![usize::MAX; nx * ny];
    for (k, &p) in missing.iter().enumerate() {
        slot[p] = k;
    }
    let m = missing.len();
    let mut n = DMatrix::<f64>::zeros(m, m);
    let mut rhs = [DVector::zeros(m), DVector::zeros(m), DVector::zeros(m)];
    const W: [f64; 3] = [1.0, -2.0, 1.0];
    for t in triples(nx, ny) {
        if t.iter().all(|&p| present[p]) {
            continue;
        }
        let known: Vector3<f64> = t
            .iter()
            .zip(W)
            .filter(|(p, _)| present[**p])
            .map(|(p, w)| w * x[*p])
            .sum();
        for (&p, wp) in t.iter().zip(W).filter(|(p, _)| !present[**p]) {
            for (&q, wq) in t.iter().zip(W).filter(|(q, _)| !present[**q]) {
                n[(slot[p], slot[q])] += wp * wq;
            }
            for (c, r) in rhs.iter_mut().enumerate() {
                r[slot[p]] -= wp * known[c];
            }
        }
    }
    // A missing region without enough present neighbours to pin its affine part gets a tiny
    // regularisation towards the origin rather than no answer.
    let chol = n.clone().cholesky().or_else(|| {
        let eps = 1e-10 * n.diagonal().max();
        (n + DMatrix::identity(m, m) * eps).cholesky()
    });
    let Some(chol) = chol else {
        return out;
    };
    let sol = rhs.map(|r| chol.solve(&r));
    for (k, &p) in missing.iter().enumerate() {
        out[p] = Vector3::new(sol[0][k], sol[1][k], sol[2][k]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_affine_sheet_extends_to_the_same_plane() {
        // A tilted plane with only a disc of nodes present: the thin-plate extension of an affine
        // field is that field, corners included.
        let (nx, ny) = (9, 7);
        let f = |i: usize, j: usize| {
            Vector3::new(
                i as f64 * 0.1,
                j as f64 * 0.1,
                0.03 * i as f64 - 0.02 * j as f64,
            )
        };
        let x: Vec<_> = (0..nx * ny).map(|p| f(p % nx, p / nx)).collect();
        let present: Vec<bool> = (0..nx * ny)
            .map(|p| {
                let (i, j) = ((p % nx) as f64 - 4.0, (p / nx) as f64 - 3.0);
                i * i + j * j <= 9.0
            })
            .collect();
        let mut broken = x.clone();
        for (q, p) in broken.iter_mut().zip(&present) {
            if !p {
                *q = Vector3::new(5.0, -3.0, 2.0);
            }
        }
        let e = extend_to_rectangle(&broken, &present, nx, ny);
        let worst = e
            .iter()
            .zip(&x)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        assert!(worst < 1e-9, "{worst}");
    }
}
