//! Sparse symmetric positive-definite solves on the free degrees of freedom (faer's supernodal
//! Cholesky, with the symbolic analysis done once per sparsity pattern).

use crate::physics::HessianBlocks;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymmetricOrdering,
    factorize_symbolic_cholesky,
};
use faer::sparse::{Argsort, Pair, SparseColMat, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side};

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

/// A sparse SPD matrix H + diag(shift) over the free DOFs, assembled from Hessian blocks, with the
/// pattern, its symbolic supernodal Cholesky and the numeric buffers kept between calls.
pub struct SparseSpd {
    pattern_pairs: Vec<(u32, u32)>,
    symbolic: Option<(
        SymbolicSparseColMat<usize>,
        Argsort<usize>,
        SymbolicCholesky<usize>,
    )>,
    values: Vec<f64>,
    l_values: Vec<f64>,
    mem: MemBuffer,
    /// Number of numeric factorizations done.
    pub factorizations: usize,
}

impl Default for SparseSpd {
    fn default() -> Self {
        Self::new()
    }
}

impl SparseSpd {
    /// An empty solver; the pattern is analysed (AMD ordering, supernodal) at the first factorization.
    pub fn new() -> Self {
        Self {
            pattern_pairs: Vec::new(),
            symbolic: None,
            values: Vec::new(),
            l_values: Vec::new(),
            mem: MemBuffer::new(StackReq::empty()),
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
                        // Lower triangle: row ≥ column (dp ≥ dq when p > q, as DOFs follow particles).
                        visit(dp + r, dq + c, b[(r, c)]);
                    }
                }
            }
        }
    }

    /// Factorizes H + diag(shift) over the free DOFs. Returns false when the matrix is not
    /// positive definite (the caller raises its damping and tries again).
    pub fn factorize(&mut self, dofs: &DofMap, h: &HessianBlocks, shift: &[f64]) -> bool {
        let n = dofs.n;
        if self.symbolic.is_none() || h.pairs != self.pattern_pairs {
            let mut idx: Vec<Pair<usize, usize>> = Vec::new();
            Self::entries(dofs, h, |r, c, _| idx.push(Pair::new(r, c)));
            idx.extend((0..n).map(|d| Pair::new(d, d)));
            let Ok((sym, argsort)) = SymbolicSparseColMat::try_new_from_indices(n, n, &idx) else {
                return false;
            };
            let params = CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            };
            let Ok(symbolic) = factorize_symbolic_cholesky(
                sym.as_ref(),
                Side::Lower,
                SymmetricOrdering::Amd,
                params,
            ) else {
                return false;
            };
            self.mem = MemBuffer::new(StackReq::any_of(&[
                symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
                symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
            ]));
            self.l_values = vec![0.0; symbolic.len_val()];
            self.symbolic = Some((sym, argsort, symbolic));
            self.pattern_pairs = h.pairs.clone();
        }
        self.values.clear();
        let values = &mut self.values;
        Self::entries(dofs, h, |_, _, v| values.push(v));
        values.extend_from_slice(shift);
        let Some((sym, argsort, symbolic)) = self.symbolic.as_ref() else {
            return false;
        };
        let Ok(mat) = SparseColMat::new_from_argsort(sym.clone(), argsort, &self.values) else {
            return false;
        };
        self.factorizations += 1;
        symbolic
            .factorize_numeric_llt(
                &mut self.l_values,
                mat.as_ref(),
                Side::Lower,
                LltRegularization::default(),
                Par::Seq,
                MemStack::new(&mut self.mem),
                Default::default(),
            )
            .is_ok()
    }

    /// Solves (H + diag(shift)) y = rhs in place with the last successful factorization.
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) {
        let n = rhs.len();
        let Some((_, _, symbolic)) = self.symbolic.as_ref() else {
            return;
        };
        let llt = LltRef::new(symbolic, &self.l_values);
        llt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, n, 1),
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
    }
}
