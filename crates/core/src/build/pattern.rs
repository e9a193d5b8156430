//! A flat pattern as the sheet ([`crate::pattern::Pattern`]): the continuum material of seed
//! 003's scenes on its triangles — the orthotropic membrane ([`Membrane`]: tensile warp/weft and
//! shear rigidities) and orthotropic hinge bending (warp/weft bending rigidities) — with masses
//! lumped from the triangles' areas and gravity; obstacles and self-contact are added to the
//! builder it returns, as for every sheet.

use crate::material::Rigidities;
use crate::pattern::Pattern;
use crate::physics::{
    EnergyTerm, Membrane, MembraneError, ModelBuilder, SewnSheet, hinge_curl, patch_bending,
    reads_creases, sewn_hinge_bending,
};

/// A pattern and its fabric.
pub struct PatternSheet<'a> {
    /// The checked pattern (rest positions in its plane, m).
    pub pattern: &'a Pattern,
    /// The fabric's rigidities (SI: N/m for tensile and shear, N·m for bending).
    pub rigidities: &'a Rigidities,
    /// The warp's angle from the pattern's +x, rad.
    pub warp_angle_rad: f64,
    /// The curvature beyond which the bending moment levels off, 1/m (∞: linear bending).
    pub bending_saturation_per_m: f64,
    /// The natural curl, 1/m ([`crate::physics::hinge_curl`]); none: no curl term.
    pub curl_per_m: Option<f64>,
    /// Areal density, kg/m².
    pub areal_density_kg_per_m2: f64,
}

impl PatternSheet<'_> {
    /// Lumped masses: a third of each triangle's mass (its rest area's) to each of its vertices, kg.
    pub fn lumped_masses(&self) -> Vec<f64> {
        let p = self.pattern;
        let mut m = vec![0.0; p.vertex_count()];
        for (t, r) in p.triangles.iter().zip(&p.rest_triangles) {
            let [a, b, c] = r.map(|v| p.rest_m[v]);
            let area = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])).abs();
            for &v in t {
                m[v] += self.areal_density_kg_per_m2 * area / 3.0;
            }
        }
        m
    }
}

/// The builder of `sheet` under gravity `g_m_per_s2` with the particles `pinned` fixed: lumped
/// masses, membrane, hinge bending (when the bending rigidities are not both zero) and gravity.
pub fn pattern_builder(
    sheet: &PatternSheet<'_>,
    g_m_per_s2: f64,
    pinned: &[usize],
) -> Result<ModelBuilder, MembraneError> {
    let p = sheet.pattern;
    let r = sheet.rigidities;
    let mut fixed = vec![false; p.vertex_count()];
    pinned.iter().for_each(|&v| fixed[v] = true);
    let mut b = ModelBuilder::new(sheet.lumped_masses(), fixed, g_m_per_s2);
    let y = [
        r.tensile_warp_N_per_m,
        r.tensile_weft_N_per_m,
        r.shear_N_per_m,
    ];
    let sewn = SewnSheet {
        rest: &p.rest_m,
        rest_triangles: &p.rest_triangles,
        triangles: &p.triangles,
    };
    b.term(Box::new(Membrane::sewn(&sewn, sheet.warp_angle_rad, y)?));
    if r.bending_warp_N_m > 0.0 || r.bending_weft_N_m > 0.0 {
        b.term(bending(&sewn, sheet));
    }
    if let Some(curl) = sheet.curl_per_m {
        let mean = (r.bending_warp_N_m * r.bending_weft_N_m).sqrt();
        b.term(Box::new(hinge_curl(&sewn, mean, curl)));
    }
    b.gravity();
    Ok(b)
}

/// The sheet's bending: the orthotropic plate from each triangle's quadratic patch
/// ([`patch_bending`], exact on quadratics, the grid's twist rigidity included) where the patches
/// read every crease as curvature across it ([`reads_creases`]: a grid split along one diagonal),
/// else orthotropic hinges ([`sewn_hinge_bending`], which charge every crease but read twist and
/// bending across the diagonals two to three times the plate's). A saturating law bends by hinges
/// (seed 000's Cusick model: [`sewn_hinge_bending`] with its κ₀).
fn bending(sewn: &SewnSheet<'_>, sheet: &PatternSheet<'_>) -> Box<dyn EnergyTerm> {
    let (r, warp_angle_rad) = (sheet.rigidities, sheet.warp_angle_rad);
    let b = [r.bending_warp_N_m, r.bending_weft_N_m];
    let kappa0 = sheet.bending_saturation_per_m;
    let patch = (reads_creases(sewn) && kappa0 == f64::INFINITY)
        .then(|| patch_bending(sewn, [b[0], b[1], r.bending_twist_N_m], warp_angle_rad))
        .flatten();
    match patch {
        Some(p) => Box::new(p),
        None => Box::new(sewn_hinge_bending(sewn, b, warp_angle_rad, kappa0)),
    }
}

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
