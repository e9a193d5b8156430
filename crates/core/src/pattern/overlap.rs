//! The checks of a pattern's rest shape against itself and its start: no piece laid flat over
//! itself (two of its triangles overlapping in the plane: a rest shape no sheet can have), and a
//! garment's texture coordinates at the scale of its placed pieces (UVs normalized to [0, 1], as
//! garment tools export them, would make every rest edge a multiple of the placed one).

use super::checks::pieces;
use super::{Defect, defect};
use std::collections::HashMap;

/// The median rest edge over its placed length a garment may have: placing stretches or eases a
/// piece by a few per cent, never by half.
const REST_SCALE: (f64, f64) = (2.0 / 3.0, 1.5);

/// Refuses a garment whose rest edges (`rest` over `rest_tris`) are not at the scale of its placed
/// edges (`start` over `tris`, the same triangles): the median of their ratios within
/// [`REST_SCALE`].
pub(super) fn rest_at_start_scale(
    rest: &[[f64; 2]],
    rest_tris: &[[usize; 3]],
    start: &[[f64; 3]],
    tris: &[[usize; 3]],
) -> Result<(), Defect> {
    let mut ratios: Vec<f64> = rest_tris
        .iter()
        .zip(tris)
        .flat_map(|(r, t)| {
            (0..3).map(move |k| {
                let (a, b) = (rest[r[k]], rest[r[(k + 1) % 3]]);
                let (p, q) = (start[t[k]], start[t[(k + 1) % 3]]);
                let lr = (a[0] - b[0]).hypot(a[1] - b[1]);
                let lp =
                    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt();
                lr / lp
            })
        })
        .filter(|r| r.is_finite())
        .collect();
    if ratios.is_empty() {
        return Ok(());
    }
    ratios.sort_unstable_by(f64::total_cmp);
    let median = ratios[ratios.len() / 2];
    if (REST_SCALE.0..=REST_SCALE.1).contains(&median) {
        return Ok(());
    }
    Err(defect(
        "vt",
        format!(
            "the texture coordinates (the pieces laid flat) are {median:.3} times the placed \
pieces' size (median over the edges): give them in the file's unit, as the flat pattern \
measures (not normalized to [0, 1])"
        ),
    ))
}

/// Refuses a rest shape where two triangles of one piece overlap in the plane (their interiors
/// meet; a shared edge or corner does not count): the piece folds over itself.
pub(super) fn no_self_overlap(
    rest: &[[f64; 2]],
    rest_tris: &[[usize; 3]],
    line_of: &[usize],
) -> Result<(), Defect> {
    let piece = pieces(rest.len(), rest_tris);
    let boxes: Vec<[f64; 4]> = rest_tris.iter().map(|t| bbox(rest, t)).collect();
    let cell = boxes
        .iter()
        .map(|b| (b[2] - b[0]).max(b[3] - b[1]))
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (i, b) in boxes.iter().enumerate() {
        let c = |v: f64| (v / cell).floor() as i64;
        for gx in c(b[0])..=c(b[2]) {
            for gy in c(b[1])..=c(b[3]) {
                grid.entry((gx, gy)).or_default().push(i);
            }
        }
    }
    let extent = boxes
        .iter()
        .fold(0.0f64, |m, b| m.max(b[2].abs()).max(b[3].abs()));
    let eps = 1e-9 * extent.max(cell);
    let mut cells: Vec<_> = grid.into_values().collect();
    cells.sort_unstable();
    for members in cells {
        for (k, &i) in members.iter().enumerate() {
            for &j in &members[k + 1..] {
                let same_piece = piece[rest_tris[i][0]] == piece[rest_tris[j][0]];
                if same_piece && overlap(rest, &rest_tris[i], &rest_tris[j], eps) {
                    let (a, b) = (line_of[i.min(j)], line_of[i.max(j)]);
                    return Err(defect(
                        format!("line {b}"),
                        format!(
                            "this face overlaps the face on line {a} in the flat pattern: the \
piece lies over itself; give each piece as a flat shape without overlaps"
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// A triangle's box: [x_min, y_min, x_max, y_max].
fn bbox(p: &[[f64; 2]], t: &[usize; 3]) -> [f64; 4] {
    let xs = t.map(|i| p[i][0]);
    let ys = t.map(|i| p[i][1]);
    [
        xs.iter().copied().fold(f64::INFINITY, f64::min),
        ys.iter().copied().fold(f64::INFINITY, f64::min),
        xs.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        ys.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    ]
}

/// Whether the interiors of triangles `a` and `b` overlap by more than `eps` (the separating axis
/// theorem over their six edge normals: touching along an edge or at a corner is separation).
fn overlap(p: &[[f64; 2]], a: &[usize; 3], b: &[usize; 3], eps: f64) -> bool {
    let (ta, tb) = (a.map(|i| p[i]), b.map(|i| p[i]));
    for tri in [&ta, &tb] {
        for k in 0..3 {
            let (u, v) = (tri[k], tri[(k + 1) % 3]);
            let len = (v[0] - u[0]).hypot(v[1] - u[1]);
            let n = [(u[1] - v[1]) / len, (v[0] - u[0]) / len];
            let proj = |t: &[[f64; 2]; 3]| {
                let d = t.map(|q| q[0] * n[0] + q[1] * n[1]);
                (
                    d.iter().copied().fold(f64::INFINITY, f64::min),
                    d.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                )
            };
            let ((lo1, hi1), (lo2, hi2)) = (proj(&ta), proj(&tb));
            if hi1 <= lo2 + eps || hi2 <= lo1 + eps {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangles_meeting_at_an_edge_do_not_overlap_and_a_folded_piece_does() {
        let p = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.2]];
        let (a, b) = ([0, 1, 2], [0, 2, 3]);
        assert!(!overlap(&p, &a, &b, 1e-12));
        // A triangle over the first's inside.
        assert!(overlap(&p, &a, &[4, 1, 2], 1e-12));
        assert!(no_self_overlap(&p, &[a, b], &[1, 2]).is_ok());
        let e = no_self_overlap(&p, &[a, b, [4, 1, 2]], &[1, 2, 3]).unwrap_err();
        assert_eq!(e.key, "line 3");
    }

    #[test]
    fn uvs_normalized_to_the_unit_square_are_refused() {
        let start = [[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [0.0, 0.5, 0.0]];
        let tris = [[0, 1, 2]];
        let unit = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        assert!(rest_at_start_scale(&unit, &tris, &start, &tris).is_err());
        let same = [[0.0, 0.0], [0.5, 0.0], [0.0, 0.5]];
        assert!(rest_at_start_scale(&same, &tris, &start, &tris).is_ok());
    }
}
