//! A drape as a smooth surface (seed 003 §10.8): the bicubic interpolant of its grid (extended to the
//! rectangle and trimmed when the drape is not one), its material coordinates, and its evaluation into
//! a triangle mesh at any resolution with exact normals.

use super::{BSplineSurface, Parametrization, Trim, extend_to_rectangle};
use crate::cloth::Grid;
use nalgebra::Vector3;
use std::collections::HashMap;

/// A drape's smooth surface.
#[derive(Debug, Clone)]
pub struct DrapeSurface {
    /// The deformed surface S(u, v), m.
    pub shape: BSplineSurface,
    /// The material (rest) coordinates M(u, v) = (x, y, 0) of the flat sheet at the same
    /// parameters, m: x along the warp, y along the weft.
    pub material: BSplineSurface,
    /// The outline for a drape that is not the whole grid (a disc); None for a rectangle.
    pub trim: Option<Trim>,
    /// The material rectangle: lower corner and size (x, y), m.
    pub extent_m: ([f64; 2], [f64; 2]),
}

/// A drape surface evaluated into triangles.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SurfaceMesh {
    /// Vertices, m.
    pub positions: Vec<Vector3<f64>>,
    /// Unit normals S_u × S_v (+z for a flat sheet seen from above).
    pub normals: Vec<Vector3<f64>>,
    /// Material coordinates (x along the warp, y along the weft) of each vertex, m.
    pub material_m: Vec<[f64; 2]>,
    /// Surface parameters (u, v) of each vertex.
    pub params: Vec<[f64; 2]>,
    /// Triangles, counter-clockwise in the parameter plane.
    pub triangles: Vec<[u32; 3]>,
}

impl SurfaceMesh {
    /// Total area, m².
    pub fn area_m2(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|k| self.positions[k as usize]);
                (b - a).cross(&(c - a)).norm() / 2.0
            })
            .sum()
    }

    /// Area of the vertical projection (onto the x–y plane), each triangle counted once, m².
    pub fn projected_area_m2(&self) -> f64 {
        projected_area(&self.positions, &self.triangles)
    }
}

/// Area of the vertical projection of `triangles` over `x`, each triangle counted once, m².
pub fn projected_area(x: &[Vector3<f64>], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|k| x[k as usize]);
            ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)).abs() / 2.0
        })
        .sum()
}

impl DrapeSurface {
    /// The surface of the drape `x` on `grid`, where `present` marks the particles of the sheet
    /// (false for a disc's corners). None when the grid is smaller than 2 × 2, has fewer than three
    /// present nodes, or an interpolation system is singular.
    pub fn new(
        grid: &Grid,
        x: &[Vector3<f64>],
        present: &[bool],
        kind: Parametrization,
    ) -> Option<Self> {
        let (nx, ny) = (grid.nx, grid.ny);
        if nx < 2
            || ny < 2
            || x.len() < nx * ny
            || present.iter().take(nx * ny).filter(|p| **p).count() < 3
        {
            return None;
        }
        let full = present[..nx * ny].iter().all(|p| *p);
        let nodes = extend_to_rectangle(x, present, nx, ny);
        let shape = BSplineSurface::interpolate(&nodes, nx, ny, kind)?;
        let rest: Vec<Vector3<f64>> = (0..nx * ny)
            .map(|p| Vector3::new(grid.xs[p % nx], grid.ys[p / nx], 0.0))
            .collect();
        let (u, v) = shape.params.clone();
        let material = BSplineSurface::interpolate_at(&rest, nx, ny, u.clone(), v.clone())?;
        let trim = (!full).then(|| {
            let pts: Vec<[f64; 2]> = (0..nx * ny).map(|p| [u[p % nx], v[p / nx]]).collect();
            let kept: Vec<[u32; 3]> = crate::cloth::grid_triangles(grid)
                .into_iter()
                .filter(|t| t.iter().all(|&k| present[k as usize]))
                .collect();
            Trim::from_triangles(&pts, &kept)
        });
        let (x0, y0) = (grid.xs[0], grid.ys[0]);
        let extent_m = ([x0, y0], [grid.xs[nx - 1] - x0, grid.ys[ny - 1] - y0]);
        Some(Self {
            shape,
            material,
            trim,
            extent_m,
        })
    }

