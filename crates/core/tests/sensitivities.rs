//! The sensitivities of an equilibrium against central differences of equilibria, for every
//! continuous key of the scenes the derivative issue names (hang4, hang2, the cantilever, a table
//! with obstacle contact, a sheet in self-contact), and the adjoint against the sensitivities.

use drapelab_core::params::{continuous_keys, free_keys, value, with_value};
use drapelab_core::physics::EnergyTerm;
use drapelab_core::scene::{Scene, ValidatedScene};
use drapelab_core::sensitivity::{Equilibrium, NoSensitivity, mean_height_gradient};
use drapelab_core::simulate::{Solution, solve_scene, solve_scene_from};
use drapelab_core::solve::NoFactor;
use drapelab_core::solve::NoObserver;
use nalgebra::Vector3;

/// Relative tolerance of the issue: 2-norm over particles.
const TOL_REL: f64 = 1e-4;
/// The relative step of the reference's central difference of equilibria: 10⁻⁵, because the limp
/// sheet over the table's edge is so nonlinear in `cloth.origin_m.1` that at 10⁻⁴ the difference
/// itself is 3·10⁻⁴ off (3·10⁻⁶ at 10⁻⁵, converging as h²).
const FD_STEP_REL: f64 = 1e-5;

/// A bundled scene with overrides, solved to 1e-12 of a particle's weight (or the round-off floor)
/// so that the reference's differences of equilibria resolve 1e-4 of the sensitivity.
fn load(name: &str, set: &[(&str, toml::Value)]) -> ValidatedScene {
    load_tol(name, set, 1e-12)
}

fn load_tol(name: &str, set: &[(&str, toml::Value)], tol: f64) -> ValidatedScene {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(format!("../../datasets/scenes/{name}.toml"));
    let mut o: Vec<(String, toml::Value)> = set
        .iter()
        .map(|(k, v)| (k.to_string(), v.clone()))
        .collect();
    o.push((
        "solver.static.residual_tol_rel".into(),
        toml::Value::Float(tol),
    ));
    Scene::load(&path, &o).unwrap().scene
}

fn solved(scene: &ValidatedScene) -> Solution {
    let s = solve_scene(scene, &mut NoObserver);
    assert!(
        s.report.is_converged(),
        "{}: {}",
        scene.name,
        s.report.message
    );
    assert_eq!(s.report.minimum, Some(true), "{}", scene.name);
    s
}

/// dx*/dθ by central differences of equilibria solved from x* at θ(1 ± δ), δ = 10⁻⁵, or 10⁻⁶ and
/// 10⁻⁷ where a neighbour's solve stalls (the self-contact drapes' known stalls, issue 47): the
/// reference itself, not the sensitivity, is what fails there.
fn central_difference(scene: &ValidatedScene, sol: &Solution, key: &str) -> Vec<Vector3<f64>> {
    central_difference_at(scene, sol, key, FD_STEP_REL)
}

/// The equilibrium of `scene` (a neighbour of the solved one) from x*, with the pinned particles
/// where the changed scene puts them and the barriers' κ held where the solve of x* left it: the
/// sensitivity is that of the solved model, whose self-contact κ the static solve may have doubled
/// (IPC's adaptive κ), so the neighbours hold that κ and do not adapt it.
fn neighbour(scene: &ValidatedScene, sol: &Solution) -> Option<Vec<Vector3<f64>>> {
    let mut b = drapelab_core::build::build_scene(scene);
    let growth = sol
        .model
        .self_contact(&sol.x)
        .map_or(1.0, |s| s.kappa_growth);
    if let Some(t) = b.model.self_contact_term_mut() {
        let mut c = t.coefficients();
        c[2] *= growth;
        t.set_coefficients(&c);
    }
    let mut x: Vec<Vector3<f64>> = (0..sol.x.len())
        .map(|p| if b.model.fixed[p] { b.x0[p] } else { sol.x[p] })
        .collect();
    // Lagged friction's stages share one iteration budget; a neighbour at μ = 10⁻⁶ of a
    // frictionless drape re-ramps its load from the drape (20 increments), so it gets ten times
    // the scene's.
    let held = drapelab_core::solve::StaticOptions {
        kappa_adapt_gap_rel: 0.0,
        max_iterations: 10 * scene.solver.static_.max_iterations,
        ..scene.solver.static_.clone()
    };
    let r = drapelab_core::simulate::solve_model_warm(
        scene,
        &held,
        &b.grid,
        &mut b.model,
        &mut x,
        Default::default(),
        &mut NoObserver,
    );
    r.is_converged().then_some(x)
}

