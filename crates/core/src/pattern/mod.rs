//! A pattern as the sheet: a triangle mesh read from a Wavefront OBJ file (what CLO, Marvelous
//! Designer, Blender and the IPC and BDP examples exchange), checked once so that the physics can
//! rely on it: one connected, manifold mesh of triangles with area, oriented alike. Two layouts:
//! - a **flat pattern**: the vertices (`v`) lie in one plane z = const and are the rest shape and
//!   the start;
//! - a **sewn garment** (the layout garment tools export): the vertices are the pieces placed in 3D
//!   (the start), and every face corner names its flat pattern position as texture coordinates
//!   (`f v/vt`): the rest shape is the pieces laid flat. A vertex shared by faces of two pieces is a
//!   seam (identified vertices): it has one position and a rest position in each piece.
//!
//! Polygons are split into fans; `g`/`o` groups name vertex sets (the vertices of the group's faces
//! and `l` polylines) that pins and clamps can address.

mod checks;
mod overlap;
mod refine;

use checks::{connected, manifold, off_plane, oriented, rest_layout, unused_vertex};
use std::collections::BTreeMap;

/// A checked pattern: the sheet's vertices (its particles) with their start positions, and the
/// rest shape laid flat, per rest vertex (a seam's vertex has one in each piece).
#[derive(Debug, Clone, PartialEq)]
pub struct Pattern {
    /// Rest positions in the pattern's plane, m (a flat pattern's x and y, or a garment's texture
    /// coordinates, times the file's unit), one per rest vertex.
    pub rest_m: Vec<[f64; 2]>,
    /// The triangles over rest vertices, counter-clockwise in the pattern's plane.
    pub rest_triangles: Vec<[usize; 3]>,
    /// The same triangles over the sheet's vertices (particles).
    pub triangles: Vec<[usize; 3]>,
    /// The vertex (particle) of each rest vertex.
    pub vertex_of_rest: Vec<usize>,
    /// Start positions of the vertices in the file's frame, m (z = 0 for a flat pattern).
    pub start_m: Vec<[f64; 3]>,
    /// Vertex sets by group name (`g` and `o` lines), sorted.
    pub groups: BTreeMap<String, Vec<usize>>,
}

/// What is wrong with a pattern file, in one line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Defect {
    /// The key to name in the error: `line N` or what is wrong overall.
    pub key: String,
    /// What is wrong and what to do.
    pub message: String,
}

fn defect(key: impl Into<String>, message: impl Into<String>) -> Defect {
    Defect {
        key: key.into(),
        message: message.into(),
    }
}

/// Relative tolerance of flatness and area against the pattern's extent.
const FLAT_REL: f64 = 1e-6;
const AREA_REL: f64 = 1e-10;

/// What the parser collects before the checks.
#[derive(Default)]
struct Raw {
    v: Vec<[f64; 3]>,
    vt: Vec<[f64; 2]>,
    faces: Vec<([usize; 3], usize)>,
    /// Each face's texture coordinates, where every corner gave one.
    face_vt: Vec<Option<[usize; 3]>>,
    groups: BTreeMap<String, Vec<usize>>,
}

/// The vertices (in the file's unit) and the triangles (polygons split into fans, each with its
/// line) of OBJ text, without a pattern's checks: a rigid body's mesh ([`crate::obstacle::TriangleBody`]).
pub fn parse_obj_triangles(text: &str) -> Result<ObjTriangles, Defect> {
    let raw = parse(text)?;
    Ok((raw.v, raw.faces))
}

/// Vertices, and triangles with the line each came from.
pub type ObjTriangles = (Vec<[f64; 3]>, Vec<([usize; 3], usize)>);

/// Reads a pattern from OBJ text; `unit_m` is the file's unit in metres (1 for m, 0.01 for cm).
pub fn parse_obj(text: &str, unit_m: f64) -> Result<Pattern, Defect> {
    let raw = parse(text)?;
    check(raw, unit_m)
}

