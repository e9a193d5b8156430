//! The checks a start given from outside (`--start FILE`, a saved drape) must pass before a solve
//! trusts it: the scene's fixed particles where the scene puts them, no particle inside an obstacle,
//! no two particles of an edge at one point, every term's energy finite (no layers closer than
//! the sheet's thickness). A start that fails one is refused naming the particle,
//! never run into a "diverged" without a message or a "converged in 0 iterations" whose pins moved.

use super::BuiltScene;
use crate::scene::Scene;
use nalgebra::Vector3;

/// How far a fixed particle may lie from where the scene fixes it, m: a saved drape writes its
/// fixed particles exactly as they were.
const FIXED_SLACK_M: f64 = 1e-9;

/// What is wrong with a start: the column to name (`x_m`, …) and why, with the particle.
#[derive(Debug, Clone, PartialEq)]
pub struct StartDefect {
    /// The column of the start file the defect is in.
    pub column: &'static str,
    /// What is wrong and what to do.
    pub message: String,
}

/// Checks the grid particles' start `x` (the first `x.len()` particles of `built`) against the
/// scene: see the module's comment.
pub fn check_start(
    scene: &Scene,
    built: &BuiltScene,
    x: &[Vector3<f64>],
) -> Result<(), StartDefect> {
    let name = |p: usize| scene.particle_name(p);
    for (p, (xs, x0)) in x.iter().zip(&built.x0).enumerate() {
        if built.model.fixed[p] && (xs - x0).norm() > FIXED_SLACK_M {
            return Err(StartDefect {
                column: "x_m",
                message: format!(
                    "particle {} is fixed by the scene at {:?} m and starts {:.3e} m from it: \
                     start from a drape of this scene (pins, clamps and supports stay where it puts them)",
                    name(p),
                    [x0.x, x0.y, x0.z],
                    (xs - x0).norm()
                ),
            });
        }
    }
    for (k, o) in scene.obstacles.iter().enumerate() {
        let deepest = (0..x.len())
            .filter(|&p| !built.model.fixed[p])
            .map(|p| (p, o.signed_distance(&x[p]).0))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((p, d)) = deepest.filter(|(_, d)| *d <= 0.0) {
            return Err(StartDefect {
                column: "z_m",
                message: format!(
                    "particle {} starts {:.3e} m inside obstacles.{k}: a start must lie outside \
                     every obstacle",
                    name(p),
                    -d
                ),
            });
        }
    }
    coincident_neighbours(scene, built, x)?;
    finite_energy(built, x)
}

/// Refuses a start where a term's energy is not finite, naming the term: layers of the sheet
/// closer than its thickness (self-contact), a particle on an obstacle's surface (its barrier),
/// or positions no term can take.
fn finite_energy(built: &BuiltScene, x: &[Vector3<f64>]) -> Result<(), StartDefect> {
    let mut full = built.x0.clone();
    full[..x.len()].copy_from_slice(x);
    let Some(term) = built
        .model
        .terms
        .iter()
        .find(|t| !t.energy(&full).is_finite())
    else {
        return Ok(());
    };
    let why = match term.name().as_str() {
        "contact/self" => {
            "layers of the sheet start closer than its thickness (contact.self_thickness_m) or \
             through each other"
        }
        "contact/barrier" => "a particle starts on an obstacle's surface",
        _ => "the positions are out of its range",
    };
    Err(StartDefect {
        column: "x_m",
        message: format!(
            "the start's energy is not finite in the term `{}`: {why}; start from a drape of \
             this scene (pins, contact and thickness as it sets them)",
            term.name()
        ),
    })
}

/// Refuses two particles joined by an edge of the grid (or of the mesh) at one point: a triangle
/// without area has no normal, its membrane no strain.
fn coincident_neighbours(
    scene: &Scene,
    built: &BuiltScene,
    x: &[Vector3<f64>],
) -> Result<(), StartDefect> {
    let scale = built.x0.iter().map(|p| p.norm()).fold(1e-3, f64::max);
    let tiny = 1e-12 * scale;
    for t in super::scene_triangles(scene) {
        let t = t.map(|v| v as usize);
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            if a < x.len() && b < x.len() && (x[a] - x[b]).norm() <= tiny {
                return Err(StartDefect {
                    column: "x_m",
                    message: format!(
                        "particles {} and {} start at one point: neighbours must be apart",
                        scene.particle_name(a),
                        scene.particle_name(b)
                    ),
                });
            }
        }
    }
    Ok(())
}
