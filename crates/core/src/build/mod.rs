//! From a scene to a [`Model`]: the springs the topology asks for, or the continuum terms, the
//! lumped masses, pins and clamps. Terms a scene does not need are never built.

mod continuum;
mod pattern;
mod start;
use continuum::{continuum_terms, symmetry_planes};
pub use pattern::{PatternSheet, pattern_builder};
pub use start::{StartDefect, check_start};

use crate::cloth::Grid;
use crate::physics::{EnergyTerm, Model, ModelBuilder, SpringFamily, Springs};
use crate::scene::{Scene, ValidatedScene};
use nalgebra::Vector3;

/// A scene turned into a model with its grid and initial positions.
pub struct BuiltScene {
    /// The grid of real particles.
    pub grid: Grid,
    /// The model (possibly with virtual clamp points after the grid particles).
    pub model: Model,
    /// Initial positions of all particles in m.
    pub x0: Vec<Vector3<f64>>,
}

/// For `cloth.shape = "disc"`, the grid particles outside the circle inscribed in the sheet (plus a
/// hundredth of the spacing, so that the circle's four extreme points stay); none for a square sheet.
pub fn absent_particles(scene: &Scene, x0: &[Vector3<f64>]) -> Vec<bool> {
    let c = &scene.cloth;
    let n = scene.grid().len();
    if c.shape != crate::scene::SheetShape::Disc {
        return vec![false; n];
    }
    let r = 0.5 * c.size_x_m.min(c.size_y_m);
    let centre = Vector3::new(
        c.origin_m[0] + 0.5 * c.size_x_m,
        c.origin_m[1] + 0.5 * c.size_y_m,
        0.0,
    );
    let tol = 0.01 * c.size_x_m / (c.nx - 1) as f64;
    x0[..n]
        .iter()
        .map(|p| ((p.x - centre.x).powi(2) + (p.y - centre.y).powi(2)).sqrt() > r + tol)
        .collect()
}

/// Which grid particles belong to the sheet: all of a square sheet, a disc's inside its circle (the
/// complement of [`absent_particles`] at the flat start).
pub fn present_particles(scene: &Scene) -> Vec<bool> {
    absent_particles(scene, &initial_positions(scene))
        .iter()
        .map(|a| !a)
        .collect()
}

/// Initial positions of the grid particles ([`Scene::initial_positions`]).
pub fn initial_positions(scene: &Scene) -> Vec<Vector3<f64>> {
    scene.initial_positions()
}

/// Checks that the scene `loaded` has something to solve: at least one free particle with mass
/// (a 2 × 2 sheet pinned at its four corners has none; the error names `boundary`, or
/// `contact.fix_supported` where that fixed them), and where `contact.fix_supported` is the only
/// hold, at least one particle it fixes.
pub fn check_something_free(
    loaded: &crate::scene::LoadedScene,
) -> Result<(), crate::error::InputError> {
    let model = build_scene(&loaded.scene).model;
    let n = loaded.scene.grid().len();
    let c = &loaded.scene.contact;
    let held = model.fixed.iter().any(|&f| f) || model.held_components.iter().flatten().any(|&h| h);
    if c.fix_supported && !held {
        // The scene's only hold is what rests on a support, and nothing does: the sheet would fall
        // (or slide off) with nothing to stop it, and Newton would spend its whole budget on it.
        return Err(crate::error::InputError::new(
            &loaded.path,
            "contact.fix_supported",
            format!(
                "fixes none of the sheet's {n} particles (none starts over an obstacle's top face): \
pin the sheet (boundary) or place it over the support"
            ),
        ));
    }
    if model.reference_weight().is_finite() {
        return Ok(());
    }
    if c.fix_supported && !loaded.scene.obstacles.is_empty() {
        return Err(crate::error::InputError::new(
            &loaded.path,
            "contact.fix_supported",
            format!(
                "fixes every particle resting on an obstacle's top, and with the pins that leaves \
none of the sheet's {n} particles free: set it to false, or make the sheet larger than the support"
            ),
        ));
    }
    Err(crate::error::InputError::new(
        &loaded.path,
        "boundary",
        format!(
            "no free particle with mass on the {n} particles of the sheet: every particle is pinned, \
clamped or outside the sheet; pin fewer or use a finer sheet (cloth.nx, cloth.ny, or the mesh)"
        ),
    ))
}

