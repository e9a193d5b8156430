//! A sewing pattern as triangles: each panel's boundary sampled at the resolution (both edges of a
//! stitch with one vertex count, the longer edge's, so that a longer edge gathers onto a shorter
//! one), triangulated in 2D by constrained Delaunay refinement (spade: Ruppert/Chew, boundary
//! segments kept), placed in 3D where the pattern puts it, and laid flat side by side as the rest
//! shape (the texture coordinates). The pieces are not joined yet: each stitch becomes a list of
//! vertex pairs, the seams ([`Unsewn::seams`]).

use super::curve::P2;
use super::garmentcode::{Panel, SewingPattern};
use crate::pattern::Defect;
use nalgebra::{Rotation3, Vector3};
use spade::{ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation};
use std::collections::{BTreeMap, HashMap};

/// The pattern's pieces as separate triangle meshes, in metres and drapelab's frame (z up).
#[derive(Debug, Clone)]
pub struct Unsewn {
    /// Rest positions, m: the panels laid flat side by side (y as in the pattern).
    pub rest_m: Vec<P2>,
    /// Triangles, counter-clockwise in the rest layout.
    pub triangles: Vec<[usize; 3]>,
    /// Start positions, m: each panel where the pattern places it (GarmentCode's y up turned to z
    /// up: (x, y, z) → (x, −z, y)).
    pub start_m: Vec<[f64; 3]>,
    /// The vertex pairs the stitches join.
    pub seams: Vec<[usize; 2]>,
    /// The panel of each vertex.
    pub panel_of: Vec<usize>,
    /// The panels' names.
    pub panel_names: Vec<String>,
    /// Vertex sets: each panel's by its name, each edge label's (`label` of GarmentCode's edges).
    pub groups: BTreeMap<String, Vec<usize>>,
}

/// One panel's triangulation: vertices in the panel's plane (file units), triangles, and each
/// edge's vertices from its start to its end.
struct PanelMesh {
    points: Vec<P2>,
    triangles: Vec<[usize; 3]>,
    edge_vertices: Vec<Vec<usize>>,
}

/// The vertex count of each panel's edges at `resolution` (file units): ⌈length / resolution⌉ + 1,
/// the longer edge's count on both edges of a stitch.
fn edge_counts(p: &SewingPattern, resolution: f64) -> Vec<Vec<usize>> {
    let count = |l: f64| (l / resolution).ceil().max(1.0) as usize + 1;
    let mut n: Vec<Vec<usize>> = p
        .panels
        .iter()
        .map(|pn| pn.edges.iter().map(|e| count(e.curve.length())).collect())
        .collect();
    for s in &p.stitches {
        let [a, b] = s.sides;
        let m = n[a.panel][a.edge].max(n[b.panel][b.edge]);
        n[a.panel][a.edge] = m;
        n[b.panel][b.edge] = m;
    }
    n
}

