//! Sparse symmetric positive-definite solves on the free degrees of freedom (faer's supernodal
//! Cholesky). The symbolic analysis (pattern, ordering, supernodes) of a sparsity structure is done
//! once per process and shared by every solve with that structure — every Newton iteration, and
//! every solve of a calibration population on one grid — and the numeric values are scattered into
//! a buffer kept between factorizations, so an iteration allocates nothing. A set of contact pairs
//! that changes within the structure a solve already holds (self-contact's pairs coming and going,
//! an obstacle's active particles) is mapped into it without a new analysis; one that leaves it
//! grows it to the union.

pub mod dissection;
mod structure;

use crate::physics::HessianBlocks;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::SparseColMatRef;
use faer::sparse::linalg::cholesky::supernodal::factorize_supernodal_numeric_llt;
use faer::sparse::linalg::cholesky::{LltRef, SymbolicCholesky, SymbolicCholeskyRaw};
use faer::{Conj, MatMut, Par};
use std::sync::Arc;
use std::time::Instant;
use structure::Pattern;

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

/// The fill-reducing ordering of a factorization's unknowns (`solver.static.ordering`).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, Default, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum FillOrdering {
    /// Approximate minimum degree (faer's AMD) on the DOFs.
    Amd,
    /// Nested dissection of the free particles' graph ([`dissection`]), a particle's three DOFs
    /// together.
    NestedDissection,
    /// Nested dissection from [`DISSECTION_MIN_PARTICLES`] free particles, AMD below. Default.
    #[default]
    BySize,
}

/// Free particles from which [`FillOrdering::BySize`] orders by nested dissection: beyond every
/// bundled scene and pipeline's sheet (their paths stay AMD's), where it clearly pays. On hang4 it
/// factorizes 1.67× faster than AMD at 321² (103,037 free particles) and 4 % faster at 161²;
/// on the skirt with its contact pairs at 121², as fast as AMD (`cargo bench --bench ordering`,
/// `docs/src/benchmarks.md`).
pub const DISSECTION_MIN_PARTICLES: usize = 25_000;

impl FillOrdering {
    /// Whether a structure over `particles` free particles is ordered by nested dissection.
    pub(super) fn dissects(self, particles: usize) -> bool {
        match self {
            Self::Amd => false,
            Self::NestedDissection => true,
            Self::BySize => particles >= DISSECTION_MIN_PARTICLES,
        }
    }
}

/// The compressed values of a Hessian's constant part on one pattern (held with the part itself,
/// so that the pointer identifies it while the values live).
struct Base {
    constant: Arc<HessianBlocks>,
    pattern: Arc<Pattern>,
    values: Vec<f64>,
}

/// A sparse SPD matrix H + diag(shift) over the free DOFs, assembled from Hessian blocks, factorized
/// with a shared symbolic analysis and numeric buffers kept between calls.
pub struct SparseSpd {
    /// The fill-reducing ordering of its factorizations.
    ordering: FillOrdering,
    pattern: Option<Arc<Pattern>>,
    values: Vec<f64>,
    /// The last assembled matrix's diagonal before its shift (the rest of `values` stays as
    /// assembled: the factorization only reads it), for [`Self::refactorize`]; empty when there
    /// is none.
    unshifted_diagonal: Vec<f64>,
    /// The assembled values of the Hessian's constant part on the current pattern.
    base: Option<Base>,
    /// The factor's values, shared with the copies made of it until one factorizes on its own.
    l_values: Arc<Vec<f64>>,
    mem: MemBuffer,
    /// Whether `mem` holds a numeric factorization's scratch (a copy holds a solve's only).
    factor_scratch: bool,
    /// Number of numeric factorizations done.
    pub factorizations: usize,
    /// Number of triangular solves (back-substitutions) with a factor.
    pub back_substitutions: usize,
    /// Symbolic analyses this solver had to do (0 when every pattern came from the cache).
    pub analyses: usize,
    /// Wall time of those analyses (ordering and symbolic factorization), s.
    pub analysis_time_s: f64,
    /// Wall time spent in numeric factorizations and triangular solves, s.
    pub factor_time_s: f64,
}

impl Default for SparseSpd {
    fn default() -> Self {
        Self::new()
    }
}