fn central_difference_at(
    scene: &ValidatedScene,
    sol: &Solution,
    key: &str,
    step: f64,
) -> Vec<Vector3<f64>> {
    let x = &sol.x;
    let theta = value(scene, key, "test").unwrap();
    let at = |t: f64| -> Option<Option<Vec<Vector3<f64>>>> {
        let Ok(s) = with_value(scene, key, t, "test") else {
            return Some(None);
        };
        neighbour(&s, sol).map(Some)
    };
    for rel in [step, 0.1 * step, 0.01 * step] {
        let h = if theta == 0.0 {
            1e-6
        } else {
            rel * theta.abs()
        };
        let (Some(hi), Some(lo)) = (at(theta + h), at(theta - h)) else {
            eprintln!("{key}: a neighbour at ±{rel:e} did not converge; a smaller step");
            continue;
        };
        let (hi, lo, span) = match (hi, lo) {
            (Some(a), Some(b)) => (a, b, 2.0 * h),
            (Some(a), None) => (a, x.to_vec(), h),
            (None, Some(b)) => (x.to_vec(), b, h),
            (None, None) => panic!("{key}: no valid neighbour"),
        };
        return hi.iter().zip(&lo).map(|(a, b)| (a - b) / span).collect();
    }
    panic!("{key}: the neighbouring equilibria do not converge at any step")
}

/// The rigid motions of the sheet that leave the energy unchanged to second order (φᵀHφ below
/// 10⁻⁹ of the Hessian's scale): a sheet held at one point on a frictionless sphere may turn about
/// the vertical through it. Orthonormalized. Along them the equilibrium is not isolated, the
/// sensitivity is the one orthogonal to them, and a difference of equilibria may drift along them.
fn neutral_modes(
    model: &drapelab_core::physics::Model,
    x: &[Vector3<f64>],
) -> Vec<Vec<Vector3<f64>>> {
    let centre = (0..x.len())
        .find(|&p| model.fixed[p])
        .map_or(Vector3::zeros(), |p| x[p]);
    let mut h = drapelab_core::physics::HessianBlocks::default();
    model.hessian(x, &mut h, drapelab_core::physics::HessianMode::Exact);
    let scale = h.diagonal(x.len()).iter().map(|b| b.trace()).sum::<f64>() / (3 * x.len()) as f64;
    let mut modes: Vec<Vec<Vector3<f64>>> = Vec::new();
    for axis in 0..6 {
        let e = Vector3::ith(axis % 3, 1.0);
        let mut phi: Vec<Vector3<f64>> = x
            .iter()
            .enumerate()
            .map(|(p, y)| {
                if model.fixed[p] {
                    Vector3::zeros()
                } else if axis < 3 {
                    e
                } else {
                    e.cross(&(y - centre))
                }
            })
            .collect();
        for m in &modes {
            let a = dot_all(&phi, m);
            for (p, q) in phi.iter_mut().zip(m) {
                *p -= q * a;
            }
        }
        let n = norm(&phi);
        if n == 0.0 {
            continue;
        }
        phi.iter_mut().for_each(|p| *p /= n);
        let mut hphi = vec![Vector3::zeros(); x.len()];
        h.mul_add(&phi, &mut hphi);
        if dot_all(&phi, &hphi) < 1e-9 * scale {
            modes.push(phi);
        }
    }
    modes
}

fn norm(v: &[Vector3<f64>]) -> f64 {
    v.iter().map(|p| p.norm_squared()).sum::<f64>().sqrt()
}

/// Every continuous key of the scene: sensitivity against the central difference. Returns the keys
/// checked. A key that changes the model's structure must be reported as such, never guessed.
fn check_every_key(scene: &ValidatedScene) -> Vec<String> {
    check_keys_of(scene, &solved(scene))
}