/// Reads and checks `path` ([`parse_obj`]); errors name the file and the line or defect.
pub fn read_obj(path: &std::path::Path, unit_m: f64) -> Result<Pattern, crate::error::InputError> {
    use crate::error::InputError;
    let text = crate::textfile::read_text(path, crate::textfile::NonUtf8::Replace)
        .map_err(|e| InputError::new(path, "", e))?;
    parse_obj(&text, unit_m).map_err(|d| InputError::new(path, d.key, d.message))
}

impl Pattern {
    /// The number of vertices (the sheet's particles).
    pub fn vertex_count(&self) -> usize {
        self.start_m.len()
    }

    /// Whether the file's vertices lie in one plane (a flat pattern: its vertices are its rest
    /// shape), rather than a garment's pieces placed in 3D.
    pub fn is_flat(&self) -> bool {
        off_plane(&self.start_m).is_none()
    }

    /// Scales every length (rest and start) by `s`.
    pub fn scaled(&self, s: f64) -> Pattern {
        let mut q = self.clone();
        q.rest_m.iter_mut().for_each(|v| *v = v.map(|c| c * s));
        q.start_m.iter_mut().for_each(|v| *v = v.map(|c| c * s));
        q
    }

    /// The area of the rest shape (the pieces laid flat), m².
    pub fn rest_area_m2(&self) -> f64 {
        self.rest_triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| self.rest_m[v]);
                0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1])).abs()
            })
            .sum()
    }

    /// The shortest edge of a triangle, m.
    pub fn shortest_edge_m(&self) -> f64 {
        let len = |a: usize, b: usize| {
            let (p, q) = (self.rest_m[a], self.rest_m[b]);
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt()
        };
        self.rest_triangles
            .iter()
            .flat_map(|&[a, b, c]| [len(a, b), len(b, c), len(c, a)])
            .fold(f64::INFINITY, f64::min)
    }

    /// The smallest box (m) holding the rest positions: ([x_min, y_min], [x_max, y_max]).
    pub fn bounds_m(&self) -> ([f64; 2], [f64; 2]) {
        self.rest_m.iter().fold(
            ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]),
            |(lo, hi), p| {
                (
                    [lo[0].min(p[0]), lo[1].min(p[1])],
                    [hi[0].max(p[0]), hi[1].max(p[1])],
                )
            },
        )
    }
}

/// The vertex index of an OBJ face or line token (`7`, `7/2`, `7//3`, `-1`), 0-based.
fn index(token: &str, count: usize, line: usize) -> Result<usize, Defect> {
    let first = token.split('/').next().unwrap_or("");
    resolve(first, token, count, line, "vertex")
}

/// The texture-coordinate index of a face token (`7/2` → 1), if it has one.
fn texture_index(token: &str, count: usize, line: usize) -> Result<Option<usize>, Defect> {
    match token.split('/').nth(1) {
        Some(t) if !t.is_empty() => resolve(t, token, count, line, "texture coordinate").map(Some),
        _ => Ok(None),
    }
}

fn resolve(
    text: &str,
    token: &str,
    count: usize,
    line: usize,
    what: &str,
) -> Result<usize, Defect> {
    let at = format!("line {line}");
    let i: i64 = text
        .parse()
        .map_err(|_| defect(&at, format!("`{token}` is not a {what} index")))?;
    let resolved = if i < 0 { count as i64 + i } else { i - 1 };
    if i == 0 || resolved < 0 || resolved >= count as i64 {
        return Err(defect(
            at,
            format!("refers to {what} {i}; the file has {count} before this line"),
        ));
    }
    Ok(resolved as usize)
}

/// The largest vertex coordinate a pattern file may hold, in its unit (a kilometre in
/// millimetres): beyond it areas overflow long before a sheet could be that size.
const MAX_COORDINATE: f64 = 1e6;

