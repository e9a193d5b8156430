//! A body mesh's pseudo-normals (the sign of its signed distance) and its flat edges.

use super::V3;
use std::collections::HashMap;

/// The edges whose two faces are coplanar (their unit normals within 10⁻⁹ of each other).
pub(super) fn flat_edges(
    triangles: &[[u32; 3]],
    face_normals: &[V3],
) -> std::collections::HashSet<(u32, u32)> {
    let mut first: HashMap<(u32, u32), V3> = HashMap::new();
    let mut flat = std::collections::HashSet::new();
    for (t, n) in triangles.iter().zip(face_normals) {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let key = (a.min(b), a.max(b));
            match first.get(&key) {
                Some(m) if (m - n).norm() < 1e-9 => {
                    flat.insert(key);
                }
                Some(_) => {}
                None => {
                    first.insert(key, *n);
                }
            }
        }
    }
    flat
}

/// Every vertex's angle-weighted pseudo-normal (its faces' normals weighted by their angles at it)
/// and every edge's (the sum of its faces' normals), normalised (Bærentzen and Aanæs 2005).
pub(super) fn pseudo_normals(
    vertices: &[V3],
    triangles: &[[u32; 3]],
    face_normals: &[V3],
) -> (Vec<V3>, HashMap<(u32, u32), V3>) {
    let mut vn = vec![V3::zeros(); vertices.len()];
    let mut en: HashMap<(u32, u32), V3> = HashMap::new();
    for (t, n) in triangles.iter().zip(face_normals) {
        for k in 0..3 {
            let (v, a, b) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            let (e1, e2) = (
                vertices[a as usize] - vertices[v as usize],
                vertices[b as usize] - vertices[v as usize],
            );
            let angle = e1.angle(&e2);
            vn[v as usize] += n * angle;
            let key = (v.min(a), v.max(a));
            *en.entry(key).or_insert_with(V3::zeros) += n;
        }
    }
    let unit = |v: V3| v.try_normalize(1e-300).unwrap_or(V3::z());
    (
        vn.into_iter().map(unit).collect(),
        en.into_iter().map(|(k, v)| (k, unit(v))).collect(),
    )
}
