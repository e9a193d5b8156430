//! The checks of a pattern's mesh, each naming the first defect it finds: the rest shape laid flat
//! (a flat file's vertices or a garment's texture coordinates), every vertex used, triangles
//! oriented alike, an edge-manifold mesh, one connected piece.

use super::{AREA_REL, Defect, FLAT_REL, Raw, defect};
use std::collections::HashMap;

/// The rest shape before its checks: flat positions, the faces over them, and each one's vertex.
pub(super) struct Rest {
    pub(super) points: Vec<[f64; 2]>,
    pub(super) faces: Vec<[usize; 3]>,
    pub(super) vertex_of: Vec<usize>,
}

/// A flat file's vertices are its rest shape; a garment's (vertices not in one plane) are its
/// faces' texture coordinates, each used by one vertex only.
pub(super) fn rest_layout(raw: &Raw) -> Result<Rest, Defect> {
    let z0 = raw.v[0][2];
    let Some((k, p)) = off_plane(&raw.v) else {
        return Ok(Rest {
            points: raw.v.iter().map(|p| [p[0], p[1]]).collect(),
            faces: raw.faces.iter().map(|f| f.0).collect(),
            vertex_of: (0..raw.v.len()).collect(),
        });
    };
    if let Some(f) = raw.face_vt.iter().position(Option::is_none) {
        return Err(defect(
            "vertices",
            format!(
                "not a flat pattern: vertex {} lies {:.3e} off the plane z = {z0} of vertex 1; give the piece flat (z constant), or a garment with every face corner's flat position as texture coordinates (`f v/vt`; the face on line {} has none)",
                k + 1,
                p[2] - z0,
                raw.faces[f].1
            ),
        ));
    }
    // Rest vertices: the texture coordinates the faces use, numbered in order of first use.
    let mut number: HashMap<usize, usize> = HashMap::new();
    let mut rest = Rest {
        points: Vec::new(),
        faces: Vec::with_capacity(raw.faces.len()),
        vertex_of: Vec::new(),
    };
    for ((v, line), vt) in raw.faces.iter().zip(&raw.face_vt) {
        let vt = vt.expect("checked above");
        let mut face = [0; 3];
        for k in 0..3 {
            let r = *number.entry(vt[k]).or_insert_with(|| {
                rest.points.push(raw.vt[vt[k]]);
                rest.vertex_of.push(v[k]);
                rest.points.len() - 1
            });
            if rest.vertex_of[r] != v[k] {
                return Err(defect(
                    format!("line {line}"),
                    format!(
                        "texture coordinate {} is the flat position of vertices {} and {}: give each piece's corner its own `vt`",
                        vt[k] + 1,
                        rest.vertex_of[r] + 1,
                        v[k] + 1
                    ),
                ));
            }
            face[k] = r;
        }
        rest.faces.push(face);
    }
    Ok(rest)
}

/// The first vertex off the plane z = const of vertex 1 (by more than [`FLAT_REL`] of the
/// extent), with its position; none for a flat set.
pub(super) fn off_plane(v: &[[f64; 3]]) -> Option<(usize, [f64; 3])> {
    let extent = extent(v);
    let z0 = v.first()?[2];
    v.iter()
        .enumerate()
        .find(|(_, p)| (p[2] - z0).abs() > FLAT_REL * extent)
        .map(|(k, p)| (k, *p))
}

fn extent(v: &[[f64; 3]]) -> f64 {
    let span = |c: usize| {
        let (lo, hi) = v
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p[c]), hi.max(p[c]))
            });
        hi - lo
    };
    span(0).max(span(1)).max(f64::MIN_POSITIVE)
}

/// Every vertex must belong to a face (a vertex in none would be a particle with no mass).
pub(super) fn unused_vertex(raw: &Raw) -> Result<(), Defect> {
    let mut used = vec![false; raw.v.len()];
    for (t, _) in &raw.faces {
        t.iter().for_each(|&v| used[v] = true);
    }
    match used.iter().position(|u| !u) {
        Some(k) => Err(defect(
            "vertices",
            format!("vertex {} is in no face: remove it or connect it", k + 1),
        )),
        None => Ok(()),
    }
}

