//! What a solve may start from besides its configuration and its start positions: data from a
//! neighbouring solve (a nearby parameter's equilibrium, the last time step), handed to the solve
//! in its own argument ([`WarmData`]), never carried by the options.

use crate::physics::{Adapted, CandidateSet};

/// A neighbouring equilibrium's factor, shared. As a preconditioner of conjugate gradients it
/// needs no scale: a model whose energy is a multiple of the neighbour's takes the same steps.
#[derive(Clone)]
pub struct NeighbourFactor(pub std::sync::Arc<super::SparseSpd>);

impl std::fmt::Debug for NeighbourFactor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "NeighbourFactor")
    }
}

/// Data from a neighbouring solve that starts this one. The default is a cold start.
#[derive(Clone, Copy, Default)]
pub struct WarmData<'a> {
    /// The factor of a neighbouring equilibrium's Hessian: each Newton step of the solve's first
    /// run is solved by conjugate gradients preconditioned with it, with no factorization of its
    /// own while that converges. The calibration hands over its lattice node's; implicit Euler
    /// the last step's.
    pub factor: Option<&'a NeighbourFactor>,
    /// A self-contact candidate set from the neighbour's solve
    /// ([`crate::physics::Model::candidates_covering`]): the solve starts carrying it (rebuilt
    /// where it was built for another mesh or activation distance).
    pub candidates: Option<&'a CandidateSet>,
    /// What the neighbour's solve adapted in its model (κ growth): the model takes it up before
    /// its start is scored, so a restart at the neighbour's parameters continues its run.
    pub adapted: Option<Adapted>,
}
