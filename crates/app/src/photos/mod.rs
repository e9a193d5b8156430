//! Photos of hangs: edges fitted from photos, and simulated edges scored against them (seed 000 Eq. 5).

pub mod fit_edges;
pub mod score;