/// [`check_every_key`] at the solved equilibrium `sol` of `scene`. A key that pushes the drape
/// along a neutral turn the scene allows (a pin moved off the sphere's axis) is refused as not
/// isolated; only where the scene has such a turn.
fn check_keys_of(scene: &ValidatedScene, sol: &Solution) -> Vec<String> {
    let mut eq = Equilibrium::new(scene, &sol.model, &sol.x, &sol.report, "test").unwrap();
    let neutral = neutral_modes(&sol.model, &sol.x);
    if !neutral.is_empty() {
        eprintln!(
            "{}: {} neutral rigid motions left out of the comparison",
            scene.name,
            neutral.len()
        );
    }
    let mut checked = Vec::new();
    for key in free_keys(scene) {
        let s = match eq.sensitivity(&key) {
            Ok(s) => s,
            Err(NoSensitivity::Structural(_)) => {
                eprintln!(
                    "{}: {key} changes the model's structure: no sensitivity",
                    scene.name
                );
                continue;
            }
            Err(NoSensitivity::NotIsolated(_, r)) if !neutral.is_empty() => {
                eprintln!(
                    "{}: {key} pushes along the neutral turn (residual {r:.1e}): refused",
                    scene.name
                );
                continue;
            }
            Err(e) => panic!("{}: {key}: {e}", scene.name),
        };
        // The reference trades truncation (a strongly nonlinear key) for the solver's round-off (a
        // key the drape barely feels): a correct sensitivity agrees at one of three steps.
        let theta = s.value.abs().max(1e-300);
        let mut misses = Vec::new();
        for step in [
            FD_STEP_REL,
            0.1 * FD_STEP_REL,
            10.0 * FD_STEP_REL,
            100.0 * FD_STEP_REL,
        ] {
            let fd = central_difference_at(scene, sol, &key, step);
            let mut diff: Vec<Vector3<f64>> =
                s.dx.iter().zip(&fd).map(|(a, b)| (a - b) * theta).collect();
            for m in &neutral {
                let a = dot_all(&diff, m);
                diff.iter_mut().zip(m).for_each(|(p, q)| *p -= q * a);
            }
            let scale = norm(&fd) * theta;
            // Keys the equilibrium does not depend on (dynamics-only damping) differ from zero by
            // the solver's tolerance over the step only: 1e-9 m per particle.
            let floor = 1e-9 * (sol.x.len() as f64).sqrt();
            if norm(&diff) <= TOL_REL * scale + floor {
                misses.clear();
                break;
            }
            misses.push(format!(
                "step {step:e}: |sensitivity − fd| = {:.3e} m, |fd| = {scale:.3e} m",
                norm(&diff)
            ));
        }
        assert!(
            misses.is_empty(),
            "{}: {key} (per unit relative change): {}",
            scene.name,
            misses.join("; ")
        );
        checked.push(key);
    }
    eprintln!("{}: keys checked {checked:?}", scene.name);
    checked
}

#[test]
fn hang4_sensitivities_match_central_differences_for_every_key() {
    let keys = check_every_key(&load("hang4", &[]));
    for k in [
        "material.mass_spring.stiffness_N_per_m",
        "cloth.areal_density_kg_per_m2",
        "gravity.g_m_per_s2",
        "cloth.size_x_m",
        "cloth.size_y_m",
    ] {
        assert!(keys.iter().any(|c| c == k), "{k} not covered: {keys:?}");
    }
}

#[test]
fn hang2_sensitivities_match_central_differences_for_every_key() {
    let keys = check_every_key(&load("hang2", &[]));
    assert!(
        keys.iter()
            .any(|c| c == "material.mass_spring.stiffness_N_per_m")
    );
}

#[test]
fn cantilever_sensitivities_match_central_differences_for_every_key() {
    let keys = check_every_key(&load_tol("cantilever_wool_warp", &[], 1e-11));
    for k in [
        "material.continuum.bending_warp_gf_cm2_per_cm",
        "material.continuum.tensile_warp_gf_per_cm",
        "cloth.areal_density_kg_per_m2",
    ] {
        assert!(keys.iter().any(|c| c == k), "{k} not covered: {keys:?}");
    }
}

#[test]
fn table_contact_sensitivities_match_central_differences_for_every_key() {
    let scene = load(
        "table_wool",
        &[
            ("cloth.nx", toml::Value::Integer(21)),
            ("cloth.ny", toml::Value::Integer(21)),
        ],
    );
    let keys = check_every_key(&scene);
    for k in ["contact.distance_m", "obstacles.0.max_m.2"] {
        assert!(keys.iter().any(|c| c == k), "{k} not covered: {keys:?}");
    }
}