fn signed_area(pts: &[P2]) -> f64 {
    (0..pts.len())
        .map(|i| {
            let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        / 2.0
}

/// Triangulates `panel` with the edge vertex `counts`, triangles no larger than an equilateral one
/// of side `resolution`, no angle under 25° away from the boundary's own corners.
fn mesh_panel(panel: &Panel, counts: &[usize], resolution: f64) -> Result<PanelMesh, Defect> {
    let mut boundary: Vec<P2> = Vec::new();
    let mut starts = Vec::new();
    for (e, &n) in panel.edges.iter().zip(counts) {
        starts.push(boundary.len());
        let s = e.curve.samples(n);
        boundary.extend_from_slice(&s[..n - 1]);
    }
    let nb = boundary.len();
    let edge_vertices = (0..counts.len())
        .map(|i| (0..counts[i]).map(|k| (starts[i] + k) % nb).collect())
        .collect();
    // Counter-clockwise in the plane the triangulation sees; a clockwise panel mirrored there.
    let flip = if signed_area(&boundary) < 0.0 {
        -1.0
    } else {
        1.0
    };
    let pts: Vec<Point2<f64>> = boundary
        .iter()
        .map(|p| Point2::new(flip * p[0], p[1]))
        .collect();
    let segments: Vec<[usize; 2]> = (0..nb).map(|i| [i, (i + 1) % nb]).collect();
    let bad = |m: String| Defect {
        key: format!("pattern.panels.{}", panel.name),
        message: m,
    };
    let mut cdt = outline_cdt(pts.clone(), segments).map_err(bad)?;
    let area = 3f64.sqrt() / 4.0 * resolution * resolution;
    let params = RefinementParameters::<f64>::new()
        .exclude_outer_faces(true)
        .keep_constraint_edges()
        .with_max_allowed_area(area)
        .with_angle_limit(spade::AngleLimit::from_deg(25.0))
        .with_max_additional_vertices(4 * (nb + 16) * (nb + 16));
    let result = cdt.refine(params);
    let excluded: std::collections::HashSet<_> = result.excluded_faces.into_iter().collect();
    let key = |p: Point2<f64>| (p.x.to_bits(), p.y.to_bits());
    let by_position: HashMap<_, usize> =
        pts.iter().enumerate().map(|(i, &p)| (key(p), i)).collect();
    let mut index: HashMap<usize, usize> = HashMap::new();
    let mut points = boundary.clone();
    let mut triangles = Vec::new();
    for f in cdt.inner_faces().filter(|f| !excluded.contains(&f.fix())) {
        let t = f.vertices().map(|v| {
            let p = v.position();
            *index
                .entry(v.fix().index())
                .or_insert_with(|| match by_position.get(&key(p)) {
                    Some(&i) => i,
                    None => {
                        points.push([flip * p.x, p.y]);
                        points.len() - 1
                    }
                })
        });
        triangles.push(t);
    }
    if index.len() < nb || triangles.is_empty() {
        return Err(bad(
            "triangulates to nothing inside its outline: check that its edges form one simple loop"
                .into(),
        ));
    }
    if flip < 0.0 {
        triangles.iter_mut().for_each(|t| t.swap(1, 2));
    }
    Ok(PanelMesh {
        points,
        triangles,
        edge_vertices,
    })
}

type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

/// The constrained triangulation of a panel's outline, or why the outline is no simple loop.
fn outline_cdt(pts: Vec<Point2<f64>>, segments: Vec<[usize; 2]>) -> Result<Cdt, String> {
    let crossing = || {
        "crosses itself or passes through one point twice: its edges must form one simple loop"
            .to_string()
    };
    let distinct: std::collections::HashSet<_> =
        pts.iter().map(|p| (p.x.to_bits(), p.y.to_bits())).collect();
    if distinct.len() < pts.len() {
        return Err(crossing());
    }
    let mut conflicts = 0;
    let cdt = Cdt::try_bulk_load_cdt(pts, segments, |_| conflicts += 1).map_err(|_| crossing())?;
    if conflicts > 0 {
        return Err(crossing());
    }
    Ok(cdt)
}

/// GarmentCode's rotation: XYZ Euler angles in degrees, R = Rz·Ry·Rx.
fn rotation(deg: [f64; 3]) -> Rotation3<f64> {
    let [x, y, z] = deg.map(f64::to_radians);
    Rotation3::from_axis_angle(&Vector3::z_axis(), z)
        * Rotation3::from_axis_angle(&Vector3::y_axis(), y)
        * Rotation3::from_axis_angle(&Vector3::x_axis(), x)
}

/// The pattern's panels meshed at `resolution_m` and placed (see the module's description).
pub fn unsewn(p: &SewingPattern, resolution_m: f64) -> Result<Unsewn, Defect> {
    let counts = edge_counts(p, resolution_m / p.unit_m);
    let mut u = Unsewn {
        rest_m: Vec::new(),
        triangles: Vec::new(),
        start_m: Vec::new(),
        seams: Vec::new(),
        panel_of: Vec::new(),
        panel_names: p.panels.iter().map(|pn| pn.name.clone()).collect(),
        groups: BTreeMap::new(),
    };
    let mut edge_vertices = Vec::new();
    let mut x_offset = 0.0;
    for (k, panel) in p.panels.iter().enumerate() {
        let m = mesh_panel(panel, &counts[k], resolution_m / p.unit_m)?;
        let base = u.start_m.len();
        let r = rotation(panel.rotation_deg);
        let t = Vector3::from(panel.translation);
        let lo = m.points.iter().map(|q| q[0]).fold(f64::INFINITY, f64::min);
        let hi = m
            .points
            .iter()
            .map(|q| q[0])
            .fold(f64::NEG_INFINITY, f64::max);
        for q in &m.points {
            let w = (r * Vector3::new(q[0], q[1], 0.0) + t) * p.unit_m;
            u.start_m.push([w.x, -w.z, w.y]);
            u.rest_m
                .push([x_offset + (q[0] - lo) * p.unit_m, q[1] * p.unit_m]);
            u.panel_of.push(k);
        }
        x_offset += (hi - lo) * p.unit_m + 0.05;
        u.triangles
            .extend(m.triangles.iter().map(|t| t.map(|v| v + base)));
        u.groups
            .insert(panel.name.clone(), (base..u.start_m.len()).collect());
        for (e, ev) in panel.edges.iter().zip(&m.edge_vertices) {
            if !e.label.is_empty() {
                u.groups
                    .entry(e.label.clone())
                    .or_default()
                    .extend(ev.iter().map(|v| v + base));
            }
        }
        edge_vertices.push(
            m.edge_vertices
                .iter()
                .map(|ev| ev.iter().map(|v| v + base).collect::<Vec<_>>())
                .collect::<Vec<_>>(),
        );
    }
    for s in &p.stitches {
        let [a, b] = s.sides;
        let mut va = edge_vertices[a.panel][a.edge].clone();
        if s.reversed {
            va.reverse();
        }
        let vb = &edge_vertices[b.panel][b.edge];
        u.seams.extend(va.iter().zip(vb).map(|(&i, &j)| [i, j]));
    }
    u.groups.values_mut().for_each(|g| {
        g.sort_unstable();
        g.dedup();
    });
    Ok(u)
}
