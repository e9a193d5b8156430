//! Garments from sewing patterns (issue 91): GarmentCode's JSON read ([`garmentcode`]), its edges'
//! curves ([`curve`]), the panels triangulated and placed ([`panels`]), and the seams welded into
//! one sheet ([`weld`]) that the rest of drapelab drapes as a sewn garment
//! ([`crate::pattern::Pattern`]).

pub mod curve;
pub mod garmentcode;
pub mod panels;
pub mod sew;
pub mod weld;

pub use garmentcode::{SewingPattern, parse};
pub use panels::{Unsewn, unsewn};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Rigidities;
    use crate::obstacle::Obstacle;
    use sew::{SewSetup, arrange, sew};

    fn sample(name: &str) -> SewingPattern {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../datasets/garments");
        let text = std::fs::read_to_string(dir.join(format!("{name}_specification.json"))).unwrap();
        parse(&text).unwrap()
    }

    #[test]
    fn every_bundled_sample_meshes_and_its_stitches_weld_into_one_garment() {
        for name in ["shirt_mean", "hoody_mean", "dress_pencil", "js_mean_all"] {
            let p = sample(name);
            let u = unsewn(&p, 0.03).unwrap();
            // Both sides of every stitch have one vertex count: the pairs cover each edge once.
            let paired: usize = p.stitches.len();
            assert!(u.seams.len() >= 2 * paired, "{name}");
            // Welded where the pattern places the pieces, the stitches make one connected,
            // manifold, consistently oriented sheet (the garment checks of an OBJ file).
            let w = weld::weld(&u, &u.start_m).unwrap_or_else(|d| panic!("{name}: {d:?}"));
            assert!(w.vertex_count() < u.start_m.len(), "{name}");
            // The rest shape is the panels' own area.
            let flat: f64 = u
                .triangles
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|v| u.rest_m[v]);
                    0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]))
                })
                .sum();
            assert!((w.rest_area_m2() - flat).abs() < 1e-9, "{name}");
        }
    }

    /// Two panels `w` × `h` cm, front and back of a vertical tube, stitched at both sides; the
    /// back's loop runs the other way (as GarmentCode's mirrored back panels do). Bottom edges
    /// labelled `hem`. A back shorter than `h` (`back_h`) makes the side seams gather.
    fn tube(w: f64, h: f64, back_h: f64, z: f64) -> String {
        let b = w;
        format!(
            r#"{{"pattern": {{"panels": {{
              "front": {{"translation": [{x0}, 0, {z}], "rotation": [0, 0, 0],
                "vertices": [[0, 0], [{w}, 0], [{w}, {h}], [0, {h}]],
                "edges": [{{"endpoints": [0, 1], "label": "hem"}}, {{"endpoints": [1, 2]}},
                          {{"endpoints": [2, 3]}}, {{"endpoints": [3, 0]}}]}},
              "back": {{"translation": [{x1}, 0, -{z}], "rotation": [0, 0, 0],
                "vertices": [[0, 0], [{b}, 0], [{b}, {back_h}], [0, {back_h}]],
                "edges": [{{"endpoints": [0, 3]}}, {{"endpoints": [3, 2]}},
                          {{"endpoints": [2, 1]}}, {{"endpoints": [1, 0], "label": "hem"}}]}}}},
              "stitches": [[{{"panel": "front", "edge": 1}}, {{"panel": "back", "edge": 2}}],
                           [{{"panel": "front", "edge": 3}}, {{"panel": "back", "edge": 0}}]]}},
              "properties": {{"units_in_meter": 100}}}}"#,
            x0 = -w / 2.0,
            x1 = -b / 2.0,
        )
    }

    fn wool() -> Rigidities {
        Rigidities {
            tensile_warp_N_per_m: 1000.0,
            tensile_weft_N_per_m: 1000.0,
            shear_N_per_m: 40.0,
            bending_warp_N_m: 1e-5,
            bending_weft_N_m: 1e-5,
            bending_twist_N_m: 1e-5,
        }
    }

    fn rod(radius_m: f64) -> Obstacle {
        Obstacle::Cylinder {
            point_m: [0.0; 3],
            axis: [0.0, 0.0, 1.0],
            radius_m,
        }
    }

    /// Sewing in wool `r` on `body`, the warp along the panels' length.
    fn setup<'a>(r: &'a Rigidities, body: &'a [Obstacle]) -> SewSetup<'a> {
        SewSetup {
            rigidities: r,
            areal_density_kg_per_m2: 0.2,
            warp_angle_rad: std::f64::consts::FRAC_PI_2,
            obstacles: body,
            distance_m: 0.002,
            thickness_m: 1e-3,
        }
    }

    #[test]
    fn a_tube_of_two_panels_sewn_round_a_cylinder_closes_to_their_width_and_welds() {
        let u = unsewn(&parse(&tube(30.0, 20.0, 20.0, 12.0)).unwrap(), 0.03).unwrap();
        let r = wool();
        let body = [rod(0.06)];
        let setup = setup(&r, &body);
        let (w, report) = sew(&u, &setup, &mut |_| {}, &mut crate::solve::NoObserver).unwrap();
        assert!(
            report.gap_before_weld_m < sew::GAP_TOLERANCE_M,
            "{report:?}"
        );
        assert_eq!(report.crossing_edges, 0);
        assert_eq!(report.penetration_m, 0.0);
        // Both side seams' vertices became one particle each.
        let seam_vertices: std::collections::BTreeSet<usize> =
            u.seams.iter().map(|s| s[0]).collect();
        assert_eq!(w.vertex_count(), u.start_m.len() - seam_vertices.len());
        // The hem is one closed loop round the rod, as long as the two panels are wide.
        let hem = &w.groups["hem"];
        let mut ring: Vec<[f64; 3]> = hem.iter().map(|&v| w.start_m[v]).collect();
        ring.sort_by(|a, b| a[1].atan2(a[0]).total_cmp(&b[1].atan2(b[0])));
        let perimeter: f64 = (0..ring.len())
            .map(|i| {
                let (a, b) = (ring[i], ring[(i + 1) % ring.len()]);
                ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
            })
            .sum();
        assert!(
            (perimeter - 0.60).abs() < 0.02 * 0.60,
            "hem {perimeter} m round, panels 0.60 m wide"
        );
        assert!(ring.iter().all(|p| p[0].hypot(p[1]) > 0.06));
    }

    #[test]
    fn a_panel_whose_outline_crosses_itself_is_refused_naming_it() {
        // The front's third corner moved onto its first: the loop passes through one point twice.
        let text =
            tube(30.0, 20.0, 20.0, 12.0).replacen("[30, 20], [0, 20]]", "[0, 0], [0, 20]]", 1);
        let e = unsewn(&parse(&text).unwrap(), 0.03).unwrap_err();
        assert_eq!(e.key, "pattern.panels.front", "{e:?}");
        assert!(e.message.contains("crosses itself"), "{}", e.message);
    }

    #[test]
    fn a_seam_of_two_unequal_edges_gathers_the_longer_onto_the_shorter() {
        // The front's 20 cm right side sewn to the back's 10 cm one: both edges get the longer
        // edge's 11 vertices at 2 cm, so the back's are 1 cm apart and the front gathers onto it.
        let text = tube(30.0, 20.0, 10.0, 12.0);
        let u = unsewn(&parse(&text).unwrap(), 0.02).unwrap();
        assert_eq!(u.seams.len(), 2 * 11);
        let spacing = |side: usize| {
            let d: Vec<f64> = u.seams[..11]
                .windows(2)
                .map(|w| {
                    let (p, q) = (u.rest_m[w[0][side]], u.rest_m[w[1][side]]);
                    (p[0] - q[0]).hypot(p[1] - q[1])
                })
                .collect();
            d.iter().sum::<f64>() / d.len() as f64
        };
        assert!((spacing(0) - 0.02).abs() < 1e-9, "{}", spacing(0));
        assert!((spacing(1) - 0.01).abs() < 1e-9, "{}", spacing(1));
    }

    #[test]
    fn a_panel_placed_through_the_body_is_moved_clear() {
        // The front panel placed 2 cm in front of the axis, through a rod of 6 cm: moved out.
        let u = unsewn(&parse(&tube(30.0, 20.0, 20.0, 2.0)).unwrap(), 0.03).unwrap();
        let r = wool();
        let body = [rod(0.06)];
        let setup = setup(&r, &body);
        let (x, moved) = arrange(&u, &setup).unwrap();
        assert_eq!(
            moved.iter().filter(|m| m.0 != "lift").count(),
            2,
            "{moved:?}"
        );
        assert!(
            x.iter()
                .all(|p| p[0].hypot(p[1]) > 0.06 + 2.0 * setup.distance_m)
        );
        // A rod wider than 30 cm of moves can clear is refused, naming the panel.
        let wide = [rod(0.5)];
        let e = arrange(
            &u,
            &SewSetup {
                obstacles: &wide,
                ..setup
            },
        )
        .unwrap_err();
        assert!(e.key.starts_with("pattern.panels."), "{e:?}");
    }
}
