//! The finite-difference harness of the energy terms: for every bundled scene (on an 11 × 11 grid,
//! at a state a thousandth of the spacing off its drape, so that contact and folds are in play), every term's gradient against
//! central differences of its energy and its exact Hessian (`add_hessian` with `HessianMode::Exact`) against central differences of its
//! gradient, along random directions; and every term's derivatives in its coefficients (the mixed derivative
//! ∂g/∂c and ∂E/∂c the sensitivities are built on), contact's where it is in contact. A term whose derivative
//! is wrong fails here by name.

use drapelab_core::physics::{EnergyTerm, HessianBlocks, HessianMode};
use drapelab_core::scene::Scene;
use drapelab_core::simulate::solve_scene;
use drapelab_core::solve::NoObserver;
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};

/// The bundled scenes: the grid scenes, the patterns read from OBJ (issue 49), then the scenes on
/// mesh bodies (issue 77: the barrier against a triangle mesh, its offset a coefficient).
fn scenes() -> Vec<std::path::PathBuf> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../datasets");
    let mut v = Vec::new();
    for dir in ["scenes", "patterns", "bodies"] {
        let mut d: Vec<_> = std::fs::read_dir(root.join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        d.sort();
        v.extend(d);
    }
    v
}

/// A scene on the harness's 11 × 11 grid, or a pattern as its file has it, with `extra` set.
fn load(
    path: &std::path::Path,
    extra: &[(String, toml::Value)],
) -> Option<drapelab_core::scene::LoadedScene> {
    let mut set = Vec::new();
    if !path.parent().is_some_and(|d| d.ends_with("patterns")) {
        set.push(("cloth.nx".to_string(), toml::Value::Integer(11)));
        set.push(("cloth.ny".to_string(), toml::Value::Integer(11)));
    }
    set.extend(extra.iter().cloned());
    Scene::load(path, &set).ok()
}

fn dot(a: &[Vector3<f64>], b: &[Vector3<f64>]) -> f64 {
    a.iter().zip(b).map(|(p, q)| p.dot(q)).sum()
}

/// The errors of one term at `x` along `v` with step `eps` (m), each relative to its quantity: ∇E·v
/// against the central difference of E, H v against the central difference of ∇E (2-norm). None
/// where the energy is not finite on the stencil (a barrier's step into the thickness).
fn errors(
    t: &dyn EnergyTerm,
    x: &[Vector3<f64>],
    v: &[Vector3<f64>],
    eps: f64,
) -> Option<(f64, f64)> {
    let n = x.len();
    let shifted =
        |s: f64| -> Vec<Vector3<f64>> { x.iter().zip(v).map(|(p, d)| p + d * s).collect() };
    let (xp, xm) = (shifted(eps), shifted(-eps));
    let (ep, em) = (t.energy(&xp), t.energy(&xm));
    if !(ep.is_finite() && em.is_finite() && t.energy(x).is_finite()) {
        return None;
    }
    let grad = |y: &[Vector3<f64>]| {
        let mut g = vec![Vector3::zeros(); n];
        t.add_gradient(y, &mut g);
        g
    };
    let fd = (ep - em) / (2.0 * eps);
    let an = dot(&grad(x), v);
    let e_grad = (fd - an).abs() / fd.abs().max(an.abs()).max(1e-300);
    let mut h = HessianBlocks::default();
    t.add_hessian(x, &mut h, HessianMode::Exact);
    let mut hv = vec![Vector3::zeros(); n];
    h.mul_add(v, &mut hv);
    let (gp, gm) = (grad(&xp), grad(&xm));
    let fdv: Vec<Vector3<f64>> = gp
        .iter()
        .zip(&gm)
        .map(|(a, b)| (a - b) / (2.0 * eps))
        .collect();
    let err: f64 = hv
        .iter()
        .zip(&fdv)
        .map(|(a, b)| (a - b).norm_squared())
        .sum::<f64>()
        .sqrt();
    let size: f64 = fdv.iter().map(|a| a.norm_squared()).sum::<f64>().sqrt();
    Some((e_grad, err / size.max(1e-300)))
}

