//! Lagged friction for a static solve (seed 003 §10.5's sticking contact, as incremental potential
//! contact lags it): the load raised in increments, the friction anchors refreshed before each.

use crate::scene::Scene;
use crate::solve::{Observer, SolveReport};
use nalgebra::Vector3;

/// The static solve with lagged friction: the load raised in increments (20 when the scene asks for
/// one step), the friction anchors refreshed before each, then up to 10 more refreshes at full load
/// until no particle moves by more than 1e-7 m.
pub(super) fn solve_with_friction(
    scene: &Scene,
    model: &mut crate::physics::Model,
    x: &mut [Vector3<f64>],
    opts: &crate::solve::StaticOptions,
    warm: crate::solve::WarmData<'_>,
    observer: &mut dyn Observer,
) -> SolveReport {
    let steps = if opts.load_steps > 1 {
        opts.load_steps
    } else {
        20
    };
    let mut loads: Vec<f64> = (1..=steps).map(|k| k as f64 / steps as f64).collect();
    loads.extend([1.0; FRICTION_UPDATES]);
    model
        .terms
        .push(Box::new(crate::physics::LaggedFriction::anchored(
            vec![],
            FRICTION_EPS_M,
        )));
    let mut lag = FrictionLag {
        contact: crate::build::barrier_contact(scene, &model.masses, &model.fixed),
        mu: scene.contact.friction_coefficient,
        loads,
        steps,
        stage: 0,
        before: Vec::new(),
        moved: f64::INFINITY,
    };
    crate::solve::execute(model, x, opts, warm, &mut lag, observer)
}

/// Refreshes of the friction anchors at full load after the load increments.
const FRICTION_UPDATES: usize = 30;
/// The lagged friction's smoothing length, m (see [`crate::physics::LaggedFriction`]).
const FRICTION_EPS_M: f64 = 1e-5;
/// The friction lag has settled when no particle moves by more than this in one update, m.
const FRICTION_SETTLED_M: f64 = 1e-7;

/// Lagged friction as a continuation: before each stage the anchors are the contacts where the
/// last stage left them (the model's last term).
struct FrictionLag {
    contact: crate::physics::ObstacleBarrier,
    mu: f64,
    /// The load factor of each stage.
    loads: Vec<f64>,
    /// The number of increments among the stages.
    steps: usize,
    stage: usize,
    /// The positions before the last stage.
    before: Vec<Vector3<f64>>,
    /// The largest distance a particle moved in the last stage, m.
    moved: f64,
}

impl crate::solve::Continuation for FrictionLag {
    /// The lag's updates need not settle: `max_iterations` bounds them all together.
    fn shares_budget(&self) -> bool {
        true
    }

    fn next(
        &mut self,
        model: &mut crate::physics::Model,
        x: &mut [Vector3<f64>],
        solved: bool,
    ) -> crate::solve::Stage {
        use crate::physics::{FrictionAnchor, LaggedFriction};
        use crate::solve::Stage;
        if solved {
            self.moved = x
                .iter()
                .zip(&self.before)
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, f64::max);
            let k = self.stage - 1;
            if k >= self.steps && self.moved < FRICTION_SETTLED_M {
                return Stage::Done(format!(
                    " (friction μ = {}, {} lag updates)",
                    self.mu,
                    k + 1
                ));
            }
        }
        let Some(&load) = self.loads.get(self.stage) else {
            // Not settled: the anchors still move the sheet, so the state is no equilibrium of
            // the friction it carries (a status, never "converged").
            return Stage::Stop(
                crate::solve::StopReason::ContactRounds,
                format!(
                    "friction μ = {}: {FRICTION_UPDATES} lag updates at full load still move the sheet ({:.2e} m in the last, more than {FRICTION_SETTLED_M} m)",
                    self.mu, self.moved
                ),
            );
        };
        let anchors = self
            .contact
            .contacts(x)
            .into_iter()
            .map(|(p, n, force)| FrictionAnchor {
                particle: p,
                anchor_m: x[p],
                normal: n,
                limit_N: self.mu * force,
            })
            .collect();
        if let Some(t) = model.terms.last_mut() {
            *t = Box::new(LaggedFriction::anchored(anchors, FRICTION_EPS_M));
        }
        self.before = x.to_vec();
        self.stage += 1;
        Stage::Solve(load)
    }
}