/// The table as a mesh body (issue 77): its offset is a parameter like the analytic table's
/// corners, and the drape's derivative in it matches differences of drapes; also with the sheet's
/// edges kept off the table's rim (`contact.body_edges`, at 9 × 9 where the rim would cut the
/// sheet's edges without it), whose term's derivative in a key is the difference of its rebuilt
/// gradients.
#[test]
fn a_mesh_body_offset_has_the_sensitivity_of_differences_of_drapes() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../datasets/bodies/table_wool_mesh.toml");
    for (n, body_edges) in [(21, false), (9, true)] {
        let o = [
            ("cloth.nx", toml::Value::Integer(n)),
            ("cloth.ny", toml::Value::Integer(n)),
            ("solver.static.residual_tol_rel", toml::Value::Float(1e-12)),
            ("contact.body_edges", toml::Value::Boolean(body_edges)),
        ];
        let o: Vec<(String, toml::Value)> =
            o.iter().map(|(k, v)| (k.to_string(), v.clone())).collect();
        let scene = Scene::load(&path, &o).unwrap().scene;
        let sol = solved(&scene);
        let edge_terms = sol
            .model
            .term_names()
            .iter()
            .filter(|t| t.contains("edge"))
            .count();
        assert_eq!(edge_terms > 0, body_edges, "{:?}", sol.model.term_names());
        let keys = check_keys_of(&scene, &sol);
        for k in ["obstacles.0.offset_m.2", "contact.distance_m"] {
            assert!(keys.iter().any(|c| c == k), "{k}: {keys:?}");
        }
    }
}

#[test]
fn the_adjoint_gradient_equals_the_sensitivity_contracted_with_dj_dx() {
    let scene = load_tol("cantilever_wool_warp", &[], 1e-11);
    let sol = solved(&scene);
    let mut eq = Equilibrium::new(&scene, &sol.model, &sol.x, &sol.report, "test").unwrap();
    let dj = mean_height_gradient(&sol.model);
    let keys = [
        "material.continuum.bending_warp_gf_cm2_per_cm",
        "cloth.areal_density_kg_per_m2",
        "cloth.size_x_m",
    ];
    let adjoint = eq.gradient(&dj, &keys).unwrap();
    for (k, a) in keys.iter().zip(&adjoint) {
        let s = eq.sensitivity(k).unwrap();
        let direct: f64 = s.dx.iter().zip(&dj).map(|(d, j)| d.dot(j)).sum();
        assert!(
            (a - direct).abs() <= 1e-9 * direct.abs().max(1e-300),
            "{k}: adjoint {a}, contracted {direct}"
        );
        assert!(direct != 0.0, "{k}");
    }
    // Heavier sags lower; a stiffer strip sags less.
    assert!(adjoint[0] > 0.0 && adjoint[1] < 0.0, "{adjoint:?}");
}

#[test]
fn an_unconverged_state_has_no_sensitivities() {
    let scene = load(
        "hang4",
        &[("solver.static.max_iterations", toml::Value::Integer(1))],
    );
    let sol = solve_scene(&scene, &mut NoObserver);
    assert!(!sol.report.is_converged());
    let e = Equilibrium::new(&scene, &sol.model, &sol.x, &sol.report, "test").err();
    assert!(
        matches!(e, Some(NoSensitivity::NoFactor(_))),
        "{:?}",
        e.map(|e| e.to_string())
    );
}

#[test]
fn self_contact_sensitivities_match_central_differences_for_every_key() {
    // The limp sheet around its table folds onto itself: 167 pairs within the self-contact band at
    // its 11 × 11 drape, beside the table's barrier.
    let scene = load_tol(
        "table_limp_hanging",
        &[
            ("cloth.nx", toml::Value::Integer(11)),
            ("cloth.ny", toml::Value::Integer(11)),
        ],
        1e-10,
    );
    let sol = solved(&scene);
    let active = sol.model.self_contact(&sol.x).map_or(0, |s| s.active_pairs);
    assert!(active > 100, "{active} pairs in contact");
    let keys = check_every_key(&scene);
    for k in [
        "material.continuum.thickness_m",
        "contact.distance_m",
        "material.continuum.bending_warp_gf_cm2_per_cm",
        "cloth.areal_density_kg_per_m2",
    ] {
        assert!(keys.iter().any(|c| c == k), "{k} not covered: {keys:?}");
    }
}

