//! Sparsity structures of the free Hessian and their symbolic analyses, shared per process: a
//! structure's pattern (ordering, supernodes, the map from Hessian blocks into compressed values),
//! a solve's structure grown to a superset when its contact pairs leave it.

use super::{DofMap, FillOrdering};
use crate::physics::HessianBlocks;
use faer::Side;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::perm::PermRef;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::utils::permute_self_adjoint_to_unsorted;
use faer::sparse::{Pair, SparseColMatRef, SymbolicSparseColMat};
use std::hash::{Hash, Hasher};
use std::sync::{Arc, Mutex};

/// A sparsity structure analysed once: the lower triangle over the free DOFs of a set of particle
/// blocks, and its symbolic Cholesky factorization (ordering, supernodes).
pub(super) struct Structure {
    pub(super) first: Vec<u32>,
    /// The fill-reducing ordering asked for.
    pub(super) ordering: FillOrdering,
    /// The particle blocks (p ≥ q) it holds, sorted and unique.
    pub(super) blocks: Vec<(u32, u32)>,
    pub(super) sym: SymbolicSparseColMat<usize>,
    pub(super) symbolic: SymbolicCholesky<usize>,
    /// The lower triangle in the fill-reducing order, as faer's supernodal factorization reads it
    /// (columns unsorted), and where each entry of `sym` lands in it: the values are assembled
    /// there directly, so a factorization does not permute the matrix (8 % of a Cusick drape's solve).
    pub(super) permuted: SymbolicSparseColMat<usize>,
    pub(super) to_permuted: Vec<u32>,
}

/// The structures analysed so far in this process, by their blocks (a handful: one per grid and
/// pin set, and the self-contact patterns a solve grew).
static STRUCTURES: Mutex<Vec<(u64, Arc<Structure>)>> = Mutex::new(Vec::new());
/// Structures kept at most; the oldest is dropped beyond.
const MAX_STRUCTURES: usize = 64;

/// A structure that holds more blocks than this times those of the Hessian at hand is analysed
/// afresh for that Hessian when a new block forces an analysis anyway (its fill would cost more
/// than the analyses it saves).
const MAX_SUPERSET: f64 = 1.25;

/// A permutation of the DOFs: the DOF eliminated k-th (`forward`), each DOF's place (`inverse`).
struct DofOrder {
    forward: Vec<usize>,
    inverse: Vec<usize>,
}

fn structure_key(first: &[u32], blocks: &[(u32, u32)], ordering: FillOrdering) -> u64 {
    let mut s = std::collections::hash_map::DefaultHasher::new();
    ordering.hash(&mut s);
    blocks.hash(&mut s);
    first.hash(&mut s);
    s.finish()
}

/// The unique blocks of `h` between free particles, sorted.
fn free_blocks(dofs: &DofMap, h: &HessianBlocks) -> Vec<(u32, u32)> {
    let mut b: Vec<(u32, u32)> = h
        .all()
        .map(|(&pair, _)| pair)
        .filter(|&(p, q)| dofs.dof(p as usize).is_some() && dofs.dof(q as usize).is_some())
        .collect();
    b.sort_unstable();
    b.dedup();
    b
}

impl Structure {
    /// The structure of `blocks` over `dofs` under `ordering`. A structure grown by contact pairs
    /// is ordered afresh: the order of the structure it grew from, kept, cost 15 % more a
    /// factorization on the 121² skirt.
    pub(super) fn analyse(
        dofs: &DofMap,
        blocks: Vec<(u32, u32)>,
        ordering: FillOrdering,
    ) -> Option<Self> {
        let n = dofs.n;
        let mut idx: Vec<Pair<usize, usize>> = Vec::new();
        for &(p, q) in &blocks {
            let (Some(dp), Some(dq)) = (dofs.dof(p as usize), dofs.dof(q as usize)) else {
                continue;
            };
            for r in 0..3 {
                for c in 0..3 {
                    if p != q || r >= c {
                        idx.push(Pair::new(dp + r, dq + c));
                    }
                }
            }
        }
        idx.extend((0..n).map(|d| Pair::new(d, d)));
        let (sym, _) = SymbolicSparseColMat::try_new_from_indices(n, n, &idx).ok()?;
        // Supernodal always: on the 14 × 14 slack net it factorizes in 0.84 ms against 1.26 ms
        // simplicial and 1.9 ms with faer's automatic choice (measured on this machine).
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        // faer 0.24 offers AMD or a given permutation (its supernodal path panics with the identity
        // ordering on these patterns): nested dissection of the particles on large sheets.
        let dissection = ordering
            .dissects(n / 3)
            .then(|| dissection_order(dofs, &blocks));
        let fill_reducing = match &dissection {
            Some(o) => SymmetricOrdering::Custom(PermRef::new_checked(&o.forward, &o.inverse, n)),
            None => SymmetricOrdering::Amd,
        };
        let symbolic =
            factorize_symbolic_cholesky(sym.as_ref(), Side::Lower, fill_reducing, params).ok()?;
        let (permuted, to_permuted) = permute_once(&sym, &symbolic)?;
        Some(Self {
            first: dofs.first.clone(),
            ordering,
            blocks,
            sym,
            symbolic,
            permuted,
            to_permuted,
        })
    }

