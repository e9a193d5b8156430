//! Seed 003's contact scenes: no particle inside an obstacle with either contact treatment, the
//! symmetry of the concentric table drape, the limits of the drape coefficient, the rod drape against
//! Table 10.4, and bad obstacle definitions. A failure means contact or the drape measures broke.

use crate::support::scene;
use drapelab::measure::drape_measures;
use drapelab::physics::max_penetration_m;
use drapelab::simulate::solve_scene;
use drapelab::solve::NoObserver;

/// Solves `scene` and asserts that the solve converged.
fn converged(scene: &drapelab::scene::Scene) -> drapelab::simulate::Solution {
    let sol = solve_scene(scene, &mut NoObserver);
    assert!(sol.report.is_converged(), "{}", sol.report.message);
    sol
}

#[test]
fn no_particle_ends_inside_an_obstacle_with_either_contact_treatment() {
    let cases: [(&str, &[&str]); 4] = [
        (
            "sphere_wool.toml",
            &[
                "cloth.nx=21",
                "cloth.ny=21",
                "boundary.pin_particles=[[10, 10]]",
            ],
        ),
        (
            "rod_polyester.toml",
            &[
                "cloth.nx=17",
                "cloth.ny=17",
                "boundary.pin_particles=[[8, 8], [4, 12], [12, 4]]",
            ],
        ),
        ("table_wool.toml", &["cloth.nx=21", "cloth.ny=21"]),
        ("pedestal_wool.toml", &["cloth.nx=21", "cloth.ny=21"]),
    ];
    for (file, sets) in cases {
        for method in ["barrier", "vertical-gap"] {
            let mut all = sets.to_vec();
            let m = format!("contact.method=\"{method}\"");
            all.push(&m);
            let s = scene(file, &all);
            let sol = solve_scene(&s, &mut NoObserver);
            assert!(
                sol.report.is_converged(),
                "{file} {method}: {}",
                sol.report.message
            );
            let pen = max_penetration_m(&s.obstacles, sol.grid_positions());
            eprintln!(
                "{file} {method}: penetration {pen:.2e} m, lowest z {:.4} m, {} iterations",
                sol.grid_positions()
                    .iter()
                    .map(|p| p.z)
                    .fold(f64::INFINITY, f64::min),
                sol.report.iterations
            );
            assert!(pen < 1e-6, "{file} {method}: penetration {pen} m");
            // With the barrier the sheet drapes: something falls well below where it started. (The
            // vertical-gap contact is sticky: a node that reaches a sphere, or a pedestal's side, is
            // pulled up onto the top and held, so there it need not drape far.)
            if method == "vertical-gap" {
                continue;
            }
            let low = sol
                .grid_positions()
                .iter()
                .map(|p| p.z)
                .fold(f64::INFINITY, f64::min);
            assert!(low < -0.02, "{file} {method}: lowest z {low}");
        }
    }
}

#[test]
fn the_concentric_table_drape_is_symmetric_in_the_full_model() {
    // x → −x and y → −y are symmetries of the scene (warp along x, weft along y): the drape must
    // keep them within 0.1 mm.
    let s = scene("table_wool.toml", &[]);
    let sol = converged(&s);
    let n = s.cloth.nx;
    let (mut ex, mut ey) = (0.0f64, 0.0f64);
    for j in 0..n {
        for i in 0..n {
            let (p, q, r) = (sol.at(i, j), sol.at(n - 1 - i, j), sol.at(i, n - 1 - j));
            ex = ex
                .max((p.x + q.x).abs())
                .max((p.y - q.y).abs())
                .max((p.z - q.z).abs());
            ey = ey
                .max((p.x - r.x).abs())
                .max((p.y + r.y).abs())
                .max((p.z - r.z).abs());
        }
    }
    eprintln!("largest mirror differences: x {ex:.2e} m, y {ey:.2e} m");
    assert!(ex < 1e-4 && ey < 1e-4, "x {ex} y {ey}");
    // The edge midpoint drops by about the seed's 4.57 cm (Table 10.2, point 1), within 1 cm.
    let drop = -sol.at(n / 2, n - 1).z * 100.0;
    assert!((drop - 4.57).abs() < 1.0, "edge midpoint drop {drop} cm");
}

