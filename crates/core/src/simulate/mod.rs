//! Running one scene: build the model and solve it with the scene's solver (static Newton, with a
//! coarse or sagged start, friction increments and contact rounds as the scene asks, or dynamics).
//! Writing the outputs of a run is `drapelab_record::simulate_to_dir`'s.

mod friction;
mod start;

use crate::build::{BuiltScene, build_scene};
use crate::cloth::Grid;
use crate::scene::Scene;
use crate::solve::{
    Observer, SolveReport, StaticOptions, WarmData, solve_dynamic, solve_static_warm,
};
use friction::solve_with_friction;
use nalgebra::Vector3;
use start::{coarse_start, taut_start};

/// A solved scene.
pub struct Solution {
    /// The grid of real particles.
    pub grid: Grid,
    /// Final positions of all particles (virtual points after the grid ones) in m.
    pub x: Vec<Vector3<f64>>,
    /// How the solve went.
    pub report: SolveReport,
    /// The energy terms that were built.
    pub terms: Vec<String>,
    /// The model, for evaluating residuals or energies afterwards.
    pub model: crate::physics::Model,
}

impl Solution {
    /// The solution of a scene that failed its checks: no particles, status invalid, the error as
    /// the message.
    pub fn invalid(scene: &Scene, error: crate::error::InputError) -> Self {
        let mut report = SolveReport::unsolved(scene.solver.kind);
        report.stop_with(crate::solve::StopReason::Invalid, error.to_string());
        Solution {
            grid: Grid {
                nx: 0,
                ny: 0,
                xs: Vec::new(),
                ys: Vec::new(),
            },
            x: Vec::new(),
            report,
            terms: Vec::new(),
            model: crate::physics::Model {
                masses: Vec::new(),
                fixed: Vec::new(),
                held_components: Vec::new(),
                n_grid: 0,
                terms: Vec::new(),
                gravity_m_per_s2: scene.gravity.g_m_per_s2,
                damping_Ns_per_m: 0.0,
                elongation_rate: None,
                constant_hessian: Default::default(),
            },
        }
    }
    /// Positions of the grid particles only.
    pub fn grid_positions(&self) -> &[Vector3<f64>] {
        &self.x[..self.grid.len()]
    }
    /// Position of grid particle (i, j).
    pub fn at(&self, i: usize, j: usize) -> Vector3<f64> {
        self.x[self.grid.index(i, j)]
    }
    /// Where the material point at sheet coordinates (u, v) in m (from particle (0, 0) of the flat
    /// sheet) ended: bilinear interpolation over its grid cell, exact at grid particles. Lets grids
    /// of different resolution or grading be compared at the same material points.
    pub fn at_material(&self, u_m: f64, v_m: f64) -> Vector3<f64> {
        let cell = |lines: &[f64], s: f64| {
            let k = lines.partition_point(|&c| c <= s).clamp(1, lines.len() - 1) - 1;
            let t = ((s - lines[k]) / (lines[k + 1] - lines[k])).clamp(0.0, 1.0);
            (k, t)
        };
        let ((i, a), (j, b)) = (cell(&self.grid.xs, u_m), cell(&self.grid.ys, v_m));
        self.at(i, j) * ((1.0 - a) * (1.0 - b))
            + self.at(i + 1, j) * (a * (1.0 - b))
            + self.at(i, j + 1) * ((1.0 - a) * b)
            + self.at(i + 1, j + 1) * (a * b)
    }
}

/// The sheet's self-contact at the end of a solve, as `run.json` and the benchmark report it.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SelfContactSummary {
    /// "auto", "on" or "off", as the scene asks.
    pub mode: crate::scene::SelfContactMode,
    /// Whether the solve modelled self-contact (the term was built).
    pub modelled: bool,
    /// Thickness ξ, m (the closest two layers may come); null when not modelled.
    pub thickness_m: Option<f64>,
    /// Activation distance ξ + d̂, m; null when not modelled.
    pub activation_distance_m: Option<f64>,
    /// Smallest distance between two parts of the sheet that share no vertex, m (null when none is
    /// within the longest edge of another); null when not modelled.
    pub min_distance_m: Option<f64>,
    /// The barrier's stiffness κ at the end, J; null when not modelled.
    pub kappa_J: Option<f64>,
    /// κ at the end over κ as built: above 1 where a solve stiffened the barrier because layers
    /// pressed pairs to within a small fraction of the band (IPC's adaptive κ); null when not
    /// modelled.
    pub kappa_growth: Option<f64>,
    /// Pairs within the activation distance at the end.
    pub active_pairs: usize,
    /// Broad phases the solve ran.
    pub broad_phases: usize,
    /// Wall time spent in self-contact (broad phase, collision detection, energy), s.
    pub time_s: f64,
    /// Mesh edges that cross a triangle sharing no vertex with them (segment–triangle tests on
    /// the triangulated grid): the sheet passing through itself. Counted in every mode.
    pub crossing_edges: usize,
}