/// Checks one term: over steps of 10⁻⁴…10⁻⁸ of the spacing, the best agreement (a central
/// difference trades truncation for round-off; a correct derivative agrees at some step: the
/// largest for a linear term such as gravity on a sheet hung far below z = 0, whose energy's
/// round-off is large against its change) is within
/// 10⁻⁶ for the gradient and 10⁻⁵ for the Hessian, self-contact's included (its pairs' exact
/// curvature is analytic: 3·10⁻⁹ at most over the bundled scenes in contact).
fn check_term(
    t: &dyn EnergyTerm,
    x: &[Vector3<f64>],
    v: &[Vector3<f64>],
    spacing: f64,
    scene: &str,
) {
    let best = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8]
        .iter()
        .filter_map(|s| errors(t, x, v, s * spacing))
        .fold((f64::INFINITY, f64::INFINITY), |a, b| {
            (a.0.min(b.0), a.1.min(b.1))
        });
    if best.0.is_infinite() {
        return;
    }
    // A term that is zero along v (a load on one particle, a contact not in play) agrees exactly.
    assert!(
        best.0 <= 1e-6,
        "{scene}: {}: gradient off by {:e} (relative)",
        t.name(),
        best.0
    );
    assert!(
        best.1 <= 1e-5,
        "{scene}: {}: Hessian off by {:e} (relative)",
        t.name(),
        best.1
    );
}

#[test]
fn every_terms_gradient_and_hessian_match_central_differences_in_every_bundled_scene() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(46);
    let mut checked = std::collections::BTreeSet::new();
    let mut in_contact = std::collections::BTreeSet::new();
    // Every bundled scene, the polyester rod with friction (no bundled scene has any).
    let friction = (
        "contact.friction_coefficient".to_string(),
        toml::Value::Float(0.3),
    );
    // And the meshed table with the sheet's edges and faces kept off its rim and corners
    // (`contact.body_edges`, off in every bundled scene).
    let body_edges = ("contact.body_edges".to_string(), toml::Value::Boolean(true));
    let find = |name: &str| scenes().into_iter().find(|p| p.ends_with(name)).unwrap();
    let runs = scenes().into_iter().map(|p| (p, None)).chain([
        (find("rod_polyester.toml"), Some(friction)),
        (find("table_wool_mesh.toml"), Some(body_edges)),
    ]);
    for (path, extra) in runs {
        let mut set = vec![(
            "solver.static.max_iterations".to_string(),
            toml::Value::Integer(150),
        )];
        set.extend(extra);
        let Some(loaded) = load(&path, &set) else {
            continue;
        };
        let name = loaded.scene.name.clone();
        let mut sol = solve_scene(&loaded.scene, &mut NoObserver);
        let spacing = loaded.scene.sheet_spacing_m();
        // Off the equilibrium by a thousandth of the spacing: every spring strained, so that the
        // differences test the derivatives and not a stationary point's round-off.
        let x: Vec<Vector3<f64>> = sol
            .x
            .iter()
            .map(|p| {
                p + (Vector3::new(rng.random(), rng.random(), rng.random()) - Vector3::repeat(0.5))
                    * (2e-3 * spacing)
            })
            .collect();
        for t in &sol.model.terms {
            for _ in 0..3 {
                let v: Vec<Vector3<f64>> = (0..x.len())
                    .map(|_| {
                        Vector3::new(rng.random(), rng.random(), rng.random()) * 2.0
                            - Vector3::repeat(1.0)
                    })
                    .collect();
                check_term(t.as_ref(), &x, &v, spacing, &name);
            }
            checked.insert(t.name());
        }
        // Contact's coefficients (κ, d̂, obstacle shapes, thickness) are checked at the drape, in
        // the barrier's band (off it a particle may be inside); friction off it, where it slips.
        let drape = sol.x.clone();
        for t in sol
            .model
            .terms
            .iter_mut()
            .filter(|t| t.name().contains("contact/"))
        {
            let x = if t.name() == "contact/friction" {
                &x
            } else {
                &drape
            };
            if !t.energy(x).is_finite() {
                continue;
            }
            let c = t.coefficients();
            // A term without coefficients (the body-edge barrier) is differentiated in a key by
            // differences of its rebuilt gradients (sensitivity::mixed_of_term): nothing to check.
            if c.is_empty() {
                continue;
            }
            check_contact_coefficients(t.as_mut(), x, &name, &mut rng);
            let mut g = vec![Vector3::zeros(); x.len()];
            t.add_coefficient_gradient(x, &random_change(&c, &mut rng), &mut g);
            if g.iter().any(|v| v.norm() > 0.0) {
                in_contact.insert(t.name());
            }
        }
    }
    // Both contact terms were checked somewhere in contact (a zero derivative agrees trivially).
    for family in ["contact/barrier", "contact/self", "contact/friction"] {
        assert!(
            in_contact.contains(family),
            "{family} never in contact: {in_contact:?}"
        );
    }
    // The harness saw the terms of every family the scenes use.
    for family in ["gravity", "contact/barrier", "contact/self"] {
        assert!(
            checked.iter().any(|n| n.contains(family)),
            "no {family} term among {checked:?}"
        );
    }
    eprintln!("terms checked: {checked:?}");
}

