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

use super::continuation::{Continuation, Stage, execute};
use super::{Observer, SolveReport, StaticOptions, StopReason};
use crate::obstacle::Obstacle;
use crate::physics::Model;
use nalgebra::Vector3;

/// Active-set rounds per load increment before giving up.
const MAX_ROUNDS: usize = 100;
/// Rounds (per increment) in which held nodes may be let go.
const RELEASE_ROUNDS: usize = 5;
/// Load increments when the scene asks for a single step.
const DEFAULT_INCREMENTS: usize = 20;
/// The smallest load increment, as a fraction of the configured one, that cutbacks go down to.
const MAX_CUTBACK: f64 = 64.0;
/// A node is pulled back vertically only while that lifts it by at most this many times its depth
/// inside the obstacle, i.e. where the surface is within ~25° of horizontal (a plane at slope θ
/// lifts by depth / cos θ); on steeper surfaces (a rod's sides) it goes back out along the normal.
/// A vertical pull-back on a steep side shifts a held node along the surface by depth · tan θ,
/// which a sheet stiff in tension (polyester) cannot follow: with 3 (70°) the rod's drape wandered
/// from grid to grid (corner A 0.9 to 12 cm from the experiment); with 1.1 it converges with the
/// grid to the friction barrier's drape.
const MAX_LIFT_OVER_DEPTH: f64 = 1.1;

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
/// `opts.load_steps` increments (20 when that is 1), each halved (down to 1/64 of it) while a free
/// node passes deeper into an obstacle than a quarter of the smallest grid spacing on its way
/// (`spacing_m`), and grown back after an increment that goes through. Iterations and times add
/// up over the rounds, those of rejected increments included; a round that does not converge ends
/// the solve with its status.
pub fn solve_vertical_gap(
    model: &mut Model,
    x: &mut [Vector3<f64>],
    obstacles: &[Obstacle],
    spacing_m: f64,
    opts: &StaticOptions,
    warm: super::WarmData<'_>,
    observer: &mut dyn Observer,
) -> SolveReport {
    let increments = if opts.load_steps > 1 {
        opts.load_steps
    } else {
        DEFAULT_INCREMENTS
    };
    let mut gap = VerticalGap {
        obstacles,
        pinned: model.fixed.clone(),
        held: vec![false; model.len()],
        depth_limit: 0.25 * spacing_m,
        increments,
        full_step: 1.0 / increments as f64,
        load: 0.0,
        step: 1.0 / increments as f64,
        increment: Increment::default(),
        counts: (0, 0),
        g: Vec::new(),
    };
    execute(model, x, opts, warm, &mut gap, observer)
}

/// The state at the start of a load increment, to roll a rejected one back to.
#[derive(Default)]
struct Increment {
    target: f64,
    round: usize,
    start: Vec<Vector3<f64>>,
    held: Vec<bool>,
    fixed: Vec<bool>,
}

/// Seed 003's contact determination as a continuation: per load increment, rounds of (solve,
/// pull back, let go) until the held set settles.
struct VerticalGap<'a> {
    obstacles: &'a [Obstacle],
    /// The model's own fixed particles (pins), never pulled back or let go.
    pinned: Vec<bool>,
    /// Nodes held on an obstacle's surface.
    held: Vec<bool>,
    depth_limit: f64,
    increments: usize,
    full_step: f64,
    /// The load reached, and the next increment's size.
    load: f64,
    step: f64,
    increment: Increment,
    /// (rounds, halved increments) so far.
    counts: (usize, usize),
    g: Vec<Vector3<f64>>,
}

impl VerticalGap<'_> {
    /// Starts the next increment from `x`: its first round.
    fn begin(&mut self, model: &Model, x: &[Vector3<f64>]) -> Stage {
        let target = if self.load + self.step > 1.0 - 1e-12 {
            1.0
        } else {
            self.load + self.step
        };
        self.increment = Increment {
            target,
            round: 0,
            start: x.to_vec(),
            held: self.held.clone(),
            fixed: model.fixed.clone(),
        };
        self.counts.0 += 1;
        Stage::Solve(target)
    }

    /// The note on the result: nodes held, increments, halvings, rounds.
    fn note(&self) -> String {
        let (rounds, cutbacks) = self.counts;
        format!(
            " ({} nodes held by vertical-gap contact; {} load increments, {cutbacks} halved, {rounds} rounds)",
            self.held.iter().filter(|h| **h).count(),
            self.increments,
        )
    }
}

