//! Seed 003's contact determination (§10.7.1) around the static Newton solver. The load (gravity) is
//! raised in small increments so that no node can pass an obstacle within one; after each increment,
//! every free node that went below an obstacle's upper surface is pulled back vertically onto it and
//! held there (a node that entered from the side, which the vertical pull would lift over the
//! obstacle, goes back out along the surface normal instead), and a held node on which the net force
//! points up (the obstacle no longer pushes) is let go; the increment is solved again until the set of held nodes settles (releases stop after a few
//! rounds, so it cannot cycle). A held node is fixed in all directions, as the seed fixes the nodes in
//! contact with a table: the contact is sticky (a node that touched stays where it touched until it is
//! let go), which suits tables, pedestals and rods; on a sphere the sheet stays where it first touched.
//! The barrier method is the frictionless one.

use super::{NoObserver, Observer, SolveReport, StaticOptions, Status, solve_static_loads};
use crate::contact::Obstacle;
use crate::physics::Model;
use nalgebra::Vector3;

/// Active-set rounds per load increment before giving up.
const MAX_ROUNDS: usize = 100;
/// Rounds (per increment) in which held nodes may be let go.
const RELEASE_ROUNDS: usize = 5;
/// Load increments when the scene asks for a single step.
const DEFAULT_INCREMENTS: usize = 20;
/// A node is pulled back vertically only while that lifts it by at most this many times its depth
/// inside the obstacle; deeper side entries go back out along the surface normal.
const MAX_LIFT_OVER_DEPTH: f64 = 3.0;

/// The highest upper surface of the obstacles under (x, y), if any.
fn surface_below(obstacles: &[Obstacle], p: &Vector3<f64>) -> Option<f64> {
    obstacles
        .iter()
        .filter_map(|o| o.top_at(p.x, p.y))
        .fold(None, |best: Option<f64>, z| {
            Some(best.map_or(z, |b| b.max(z)))
        })
}

/// Solves `model` from `x` with vertical-gap contact against `obstacles`, raising the load in
/// `opts.load_steps` increments (20 when that is 1). Iterations and times add up over the rounds; a
/// round that does not converge ends the solve with its status.
pub fn solve_vertical_gap(
    model: &mut Model,
    x: &mut [Vector3<f64>],
    obstacles: &[Obstacle],
    opts: &StaticOptions,
    observer: &mut dyn Observer,
) -> SolveReport {
    let pinned = model.fixed.clone();
    let mut held = vec![false; model.len()];
    let mut total: Option<SolveReport> = None;
    let mut g = Vec::new();
    let increments = if opts.load_steps > 1 {
        opts.load_steps
    } else {
        DEFAULT_INCREMENTS
    };
    let mut first = true;
    let mut rounds = 0;
    for k in 1..=increments {
        let load = k as f64 / increments as f64;
        let mut settled = false;
        for round in 0..MAX_ROUNDS {
            rounds += 1;
            let obs: &mut dyn Observer = if first {
                &mut *observer
            } else {
                &mut NoObserver
            };
            first = false;
            let report = SolveReport::accumulate(
                total.take(),
                solve_static_loads(model, x, opts, &[load], obs),
            );
            if report.status != Status::Converged {
                return report;
            }
            let mut changed = false;
            // Pull back the nodes that went in, and hold them.
            for p in 0..model.n_grid {
                if pinned[p] || held[p] {
                    continue;
                }
                let deepest = obstacles
                    .iter()
                    .map(|o| o.signed_distance(&x[p]))
                    .filter(|(d, _)| *d < 0.0)
                    .min_by(|a, b| a.0.total_cmp(&b.0));
                let Some((depth, normal)) = deepest else {
                    continue;
                };
                match surface_below(obstacles, &x[p]) {
                    // The seed's pull-back: vertically onto the upper surface, for a node that came
                    // from above (the lift is not much more than its depth).
                    Some(z) if z - x[p].z <= MAX_LIFT_OVER_DEPTH * -depth => x[p].z = z,
                    // A node that entered from the side or from below would be lifted over the
                    // obstacle (the sheet would fold over it): put it back out along the normal.
                    _ => x[p] -= normal * depth,
                }
                held[p] = true;
                model.fixed[p] = true;
                changed = true;
            }
            // Let go of the held nodes that the obstacle no longer supports.
            if round < RELEASE_ROUNDS {
                model.gradient(x, load, &mut g);
                for p in 0..model.n_grid {
                    if held[p] && -g[p].z > 0.0 {
                        held[p] = false;
                        model.fixed[p] = false;
                        changed = true;
                    }
                }
            }
            total = Some(report);
            if !changed {
                settled = true;
                break;
            }
        }
        if !settled {
            let mut report = total.expect("at least one round");
            report.status = Status::MaxIterations;
            report.message = format!(
                "vertical-gap contact did not settle in {MAX_ROUNDS} rounds at load {load:.3}"
            );
            return report;
        }
    }
    let mut report = total.expect("at least one round");
    report.message = format!(
        "{} ({} nodes held by vertical-gap contact; {increments} load increments, {rounds} rounds)",
        report.message,
        held.iter().filter(|h| **h).count(),
    );
    report
}