#[test]
fn the_drape_coefficient_is_100_for_a_flat_sheet_and_0_for_one_hanging_straight_down() {
    // DC = (S − S_s)/(S_f − S_s): a very stiff disc stays flat on its pedestal (S = S_f), a limp
    // sheet on a table hangs straight down around it (S ≈ S_s).
    let flat = scene(
        "pedestal_wool.toml",
        &[
            "material.continuum.bending_warp_gf_cm2_per_cm=10000",
            "material.continuum.bending_weft_gf_cm2_per_cm=10000",
        ],
    );
    let sol = converged(&flat);
    let m = drape_measures(&flat, &sol.x);
    let dc = m.drape_coefficient_pct.unwrap();
    assert!((dc - 100.0).abs() < 1.0, "flat: DC {dc} %");
    assert_eq!(m.folds, Some(0));
    let limp = scene(
        "table_wool.toml",
        &[
            "cloth.nx=31",
            "cloth.ny=31",
            "material.continuum.bending_warp_gf_cm2_per_cm=0.0001",
            "material.continuum.bending_weft_gf_cm2_per_cm=0.0001",
            "material.continuum.shear_gf_per_cm=0.01",
        ],
    );
    let sol = converged(&limp);
    let dc = drape_measures(&limp, &sol.x).drape_coefficient_pct.unwrap();
    assert!(dc.abs() < 5.0, "hanging: DC {dc} %");
    // And the wool between them, with folds.
    let wool = scene("pedestal_wool.toml", &[]);
    let sol = solve_scene(&wool, &mut NoObserver);
    let m = drape_measures(&wool, &sol.x);
    let dc = m.drape_coefficient_pct.unwrap();
    eprintln!("wool on the pedestal: DC {dc:.1} %, {:?} folds", m.folds);
    assert!(dc > 10.0 && dc < 90.0 && m.folds.unwrap() >= 4, "{m:?}");
}

#[test]
fn the_rod_drape_hangs_corner_a_near_the_experiment_of_table_10_4() {
    // Table 10.4: corner A from (10, 10, 0) cm to (3.27, 3.27, 12.25) cm in the experiment; the
    // finite-element prediction (2.70, 2.70, 12.56) is 0.86 cm from it, seed 003's own 0.58 cm.
    // Two contact treatments, seed 003's sticky vertical gap and the barrier with lagged Coulomb
    // friction, must agree on where the corner hangs once the grid resolves the fold (41 × 41:
    // measured 0.01 cm apart); both land within 2 cm of the experiment (the must-show "closer than
    // the finite elements" is NOT met: README, Status, and reports/seed003.md).
    let grid = [
        "cloth.nx=41",
        "cloth.ny=41",
        "boundary.pin_particles=[[20, 20], [10, 30], [30, 10]]",
    ];
    let corner = |method: &str| {
        let s = scene("rod_polyester.toml", &[&grid[..], &[method]].concat());
        let sol = converged(&s);
        assert!(max_penetration_m(&s.obstacles, sol.grid_positions()) < 1e-6);
        let n = s.cloth.nx;
        (sol.at(n - 1, n - 1) * 100.0, sol.at(0, 0) * 100.0)
    };
    let (friction, _) = corner("contact.friction_coefficient=0.3");
    let (a, b) = corner("contact.method=\"vertical-gap\"");
    let dist = ((a.x - 3.27).powi(2) + (a.y - 3.27).powi(2) + (-a.z - 12.25).powi(2)).sqrt();
    eprintln!(
        "corner A at ({:.2}, {:.2}, {:.2}) cm, {dist:.2} cm from the experiment; with friction ({:.2}, {:.2}, {:.2}) cm",
        a.x, a.y, -a.z, friction.x, friction.y, -friction.z
    );
    assert!(
        (a - friction).norm() < 0.05,
        "the treatments disagree: {a:?} {friction:?} cm"
    );
    assert!(dist < 2.0, "{dist} cm");
    // The drape keeps the scene's 180° symmetry about the vertical: B mirrors A.
    assert!(
        (a + b).xy().norm() < 0.01 && (a.z - b.z).abs() < 0.01,
        "{a:?} {b:?}"
    );
}