    /// The structure of `blocks` over `dofs`, from the process-wide cache or analysed now (with
    /// whether it was analysed now).
    pub(super) fn shared(
        dofs: &DofMap,
        blocks: Vec<(u32, u32)>,
        ordering: FillOrdering,
    ) -> Option<(Arc<Self>, bool)> {
        let key = structure_key(&dofs.first, &blocks, ordering);
        let same =
            |s: &Structure| s.blocks == blocks && s.first == dofs.first && s.ordering == ordering;
        {
            let cache = STRUCTURES.lock().unwrap_or_else(|e| e.into_inner());
            if let Some((_, s)) = cache.iter().find(|(k, s)| *k == key && same(s)) {
                return Some((s.clone(), false));
            }
        }
        let s = Arc::new(Self::analyse(dofs, blocks, ordering)?);
        let mut cache = STRUCTURES.lock().unwrap_or_else(|e| e.into_inner());
        if cache.len() >= MAX_STRUCTURES {
            cache.remove(0);
        }
        cache.push((key, s.clone()));
        Some((s, true))
    }

    /// Where the entry (`r`, `c`), r ≥ c, lands in the compressed values.
    pub(super) fn position(&self, r: usize, c: usize) -> u32 {
        let sym = &self.sym;
        let (start, end) = (sym.col_ptr()[c], sym.col_ptr()[c + 1]);
        let k = sym.row_idx()[start..end].partition_point(|&i| i < r);
        self.to_permuted[start + k]
    }

    /// The slots of the blocks at `pairs` ([`super::SparseSpd::entries`]' order: per block rows, then
    /// columns, the lower triangle of a diagonal block), onto `out`: a block's rows lie next to one
    /// another in each of its columns, so one search per column finds its three.
    fn block_slots(&self, dofs: &DofMap, pairs: &[(u32, u32)], out: &mut Vec<u32>) {
        let sym = &self.sym;
        for &(p, q) in pairs {
            let (Some(dp), Some(dq)) = (dofs.dof(p as usize), dofs.dof(q as usize)) else {
                continue;
            };
            let diagonal = p == q;
            let first: [usize; 3] = std::array::from_fn(|c| {
                let (col, row) = (dq + c, if diagonal { dp + c } else { dp });
                let (start, end) = (sym.col_ptr()[col], sym.col_ptr()[col + 1]);
                start + sym.row_idx()[start..end].partition_point(|&i| i < row)
            });
            for r in 0..3 {
                for (c, &k) in first.iter().enumerate() {
                    if !diagonal || r >= c {
                        out.push(self.to_permuted[k + if diagonal { r - c } else { r }]);
                    }
                }
            }
        }
    }

    /// Whether every block of `blocks` is in the structure, over the same DOFs.
    pub(super) fn covers(&self, dofs: &DofMap, blocks: &[(u32, u32)]) -> bool {
        self.first == dofs.first && blocks.iter().all(|b| self.blocks.binary_search(b).is_ok())
    }
}

/// The DOFs' nested-dissection order from their particles' (forward: the DOF eliminated k-th;
/// inverse: each DOF's place), a particle's three DOFs together.
fn dissection_order(dofs: &DofMap, blocks: &[(u32, u32)]) -> DofOrder {
    let particle = |p: u32| dofs.dof(p as usize).map(|d| d / 3);
    let edges: Vec<(usize, usize)> = blocks
        .iter()
        .filter_map(|&(p, q)| Some((particle(p)?, particle(q)?)))
        .collect();
    let order = super::dissection::nested_dissection(dofs.n / 3, &edges);
    let forward: Vec<usize> = order
        .iter()
        .flat_map(|&p| [3 * p, 3 * p + 1, 3 * p + 2])
        .collect();
    let mut inverse = vec![0; forward.len()];
    forward
        .iter()
        .enumerate()
        .for_each(|(k, &d)| inverse[d] = k);
    DofOrder { forward, inverse }
}

