//! Issue 20: smooth textured drape surfaces (seed 003 §10.8) — trimming, texture mapping, glTF.

use crate::support::{drapelab, root, scene};
use drapelab::scene::Scene;
use drapelab_core::surface::{DrapeSurface, Parametrization, SurfaceMesh};
use nalgebra::Vector3;

/// A scene solved statically: its grid, positions and which particles belong to the sheet.
fn solved(s: &Scene) -> (drapelab_core::cloth::Grid, Vec<Vector3<f64>>, Vec<bool>) {
    let v = s.clone().validated().expect("valid");
    let built = drapelab_core::build::build_scene(&v);
    let (grid, mut model, mut x) = (built.grid, built.model, built.x0);
    let present: Vec<bool> = model.masses[..grid.len()]
        .iter()
        .map(|m| *m > 0.0)
        .collect();
    let r = drapelab_core::simulate::solve_model(
        &v,
        &grid,
        &mut model,
        &mut x,
        &mut drapelab_core::solve::NoObserver,
    );
    assert!(r.is_converged(), "{}: {}", s.name, r.message);
    x.truncate(grid.len());
    (grid, x, present)
}

/// Area of the parameter-plane triangles of a mesh.
fn param_area(m: &SurfaceMesh) -> f64 {
    m.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|k| m.params[k as usize]);
            ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs() / 2.0
        })
        .sum()
}

/// Chessboard distance, in pixels, from every pixel to the nearest covered pixel of `p` (BFS).
fn distance_to(p: &drapelab_core::measure::Projection) -> Vec<usize> {
    let mut d = vec![usize::MAX; p.covered.len()];
    let mut queue: std::collections::VecDeque<usize> =
        (0..p.covered.len()).filter(|&k| p.covered[k]).collect();
    queue.iter().for_each(|&k| d[k] = 0);
    while let Some(k) = queue.pop_front() {
        let (c, r) = ((k % p.nx) as i64, (k / p.nx) as i64);
        for (dc, dr) in [
            (-1, -1),
            (-1, 0),
            (-1, 1),
            (0, -1),
            (0, 1),
            (1, -1),
            (1, 0),
            (1, 1),
        ] {
            let (c2, r2) = (c + dc, r + dr);
            if c2 >= 0 && r2 >= 0 && (c2 as usize) < p.nx && (r2 as usize) < p.ny {
                let q = r2 as usize * p.nx + c2 as usize;
                if d[q] == usize::MAX {
                    d[q] = d[k] + 1;
                    queue.push_back(q);
                }
            }
        }
    }
    d
}