fn parse(text: &str) -> Result<Raw, Defect> {
    let mut raw = Raw::default();
    let mut current: Vec<String> = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let n = k + 1;
        let mut it = line.split_whitespace();
        let Some(tag) = it.next() else { continue };
        let rest: Vec<&str> = it.collect();
        match tag {
            "v" => {
                let c: Vec<f64> = rest.iter().take(3).filter_map(|t| t.parse().ok()).collect();
                match c[..] {
                    [x, y, z] if c.iter().all(|v| v.abs() <= MAX_COORDINATE) => {
                        raw.v.push([x, y, z])
                    }
                    [_, _, _] if c.iter().all(|v| v.is_finite()) => {
                        return Err(defect(
                            format!("line {n}"),
                            format!(
                                "a vertex coordinate beyond ±{MAX_COORDINATE:e} (in the file's unit): \
                                 not a pattern piece's or a body's size"
                            ),
                        ));
                    }
                    _ => {
                        return Err(defect(
                            format!("line {n}"),
                            "a vertex (`v`) needs three finite numbers",
                        ));
                    }
                }
            }
            "vt" => {
                let c: Vec<f64> = rest.iter().take(2).filter_map(|t| t.parse().ok()).collect();
                match c[..] {
                    [u, w] if c.iter().all(|v| v.is_finite()) => raw.vt.push([u, w]),
                    _ => {
                        return Err(defect(
                            format!("line {n}"),
                            "a texture coordinate (`vt`) needs two finite numbers",
                        ));
                    }
                }
            }
            "f" | "l" => {
                let idx: Vec<usize> = rest
                    .iter()
                    .map(|t| index(t, raw.v.len(), n))
                    .collect::<Result<_, _>>()?;
                let tex: Vec<Option<usize>> = rest
                    .iter()
                    .map(|t| texture_index(t, raw.vt.len(), n))
                    .collect::<Result<_, _>>()?;
                for g in &current {
                    raw.groups.entry(g.clone()).or_default().extend(&idx);
                }
                if tag == "l" {
                    continue;
                }
                if idx.len() < 3 {
                    return Err(defect(
                        format!("line {n}"),
                        "a face (`f`) needs three vertices",
                    ));
                }
                for j in 1..idx.len() - 1 {
                    raw.faces.push(([idx[0], idx[j], idx[j + 1]], n));
                    let t = [tex[0], tex[j], tex[j + 1]];
                    raw.face_vt.push(match t {
                        [Some(a), Some(b), Some(c)] => Some([a, b, c]),
                        _ => None,
                    });
                }
            }
            "g" | "o" => current = rest.iter().map(|s| s.to_string()).collect(),
            _ => {}
        }
    }
    Ok(raw)
}