/// A converged solve whose sheet passes through itself is not a drape: where self-contact was not
/// modelled (with it no step can cross), the final state's crossing edges are counted and any
/// makes the status invalid ([`StopReason::PassesThroughItself`](crate::solve::StopReason)).
pub fn check_crossings(
    scene: &Scene,
    grid: &Grid,
    model: &crate::physics::Model,
    x: &[Vector3<f64>],
    report: &mut SolveReport,
) {
    if !report.is_converged() || model.models_self_contact() || x.len() < grid.len() {
        return;
    }
    let n = crossing_edges(scene, x);
    if n > 0 {
        report.stop_for(crate::solve::StopReason::PassesThroughItself);
        report.message += &format!(
            "; the sheet passes through itself at {n} mesh edges (contact.self = \"{}\" on {}): not a drape",
            match scene.contact.self_contact {
                crate::scene::SelfContactMode::Off => "off",
                crate::scene::SelfContactMode::On => "on",
                crate::scene::SelfContactMode::Auto => "auto",
            },
            scene.solver.kind.name()
        );
    }
}

/// Mesh edges of the sheet at `x` that cross a triangle sharing no vertex with them.
fn crossing_edges(scene: &Scene, x: &[Vector3<f64>]) -> usize {
    let topo = crate::proximity::MeshTopology::from_triangles(crate::build::scene_triangles(scene));
    crate::proximity::edge_triangle_crossings(&topo, x)
        .iter()
        .map(|c| c.0)
        .collect::<std::collections::BTreeSet<_>>()
        .len()
}

/// The self-contact summary of a solved model at `x`.
pub fn self_contact_summary(
    scene: &Scene,
    model: &crate::physics::Model,
    x: &[Vector3<f64>],
) -> SelfContactSummary {
    let crossing_edges = crossing_edges(scene, x);
    let state = model.self_contact(x);
    let xi = state.map(|_| crate::build::self_thickness_m(scene));
    SelfContactSummary {
        mode: scene.contact.self_contact,
        modelled: state.is_some(),
        thickness_m: xi,
        activation_distance_m: xi.map(|t| 2.0 * t),
        min_distance_m: state
            .and_then(|s| s.min_distance_m.is_finite().then_some(s.min_distance_m)),
        kappa_J: state.map(|s| s.kappa_J),
        kappa_growth: state.map(|s| s.kappa_growth),
        active_pairs: state.map_or(0, |s| s.active_pairs),
        broad_phases: state.map_or(0, |s| s.broad_phases),
        time_s: state.map_or(0.0, |s| s.time_s),
        crossing_edges,
    }
}

/// Solves a scene in memory with its configured solver; the observer sees each state. The scene is
/// checked first ([`Scene::validated`]): an invalid one gives a solution with status invalid, the
/// bad key in its message, and no particles.
pub fn solve_scene(scene: &Scene, observer: &mut dyn Observer) -> Solution {
    let cold = WarmData::default();
    solve_built(scene, None, &[], cold, Choice::Lowest, observer)
}

/// Solves a validated scene statically or dynamically from the given positions of all particles
/// (a warm start: no coarse or sagged start is made); the scene's own start when `x0` does not match
/// the built model's particle count. The model starts as built (κ growth 1): to continue the run
/// that made `x0`, hand its [`crate::physics::Adapted`] to [`solve_scene_from_lowest`].
pub fn solve_scene_from(
    scene: &Scene,
    x0: &[Vector3<f64>],
    observer: &mut dyn Observer,
) -> Solution {
    let cold = WarmData::default();
    solve_built(scene, None, &[x0], cold, Choice::Lowest, observer)
}

/// [`solve_scene_from`] the candidate start with the lowest energy in the scene's model (e.g. a
/// neighbouring drape and its tangent prediction): the model is built once for the choice and the
/// solve. Candidates that do not match the model's particle count are passed over; with none left,
/// the scene's own start. `opts`, where given, replaces the scene's static solver options (a
/// calibration's cheaper steps, with no copy of the scene); `warm` is the neighbour's data (its
/// factor, its self-contact candidates, which seed the model's broad phase where they fit).
pub fn solve_scene_from_lowest(
    scene: &Scene,
    opts: Option<&StaticOptions>,
    starts: &[&[Vector3<f64>]],
    warm: WarmData<'_>,
    observer: &mut dyn Observer,
) -> Solution {
    solve_built(scene, opts, starts, warm, Choice::Lowest, observer)
}