/// Builds the model of a validated scene ([`ModelBuilder`]: the material's terms on the grid, then
/// gravity, point loads, the obstacles' barrier and self-contact).
pub fn build_scene(scene: &ValidatedScene) -> BuiltScene {
    if let Some(p) = scene.pattern() {
        return pattern::build_mesh_scene(scene, p);
    }
    let c = &scene.cloth;
    let grid = scene.grid();
    let mut x0 = initial_positions(scene);
    let mut b = ModelBuilder::new(
        grid.lumped_masses(c.areal_density_kg_per_m2),
        vec![false; grid.len()],
        scene.gravity.g_m_per_s2,
    );
    // A disc sheet: the particles outside the inscribed circle are absent (fixed, massless, in no term).
    let absent = absent_particles(scene, &x0);
    for (p, &a) in absent.iter().enumerate() {
        if a {
            b.masses[p] = 0.0;
            b.fixed[p] = true;
        }
    }
    for corner in &scene.boundary.pin_corners {
        let (i, j) = corner.ij(&grid);
        b.fixed[grid.index(i, j)] = true;
    }
    for p in &scene.boundary.pin_particles {
        b.fixed[grid.index(p[0], p[1])] = true;
    }
    if let Some(ms) = &scene.material.mass_spring {
        b.mass_spring_dynamics(ms.damping_Ns_per_m, Some(ms.elongation_rate));
        mass_spring_terms(scene, ms, &grid, &absent, &mut b.fixed, &mut b.terms);
    }
    if let Some(cont) = &scene.material.continuum {
        let r = cont.rigidities().expect("validated scene");
        let edges = &scene.boundary.symmetry_edges;
        symmetry_planes(&grid, &r, edges, &x0, &mut b.held, &mut b.terms);
        let clamps = &scene.boundary.clamp_edges;
        continuum_terms(&grid, &r, &absent, clamps, &mut b, &mut x0);
    }
    b.gravity();
    point_loads(scene, &grid, &absent, &x0, &mut b.terms);
    holds(scene, &grid, &mut b.held);
    contact_terms(scene, &x0, &mut b);
    if scene.contact.self_contact.applies_to(scene.solver.kind) {
        let xi = self_thickness_m(scene);
        let triangles = sheet_triangles(&grid, &absent);
        b.self_contact(triangles, &x0, (xi, xi), kappa_gravity(scene));
    }
    BuiltScene {
        grid,
        model: b.build(),
        x0,
    }
}