/// The checks, in the order a user would fix them; then the pattern in metres.
fn check(raw: Raw, unit_m: f64) -> Result<Pattern, Defect> {
    if raw.faces.is_empty() {
        return Err(defect(
            "faces",
            "the file has no faces (`f` lines): nothing to drape",
        ));
    }
    unused_vertex(&raw)?;
    let rest = rest_layout(&raw)?;
    let (rest_triangles, triangles) = oriented(&raw, &rest)?;
    manifold(&raw, &triangles)?;
    connected(raw.v.len(), &triangles)?;
    let lines: Vec<usize> = raw.faces.iter().map(|f| f.1).collect();
    overlap::no_self_overlap(&rest.points, &rest_triangles, &lines)?;
    if off_plane(&raw.v).is_some() {
        overlap::rest_at_start_scale(&rest.points, &rest_triangles, &raw.v, &triangles)?;
    }
    Ok(Pattern {
        rest_m: rest.points.iter().map(|p| p.map(|c| c * unit_m)).collect(),
        rest_triangles,
        triangles,
        vertex_of_rest: rest.vertex_of,
        start_m: raw.v.iter().map(|p| p.map(|c| c * unit_m)).collect(),
        groups: raw
            .groups
            .into_iter()
            .map(|(g, mut v)| {
                v.sort_unstable();
                v.dedup();
                (g, v)
            })
            .collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const SQUARE: &str = "o panel\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\ng hem\nl 1 2\n";

    #[test]
    fn a_quad_becomes_two_counter_clockwise_triangles_with_its_groups() {
        let p = parse_obj(SQUARE, 0.01).unwrap();
        assert_eq!(p.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(p.rest_m[2], [0.01, 0.01]);
        assert_eq!(p.groups["panel"], vec![0, 1, 2, 3]);
        assert_eq!(p.groups["hem"], vec![0, 1]);
        // Clockwise as a whole is turned over, with the same vertices.
        let cw = parse_obj("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 3 2\n", 1.0).unwrap();
        assert_eq!(cw.triangles, vec![[0, 1, 2]]);
    }

    /// Each malformed file with the defect its message must name.
    pub(crate) const MALFORMED: [(&str, &str, &str); 12] = [
        ("no_faces", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no faces"),
        (
            "bad_vertex",
            "v 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            "three finite numbers",
        ),
        (
            "out_of_range",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
            "refers to vertex 4",
        ),
        (
            "short_face",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n",
            "needs three vertices",
        ),
        (
            "not_flat",
            "v 0 0 0\nv 1 0 0\nv 0 1 0.2\nf 1 2 3\n",
            "not a flat pattern",
        ),
        (
            "degenerate",
            "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 4\nf 1 2 3\n",
            "without area",
        ),
        (
            "inverted",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 4 3\n",
            "inverted face",
        ),
        (
            "non_manifold_edge",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 2 1 0\nf 1 2 3\nf 2 1 4\nf 1 2 5\n",
            "non-manifold edge",
        ),
        (
            "disconnected",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 0 0\nv 6 0 0\nv 5 1 0\nf 1 2 3\nf 4 5 6\n",
            "disconnected pieces",
        ),
        (
            "garment_without_texture",
            "v 0 0 0\nv 1 0 0\nv 0 1 0.2\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3\n",
            "texture coordinates",
        ),
        (
            "texture_shared_by_two_vertices",
            "v 0 0 0\nv 1 0 0\nv 0 1 0.2\nv 1 1 0.2\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\nf 2/2 4/3 3/3\n",
            "flat position of vertices",
        ),
        (
            "bow_tie",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv -1 0 0\nv -1 -1 0\nf 1 2 3\nf 1 4 5\n",
            "non-manifold vertex",
        ),
    ];

    /// Two pieces sewn along one edge, folded at it in 3D: vertices 2 and 3 are the seam's, each
    /// with a rest vertex in both pieces (the second piece laid elsewhere in the pattern's plane).
    pub(crate) const SEWN: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0.5 0.5 0.7\n\
vt 0 0\nvt 1 0\nvt 0 1\nvt 5 0\nvt 4 1\nvt 5 1\n\
g front\nf 1/1 2/2 3/3\ng back\nf 2/4 4/6 3/5\n";

    #[test]
    fn a_garment_keeps_its_placed_vertices_and_its_pieces_flat_rest_shapes() {
        let p = parse_obj(SEWN, 1.0).unwrap();
        assert!(!p.is_flat());
        assert_eq!(p.vertex_count(), 4);
        assert_eq!(p.start_m[3], [0.5, 0.5, 0.7]);
        assert_eq!(p.triangles, vec![[0, 1, 2], [1, 3, 2]]);
        assert_eq!(p.rest_triangles, vec![[0, 1, 2], [3, 4, 5]]);
        // The seam's vertices 2 and 3 (0-based 1, 2) have a rest vertex in each piece.
        assert_eq!(p.vertex_of_rest, vec![0, 1, 2, 1, 3, 2]);
        assert!((p.rest_area_m2() - 1.0).abs() < 1e-12);
        // One piece placed in 3D whose texture coordinates are numbered as its vertices is a
        // garment still: it starts where the file places it.
        let folded = parse_obj(
            "v 0 0 0\nv 1 0 0\nv 0 1 0.3\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n",
            1.0,
        )
        .unwrap();
        assert!(!folded.is_flat());
        assert_eq!(folded.rest_triangles, folded.triangles);
        // A flat file with texture coordinates (a print) keeps its vertices as its rest shape.
        let printed = parse_obj(
            "v 0 0 0\nv 2 0 0\nv 0 2 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n",
            1.0,
        )
        .unwrap();
        assert!(printed.is_flat());
        assert_eq!(printed.rest_m[1], [2.0, 0.0]);
    }

    #[test]
    fn each_malformed_pattern_is_refused_naming_its_defect() {
        for (name, text, says) in MALFORMED {
            let err = parse_obj(text, 1.0).expect_err(name);
            assert!(err.message.contains(says), "{name}: {err:?}");
            assert!(!err.message.contains('\n'), "{name}: one line");
        }
    }
}
