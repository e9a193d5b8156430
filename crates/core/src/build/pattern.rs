//! A scene whose sheet is a pattern ([`crate::pattern::Pattern`]): the pattern's model
//! ([`pattern_builder`]) with the scene's fabric, pins, loads, obstacles and self-contact.

use crate::pattern::Pattern;
pub use crate::physics::{PatternSheet, pattern_builder};

/// Builds the model of a validated scene whose sheet is a mesh (`cloth.mesh`): the pattern's
/// builder ([`pattern_builder`]) with the scene's continuum rigidities, warp angle and pinned groups,
/// then the scene's point loads, obstacles and self-contact, as for a grid sheet.
pub(super) fn build_mesh_scene(
    scene: &crate::scene::ValidatedScene,
    pattern: &Pattern,
) -> super::BuiltScene {
    let c = scene
        .material
        .continuum
        .as_ref()
        .expect("validated mesh scene: continuum material");
    let r = c.rigidities().expect("validated rigidities");
    let sheet = PatternSheet {
        pattern,
        rigidities: &r,
        warp_angle_rad: scene.cloth.warp_angle_deg.to_radians(),
        bending_saturation_per_m: c.bending_saturation_per_m.unwrap_or(f64::INFINITY),
        curl_per_m: c.curl_per_m,
        areal_density_kg_per_m2: scene.cloth.areal_density_kg_per_m2,
    };
    let pinned = scene.pinned_group_vertices();
    let mut b = pattern_builder(&sheet, scene.gravity.g_m_per_s2, &pinned)
        .expect("a checked pattern's triangles have area");
    let x0 = scene.initial_positions();
    let grid = scene.grid();
    let absent = vec![false; grid.len()];
    super::point_loads(scene, &grid, &absent, &x0, &mut b.terms);
    super::contact_terms(scene, &x0, &mut b);
    if scene.contact.self_contact.applies_to(scene.solver.kind) {
        let xi = super::self_thickness_m(scene);
        let triangles = super::scene_triangles(scene);
        b.self_contact(triangles, &x0, (xi, xi), super::kappa_gravity(scene));
    }
    super::BuiltScene {
        grid,
        model: b.build(),
        x0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Rigidities;
    use crate::solve::{NoObserver, StaticOptions, solve_static};
    use nalgebra::Vector3;

    /// A strip `w` × `l` (m) of `nx` × `ny` vertices as OBJ text (quads), its top row in group `top`.
    fn strip_obj(w: f64, l: f64, nx: usize, ny: usize) -> String {
        let mut s = String::new();
        for j in 0..ny {
            for i in 0..nx {
                let (u, v) = (
                    w * i as f64 / (nx - 1) as f64,
                    l * j as f64 / (ny - 1) as f64,
                );
                s += &format!("v {u} {v} 0\n");
            }
        }
        let id = |i: usize, j: usize| j * nx + i + 1;
        s += "g cloth\n";
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                s += &format!(
                    "f {} {} {} {}\n",
                    id(i, j),
                    id(i + 1, j),
                    id(i + 1, j + 1),
                    id(i, j + 1)
                );
            }
        }
        s += "g top\nl";
        for i in 0..nx {
            s += &format!(" {}", id(i, ny - 1));
        }
        s + "\n"
    }

    fn rigidities(warp: f64, weft: f64) -> Rigidities {
        Rigidities {
            tensile_warp_N_per_m: warp,
            tensile_weft_N_per_m: weft,
            shear_N_per_m: 5.0,
            bending_warp_N_m: 0.0,
            bending_weft_N_m: 0.0,
            bending_twist_N_m: 0.0,
        }
    }

    /// A strip hung from its top row in the x–z plane stretches under its own weight by
    /// ρ g L² / (2 Y) (Y the tensile rigidity along the strip): the warp's when the warp runs
    /// along it, the weft's when it runs across.
    #[test]
    fn a_hung_strip_stretches_as_a_bar_under_its_own_weight() {
        let (w, l, rho, g) = (0.05, 0.5, 0.2, 9.81);
        let pattern = crate::pattern::parse_obj(&strip_obj(w, l, 4, 21), 1.0).unwrap();
        for (angle, along) in [(std::f64::consts::FRAC_PI_2, 2000.0), (0.0, 500.0)] {
            let r = rigidities(2000.0, 500.0);
            let sheet = PatternSheet {
                pattern: &pattern,
                rigidities: &r,
                warp_angle_rad: angle,
                bending_saturation_per_m: f64::INFINITY,
                curl_per_m: None,
                areal_density_kg_per_m2: rho,
            };
            let mut model = pattern_builder(&sheet, g, &pattern.groups["top"])
                .unwrap()
                .build();
            let mut x: Vec<Vector3<f64>> = pattern
                .rest_m
                .iter()
                .map(|p| Vector3::new(p[0], 0.0, p[1]))
                .collect();
            let report = solve_static(
                &mut model,
                &mut x,
                &StaticOptions::default(),
                &mut NoObserver,
            );
            assert!(report.is_converged(), "{}", report.message);
            // Bottom row: its drop from rest, against the bar's exact ρ g L² / (2 Y) (with the
            // strip's own lateral freedom: no Poisson coupling in this material).
            let drop = -x[1].z;
            let want = rho * g * l * l / (2.0 * along);
            assert!(
                (drop / want - 1.0).abs() < 0.01,
                "warp at {angle}: drop {drop} want {want}"
            );
        }
    }

    /// An L-shaped panel (two 20 × 10 cm arms, 2 cm spacing) of seed 003's wool, its corner
    /// vertex held over a 5 cm sphere: the static drape with the sphere's barrier and the sheet's
    /// self-contact converges, the sheet stays outside the sphere and does not pass through itself.
    #[test]
    fn an_l_shaped_wool_panel_drapes_over_a_sphere_without_crossing_itself() {
        use crate::material::{gf_cm2_per_cm_to_n_m, gf_per_cm_to_n_per_m};
        let h = 0.02;
        let inside = |i: usize, j: usize| i <= 10 && j <= 10 && (i <= 5 || j <= 5);
        let mut id = std::collections::HashMap::new();
        let mut obj = String::new();
        for j in 0..=10 {
            for i in 0..=10 {
                if inside(i, j) {
                    id.insert((i, j), id.len() + 1);
                    obj += &format!("v {} {} 0\n", i as f64 * h, j as f64 * h);
                }
            }
        }
        for j in 0..10 {
            for i in 0..10 {
                let q = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
                if q.iter().all(|&(a, b)| inside(a, b)) && (i < 5 || j < 5) {
                    let v = q.map(|k| id[&k]);
                    obj += &format!("f {} {} {} {}\n", v[0], v[1], v[2], v[3]);
                }
            }
        }
        let pattern = crate::pattern::parse_obj(&obj, 1.0).unwrap();
        let r = Rigidities {
            tensile_warp_N_per_m: gf_per_cm_to_n_per_m(1118.2),
            tensile_weft_N_per_m: gf_per_cm_to_n_per_m(759.5),
            shear_N_per_m: gf_per_cm_to_n_per_m(41.8),
            bending_warp_N_m: gf_cm2_per_cm_to_n_m(0.083),
            bending_weft_N_m: gf_cm2_per_cm_to_n_m(0.063),
            bending_twist_N_m: 0.0,
        };
        let sheet = PatternSheet {
            pattern: &pattern,
            rigidities: &r,
            warp_angle_rad: 0.0,
            bending_saturation_per_m: f64::INFINITY,
            curl_per_m: None,
            areal_density_kg_per_m2: 0.19,
        };
        // The corner vertex (5, 5) sits on the sphere's top.
        let corner = id[&(5, 5)] - 1;
        let mut b = pattern_builder(&sheet, 9.81, &[corner]).unwrap();
        let c = pattern.rest_m[corner];
        let sphere = crate::obstacle::Obstacle::Sphere {
            centre_m: [0.0, 0.0, -0.0505],
            radius_m: 0.05,
        };
        b.obstacles(vec![sphere.clone()], 1e-3, 9.81);
        let mut x: Vec<Vector3<f64>> = pattern
            .rest_m
            .iter()
            .map(|p| Vector3::new(p[0] - c[0], p[1] - c[1], 0.0))
            .collect();
        let tris: Vec<[u32; 3]> = pattern
            .triangles
            .iter()
            .map(|t| t.map(|v| v as u32))
            .collect();
        b.self_contact(tris.clone(), &x, (5.93e-4, 5.93e-4), 9.81);
        let mut model = b.build();
        let opts = StaticOptions {
            residual_tol_rel: 1e-6,
            max_iterations: 3000,
            ..StaticOptions::default()
        };
        let report = solve_static(&mut model, &mut x, &opts, &mut NoObserver);
        assert!(report.is_converged(), "{}", report.message);
        // Draped: the arms hang below the sphere's top, every vertex outside the sphere.
        let lowest = x.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
        assert!(lowest < -0.05, "lowest {lowest}");
        for p in &x {
            assert!((p - Vector3::new(0.0, 0.0, -0.0505)).norm() > 0.05);
        }
        let topo = crate::proximity::MeshTopology::from_triangles(tris);
        assert!(crate::proximity::edge_triangle_crossings(&topo, &x).is_empty());
    }
}