    /// The surface evaluated on an `n` × `n` lattice of the parameter square (n ≥ 2), clipped along
    /// the trimming curves: a lattice triangle that the outline crosses is cut where its edges cross
    /// it (found by bisection to 1e-9 in parameter), and the cut points lie on the surface.
    pub fn tessellate(&self, n: usize) -> SurfaceMesh {
        let n = n.max(2);
        let uv = |i: usize, j: usize| [i as f64 / (n - 1) as f64, j as f64 / (n - 1) as f64];
        let inside: Vec<bool> = match &self.trim {
            None => vec![true; n * n],
            Some(t) => (0..n)
                .flat_map(|j| {
                    let v = uv(0, j)[1];
                    let cr = t.crossings(v);
                    (0..n).map(move |i| {
                        let u = uv(i, 0)[0];
                        cr.iter().filter(|c| **c < u).count() % 2 == 1
                    })
                })
                .collect(),
        };
        let mut params: Vec<[f64; 2]> = (0..n * n).map(|p| uv(p % n, p / n)).collect();
        let mut cuts: HashMap<(u32, u32), u32> = HashMap::new();
        let mut triangles = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let k = |a: usize, b: usize| (b * n + a) as u32;
                for tri in [
                    [k(i, j), k(i + 1, j), k(i + 1, j + 1)],
                    [k(i, j), k(i + 1, j + 1), k(i, j + 1)],
                ] {
                    let ins = tri.map(|p| inside[p as usize]);
                    if ins.iter().all(|b| *b) {
                        triangles.push(tri);
                        continue;
                    }
                    if !ins.iter().any(|b| *b) {
                        continue;
                    }
                    let mut poly = Vec::with_capacity(4);
                    for e in 0..3 {
                        let (a, b) = (tri[e], tri[(e + 1) % 3]);
                        if ins[e] {
                            poly.push(a);
                        }
                        if ins[e] != ins[(e + 1) % 3] {
                            let key = (a.min(b), a.max(b));
                            let id = *cuts.entry(key).or_insert_with(|| {
                                let (pin, pout) = if ins[e] { (a, b) } else { (b, a) };
                                let p = self.cut(params[pin as usize], params[pout as usize]);
                                params.push(p);
                                (params.len() - 1) as u32
                            });
                            poly.push(id);
                        }
                    }
                    for m in 1..poly.len() - 1 {
                        triangles.push([poly[0], poly[m], poly[m + 1]]);
                    }
                }
            }
        }
        self.evaluate(&params, triangles)
    }

    /// The point where the trimming outline crosses the segment from `pin` (inside) to `pout`.
    fn cut(&self, pin: [f64; 2], pout: [f64; 2]) -> [f64; 2] {
        let trim = self.trim.as_ref().expect("cuts only on a trimmed surface");
        let (mut a, mut b) = (0.0, 1.0);
        let at = |s: f64| {
            [
                pin[0] + s * (pout[0] - pin[0]),
                pin[1] + s * (pout[1] - pin[1]),
            ]
        };
        while b - a > 1e-9 {
            let m = 0.5 * (a + b);
            let p = at(m);
            if trim.contains(p[0], p[1]) {
                a = m;
            } else {
                b = m;
            }
        }
        at(0.5 * (a + b))
    }

    /// The mesh of the used `params` among `triangles` (unused vertices dropped), evaluated.
    fn evaluate(&self, params: &[[f64; 2]], triangles: Vec<[u32; 3]>) -> SurfaceMesh {
        let mut map = vec![u32::MAX; params.len()];
        let mut mesh = SurfaceMesh::default();
        for t in &triangles {
            for &k in t {
                if map[k as usize] == u32::MAX {
                    map[k as usize] = mesh.params.len() as u32;
                    mesh.params.push(params[k as usize]);
                }
            }
        }
        mesh.triangles = triangles
            .iter()
            .map(|t| t.map(|k| map[k as usize]))
            .collect();
        for &[u, v] in &mesh.params {
            let d = self.shape.derivatives(u, v);
            mesh.positions.push(d[0][0]);
            mesh.normals.push(
                d[1][0]
                    .cross(&d[0][1])
                    .try_normalize(1e-300)
                    .unwrap_or_else(Vector3::z),
            );
            let m = self.material.point(u, v);
            mesh.material_m.push([m.x, m.y]);
        }
        mesh
    }
}