#[test]
fn an_equilibrium_free_to_turn_has_the_sensitivity_orthogonal_to_the_turn() {
    // Held at its centre on a frictionless sphere, the wool sheet may turn about the vertical (188
    // self-contact pairs in the band at 21 × 21): its equilibria form a family, the neighbouring
    // equilibria drift along it, and the sensitivity is the one orthogonal to the turn.
    let scene = load_tol(
        "sphere_wool",
        &[
            ("cloth.nx", toml::Value::Integer(21)),
            ("cloth.ny", toml::Value::Integer(21)),
        ],
        1e-10,
    );
    let sol = solved(&scene);
    let neutral = neutral_modes(&sol.model, &sol.x);
    assert_eq!(neutral.len(), 1);
    let mut eq = Equilibrium::new(&scene, &sol.model, &sol.x, &sol.report, "test").unwrap();
    for key in [
        "cloth.areal_density_kg_per_m2",
        "material.continuum.thickness_m",
    ] {
        let s = eq.sensitivity(key).unwrap();
        let fd = central_difference(&scene, &sol, key);
        let mut diff: Vec<Vector3<f64>> = s.dx.iter().zip(&fd).map(|(a, b)| a - b).collect();
        for m in &neutral {
            let a = dot_all(&diff, m);
            diff.iter_mut().zip(m).for_each(|(p, q)| *p -= q * a);
        }
        assert!(
            norm(&diff) <= TOL_REL * norm(&fd),
            "{key}: {:e} of {:e}",
            norm(&diff),
            norm(&fd)
        );
    }
}

fn dot_all(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
    a.iter().zip(b).map(|(p, q)| p.dot(q)).sum()
}

#[test]
fn cusick_specimen_sensitivities_match_central_differences_for_every_key() {
    // The Cusick disc over its own parameters (bending length, anisotropy, saturation, warp angle,
    // natural curl, areal density, tensile rigidity, gravity): an orthotropic, saturating drape on the pedestal's
    // barrier, solved to 1e-12 of a vertex's weight, each key's sensitivity against the central
    // difference of drapes solved from x* at θ(1 ± δ).
    use drapelab_core::cusick::{
        DiscMesh, DrapeParams, SPECIMEN_KEYS, SpecimenParameters, Tester, drape_model, drape_start,
        polar_disc,
    };
    use drapelab_core::params::Parameterized;
    use drapelab_core::solve::{StaticOptions, solve_static};
    let tester = Tester::default();
    let (rest, tris) = polar_disc(tester.specimen_radius_m, 8);
    let mesh = DiscMesh {
        rest_xy: &rest,
        triangles: &tris,
    };
    let params = DrapeParams {
        bending_ratio: 2.0,
        warp_angle_deg: 20.0,
        bending_saturation: Some(3.0),
        curl_per_m: Some(6.0),
        self_thickness_m: None,
        ..DrapeParams::default()
    };
    let opts = StaticOptions {
        residual_tol_rel: 1e-12,
        max_iterations: 2000,
        ..StaticOptions::default()
    };
    let solve_from = |p: &DrapeParams, start: &[Vector3<f64>], tol: f64| {
        let mut model = drape_model(mesh, p, &tester);
        let mut x = start.to_vec();
        let opts = StaticOptions {
            residual_tol_rel: tol,
            ..opts.clone()
        };
        let r = solve_static(&mut model, &mut x, &opts, &mut NoObserver);
        (model, x, r)
    };
    let (model, x, report) = solve_from(&params, &drape_start(mesh, &params, &tester), 1e-12);
    assert!(report.is_converged(), "{}", report.message);
    let specimen = SpecimenParameters {
        mesh,
        params: params.clone(),
        tester: &tester,
    };
    let keys = specimen.keys();
    let mut eq = Equilibrium::of(Box::new(specimen), &model, &x, &report).unwrap();
    for key in &keys {
        let s = eq.sensitivity(key).unwrap_or_else(|e| panic!("{key}: {e}"));
        let theta = s.value;
        let h = FD_STEP_REL * theta.abs();
        let side = |t: f64| {
            let mut p = params.clone();
            match key.as_str() {
                "bending_length_m" => p.bending_length_m = t,
                "areal_density_kg_per_m2" => p.areal_density_kg_per_m2 = t,
                "tensile_N_per_m" => p.tensile_N_per_m = t,
                "gravity_m_per_s2" => p.gravity_m_per_s2 = t,
                "bending_ratio" => p.bending_ratio = t,
                "bending_saturation" => p.bending_saturation = Some(t),
                "warp_angle_deg" => p.warp_angle_deg = t,
                "curl_per_m" => p.curl_per_m = Some(t),
                other => panic!("{other} is not set by this test"),
            }
            // From x*, to 1e-9 of a vertex's weight: the disc's residual can stall at 5e-10 (bending_ratio
            // 1.99998), a few times its round-off floor estimate; δx ~ 1e-12 m.
            let (_, y, r) = solve_from(&p, &x, 1e-9);
            assert!(r.is_converged(), "{key} at {t}: {}", r.message);
            y
        };
        let (hi, lo) = (side(theta + h), side(theta - h));
        let fd: Vec<Vector3<f64>> = hi
            .iter()
            .zip(&lo)
            .map(|(a, b)| (a - b) / (2.0 * h))
            .collect();
        let diff: Vec<Vector3<f64>> = s.dx.iter().zip(&fd).map(|(a, b)| a - b).collect();
        let floor = 1e-9 * (x.len() as f64).sqrt() / (theta.abs() * FD_STEP_REL);
        assert!(
            norm(&diff) <= TOL_REL * norm(&fd) + floor,
            "{key}: |sensitivity − fd| = {:.3e}, |fd| = {:.3e} (m per unit)",
            norm(&diff),
            norm(&fd)
        );
    }
    for k in SPECIMEN_KEYS.iter().filter(|k| **k != "self_thickness_m") {
        assert!(keys.iter().any(|c| c == k), "{k} not covered: {keys:?}");
    }
    eprintln!("cusick specimen: keys checked {keys:?}");
}

