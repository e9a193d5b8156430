//! Sparse symmetric positive-definite solves on the free degrees of freedom (faer's supernodal
//! Cholesky, with the symbolic analysis done once per sparsity pattern).

use crate::physics::HessianBlocks;
use faer::Par;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{Argsort, Pair, SparseColMat, SymbolicSparseColMat};
use faer::{MatMut, Side};

/// Map from particles to free degrees of freedom (3 per free particle).
#[derive(Debug, Clone)]
pub struct DofMap {
    /// First DOF of each particle, `u32::MAX` for fixed particles.
    pub first: Vec<u32>,
    /// Number of free DOFs.
    pub n: usize,
}

impl DofMap {
    /// DOFs of the particles whose `fixed` flag is false.
    pub fn new(fixed: &[bool]) -> Self {
        let mut first = Vec::with_capacity(fixed.len());
        let mut n = 0u32;
        for &f in fixed {
            if f {
                first.push(u32::MAX);
            } else {
                first.push(n);
                n += 3;
            }
        }
        Self {
            first,
            n: n as usize,
        }
    }
    /// First DOF of particle p, if free.
    #[inline]
    pub fn dof(&self, p: usize) -> Option<usize> {
        let d = self.first[p];
        (d != u32::MAX).then_some(d as usize)
    }
}

/// A sparse SPD matrix H + shift·D over the free DOFs, assembled from Hessian blocks, with the
/// pattern and its symbolic Cholesky kept between calls.
pub struct SparseSpd {
    pattern_pairs: Vec<(u32, u32)>,
    symbolic: Option<(
        SymbolicSparseColMat<usize>,
        Argsort<usize>,
        SymbolicLlt<usize>,
    )>,
    values: Vec<f64>,
    /// Number of numeric factorizations done.
    pub factorizations: usize,
}

impl Default for SparseSpd {
    fn default() -> Self {
        Self::new()
    }
}

impl SparseSpd {
    /// An empty solver; the pattern is analysed at the first factorization.
    pub fn new() -> Self {
        faer::set_global_parallelism(Par::Seq);
        Self {
            pattern_pairs: Vec::new(),
            symbolic: None,
            values: Vec::new(),
            factorizations: 0,
        }
    }

    fn entries(dofs: &DofMap, h: &HessianBlocks, mut visit: impl FnMut(usize, usize, f64)) {
        for (&(p, q), b) in h.pairs.iter().zip(&h.blocks) {
            let (Some(dp), Some(dq)) = (dofs.dof(p as usize), dofs.dof(q as usize)) else {
                continue;
            };
            for r in 0..3 {
                for c in 0..3 {
                    if p != q || r >= c {
                        visit(dp + r, dq + c, b[(r, c)]);
                    }
                }
            }
        }
    }

    /// Factorizes H + diag(shift) over the free DOFs. Returns None when the matrix is not
    /// positive definite (the caller raises its damping and tries again).
    pub fn factorize(
        &mut self,
        dofs: &DofMap,
        h: &HessianBlocks,
        shift: &[f64],
    ) -> Option<Llt<usize, f64>> {
        let n = dofs.n;
        if self.symbolic.is_none() || h.pairs != self.pattern_pairs {
            let mut idx: Vec<Pair<usize, usize>> = Vec::new();
            Self::entries(dofs, h, |r, c, _| idx.push(Pair::new(r, c)));
            idx.extend((0..n).map(|d| Pair::new(d, d)));
            let (sym, argsort) = SymbolicSparseColMat::try_new_from_indices(n, n, &idx).ok()?;
            let llt = SymbolicLlt::try_new(sym.as_ref(), Side::Lower).ok()?;
            self.symbolic = Some((sym, argsort, llt));
            self.pattern_pairs = h.pairs.clone();
        }
        self.values.clear();
        let values = &mut self.values;
        Self::entries(dofs, h, |_, _, v| values.push(v));
        values.extend_from_slice(shift);
        let (sym, argsort, llt) = self.symbolic.as_ref()?;
        let mat = SparseColMat::new_from_argsort(sym.clone(), argsort, &self.values).ok()?;
        self.factorizations += 1;
        Llt::try_new_with_symbolic(llt.clone(), mat.as_ref(), Side::Lower).ok()
    }
}

/// Solves L Lᵀ y = rhs in place.
pub fn solve_in_place(llt: &Llt<usize, f64>, rhs: &mut [f64]) {
    let n = rhs.len();
    let m = MatMut::from_column_major_slice_mut(rhs, n, 1);
    llt.solve_in_place(m);
}