#[test]
fn with_the_finite_elements_material_the_rod_drape_lands_on_their_prediction() {
    // Deng (1994) solved the rod with isotropic shells carrying the warp rigidity in every direction;
    // given that material (D_weft = D_twist = D_warp = 0.322 gf cm²/cm), drapelab's friction drape
    // on the seed's 33 × 33 grid must put corner A where the finite elements do, (2.70, 2.70, 12.56)
    // cm, within 3 mm (measured 1.7 mm; 2.0 mm on 41 × 41 and 49 × 49): two discretisations of one
    // plate agree, which places the gap to the experiment in the material, not the solver.
    let s = scene(
        "rod_polyester.toml",
        &[
            "contact.friction_coefficient=0.3",
            "material.continuum.bending_weft_gf_cm2_per_cm=0.322",
            "material.continuum.bending_twist_gf_cm2_per_cm=0.322",
        ],
    );
    let sol = converged(&s);
    let n = s.cloth.nx;
    let a = sol.at(n - 1, n - 1) * 100.0;
    let d = ((a.x - 2.70).powi(2) + (a.y - 2.70).powi(2) + (-a.z - 12.56).powi(2)).sqrt();
    eprintln!(
        "corner A ({:.2}, {:.2}, {:.2}) cm, {d:.2} cm from the finite elements",
        a.x, a.y, -a.z
    );
    assert!(d < 0.3, "{d} cm");
    // Isotropic material and a symmetric scene: corner A stays on the diagonal x = y.
    assert!((a.x - a.y).abs() < 0.02, "{a:?}");
}

#[test]
fn bad_obstacles_exit_2_naming_the_key() {
    crate::support::assert_bad_edits(
        "simulate",
        "datasets/scenes/sphere_wool.toml",
        &[
            (
                "radius_m = 0.05",
                "radius_m = -0.05",
                "obstacles.0.radius_m",
            ),
            (
                "centre_m = [0.0, 0.0, -0.0505]",
                "centre_m = [0.0, 0.0, -0.02]",
                "obstacles.0",
            ),
            ("kind = \"sphere\"", "kind = \"cone\"", "obstacles"),
            (
                "distance_m = 0.001",
                "distance_m = -1.0",
                "contact.distance_m",
            ),
        ],
    );
}

#[test]
fn bad_refined_lines_exit_2_naming_the_key() {
    crate::support::assert_bad_edits(
        "simulate",
        "datasets/scenes/table_wool_quarter.toml",
        &[
            // A line outside the sheet (0 to 10 cm), a non-finite one, and lines on a uniform grid.
            (
                "refine_x_m = [0.05]",
                "refine_x_m = [0.12]",
                "cloth.refine_x_m",
            ),
            (
                "refine_y_m = [0.05]",
                "refine_y_m = [nan]",
                "cloth.refine_y_m",
            ),
            (
                "spacing = \"graded\"",
                "spacing = \"uniform\"",
                "cloth.refine_x_m",
            ),
        ],
    );
}