/// The largest distance from a point of `params` outside the region of `triangles` (over `pts`) to
/// that region's outline.
fn beyond_region(params: &[[f64; 2]], pts: &[[f64; 2]], triangles: &[[u32; 3]]) -> f64 {
    let inside = |q: [f64; 2]| {
        triangles.iter().any(|t| {
            let [a, b, c] = t.map(|k| pts[k as usize]);
            let cross = |p: [f64; 2], r: [f64; 2]| {
                (r[0] - p[0]) * (q[1] - p[1]) - (r[1] - p[1]) * (q[0] - p[0])
            };
            let (d0, d1, d2) = (cross(a, b), cross(b, c), cross(c, a));
            let e = 1e-12;
            (d0 >= -e && d1 >= -e && d2 >= -e) || (d0 <= e && d1 <= e && d2 <= e)
        })
    };
    let loops = drapelab_core::surface::outline(pts, triangles);
    let seg_dist = |q: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let t = (((q[0] - a[0]) * dx + (q[1] - a[1]) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
        ((q[0] - a[0] - t * dx).powi(2) + (q[1] - a[1] - t * dy).powi(2)).sqrt()
    };
    params
        .iter()
        .filter(|q| !inside(**q))
        .map(|q| {
            loops
                .iter()
                .flat_map(|l| (0..l.len()).map(move |k| (l[k], l[(k + 1) % l.len()])))
                .map(|(a, b)| seg_dist(*q, pts[a as usize], pts[b as usize]))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

/// Seed 003 §10.8 on the skirt: extended to the rectangle, interpolated, trimmed. The surface passes
/// through every particle; in the pattern (parameter) plane the trimmed region has the area of the
/// solver's mesh; seen from above (the shadow a drape tester measures) it covers the mesh's shadow to
/// 1 %, reaching beyond it only by the bulge of a cubic between nodes.
#[test]
fn the_trimmed_skirt_covers_its_own_mesh_and_nothing_outside_it() {
    let s = scene("skirt_wool.toml", &[]);
    let (grid, x, present) = solved(&s);
    let surf = DrapeSurface::new(&grid, &x, &present, Parametrization::Uniform).expect("surface");
    let (u, v) = surf.shape.params.clone();
    let worst_node = (0..grid.len())
        .filter(|&p| present[p])
        .map(|p| (surf.shape.point(u[p % grid.nx], v[p / grid.nx]) - x[p]).norm())
        .fold(0.0, f64::max);
    assert!(
        worst_node < 1e-10,
        "a node {worst_node:.2e} m off the surface"
    );
    let mesh = surf.tessellate(240);
    let kept: Vec<[u32; 3]> = drapelab_core::cloth::grid_triangles(&grid)
        .into_iter()
        .filter(|t| t.iter().all(|&k| present[k as usize]))
        .collect();
    let pts: Vec<[f64; 2]> = (0..grid.len())
        .map(|p| [u[p % grid.nx], v[p / grid.nx]])
        .collect();
    let kept_param: f64 = kept
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|k| pts[k as usize]);
            ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])).abs() / 2.0
        })
        .sum();
    let rel = (param_area(&mesh) - kept_param).abs() / kept_param;
    assert!(
        rel < 0.01,
        "pattern-plane area {:.5} against the mesh's {kept_param:.5}",
        param_area(&mesh)
    );
    let shadow_mesh = drapelab_core::measure::vertical_projection(&grid, &x, &present, 1000);
    let mut shadow = drapelab_core::measure::Projection::empty(
        shadow_mesh.nx,
        shadow_mesh.ny,
        shadow_mesh.pixel_m,
        shadow_mesh.origin_m,
    );
    shadow.fill_triangles(
        &mesh.positions,
        mesh.triangles.iter().map(|t| t.map(|k| k as usize)),
    );
    let (a, b) = (shadow.area_m2(), shadow_mesh.area_m2());
    println!(
        "shadow: surface {a:.5} m², mesh {b:.5} m² ({:+.2} %)",
        100.0 * (a - b) / b
    );
    assert!(
        (a - b).abs() < 0.01 * b,
        "shadow {a:.5} m² against the mesh's {b:.5} m²"
    );
    let dist = distance_to(&shadow_mesh);
    let farthest = shadow
        .covered
        .iter()
        .zip(&dist)
        .filter(|(c, _)| **c)
        .map(|(_, d)| *d)
        .max()
        .unwrap_or(0) as f64
        * shadow.pixel_m;
    let h = grid.min_spacing_m();
    println!(
        "farthest beyond the mesh's shadow: {:.2} mm (grid spacing {:.1} mm)",
        farthest * 1e3,
        h * 1e3
    );
    // Between nodes a cubic bulges beyond the chords of the solver's mesh where the drape bends sharply (at the hem): by
    // h²/(8r) for a curl of radius r; 7 mm here at h = 22.5 mm (a curl of about 1 cm).
    assert!(
        farthest < 0.5 * h,
        "the surface reaches {farthest:.4} m beyond the mesh's shadow"
    );
    // In the pattern plane the trimmed domain stays on the mesh's region: where the smooth outline
    // crosses the staircase it leaves it by at most a fraction of a grid cell.
    let beyond = beyond_region(&mesh.params, &pts, &kept);
    let cell = 1.0 / (grid.nx - 1) as f64;
    println!(
        "pattern plane: farthest beyond the mesh's region {:.3} of a cell",
        beyond / cell
    );
    assert!(
        beyond < 0.25 * cell,
        "the trimmed domain leaves the mesh's region by {:.3} cells",
        beyond / cell
    );
}