/// Checks a contact term's derivatives in its coefficients at `x` (see the caller): random changes
/// of all of them and of its last few (band, thickness, obstacle shapes), alone and together.
fn check_contact_coefficients(
    t: &mut dyn EnergyTerm,
    x: &[Vector3<f64>],
    name: &str,
    rng: &mut impl Rng,
) {
    let c = t.coefficients();
    // Random changes of all; each of the last few alone where it is not zero (the band, the
    // thickness: a random change of all is mostly the per-particle κ); and random changes
    // of the last few together (the obstacles' shapes, a zero coordinate by ±1 mm: one
    // alone may move nothing by symmetry, a pedestal's centre along x).
    let tail = c.len().saturating_sub(16);
    let single = |i: usize| -> Vec<f64> {
        let mut d = vec![0.0; c.len()];
        d[i] = c[i];
        d
    };
    let mut changes: Vec<Vec<f64>> = (0..2)
        .map(|_| random_change(&c, rng))
        .chain((tail..c.len()).filter(|&i| c[i] != 0.0).map(single))
        .collect();
    for _ in 0..2 {
        let mut d = random_change(&c, rng);
        for (i, v) in d.iter_mut().enumerate() {
            if i < tail {
                *v = 0.0;
            } else if c[i] == 0.0 {
                *v = 1e-3 * (rng.random::<f64>() * 2.0 - 1.0);
            }
        }
        changes.push(d);
    }
    for dc in changes {
        let (e, e_energy) = coefficient_error(t, x, &dc);
        // A change of the obstacles' shapes alone is differentiated by a central difference of 1 %
        // of each particle's gap: a particle in contact near a vertex of a solid of revolution's
        // profile sees the kink between the segment's and the vertex's regions within that step
        // (5e-4 of the gradient on skirt_form, whose hem rests on the form's hips).
        let shape_only =
            dc[..tail].iter().all(|v| *v == 0.0) && !dc[tail..].iter().all(|v| *v == 0.0);
        let tol = if shape_only { 1e-3 } else { 1e-6 };
        assert!(e <= tol, "{name}: {}: ∂g/∂c off by {e:e}", t.name());
        assert!(
            e_energy <= tol,
            "{name}: {}: ∂E/∂c off by {e_energy:e}",
            t.name()
        );
    }
}

/// The relative errors of a term's mixed derivative ∂g/∂c · dc (2-norm) and of ∂E/∂c · dc at `x`
/// against the central differences of its gradient and energy with the coefficients moved by
/// ±eps dc (each the best over the steps; down to 10⁻⁹, for an obstacle moved by its own size
/// against a particle 10⁻⁵ m from it).
fn coefficient_error(t: &mut dyn EnergyTerm, x: &[Vector3<f64>], dc: &[f64]) -> (f64, f64) {
    let n = x.len();
    let c = t.coefficients();
    let de = t
        .coefficient_energy(x, dc)
        .unwrap_or_else(|| panic!("{}: gives coefficients but no ∂E/∂c", t.name()));
    let mut an = vec![Vector3::zeros(); n];
    assert!(
        t.add_coefficient_gradient(x, dc, &mut an),
        "{}: gives coefficients but no mixed derivative",
        t.name()
    );
    let size = |v: &[Vector3<f64>]| v.iter().map(|a| a.norm_squared()).sum::<f64>().sqrt();
    let (mut best, mut best_e) = (f64::INFINITY, f64::INFINITY);
    let rel = c
        .iter()
        .zip(dc)
        .filter(|(a, d)| a.is_finite() && **a != 0.0 && **d != 0.0)
        .map(|(a, d)| (d / a).abs())
        .fold(0.0, f64::max);
    let e_scale = t.energy(x).abs() * rel;
    let mut g0 = vec![Vector3::zeros(); n];
    t.add_gradient(x, &mut g0);
    let g_scale = size(&g0) * rel;
    for eps in [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9] {
        let grad_at = |t: &mut dyn EnergyTerm, s: f64| -> (Vec<Vector3<f64>>, f64) {
            let moved: Vec<f64> = c
                .iter()
                .zip(dc)
                .map(|(a, d)| if *d == 0.0 { *a } else { a + d * s })
                .collect();
            t.set_coefficients(&moved);
            let mut g = vec![Vector3::zeros(); n];
            t.add_gradient(x, &mut g);
            (g, t.energy(x))
        };
        let ((gp, ep), (gm, em)) = (grad_at(t, eps), grad_at(t, -eps));
        let fde = (ep - em) / (2.0 * eps);
        // Relative to the derivative, or where the coefficients' changes nearly cancel (a cell's
        // dG/G − dh_x/h_x − dh_y/h_y ≈ 0), to a thousandth of the energy's own scale of change.
        let scale = fde.abs().max(de.abs()).max(1e-3 * e_scale).max(1e-300);
        best_e = best_e.min((fde - de).abs() / scale);
        t.set_coefficients(&c);
        let fd: Vec<Vector3<f64>> = gp
            .iter()
            .zip(&gm)
            .map(|(a, b)| (a - b) / (2.0 * eps))
            .collect();
        let diff: Vec<Vector3<f64>> = fd.iter().zip(&an).map(|(a, b)| a - b).collect();
        // Relative to the derivative, or where it vanishes (a body moved along its own flat side:
        // the central difference is the distance's round-off), to 10⁻⁶ of the gradient's own
        // scale of change.
        let scale = size(&fd).max(size(&an)).max(1e-6 * g_scale).max(1e-300);
        best = best.min(size(&diff) / scale);
    }
    (best, best_e)
}