#[test]
fn the_quarter_table_model_is_an_equilibrium_of_the_full_model_and_matches_table_10_2() {
    let quarter = scene("table_wool_quarter.toml", &[]);
    let q = converged(&quarter);
    // Unfold the quarter (x, y ≥ 0) into the full sheet by the two mirrors (the graded grids match:
    // the full grid's lines mirror the quarter's).
    let full = scene("table_wool.toml", &[]);
    let built = crate::support::built(&full);
    let (nq, nf) = (quarter.cloth.nx, full.cloth.nx);
    assert_eq!(2 * nq - 1, nf);
    let mut x = built.x0.clone();
    for j in 0..nf {
        for i in 0..nf {
            let (qi, qj) = (
                (i as i64 - (nq as i64 - 1)).unsigned_abs() as usize,
                (j as i64 - (nq as i64 - 1)).unsigned_abs() as usize,
            );
            let mut p = q.at(qi, qj);
            if i < nq - 1 {
                p.x = -p.x;
            }
            if j < nq - 1 {
                p.y = -p.y;
            }
            x[built.grid.index(i, j)] = p;
        }
    }
    let mut g = Vec::new();
    built.model.gradient(&x, 1.0, &mut g);
    let r = built.model.max_residual(&g) / built.model.reference_weight();
    eprintln!("full-model residual at the unfolded quarter drape: {r:.2e} of a particle's weight");
    assert!(r < 1e-5, "{r}");
    // The full model, solved from the flat sheet, lands on the same drape.
    let f = converged(&full);
    let gap = f.x[..built.grid.len()]
        .iter()
        .zip(&x)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    eprintln!("full against unfolded quarter: largest gap {gap:.2e} m");
    assert!(gap < 1e-4, "{gap} m");
    // Table 10.2: the edge points of seed 003's quarter model (cm; z is the drop), within 1 mm on
    // the seed's graded grid (measured 0.1–0.6 mm).
    let table = [
        (0, 20, 0.0, 6.5289, 4.5662),
        (5, 20, 2.4892, 6.7319, 4.5169),
        (10, 20, 4.8289, 7.5258, 4.2028),
        (15, 20, 6.9641, 8.7134, 3.6763),
        (20, 20, 9.3813, 9.2186, 3.6625),
        (20, 15, 9.3281, 6.8742, 3.0236),
        (20, 10, 8.2324, 4.7471, 3.7170),
        (20, 5, 7.3465, 2.4851, 4.2436),
        (20, 0, 7.1206, 0.0, 4.3385),
    ];
    let mut worst = 0.0f64;
    for (i, j, sx, sy, sz) in table {
        // Material points 5 mm apart along the edges (the seed's points; not all are grid lines of
        // the graded grid).
        let p = q.at_material(i as f64 * 0.005, j as f64 * 0.005) * 100.0;
        let d = ((p.x - sx).powi(2) + (p.y - sy).powi(2) + (-p.z - sz).powi(2)).sqrt();
        eprintln!(
            "point ({i}, {j}): ({:.2}, {:.2}, {:.2}) cm vs ({sx}, {sy}, {sz}): {d:.2} cm",
            p.x, p.y, -p.z
        );
        worst = worst.max(d);
    }
    assert!(worst < 0.1, "worst {worst} cm");
}

#[test]
fn the_skirt_drapes_over_the_body_form_without_entering_it() {
    // A disc skirt held at the waist of a body form of revolution (seed 003 §10.7.2.3): it must hang
    // over the hips, below the waist, outside the form everywhere.
    let s = scene("skirt_wool.toml", &["cloth.nx=31", "cloth.ny=31"]);
    let sol = converged(&s);
    let x = sol.grid_positions();
    assert!(max_penetration_m(&s.obstacles, x) < 1e-6);
    let present: Vec<_> = x
        .iter()
        .zip(&sol.model.masses)
        .filter(|(_, m)| **m > 0.0)
        .map(|(p, _)| *p)
        .collect();
    let low = present.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
    assert!(low < -0.15, "the hem hangs below the hips: lowest z {low}");
    // The hem lies outside the hips' radius (17 cm) wherever it is below them.
    for p in &present {
        if p.z < -0.2 && p.z > -0.35 {
            assert!(p.xy().norm() > 0.165, "{p:?}");
        }
    }
}

#[test]
fn lagged_friction_keeps_the_rod_drape_symmetric_and_outside_the_rod() {
    // Without friction the sheet rolls to one side of the rod (corners A and B differ by cm); with
    // Coulomb friction (μ = 0.3, lagged over 20 load increments) the drape keeps the scene's 180°
    // symmetry about the vertical, and no particle enters the rod.
    let s = scene(
        "rod_polyester.toml",
        &[
            "cloth.nx=17",
            "cloth.ny=17",
            "boundary.pin_particles=[[8, 8], [4, 12], [12, 4]]",
            "contact.friction_coefficient=0.3",
        ],
    );
    let sol = converged(&s);
    assert!(
        sol.terms.iter().any(|t| t == "contact/friction"),
        "{:?}",
        sol.terms
    );
    let n = s.cloth.nx;
    let (a, b) = (sol.at(n - 1, n - 1), sol.at(0, 0));
    eprintln!("corner A {a:?}, corner B {b:?}");
    assert!(
        (a + b).xy().norm() < 1e-4 && (a.z - b.z).abs() < 1e-4,
        "{a:?} {b:?}"
    );
    assert!(a.z < -0.08, "the corners hang: {a:?}");
    assert!(max_penetration_m(&s.obstacles, sol.grid_positions()) < 1e-6);
}

