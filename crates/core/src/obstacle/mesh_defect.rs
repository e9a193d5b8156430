//! What makes a triangle mesh no body: the defects a body mesh is refused for, each named for
//! an error that points at the file, and the test of a closed, outward-oriented surface.

use nalgebra::Vector3;
use std::collections::HashMap;

type V3 = Vector3<f64>;

/// What is wrong with a body mesh, for an error naming the file.
#[derive(Debug, Clone, PartialEq)]
pub enum BodyDefect {
    /// No triangle at all.
    NoTriangles,
    /// A vertex with a coordinate that is not finite.
    NotFinite(usize),
    /// A triangle naming a vertex the mesh does not have.
    MissingVertex(usize),
    /// A triangle without area (its corners on a line, or two the same).
    Degenerate(usize),
    /// An edge (its vertices, 0-based) of one face only: a hole or a border, so the mesh encloses
    /// no inside (a triangle soup's every edge is one).
    Open(u32, u32),
    /// An edge (its vertices) of more than two faces: a fin or two bodies touching along it.
    NonManifold(u32, u32),
    /// An edge two faces run the same way: their orientations disagree.
    Inconsistent(u32, u32),
    /// The faces are counter-clockwise seen from inside (the enclosed volume is negative).
    InsideOut,
    /// An edge (its vertices) passes through a face (its index) that shares no vertex with it:
    /// the surface crosses itself, so inside and outside are not defined.
    SelfIntersecting(u32, u32, usize),
}

impl std::fmt::Display for BodyDefect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BodyDefect::NoTriangles => write!(f, "the mesh has no triangles"),
            BodyDefect::NotFinite(v) => {
                write!(f, "vertex {} has a coordinate that is not finite", v + 1)
            }
            BodyDefect::MissingVertex(t) => {
                write!(f, "face {} names a vertex the file does not have", t + 1)
            }
            BodyDefect::Degenerate(t) => {
                write!(f, "face {} has no area (its corners on a line)", t + 1)
            }
            BodyDefect::Open(a, b) => write!(
                f,
                "the mesh is open: the edge from vertex {} to {} borders one face only (a hole or \
a border); a body must be closed (watertight): close it, e.g. MeshLab's Close Holes",
                a + 1,
                b + 1
            ),
            BodyDefect::NonManifold(a, b) => write!(
                f,
                "the edge from vertex {} to {} borders more than two faces (a fin, or bodies \
touching): give each body as one closed surface",
                a + 1,
                b + 1
            ),
            BodyDefect::Inconsistent(a, b) => write!(
                f,
                "two faces run the edge from vertex {} to {} the same way: orient every face \
counter-clockwise seen from outside",
                a + 1,
                b + 1
            ),
            BodyDefect::SelfIntersecting(a, b, t) => write!(
                f,
                "the surface crosses itself: the edge from vertex {} to {} passes through face {}; \
give the body as a surface that does not intersect itself",
                a + 1,
                b + 1,
                t + 1
            ),
            BodyDefect::InsideOut => write!(
                f,
                "the mesh is inside out (its faces are clockwise seen from outside, the volume \
they enclose negative): reverse every face's vertex order"
            ),
        }
    }
}

/// What keeps `triangles` from being a closed, consistently oriented surface that faces outward:
/// every edge in exactly two faces which run it in opposite directions, and a positive enclosed
/// volume (the divergence theorem: V = Σ (a · (b × c)) / 6 over the faces). None when it is one.
pub fn closed_surface_defect(vertices: &[V3], triangles: &[[u32; 3]]) -> Option<BodyDefect> {
    let mut directed: HashMap<(u32, u32), u32> = HashMap::with_capacity(3 * triangles.len());
    for t in triangles {
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    let mut edges: Vec<(u32, u32)> = directed.keys().copied().collect();
    edges.sort_unstable();
    for (a, b) in edges {
        let (here, back) = (
            directed[&(a, b)],
            directed.get(&(b, a)).copied().unwrap_or(0),
        );
        if here + back > 2 {
            return Some(BodyDefect::NonManifold(a.min(b), a.max(b)));
        }
        if here > 1 {
            return Some(BodyDefect::Inconsistent(a, b));
        }
        if back == 0 {
            return Some(BodyDefect::Open(a, b));
        }
    }
    let volume: f64 = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum();
    (volume <= 0.0).then_some(BodyDefect::InsideOut)
}