/// The lower triangle `sym` permuted by `symbolic`'s ordering (faer's own permutation, run once on
/// the entries' indices) and the position of each entry of `sym` in it. None for a simplicial
/// factor or no permutation (the structures here are supernodal with AMD).
fn permute_once(
    sym: &SymbolicSparseColMat<usize>,
    symbolic: &SymbolicCholesky<usize>,
) -> Option<(SymbolicSparseColMat<usize>, Vec<u32>)> {
    let (n, nnz) = (sym.nrows(), sym.row_idx().len());
    let perm = symbolic.perm()?;
    let ids: Vec<f64> = (0..nnz).map(|k| k as f64).collect();
    let (mut val, mut col_ptr, mut row_idx) =
        (vec![0.0; nnz], vec![0usize; n + 1], vec![0usize; nnz]);
    let mut mem = MemBuffer::new(StackReq::new::<usize>(n));
    let out = permute_self_adjoint_to_unsorted(
        &mut val,
        &mut col_ptr,
        &mut row_idx,
        SparseColMatRef::new(sym.as_ref(), &ids),
        perm,
        Side::Lower,
        Side::Lower,
        MemStack::new(&mut mem),
    );
    let nnz_per_col = out.symbolic().col_nnz().map(|c| c.to_vec());
    let permuted = SymbolicSparseColMat::new_unsorted_checked(n, n, col_ptr, nnz_per_col, row_idx);
    let mut to_permuted = vec![0u32; nnz];
    for (k, &id) in val.iter().enumerate() {
        to_permuted[id as usize] = k as u32;
    }
    Some((permuted, to_permuted))
}

/// Where the entries of one list of Hessian blocks land in a structure.
pub(super) struct Pattern {
    pub(super) pairs: Vec<(u32, u32)>,
    /// The pairs of the Hessian's constant part ([`HessianBlocks::constant`]).
    pub(super) constant_pairs: Vec<(u32, u32)>,
    pub(super) structure: Arc<Structure>,
    /// For each entry ([`super::SparseSpd::entries`] order: the constant part's, then the others), then
    /// each diagonal shift, its position in the compressed values: a factorization adds every
    /// entry straight into its slot, in that order.
    pub(super) slot: Vec<u32>,
    /// How many of the entries are the constant part's.
    pub(super) constant_entries: usize,
}

impl Pattern {
    /// The entries of `h` over `dofs` mapped into `structure` (which holds all of its blocks).
    pub(super) fn map(dofs: &DofMap, h: &HessianBlocks, structure: Arc<Structure>) -> Self {
        let mut slot = Vec::new();
        if let Some(c) = h.constant.as_deref() {
            structure.block_slots(dofs, &c.pairs, &mut slot);
        }
        let constant_entries = slot.len();
        structure.block_slots(dofs, &h.pairs, &mut slot);
        slot.extend((0..dofs.n).map(|d| structure.position(d, d)));
        Self {
            pairs: h.pairs.clone(),
            constant_pairs: h.constant_pairs().to_vec(),
            slot,
            constant_entries,
            structure,
        }
    }

    /// The pattern of `h` on `last`'s structure when `h`'s blocks after those it shares with
    /// `last` from the start (the elastic terms push first, the contact pairs that come and go
    /// last) are all in it: `last`'s slots kept for the shared blocks, the others mapped — the
    /// slots [`Self::map`] gives, without searching the elastic entries again at every change of
    /// the contact set. None where a block is missing.
    pub(super) fn extend(last: &Pattern, dofs: &DofMap, h: &HessianBlocks) -> Option<Self> {
        let structure = &last.structure;
        if last.constant_pairs != h.constant_pairs() || structure.first != dofs.first {
            return None;
        }
        let shared = last
            .pairs
            .iter()
            .zip(&h.pairs)
            .take_while(|(a, b)| a == b)
            .count();
        let free =
            |&(p, q): &(u32, u32)| dofs.dof(p as usize).is_some() && dofs.dof(q as usize).is_some();
        let rest = &h.pairs[shared..];
        let missing = rest
            .iter()
            .filter(|b| free(b))
            .any(|b| structure.blocks.binary_search(b).is_err());
        if missing {
            return None;
        }
        let entries = |b: &(u32, u32)| match (free(b), b.0 == b.1) {
            (false, _) => 0,
            (true, true) => 6,
            (true, false) => 9,
        };
        let kept = last.constant_entries + last.pairs[..shared].iter().map(entries).sum::<usize>();
        let mut slot = last.slot[..kept].to_vec();
        structure.block_slots(dofs, rest, &mut slot);
        slot.extend_from_slice(&last.slot[last.slot.len() - dofs.n..]);
        Some(Self {
            pairs: h.pairs.clone(),
            constant_pairs: last.constant_pairs.clone(),
            slot,
            constant_entries: last.constant_entries,
            structure: structure.clone(),
        })
    }