impl SparseSpd {
    /// An empty solver ([`FillOrdering::BySize`]); the pattern is looked up at the first
    /// factorization.
    pub fn new() -> Self {
        Self::with_ordering(FillOrdering::default())
    }

    /// An empty solver whose factorizations use `ordering`.
    pub fn with_ordering(ordering: FillOrdering) -> Self {
        Self {
            ordering,
            pattern: None,
            values: Vec::new(),
            unshifted_diagonal: Vec::new(),
            base: None,
            l_values: Arc::new(Vec::new()),
            mem: MemBuffer::new(StackReq::empty()),
            factor_scratch: false,
            factorizations: 0,
            back_substitutions: 0,
            analyses: 0,
            analysis_time_s: 0.0,
            factor_time_s: 0.0,
        }
    }

    /// Whether a factorization has been made (or copied in) to solve with.
    pub fn has_factor(&self) -> bool {
        self.pattern.is_some()
    }

    /// A copy of the last factorization (no counts), for another solve to precondition its steps
    /// with. The factor's values are shared, not copied (a copy that factorizes gets its own), and
    /// the scratch is a solve's: a calibration evaluation copies its lattice node's factor and, as a
    /// rule, never factorizes (copying the values and a factorization's scratch was 4 % of the main
    /// job's calibrate stage).
    pub fn copy(&self) -> Self {
        let mut out = Self::with_ordering(self.ordering);
        if let Some(pattern) = &self.pattern {
            let symbolic = &pattern.structure.symbolic;
            out.mem = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
            out.pattern = Some(pattern.clone());
            out.l_values = self.l_values.clone();
        }
        out
    }

    /// A factorization's scratch, numeric buffers and own values for `symbolic`.
    fn prepare_buffers(&mut self, symbolic: &SymbolicCholesky<usize>, nnz: usize) {
        self.mem = MemBuffer::new(StackReq::any_of(&[
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]));
        self.factor_scratch = true;
        self.l_values = Arc::new(vec![0.0; symbolic.len_val()]);
        self.values = vec![0.0; nnz];
    }

    /// Adds the lower-triangle entries of `h`'s own list over the free DOFs (not its constant
    /// part) into `values` at their slots (`slot`, one per entry in this order: per block its
    /// rows, then columns, the lower triangle of a diagonal block); the number of entries.
    fn scatter(dofs: &DofMap, h: &HessianBlocks, slot: &[u32], values: &mut [f64]) -> usize {
        /// (row, column) of a diagonal block's lower triangle, in the order of the slots.
        const LOWER: [(usize, usize); 6] = [(0, 0), (1, 0), (1, 1), (2, 0), (2, 1), (2, 2)];
        let mut e = 0;
        for (&(p, q), b) in h.pairs.iter().zip(&h.blocks) {
            if dofs.dof(p as usize).is_none() || dofs.dof(q as usize).is_none() {
                continue;
            }
            // Lower triangle: row ≥ column (dp ≥ dq when p > q, as DOFs follow particles).
            if p != q {
                let s = &slot[e..e + 9];
                for r in 0..3 {
                    for c in 0..3 {
                        values[s[3 * r + c] as usize] += b[(r, c)];
                    }
                }
                e += 9;
            } else {
                let s = &slot[e..e + 6];
                for (k, &(r, c)) in LOWER.iter().enumerate() {
                    values[s[k] as usize] += b[(r, c)];
                }
                e += 6;
            }
        }
        e
    }