/// Seed 000's mass-spring net (§3, Table 3): structural, shear and bend springs of the present
/// particles, with the scene's natural length or the flat grid's; a clamped edge pins its line and
/// the next (a net has no rotational degrees of freedom).
fn mass_spring_terms(
    scene: &ValidatedScene,
    ms: &crate::material::MassSpring,
    grid: &Grid,
    absent: &[bool],
    fixed: &mut [bool],
    terms: &mut Vec<Box<dyn EnergyTerm>>,
) {
    let flat = grid.flat_positions();
    for edge in &scene.boundary.clamp_edges {
        // A mass-spring net has no rotational degrees of freedom: clamp = pin the edge and the next line.
        let (on, next) = edge.lines(grid);
        for p in on.into_iter().chain(next) {
            fixed[p] = true;
        }
    }
    let rest = |a: usize, b: usize, factor: f64| match ms.natural_length_m {
        Some(l0) => l0 * factor,
        None => (flat[b] - flat[a]).norm(),
    };
    let mut family = |fam: SpringFamily, k: f64, offsets: &[(usize, usize)], factor: f64| {
        let mut pairs = Vec::new();
        for j in 0..grid.ny {
            for i in 0..grid.nx {
                for &(di, dj) in offsets {
                    if i + di < grid.nx && j + dj < grid.ny {
                        let (a, b) = (grid.index(i, j), grid.index(i + di, j + dj));
                        if !absent[a] && !absent[b] {
                            pairs.push((a, b));
                        }
                    }
                }
            }
        }
        // The anti-diagonal of each cell for shear springs.
        if fam == SpringFamily::Shear {
            for j in 0..grid.ny - 1 {
                for i in 0..grid.nx - 1 {
                    let (a, b) = (grid.index(i + 1, j), grid.index(i, j + 1));
                    if !absent[a] && !absent[b] {
                        pairs.push((a, b));
                    }
                }
            }
        }
        let rests: Vec<f64> = pairs.iter().map(|&(a, b)| rest(a, b, factor)).collect();
        let n = pairs.len();
        if n > 0 {
            terms.push(Box::new(Springs::new(fam, pairs, rests, vec![k; n])));
        }
    };
    family(
        SpringFamily::Structural,
        ms.structural(),
        &[(1, 0), (0, 1)],
        1.0,
    );
    if ms.topology.has_shear() {
        family(
            SpringFamily::Shear,
            ms.shear(),
            &[(1, 1)],
            std::f64::consts::SQRT_2,
        );
    }
    if ms.topology.has_bend() {
        family(SpringFamily::Bend, ms.bend(), &[(2, 0), (0, 2)], 2.0);
    }
}

/// The scene's `[[loads]]` as one term (only when it has some): a load given by position goes to the
/// nearest present particle.
pub(crate) fn point_loads(
    scene: &Scene,
    grid: &Grid,
    absent: &[bool],
    x0: &[Vector3<f64>],
    terms: &mut Vec<Box<dyn EnergyTerm>>,
) {
    if scene.loads.is_empty() {
        return;
    }
    let loads = scene
        .loads
        .iter()
        .map(|l| {
            let p = match (l.particle, l.at_m) {
                (Some([i, j]), _) => grid.index(i, j),
                (None, Some([x, y])) => (0..grid.len())
                    .filter(|&p| !absent[p])
                    .min_by(|&a, &b| {
                        let d = |p: usize| (x0[p].x - x).powi(2) + (x0[p].y - y).powi(2);
                        d(a).total_cmp(&d(b))
                    })
                    .expect("a sheet has particles"),
                (None, None) => unreachable!("validated scene"),
            };
            let d = Vector3::from(l.direction).normalize();
            (p, d * l.magnitude_N)
        })
        .collect();
    terms.push(Box::new(crate::physics::PointLoads::forces(loads)));
}

/// The scene's `[[boundary.holds]]` into the per-particle held components.
fn holds(scene: &Scene, grid: &Grid, held: &mut Vec<[bool; 3]>) {
    if scene.boundary.holds.is_empty() {
        return;
    }
    held.resize(grid.len(), [false; 3]);
    for h in &scene.boundary.holds {
        let mut ps: Vec<usize> = h.particles.iter().map(|&[i, j]| grid.index(i, j)).collect();
        for e in &h.edges {
            ps.extend(e.lines(grid).0);
        }
        for p in ps {
            for c in &h.components {
                held[p][c.index()] = true;
            }
        }
    }
}