#[test]
fn the_rendered_view_from_above_covers_the_measured_vertical_projection() {
    // Two independent computations of the table drape's vertical projection: the drape-coefficient
    // raster (src/measure.rs) and the shaded rendering seen from straight above (src/edges/render.rs).
    let s = scene("table_wool.toml", &[]);
    let sol = converged(&s);
    let d = drapelab::measure::drape_measures(&s, &sol.x);
    let present = vec![true; sol.grid.len()];
    let px_per_cm = 20.0;
    let img = drapelab::edges::render_view(&sol.grid, &sol.x, &present, 0.0, 90.0, px_per_cm, 5);
    // Background 232, fabric at most 150 grey: a pixel counts when more than half covered.
    let background = img.get_pixel(0, 0).0[0] as f64;
    assert!(background > 200.0);
    let covered = img
        .pixels()
        .filter(|p| (p.0[0] as f64) < (background + 150.0) / 2.0)
        .count() as f64;
    let area_m2 = covered / (px_per_cm * 100.0).powi(2);
    let rel = (area_m2 - d.projected_area_m2).abs() / d.projected_area_m2;
    assert!(
        rel < 0.03,
        "rendered {area_m2} m² against measured {} m²",
        d.projected_area_m2
    );
}

#[test]
fn baraff_witkin_settles_on_the_static_pedestal_drape_with_steps_cut_at_contact() {
    // Baraff–Witkin (one linear solve per step): each step is cut where a particle would enter the
    // obstacle (CCD), and it settles on a static equilibrium: Newton's static solve started where it
    // settled stays there. (The drape folds: which fold pattern a path lands on is its own, so the
    // static solve from the flat sheet may land on another minimum.) Implicit Euler's falls are
    // tested in dynamics.rs.
    let sets = ["cloth.nx=11", "cloth.ny=11"];
    let bw = scene(
        "pedestal_wool.toml",
        &[
            sets[0],
            sets[1],
            "solver.kind=\"baraff-witkin\"",
            "solver.dynamic.dt_s=0.01",
            "solver.dynamic.residual_tol_rel=1e-4",
            "solver.dynamic.speed_tol_m_per_s=1e-5",
        ],
    );
    let bw_sol = converged(&bw);
    assert!(
        bw_sol.report.contact_cut_steps > 0,
        "{}",
        bw_sol.report.message
    );
    assert_eq!(
        max_penetration_m(&bw.obstacles, bw_sol.grid_positions()),
        0.0
    );
    let stat = drapelab::simulate::solve_scene_from(
        &scene("pedestal_wool.toml", &sets),
        &bw_sol.x,
        &mut NoObserver,
    );
    assert!(stat.report.is_converged(), "{}", stat.report.message);
    assert_eq!(stat.report.minimum, Some(true));
    let gap = drapelab::benchmark::distance_to(&bw_sol, &stat);
    assert!(gap < 1e-4, "Baraff–Witkin and static differ by {gap} m");
}

#[test]
fn a_grid_graded_towards_the_table_edge_is_closer_to_the_fine_drape_than_a_uniform_one() {
    // The quarter table drape on the seed's 31 × 31 grid, graded towards the table's edge (Fig. 10.3)
    // and uniform, against a uniform 81 × 81 reference, at the free edges' material points: the
    // graded grid spends its particles where the sheet bends (measured: 0.4 mm against 2.0 mm).
    let graded = scene("table_wool_quarter.toml", &[]);
    assert_eq!(graded.cloth.refine_x_m, vec![0.05]);
    let flat = [
        "cloth.spacing=\"uniform\"",
        "cloth.refine_x_m=[]",
        "cloth.refine_y_m=[]",
    ];
    let uniform = scene("table_wool_quarter.toml", &flat);
    let reference = scene(
        "table_wool_quarter.toml",
        &[&flat[..], &["cloth.nx=81", "cloth.ny=81"]].concat(),
    );
    let r = converged(&reference);
    let error = |s: &drapelab::scene::Scene| {
        let sol = converged(s);
        (0..=20)
            .flat_map(|k| {
                let u = k as f64 * 0.005;
                [(u, 0.1), (0.1, u)]
            })
            .map(|(u, v)| (sol.at_material(u, v) - r.at_material(u, v)).norm())
            .fold(0.0, f64::max)
    };
    let (eg, eu) = (error(&graded), error(&uniform));
    eprintln!("largest edge gap to 81 × 81: graded {eg:.2e} m, uniform {eu:.2e} m");
    assert!(eg < 0.5 * eu, "graded {eg} m, uniform {eu} m");
}