    /// Factorizes H + diag(shift) over the free DOFs. Returns false when the matrix is not
    /// positive definite (the caller raises its damping or projects the Hessian and tries again).
    pub fn factorize(&mut self, dofs: &DofMap, h: &HessianBlocks, shift: &[f64]) -> bool {
        self.unshifted_diagonal.clear();
        let Some(pattern) = self.pattern_for(dofs, h) else {
            return false;
        };
        if !self.factor_scratch || Arc::strong_count(&self.l_values) > 1 {
            // A copy factorizing on its own: its own values and scratch, the shared factor untouched.
            let nnz = pattern.structure.sym.row_idx().len();
            self.prepare_buffers(&pattern.structure.symbolic, nnz);
        }
        let start = Instant::now();
        // Every entry added straight into its slot (a gather through a buffer of the raw entries,
        // several MB on a 2,700-vertex disc, was a fifth of a Cusick drape's solve).
        let (values, slot) = (&mut self.values, &pattern.slot);
        // The pattern was mapped from these very pairs over these DOFs: one slot per entry, then n.
        if shift.len() != dofs.n || slot.len() < dofs.n {
            return false;
        }
        // The constant part's values once per model and pattern, copied in at every factorization.
        let base_holds = |b: &Base| {
            Arc::ptr_eq(&b.pattern, &pattern)
                && h.constant
                    .as_ref()
                    .is_some_and(|c| Arc::ptr_eq(&b.constant, c))
        };
        match (&self.base, &h.constant) {
            (Some(b), _) if base_holds(b) => values.copy_from_slice(&b.values),
            (_, Some(c)) => {
                values.fill(0.0);
                Self::scatter(dofs, c, slot, values);
                self.base = Some(Base {
                    constant: c.clone(),
                    pattern: pattern.clone(),
                    values: values.clone(),
                });
            }
            (_, None) => values.fill(0.0),
        }
        let e = pattern.constant_entries;
        let e = e + Self::scatter(dofs, h, &slot[e..], values);
        debug_assert_eq!(e + dofs.n, slot.len());
        let diagonal = slot[slot.len() - dofs.n..].iter();
        self.unshifted_diagonal = diagonal.map(|&s| values[s as usize]).collect();
        self.factorize_shifted(&pattern, shift, start)
    }

    /// Factorizes the matrix the last [`Self::factorize`] assembled with another `shift` (H itself
    /// unchanged: a failed attempt's next damping): the same values, bit for bit, without
    /// scattering the Hessian's entries again. Whether it is positive definite; None when no
    /// assembled matrix is held (the last assembly failed, or none was made).
    pub fn refactorize(&mut self, shift: &[f64]) -> Option<bool> {
        let pattern = self.pattern.clone()?;
        let held = self.factor_scratch && !self.unshifted_diagonal.is_empty();
        if !held || shift.len() != self.unshifted_diagonal.len() {
            return None;
        }
        let start = Instant::now();
        let diagonal = &pattern.slot[pattern.slot.len() - shift.len()..];
        for (&s, &v) in diagonal.iter().zip(&self.unshifted_diagonal) {
            self.values[s as usize] = v;
        }
        Some(self.factorize_shifted(&pattern, shift, start))
    }

    /// Adds `shift` to the diagonal of the assembled values and factorizes them numerically.
    fn factorize_shifted(&mut self, pattern: &Pattern, shift: &[f64], start: Instant) -> bool {
        let values = &mut self.values;
        let diagonal = &pattern.slot[pattern.slot.len() - shift.len()..];
        for (&s, &v) in diagonal.iter().zip(shift) {
            values[s as usize] += v;
        }
        let structure = &pattern.structure;
        let SymbolicCholeskyRaw::Supernodal(supernodal) = structure.symbolic.raw() else {
            return false;
        };
        let mat = SparseColMatRef::new(structure.permuted.as_ref(), values);
        self.factorizations += 1;
        let l_values = Arc::make_mut(&mut self.l_values);
        let ok = factorize_supernodal_numeric_llt(
            l_values,
            mat,
            LltRegularization::default(),
            supernodal,
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        )
        .is_ok();
        self.factor_time_s += start.elapsed().as_secs_f64();
        ok
    }

    /// The pattern of `h` over `dofs`: the one held while it holds them, else the next one (from
    /// the process's cache, or analysed), its buffers prepared. None when no pattern maps them.
    fn pattern_for(&mut self, dofs: &DofMap, h: &HessianBlocks) -> Option<Arc<Pattern>> {
        let stale = self.pattern.as_ref().is_none_or(|p| !p.holds(dofs, h));
        if stale {
            let start = Instant::now();
            let (pattern, analysed) = Pattern::next(dofs, h, self.pattern.as_ref(), self.ordering)?;
            self.analyses += usize::from(analysed);
            let same_structure = self
                .pattern
                .as_ref()
                .is_some_and(|p| Arc::ptr_eq(&p.structure, &pattern.structure));
            if !same_structure {
                let nnz = pattern.structure.sym.row_idx().len();
                self.prepare_buffers(&pattern.structure.symbolic, nnz);
            }
            self.pattern = Some(pattern);
            self.analysis_time_s += start.elapsed().as_secs_f64();
        }
        self.pattern.clone()
    }