/// Contact with the scene's obstacles (only when it has some): with `contact.fix_supported`, the
/// particles that start above the top face of a table or pedestal, above the flat top of a body
/// form (a skirt's waist) or above a horizontal top face of a mesh body, are fixed (seed 003 §10.5, §10.7.2.3); with
/// the barrier method every other particle gets the barrier term (the vertical-gap method works in the
/// solver instead, [`crate::simulate`]).
pub(crate) fn contact_terms(scene: &Scene, x0: &[Vector3<f64>], b: &mut ModelBuilder) {
    use crate::obstacle::Obstacle;
    use crate::scene::ContactMethod;
    if scene.obstacles.is_empty() {
        return;
    }
    if scene.contact.fix_supported {
        for (p, x) in x0.iter().enumerate().take(b.fixed.len()) {
            let on_top = scene.obstacles.iter().any(|o| match o {
                Obstacle::Box { .. } | Obstacle::Pedestal { .. } => o.top_at(x.x, x.y).is_some(),
                // A mesh body: over a horizontal top face, starting above it.
                Obstacle::Mesh { .. } => o.flat_top_at(x.x, x.y).is_some_and(|z| x.z >= z),
                // A body form: the part over its flat top (the waist of a skirt).
                Obstacle::Revolution { axis_m, profile_m } => {
                    let top = profile_m[profile_m.len() - 1];
                    ((x.x - axis_m[0]).powi(2) + (x.y - axis_m[1]).powi(2)).sqrt() <= top[1]
                }
                _ => false,
            });
            if on_top {
                b.fixed[p] = true;
            }
        }
    }
    if scene.contact.method == ContactMethod::Barrier {
        let (obstacles, d_hat) = (scene.obstacles.clone(), scene.contact.distance_m);
        b.obstacles(obstacles, d_hat, kappa_gravity(scene));
        if scene.contact.body_edges {
            let edges = crate::physics::BodyEdgeBarrier::new(
                &scene.obstacles,
                &scene_triangles(scene),
                &b.masses,
                &b.fixed,
                (d_hat, kappa_gravity(scene)),
            );
            b.terms
                .extend(edges.map(|t| Box::new(t) as Box<dyn crate::physics::EnergyTerm>));
        }
    }
}

/// The gravity the barriers' κ is set by (a particle's weight at a tenth of the band): the scene's,
/// or the standard one in a scene without gravity (whose contacts are pressed by loads).
fn kappa_gravity(scene: &Scene) -> f64 {
    if scene.gravity.g_m_per_s2 > 0.0 {
        scene.gravity.g_m_per_s2
    } else {
        crate::STANDARD_GRAVITY_M_PER_S2
    }
}

/// The barrier contact term of a scene: every free particle with mass against every obstacle, κ from
/// its weight ([`ObstacleBarrier::kappa_for_weight`](crate::physics::ObstacleBarrier::kappa_for_weight)).
pub fn barrier_contact(
    scene: &Scene,
    masses: &[f64],
    fixed: &[bool],
) -> crate::physics::ObstacleBarrier {
    crate::physics::ObstacleBarrier::for_particles(
        scene.obstacles.clone(),
        scene.contact.distance_m,
        masses,
        fixed,
        kappa_gravity(scene),
    )
}

/// The thickness ξ of the sheet for self-contact, m ([`ContactSpec::self_thickness_m`](crate::scene::ContactSpec::self_thickness_m)):
/// as given, else the material's thickness or 1 mm, at most a fifth of the shortest spacing.
pub fn self_thickness_m(scene: &Scene) -> f64 {
    scene.contact.self_thickness_m.unwrap_or_else(|| {
        let t = scene
            .material
            .continuum
            .as_ref()
            .and_then(|c| c.thickness_m)
            .unwrap_or(1e-3);
        t.min(0.2 * scene.sheet_spacing_m())
    })
}

/// The sheet's triangles (indices of its particles): a mesh's, or the grid's whose three particles
/// are all present. The one source of the sheet's triangles for self-contact, measures and records.
pub fn scene_triangles(scene: &Scene) -> Vec<[u32; 3]> {
    match scene.pattern() {
        Some(p) => p.triangles.iter().map(|t| t.map(|v| v as u32)).collect(),
        None => {
            let absent = absent_particles(scene, &scene.initial_positions());
            sheet_triangles(&scene.grid(), &absent)
        }
    }
}

/// The triangles of the grid whose three particles are all present (not `absent`).
pub fn sheet_triangles(grid: &Grid, absent: &[bool]) -> Vec<[u32; 3]> {
    crate::cloth::grid_triangles(grid)
        .into_iter()
        .filter(|t| t.iter().all(|&v| !absent[v as usize]))
        .collect()
}