/// [`solve_scene_from_lowest`], but from the first candidate whose energy is finite: the starts come
/// in order of preference (a prediction known to lie close to the drape first, as the calibration's
/// Hermite start), and the energies of the others are not taken (each is a pass over the model).
pub fn solve_scene_from_first(
    scene: &Scene,
    opts: Option<&StaticOptions>,
    starts: &[&[Vector3<f64>]],
    warm: WarmData<'_>,
    observer: &mut dyn Observer,
) -> Solution {
    solve_built(scene, opts, starts, warm, Choice::FirstFinite, observer)
}

/// How a solve picks among its candidate starts.
#[derive(Clone, Copy, PartialEq)]
enum Choice {
    /// The one of lowest energy.
    Lowest,
    /// The first of finite energy.
    FirstFinite,
}

fn solve_built(
    scene: &Scene,
    opts: Option<&StaticOptions>,
    starts: &[&[Vector3<f64>]],
    warm: WarmData<'_>,
    choice: Choice,
    observer: &mut dyn Observer,
) -> Solution {
    // Only a checked scene is built; one changed in code into an invalid one is a status, not a panic.
    let scene = match scene.clone().validated() {
        Ok(v) => v,
        Err(e) => return Solution::invalid(scene, e),
    };
    let scene = &scene;
    let BuiltScene {
        grid,
        mut model,
        x0: mut x,
    } = build_scene(scene);
    if let Some(a) = &warm.adapted {
        a.apply_to(&mut model);
    }
    // The starts are scored over the neighbour's candidate set (no broad phase where it covers
    // them), which the solve then carries on.
    let mut candidates = warm.candidates.cloned().unwrap_or_default();
    let opts = opts.unwrap_or(&scene.solver.static_);
    let mut energy = |s: &[Vector3<f64>]| model.energy_with(s, &mut candidates, 1.0);
    let mut scored = starts
        .iter()
        .filter(|s| s.len() == x.len())
        .map(|s| (energy(s), *s));
    let start = match choice {
        Choice::FirstFinite => scored.find(|(e, _)| e.is_finite()),
        Choice::Lowest => scored
            .filter(|(e, _)| !e.is_nan())
            .min_by(|a, b| a.0.total_cmp(&b.0)),
    }
    .map(|(_, s)| s);
    let warm = WarmData {
        candidates: Some(&candidates),
        ..warm
    };
    let report = match start {
        Some(x0) => {
            x.copy_from_slice(x0);
            solve_model_warm(scene, opts, &grid, &mut model, &mut x, warm, observer)
        }
        _ => solve_model_with(scene, opts, &grid, &mut model, &mut x, observer),
    };
    let mut report = report;
    check_crossings(scene, &grid, &model, &x, &mut report);
    Solution {
        grid,
        terms: model.term_names(),
        x,
        report,
        model,
    }
}

/// Solves a built scene from `x` as it is, a warm start near the equilibrium (a saved drape, a
/// neighbouring parameter's solution) with the static options `opts` (the scene's, or a caller's
/// in their place) and the neighbour's data `warm`: no coarse, sagged or folded start, and Newton
/// starts far less damped ([`WARM_LM_DAMPING`]).
pub fn solve_model_warm(
    scene: &Scene,
    opts: &StaticOptions,
    grid: &Grid,
    model: &mut crate::physics::Model,
    x: &mut [Vector3<f64>],
    warm: WarmData<'_>,
    observer: &mut dyn Observer,
) -> SolveReport {
    let damped = StaticOptions {
        lm_damping_initial: opts.lm_damping_initial.min(WARM_LM_DAMPING),
        ..opts.clone()
    };
    let mut report = static_or_dynamic(scene, &damped, grid, model, x, warm, observer);
    check_minimum(opts.check_minimum, model, x, &mut report);
    report
}

/// The initial Levenberg–Marquardt damping of a solve from a warm start (relative to the mean
/// diagonal; the flat or sagged start's default is 1e-3).
pub const WARM_LM_DAMPING: f64 = 1e-5;