/// Random relative changes of the coefficients (each by up to its own size; none for an infinite one).
fn random_change(c: &[f64], rng: &mut impl Rng) -> Vec<f64> {
    c.iter()
        .map(|v| {
            if v.is_finite() {
                v * (rng.random::<f64>() * 2.0 - 1.0)
            } else {
                0.0
            }
        })
        .collect()
}

#[test]
fn every_terms_derivatives_in_its_coefficients_match_central_differences() {
    // ∂g/∂c · dc and ∂E/∂c · dc of every term that gives coefficients, at a state off the flat sheet (every spring
    // strained, every stencil bent), in every bundled scene; and the saturating hinge bending of the
    // Cusick disc, whose saturation u₀ is a coefficient too. A term whose mixed derivative is wrong
    // fails here by name; the sensitivities (tests/sensitivities.rs) are built on these.
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4646);
    let mut checked = std::collections::BTreeSet::new();
    let mut check = |t: &mut dyn EnergyTerm, x: &[Vector3<f64>], scene: &str, rng: &mut _| {
        let c = t.coefficients();
        if c.is_empty() {
            return;
        }
        for _ in 0..2 {
            let dc = random_change(&c, rng);
            let (e, e_energy) = coefficient_error(t, x, &dc);
            assert!(e <= 1e-6, "{scene}: {}: ∂g/∂c off by {e:e}", t.name());
            assert!(
                e_energy <= 1e-6,
                "{scene}: {}: ∂E/∂c off by {e_energy:e}",
                t.name()
            );
        }
        checked.insert(t.name());
    };
    for path in scenes() {
        let Some(loaded) = load(&path, &[]) else {
            continue;
        };
        let mut built = drapelab_core::build::build_scene(&loaded.scene);
        let spacing = loaded.scene.sheet_spacing_m();
        let x: Vec<Vector3<f64>> = built
            .x0
            .iter()
            .map(|p| {
                p + (Vector3::new(rng.random(), rng.random(), rng.random()) - Vector3::repeat(0.5))
                    * (0.2 * spacing)
            })
            .collect();
        // Contact's coefficients are checked in contact, near the drape (the test above).
        for t in built.model.terms.iter_mut() {
            if t.name().contains("contact/") {
                continue;
            }
            check(t.as_mut(), &x, &loaded.scene.name, &mut rng);
        }
    }
    let (bent, terms) = small_sheet_terms();
    for (mut t, label) in terms {
        check(t.as_mut(), &bent, label, &mut rng);
    }
    for family in [
        "springs",
        "gravity",
        "bending/continuum",
        "bending/hinge",
        "bending/patch",
        "bending/curl",
        "bending/symmetry-plane",
        "shear",
        "twist",
        "point-loads",
    ] {
        assert!(
            checked.iter().any(|n| n.contains(family)),
            "no {family} term among {checked:?}"
        );
    }
    eprintln!("terms checked: {checked:?}");
}

