//! Whether a straight segment (an edge of the sheet) passes through an obstacle: the check that a
//! sheet does not start through a body thinner than its spacing, with both ends outside.

use super::Obstacle;
use nalgebra::Vector3;

/// Points along a segment at which [`Obstacle::segment_enters`] asks an analytic shape.
pub const SEGMENT_SAMPLES: usize = 16;

impl Obstacle {
    /// Whether the straight segment pq passes through the obstacle: a mesh body's faces crossed
    /// (exact), an analytic shape's inside met at one of [`SEGMENT_SAMPLES`] points along it.
    pub fn segment_enters(&self, p: &Vector3<f64>, q: &Vector3<f64>) -> bool {
        match self {
            Obstacle::Mesh {
                offset_m,
                body: Some(b),
                ..
            } => b.segment_crosses(
                &(p - Vector3::from(*offset_m)),
                &(q - Vector3::from(*offset_m)),
            ),
            _ => (0..=SEGMENT_SAMPLES).any(|k| {
                let t = k as f64 / SEGMENT_SAMPLES as f64;
                self.signed_distance(&(p + (q - p) * t)).0 <= 0.0
            }),
        }
    }
}