/// The scene's solver from `x` as it is: the static solve, or the dynamic integrator.
fn static_or_dynamic(
    scene: &Scene,
    opts: &StaticOptions,
    grid: &Grid,
    model: &mut crate::physics::Model,
    x: &mut [Vector3<f64>],
    warm: WarmData<'_>,
    observer: &mut dyn Observer,
) -> SolveReport {
    match scene.solver.kind.integrator() {
        None => static_solve(scene, opts, grid, model, x, warm, observer),
        Some(integ) => {
            let mut v = vec![Vector3::zeros(); x.len()];
            let mut report =
                solve_dynamic(model, integ, x, &mut v, &scene.solver.dynamic, observer);
            check_minimum(true, model, x, &mut report);
            report
        }
    }
}

/// Stability of a converged (or settled) state, checked once: after every load increment and contact
/// round of a static solve, at the end of a dynamic one (a heavily damped sheet can come to rest on a
/// saddle it would leave only slowly); not when `wanted` is false (`solver.static.check_minimum`).
fn check_minimum(
    wanted: bool,
    model: &crate::physics::Model,
    x: &[Vector3<f64>],
    report: &mut SolveReport,
) {
    if wanted && report.is_converged() && report.minimum.is_none() {
        let minimum = crate::solve::is_minimum(model, x);
        report.minimum = Some(minimum);
        if !minimum {
            report.message += "; not a minimum: an unstable equilibrium (a saddle), which a \
small perturbation (cloth.initial_perturbation_m, [[loads]]) moves off";
        }
    }
}

/// Solves a built scene from `x` (updated in place) with the scene's solver.
pub fn solve_model(
    scene: &Scene,
    grid: &Grid,
    model: &mut crate::physics::Model,
    x: &mut [Vector3<f64>],
    observer: &mut dyn Observer,
) -> SolveReport {
    solve_model_with(scene, &scene.solver.static_, grid, model, x, observer)
}

/// [`solve_model`] with the static options `opts` in place of the scene's (its coarse and taut
/// starts solve with the scene's own).
fn solve_model_with(
    scene: &Scene,
    opts: &StaticOptions,
    grid: &Grid,
    model: &mut crate::physics::Model,
    x: &mut [Vector3<f64>],
    observer: &mut dyn Observer,
) -> SolveReport {
    let cold = WarmData::default();
    if scene.solver.kind.integrator().is_some() {
        return static_or_dynamic(scene, opts, grid, model, x, cold, observer);
    }
    // Nested iteration: start Newton from the interpolated solution of the scene on the grid with
    // every other line, when that grid exists; far fewer fine iterations are needed. Otherwise,
    // without obstacles, from the sagged sheet.
    let taut = match opts.start.is_shaped() {
        true => taut_start(scene, x),
        false => None,
    };
    let coarse = match taut {
        Some(_) => None,
        None => coarse_start(scene, grid, x),
    };
    if coarse.is_none()
        && taut.is_none()
        && opts.start.is_shaped()
        && scene.obstacles.is_empty()
        && crate::solve::folded_start(model, x).is_none()
    {
        crate::solve::sagged_start(model, x);
    }
    let nested = opts.nested_for(coarse.is_some());
    let opts = &nested;
    let mut report = static_solve(scene, opts, grid, model, x, cold, observer);
    if let Some(r) = taut {
        report.merge(&r, crate::solve::Part::Start);
        report.message += " (from the taut net's drape)";
    }
    if let Some((r, _)) = coarse {
        report.merge(&r, crate::solve::Part::Start);
        report.message += &format!(
            " (from a {}×{} start)",
            grid.nx.div_ceil(2),
            grid.ny.div_ceil(2)
        );
    }
    check_minimum(opts.check_minimum, model, x, &mut report);
    report
}

/// The static solve of a built scene from `x`: Newton, wrapped in the vertical-gap active set when the
/// scene asks for that contact treatment.
fn static_solve(
    scene: &Scene,
    opts: &StaticOptions,
    grid: &Grid,
    model: &mut crate::physics::Model,
    x: &mut [Vector3<f64>],
    warm: WarmData<'_>,
    observer: &mut dyn Observer,
) -> SolveReport {
    if scene.contact.method == crate::scene::ContactMethod::VerticalGap
        && !scene.obstacles.is_empty()
    {
        crate::solve::solve_vertical_gap(
            model,
            x,
            &scene.obstacles,
            grid.min_spacing_m(),
            opts,
            warm,
            observer,
        )
    } else if scene.contact.friction_coefficient > 0.0 && !scene.obstacles.is_empty() {
        solve_with_friction(scene, model, x, opts, warm, observer)
    } else {
        solve_static_warm(model, x, opts, warm, observer)
    }
}