/// A term and the name its check reports.
type Labelled = (Box<dyn EnergyTerm>, &'static str);

/// A small bent sheet and the terms no bundled grid scene has: the Cusick disc's orthotropic,
/// saturating hinge bending and its natural curl, a triangulated grid's patch bending
/// (orthotropic, with a twist rigidity, its warp turned) and a cell's twist.
fn small_sheet_terms() -> (Vec<Vector3<f64>>, Vec<Labelled>) {
    let n = 6;
    let rest: Vec<[f64; 2]> = (0..n * n)
        .map(|k| [(k % n) as f64 * 0.01, (k / n) as f64 * 0.01])
        .collect();
    let id = |i: usize, j: usize| j * n + i;
    let tris: Vec<[usize; 3]> = (0..n - 1)
        .flat_map(|j| (0..n - 1).map(move |i| (i, j)))
        .flat_map(|(i, j)| {
            [
                [id(i, j), id(i + 1, j), id(i + 1, j + 1)],
                [id(i, j), id(i + 1, j + 1), id(i, j + 1)],
            ]
        })
        .collect();
    let hinge =
        drapelab_core::physics::saturating_hinge_bending(&rest, &tris, [2e-5, 1e-5], 0.3, 20.0);
    let bent: Vec<Vector3<f64>> = rest
        .iter()
        .map(|p| Vector3::new(p[0], p[1], 3.0 * p[0] * p[0] + 2.0 * p[0] * p[1]))
        .collect();
    let sheet = drapelab_core::physics::SewnSheet {
        rest: &rest,
        rest_triangles: &tris,
        triangles: &tris,
    };
    let patch = drapelab_core::physics::patch_bending(&sheet, [2e-5, 1e-5, 0.7e-5], 0.3)
        .expect("a grid has patches");
    let curl = drapelab_core::physics::hinge_curl(&sheet, 1.4e-5, -8.0);
    let cells: Vec<[usize; 4]> = (0..n - 1)
        .flat_map(|j| {
            (0..n - 1).map(move |i| [id(i, j), id(i + 1, j), id(i, j + 1), id(i + 1, j + 1)])
        })
        .collect();
    let sides = vec![(0.01, 0.01); cells.len()];
    let twist = drapelab_core::physics::CellTwist::cells(cells, &sides, 3e-6);
    let terms: Vec<Labelled> = vec![
        (Box::new(hinge), "cusick hinge"),
        (Box::new(patch), "patch bending"),
        (Box::new(curl), "curled sheet"),
        (Box::new(twist), "twisted sheet"),
    ];
    (bent, terms)
}

/// The model's Hessian, whose constant terms' blocks are made at the first evaluation and kept
/// ([`HessianBlocks::constant`]), is the sum of every term's own Hessian, at the first evaluation
/// and at another position after it, in both modes.
#[test]
fn the_model_hessian_with_its_constant_part_kept_is_the_sum_of_its_terms() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(47);
    let mut random = |n: usize, scale: f64| -> Vec<Vector3<f64>> {
        (0..n)
            .map(|_| {
                (Vector3::new(rng.random(), rng.random(), rng.random()) * 2.0
                    - Vector3::repeat(1.0))
                    * scale
            })
            .collect()
    };
    let mut kept = 0;
    for path in scenes() {
        let Some(loaded) = load(&path, &[]) else {
            continue;
        };
        let built = drapelab_core::build::build_scene(&loaded.scene);
        let (model, n) = (&built.model, built.x0.len());
        let v = random(n, 1.0);
        for (k, project) in [(0, false), (1, true), (2, false)] {
            let mode = match project {
                true => HessianMode::Projected,
                false => HessianMode::NEWTON,
            };
            let shift = random(n, if k == 0 { 0.0 } else { 1e-5 });
            let x: Vec<Vector3<f64>> = built.x0.iter().zip(&shift).map(|(a, b)| a + b).collect();
            let mut h = HessianBlocks::default();
            model.hessian(&x, &mut h, mode);
            let mut got = vec![Vector3::zeros(); n];
            h.mul_add(&v, &mut got);
            let mut want = vec![Vector3::zeros(); n];
            for t in &model.terms {
                let mut ht = HessianBlocks::default();
                t.add_hessian(&x, &mut ht, mode);
                ht.mul_add(&v, &mut want);
            }
            let size = dot(&want, &want).sqrt();
            if !size.is_finite() {
                continue;
            }
            let diff: Vec<Vector3<f64>> = got.iter().zip(&want).map(|(a, b)| a - b).collect();
            assert!(
                dot(&diff, &diff).sqrt() <= 1e-12 * size,
                "{}: evaluation {k}",
                loaded.scene.name
            );
            kept += usize::from(h.constant.is_some());
        }
    }
    assert!(
        kept > 0,
        "no bundled scene has a term with a constant Hessian"
    );
}