impl Continuation for VerticalGap<'_> {
    fn next(&mut self, model: &mut Model, x: &mut [Vector3<f64>], solved: bool) -> Stage {
        if !solved {
            return self.begin(model, x);
        }
        let target = self.increment.target;
        // The seed's premise: increments small enough that no node passes into an obstacle beyond
        // the pull-back's reach. When one went deeper on its way, take half the step.
        let inc = &self.increment;
        if inc.round == 0
            && self.step > self.full_step / MAX_CUTBACK
            && passed_too_deep(
                self.obstacles,
                &inc.start,
                x,
                &self.held,
                &self.pinned,
                self.depth_limit,
            )
        {
            x.copy_from_slice(&inc.start);
            self.held.clone_from(&inc.held);
            model.fixed.clone_from(&inc.fixed);
            self.step *= 0.5;
            self.counts.1 += 1;
            return self.begin(model, x);
        }
        let mut changed = pull_back(model, x, self.obstacles, &self.pinned, &mut self.held);
        // Let go of the held nodes that the obstacle no longer supports.
        if self.increment.round < RELEASE_ROUNDS {
            model.gradient(x, target, &mut self.g);
            for p in 0..model.n_grid {
                if self.held[p] && -self.g[p].z > 0.0 {
                    self.held[p] = false;
                    model.fixed[p] = false;
                    changed = true;
                }
            }
        }
        if changed {
            self.increment.round += 1;
            if self.increment.round == MAX_ROUNDS {
                return Stage::Stop(
                    StopReason::ContactRounds,
                    format!(
                        "vertical-gap contact did not settle in {MAX_ROUNDS} rounds at load {target:.3}"
                    ),
                );
            }
            self.counts.0 += 1;
            return Stage::Solve(target);
        }
        self.load = target;
        self.step = (2.0 * self.step).min(self.full_step);
        if self.load < 1.0 {
            self.begin(model, x)
        } else {
            Stage::Done(self.note())
        }
    }
}

/// The seed's pull-back: every free node that went into an obstacle is put back on its surface
/// (vertically onto the upper surface when it came from above, else along the normal) and held;
/// whether any moved.
fn pull_back(
    model: &mut Model,
    x: &mut [Vector3<f64>],
    obstacles: &[Obstacle],
    pinned: &[bool],
    held: &mut [bool],
) -> bool {
    let mut changed = false;
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
    changed
}

/// Whether a free node's straight path from `from` to `to` enters an obstacle deeper than `limit`
/// (m): sampled at eight points, so that a node that passed through a thin part is caught too.
fn passed_too_deep(
    obstacles: &[Obstacle],
    from: &[Vector3<f64>],
    to: &[Vector3<f64>],
    held: &[bool],
    pinned: &[bool],
    limit: f64,
) -> bool {
    (0..from.len().min(held.len())).any(|p| {
        !(pinned[p] || held[p])
            && (1..=8).any(|k| {
                let q = from[p].lerp(&to[p], k as f64 / 8.0);
                obstacles.iter().any(|o| o.signed_distance(&q).0 < -limit)
            })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_path_through_an_obstacle_is_caught_and_a_shallow_entry_is_not() {
        let ball = [Obstacle::Sphere {
            centre_m: [0.0, 0.0, 0.0],
            radius_m: 0.05,
        }];
        let v = Vector3::new;
        let free = [false];
        // Straight through the ball and out the other side: both ends outside, the middle 5 cm deep.
        let through = |held: &[bool], pinned: &[bool]| {
            passed_too_deep(
                &ball,
                &[v(0.0, 0.0, 0.1)],
                &[v(0.0, 0.0, -0.1)],
                held,
                pinned,
                0.001,
            )
        };
        assert!(through(&free, &free));
        // Held or pinned nodes do not count.
        assert!(!through(&[true], &free) && !through(&free, &[true]));
        // Ending 0.5 mm inside (the pull-back's job) with a 1 mm limit, and passing beside it.
        assert!(!passed_too_deep(
            &ball,
            &[v(0.0, 0.0, 0.1)],
            &[v(0.0, 0.0, 0.0495)],
            &free,
            &free,
            0.001
        ));
        assert!(!passed_too_deep(
            &ball,
            &[v(0.06, 0.0, 0.1)],
            &[v(0.06, 0.0, -0.1)],
            &free,
            &free,
            0.001
        ));
    }
}