#[test]
fn the_equilibrium_energys_derivative_is_the_envelope_theorems() {
    // dE*/dθ = ∂E/∂θ at x* (plus the pins' forces along their motion): at a minimum the drape's own
    // motion does no work. Against the central difference of equilibrium energies for every key of
    // hang4 (kernels only) and of the table drape (obstacle barrier: its differences of energy).
    for scene in [
        load("hang4", &[]),
        load(
            "table_wool",
            &[
                ("cloth.nx", toml::Value::Integer(21)),
                ("cloth.ny", toml::Value::Integer(21)),
            ],
        ),
    ] {
        let sol = solved(&scene);
        let mut eq = Equilibrium::new(&scene, &sol.model, &sol.x, &sol.report, "test").unwrap();
        let mut checked = 0;
        for key in continuous_keys(&scene) {
            let Ok(s) = eq.sensitivity(&key) else {
                continue;
            };
            let theta = s.value;
            let h = FD_STEP_REL * theta.abs().max(1e-3);
            let energy = |t: f64| -> Option<f64> {
                let changed = with_value(&scene, &key, t, "test").ok()?;
                let b = drapelab_core::build::build_scene(&changed);
                let start: Vec<Vector3<f64>> = (0..sol.x.len())
                    .map(|p| if b.model.fixed[p] { b.x0[p] } else { sol.x[p] })
                    .collect();
                let r = solve_scene_from(&changed, &start, &mut NoObserver);
                r.report.is_converged().then_some(r.report.energy_J)
            };
            let (Some(hi), Some(lo)) = (energy(theta + h), energy(theta - h)) else {
                continue;
            };
            let fd = (hi - lo) / (2.0 * h);
            // The energies' own round-off: 1e-14 of the energy over the step.
            let floor = 1e-14 * sol.report.energy_J.abs() / h;
            assert!(
                (s.d_energy - fd).abs() <= 1e-5 * fd.abs() + floor,
                "{}: {key}: dE*/dθ {:.6e} against {fd:.6e} J per unit",
                scene.name,
                s.d_energy
            );
            checked += 1;
        }
        eprintln!("{}: {checked} keys' dE*/dθ checked", scene.name);
        assert!(checked >= 4, "{}: only {checked} keys", scene.name);
    }
}