    /// Non-zeros of the last factorization's Cholesky factor (0 before the first).
    pub fn factor_nonzeros(&self) -> usize {
        self.pattern
            .as_ref()
            .map_or(0, |p| p.structure.symbolic.len_val())
    }

    /// Solves (H + diag(shift)) y = rhs in place with the last successful factorization.
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) {
        let n = rhs.len();
        let Some(pattern) = self.pattern.as_ref() else {
            return;
        };
        let start = Instant::now();
        self.back_substitutions += 1;
        let llt = LltRef::new(&pattern.structure.symbolic, &self.l_values);
        llt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, n, 1),
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
        self.factor_time_s += start.elapsed().as_secs_f64();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, Vector3};

    /// A chain of `n` free particles, each coupled to the next, plus the extra blocks `extra`
    /// (p > q): an SPD matrix (diagonally dominant).
    fn chain(n: usize, extra: &[(usize, usize)]) -> HessianBlocks {
        let mut h = HessianBlocks::default();
        for p in 0..n {
            h.push(p, p, Matrix3::identity() * 10.0);
            if p > 0 {
                h.push(p, p - 1, Matrix3::identity() * -1.0);
            }
        }
        for &(p, q) in extra {
            h.push(p, q, Matrix3::from_diagonal_element(0.5));
        }
        h
    }

    fn solve(spd: &mut SparseSpd, dofs: &DofMap, h: &HessianBlocks) -> Vec<f64> {
        assert!(spd.factorize(dofs, h, &vec![0.0; dofs.n]));
        let mut x: Vec<f64> = (0..dofs.n).map(|k| (k as f64 * 0.7).sin()).collect();
        spd.solve_in_place(&mut x);
        x
    }

    /// An m × m grid of particles, each coupled to its neighbours along the lines and diagonals
    /// and to the particles two away (a cloth's stretch, shear and bending stencil): SPD.
    fn sheet(m: usize) -> HessianBlocks {
        let mut h = HessianBlocks::default();
        let couple = |(di, dj): (usize, usize)| {
            (0..m * m).filter_map(move |p| {
                let (i, j) = (p / m + di, p % m + dj);
                (i < m && j < m).then_some((i * m + j, p))
            })
        };
        for p in 0..m * m {
            h.push(
                p,
                p,
                Matrix3::new(14.0, 0.3, 0.0, 0.3, 14.0, 0.1, 0.0, 0.1, 14.0),
            );
        }
        for step in [(0, 1), (1, 0), (1, 1), (0, 2), (2, 0)] {
            for (p, q) in couple(step) {
                h.push(p, q, Matrix3::from_diagonal_element(-0.9));
            }
        }
        h
    }

    #[test]
    fn nested_dissection_and_amd_solve_the_same_sheet_and_by_size_keeps_amd_below_its_threshold() {
        let m = 60;
        let dofs = DofMap::new(&vec![false; m * m]);
        let h = sheet(m);
        let (mut amd, mut nd) = (
            SparseSpd::with_ordering(FillOrdering::Amd),
            SparseSpd::with_ordering(FillOrdering::NestedDissection),
        );
        let (ya, yn) = (solve(&mut amd, &dofs, &h), solve(&mut nd, &dofs, &h));
        let scale = ya.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let gap = ya
            .iter()
            .zip(&yn)
            .fold(0.0f64, |a, (u, v)| a.max((u - v).abs()));
        assert!(
            gap <= 1e-12 * scale,
            "solutions {gap:e} apart (scale {scale:e})"
        );
        // The product H y reproduces the right-hand side through the dissected factor.
        let y: Vec<Vector3<f64>> = yn.chunks(3).map(Vector3::from_column_slice).collect();
        let mut hy = vec![Vector3::zeros(); m * m];
        h.mul_add(&y, &mut hy);
        for (k, v) in hy.iter().flat_map(|v| v.iter()).enumerate() {
            assert!((v - (k as f64 * 0.7).sin()).abs() < 1e-10);
        }
        // By size: AMD below the threshold, the dissection's factor at and above it.
        let mut by_size = SparseSpd::new();
        solve(&mut by_size, &dofs, &h);
        assert!(m * m < DISSECTION_MIN_PARTICLES);
        assert_eq!(by_size.factor_nonzeros(), amd.factor_nonzeros());
        assert_ne!(nd.factor_nonzeros(), amd.factor_nonzeros());
    }

    #[test]
    fn a_copy_solves_with_the_shared_factor_and_a_copy_that_factorizes_leaves_it_untouched() {
        let n = 30;
        let dofs = DofMap::new(&vec![false; n]);
        let (a, b) = (chain(n, &[]), chain(n, &[(20, 4)]));
        let mut original = SparseSpd::new();
        let ya = solve(&mut original, &dofs, &a);
        let rhs: Vec<f64> = (0..dofs.n).map(|k| (k as f64 * 0.7).sin()).collect();
        let solve_only = |spd: &mut SparseSpd| {
            let mut y = rhs.clone();
            spd.solve_in_place(&mut y);
            y
        };
        let mut copy = original.copy();
        assert_eq!(solve_only(&mut copy), ya);
        // The copy factorizes another matrix: its solves are that matrix's, the original's (and
        // a second copy's) still the first matrix's.
        let mut second = original.copy();
        let yb = solve(&mut copy, &dofs, &b);
        assert_eq!(yb, solve(&mut SparseSpd::new(), &dofs, &b));
        assert_ne!(yb, ya);
        assert_eq!(solve_only(&mut original), ya);
        assert_eq!(solve_only(&mut second), ya);
        // And the original factorizing again leaves the second copy's factor as it was.
        solve(&mut original, &dofs, &b);
        assert_eq!(solve_only(&mut second), ya);
    }

    #[test]
    fn a_contact_set_that_changes_within_the_structure_needs_no_new_analysis() {
        // Contact blocks that come and go (self-contact's pairs): the first new block grows the
        // structure to the union, after which the pairs may come and go without an analysis; every
        // solve equals the solve on the matrix's own structure.
        let n = 40;
        let dofs = DofMap::new(&vec![false; n]);
        let (plain, touching) = (chain(n, &[]), chain(n, &[(30, 3), (25, 7)]));
        let mut spd = SparseSpd::new();
        let fresh = |h: &HessianBlocks| solve(&mut SparseSpd::new(), &dofs, h);
        let mut seen = Vec::new();
        for h in [&plain, &touching, &plain, &touching, &plain] {
            let y = solve(&mut spd, &dofs, h);
            let want = fresh(h);
            let err = y
                .iter()
                .zip(&want)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-14, "{err}");
            seen.push(spd.analyses);
        }
        // Analysed at most for the plain chain and the union; then nothing (whatever other tests
        // left in the process-wide cache, no more than two).
        assert!(seen[4] <= 2 && seen[4] == seen[1], "{seen:?}");
        // The same sequence in another solver gives the same bits.
        let mut other = SparseSpd::new();
        for h in [&plain, &touching, &plain] {
            solve(&mut other, &dofs, h);
        }
        let (a, b) = (
            solve(&mut spd, &dofs, &touching),
            solve(&mut other, &dofs, &touching),
        );
        assert_eq!(a, b);
    }

    #[test]
    fn a_contact_set_growing_into_its_hinted_blocks_needs_no_new_analysis() {
        // The first contact block forces an analysis, which takes in the hinted blocks; the pairs
        // then appear without another, and every solve equals the solve on its own structure.
        let n = 44;
        let dofs = DofMap::new(&vec![false; n]);
        let mut first = chain(n, &[(30, 3)]);
        first.hints = vec![(25, 7), (26, 8), (40, 1)];
        let later = [
            chain(n, &[(30, 3), (25, 7)]),
            chain(n, &[(26, 8), (40, 1), (30, 3)]),
        ];
        let mut spd = SparseSpd::new();
        solve(&mut spd, &dofs, &chain(n, &[]));
        let before = spd.analyses;
        let close = |y: &[f64], want: &[f64]| {
            let err = y
                .iter()
                .zip(want)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(err < 1e-14, "{err}");
        };
        let y = solve(&mut spd, &dofs, &first);
        close(&y, &solve(&mut SparseSpd::new(), &dofs, &first));
        assert_eq!(spd.analyses, before + 1);
        for h in &later {
            close(
                &solve(&mut spd, &dofs, h),
                &solve(&mut SparseSpd::new(), &dofs, h),
            );
        }
        assert_eq!(
            spd.analyses,
            before + 1,
            "the hinted blocks were in the structure"
        );
        let holds = |spd: &SparseSpd, b| {
            let s = &spd.pattern.as_ref().expect("a pattern").structure;
            s.blocks.binary_search(&b).is_ok()
        };
        assert!(holds(&spd, (40, 1)));
        // Without the hints the structure grows by the contact block alone.
        let mut plain = SparseSpd::new();
        solve(&mut plain, &dofs, &chain(n, &[]));
        solve(&mut plain, &dofs, &chain(n, &[(30, 3)]));
        assert!(holds(&plain, (30, 3)) && !holds(&plain, (25, 7)));
    }

    /// The (row, column) of every lower-triangle entry of `h`'s own list over the free DOFs, in
    /// the order [`SparseSpd::scatter`] adds them.
    fn entries(dofs: &DofMap, h: &HessianBlocks, mut visit: impl FnMut(usize, usize)) {
        for &(p, q) in &h.pairs {
            let (Some(dp), Some(dq)) = (dofs.dof(p as usize), dofs.dof(q as usize)) else {
                continue;
            };
            for r in 0..3 {
                for c in 0..3 {
                    if p != q || r >= c {
                        visit(dp + r, dq + c);
                    }
                }
            }
        }
    }

    #[test]
    fn a_new_shift_of_the_assembled_matrix_factorizes_as_a_fresh_assembly_does() {
        let n = 12;
        let dofs = DofMap::new(&vec![false; n]);
        let h = chain(n, &[(9, 2)]);
        let (low, high) = (vec![-50.0; dofs.n], vec![0.5; dofs.n]);
        // A shift that makes the matrix indefinite fails; the next one, on the same values, holds.
        let mut again = SparseSpd::new();
        assert!(!again.factorize(&dofs, &h, &low));
        assert_eq!(again.refactorize(&high), Some(true));
        let mut fresh = SparseSpd::new();
        assert!(fresh.factorize(&dofs, &h, &high));
        let rhs: Vec<f64> = (0..dofs.n).map(|k| (k as f64 * 0.37).sin()).collect();
        let (mut a, mut b) = (rhs.clone(), rhs);
        again.solve_in_place(&mut a);
        fresh.solve_in_place(&mut b);
        assert_eq!(a, b, "bit for bit");
        assert_eq!(again.refactorize(&low), Some(false));
        // Nothing assembled (a pattern that could not be found, or a copy): no refactorization.
        let mut copy = fresh.copy();
        assert_eq!(copy.refactorize(&high), None);
        assert!(!copy.factorize(&dofs, &h, &high[1..]));
        assert_eq!(copy.refactorize(&high), None);
    }

    #[test]
    fn a_pattern_extended_from_the_last_one_has_the_slots_a_fresh_mapping_gives() {
        // Particle 5 held (its blocks are not entries); the contact blocks after the chain's change,
        // one of them diagonal, one of them the held particle's.
        let n = 24;
        let mut fixed = vec![false; n];
        fixed[5] = true;
        let dofs = DofMap::new(&fixed);
        let with = |extra: &[(usize, usize)]| {
            let mut h = chain(n, &[(20, 2), (17, 9)]);
            for &(p, q) in extra {
                h.push(p, q, Matrix3::from_diagonal_element(0.25));
            }
            h
        };
        let all = with(&[(15, 1), (22, 11), (12, 12), (18, 5)]);
        let (first, next) = (
            with(&[(15, 1), (12, 12)]),
            with(&[(22, 11), (18, 5), (12, 12)]),
        );
        let (whole, _) = Pattern::exact(&dofs, &all, FillOrdering::default()).expect("a structure");
        let last = Pattern::map(&dofs, &first, whole.structure.clone());
        let extended = Pattern::extend(&last, &dofs, &next).expect("within the structure");
        let fresh = Pattern::map(&dofs, &next, whole.structure.clone());
        assert_eq!(extended.slot, fresh.slot);
        // Each entry's slot is its own position in the structure (one search per entry).
        let s = &whole.structure;
        let mut want = Vec::new();
        entries(&dofs, &next, |r, c| want.push(s.position(r, c)));
        want.extend((0..dofs.n).map(|d| s.position(d, d)));
        assert_eq!(fresh.slot, want);
        assert_eq!(extended.constant_entries, fresh.constant_entries);
        // A block outside the structure: no extension.
        assert!(Pattern::extend(&last, &dofs, &with(&[(23, 0)])).is_none());
    }
}
