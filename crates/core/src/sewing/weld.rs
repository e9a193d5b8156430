//! Welding: each seam's paired vertices become one particle (a union over all pairs, so that a
//! corner where three seams meet is one), at the mean of their positions; the garment is then a
//! sewn pattern in OBJ's garment layout (pieces placed in 3D, their flat shapes as texture
//! coordinates, [`crate::pattern`]) and goes through every check a garment file does.

use super::panels::Unsewn;
use crate::pattern::{Defect, Pattern, parse_obj};
use std::fmt::Write;

/// The class of each vertex under the seams' pairs (union–find; a class's smallest vertex names it).
pub fn classes(n: usize, seams: &[[usize; 2]]) -> Vec<usize> {
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], mut v: usize) -> usize {
        while p[v] != v {
            p[v] = p[p[v]];
            v = p[v];
        }
        v
    }
    for &[a, b] in seams {
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        parent[ra.max(rb)] = ra.min(rb);
    }
    (0..n).map(|v| find(&mut parent, v)).collect()
}

/// The largest distance between a seam's paired vertices at positions `x`, m.
pub fn largest_gap_m(seams: &[[usize; 2]], x: &[[f64; 3]]) -> f64 {
    seams
        .iter()
        .map(|&[a, b]| {
            let d = [x[a][0] - x[b][0], x[a][1] - x[b][1], x[a][2] - x[b][2]];
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
        })
        .fold(0.0, f64::max)
}

/// The garment with its seams welded, the pieces at positions `x` (m), as OBJ text.
pub fn welded_obj(u: &Unsewn, x: &[[f64; 3]]) -> String {
    let class = classes(x.len(), &u.seams);
    let mut particle = vec![usize::MAX; x.len()];
    let mut members: Vec<Vec<usize>> = Vec::new();
    for (v, &c) in class.iter().enumerate() {
        if particle[c] == usize::MAX {
            particle[c] = members.len();
            members.push(Vec::new());
        }
        members[particle[c]].push(v);
    }
    let mut s = String::from("# a garment sewn by drapelab from a GarmentCode pattern\n");
    for m in &members {
        let k = m.len() as f64;
        let mean: [f64; 3] = std::array::from_fn(|i| m.iter().map(|&v| x[v][i]).sum::<f64>() / k);
        let _ = writeln!(s, "v {:.17e} {:.17e} {:.17e}", mean[0], mean[1], mean[2]);
    }
    for r in &u.rest_m {
        let _ = writeln!(s, "vt {:.17e} {:.17e}", r[0], r[1]);
    }
    let p = |v: usize| particle[class[v]] + 1;
    for (k, name) in u.panel_names.iter().enumerate() {
        let _ = writeln!(s, "o {name}");
        for t in u.triangles.iter().filter(|t| u.panel_of[t[0]] == k) {
            let _ = writeln!(
                s,
                "f {}/{} {}/{} {}/{}",
                p(t[0]),
                t[0] + 1,
                p(t[1]),
                t[1] + 1,
                p(t[2]),
                t[2] + 1
            );
        }
    }
    for (g, vs) in u.groups.iter().filter(|(g, _)| !u.panel_names.contains(g)) {
        let _ = writeln!(s, "g {g}");
        let mut ids: Vec<usize> = vs.iter().map(|&v| p(v)).collect();
        ids.sort_unstable();
        ids.dedup();
        let _ = writeln!(
            s,
            "l {}",
            ids.iter()
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
    s
}

/// The garment welded at positions `x` and checked as a garment file is.
pub fn weld(u: &Unsewn, x: &[[f64; 3]]) -> Result<Pattern, Defect> {
    parse_obj(&welded_obj(u, x), 1.0)
}