/// The triangles counter-clockwise in the rest plane: every face must have area there and the
/// same orientation as the first (all clockwise is turned over as a whole). Returns the triangles
/// over rest vertices and over vertices, turned alike.
#[allow(clippy::type_complexity)]
pub(super) fn oriented(
    raw: &Raw,
    rest: &Rest,
) -> Result<(Vec<[usize; 3]>, Vec<[usize; 3]>), Defect> {
    let extent = {
        let v: Vec<[f64; 3]> = rest.points.iter().map(|p| [p[0], p[1], 0.0]).collect();
        extent(&v)
    };
    let signed = |t: &[usize; 3]| {
        let [a, b, c] = t.map(|i| rest.points[i]);
        0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]))
    };
    let sign = signed(&rest.faces[0]).signum();
    let (mut rest_out, mut out) = (Vec::new(), Vec::new());
    for (t, (v, line)) in rest.faces.iter().zip(&raw.faces) {
        let s = signed(t);
        if s.abs() <= AREA_REL * extent * extent {
            return Err(defect(
                format!("line {line}"),
                "a face without area (its vertices are collinear or repeated)",
            ));
        }
        if s.signum() != sign {
            return Err(defect(
                format!("line {line}"),
                "an inverted face: its vertices run the other way round from the first face's (a folded or flipped pattern)",
            ));
        }
        let turn = |t: &[usize; 3]| if sign > 0.0 { *t } else { [t[0], t[2], t[1]] };
        rest_out.push(turn(t));
        out.push(turn(v));
    }
    Ok((rest_out, out))
}

/// Each edge in at most two faces, and each vertex's faces one fan.
pub(super) fn manifold(raw: &Raw, tris: &[[usize; 3]]) -> Result<(), Defect> {
    let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
    for (t, (_, line)) in tris.iter().zip(&raw.faces) {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let e = edges.entry((a.min(b), a.max(b))).or_default();
            *e += 1;
            if *e > 2 {
                return Err(defect(
                    format!("line {line}"),
                    format!(
                        "a non-manifold edge: vertices {} and {} are shared by three or more faces",
                        a + 1,
                        b + 1
                    ),
                ));
            }
        }
    }
    // Around each vertex, its faces joined through shared edges must be one fan (no bow-tie).
    let mut around: Vec<Vec<usize>> = vec![Vec::new(); raw.v.len()];
    for (f, t) in tris.iter().enumerate() {
        t.iter().for_each(|&v| around[v].push(f));
    }
    for (v, faces) in around.iter().enumerate() {
        let shares = |f: usize, g: usize| {
            tris[f]
                .iter()
                .filter(|&&a| a != v && tris[g].contains(&a))
                .count()
                > 0
        };
        if components(faces.len(), |i, j| shares(faces[i], faces[j])) > 1 {
            let message = match seam_vertex(raw, v) {
                true => format!(
                    "vertex {} is sewn (faces of two pieces share it) but the pieces meet only \
at it: the two edges of a seam do not have the same vertices (unequal counts); give both edges \
of the seam the same number of vertices, shared pairwise",
                    v + 1
                ),
                false => format!(
                    "a non-manifold vertex: the faces around vertex {} meet only at it (a bow-tie); split it in two",
                    v + 1
                ),
            };
            return Err(defect("vertices", message));
        }
    }
    Ok(())
}

/// Whether vertex `v` is a seam's: its faces give it more than one flat position (`vt`).
fn seam_vertex(raw: &Raw, v: usize) -> bool {
    let mut vts = raw
        .faces
        .iter()
        .zip(&raw.face_vt)
        .filter_map(|((f, _), vt)| {
            let k = f.iter().position(|&a| a == v)?;
            vt.map(|t| t[k])
        });
    vts.next()
        .is_some_and(|first| vts.any(|other| other != first))
}

/// The piece (a root vertex of its connected component through shared faces) of every one of
/// the `n` vertices of `tris`.
pub(super) fn pieces(n: usize, tris: &[[usize; 3]]) -> Vec<usize> {
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    for t in tris {
        for k in 1..3 {
            let (a, b) = (root(&mut parent, t[0]), root(&mut parent, t[k]));
            parent[a] = b;
        }
    }
    (0..n).map(|i| root(&mut parent, i)).collect()
}

/// One piece: every vertex reachable from the first through faces.
pub(super) fn connected(n: usize, tris: &[[usize; 3]]) -> Result<(), Defect> {
    let piece = pieces(n, tris);
    let count = piece
        .iter()
        .collect::<std::collections::BTreeSet<_>>()
        .len();
    match (0..n).find(|&i| piece[i] != piece[0]) {
        Some(k) => Err(defect(
            "faces",
            format!(
                "{count} disconnected pieces (vertex {} is not joined to vertex 1): give one piece per file, or sew the pieces (faces of both pieces sharing the seam's vertices)",
                k + 1
            ),
        )),
        None => Ok(()),
    }
}

/// Connected components of `n` items under the relation `joined`.
fn components(n: usize, joined: impl Fn(usize, usize) -> bool) -> usize {
    let mut seen = vec![false; n];
    let mut count = 0;
    for s in 0..n {
        if seen[s] {
            continue;
        }
        count += 1;
        let mut stack = vec![s];
        seen[s] = true;
        while let Some(i) = stack.pop() {
            for (j, s) in seen.iter_mut().enumerate() {
                if !*s && joined(i, j) {
                    *s = true;
                    stack.push(j);
                }
            }
        }
    }
    count
}
