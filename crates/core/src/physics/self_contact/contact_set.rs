//! The contact set at one state (ipc-toolkit's `Collisions`): every pair of the sheet's primitives
//! that share no vertex and lie within the activation distance ξ + d̂, with what the barrier's
//! energy and derivatives need of each. Built by [`super::SelfContact::contact_set`] (the
//! candidate set's narrow phase) and handed to the barrier ([`super::SelfContact::energy_of`],
//! [`super::SelfContact::add_gradient_of`], [`super::SelfContact::add_hessian_of`]).

/// A contact pair's stencil.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PairKind {
    /// A vertex and a triangle: `vertices` = [point, triangle's three].
    PointTriangle,
    /// Two edges: `vertices` = [first edge's two, second edge's two].
    EdgeEdge,
}

/// One pair within the activation distance at the state its set was built for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPair {
    /// The stencil's kind.
    pub kind: PairKind,
    /// The stencil's four particles (see [`PairKind`]).
    pub vertices: [usize; 4],
    /// The distance between the two primitives, m.
    pub distance_m: f64,
    /// The closest points' coefficients: Σₖ cₖ xₖ is the vector from the second primitive's
    /// closest point to the first's (positive on the first primitive's vertices).
    pub coefficients: [f64; 4],
}

impl ContactPair {
    /// Whether the pair is a vertex and a triangle.
    pub fn is_point_triangle(&self) -> bool {
        self.kind == PairKind::PointTriangle
    }
}

/// Every pair within the activation distance at one state.
#[derive(Debug, Clone, Default)]
pub struct ContactSet {
    /// The pairs, in the candidate list's order.
    pub pairs: Vec<ContactPair>,
    /// The particle blocks of the candidate pairs near range (within the candidate list's margin
    /// of the activation distance, by the list's bound): zero blocks the Hessian adds so that its
    /// factor's pattern holds over the next steps ([`crate::physics::HessianBlocks::hints`]).
    /// A suggestion of the list the set was measured with, not part of the state's contact.
    pub hints: Vec<(u32, u32)>,
}

/// Two sets are equal when they hold the same pairs (their hints depend on the list that measured
/// them, not on the state).
impl PartialEq for ContactSet {
    fn eq(&self, other: &Self) -> bool {
        self.pairs == other.pairs
    }
}

impl ContactSet {
    /// The number of pairs.
    pub fn len(&self) -> usize {
        self.pairs.len()
    }
    /// Whether no pair is within reach.
    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty()
    }
    /// The smallest distance of a pair, m (infinite for an empty set).
    pub fn min_distance_m(&self) -> f64 {
        self.pairs
            .iter()
            .map(|p| p.distance_m)
            .fold(f64::INFINITY, f64::min)
    }
}