    /// Whether this is the pattern of `h`'s blocks over `dofs`.
    pub(super) fn holds(&self, dofs: &DofMap, h: &HessianBlocks) -> bool {
        self.pairs == h.pairs
            && self.constant_pairs == h.constant_pairs()
            && self.structure.first == dofs.first
    }

    /// The pattern of `h` on its own structure, from the process-wide cache or mapped now (with
    /// whether its structure was analysed now).
    pub(super) fn exact(
        dofs: &DofMap,
        h: &HessianBlocks,
        ordering: FillOrdering,
    ) -> Option<(Arc<Self>, bool)> {
        let mut key = std::collections::hash_map::DefaultHasher::new();
        ordering.hash(&mut key);
        h.pairs.hash(&mut key);
        h.constant_pairs().hash(&mut key);
        dofs.first.hash(&mut key);
        let key = key.finish();
        let same = |p: &Pattern| p.holds(dofs, h) && p.structure.ordering == ordering;
        {
            let cache = PATTERNS.lock().unwrap_or_else(|e| e.into_inner());
            if let Some((_, p)) = cache.iter().find(|(k, p)| *k == key && same(p)) {
                return Some((p.clone(), false));
            }
        }
        let (structure, analysed) = Structure::shared(dofs, free_blocks(dofs, h), ordering)?;
        let p = Arc::new(Self::map(dofs, h, structure));
        let mut cache = PATTERNS.lock().unwrap_or_else(|e| e.into_inner());
        if cache.len() >= MAX_STRUCTURES {
            cache.remove(0);
        }
        cache.push((key, p.clone()));
        Some((p, analysed))
    }

    /// The pattern of `h` after `last` (this solver's previous pattern, if any): on `last`'s
    /// structure when that holds every block of `h` (a contact set that changed within it: no
    /// analysis); otherwise on the union of its blocks and `h`'s (so that blocks that come and go
    /// stay inside), or on `h`'s own where the union has grown past [`MAX_SUPERSET`] of them, or
    /// where there is no `last`. The structure depends on this solve's own history only, never on
    /// what other solves analysed: the same solve gives the same bits. With whether a structure was
    /// analysed now.
    pub(super) fn next(
        dofs: &DofMap,
        h: &HessianBlocks,
        last: Option<&Arc<Pattern>>,
        ordering: FillOrdering,
    ) -> Option<(Arc<Self>, bool)> {
        let fits = |s: &&Arc<Structure>| s.first == dofs.first && s.ordering == ordering;
        let Some(own) = last.map(|p| &p.structure).filter(fits) else {
            return Self::exact(dofs, h, ordering);
        };
        if let Some(p) = last.and_then(|l| Self::extend(l, dofs, h)) {
            return Some((Arc::new(p), false));
        }
        let blocks = free_blocks(dofs, h);
        if own.covers(dofs, &blocks) {
            return Some((Arc::new(Self::map(dofs, h, own.clone())), false));
        }
        let mut union = own.blocks.clone();
        union.extend_from_slice(&blocks);
        union.sort_unstable();
        union.dedup();
        if union.len() as f64 > MAX_SUPERSET * blocks.len() as f64 {
            return Self::exact(dofs, h, ordering);
        }
        // The blocks the terms expect next, where they fit under the same bound.
        let free =
            |&(p, q): &(u32, u32)| dofs.dof(p as usize).is_some() && dofs.dof(q as usize).is_some();
        let mut hinted = union.clone();
        hinted.extend(h.hints.iter().filter(|b| free(b)));
        hinted.sort_unstable();
        hinted.dedup();
        if hinted.len() as f64 <= MAX_SUPERSET * blocks.len() as f64 {
            union = hinted;
        }
        let (structure, analysed) = Structure::shared(dofs, union, ordering)?;
        Some((Arc::new(Self::map(dofs, h, structure)), analysed))
    }
}

/// The patterns of whole Hessians on their own structures met so far in this process (one per
/// grid, pin set and contact set): a solve's first factorization finds its mapping here.
pub(super) static PATTERNS: Mutex<Vec<(u64, Arc<Pattern>)>> = Mutex::new(Vec::new());