/// The overrides of the sweep's reference for the static scene at `path`: its grid at 11 × 11 (or
/// its own size if smaller), a pattern at its file's resolution, solved to `tol`; none for a
/// dynamic scene or one that does not load.
fn sweep_overrides(path: &std::path::Path, tol: f64) -> Option<Vec<(String, toml::Value)>> {
    let plain = Scene::load(path, &[]).ok()?;
    let s = &plain.scene;
    if s.solver.kind != drapelab_core::scene::SolverKind::Static {
        return None;
    }
    let mut o = vec![(
        "solver.static.residual_tol_rel".to_string(),
        toml::Value::Float(tol),
    )];
    if !s.cloth.is_mesh() {
        o.push((
            "cloth.nx".into(),
            toml::Value::Integer(s.cloth.nx.min(11) as i64),
        ));
        o.push((
            "cloth.ny".into(),
            toml::Value::Integer(s.cloth.ny.min(11) as i64),
        ));
    } else if s.cloth.mesh_refine > 0 {
        o.push(("cloth.mesh_refine".into(), toml::Value::Integer(0)));
    }
    Some(o)
}

/// The sweep's check of one bundled scene: its equilibrium solved to 10⁻¹² of a particle's weight,
/// or 10⁻¹⁰ where 10⁻¹² lies below its round-off floor (the reference tolerance); at a
/// saddle the sensitivities must be refused as not a minimum; else every free key checked. The
/// number of keys checked, or none for a scene the sweep does not take.
fn sweep_scene(path: &std::path::Path) -> Option<(String, usize)> {
    let mut scene = Scene::load(path, &sweep_overrides(path, 1e-12)?)
        .unwrap()
        .scene;
    let mut sol = solve_scene(&scene, &mut NoObserver);
    if !sol.report.is_converged() {
        scene = Scene::load(path, &sweep_overrides(path, 1e-10)?)
            .unwrap()
            .scene;
        sol = solve_scene(&scene, &mut NoObserver);
    }
    assert!(
        sol.report.is_converged(),
        "{}: {}",
        scene.name,
        sol.report.message
    );
    if sol.report.minimum == Some(false) {
        let refused = Equilibrium::new(&scene, &sol.model, &sol.x, &sol.report, "test").err();
        assert_eq!(
            refused,
            Some(NoSensitivity::NoFactor(NoFactor::NotAMinimum)),
            "{}: a saddle's sensitivities must be refused",
            scene.name
        );
        return Some((format!("{}: a saddle, refused", scene.name), 0));
    }
    let keys = check_keys_of(&scene, &sol);
    Some((scene.name.clone(), keys.len()))
}

/// Every bundled scene (datasets/scenes, patterns and bodies, static solves; see
/// [`sweep_overrides`]), every continuous key a scene lets change: the sensitivity against central
/// differences of drapes solved to 10⁻¹² (10⁻¹⁰ where that is below the round-off floor), the
/// neighbours holding the solved barrier stiffness and neutral turns removed; or the key reported
/// as a structural change, a push along a neutral turn, or (at a saddle) every key refused.
/// `cargo test --release -p drapelab-core --test sensitivities -- --nocapture` prints a line per
/// scene (about a minute and a half on 2 cores).
#[test]
fn every_bundled_scenes_sensitivities_match_central_differences() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../datasets");
    let (mut checked, mut failed) = (0, Vec::new());
    for dir in ["scenes", "patterns", "bodies"] {
        let mut files: Vec<_> = std::fs::read_dir(root.join(dir))
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        files.sort();
        for path in files {
            let start = std::time::Instant::now();
            match std::panic::catch_unwind(|| sweep_scene(&path)) {
                Ok(None) => continue,
                Ok(Some((name, keys))) => eprintln!(
                    "SUMMARY {name}: {keys} keys within 1e-4 in {:.1} s",
                    start.elapsed().as_secs_f64()
                ),
                Err(_) => failed.push(path.display().to_string()),
            }
            checked += 1;
        }
    }
    assert!(checked >= 20, "{checked} scenes");
    assert!(failed.is_empty(), "scenes with a key off: {failed:?}");
}
